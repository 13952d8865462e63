//! One entry point per decoder or parser that bytes from outside reach. Each takes arbitrary
//! bytes and must return without panicking, whatever they are; errors are fine. The cargo-fuzz
//! targets (`fuzz/fuzz_targets/`) call these, and `tests/binaries/bad_input.rs` replays the corpora
//! (`fuzz/corpus/<target>/`) and random bytes through them on stable Rust.
//!
//! `agsteer dbc decode` and `agsteer maneuver` parse in the binary; their modules are compiled
//! in here as they are in the binary.

use agsteer::config::Config;

#[allow(dead_code)]
#[path = "../../src/bin/agsteer/dbc_cmd.rs"]
mod dbc_cmd;
#[allow(dead_code)]
#[path = "../../src/bin/agsteer/maneuver_cmd.rs"]
mod maneuver_cmd;

/// A target: its name (the corpus directory) and its entry point.
pub type Target = (&'static str, fn(&[u8]));

/// Every target.
pub const TARGETS: [Target; 12] = [
    ("candump", candump),
    ("can_frame", can_frame),
    ("can_inputs", can_inputs),
    ("fast_packet", fast_packet),
    ("gnss_stream", gnss_stream),
    ("geojson", geojson),
    ("taskdata", taskdata),
    ("map", map),
    ("config", config),
    ("progress", progress),
    ("maneuver_jsonl", maneuver_jsonl),
    ("status_reply", status_reply),
];

/// candump log lines through `agsteer dbc decode`'s decoder (line parser, DBC codec, counter
/// check, fast-packet reassembly of 129029, GNSS payload decoding), as it reads a log.
pub fn candump(data: &[u8]) {
    let mut dec = dbc_cmd::LogDecoder::default();
    let mut out = Vec::new();
    let _ = dec.run(data, &mut out);
}

/// One CAN frame: 4 bytes of identifier, then up to 8 data bytes, through the DBC codec.
pub fn can_frame(data: &[u8]) {
    let Some((id, payload)) = data.split_first_chunk::<4>() else {
        return;
    };
    let id = u32::from_le_bytes(*id);
    let _ = agsteer::can::codec::decode(id, payload);
    let _ = agsteer::can::codec::decode(id & 0x1FFF_FFFF, &payload[..payload.len().min(8)]);
}

/// A sequence of CAN frames (4 bytes of identifier, a length byte, 8 data bytes each) through
/// the bus adapter that turns them into inputs (codec, counters, CRCs, fast packets).
pub fn can_inputs(data: &[u8]) {
    let mut adapter = agsteer::input::can::CanAdapter::default();
    for (k, rec) in data.chunks(13).enumerate() {
        let Some((id, rest)) = rec.split_first_chunk::<4>() else {
            return;
        };
        let (len, bytes) = rest.split_first().unwrap_or((&0, &[]));
        let bytes = &bytes[..bytes.len().min(*len as usize)];
        let tf = agsteer::can::TimedFrame {
            t: k as f64 * 0.01,
            frame: agsteer::can::Frame::new(u32::from_le_bytes(*id), bytes),
        };
        let _ = adapter.on_frame(&tf);
    }
}

/// A GNSS byte stream (NMEA 0183, UBX, RTCM 3 mixed) through the framer and the decoders: the
/// first byte picks the protocol (bit 0) and the chunk size the bytes arrive in.
pub fn gnss_stream(data: &[u8]) {
    use agsteer::input::nmea0183::{clock::Receipt, convert::StreamParams};
    use agsteer::io::decoder::{DecoderParams, GnssDecoder, Protocol};
    let Some((head, stream)) = data.split_first() else {
        return;
    };
    let protocol = if head & 1 == 0 {
        Protocol::Nmea0183
    } else {
        Protocol::Ubx
    };
    let mut d = GnssDecoder::new(DecoderParams {
        protocol,
        stream: StreamParams {
            source: agsteer::input::SourceId::Stream(0),
            baseline_angle: 0.0,
            max_delay_s: 0.5,
        },
        max_correction_age_s: 10.0,
    });
    let chunk = usize::from(head >> 1).max(1);
    for (k, c) in stream.chunks(chunk).enumerate() {
        d.push(c, &Receipt::at(k as f64 * 0.001), &mut |_| {}, &mut |_| {});
    }
    let _ = d.counters();
}

/// A sequence of fast-packet frames (source address, then 8 bytes each) through the
/// reassembler, each completed payload through the 129029 decoder.
pub fn fast_packet(data: &[u8]) {
    let mut r = agsteer::can::fastpacket::Reassembler::default();
    for chunk in data.chunks(9) {
        let (source, frame) = chunk.split_first().unwrap_or((&0, &[]));
        if let Ok(Some(payload)) = r.push(*source, frame) {
            let _ = agsteer::can::gnss::GnssPosition::decode(payload);
        }
    }
}

fn text(data: &[u8]) -> std::borrow::Cow<'_, str> {
    String::from_utf8_lossy(data)
}

/// A field file (GeoJSON, or anything not starting with '<') through the field loader.
pub fn geojson(data: &[u8]) {
    let _ = agsteer::field::load_field(&text(data), &agsteer::field::LoadOptions::default());
}

/// TASKDATA.XML through the field loader (the text is made to start with '<').
pub fn taskdata(data: &[u8]) {
    let t = text(data);
    let t = if t.trim_start().starts_with('<') {
        t.into_owned()
    } else {
        format!("<{t}")
    };
    let _ = agsteer::field::load_field(&t, &agsteer::field::LoadOptions::default());
}

/// A manoeuvre map (GeoJSON in local metres).
pub fn map(data: &[u8]) {
    let _ = agsteer::field::load_local_map(&text(data));
}

/// A configuration: parsed, overridden (the first line as a `--set`), validated, and when
/// valid turned into the parameter structs the layers below take.
pub fn config(data: &[u8]) {
    let t = text(data);
    let (first, rest) = t.split_once('\n').unwrap_or(("", &t));
    for overrides in [Vec::new(), vec![first.to_string()]] {
        let Ok(cfg) = Config::parse_with(rest, &overrides) else {
            continue;
        };
        if cfg.validate().is_empty() {
            let _ = cfg.safety_params();
            let _ = cfg.coverage_params();
            let _ = cfg.field_load_options();
            let _ = cfg.maneuver_params();
            let _ = cfg.to_toml();
        }
    }
}

/// A progress file.
pub fn progress(data: &[u8]) {
    let _ = agsteer::guidance::progress::Progress::decode(data);
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct Request {
    from: [f64; 3],
    to: [f64; 3],
}

/// `agsteer maneuver --batch` JSON lines and `--from`/`--to` poses: parsed and checked
/// against the envelope.
pub fn maneuver_jsonl(data: &[u8]) {
    for line in text(data).lines() {
        if let Ok(r) = serde_json::from_str::<Request>(line) {
            let _ = maneuver_cmd::check_request(r.from, r.to);
        }
        let _ = maneuver_cmd::parse_pose(line);
    }
}

/// The daemon's status reply as `agsteer status` reads it.
pub fn status_reply(data: &[u8]) {
    let _ = serde_json::from_slice::<serde_json::Value>(data);
}
