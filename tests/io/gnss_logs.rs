//! The GNSS parsers on real captured data (tools/gnss/logs: receivers' output recorded by the
//! gpsd project, BSD-2-Clause, see tools/gnss/README.md): every sentence and frame in them is
//! framed, its checksum holds, and every sentence agsteer uses decodes; values agree with
//! gpsd's own decoding of the same logs (the `.chk` files).

use agsteer::input::nmea0183::{self, NmeaError, Sentence};
use agsteer::input::ubx::{self, UbxMessage};
use agsteer::io::framer::{rtcm_message_type, Frame, Framer};
use std::collections::BTreeMap;
use std::path::PathBuf;

fn log(name: &str) -> Vec<u8> {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tools/gnss/logs")
        .join(name);
    std::fs::read(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// What a log holds, framed and decoded.
#[derive(Default, Debug)]
struct Census {
    nmea: BTreeMap<String, usize>,
    ubx: BTreeMap<(u8, u8), usize>,
    rtcm: BTreeMap<u16, usize>,
    sentences: Vec<Sentence>,
    messages: Vec<UbxMessage>,
}

fn census(name: &str) -> Census {
    let data = log(name);
    let mut c = Census::default();
    let mut framer = Framer::new();
    framer.push(&data, &mut |f| match f {
        Frame::Nmea(line) => {
            let text = String::from_utf8_lossy(line).to_string();
            match nmea0183::parse(line) {
                Ok(s) => {
                    *c.nmea.entry(s.name().to_string()).or_default() += 1;
                    c.sentences.push(s);
                }
                Err(NmeaError::Unsupported) => {
                    let kind = text.get(3..6).unwrap_or("?").to_string();
                    *c.nmea.entry(format!("unused {kind}")).or_default() += 1;
                }
                Err(e) => panic!("{name}: {text}: {e}"),
            }
        }
        Frame::Text(_) => {}
        Frame::Ubx { class, id, payload } => {
            *c.ubx.entry((class, id)).or_default() += 1;
            match ubx::decode(class, id, payload) {
                Ok(m) => c.messages.push(m),
                Err(ubx::UbxError::Unsupported) => {}
                Err(e) => panic!("{name}: {e}"),
            }
        }
        Frame::Rtcm(f) => *c.rtcm.entry(rtcm_message_type(f).unwrap_or(0)).or_default() += 1,
    });
    let k = framer.counters;
    assert_eq!(
        k.ubx_checksum_errors + k.rtcm_crc_errors,
        0,
        "{name}: {k:?}"
    );
    c
}

fn count(c: &Census, name: &str) -> usize {
    c.nmea.get(name).copied().unwrap_or(0)
}

#[test]
fn every_nmea_sentence_of_the_real_logs_decodes() {
    // (log, sentence, how many it holds)
    let expect = [
        ("nmea-rtk.log", "GGA", 122),
        ("nmea-rtk.log", "RMC", 122),
        ("polarx2.log", "GST", 5),
        ("polarx2.log", "GNS", 5),
        ("polarx2.log", "VTG", 5),
        ("hemi.log", "HDT", 215),
        ("hemi.log", "VTG", 215),
        ("skytraq-PX1172RH_DS.log", "HDT", 9),
        ("skytraq-PX1172RH_DS.log", "GGA", 9),
        ("ublox-zed-f9p-nmea.log", "GST", 29),
        ("ublox-zed-f9p-nmea.log", "RMC", 29),
        ("ublox-zed-f9t-ubx_nmea_l5.log", "GGA", 9),
    ];
    for (name, sentence, n) in expect {
        let c = census(name);
        assert_eq!(count(&c, sentence), n, "{name}: {:?}", c.nmea);
    }
}

#[test]
fn trimble_rtk_gga_agrees_with_gpsd() {
    let c = census("nmea-rtk.log");
    let chk = String::from_utf8(log("nmea-rtk.log.chk")).unwrap();
    // gpsd's TPV reports by time of day: "T13:28:19.600Z" → (lat, lon, dgpsAge).
    let mut gpsd = BTreeMap::new();
    for l in chk.lines().filter(|l| l.contains("\"class\":\"TPV\"")) {
        let field = |k: &str| -> Option<&str> {
            let at = l.find(&format!("\"{k}\":"))? + k.len() + 3;
            let rest = l.get(at..)?;
            Some(rest.get(..rest.find([',', '}'])?)?.trim_matches('"'))
        };
        if let (Some(time), Some(lat), Some(lon)) = (field("time"), field("lat"), field("lon")) {
            let tod = time.get(11..23).unwrap_or("").to_string();
            let age: Option<f64> = field("dgpsAge").and_then(|a| a.parse().ok());
            gpsd.insert(
                tod,
                (
                    lat.parse::<f64>().unwrap(),
                    lon.parse::<f64>().unwrap(),
                    age,
                ),
            );
        }
    }
    let mut compared = 0;
    let mut rtk_fixed = 0;
    for s in &c.sentences {
        let Sentence::Gga(g) = s else { continue };
        let ts = g.time_s.unwrap();
        let tod = format!(
            "{:02}:{:02}:{:06.3}",
            (ts / 3600.0) as u32,
            ((ts % 3600.0) / 60.0) as u32,
            ts % 60.0
        );
        rtk_fixed += usize::from(g.quality == 4);
        if let Some((lat, lon, age)) = gpsd.get(&tod) {
            assert!((g.lat_deg.unwrap() - lat).abs() < 2e-9, "{tod}");
            assert!((g.lon_deg.unwrap() - lon).abs() < 2e-9, "{tod}");
            assert_eq!(g.correction_age_s, *age, "{tod}");
            compared += 1;
        }
    }
    assert!(compared > 100, "{compared}");
    assert!(rtk_fixed > 10, "the log's RTK part: {rtk_fixed}");
}

#[test]
fn zed_f9p_high_precision_position_agrees_with_gpsd() {
    let c = census("ublox-zed-f9p-hp.log");
    assert_eq!(c.ubx.get(&(1, 0x07)), Some(&29));
    assert_eq!(c.ubx.get(&(1, 0x14)), Some(&29));
    let chk = String::from_utf8(log("ublox-zed-f9p-hp.log.chk")).unwrap();
    let mut utc_of_itow = BTreeMap::new();
    let mut compared = 0;
    for m in &c.messages {
        match m {
            UbxMessage::NavPvt(p) => {
                assert!(p.gnss_fix_ok && p.fix_type == 3, "{p:?}");
                utc_of_itow.insert(p.itow_ms, p.utc_s.unwrap());
            }
            UbxMessage::NavHpPosLlh(h) => {
                let utc = utc_of_itow[&h.itow_ms];
                let (y, mo, d) = ubx::encode::civil_from_days((utc / 86_400.0).floor() as i64);
                let tod = utc.rem_euclid(86_400.0);
                let time = format!(
                    "\"time\":\"{y:04}-{mo:02}-{d:02}T{:02}:{:02}:{:06.3}Z\"",
                    (tod / 3600.0) as u32,
                    ((tod % 3600.0) / 60.0) as u32,
                    tod % 60.0
                );
                let Some(tpv) = chk
                    .lines()
                    .find(|l| l.contains("\"class\":\"TPV\"") && l.contains(&time))
                else {
                    continue;
                };
                let num = |k: &str| -> f64 {
                    let at = tpv.find(&format!("\"{k}\":")).unwrap() + k.len() + 3;
                    let rest = &tpv[at..];
                    rest[..rest.find(',').unwrap()].parse().unwrap()
                };
                assert!((h.lat_deg - num("lat")).abs() < 1e-9, "{time}");
                assert!((h.lon_deg - num("lon")).abs() < 1e-9, "{time}");
                assert!((h.height_m - num("altHAE")).abs() < 1e-3, "{time}");
                compared += 1;
            }
            _ => {}
        }
    }
    assert_eq!(compared, 28);
}

#[test]
fn m8p_relposned_version_0_decodes() {
    let c = census("ublox-neo-m8p.log");
    let rel: Vec<_> = c
        .messages
        .iter()
        .filter_map(|m| {
            if let UbxMessage::NavRelPosNed(r) = m {
                Some(*r)
            } else {
                None
            }
        })
        .collect();
    assert_eq!(rel.len(), 59);
    assert!(rel.iter().all(|r| r.version == 0));
    // A rover a fixed distance from its base: the baseline length stays put.
    let len: Vec<f64> = rel
        .iter()
        .map(|r| (r.north_m.powi(2) + r.east_m.powi(2) + r.down_m.powi(2)).sqrt())
        .collect();
    let (lo, hi) = len
        .iter()
        .fold((f64::MAX, 0.0_f64), |(a, b), &l| (a.min(l), b.max(l)));
    assert!(hi - lo < 0.5 * hi.max(1.0), "{lo}..{hi}");
}

#[test]
fn real_rtcm_streams_frame_with_their_crc() {
    let c = census("rtcm3.2.log");
    let total: usize = c.rtcm.values().sum();
    assert!(total > 180, "{:?}", c.rtcm);
    for msm7 in [1077, 1087, 1097, 1107] {
        assert!(
            c.rtcm.get(&msm7).is_some_and(|&n| n > 20),
            "{msm7}: {:?}",
            c.rtcm
        );
    }
    let c = census("ublox-f9p-rtcm.log");
    assert_eq!(c.rtcm.values().sum::<usize>(), 15);
}
