//! Generates the CAN codec tables and typed messages from `dbc/agsteer.dbc` (the single source
//! of truth for every frame). Editing the DBC and rebuilding is the only way to change a frame.

use can_dbc::{AttributeValue, ByteOrder, Dbc, MessageId, ValueType};
use std::fmt::Write;

fn snake(name: &str) -> String {
    let mut out = String::new();
    for (i, c) in name.chars().enumerate() {
        if c.is_ascii_uppercase() {
            if i > 0 {
                out.push('_');
            }
            out.push(c.to_ascii_lowercase());
        } else {
            out.push(c);
        }
    }
    out
}

/// `operator_override` → `OperatorOverride`.
fn camel(name: &str) -> String {
    let mut out = String::new();
    let mut up = true;
    for c in name.chars() {
        if c == '_' || c == ' ' || c == '-' {
            up = true;
        } else if up {
            out.push(c.to_ascii_uppercase());
            up = false;
        } else {
            out.push(c);
        }
    }
    if out.starts_with(|c: char| c.is_ascii_digit()) {
        out.insert(0, 'V');
    }
    out
}

/// The smallest unsigned type holding `bits` bits.
fn uint_for(bits: u64) -> &'static str {
    match bits {
        0..=8 => "u8",
        9..=16 => "u16",
        17..=32 => "u32",
        _ => "u64",
    }
}

fn raw_max(size: u64) -> u64 {
    if size >= 64 {
        u64::MAX
    } else {
        (1u64 << size) - 1
    }
}

/// The first raw code, counting up to the top of a field of `size` bits, that is a sentinel
/// (not available, error / out of range, reserved) rather than a value; for a signed field, the
/// first such code among the positive values. `None` when every code is a value.
///
/// - NMEA 2000 (data page 1), as canboat reads it (analyzer/fieldtype.c `reservedCountForSize`,
///   after Cassidy, "NMEA 2000 Explained": a uint16's valid range is 0..65532): the top 3 codes
///   of a field of 8 bits or more (max = unknown / not available, max − 1 = out of range,
///   max − 2 = reserved), the top 2 of a 4–7-bit field, the top code of a 2–3-bit field, none of
///   a single bit. Signed fields count down from the largest positive value.
/// - J1939 / ISO 11783 (data page 0), SAE J1939-71 §5.1.4 (parameter ranges): an 8-, 16- or
///   32-bit unsigned parameter is valid up to 0xFA, 0xFAFF, 0xFAFFFFFF; above come the
///   parameter-specific indicator (0xFB..), the reserved range (0xFC..–0xFD..), error (0xFE..)
///   and not available (0xFF..). A field of another length: all ones = not available, all ones
///   − 1 = error (as the 2-bit discrete parameters: 10 error, 11 not available). Signed fields,
///   which J1939 does not define, follow canboat's convention above.
fn sentinel_from(n2k: bool, size: u64, signed: bool) -> Option<u64> {
    let bits = if signed { size - 1 } else { size };
    let top = raw_max(bits);
    let count = if n2k || signed {
        match size {
            8.. => 3,
            4..=7 => 2,
            2..=3 => 1,
            _ => 0,
        }
    } else {
        match size {
            8 | 16 | 32 => return Some(0xFBu64 << (size - 8)),
            2.. => 2,
            _ => 0,
        }
    };
    (count > 0).then(|| top - (count - 1))
}

fn attr_u64(v: &AttributeValue) -> u64 {
    match v {
        AttributeValue::Uint(u) => *u,
        AttributeValue::Int(i) => *i as u64,
        AttributeValue::Double(d) => *d as u64,
        AttributeValue::String(_) => 0,
    }
}

fn lit(x: f64) -> String {
    // Debug formatting of f64 round-trips exactly and always has a '.' or an exponent.
    format!("{x:?}_f64")
}

