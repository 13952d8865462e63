//! NMEA 2000 fast-packet transport: messages longer than 8 bytes split over up to 32 frames.
//!
//! Byte 0 of every frame is `sequence id << 5 | frame index`. Frame 0 carries the payload
//! length in byte 1 and six payload bytes; later frames carry seven. Frames must arrive in
//! order: a gap or a frame out of order drops the message (it is never patched together).
//! Memory is bounded: a fixed number of messages in flight, 223 bytes each.

/// Largest fast-packet payload, bytes.
pub const MAX_PAYLOAD: usize = 223;
/// Messages reassembled at once (per source address and sequence id).
const SLOTS: usize = 8;

/// Why a frame was rejected.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum FastPacketError {
    #[error("fast-packet frame shorter than 2 bytes")]
    Short,
    #[error("fast-packet length {0} is over {MAX_PAYLOAD}")]
    TooLong(usize),
    #[error("fast-packet frame {got} arrived, frame {expected} was expected: message dropped")]
    OutOfOrder { expected: u8, got: u8 },
    #[error("fast-packet frame {0} without its first frame")]
    NoStart(u8),
}

#[derive(Debug, Clone, Copy)]
struct Slot {
    active: bool,
    source: u8,
    seq: u8,
    next: u8,
    len: usize,
    have: usize,
    buf: [u8; MAX_PAYLOAD],
    age: u64,
}

const EMPTY: Slot = Slot {
    active: false,
    source: 0,
    seq: 0,
    next: 0,
    len: 0,
    have: 0,
    buf: [0; MAX_PAYLOAD],
    age: 0,
};

/// Reassembles fast-packet messages of one PGN.
#[derive(Debug, Clone)]
pub struct Reassembler {
    slots: [Slot; SLOTS],
    clock: u64,
    out: [u8; MAX_PAYLOAD],
    out_len: usize,
}

impl Default for Reassembler {
    fn default() -> Self {
        Reassembler {
            slots: [EMPTY; SLOTS],
            clock: 0,
            out: [0; MAX_PAYLOAD],
            out_len: 0,
        }
    }
}

impl Reassembler {
    /// Feed one frame from `source`. Returns the whole payload when this frame completes it.
    pub fn push(&mut self, source: u8, data: &[u8]) -> Result<Option<&[u8]>, FastPacketError> {
        if data.len() < 2 {
            return Err(FastPacketError::Short);
        }
        self.clock += 1;
        let seq = data[0] >> 5;
        let index = data[0] & 0x1F;
        let found = self
            .slots
            .iter()
            .position(|s| s.active && s.source == source && s.seq == seq);
        let slot_i = if index == 0 {
            let len = data[1] as usize;
            if len > MAX_PAYLOAD {
                if let Some(i) = found {
                    self.slots[i].active = false;
                }
                return Err(FastPacketError::TooLong(len));
            }
            // Restart this (source, seq), or take a free or the oldest slot.
            let i = found
                .or_else(|| self.slots.iter().position(|s| !s.active))
                .unwrap_or_else(|| (0..SLOTS).min_by_key(|&i| self.slots[i].age).unwrap_or(0));
            let s = &mut self.slots[i];
            s.active = true;
            s.source = source;
            s.seq = seq;
            s.next = 1;
            s.len = len;
            let take = (data.len() - 2).min(6).min(len);
            s.buf[..take].copy_from_slice(&data[2..2 + take]);
            s.have = take;
            i
        } else {
            let Some(i) = found else {
                return Err(FastPacketError::NoStart(index));
            };
            let s = &mut self.slots[i];
            if index != s.next {
                let expected = s.next;
                s.active = false;
                return Err(FastPacketError::OutOfOrder {
                    expected,
                    got: index,
                });
            }
            let take = (data.len() - 1).min(7).min(s.len - s.have);
            s.buf[s.have..s.have + take].copy_from_slice(&data[1..1 + take]);
            s.have += take;
            s.next += 1;
            i
        };
        let s = &mut self.slots[slot_i];
        s.age = self.clock;
        if s.have >= s.len {
            s.active = false;
            self.out[..s.len].copy_from_slice(&s.buf[..s.len]);
            self.out_len = s.len;
            return Ok(Some(&self.out[..self.out_len]));
        }
        Ok(None)
    }
}

