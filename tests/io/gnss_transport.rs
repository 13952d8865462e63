//! GNSS transports on this host: a serial receiver on a pseudo-terminal (unplugged and plugged
//! back behind the same `/dev/serial/by-id`-style link), UDP with a source filter and a flood,
//! a TCP server that drops the connection. Everything on loopback or a pty; bounded in count
//! and time.

use agsteer::input::nmea0183::{convert::StreamParams, xor_checksum};
use agsteer::input::{FixQuality, Input, SourceId};
use agsteer::io::decoder::{DecoderParams, Protocol};
use agsteer::io::pty::Pty;
use agsteer::io::transport::{
    run_stream, SharedStatus, StreamConfig, StreamPorts, StreamStatus, Transport,
};
use std::io::Write;
use std::net::{SocketAddr, UdpSocket};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};
use tokio::sync::mpsc;

fn config(transport: Transport) -> StreamConfig {
    StreamConfig {
        transport,
        decoder: DecoderParams {
            protocol: Protocol::Nmea0183,
            stream: StreamParams {
                source: SourceId::Stream(0),
                baseline_angle: 0.0,
                max_delay_s: 0.5,
            },
            max_correction_age_s: 10.0,
        },
        silence_timeout_s: 2.0,
        backoff_min_s: 0.05,
        backoff_max_s: 0.4,
        max_rate_bytes_s: 200_000.0,
        host_utc: false,
    }
}

/// A GGA of epoch `k` (10 Hz) with its checksum, CR LF ended.
fn gga(k: u64) -> Vec<u8> {
    let tod = 36_000.0 + k as f64 * 0.1;
    let body = format!(
        "GNGGA,{:02}{:02}{:05.2},4807.0381234,N,01131.0001234,E,4,14,0.6,500.0,M,47.0,M,1.0,0001",
        (tod / 3600.0) as u32,
        ((tod % 3600.0) / 60.0) as u32,
        tod % 60.0
    );
    format!("${body}*{:02X}\r\n", xor_checksum(body.as_bytes())).into_bytes()
}

struct Running {
    status: SharedStatus,
    inputs: mpsc::Receiver<Input>,
    rtcm: mpsc::Sender<Vec<u8>>,
}

fn start(cfg: StreamConfig) -> Running {
    let status: SharedStatus = Arc::new(Mutex::new(StreamStatus::default()));
    let (tx, inputs) = mpsc::channel(1024);
    let (rtcm, rtcm_rx) = mpsc::channel(16);
    tokio::spawn(run_stream(
        cfg,
        StreamPorts {
            inputs: tx,
            rtcm: Some(rtcm_rx),
            last_rtcm: None,
            position: None,
            status: status.clone(),
        },
    ));
    Running {
        status,
        inputs,
        rtcm,
    }
}

fn status(r: &Running) -> StreamStatus {
    r.status.lock().unwrap().clone()
}

/// Positions received within `within`.
async fn positions(r: &mut Running, within: Duration) -> Vec<agsteer::input::PositionInput> {
    let mut out = Vec::new();
    let end = tokio::time::Instant::now() + within;
    while let Ok(Some(i)) = tokio::time::timeout_at(end, r.inputs.recv()).await {
        if let Input::Position(p) = i {
            out.push(p);
        }
    }
    out
}

/// Write epochs `k0..k0+n` to a pty at 10 Hz (the writes pace the epochs in real time).
async fn feed(pty: &Pty, k0: u64, n: u64) {
    let mut m = pty.master();
    for k in k0..k0 + n {
        let _ = m.write_all(&gga(k));
        tokio::time::sleep(Duration::from_millis(100)).await;
    }
}