fn main() {
    let path = "dbc/agsteer.dbc";
    println!("cargo:rerun-if-changed={path}");
    let text = std::fs::read_to_string(path).expect("read dbc/agsteer.dbc");
    let dbc = Dbc::try_from(text.as_str()).unwrap_or_else(|e| panic!("{path}: {e:?}"));

    let sig_attr = |id: MessageId, sig: &str, name: &str| -> u64 {
        dbc.attribute_values_signal
            .iter()
            .find(|a| a.message_id == id && a.signal_name == sig && a.name == name)
            .map(|a| attr_u64(&a.value))
            .unwrap_or(0)
    };
    let msg_attr = |id: MessageId, name: &str| -> u64 {
        dbc.attribute_values_message
            .iter()
            .find(|a| a.message_id == id && a.name == name)
            .map(|a| attr_u64(&a.value))
            .unwrap_or(0)
    };

    let mut table = String::new();
    let mut types = String::new();
    let mut enums = String::new();
    writeln!(table, "/// Every message of the DBC, in file order.").unwrap();
    writeln!(table, "pub static MESSAGES: &[MessageDef] = &[").unwrap();
    for (index, m) in dbc.messages.iter().enumerate() {
        let MessageId::Extended(id) = m.id else {
            panic!("{}: agsteer frames are J1939 29-bit", m.name);
        };
        let pf = (id >> 16) & 0xFF;
        let pdu1 = pf < 0xF0;
        let pgn = if pdu1 {
            (id >> 8) & 0x3FF00
        } else {
            (id >> 8) & 0x3FFFF
        };
        let comment = dbc.message_comment(m.id).unwrap_or("").replace('"', "'");
        let transmitter = match &m.transmitter {
            can_dbc::Transmitter::NodeName(n) => n.clone(),
            _ => String::new(),
        };
        assert!(m.size <= 8, "{}: classic CAN frames only", m.name);
        writeln!(
            table,
            "    MessageDef {{ name: {:?}, id: 0x{id:08X}, pgn: {pgn}, pdu1: {pdu1}, size: {}, cycle_ms: {}, transmitter: {:?}, comment: {:?}, signals: &[",
            m.name,
            m.size,
            msg_attr(m.id, "GenMsgCycleTime"),
            transmitter,
            comment
        )
        .unwrap();
        let mut fields = String::new();
        let mut from_values = String::new();
        let mut to_values = String::new();
        for (si, s) in m.signals.iter().enumerate() {
            assert_eq!(
                s.byte_order,
                ByteOrder::LittleEndian,
                "{}.{}: little-endian only",
                m.name,
                s.name
            );
            assert!(s.size >= 1 && s.size <= 64 && s.start_bit + s.size <= 8 * m.size);
            let role = match sig_attr(m.id, &s.name, "AgRole") {
                1 => "Role::Counter",
                2 => "Role::Crc",
                _ => "Role::Value",
            };
            if role == "Role::Crc" {
                assert!(
                    s.size == 8 && s.start_bit % 8 == 0,
                    "{}.{}: CRC must be a whole byte",
                    m.name,
                    s.name
                );
            }
            let signed = s.value_type == ValueType::Signed;
            let descs: Vec<(i64, String)> = dbc
                .value_descriptions_for_signal(m.id, &s.name)
                .map(|v| v.iter().map(|d| (d.id, d.description.clone())).collect())
                .unwrap_or_default();
            // The first raw code that is a sentinel (see `sentinel_from`), unless the DBC's
            // range or value table declares it a value.
            let n2k = (id >> 24) & 1 == 1;
            let declared = {
                let max_raw = ((s.max - s.offset) / s.factor).round();
                let named = descs.iter().map(|(id, _)| *id).max().unwrap_or(0) as f64;
                max_raw.max(named).max(0.0) as u64
            };
            let top = if signed {
                (1u64 << (s.size - 1)) - 1
            } else {
                raw_max(s.size)
            };
            let na_from = if role == "Role::Value" {
                sentinel_from(n2k, s.size, signed)
                    .map(|f| f.max(declared.saturating_add(1)))
                    .filter(|&f| f <= top)
            } else {
                None
            };
            let na = na_from.is_some();
            let choices = descs
                .iter()
                .map(|(id, d)| format!("({id}, {d:?})"))
                .collect::<Vec<_>>()
                .join(", ");
            writeln!(
                table,
                "        SignalDef {{ name: {:?}, start_bit: {}, size: {}, signed: {signed}, factor: {}, offset: {}, min: {}, max: {}, unit: {:?}, role: {role}, na_from: {na_from:?}, choices: &[{choices}] }},",
                s.name,
                s.start_bit,
                s.size,
                lit(s.factor),
                lit(s.offset),
                lit(s.min),
                lit(s.max),
                s.unit,
            )
            .unwrap();
            if role == "Role::Value" {
                let field = snake(&s.name);
                // A signal with a value table is a generated enum (`{Message}{Signal}`), with
                // `Other(raw)` for raw values the table does not name.
                let enum_name = format!("{}{}", m.name, s.name);
                let is_enum = !descs.is_empty();
                if is_enum {
                    assert!(
                        s.factor == 1.0 && s.offset == 0.0 && !signed,
                        "{}.{}: a value table needs an unsigned raw signal (factor 1, offset 0)",
                        m.name,
                        s.name
                    );
                    write_enum(
                        &mut enums,
                        &enum_name,
                        m.name.as_str(),
                        &s.name,
                        s.size,
                        &descs,
                    );
                }
                let base = if is_enum { enum_name.as_str() } else { "f64" };
                let ty = if na {
                    format!("Option<{base}>")
                } else {
                    base.to_string()
                };
                writeln!(
                    fields,
                    "    /// `{}`: {} [{} ..= {}]{}{}.\n    pub {field}: {ty},",
                    s.name,
                    if s.unit.is_empty() { "raw" } else { &s.unit },
                    s.min,
                    s.max,
                    if na { ", None = not available" } else { "" },
                    if choices.is_empty() {
                        String::new()
                    } else {
                        format!("; values {choices}")
                    }
                )
                .unwrap();
                let raw = uint_for(s.size);
                match (is_enum, na) {
                    (false, true) => {
                        writeln!(from_values, "            {field}: v[{si}],").unwrap();
                        writeln!(to_values, "        v[{si}] = self.{field};").unwrap();
                    }
                    (false, false) => {
                        writeln!(from_values, "            {field}: v[{si}].unwrap_or(0.0),")
                            .unwrap();
                        writeln!(to_values, "        v[{si}] = Some(self.{field});").unwrap();
                    }
                    (true, true) => {
                        writeln!(
                            from_values,
                            "            {field}: v[{si}].map(|x| {enum_name}::from_raw(x as {raw})),"
                        )
                        .unwrap();
                        writeln!(
                            to_values,
                            "        v[{si}] = self.{field}.map(|e| e.raw() as f64);"
                        )
                        .unwrap();
                    }
                    (true, false) => {
                        writeln!(
                            from_values,
                            "            {field}: {enum_name}::from_raw(v[{si}].unwrap_or(0.0) as {raw}),"
                        )
                        .unwrap();
                        writeln!(
                            to_values,
                            "        v[{si}] = Some(self.{field}.raw() as f64);"
                        )
                        .unwrap();
                    }
                }
            }
        }
        writeln!(table, "    ] }},").unwrap();
        writeln!(
            types,
            "/// {comment}\n#[derive(Debug, Clone, Copy, PartialEq)]\npub struct {name} {{\n{fields}}}\n\nimpl DbcMessage for {name} {{\n    const INDEX: usize = {index};\n    fn from_values(v: &[Option<f64>]) -> Self {{\n        {name} {{\n{from_values}        }}\n    }}\n    fn to_values(&self, v: &mut [Option<f64>]) {{\n{to_values}    }}\n}}\n",
            name = m.name,
        )
        .unwrap();
    }
    writeln!(table, "];").unwrap();
    // The message enum: one variant per message, for dispatch with one `match`.
    let mut message = String::from(
        "/// Every message of the DBC as its typed value: the node dispatches on it.\n#[derive(Debug, Clone, Copy, PartialEq)]\npub enum Message {\n",
    );
    let mut message_of = String::from(
        "/// The typed message for message `index` of [`MESSAGES`] and its decoded values.\npub fn message_of(index: usize, v: &[Option<f64>]) -> Option<Message> {\n    Some(match index {\n",
    );
    for m in &dbc.messages {
        writeln!(message, "    {0}({0}),", m.name).unwrap();
        writeln!(
            message_of,
            "        {0}::INDEX => Message::{0}({0}::from_values(v)),",
            m.name
        )
        .unwrap();
    }
    message.push_str("}\n");
    message_of.push_str("        _ => return None,\n    })\n}\n");
    let out = std::path::Path::new(&std::env::var("OUT_DIR").expect("OUT_DIR")).join("dbc_gen.rs");
    std::fs::write(
        &out,
        format!(
            "// Generated by build.rs from {path}. Do not edit.\n\n{table}\n{enums}\n{types}\n{message}\n{message_of}"
        ),
    )
    .expect("write generated codec");
}

