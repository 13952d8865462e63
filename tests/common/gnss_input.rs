//! Inputs of the real-time GNSS tests (`tests/io/gnss_closed_loop.rs`): the bad bytes written in
//! place of fixes, and free loopback ports for the caster and UDP receivers.

/// `len` bytes of bad input into `out`: random bytes, then the last good epoch with one
/// checksum digit wrong, a replay of it whole (a valid checksum, an old time), and its first
/// half (a truncated line).
pub fn bad_input(seed: &mut u64, last_epoch: &[u8], len: usize, out: &mut Vec<u8>) {
    out.clear();
    while out.len() < len / 2 {
        *seed ^= *seed << 13;
        *seed ^= *seed >> 7;
        *seed ^= *seed << 17;
        out.extend_from_slice(&seed.to_le_bytes());
    }
    if let Some(star) = last_epoch.iter().position(|&b| b == b'*') {
        let mut wrong = last_epoch.to_vec();
        if let Some(d) = wrong.get_mut(star + 1) {
            *d = if *d == b'0' { b'1' } else { b'0' };
        }
        out.extend_from_slice(&wrong);
    }
    out.extend_from_slice(last_epoch);
    out.extend_from_slice(&last_epoch[..last_epoch.len() / 2]);
    out.truncate(len);
}

/// A free TCP port on loopback (for the caster).
pub fn free_tcp_port() -> u16 {
    std::net::TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port()
}

/// A free UDP port on loopback (bound, then released for the stream to take).
pub fn free_udp_port() -> u16 {
    std::net::UdpSocket::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port()
}
