//! Real NMEA 2000 buses (tools/n2k-logs, canboat's public candump samples): every frame
//! decodes without a panic, not-available codes come out absent (never as numbers out of
//! their physical range), and the controller node takes every frame.

use agsteer::can::candump::parse_line;
use agsteer::can::codec::{self, CodecError, Message};
use agsteer::can::fastpacket::Reassembler;
use agsteer::can::gnss::GnssPosition;
use agsteer::can::TimedFrame;
use agsteer::config::Config;
use agsteer::input::can::CanAdapter;
use agsteer::input::Input;
use std::f64::consts::{PI, TAU};

const LOGS: [&str; 3] = [
    "canboat-candumpSample1.txt",
    "canboat-candumpSample2.txt",
    "canboat-candumpSample3.txt",
];

fn frames(name: &str) -> Vec<TimedFrame> {
    let path = format!("{}/tools/n2k-logs/{name}", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(&path).unwrap();
    text.lines()
        .filter_map(parse_line)
        .filter(|l| l.extended)
        .enumerate()
        .map(|(k, l)| TimedFrame {
            // Two of the logs have no time stamps: 1 ms apart.
            t: l.t.unwrap_or(k as f64 * 1e-3),
            frame: l.frame,
        })
        .collect()
}

#[derive(Default, Debug)]
struct Counts {
    frames: usize,
    decoded: usize,
    absent: usize,
    gnss_messages: usize,
}

fn in_range(v: Option<f64>, lo: f64, hi: f64) -> bool {
    v.is_none_or(|x| x.is_finite() && (lo..=hi).contains(&x))
}

fn check_log(name: &str) -> Counts {
    let mut c = Counts::default();
    let mut fast = Reassembler::default();
    for tf in frames(name) {
        c.frames += 1;
        let d = match codec::decode(tf.frame.id, tf.frame.payload()) {
            Ok(d) => d,
            Err(CodecError::UnknownId(_)) => continue,
            Err(e) => panic!("{name}: {e}"),
        };
        c.decoded += 1;
        c.absent += d.values[..d.def.signals.len()]
            .iter()
            .filter(|v| v.is_none())
            .count();
        let ok = match d.message().unwrap() {
            Message::PositionRapid(m) => {
                in_range(m.latitude, -90.0, 90.0) && in_range(m.longitude, -180.0, 180.0)
            }
            Message::CogSogRapid(m) => in_range(m.cog, 0.0, TAU) && in_range(m.sog, 0.0, 655.32),
            Message::VesselHeading(m) => {
                in_range(m.heading, 0.0, TAU)
                    && in_range(m.variation, -PI - 1e-4, PI + 1e-4)
                    && in_range(m.deviation, -PI - 1e-4, PI + 1e-4)
            }
            Message::GnssPositionData(_) => {
                if let Ok(Some(p)) = fast.push(d.source, tf.frame.payload()) {
                    let g = GnssPosition::decode(p).unwrap();
                    c.gnss_messages += 1;
                    assert!(
                        in_range(g.latitude_deg, -90.0, 90.0)
                            && in_range(g.longitude_deg, -180.0, 180.0)
                            && g.satellites.is_none_or(|s| s <= 252)
                            && in_range(g.hdop, 0.0, 327.64)
                            && in_range(g.pdop, 0.0, 327.64)
                            && in_range(g.geoidal_separation_m, -21_474_836.0, 21_474_836.0)
                            && g.method.is_none_or(|m| m <= 13),
                        "{name}: {g:?}"
                    );
                }
                true
            }
            _ => true,
        };
        assert!(ok, "{name}: {} {:?}", tf.frame.to_candump(), d.values);
    }
    c
}

#[test]
fn every_frame_of_the_public_logs_decodes_and_sentinels_are_absent() {
    let mut total = Counts::default();
    for name in LOGS {
        let c = check_log(name);
        assert!(c.decoded > 50, "{name}: {c:?}");
        total.frames += c.frames;
        total.decoded += c.decoded;
        total.absent += c.absent;
        total.gnss_messages += c.gnss_messages;
    }
    assert!(total.frames > 8000, "{total:?}");
    assert!(total.gnss_messages > 50, "{total:?}");
    // The logs carry not-available codes (COG while stopped, deviation, SID...).
    assert!(total.absent > 500, "{total:?}");
}

#[test]
fn the_stopped_receivers_cog_is_absent_not_6_55_rad() {
    // candumpSample2: a B&G ZG100 sends 129026 with COG 0xFFFF at standstill.
    let f = frames("canboat-candumpSample2.txt")
        .into_iter()
        .find(|tf| tf.frame.id == 0x09F8027F)
        .unwrap();
    assert_eq!(f.frame.payload()[2..4], [0xFF, 0xFF]);
    let Some(Message::CogSogRapid(m)) = codec::decode(f.frame.id, f.frame.payload())
        .unwrap()
        .message()
    else {
        panic!()
    };
    assert_eq!(m.cog, None);
    assert_eq!(m.sog, Some(0.0));
}

#[test]
fn the_node_takes_every_frame_and_its_inputs_hold_no_absent_numbers() {
    let cfg = Config::default();
    for name in LOGS {
        let mut node = agsteer::job::node_for_config(&cfg, None).unwrap();
        let mut adapter = CanAdapter::default();
        let mut out = Vec::new();
        let mut last_tick = 0.0;
        for tf in frames(name) {
            for input in adapter.on_frame(&tf) {
                let finite = match input {
                    Input::Position(p) => p.lat_deg.abs() <= 90.0 && p.lon_deg.abs() <= 180.0,
                    Input::Heading(h) => h.heading.is_finite(),
                    Input::CourseSpeed(c) => {
                        in_range(c.course, -TAU, TAU) && in_range(c.speed_mps, 0.0, 655.32)
                    }
                    _ => true,
                };
                assert!(finite, "{name}: {input:?}");
            }
            node.on_frame(&tf);
            if tf.t - last_tick >= cfg.dt() {
                last_tick = tf.t;
                out.clear();
                let cmd = node.tick(tf.t, &mut out);
                assert!(!cmd.engaged, "no operator engaged");
            }
        }
    }
}
