//! The DBC-derived codec against vectors made by cantools (tools/cantools/make_vectors.py):
//! encode and decode agree bit for bit, for random in-range values, extremes and
//! not-available values; plus the codec's own error behaviour.

use agsteer::can::codec::{
    crc8_except, decode, encode, encode_values, find_name, CodecError, CounterCheck, Packer, Role,
    SteeringCommand, SteeringCommandMode, WheelAngle, WheelAngleStatus, MAX_SIGNALS, MESSAGES,
};
use serde_json::Value;

fn vectors() -> Vec<Value> {
    let text = include_str!("../../tools/cantools/vectors.json");
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
        // Decode-only vectors hold a sentinel code other than the one the encoder sends.
        if v.get("decode_only").is_none() {
            let frame = encode_values(def, &values, counter, (id & 0xFF) as u8)
                .unwrap_or_else(|e| panic!("{name}: {e}"));
            assert_eq!(frame.id, id, "{name}");
            assert_eq!(frame.payload(), &data[..], "{name} encode {v}");
        }
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
            angle: Some((k as f64) * 0.5 - 10.0),
            mode: Some(SteeringCommandMode::Engaged),
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
            angle: Some(1.0),
            mode: Some(SteeringCommandMode::Engaged),
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
                status: Some(WheelAngleStatus::Ok)
            },
            0,
            0x13
        ),
        Err(CodecError::OutOfRange { .. })
    ));
    assert!(matches!(
        encode(
            &SteeringCommand {
                angle: Some(f64::NAN),
                mode: Some(SteeringCommandMode::Disengaged)
            },
            0,
            0x2A
        ),
        Err(CodecError::OutOfRange { .. })
    ));
    let f = encode(
        &WheelAngle {
            angle: None,
            status: Some(WheelAngleStatus::Ok),
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
            status: Some(WheelAngleStatus::Ok),
        },
        0,
        0x13,
    )
    .unwrap();
    assert_eq!(i16::from_le_bytes([f.data[0], f.data[1]]), 0);
    let f = encode(
        &WheelAngle {
            angle: Some(0.015),
            status: Some(WheelAngleStatus::Ok),
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
            status: Some(WheelAngleStatus::Ok),
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

/// The sentinel rule restated from its sources (see build.rs): the first raw code that means
/// "no value" for a field of `size` bits, before the DBC's declarations are applied.
fn convention_first(n2k: bool, size: u8, signed: bool) -> Option<u64> {
    let top = if signed {
        (1u64 << (size - 1)) - 1
    } else {
        (1u64 << size) - 1
    };
    let count = if n2k || signed {
        match size {
            8.. => 3,
            4..=7 => 2,
            2..=3 => 1,
            _ => 0,
        }
    } else {
        match size {
            8 | 16 | 32 => return Some(0xFB << (size - 8)),
            2.. => 2,
            _ => 0,
        }
    };
    (count > 0).then(|| top + 1 - count)
}

/// Every value signal of every message: the codes of its sentinel region decode as absent,
/// the code below as a number; `None` encodes as the not-available code; a signal without a
/// sentinel region is one whose DBC range or value table declares its top codes.
#[test]
fn every_signal_decodes_its_sentinel_codes_as_absent() {
    let mut checked = 0;
    for def in MESSAGES {
        let n2k = (def.id >> 24) & 1 == 1;
        let mut base = [None; MAX_SIGNALS];
        for (i, s) in def.signals.iter().enumerate() {
            base[i] = Some(s.min.max(0.0).min(s.max));
        }
        let frame = encode_values(def, &base, 0, 0x1C).unwrap_or_else(|e| panic!("{e}"));
        for (i, s) in def.signals.iter().enumerate() {
            if s.role != Role::Value {
                continue;
            }
            let top = if s.signed {
                (1u64 << (s.size - 1)) - 1
            } else {
                (1u64 << s.size) - 1
            };
            let declared = ((s.max - s.offset) / s.factor).round().max(0.0) as u64;
            let named = s.choices.iter().map(|(k, _)| *k as u64).max().unwrap_or(0);
            let expected = convention_first(n2k, s.size, s.signed)
                .map(|f| f.max(declared.max(named) + 1))
                .filter(|&f| f <= top);
            assert_eq!(s.na_from, expected, "{}.{}", def.name, s.name);
            let with_raw = |raw: u64| {
                let mut word = u64::from_le_bytes(frame.data);
                let m = (1u64 << s.size) - 1;
                word = (word & !(m << s.start_bit)) | ((raw & m) << s.start_bit);
                let mut data = word.to_le_bytes();
                if let Some(c) = def.signals.iter().find(|c| c.role == Role::Crc) {
                    let b = (c.start_bit / 8) as usize;
                    data[b] = crc8_except(&data[..def.size as usize], b);
                }
                decode(frame.id, &data[..def.size as usize])
                    .unwrap_or_else(|e| panic!("{}.{}: {e}", def.name, s.name))
                    .values[i]
            };
            match expected {
                Some(first) => {
                    for raw in [first, first + 1, (first + top) / 2, top] {
                        if raw <= top {
                            assert_eq!(with_raw(raw), None, "{}.{} raw {raw}", def.name, s.name);
                            checked += 1;
                        }
                    }
                    assert!(with_raw(first - 1).is_some(), "{}.{}", def.name, s.name);
                    let mut v = base;
                    v[i] = None;
                    let f = encode_values(def, &v, 0, 0x1C).unwrap();
                    let word = u64::from_le_bytes(f.data);
                    assert_eq!((word >> s.start_bit) & ((1u64 << s.size) - 1), top);
                }
                None => {
                    assert!(with_raw(top).is_some(), "{}.{}", def.name, s.name);
                    let mut v = base;
                    v[i] = None;
                    assert!(matches!(
                        encode_values(def, &v, 0, 0x1C),
                        Err(CodecError::Missing { .. })
                    ));
                }
            }
        }
    }
    assert!(checked > 100, "{checked}");
}
