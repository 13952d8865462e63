//! Framer and decoder tests on real logs (tools/gnss/logs, from gpsd, BSD-2-Clause) and on
//! streams made hostile on purpose.

use super::decoder::{DecoderParams, GnssDecoder, Protocol};
use super::framer::{rtcm_frame, rtcm_message_type, Frame, Framer};
use crate::input::nmea0183::clock::Receipt;
use crate::input::nmea0183::convert::StreamParams;
use crate::input::{FixQuality, Input, SourceId};
use rand::{Rng, SeedableRng};

fn log(name: &str) -> Vec<u8> {
    let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tools/gnss/logs")
        .join(name);
    std::fs::read(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// Owned copy of a frame, to compare framings.
#[derive(Debug, Clone, PartialEq, Eq)]
enum Owned {
    Nmea(Vec<u8>),
    Text(Vec<u8>),
    Ubx(u8, u8, Vec<u8>),
    Rtcm(Vec<u8>),
}

fn own(f: Frame<'_>) -> Owned {
    match f {
        Frame::Nmea(l) => Owned::Nmea(l.to_vec()),
        Frame::Text(l) => Owned::Text(l.to_vec()),
        Frame::Ubx { class, id, payload } => Owned::Ubx(class, id, payload.to_vec()),
        Frame::Rtcm(f) => Owned::Rtcm(f.to_vec()),
    }
}

fn frames_in_chunks(data: &[u8], seed: u64, max_chunk: usize) -> (Vec<Owned>, Framer) {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let mut framer = Framer::new();
    let mut out = Vec::new();
    let mut rest = data;
    while !rest.is_empty() {
        let n = rng.gen_range(1..=max_chunk).min(rest.len());
        let (now, later) = rest.split_at(n);
        framer.push(now, &mut |f| out.push(own(f)));
        rest = later;
    }
    (out, framer)
}

#[test]
fn real_ubx_and_rtcm_interleaved_frame_the_same_in_any_chunks() {
    // A ZED-F9P's UBX output with its RTCM 3 base output on the same port.
    let data = log("ublox-f9p-rtcm.log");
    let (whole, f) = frames_in_chunks(&data, 0, data.len());
    let ubx = whole.iter().filter(|f| matches!(f, Owned::Ubx(..))).count();
    let rtcm: Vec<u16> = whole
        .iter()
        .filter_map(|f| {
            if let Owned::Rtcm(r) = f {
                rtcm_message_type(r)
            } else {
                None
            }
        })
        .collect();
    assert_eq!(ubx, 16);
    assert_eq!(rtcm.len(), 15, "{rtcm:?}");
    assert!(rtcm.contains(&1077) && rtcm.contains(&1230) && rtcm.contains(&4072));
    assert_eq!(
        f.counters.ubx_checksum_errors + f.counters.rtcm_crc_errors,
        0
    );
    for seed in 1..20 {
        let (chunked, _) = frames_in_chunks(&data, seed, 1 + seed as usize * 7);
        assert_eq!(chunked, whole, "seed {seed}");
    }
}

#[test]
fn real_ubx_and_nmea_interleaved() {
    let data = log("ublox-zed-f9t-ubx_nmea_l5.log");
    let (frames, f) = frames_in_chunks(&data, 3, 64);
    let nmea = frames
        .iter()
        .filter(|f| matches!(f, Owned::Nmea(_)))
        .count();
    let pvt = frames
        .iter()
        .filter(|f| matches!(f, Owned::Ubx(1, 7, _)))
        .count();
    assert_eq!(pvt, 9);
    assert!(nmea >= 9 * 11, "{nmea}");
    assert_eq!(f.counters.ubx_checksum_errors, 0);
}

/// NMEA lines of a log (without gpsd's `#` comments).
fn sentences(name: &str) -> Vec<Vec<u8>> {
    log(name)
        .split(|&b| b == b'\n')
        .map(|l| l.strip_suffix(b"\r").unwrap_or(l).to_vec())
        .filter(|l| l.first() == Some(&b'$'))
        .collect()
}

#[test]
fn sentences_survive_garbage_noise_and_truncation() {
    let lines = sentences("ublox-zed-f9p-nmea.log");
    assert!(lines.len() > 1000);
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
    let mut stream = Vec::new();
    let mut garbage = 0usize;
    for l in &lines {
        match rng.gen_range(0..6) {
            // Binary garbage between sentences.
            0 => {
                let n = rng.gen_range(1..300);
                garbage += n;
                stream.extend((0..n).map(|_| rng.gen::<u8>()));
            }
            // A truncated sentence (the receiver reset mid-line).
            1 => stream.extend_from_slice(&l[..l.len() / 2]),
            _ => {}
        }
        stream.extend_from_slice(l);
        stream.extend_from_slice(if rng.gen() { b"\r\n" } else { b"\n" });
    }
    // Enough trailing bytes to settle any false binary start in the last garbage.
    stream.extend(std::iter::repeat_n(b'\n', 5000));
    let (frames, f) = frames_in_chunks(&stream, 11, 200);
    let got: Vec<&Vec<u8>> = frames
        .iter()
        .filter_map(|f| {
            if let Owned::Nmea(l) = f {
                Some(l)
            } else {
                None
            }
        })
        .collect();
    // Every whole sentence comes out, in order (a garbage byte that happens to be printable
    // right before a '$' never joins the sentence: the '$' starts a new candidate).
    let mut it = got.iter();
    for l in &lines {
        assert!(it.any(|g| *g == l), "lost {}", String::from_utf8_lossy(l));
    }
    assert!(
        f.counters.garbage_bytes as usize >= garbage / 2,
        "{:?}",
        f.counters
    );
}

#[test]
fn a_line_end_split_between_chunks() {
    let mut f = Framer::new();
    let mut n = 0;
    f.push(b"$GPHDT,,T*1B\r", &mut |_| n += 1);
    f.push(b"\n$GPHDT,,T*1B\r\n", &mut |_| n += 1);
    assert_eq!(n, 2);
    assert_eq!(f.counters.garbage_bytes, 0);
    assert_eq!(f.pending(), 0);
}

#[test]
fn overlong_and_non_printable_lines_are_garbage() {
    let mut f = Framer::new();
    let mut n = 0;
    let mut long = b"$GPGGA,".to_vec();
    long.extend(std::iter::repeat_n(b'1', 400));
    long.extend_from_slice(b"\r\n$GPHDT,,T*1B\r\n");
    f.push(&long, &mut |_| n += 1);
    assert_eq!(n, 1);
    f.push(b"$GPHDT,\x01,T*1B\r\n", &mut |_| n += 1);
    assert_eq!(n, 1);
}

#[test]
fn a_false_rtcm_start_does_not_lose_the_sentences_behind_it() {
    let mut f = Framer::new();
    let mut lines = 0;
    // 0xD3 0x00 0x40: a plausible 64-byte RTCM header in line noise.
    let mut data = vec![0xD3, 0x00, 0x40];
    for _ in 0..10 {
        data.extend_from_slice(b"$GPHDT,,T*1B\r\n");
    }
    f.push(&data, &mut |fr| {
        lines += usize::from(matches!(fr, Frame::Nmea(_)))
    });
    assert_eq!(lines, 10);
    assert_eq!(f.counters.rtcm_crc_errors, 1);
    // A real frame is taken whole, and a flipped bit in one is not.
    let frame = rtcm_frame(&[0x43, 0x50, 1, 2, 3, 4, 5]);
    let mut rtcm = 0;
    f.push(&frame, &mut |fr| {
        rtcm += usize::from(matches!(fr, Frame::Rtcm(_)))
    });
    assert_eq!(rtcm, 1);
    let mut bad = frame.clone();
    bad[5] ^= 0x10;
    f.push(&bad, &mut |fr| {
        rtcm += usize::from(matches!(fr, Frame::Rtcm(_)))
    });
    assert_eq!(rtcm, 1);
}

fn decoder(protocol: Protocol) -> GnssDecoder {
    GnssDecoder::new(DecoderParams {
        protocol,
        stream: StreamParams {
            source: SourceId::Stream(0),
            baseline_angle: 0.0,
            max_delay_s: 0.5,
        },
        max_correction_age_s: 5.0,
    })
}

#[test]
fn decoder_counts_checksum_errors_and_garbage_and_never_panics() {
    let lines = sentences("nmea-rtk.log");
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
    let mut d = decoder(Protocol::Nmea0183);
    let mut inputs = 0;
    let mut corrupted = 0;
    for (k, l) in lines.iter().enumerate() {
        let mut l = l.clone();
        if k % 10 == 3 {
            // Line noise: one flipped bit in the body.
            let at = rng.gen_range(1..l.len() - 3);
            l[at] ^= 1 << rng.gen_range(0..7);
            if l[at] != b'$' && l[at] != b'*' && (0x20..0x7F).contains(&l[at]) {
                corrupted += 1;
            }
        }
        l.extend_from_slice(b"\r\n");
        let garbage: Vec<u8> = (0..rng.gen_range(0..50)).map(|_| rng.gen()).collect();
        let r = Receipt::at(k as f64 * 0.05);
        d.push(&l, &r, &mut |_| inputs += 1, &mut |_| {});
        d.push(&garbage, &r, &mut |_| inputs += 1, &mut |_| {});
    }
    let c = d.counters();
    assert!(inputs > 0);
    assert!(
        c.nmea_checksum_errors as usize >= corrupted * 9 / 10,
        "{c:?} {corrupted}"
    );
    assert!(c.framer.garbage_bytes > 0);
    assert_eq!(c.inputs, inputs as u64);
}

#[test]
fn the_other_protocol_is_ignored() {
    let data = log("ublox-zed-f9t-ubx_nmea_l5.log");
    for (protocol, want) in [(Protocol::Ubx, "ubx"), (Protocol::Nmea0183, "nmea")] {
        let mut d = decoder(protocol);
        let mut positions = 0;
        // Times in this log are an hour apart per gpsd's replay; feed at the log's own pace.
        d.push(
            &data,
            &Receipt::at(0.0),
            &mut |i| positions += usize::from(matches!(i, Input::Position(_))),
            &mut |_| {},
        );
        let c = d.counters();
        assert!(c.decoded > 0 && c.unused > 0, "{want}: {c:?}");
        assert!(positions >= 1, "{want}: {c:?}");
    }
}

#[test]
fn old_corrections_degrade_a_fixed_solution_to_float() {
    let gga = |age: f64, tod: &str| {
        crate::input::nmea0183::tests::with_checksum(&format!(
            "GNGGA,{tod},4807.038,N,01131.000,E,4,12,0.6,500.0,M,47.0,M,{age:.1},0001"
        ))
    };
    let mut d = decoder(Protocol::Nmea0183);
    let mut q = Vec::new();
    let mut push = |d: &mut GnssDecoder, line: String, t: f64| {
        d.push(
            format!("{line}\r\n").as_bytes(),
            &Receipt::at(t),
            &mut |i| {
                if let Input::Position(p) = i {
                    q.push(p.quality)
                }
            },
            &mut |_| {},
        )
    };
    push(&mut d, gga(1.0, "100000.00"), 0.0);
    push(&mut d, gga(7.5, "100000.10"), 0.1);
    // The receiver's age is fine, but the NTRIP link has been silent for 12 s.
    d.set_link_correction_age(Some(12.0));
    push(&mut d, gga(1.0, "100000.20"), 0.2);
    d.set_link_correction_age(Some(0.5));
    push(&mut d, gga(1.0, "100000.30"), 0.3);
    let fixed = Some(FixQuality::RtkFixed);
    let float = Some(FixQuality::RtkFloat);
    assert_eq!(q, vec![fixed, float, float, fixed]);
    // One per fix: the GGA's Quality and Position of an epoch are one fix.
    assert_eq!(d.counters().degraded_fixes, 2, "two epochs");
}

#[test]
fn random_bytes_at_any_chunking_never_panic() {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(99);
    let mut d = decoder(Protocol::Ubx);
    let mut n = 0;
    for k in 0..2000 {
        let len = rng.gen_range(0..600);
        // Biased towards the sync bytes so that candidates of every kind are exercised.
        let chunk: Vec<u8> = (0..len)
            .map(|_| match rng.gen_range(0..8) {
                0 => 0xB5,
                1 => 0x62,
                2 => 0xD3,
                3 => b'$',
                4 => 0x01,
                _ => rng.gen(),
            })
            .collect();
        d.push(
            &chunk,
            &Receipt::at(k as f64 * 0.01),
            &mut |_| n += 1,
            &mut |_| {},
        );
    }
    assert!(d.counters().framer.garbage_bytes > 100_000);
}
