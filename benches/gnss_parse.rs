//! GNSS parsing speed, per sentence / message type (target: ≤ 1 µs each).
//!
//! `parse/*`: checksum and field decoding of one sentence (`nmea0183::parse`) or one UBX
//! payload (`ubx::decode`). `stream/*`: the whole path of one sentence through the stream
//! decoder (framing, checksum, decoding, conversion to `Input`s). `garbage_100kB`: the
//! decoder on 100 kB of random bytes (one second of the garbage flood).
//!
//! Measured in the benchmark thread's CPU time (`CLOCK_THREAD_CPUTIME_ID`), not wall time:
//! on a shared 2-core host under load, wall time counts the other processes' turns too.
//!
//! `cargo bench --bench gnss_parse`

use agsteer::input::nmea0183::{self, clock::Receipt, convert::StreamParams};
use agsteer::input::ubx::{self, encode, NavHpPosLlh, NavPvt, NavRelPosNed};
use agsteer::input::SourceId;
use agsteer::io::decoder::{DecoderParams, GnssDecoder, Protocol};
use criterion::{black_box, criterion_group, criterion_main, Criterion};
use rand::{Rng, SeedableRng};

#[path = "common/thread_cpu.rs"]
mod thread_cpu;
use thread_cpu::ThreadCpu;

fn line(body: &str) -> String {
    format!("${body}*{:02X}", nmea0183::xor_checksum(body.as_bytes()))
}

/// `s` with its time field (the first, `hhmmss.ss`, or KSXT's date-time) moved on by
/// `k` × 0.1 s and its checksum recomputed (KSXT keeps an XOR checksum then).
fn retime(s: &str, k: usize) -> String {
    let body = &s[1..s.rfind('*').unwrap()];
    let mut fields: Vec<String> = body.split(',').map(str::to_string).collect();
    let tod = 36_000.0 + k as f64 * 0.1;
    let hms = format!(
        "{:02}{:02}{:05.2}",
        (tod / 3600.0) as u32,
        ((tod % 3600.0) / 60.0) as u32,
        tod % 60.0
    );
    match fields[0].as_str() {
        "GNVTG" | "GNHDT" => {}
        "KSXT" => fields[1] = format!("20201222{hms}"),
        _ => fields[1] = hms,
    }
    line(&fields.join(","))
}

fn sentences() -> Vec<(&'static str, String)> {
    vec![
        // Real (tools/gnss/logs/nmea-rtk.log, Trimble RTK).
        (
            "GGA",
            "$GNGGA,133859.80,4134.50180205,N,09345.03586649,W,4,19,0.7,280.827,M,-31.442,M,5.8,0002*6D".into(),
        ),
        // Real (tools/gnss/logs/ublox-zed-f9p-nmea.log).
        ("RMC", "$GNRMC,003956.00,A,4552.65403,S,17030.00668,E,0.025,,120419,,,A,V*07".into()),
        ("VTG", line("GNVTG,054.7,T,034.4,M,005.5,N,010.2,K,A")),
        ("HDT", "$GNHDT,244.28,T*13".into()),
        // Real (tools/gnss/logs/polarx2.log).
        ("GST", "$GPGST,112257.00,0.387,317.719,3.872,1.791,317.563,10.659,180.746*61".into()),
        ("GNS", line("GNGNS,100000.00,4807.03812345,N,01131.00012345,E,RRRR,24,0.6,500.123,47.012,1.2,0007,V")),
        ("PANDA", line("PANDA,162255.50,3924.9012345,N,00731.8012345,W,4,12,0.7,341.9,1.2,4.8,2217,31,-12,0")),
        ("PAOGI", line("PAOGI,162255.50,3924.9012345,N,00731.8012345,W,4,12,0.7,341.9,1.2,4.8,221.70,3.10,,")),
        // Real (a Unicore receiver, CRC-32 checksum).
        (
            "KSXT",
            "$KSXT,20201222075720.00,119.17084152,32.07387900,83.5770,269.94,1.19,207.28,0.001,,3,3,25,25,-3.617,-4.468,-7.860,-0.000,-0.001,-0.022,1.0,56,*33736701".into(),
        ),
    ]
}