#[tokio::test(flavor = "current_thread")]
async fn serial_pty_unplugged_and_plugged_back() {
    let dir = tempfile::tempdir().unwrap();
    let link = dir.path().join("usb-u-blox_GNSS_receiver-if00");
    let pty = Pty::open().unwrap();
    std::os::unix::fs::symlink(pty.path(), &link).unwrap();
    let mut r = start(config(Transport::Serial {
        device: link.clone(),
        baud: 115_200,
    }));
    // Let the stream open the device, then 1 s of fixes.
    tokio::time::sleep(Duration::from_millis(200)).await;
    let (_, got) = tokio::join!(
        feed(&pty, 0, 10),
        positions(&mut r, Duration::from_millis(1100))
    );
    assert!(got.len() >= 8, "{} positions; {:?}", got.len(), status(&r));
    assert!(got
        .iter()
        .all(|p| p.quality == Some(FixQuality::RtkFixed) && p.source == SourceId::Stream(0)));
    assert!(status(&r).connected);

    // Unplug: half a sentence, then the device disappears.
    let _ = pty.master().write_all(&gga(10)[..30]);
    tokio::time::sleep(Duration::from_millis(50)).await;
    drop(pty);
    std::fs::remove_file(&link).unwrap();
    let unplugged = Instant::now();
    let lost = positions(&mut r, Duration::from_millis(800)).await;
    assert!(lost.is_empty(), "no fix while unplugged: {lost:?}");
    let s = status(&r);
    assert!(!s.connected && s.reconnects >= 1, "{s:?}");
    assert!(s.last_error.is_some());

    // Plug back (a new tty behind the same link, as udev does).
    let pty = Pty::open().unwrap();
    std::os::unix::fs::symlink(pty.path(), &link).unwrap();
    let replugged = Instant::now();
    let mut first = None;
    let (_, got) = tokio::join!(feed(&pty, 30, 15), async {
        let end = tokio::time::Instant::now() + Duration::from_millis(1600);
        let mut out = Vec::new();
        while let Ok(Some(i)) = tokio::time::timeout_at(end, r.inputs.recv()).await {
            if let Input::Position(p) = i {
                first.get_or_insert(Instant::now());
                out.push(p);
            }
        }
        out
    });
    let s = status(&r);
    assert!(
        got.len() >= 8,
        "{} positions after replug; {s:?}",
        got.len()
    );
    assert!(s.connected);
    assert_eq!(
        s.counters.malformed, 0,
        "the half sentence did not merge with the next: {s:?}"
    );
    let back = first.unwrap().duration_since(replugged);
    println!(
        "unplugged {:.2} s, first fix {:.0} ms after replug, reconnects {}",
        replugged.duration_since(unplugged).as_secs_f64(),
        back.as_secs_f64() * 1e3,
        s.reconnects
    );
    assert!(back < Duration::from_millis(1200), "{back:?}");

    // RTCM from the NTRIP client reaches the receiver.
    let frame = agsteer::io::framer::rtcm_frame(&[0x3E, 0xD0, 1, 2, 3]);
    r.rtcm.send(frame.clone()).await.unwrap();
    tokio::time::sleep(Duration::from_millis(100)).await;
    let mut buf = [0u8; 64];
    use std::io::Read;
    pty.set_nonblocking().unwrap();
    let n = pty.master().read(&mut buf).unwrap_or(0);
    assert_eq!(buf.get(..n), Some(&frame[..]));
    assert_eq!(status(&r).rtcm_bytes_out, frame.len() as u64);
}

fn free_udp_port() -> u16 {
    UdpSocket::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port()
}

#[tokio::test(flavor = "current_thread")]
async fn udp_with_a_source_filter() {
    let port = free_udp_port();
    let mut r = start(config(Transport::Udp {
        bind: SocketAddr::from(([127, 0, 0, 1], port)),
        source: Some([127, 0, 0, 1].into()),
        rtcm_to: None,
    }));
    tokio::time::sleep(Duration::from_millis(100)).await;
    let good = UdpSocket::bind("127.0.0.1:0").unwrap();
    let other = UdpSocket::bind("127.0.0.2:0").unwrap();
    let to = SocketAddr::from(([127, 0, 0, 1], port));
    let sender = async {
        for k in 0..10 {
            good.send_to(&gga(k), to).unwrap();
            other.send_to(&gga(100 + k), to).unwrap();
            tokio::time::sleep(Duration::from_millis(100)).await;
        }
    };
    let (_, got) = tokio::join!(sender, positions(&mut r, Duration::from_millis(1100)));
    let s = status(&r);
    assert!(got.len() >= 9, "{s:?}");
    assert_eq!(s.filtered_datagrams, 10, "{s:?}");
}