/// Split `payload` into fast-packet frame payloads (8 bytes each, unused bytes 0xFF) with
/// sequence id `seq` (0..=7). Appends to `out`; returns the number of frames.
pub fn split(payload: &[u8], seq: u8, out: &mut Vec<[u8; 8]>) -> usize {
    let len = payload.len().min(MAX_PAYLOAD);
    let payload = &payload[..len];
    let mut n = 0;
    let mut f = [0xFFu8; 8];
    f[0] = (seq & 7) << 5;
    f[1] = len as u8;
    let first = len.min(6);
    f[2..2 + first].copy_from_slice(&payload[..first]);
    out.push(f);
    n += 1;
    let mut pos = first;
    let mut index = 1u8;
    while pos < len {
        let mut f = [0xFFu8; 8];
        f[0] = ((seq & 7) << 5) | (index & 0x1F);
        let take = (len - pos).min(7);
        f[1..1 + take].copy_from_slice(&payload[pos..pos + take]);
        out.push(f);
        n += 1;
        pos += take;
        index += 1;
    }
    n
}

#[cfg(test)]
mod tests {
    use super::*;

    fn payload(n: usize) -> Vec<u8> {
        (0..n).map(|i| (i * 7 + 3) as u8).collect()
    }

    #[test]
    fn round_trip_various_lengths() {
        for n in [1usize, 6, 7, 13, 43, 47, 100, 223] {
            let p = payload(n);
            let mut frames = Vec::new();
            split(&p, 3, &mut frames);
            let mut r = Reassembler::default();
            let mut got = None;
            for (k, f) in frames.iter().enumerate() {
                let res = r.push(0x1C, f).unwrap();
                if k + 1 < frames.len() {
                    assert!(res.is_none());
                } else {
                    got = res.map(|s| s.to_vec());
                }
            }
            assert_eq!(got, Some(p), "n={n}");
        }
    }

    #[test]
    fn out_of_order_and_missing_frames_are_rejected() {
        let p = payload(47);
        let mut frames = Vec::new();
        split(&p, 1, &mut frames);
        // Swap frames 2 and 3.
        let mut r = Reassembler::default();
        r.push(0x1C, &frames[0]).unwrap();
        r.push(0x1C, &frames[1]).unwrap();
        assert!(matches!(
            r.push(0x1C, &frames[3]),
            Err(FastPacketError::OutOfOrder { .. })
        ));
        // The rest of that message never completes.
        for f in &frames[2..] {
            assert!(!matches!(r.push(0x1C, f), Ok(Some(_))));
        }
        // Missing frame 4.
        let mut r = Reassembler::default();
        let mut complete = false;
        for (k, f) in frames.iter().enumerate() {
            if k == 4 {
                continue;
            }
            if let Ok(Some(_)) = r.push(0x1C, f) {
                complete = true;
            }
        }
        assert!(!complete);
        // A later frame with no start.
        let mut r = Reassembler::default();
        assert_eq!(r.push(0x1C, &frames[2]), Err(FastPacketError::NoStart(2)));
    }

    #[test]
    fn interleaved_sources_and_sequences() {
        let (a, b) = (
            payload(30),
            payload(20).iter().map(|x| x ^ 0xAA).collect::<Vec<_>>(),
        );
        let (mut fa, mut fb) = (Vec::new(), Vec::new());
        split(&a, 0, &mut fa);
        split(&b, 5, &mut fb);
        let mut r = Reassembler::default();
        let mut done = Vec::new();
        for k in 0..fa.len().max(fb.len()) {
            if let Some(f) = fa.get(k) {
                if let Ok(Some(p)) = r.push(0x1C, f) {
                    done.push(p.to_vec());
                }
            }
            if let Some(f) = fb.get(k) {
                if let Ok(Some(p)) = r.push(0x2D, f) {
                    done.push(p.to_vec());
                }
            }
        }
        assert!(done.contains(&a) && done.contains(&b));
    }

    #[test]
    fn garbage_never_panics() {
        let mut r = Reassembler::default();
        let mut x: u32 = 12345;
        for _ in 0..100_000 {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            let len = (x % 9) as usize;
            let bytes = x.to_le_bytes();
            let data = [
                bytes[0], bytes[1], bytes[2], bytes[3], bytes[1], bytes[0], 0xFF, 0,
            ];
            let _ = r.push(bytes[2] % 3, &data[..len]);
        }
    }
}