/// A value table as an enum: `from_raw` / `raw`, `Other(raw)` for unnamed raw values.
fn write_enum(
    out: &mut String,
    name: &str,
    message: &str,
    signal: &str,
    size: u64,
    descs: &[(i64, String)],
) {
    let raw = uint_for(size);
    let variants: Vec<(i64, String)> = descs.iter().map(|(id, d)| (*id, camel(d))).collect();
    for (i, (_, v)) in variants.iter().enumerate() {
        assert!(
            v != "Other" && !variants[..i].iter().any(|(_, w)| w == v),
            "{message}.{signal}: value name {v} is used twice or is reserved"
        );
    }
    writeln!(
        out,
        "/// `{message}.{signal}` (the DBC's value table).\n#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]\npub enum {name} {{"
    )
    .unwrap();
    for ((id, v), (_, d)) in variants.iter().zip(descs) {
        writeln!(out, "    /// {id}: `{d}`.\n    {v},").unwrap();
    }
    writeln!(
        out,
        "    /// A raw value the table does not name.\n    Other({raw}),\n}}\n\nimpl {name} {{\n    /// The value for a raw code.\n    pub fn from_raw(raw: {raw}) -> Self {{\n        match raw {{"
    )
    .unwrap();
    for (id, v) in &variants {
        writeln!(out, "            {id} => {name}::{v},").unwrap();
    }
    writeln!(
        out,
        "            other => {name}::Other(other),\n        }}\n    }}\n    /// The raw code.\n    pub fn raw(self) -> {raw} {{\n        match self {{"
    )
    .unwrap();
    for (id, v) in &variants {
        writeln!(out, "            {name}::{v} => {id},").unwrap();
    }
    writeln!(
        out,
        "            {name}::Other(raw) => raw,\n        }}\n    }}\n}}\n"
    )
    .unwrap();
}