fn ubx_payloads() -> Vec<(&'static str, u8, Vec<u8>)> {
    let pvt = NavPvt {
        itow_ms: 100_000,
        utc_s: Some(1_700_000_000.0),
        fix_type: 3,
        gnss_fix_ok: true,
        diff_soln: true,
        carr_soln: 2,
        satellites: 24,
        lat_deg: 52.1234567,
        lon_deg: -1.2345678,
        height_m: 101.25,
        h_acc_m: 0.014,
        ground_speed_mps: 2.5,
        head_motion_deg: 90.0,
        pdop: 1.2,
        invalid_llh: false,
        correction_age_s: Some(2.0),
        head_vehicle_deg: None,
    };
    let hp = NavHpPosLlh {
        itow_ms: 100_000,
        invalid_llh: false,
        lat_deg: 52.123456789,
        lon_deg: -1.234567891,
        height_m: 101.2512,
        h_acc_m: 0.0141,
    };
    let rel = NavRelPosNed {
        version: 1,
        itow_ms: 100_000,
        north_m: 0.05,
        east_m: 1.2,
        down_m: 0.01,
        heading_deg: Some(87.6),
        gnss_fix_ok: true,
        rel_pos_valid: true,
        carr_soln: 2,
    };
    vec![
        ("NAV-PVT", ubx::ID_NAV_PVT, encode::nav_pvt(&pvt).to_vec()),
        (
            "NAV-HPPOSLLH",
            ubx::ID_NAV_HPPOSLLH,
            encode::nav_hpposllh(&hp).to_vec(),
        ),
        (
            "NAV-RELPOSNED",
            ubx::ID_NAV_RELPOSNED,
            encode::nav_relposned(&rel).to_vec(),
        ),
    ]
}

fn decoder(protocol: Protocol) -> GnssDecoder {
    GnssDecoder::new(DecoderParams {
        protocol,
        stream: StreamParams {
            source: SourceId::Stream(0),
            baseline_angle: 0.0,
            max_delay_s: 0.5,
        },
        max_correction_age_s: 10.0,
    })
}

fn bench(c: &mut Criterion<ThreadCpu>) {
    for (name, s) in sentences() {
        assert!(nmea0183::parse(s.as_bytes()).is_ok(), "{s}");
        c.bench_function(&format!("parse/{name}"), |b| {
            b.iter(|| nmea0183::parse(black_box(s.as_bytes())))
        });
    }
    for (name, id, p) in ubx_payloads() {
        assert!(ubx::decode(ubx::CLASS_NAV, id, &p).is_ok());
        c.bench_function(&format!("parse/{name}"), |b| {
            b.iter(|| ubx::decode(black_box(ubx::CLASS_NAV), black_box(id), black_box(&p)))
        });
    }
    // The whole path: framing + checksum + decoding + conversion, per sentence, each one a
    // new epoch (its time field advanced by 0.1 s per sentence, checksums recomputed; the
    // receipt time advances with it).
    for (name, s) in sentences() {
        let lines: Vec<Vec<u8>> = (0..1000)
            .map(|k| format!("{}\r\n", retime(&s, k)).into_bytes())
            .collect();
        let mut d = decoder(Protocol::Nmea0183);
        for l in &lines[..5] {
            d.push(l, &Receipt::at(0.0), &mut |_| {}, &mut |_| {});
        }
        let k0 = d.counters();
        assert!(
            k0.decoded == 5 && k0.malformed + k0.nmea_checksum_errors == 0,
            "{name}: {k0:?}"
        );
        let mut k = 0usize;
        c.bench_function(&format!("stream/{name}"), |b| {
            b.iter(|| {
                k += 1;
                let mut n = 0;
                let t = k as f64 * 0.1;
                d.push(
                    black_box(&lines[k % lines.len()]),
                    &Receipt::at(t),
                    &mut |_| n += 1,
                    &mut |_| {},
                );
                n
            })
        });
    }
    for (name, id, p) in ubx_payloads() {
        let frames: Vec<Vec<u8>> = (0..1000u32)
            .map(|k| {
                let mut p = p.clone();
                // iTOW is at offset 0 (NAV-PVT) or 4 (the others).
                let at = if id == ubx::ID_NAV_PVT { 0 } else { 4 };
                p[at..at + 4].copy_from_slice(&(100_000 + k * 100).to_le_bytes());
                ubx::frame(ubx::CLASS_NAV, id, &p)
            })
            .collect();
        let mut d = decoder(Protocol::Ubx);
        let mut k = 0usize;
        c.bench_function(&format!("stream/{name}"), |b| {
            b.iter(|| {
                k += 1;
                let mut n = 0;
                let t = k as f64 * 0.1;
                d.push(
                    black_box(&frames[k % frames.len()]),
                    &Receipt::at(t),
                    &mut |_| n += 1,
                    &mut |_| {},
                );
                n
            })
        });
    }
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
    let garbage: Vec<u8> = (0..100_000).map(|_| rng.gen()).collect();
    let mut d = decoder(Protocol::Nmea0183);
    c.bench_function("garbage_100kB", |b| {
        b.iter(|| {
            d.push(
                black_box(&garbage),
                &Receipt::at(0.0),
                &mut |_| {},
                &mut |_| {},
            )
        })
    });
}

criterion_group! {
    name = benches;
    config = Criterion::default().with_measurement(ThreadCpu);
    targets = bench
}
criterion_main!(benches);
