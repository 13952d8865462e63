use super::clock::Receipt;
use super::convert::{NmeaConverter, StreamParams, KNOT_MPS};
use super::*;
use crate::input::{FixQuality, Input, SourceId};
use std::f64::consts::FRAC_PI_2;

/// A sentence with its checksum computed (for constructed test sentences).
pub(crate) fn with_checksum(body: &str) -> String {
    format!("${body}*{:02X}", xor_checksum(body.as_bytes()))
}

fn params() -> StreamParams {
    StreamParams {
        source: SourceId::Stream(0),
        baseline_angle: 0.0,
        max_delay_s: 0.5,
    }
}

fn inputs(lines: &[&str], t0: f64) -> Vec<Input> {
    let mut c = NmeaConverter::new(params());
    let mut out = Vec::new();
    for (k, l) in lines.iter().enumerate() {
        let s = parse(l.as_bytes()).unwrap_or_else(|e| panic!("{l}: {e}"));
        c.convert(&s, &Receipt::at(t0 + k as f64 * 0.01), &mut |i| out.push(i));
    }
    out
}

#[test]
fn gga_trimble_rtk_fixed_with_age_and_station() {
    // Real: tools/gnss/logs/nmea-rtk.log (Trimble, BSD-2-Clause).
    let s = parse(b"$GNGGA,133859.80,4134.50180205,N,09345.03586649,W,4,19,0.7,280.827,M,-31.442,M,5.8,0002*6D\r\n").unwrap();
    let Sentence::Gga(g) = s else { panic!("{s:?}") };
    assert_eq!(g.time_s, Some(13.0 * 3600.0 + 38.0 * 60.0 + 59.8));
    assert!((g.lat_deg.unwrap() - (41.0 + 34.501_802_05 / 60.0)).abs() < 1e-12);
    assert!((g.lon_deg.unwrap() + (93.0 + 45.035_866_49 / 60.0)).abs() < 1e-12);
    assert_eq!(g.quality, 4);
    assert_eq!(g.satellites, Some(19));
    assert_eq!(g.hdop, Some(0.7));
    assert_eq!(g.correction_age_s, Some(5.8));
    assert_eq!(g.station_id, Some(2));
    let out = inputs(&["$GNGGA,133859.80,4134.50180205,N,09345.03586649,W,4,19,0.7,280.827,M,-31.442,M,5.8,0002*6D"], 1.0);
    let [Input::Quality(q), Input::Position(p)] = out.as_slice() else {
        panic!("{out:?}")
    };
    assert_eq!(q.quality, FixQuality::RtkFixed);
    assert_eq!(q.correction_age_s, Some(5.8));
    assert_eq!(p.quality, Some(FixQuality::RtkFixed));
    assert!(
        (p.altitude_m.unwrap() - (280.827 - 31.442)).abs() < 1e-9,
        "ellipsoidal height"
    );
    assert_eq!(p.latency_s, None, "no host UTC given");
    assert_eq!(p.source, SourceId::Stream(0));
}

#[test]
fn gga_quality_mapping() {
    use convert::gga_quality as q;
    assert_eq!(q(0), FixQuality::None);
    assert_eq!(q(1), FixQuality::Other);
    assert_eq!(q(2), FixQuality::Other);
    assert_eq!(q(4), FixQuality::RtkFixed);
    assert_eq!(q(5), FixQuality::RtkFloat);
    assert_eq!(q(6), FixQuality::Other);
    assert_eq!(q(7), FixQuality::None);
}

#[test]
fn gga_without_fix_gives_quality_none_and_no_position() {
    // Real: tools/gnss/logs/hemi.log.
    let out = inputs(&["$GPGGA,,,,,,0,,,,M,,M,,*66"], 0.0);
    assert!(
        matches!(out.as_slice(), [Input::Quality(q)] if q.quality == FixQuality::None),
        "{out:?}"
    );
}

