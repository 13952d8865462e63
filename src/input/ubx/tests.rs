use super::convert::{pvt_quality, UbxConverter};
use super::*;
use crate::input::nmea0183::clock::Receipt;
use crate::input::nmea0183::convert::StreamParams;
use crate::input::{FixQuality, Input, SourceId};
use std::f64::consts::FRAC_PI_2;

pub(crate) fn pvt(itow_ms: u32) -> NavPvt {
    NavPvt {
        itow_ms,
        utc_s: Some(1_700_000_000.0 + f64::from(itow_ms % 1000) * 1e-3),
        fix_type: 3,
        gnss_fix_ok: true,
        diff_soln: true,
        carr_soln: 2,
        satellites: 24,
        lat_deg: 52.123_456_7,
        lon_deg: -1.234_567_8,
        height_m: 101.25,
        h_acc_m: 0.014,
        ground_speed_mps: 2.5,
        head_motion_deg: 90.0,
        pdop: 1.2,
        invalid_llh: false,
        correction_age_s: Some(2.0),
        head_vehicle_deg: None,
    }
}

fn params() -> StreamParams {
    StreamParams {
        source: SourceId::Stream(1),
        baseline_angle: 0.0,
        max_delay_s: 0.5,
    }
}

#[test]
fn fletcher_of_a_known_frame() {
    // UBX-ACK-ACK for CFG-PRT as u-blox's manual lists it: B5 62 05 01 02 00 06 00 0E 37.
    assert_eq!(
        fletcher8(&[0x05, 0x01, 0x02, 0x00, 0x06, 0x00]),
        (0x0E, 0x37)
    );
    assert_eq!(
        frame(0x05, 0x01, &[0x06, 0x00]),
        vec![0xB5, 0x62, 0x05, 0x01, 0x02, 0x00, 0x06, 0x00, 0x0E, 0x37]
    );
}

#[test]
fn nav_pvt_round_trip() {
    let p = pvt(345_600_200);
    let d = decode(CLASS_NAV, ID_NAV_PVT, &encode::nav_pvt(&p)).unwrap();
    let UbxMessage::NavPvt(d) = d else { panic!() };
    assert_eq!(d.itow_ms, p.itow_ms);
    assert!((d.utc_s.unwrap() - p.utc_s.unwrap()).abs() < 1e-6);
    assert!((d.lat_deg - p.lat_deg).abs() < 1e-9 && (d.lon_deg - p.lon_deg).abs() < 1e-9);
    assert_eq!(
        (d.carr_soln, d.satellites, d.correction_age_s),
        (2, 24, Some(2.0))
    );
    assert_eq!(pvt_quality(&d), FixQuality::RtkFixed);
    let float = NavPvt { carr_soln: 1, ..p };
    assert_eq!(pvt_quality(&float), FixQuality::RtkFloat);
    let no_fix = NavPvt {
        gnss_fix_ok: false,
        ..p
    };
    assert_eq!(pvt_quality(&no_fix), FixQuality::None);
    let time_only = NavPvt { fix_type: 5, ..p };
    assert_eq!(pvt_quality(&time_only), FixQuality::None);
}

#[test]
fn correction_age_classes() {
    for (age, class_bound) in [(0.5, 1.0), (3.0, 5.0), (44.0, 45.0), (500.0, 120.0)] {
        let p = NavPvt {
            correction_age_s: Some(age),
            ..pvt(0)
        };
        let UbxMessage::NavPvt(d) = decode(CLASS_NAV, ID_NAV_PVT, &encode::nav_pvt(&p)).unwrap()
        else {
            panic!()
        };
        assert_eq!(d.correction_age_s, Some(class_bound), "{age}");
    }
}

#[test]
fn short_payloads_and_unknown_versions_are_errors() {
    assert!(matches!(
        decode(CLASS_NAV, ID_NAV_PVT, &[0; 40]),
        Err(UbxError::Short {
            len: 40,
            min: 84,
            ..
        })
    ));
    assert!(matches!(
        decode(CLASS_NAV, ID_NAV_HPPOSLLH, &[0; 35]),
        Err(UbxError::Short { .. })
    ));
    let mut r = [0u8; 64];
    r[0] = 1;
    assert!(matches!(
        decode(CLASS_NAV, ID_NAV_RELPOSNED, &r[..40]),
        Err(UbxError::Short { min: 64, .. })
    ));
    r[0] = 7;
    assert!(matches!(
        decode(CLASS_NAV, ID_NAV_RELPOSNED, &r),
        Err(UbxError::Version { version: 7, .. })
    ));
    assert_eq!(decode(0x0A, 0x04, &[]), Err(UbxError::Unsupported));
    for n in 0..100 {
        let _ = decode(CLASS_NAV, ID_NAV_PVT, &vec![0xFF; n]);
        let _ = decode(CLASS_NAV, ID_NAV_RELPOSNED, &vec![0x01; n]);
        let _ = decode(CLASS_NAV, ID_NAV_HPPOSLLH, &vec![0x80; n]);
    }
}

