//! The DBC-derived codec against vectors made by cantools (tools/cantools/make_vectors.py):
//! encode and decode agree bit for bit, for random in-range values, extremes and
//! not-available values; plus the codec's own error behaviour.

use agsteer::can::codec::{
    crc8_except, decode, encode, encode_values, find_name, CodecError, CounterCheck, Packer, Role,
    SteeringCommand, SteeringCommandMode, WheelAngle, WheelAngleStatus, MAX_SIGNALS, MESSAGES,
};
use serde_json::Value;

fn vectors() -> Vec<Value> {
    let text = include_str!("../tools/cantools/vectors.json");
    let v: Value = serde_json::from_str(text).expect("vectors.json parses");
    v["vectors"].as_array().expect("vectors").clone()
}

fn hex(s: &str) -> Vec<u8> {
    (0..s.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(&s[i..i + 2], 16).unwrap())
        .collect()
}

#[test]
fn encode_and_decode_agree_with_cantools_bit_for_bit() {
    let vs = vectors();
    assert!(vs.len() > 300);
    let mut seen = std::collections::HashSet::new();
    for v in &vs {
        let name = v["message"].as_str().unwrap();
        seen.insert(name.to_string());
        let (_, def) = find_name(name).unwrap();
        let id = u32::from_str_radix(v["id"].as_str().unwrap(), 16).unwrap();
        let data = hex(v["data"].as_str().unwrap());
        let counter = v["counter"].as_u64().unwrap() as u8;
        let mut values = [None; MAX_SIGNALS];
        for (i, s) in def.signals.iter().enumerate() {
            if s.role == Role::Value {
                values[i] = v["values"][s.name].as_f64();
            }
        }
        let frame = encode_values(def, &values, counter, (id & 0xFF) as u8)
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(frame.id, id, "{name}");
        assert_eq!(frame.payload(), &data[..], "{name} encode {v}");
        let d = decode(id, &data).unwrap_or_else(|e| panic!("{name}: {e}"));
        for (i, s) in def.signals.iter().enumerate() {
            match s.role {
                // The raw bits agree exactly (above); cantools computes raw·scale + offset in
                // another order, so the physical value may differ in the last binary digit.
                Role::Value => match (d.values[i], values[i]) {
                    (Some(a), Some(b)) => assert!(
                        (a - b).abs() <= 1e-12 * b.abs().max(1.0),
                        "{name}.{} decode {a} vs {b}",
                        s.name
                    ),
                    (a, b) => assert_eq!(a, b, "{name}.{} not-available", s.name),
                },
                Role::Counter => assert_eq!(d.counter, Some(counter)),
                Role::Crc => {}
            }
        }
    }
    assert_eq!(seen.len(), MESSAGES.len(), "every message has vectors");
}

#[test]
fn crc_is_sae_j1850() {
    // The catalogue check value of CRC-8/SAE-J1850 for "123456789".
    let mut data = b"123456789X".to_vec();
    assert_eq!(crc8_except(&data, 9), 0x4B);
    data[9] = 0;
    assert_eq!(crc8_except(&data, 9), 0x4B);
}

#[test]
fn packer_fills_counters_and_crcs_and_the_parser_checks_them() {
    let mut packer = Packer::new(0x2A);
    let mut check = CounterCheck::default();
    for k in 0..40u32 {
        let msg = SteeringCommand {
            angle: (k as f64) * 0.5 - 10.0,
            mode: SteeringCommandMode::Engaged,
        };
        let f = packer.pack(&msg).unwrap();
        assert_eq!(f.id & 0xFF, 0x2A);
        let d = decode(f.id, f.payload()).unwrap();
        assert_eq!(d.counter, Some((k % 16) as u8));
        assert!(check.check(&d), "counter continuity at {k}");
        assert_eq!(d.to::<SteeringCommand>(), Some(msg));
    }
    // A corrupted byte fails the CRC; a repeated frame fails the counter.
    let f = packer
        .pack(&SteeringCommand {
            angle: 1.0,
            mode: SteeringCommandMode::Engaged,
        })
        .unwrap();
    let mut bad = f.data;
    bad[1] ^= 0x10;
    assert!(matches!(
        decode(f.id, &bad[..8]),
        Err(CodecError::BadCrc { .. })
    ));
    let d = decode(f.id, f.payload()).unwrap();
    assert!(check.check(&d));
    assert!(!check.check(&d), "frozen counter is caught");
}

#[test]
fn out_of_range_missing_and_not_available() {
    assert!(matches!(
        encode(
            &WheelAngle {
                angle: Some(90.5),
                status: WheelAngleStatus::Ok
            },
            0,
            0x13
        ),
        Err(CodecError::OutOfRange { .. })
    ));
    assert!(matches!(
        encode(
            &SteeringCommand {
                angle: f64::NAN,
                mode: SteeringCommandMode::Disengaged
            },
            0,
            0x2A
        ),
        Err(CodecError::OutOfRange { .. })
    ));
    let f = encode(
        &WheelAngle {
            angle: None,
            status: WheelAngleStatus::Ok,
        },
        3,
        0x13,
    )
    .unwrap();
    let d = decode(f.id, f.payload()).unwrap();
    assert_eq!(d.to::<WheelAngle>().unwrap().angle, None);
    // Encoding rounds to the nearest raw value, ties to even (as cantools).
    let f = encode(
        &WheelAngle {
            angle: Some(0.005),
            status: WheelAngleStatus::Ok,
        },
        0,
        0x13,
    )
    .unwrap();
    assert_eq!(i16::from_le_bytes([f.data[0], f.data[1]]), 0);
    let f = encode(
        &WheelAngle {
            angle: Some(0.015),
            status: WheelAngleStatus::Ok,
        },
        0,
        0x13,
    )
    .unwrap();
    assert_eq!(i16::from_le_bytes([f.data[0], f.data[1]]), 2);
}

#[test]
fn any_source_address_matches_by_pgn() {
    let f = encode(
        &WheelAngle {
            angle: Some(1.0),
            status: WheelAngleStatus::Ok,
        },
        0,
        0x77,
    )
    .unwrap();
    assert_eq!(f.id & 0xFF, 0x77);
    let d = decode(f.id, f.payload()).unwrap();
    assert_eq!(d.source, 0x77);
    assert!(matches!(
        decode(0x0CFF9913, &[0; 8]),
        Err(CodecError::UnknownId(_))
    ));
}

#[test]
fn random_bytes_of_every_length_never_panic() {
    let mut x: u64 = 0x9E37_79B9_7F4A_7C15;
    let mut next = || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        x
    };
    for def in MESSAGES {
        for len in 0..=8usize {
            for _ in 0..2000 {
                let bytes = next().to_le_bytes();
                match decode(def.id, &bytes[..len]) {
                    Ok(d) => assert_eq!(len, def.size as usize, "{}", d.def.name),
                    Err(CodecError::WrongLength { .. }) => assert_ne!(len, def.size as usize),
                    Err(CodecError::BadCrc { .. }) => {}
                    Err(e) => panic!("{}: unexpected {e}", def.name),
                }
            }
        }
    }
}