#[test]
fn rmc_and_vtg_give_course_and_speed() {
    let rmc = with_checksum("GPRMC,123519,A,4807.038,N,01131.000,E,022.4,084.4,230394,003.1,W,R");
    let vtg = with_checksum("GPVTG,054.7,T,034.4,M,005.5,N,010.2,K,A");
    let out = inputs(&[&rmc, &vtg], 0.0);
    let [Input::CourseSpeed(a), Input::CourseSpeed(b)] = out.as_slice() else {
        panic!("{out:?}")
    };
    assert!((a.speed_mps.unwrap() - 22.4 * KNOT_MPS).abs() < 1e-12);
    assert!((a.course.unwrap() - (FRAC_PI_2 - 84.4_f64.to_radians())).abs() < 1e-12);
    assert!(
        (b.speed_mps.unwrap() - 10.2 / 3.6).abs() < 1e-12,
        "km/h preferred"
    );
    assert!((b.course.unwrap() - (FRAC_PI_2 - 54.7_f64.to_radians())).abs() < 1e-12);
    let Sentence::Rmc(r) = parse(rmc.as_bytes()).unwrap() else {
        panic!()
    };
    assert_eq!(r.variation_deg, Some(-3.1));
    assert_eq!(r.mode, Some(b'R'));
    assert_eq!(r.date_days, Some(fields::days_from_civil(1994, 3, 23)));
    // A void RMC says nothing.
    let void = with_checksum("GPRMC,123520,V,,,,,,,230394,,,N");
    assert!(inputs(&[&void], 0.0).is_empty());
}

#[test]
fn hdt_west_is_pi() {
    let hdt = with_checksum("GNHDT,270.0,T");
    let out = inputs(&[&hdt], 0.0);
    let [Input::Heading(h)] = out.as_slice() else {
        panic!("{out:?}")
    };
    assert!(
        (h.heading - std::f64::consts::PI).abs() < 1e-12,
        "{}",
        h.heading
    );
    // Real, empty: no heading.
    assert!(inputs(&["$GPHDT,,T*1B"], 0.0).is_empty());
}

#[test]
fn baseline_angle_turns_the_antenna_heading_into_the_vehicle_heading() {
    // Antennas across the vehicle, the secondary on the right: the baseline points 90°
    // clockwise of forward. Baseline heading 90° (East) → the vehicle faces North.
    let mut c = NmeaConverter::new(StreamParams {
        baseline_angle: -FRAC_PI_2,
        ..params()
    });
    let mut out = Vec::new();
    let s = parse(with_checksum("GNHDT,90.0,T").as_bytes()).unwrap();
    c.convert(&s, &Receipt::at(0.0), &mut |i| out.push(i));
    let [Input::Heading(h)] = out.as_slice() else {
        panic!("{out:?}")
    };
    assert!((h.heading - FRAC_PI_2).abs() < 1e-12, "{}", h.heading);
}

#[test]
fn gst_sigma_joins_the_epochs_quality() {
    // Real epoch: tools/gnss/logs/polarx2.log (Septentrio, GNS then GST).
    let gns = "$GPGNS,112257.00,3844.24011,N,00908.43828,W,AN,03,10.5,,,,*57";
    let gst = "$GPGST,112257.00,0.387,317.719,3.872,1.791,317.563,10.659,180.746*61";
    let out = inputs(&[gns, gst], 0.0);
    let [Input::Quality(q0), Input::Position(p), Input::Quality(q1)] = out.as_slice() else {
        panic!("{out:?}")
    };
    assert_eq!(q0.quality, FixQuality::Other, "modes A and N: autonomous");
    assert_eq!(q0.satellites, Some(3));
    assert_eq!(p.altitude_m, None);
    let sigma = 317.563_f64.hypot(10.659);
    assert!((q1.horizontal_sigma_m.unwrap() - sigma).abs() < 1e-9);
    assert_eq!(q1.hdop, Some(10.5));
    // GST first: the σ waits for its GGA.
    let gst = with_checksum("GNGST,100000.00,0.1,0.02,0.01,10,0.012,0.016,0.03");
    let gga =
        with_checksum("GNGGA,100000.00,4807.038,N,01131.000,E,4,12,0.6,500.0,M,47.0,M,1.0,0001");
    let out = inputs(&[&gst, &gga], 0.0);
    let [Input::Quality(q), Input::Position(_)] = out.as_slice() else {
        panic!("{out:?}")
    };
    assert!((q.horizontal_sigma_m.unwrap() - 0.02).abs() < 1e-12);
}

