//! `agsteer dbc decode|encode|table`: the DBC codec on candump logs and the command line.

use agsteer::can::codec::{self, find_name, CounterCheck, Role, MAX_SIGNALS};
use agsteer::can::fastpacket::Reassembler;
use agsteer::can::gnss::GnssPosition;
use agsteer::envelope;

/// Every field of a 129029 message; absent (not available) ones are null.
fn gnss_json(g: &GnssPosition) -> Value {
    let stations: Vec<Value> = g
        .stations
        .iter()
        .flatten()
        .map(|s| json!({"type": s.station_type, "id": s.id, "age_s": s.age_s}))
        .collect();
    json!({
        "sid": g.sid, "date_days": g.date_days, "time_s": g.time_s,
        "latitude_deg": g.latitude_deg, "longitude_deg": g.longitude_deg,
        "altitude_m": g.altitude_m, "gnss_type": g.gnss_type, "method": g.method,
        "integrity": g.integrity, "satellites": g.satellites, "hdop": g.hdop, "pdop": g.pdop,
        "geoidal_separation_m": g.geoidal_separation_m,
        "reference_stations": g.reference_stations, "stations": stations,
    })
}
use anyhow::{bail, Context, Result};
use clap::Subcommand;
use serde_json::{json, Map, Value};
use std::io::{BufRead, Write};
use std::path::PathBuf;

#[derive(Subcommand)]
pub enum DbcCommand {
    /// Decode candump log lines (`candump -L` or `iface ID#HEX`) to one JSON object per frame.
    Decode {
        /// Log file; standard input when absent.
        file: Option<PathBuf>,
    },
    /// Encode a frame: `agsteer dbc encode SteeringCommand Angle=1.5 Mode=1`; prints ID#HEX.
    Encode {
        /// Message name (case-insensitive).
        name: String,
        /// SIGNAL=VALUE in physical units; a not-available signal may be left out.
        signals: Vec<String>,
        /// J1939 source address (default: the DBC's).
        #[arg(long, value_parser = parse_u8)]
        source: Option<u8>,
    },
    /// Print the Markdown table of frames (dbc/FRAMES.md).
    Table,
}

fn parse_u8(s: &str) -> Result<u8, String> {
    let r = if let Some(h) = s.strip_prefix("0x") {
        u8::from_str_radix(h, 16)
    } else {
        s.parse()
    };
    r.map_err(|e| format!("{s}: {e}"))
}

pub fn run(cmd: DbcCommand) -> Result<u8> {
    match cmd {
        DbcCommand::Table => {
            print!("{}", codec::frames_markdown());
            Ok(0)
        }
        DbcCommand::Encode {
            name,
            signals,
            source,
        } => encode(&name, &signals, source),
        DbcCommand::Decode { file } => {
            let stdout = std::io::stdout();
            let mut out = stdout.lock();
            let mut dec = LogDecoder::default();
            match file {
                Some(p) => {
                    let f = envelope::open_stream(&p, envelope::FileKind::Log)?;
                    dec.run(std::io::BufReader::new(f), &mut out)
                        .with_context(|| format!("reading {}", p.display()))?;
                }
                None => dec.run(std::io::stdin().lock(), &mut out)?,
            }
            Ok(0)
        }
    }
}

fn encode(name: &str, signals: &[String], source: Option<u8>) -> Result<u8> {
    let Some((_, def)) = find_name(name) else {
        bail!("no message named {name}; see `agsteer dbc table`");
    };
    let mut values = [None; MAX_SIGNALS];
    let mut counter = 0u8;
    for kv in signals {
        let (k, v) = kv
            .split_once('=')
            .with_context(|| format!("`{kv}`: expected SIGNAL=VALUE"))?;
        let Some(i) = def
            .signals
            .iter()
            .position(|s| s.name.eq_ignore_ascii_case(k.trim()))
        else {
            let names: Vec<&str> = def.signals.iter().map(|s| s.name).collect();
            bail!(
                "{} has no signal {k}; it has {}",
                def.name,
                names.join(", ")
            );
        };
        let x: f64 = v
            .trim()
            .parse()
            .with_context(|| format!("`{kv}`: not a number"))?;
        match def.signals[i].role {
            Role::Counter => counter = x as u8,
            Role::Crc => {}
            Role::Value => values[i] = Some(x),
        }
    }
    let sa = source.unwrap_or((def.id & 0xFF) as u8);
    let frame = codec::encode_values(def, &values, counter, sa)?;
    println!("{}", frame.to_candump());
    Ok(0)
}

/// Decodes candump lines, keeping counters and fast-packet state across lines.
#[derive(Default)]
pub struct LogDecoder {
    counters: CounterCheck,
    fast: Reassembler,
}