#[tokio::test(flavor = "current_thread")]
async fn udp_flood_is_counted_and_the_loop_keeps_its_period() {
    let port = free_udp_port();
    let mut r = start(config(Transport::Udp {
        bind: SocketAddr::from(([127, 0, 0, 1], port)),
        source: None,
        rtcm_to: None,
    }));
    tokio::time::sleep(Duration::from_millis(100)).await;
    // A flood from another thread: 1400-byte datagrams of garbage as fast as the kernel takes
    // them, for 1.5 s at most (bounded count too).
    let to = SocketAddr::from(([127, 0, 0, 1], port));
    let flood = std::thread::spawn(move || {
        let s = UdpSocket::bind("127.0.0.1:0").unwrap();
        let junk: Vec<u8> = (0..1400u32).map(|i| (i * 7919 % 251) as u8).collect();
        let start = Instant::now();
        let mut sent = 0u64;
        while start.elapsed() < Duration::from_millis(1500) && sent < 2_000_000 {
            if s.send_to(&junk, to).is_ok() {
                sent += 1;
            }
        }
        sent
    });
    // Meanwhile a 10 ms "control loop" on the same thread, and real fixes at 10 Hz.
    let good = UdpSocket::bind("127.0.0.1:0").unwrap();
    let control = async {
        let mut tick = tokio::time::interval(Duration::from_millis(10));
        tick.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Skip);
        let start = tokio::time::Instant::now();
        let mut late_max = Duration::ZERO;
        let mut ticks = 0;
        let mut k = 0;
        while start.elapsed() < Duration::from_millis(1400) {
            let at = tick.tick().await;
            late_max = late_max.max(at.elapsed());
            ticks += 1;
            if ticks % 10 == 0 {
                good.send_to(&gga(k), to).unwrap();
                k += 1;
            }
        }
        (ticks, late_max)
    };
    let (got, (ticks, late_max)) =
        tokio::join!(positions(&mut r, Duration::from_millis(1500)), control);
    let sent = flood.join().unwrap();
    let s = status(&r);
    println!(
        "flood: {sent} datagrams sent; garbage {} B, over the rate limit {} B; loop ticks {ticks}/140, max late {:.1} ms; fixes {}",
        s.counters.framer.garbage_bytes,
        s.dropped_bytes,
        late_max.as_secs_f64() * 1e3,
        got.len()
    );
    assert!(
        s.dropped_bytes + s.counters.framer.garbage_bytes > 100_000,
        "{s:?}"
    );
    assert!(ticks >= 70, "the control loop kept running: {ticks} ticks");
    // Fixes still come through (those not dropped with the flood above the rate limit), and
    // none is stale: each was stamped when it arrived.
    assert!(!got.is_empty(), "{s:?}");
}