#[test]
fn gns_mode_letters() {
    let gns =
        with_checksum("GNGNS,100000.00,4807.038,N,01131.000,E,RRF,20,0.6,500.0,47.0,1.2,0007,V");
    let Sentence::Gns(g) = parse(gns.as_bytes()).unwrap() else {
        panic!()
    };
    assert_eq!(g.correction_age_s, Some(1.2));
    assert_eq!(g.station_id, Some(7));
    let out = inputs(&[&gns], 0.0);
    let [Input::Quality(q), Input::Position(p)] = out.as_slice() else {
        panic!("{out:?}")
    };
    assert_eq!(q.quality, FixQuality::RtkFixed);
    assert!((p.altitude_m.unwrap() - 547.0).abs() < 1e-9);
}

#[test]
fn one_position_per_epoch() {
    let gga =
        with_checksum("GNGGA,100000.00,4807.038,N,01131.000,E,4,12,0.6,500.0,M,47.0,M,1.0,0001");
    let gns = with_checksum("GNGNS,100000.00,4807.038,N,01131.000,E,RR,20,0.6,500.0,47.0,1.2,0007");
    let gga2 =
        with_checksum("GNGGA,100000.10,4807.038,N,01131.000,E,4,12,0.6,500.0,M,47.0,M,1.0,0001");
    let out = inputs(&[&gga, &gns, &gga2], 0.0);
    let positions = out
        .iter()
        .filter(|i| matches!(i, Input::Position(_)))
        .count();
    assert_eq!(positions, 2, "{out:?}");
}

#[test]
fn panda_from_the_aio_firmware() {
    // As the AiO firmware builds it: GGA fields, speed knots, IMU heading/roll/pitch ×10.
    let panda =
        with_checksum("PANDA,162255.50,3924.90,N,00731.80,W,4,12,0.7,341.9,1.2,4.8,2217,31,-12,0");
    let Sentence::Panda(a) = parse(panda.as_bytes()).unwrap() else {
        panic!()
    };
    assert_eq!(a.roll_deg, Some(3.1));
    assert_eq!(a.pitch_deg, Some(-1.2));
    assert!((a.heading_deg.unwrap() - 221.7).abs() < 1e-9);
    let out = inputs(&[&panda], 0.0);
    let [Input::Quality(q), Input::Position(p), Input::CourseSpeed(cs), Input::Attitude(at)] =
        out.as_slice()
    else {
        panic!("{out:?}")
    };
    assert_eq!(q.quality, FixQuality::RtkFixed);
    assert_eq!(q.correction_age_s, Some(1.2));
    assert!((p.lat_deg - (39.0 + 24.90 / 60.0)).abs() < 1e-12);
    assert!((cs.speed_mps.unwrap() - 4.8 * KNOT_MPS).abs() < 1e-12);
    assert_eq!(cs.course, None);
    assert!(
        (at.roll.unwrap() - 3.1_f64.to_radians()).abs() < 1e-12,
        "right side down positive"
    );
    // No IMU: heading 65535 and the IMU fields empty.
    let no_imu =
        with_checksum("PANDA,162255.60,3924.90,N,00731.80,W,4,12,0.7,341.9,1.2,4.8,65535,,,");
    let out = inputs(&[&no_imu], 0.0);
    assert!(
        !out.iter()
            .any(|i| matches!(i, Input::Attitude(_) | Input::Heading(_))),
        "{out:?}"
    );
}

#[test]
fn paogi_dual_heading_and_roll() {
    let paogi =
        with_checksum("PAOGI,162255.50,3924.90,N,00731.80,W,4,12,0.7,341.9,1.2,4.8,221.70,3.10,,");
    let out = inputs(&[&paogi], 0.0);
    let h = out.iter().find_map(|i| match i {
        Input::Heading(h) => Some(h.heading),
        _ => None,
    });
    assert!(
        (h.unwrap() - crate::geo::wrap_angle(FRAC_PI_2 - 221.7_f64.to_radians())).abs() < 1e-12
    );
    let roll = out.iter().find_map(|i| match i {
        Input::Attitude(a) => a.roll,
        _ => None,
    });
    assert!((roll.unwrap() - 3.1_f64.to_radians()).abs() < 1e-12);
}