impl LogDecoder {
    /// Decode one line into the JSON objects it produces (one per frame, plus a reassembled
    /// 129029 message when a fast-packet completes).
    pub fn line(&mut self, line: &str) -> Vec<Value> {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            return Vec::new();
        }
        let Some(lf) = agsteer::can::candump::parse_line(line) else {
            return vec![json!({"line": line, "error": "not a candump line"})];
        };
        let (t, id, bytes) = (lf.t, lf.frame.id, lf.frame.payload().to_vec());
        if !lf.extended {
            return vec![json!({"t": t, "id": format!("{id:03X}"), "error": "11-bit identifier"})];
        }
        let mut obj = Map::new();
        obj.insert("t".into(), t.map(Value::from).unwrap_or(Value::Null));
        obj.insert("id".into(), Value::from(format!("{id:08X}")));
        let mut extra = Vec::new();
        match codec::decode(id, &bytes) {
            // ISO 11783-5 network management is not in the DBC: named by can::isobus.
            Err(_) if agsteer::can::isobus::read(&lf.frame).is_some() => {
                if let Some(nf) = agsteer::can::isobus::read(&lf.frame) {
                    let (name, signals) = network_json(&nf);
                    obj.insert("name".into(), Value::from(name));
                    obj.insert("signals".into(), signals);
                }
            }
            Err(e) => {
                if let Some((_, def)) = codec::find(id) {
                    obj.insert("name".into(), Value::from(def.name));
                }
                obj.insert("error".into(), Value::from(e.to_string()));
            }
            Ok(d) => {
                obj.insert("name".into(), Value::from(d.def.name));
                let mut sig = Map::new();
                for (i, s) in d.def.signals.iter().enumerate() {
                    sig.insert(
                        s.name.into(),
                        d.values[i].map(Value::from).unwrap_or(Value::Null),
                    );
                }
                obj.insert("signals".into(), Value::Object(sig));
                if !self.counters.check(&d) {
                    obj.insert("error".into(), Value::from("bad counter"));
                }
                if d.def.name == "GnssPositionData" {
                    match self.fast.push(d.source, &bytes) {
                        Err(e) => {
                            obj.insert("error".into(), Value::from(e.to_string()));
                        }
                        Ok(Some(payload)) => extra.push(match GnssPosition::decode(payload) {
                            Ok(g) => json!({
                                "t": t, "id": format!("{id:08X}"), "name": "GnssPosition129029",
                                "signals": gnss_json(&g),
                            }),
                            Err(e) => json!({"t": t, "id": format!("{id:08X}"),
                                "name": "GnssPosition129029", "error": e.to_string()}),
                        }),
                        Ok(None) => {}
                    }
                }
            }
        }
        let mut v = vec![Value::Object(obj)];
        v.extend(extra);
        v
    }

    /// Decode every line of `input`. A line longer than [`envelope::MAX_LINE_BYTES`] is
    /// reported and skipped; a read error ends the run (it would repeat forever).
    pub fn run(&mut self, mut input: impl BufRead, out: &mut impl Write) -> Result<()> {
        let mut n = 0usize;
        while let Some(line) = envelope::file::next_line(&mut input, envelope::MAX_LINE_BYTES)
            .with_context(|| format!("after line {n}"))?
        {
            n += 1;
            match line {
                envelope::file::Line::Text(line) => {
                    for v in self.line(&line) {
                        writeln!(out, "{v}")?;
                    }
                }
                envelope::file::Line::TooLong(len) => writeln!(
                    out,
                    "{}",
                    json!({"line": n, "error": format!("line of {len} bytes, over the limit of {} bytes", envelope::MAX_LINE_BYTES)})
                )?,
            }
        }
        Ok(())
    }
}

/// An ISO 11783-5 Request (PGN 59904) or Address Claimed (60928; Cannot Claim from the null
/// address) as a name and its fields.
fn network_json(nf: &agsteer::can::isobus::NetworkFrame) -> (&'static str, Value) {
    use agsteer::can::isobus::{NetworkFrame, NULL_ADDRESS};
    match *nf {
        NetworkFrame::Request { pgn, dest, source } => (
            "Request",
            json!({"pgn": pgn, "destination": dest, "source": source}),
        ),
        NetworkFrame::AddressClaimed { name, source } => {
            let f = name.fields();
            (
                if source == NULL_ADDRESS {
                    "CannotClaimAddress"
                } else {
                    "AddressClaimed"
                },
                json!({
                    "source": source,
                    "name": format!("{:016X}", name.0),
                    "self_configurable": f.self_configurable,
                    "industry_group": f.industry_group,
                    "device_class_instance": f.device_class_instance,
                    "device_class": f.device_class,
                    "function": f.function,
                    "function_instance": f.function_instance,
                    "ecu_instance": f.ecu_instance,
                    "manufacturer_code": f.manufacturer_code,
                    "identity_number": f.identity_number,
                }),
            )
        }
    }
}