#[test]
fn hpposllh_round_trip_to_a_tenth_of_a_millimetre() {
    let h = NavHpPosLlh {
        itow_ms: 7,
        invalid_llh: false,
        lat_deg: -45.877_525_179_3,
        lon_deg: 170.500_132_760_8,
        height_m: 29.3381,
        h_acc_m: 0.0141,
    };
    let UbxMessage::NavHpPosLlh(d) =
        decode(CLASS_NAV, ID_NAV_HPPOSLLH, &encode::nav_hpposllh(&h)).unwrap()
    else {
        panic!()
    };
    assert!((d.lat_deg - h.lat_deg).abs() < 1e-9 && (d.lon_deg - h.lon_deg).abs() < 1e-9);
    assert!((d.height_m - h.height_m).abs() < 1e-4);
    assert!((d.h_acc_m - h.h_acc_m).abs() < 1e-6);
}

#[test]
fn relposned_v1_heading() {
    let r = NavRelPosNed {
        version: 1,
        itow_ms: 1000,
        north_m: 0.0,
        east_m: 1.2,
        down_m: 0.01,
        heading_deg: Some(90.0),
        gnss_fix_ok: true,
        rel_pos_valid: true,
        carr_soln: 2,
    };
    let UbxMessage::NavRelPosNed(d) =
        decode(CLASS_NAV, ID_NAV_RELPOSNED, &encode::nav_relposned(&r)).unwrap()
    else {
        panic!()
    };
    assert_eq!(d, r);
    // The antennas across the vehicle, rover on the right: heading 90° means facing North.
    let mut c = UbxConverter::new(StreamParams {
        baseline_angle: -FRAC_PI_2,
        ..params()
    });
    let mut out = Vec::new();
    c.convert(&UbxMessage::NavRelPosNed(d), &Receipt::at(0.0), &mut |i| {
        out.push(i)
    });
    let [Input::Heading(h)] = out.as_slice() else {
        panic!("{out:?}")
    };
    assert!((h.heading - FRAC_PI_2).abs() < 1e-9);
    // Float: no heading.
    let mut out = Vec::new();
    let float = NavRelPosNed {
        carr_soln: 1,
        itow_ms: 1200,
        ..d
    };
    c.convert(
        &UbxMessage::NavRelPosNed(float),
        &Receipt::at(0.2),
        &mut |i| out.push(i),
    );
    assert!(out.is_empty());
}

#[test]
fn pvt_then_hpposllh_give_one_precise_position() {
    let mut c = UbxConverter::new(params());
    let mut out = Vec::new();
    for k in 0..3u32 {
        let itow = 100_000 + k * 100;
        let t = f64::from(k) * 0.1 + 0.03;
        let p = pvt(itow);
        c.convert(&UbxMessage::NavPvt(p), &Receipt::at(t), &mut |i| {
            out.push(i)
        });
        let h = NavHpPosLlh {
            itow_ms: itow,
            invalid_llh: false,
            lat_deg: p.lat_deg + 3e-9,
            lon_deg: p.lon_deg,
            height_m: p.height_m,
            h_acc_m: p.h_acc_m,
        };
        c.convert(
            &UbxMessage::NavHpPosLlh(h),
            &Receipt::at(t + 0.001),
            &mut |i| out.push(i),
        );
    }
    let positions: Vec<_> = out
        .iter()
        .filter_map(|i| {
            if let Input::Position(p) = i {
                Some(*p)
            } else {
                None
            }
        })
        .collect();
    // Epoch 0: NAV-PVT's (no HPPOSLLH seen yet); epochs 1 and 2: HPPOSLLH's only.
    assert_eq!(positions.len(), 3, "{positions:?}");
    assert!((positions[1].lat_deg - (pvt(0).lat_deg + 3e-9)).abs() < 1e-12);
    assert_eq!(positions[1].quality, Some(FixQuality::RtkFixed));
    let cs = out.iter().find_map(|i| {
        if let Input::CourseSpeed(c) = i {
            Some(*c)
        } else {
            None
        }
    });
    let cs = cs.unwrap();
    assert!(
        cs.course.unwrap().abs() < 1e-9,
        "heading of motion 90° = East = yaw 0"
    );
    assert_eq!(cs.speed_mps, Some(2.5));
}

#[test]
fn pvt_latency_from_utc_and_stale_epochs() {
    let mut c = UbxConverter::new(params());
    let mut out = Vec::new();
    let p = pvt(200);
    let receipt = Receipt {
        t: 1.0,
        utc_s: Some(p.utc_s.unwrap() + 0.045),
    };
    c.convert(&UbxMessage::NavPvt(p), &receipt, &mut |i| out.push(i));
    let pos = out.iter().find_map(|i| {
        if let Input::Position(p) = i {
            Some(*p)
        } else {
            None
        }
    });
    assert!((pos.unwrap().latency_s.unwrap() - 0.045).abs() < 1e-6);
    // The next epoch 0.9 s late: dropped.
    out.clear();
    c.convert(
        &UbxMessage::NavPvt(pvt(300)),
        &Receipt::at(1.0 + 0.1 + 0.9),
        &mut |i| out.push(i),
    );
    assert!(out.is_empty(), "{out:?}");
    assert_eq!(c.counters.stale, 1);
}