#[test]
fn ksxt_with_unicore_crc32_and_with_xor() {
    // Real, from a Unicore receiver (8-hex CRC-32 checksum).
    let real = "$KSXT,20201222075720.00,119.17084152,32.07387900,83.5770,269.94,1.19,207.28,0.001,,3,3,25,25,-3.617,-4.468,-7.860,-0.000,-0.001,-0.022,1.0,56,*33736701";
    let Sentence::Ksxt(k) = parse(real.as_bytes()).unwrap() else {
        panic!()
    };
    let day = fields::days_from_civil(2020, 12, 22) as f64;
    assert_eq!(
        k.utc_s,
        Some(day * 86_400.0 + 7.0 * 3600.0 + 57.0 * 60.0 + 20.0)
    );
    assert_eq!(k.position_status, 3);
    assert_eq!(k.correction_age_s, Some(1.0));
    assert_eq!(k.satellites, Some(25));
    let out = inputs(&[real], 0.0);
    assert!(matches!(out.first(), Some(Input::Quality(q)) if q.quality == FixQuality::RtkFixed));
    let h = out.iter().find_map(|i| match i {
        Input::Heading(h) => Some(h.heading),
        _ => None,
    });
    assert!(
        (h.unwrap() - crate::geo::wrap_angle(FRAC_PI_2 - 269.94_f64.to_radians())).abs() < 1e-12
    );
    // Real, ArduPilot's UM982 sample with the ordinary XOR checksum.
    let xor = "$KSXT,20211016083433.00,116.31296102,39.95817066,49.4911,223.57,-11.32,330.19,0.024,,1,3,28,27,,,,-0.012,0.021,0.020,,*2D";
    let Sentence::Ksxt(k) = parse(xor.as_bytes()).unwrap() else {
        panic!()
    };
    assert_eq!(k.position_status, 1);
    assert_eq!(k.correction_age_s, None);
    // One changed digit fails the CRC.
    let bad = real.replace("83.5770", "83.5771");
    assert!(matches!(
        parse(bad.as_bytes()),
        Err(NmeaError::Checksum { .. })
    ));
}

#[test]
fn checksums_are_verified() {
    let good = "$GNGGA,133859.80,4134.50180205,N,09345.03586649,W,4,19,0.7,280.827,M,-31.442,M,5.8,0002*6D";
    assert!(parse(good.as_bytes()).is_ok());
    assert!(
        parse(good.replace("*6D", "*6d").as_bytes()).is_ok(),
        "lower-case hex"
    );
    assert_eq!(
        parse(good.replace("*6D", "*6E").as_bytes()),
        Err(NmeaError::Checksum {
            found: 0x6E,
            computed: 0x6D
        })
    );
    assert!(parse(good.replace("280.827", "280.828").as_bytes())
        .unwrap_err()
        .is_checksum());
    assert_eq!(
        parse(&good.as_bytes()[..good.len() - 3]),
        Err(NmeaError::NoChecksum)
    );
    assert_eq!(
        parse(good.replace("*6D", "*6").as_bytes()),
        Err(NmeaError::NoChecksum)
    );
    assert_eq!(parse(b"$GPGSV,1,1,00*79"), Err(NmeaError::Unsupported));
}

#[test]
fn malformed_fields_are_errors_naming_the_field() {
    let s = with_checksum(
        "GNGGA,133859.80,4134.50180205,X,09345.03586649,W,4,19,0.7,280.827,M,-31.442,M,5.8,0002",
    );
    assert_eq!(
        parse(s.as_bytes()),
        Err(NmeaError::Field {
            sentence: "GGA",
            field: 2
        })
    );
    let s = with_checksum(
        "GNGGA,133859.80,4134.50180205,N,09345.03586649,W,4,19,nan,280.827,M,-31.442,M,5.8,0002",
    );
    assert_eq!(
        parse(s.as_bytes()),
        Err(NmeaError::Field {
            sentence: "GGA",
            field: 8
        })
    );
    let s = with_checksum(
        "GNGGA,133859.80,4134.50180205,N,09345.03586649,W,,19,0.7,280.827,M,-31.442,M,5.8,0002",
    );
    assert_eq!(
        parse(s.as_bytes()),
        Err(NmeaError::Field {
            sentence: "GGA",
            field: 6
        })
    );
}