#[tokio::test(flavor = "current_thread")]
async fn tcp_client_reconnects_when_the_server_drops_it() {
    let listener = tokio::net::TcpListener::bind("127.0.0.1:0").await.unwrap();
    let port = listener.local_addr().unwrap().port();
    let mut r = start(config(Transport::Tcp {
        host: "127.0.0.1".into(),
        port,
    }));
    for round in 0..2u64 {
        let (mut sock, _) = listener.accept().await.unwrap();
        let server = async {
            use tokio::io::AsyncWriteExt;
            for k in 0..8 {
                sock.write_all(&gga(round * 100 + k)).await.unwrap();
                tokio::time::sleep(Duration::from_millis(100)).await;
            }
            sock
        };
        let (sock, got) = tokio::join!(server, positions(&mut r, Duration::from_millis(850)));
        assert!(got.len() >= 7, "round {round}: {:?}", status(&r));
        if round == 0 {
            // RTCM goes up the same connection.
            r.rtcm
                .send(vec![0xD3, 0, 0, 0x47, 0xEA, 0x4B])
                .await
                .unwrap();
            let mut sock = sock;
            let mut b = [0u8; 6];
            use tokio::io::AsyncReadExt;
            tokio::time::timeout(Duration::from_secs(1), sock.read_exact(&mut b))
                .await
                .unwrap()
                .unwrap();
            assert_eq!(b, [0xD3, 0, 0, 0x47, 0xEA, 0x4B]);
        }
        // Dropping the socket closes the connection.
    }
    let s = status(&r);
    assert!(s.reconnects >= 1, "{s:?}");
}

/// Read what the pty's slave side was given, for up to `within`.
async fn read_master(pty: &Pty, within: Duration) -> Vec<u8> {
    use std::io::Read;
    pty.set_nonblocking().unwrap();
    let mut got = Vec::new();
    let mut buf = [0u8; 1024];
    let end = Instant::now() + within;
    while Instant::now() < end {
        let mut m = pty.master();
        match m.read(&mut buf) {
            Ok(n) if n > 0 => got.extend_from_slice(&buf[..n]),
            _ => tokio::time::sleep(Duration::from_millis(10)).await,
        }
    }
    got
}

/// `gnss.rtcm_device`: corrections go to a separate serial port (a pty behind a link), in
/// order and whole; unplugged and plugged back, the port is reopened and gets the new ones.
#[tokio::test(flavor = "current_thread")]
async fn rtcm_to_a_separate_serial_port() {
    use agsteer::io::framer::rtcm_frame;
    let dir = tempfile::tempdir().unwrap();
    let link = dir.path().join("usb-FTDI_UART2-if00-port0");
    let pty = Pty::open().unwrap();
    std::os::unix::fs::symlink(pty.path(), &link).unwrap();
    let status: SharedStatus = Arc::new(Mutex::new(StreamStatus::default()));
    let (tx, rx) = mpsc::channel(16);
    tokio::spawn(agsteer::io::transport::run_rtcm_serial(
        link.clone(),
        38_400,
        rx,
        status.clone(),
        0.05,
        0.2,
    ));
    tokio::time::sleep(Duration::from_millis(200)).await;
    let frames: Vec<Vec<u8>> = (0..3u8).map(|k| rtcm_frame(&[0x3E, 0xD0 | k, k])).collect();
    for f in &frames {
        tx.send(f.clone()).await.unwrap();
    }
    let got = read_master(&pty, Duration::from_millis(300)).await;
    assert_eq!(got, frames.concat());
    assert_eq!(
        status.lock().unwrap().rtcm_bytes_out,
        frames.concat().len() as u64
    );
    // Unplugged: the next write fails; plugged back behind the same link.
    drop(pty);
    std::fs::remove_file(&link).unwrap();
    let _ = tx.send(frames[0].clone()).await;
    tokio::time::sleep(Duration::from_millis(300)).await;
    let pty = Pty::open().unwrap();
    std::os::unix::fs::symlink(pty.path(), &link).unwrap();
    let fresh = rtcm_frame(&[0x3E, 0xD7, 7]);
    let mut got = Vec::new();
    for _ in 0..20 {
        tx.send(fresh.clone()).await.unwrap();
        got.extend(read_master(&pty, Duration::from_millis(100)).await);
        if !got.is_empty() {
            break;
        }
    }
    assert!(!got.is_empty(), "written again after the replug");
    assert!(
        got.chunks(fresh.len()).all(|c| c == fresh.as_slice()),
        "only new corrections after the replug"
    );
}