#[test]
fn stale_epochs_are_dropped() {
    let mut c = NmeaConverter::new(params());
    let mut n = 0;
    let gga = |k: u32| {
        with_checksum(&format!(
            "GNGGA,1000{:02}.{}0,4807.038,N,01131.000,E,4,12,0.6,500.0,M,47.0,M,1.0,0001",
            k / 10,
            k % 10
        ))
    };
    // 10 Hz, on time.
    for k in 0..30 {
        let s = parse(gga(k).as_bytes()).unwrap();
        c.convert(&s, &Receipt::at(f64::from(k) * 0.1 + 0.05), &mut |_| n += 1);
    }
    assert_eq!(n, 60);
    // Epoch 30 arrives 1 s late (a buffer flushed after a stall): nothing passed on.
    let s = parse(gga(30).as_bytes()).unwrap();
    c.convert(&s, &Receipt::at(3.0 + 1.05), &mut |_| n += 1);
    assert_eq!(n, 60);
    assert_eq!(c.counters.stale, 1);
    // A replay of an old epoch: dropped too.
    let s = parse(gga(12).as_bytes()).unwrap();
    c.convert(&s, &Receipt::at(4.1), &mut |_| n += 1);
    assert_eq!((n, c.counters.stale), (60, 2));
}

#[test]
fn latency_from_the_host_clock() {
    let mut c = NmeaConverter::new(params());
    let gga =
        with_checksum("GNGGA,235959.90,4807.038,N,01131.000,E,4,12,0.6,500.0,M,47.0,M,1.0,0001");
    let s = parse(gga.as_bytes()).unwrap();
    let mut out = Vec::new();
    let receipt = Receipt {
        t: 10.0,
        utc_s: Some(19_500.0 * 86_400.0 + 0.07),
    };
    c.convert(&s, &receipt, &mut |i| out.push(i));
    let p = out.iter().find_map(|i| {
        if let Input::Position(p) = i {
            Some(*p)
        } else {
            None
        }
    });
    assert!((p.unwrap().latency_s.unwrap() - 0.17).abs() < 1e-6, "{p:?}");
}

#[test]
fn no_byte_sequence_panics() {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(19);
    let seeds = [
        "GNGGA,133859.80,4134.50180205,N,09345.03586649,W,4,19,0.7,280.827,M,-31.442,M,5.8,0002",
        "PANDA,162255.50,3924.90,N,00731.80,W,4,12,0.7,341.9,1.2,4.8,2217,31,-12,0",
        "KSXT,20211016083433.00,116.31296102,39.95817066,49.4911,223.57,-11.32,330.19,0.024,,1,3,28,27,,,,-0.012,0.021,0.020,,",
        "GNRMC,003956.00,A,4552.65403,S,17030.00668,E,0.025,,120419,,,A,V",
        "GNGNS,100000.00,4807.038,N,01131.000,E,RRF,20,0.6,500.0,47.0,1.2,0007,V",
        "GPGST,112257.00,0.387,317.719,3.872,1.791,317.563,10.659,180.746",
        "GNVTG,,T,,M,0.025,N,0.045,K,A",
    ];
    let mut c = NmeaConverter::new(params());
    let mut decoded = 0;
    for k in 0..20_000 {
        let mut body = seeds[k % seeds.len()].as_bytes().to_vec();
        for _ in 0..rng.gen_range(1..4) {
            let at = rng.gen_range(0..body.len());
            match rng.gen_range(0..4) {
                0 => body[at] = rng.gen(),
                1 => body[at] = b"0123456789,.-+eENSWAV*$"[rng.gen_range(0..23)],
                2 => {
                    body.remove(at);
                }
                _ => body.insert(at, rng.gen()),
            }
        }
        // Recompute the checksum so that the field decoding is exercised, not just the sum.
        let sum = xor_checksum(&body);
        let mut line = b"$".to_vec();
        line.extend_from_slice(&body);
        line.extend_from_slice(format!("*{sum:02X}").as_bytes());
        if let Ok(s) = parse(&line) {
            decoded += 1;
            c.convert(&s, &Receipt::at(k as f64 * 0.01), &mut |i| {
                if let Input::Position(p) = i {
                    assert!(p.lat_deg.abs() <= 90.0 && p.lon_deg.abs() <= 180.0, "{p:?}");
                }
            });
        }
    }
    assert!(
        decoded > 1000,
        "the mutations still leave valid sentences: {decoded}"
    );
}
