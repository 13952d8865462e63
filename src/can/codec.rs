//! The codec generated from `dbc/agsteer.dbc`.
//!
//! Decoding and encoding are in f64 (a 1e-7° latitude needs more than f32's 24 bits).
//! Encoding rounds to the nearest raw value, ties to even, as cantools does; out-of-range
//! values are errors; not-available raw values (all ones unsigned, 0x7FF… signed) decode to
//! `None`. Rolling counters and CRC-8 SAE J1850 bytes are filled in by the [`Packer`] and
//! checked by [`decode`] (CRC) and [`CounterCheck`] (counter continuity). Unused bits are sent
//! as 1. Matching is by PGN: the source address (and a PDU1 destination) may be anything.

use super::Frame;

/// What a signal is for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Role {
    Value,
    /// A rolling counter, +1 per frame.
    Counter,
    /// CRC-8 SAE J1850 over every other byte of the frame.
    Crc,
}

/// One signal of the DBC.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SignalDef {
    pub name: &'static str,
    pub start_bit: u16,
    pub size: u8,
    pub signed: bool,
    pub factor: f64,
    pub offset: f64,
    pub min: f64,
    pub max: f64,
    pub unit: &'static str,
    pub role: Role,
    pub not_available: bool,
    /// Named values (VAL_).
    pub choices: &'static [(i64, &'static str)],
}

/// One message of the DBC.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MessageDef {
    pub name: &'static str,
    /// Identifier with the DBC's default source address.
    pub id: u32,
    pub pgn: u32,
    /// PDU1 (destination-specific) PGN: byte 1 of the id is a destination address.
    pub pdu1: bool,
    pub size: u8,
    /// Nominal period, ms (0 = on event).
    pub cycle_ms: u32,
    pub transmitter: &'static str,
    pub comment: &'static str,
    pub signals: &'static [SignalDef],
}

/// Most signals in one message.
pub const MAX_SIGNALS: usize = 16;

/// A typed message generated from the DBC.
pub trait DbcMessage: Sized {
    /// Index in [`MESSAGES`].
    const INDEX: usize;
    fn from_values(v: &[Option<f64>]) -> Self;
    fn to_values(&self, v: &mut [Option<f64>]);
    fn def() -> &'static MessageDef {
        &MESSAGES[Self::INDEX]
    }
}

include!(concat!(env!("OUT_DIR"), "/dbc_gen.rs"));

/// Codec errors. None of them panics.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CodecError {
    #[error("unknown identifier {0:08X}")]
    UnknownId(u32),
    #[error("{message}: length {got}, expected {expected}")]
    WrongLength {
        message: &'static str,
        got: usize,
        expected: usize,
    },
    #[error("{message}: bad CRC {got:02X}, expected {expected:02X}")]
    BadCrc {
        message: &'static str,
        got: u8,
        expected: u8,
    },
    #[error("{message}.{signal} = {value}: out of range {min}..={max}")]
    OutOfRange {
        message: &'static str,
        signal: &'static str,
        value: f64,
        min: f64,
        max: f64,
    },
    #[error("{message}.{signal}: a value is required (the signal has no not-available value)")]
    Missing {
        message: &'static str,
        signal: &'static str,
    },
    #[error("no message named {0}")]
    UnknownName(String),
    #[error("{message} has no signal {signal}")]
    UnknownSignal {
        message: &'static str,
        signal: String,
    },
}

const CRC8: crc::Crc<u8> = crc::Crc::<u8>::new(&crc::CRC_8_SAE_J1850);

/// CRC-8 SAE J1850 over every byte of `data` except `skip`.
pub fn crc8_except(data: &[u8], skip: usize) -> u8 {
    let mut d = CRC8.digest();
    for (i, b) in data.iter().enumerate() {
        if i != skip {
            d.update(std::slice::from_ref(b));
        }
    }
    d.finalize()
}

/// The message definition for a received identifier (matched by PGN).
pub fn find(id: u32) -> Option<(usize, &'static MessageDef)> {
    MESSAGES.iter().enumerate().find(|(_, m)| {
        let mask = if m.pdu1 { 0x03FF_0000 } else { 0x03FF_FF00 };
        (id & mask) == (m.id & mask)
    })
}

/// The message definition by name.
pub fn find_name(name: &str) -> Option<(usize, &'static MessageDef)> {
    MESSAGES
        .iter()
        .enumerate()
        .find(|(_, m)| m.name.eq_ignore_ascii_case(name))
}

#[inline]
fn mask(size: u8) -> u64 {
    if size >= 64 {
        u64::MAX
    } else {
        (1u64 << size) - 1
    }
}

#[inline]
fn raw_of(word: u64, s: &SignalDef) -> u64 {
    (word >> s.start_bit) & mask(s.size)
}

/// A decoded frame: one value per signal of the message, in DBC order.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Decoded {
    pub index: usize,
    pub def: &'static MessageDef,
    pub values: [Option<f64>; MAX_SIGNALS],
    /// The rolling counter, if the message has one.
    pub counter: Option<u8>,
    pub source: u8,
}

impl Decoded {
    /// The typed message.
    pub fn to<M: DbcMessage>(&self) -> Option<M> {
        (self.index == M::INDEX).then(|| M::from_values(&self.values))
    }
}

/// Decode a frame: length and CRC checked; counters are the caller's ([`CounterCheck`]).
pub fn decode(id: u32, data: &[u8]) -> Result<Decoded, CodecError> {
    let (index, def) = find(id).ok_or(CodecError::UnknownId(id))?;
    decode_as(index, def, id, data)
}

fn decode_as(
    index: usize,
    def: &'static MessageDef,
    id: u32,
    data: &[u8],
) -> Result<Decoded, CodecError> {
    if data.len() != def.size as usize {
        return Err(CodecError::WrongLength {
            message: def.name,
            got: data.len(),
            expected: def.size as usize,
        });
    }
    let mut buf = [0u8; 8];
    buf[..data.len()].copy_from_slice(data);
    let word = u64::from_le_bytes(buf);
    let mut values = [None; MAX_SIGNALS];
    let mut counter = None;
    for (i, s) in def.signals.iter().enumerate() {
        let raw = raw_of(word, s);
        match s.role {
            Role::Crc => {
                let byte = (s.start_bit / 8) as usize;
                let expected = crc8_except(data, byte);
                if raw as u8 != expected {
                    return Err(CodecError::BadCrc {
                        message: def.name,
                        got: raw as u8,
                        expected,
                    });
                }
                values[i] = Some(raw as f64);
            }
            Role::Counter => {
                counter = Some(raw as u8);
                values[i] = Some(raw as f64);
            }
            Role::Value => {
                let m = mask(s.size);
                let v = if s.signed {
                    let sign = 1u64 << (s.size - 1);
                    if s.not_available && raw == sign - 1 {
                        None
                    } else {
                        let sv = if raw & sign != 0 {
                            (raw | !m) as i64
                        } else {
                            raw as i64
                        };
                        Some(sv as f64 * s.factor + s.offset)
                    }
                } else if s.not_available && raw == m {
                    None
                } else {
                    Some(raw as f64 * s.factor + s.offset)
                };
                values[i] = v;
            }
        }
    }
    Ok(Decoded {
        index,
        def,
        values,
        counter,
        source: (id & 0xFF) as u8,
    })
}

/// Encode values (one per signal, DBC order; counter and CRC entries are ignored).
pub fn encode_values(
    def: &'static MessageDef,
    values: &[Option<f64>],
    counter: u8,
    source: u8,
) -> Result<Frame, CodecError> {
    let size = def.size as usize;
    let mut word: u64 = if size >= 8 {
        u64::MAX
    } else {
        (1u64 << (8 * size)) - 1
    };
    let mut crc_byte = None;
    for (i, s) in def.signals.iter().enumerate() {
        let m = mask(s.size);
        let raw: u64 = match s.role {
            Role::Crc => {
                crc_byte = Some((s.start_bit / 8) as usize);
                0
            }
            Role::Counter => counter as u64 & m,
            Role::Value => match values.get(i).copied().flatten() {
                None if s.not_available => {
                    if s.signed {
                        (1u64 << (s.size - 1)) - 1
                    } else {
                        m
                    }
                }
                None => {
                    return Err(CodecError::Missing {
                        message: def.name,
                        signal: s.name,
                    })
                }
                Some(v) => {
                    if !(v.is_finite() && v >= s.min && v <= s.max) {
                        return Err(CodecError::OutOfRange {
                            message: def.name,
                            signal: s.name,
                            value: v,
                            min: s.min,
                            max: s.max,
                        });
                    }
                    let r = ((v - s.offset) / s.factor).round_ties_even();
                    (r as i64 as u64) & m
                }
            },
        };
        word = (word & !(m << s.start_bit)) | (raw << s.start_bit);
    }
    let mut data = [0u8; 8];
    data.copy_from_slice(&word.to_le_bytes());
    if let Some(b) = crc_byte {
        data[b] = crc8_except(&data[..size], b);
    }
    // A PDU1 destination stays as the DBC gives it (global 0xFF).
    let id = (def.id & !0xFF) | source as u32;
    Ok(Frame {
        id,
        len: def.size,
        data,
    })
}

/// Encode a typed message with a given counter.
pub fn encode<M: DbcMessage>(msg: &M, counter: u8, source: u8) -> Result<Frame, CodecError> {
    let mut v = [None; MAX_SIGNALS];
    msg.to_values(&mut v);
    encode_values(M::def(), &v, counter, source)
}

/// The packer: fills in rolling counters (per message) and CRCs.
#[derive(Debug, Clone)]
pub struct Packer {
    source: u8,
    counters: [u8; 64],
}

impl Packer {
    /// A packer sending from J1939 source address `source`.
    pub fn new(source: u8) -> Self {
        Packer {
            source,
            counters: [0; 64],
        }
    }
    pub fn source(&self) -> u8 {
        self.source
    }
    /// Pack the next frame of `msg`, advancing its counter.
    pub fn pack<M: DbcMessage>(&mut self, msg: &M) -> Result<Frame, CodecError> {
        let c = &mut self.counters[M::INDEX % 64];
        let f = encode(msg, *c, self.source)?;
        *c = (*c + 1) & 0x0F;
        Ok(f)
    }
}

/// Checks that each message's rolling counter advances by one per frame.
#[derive(Debug, Clone)]
pub struct CounterCheck {
    last: [Option<u8>; 64],
}

impl Default for CounterCheck {
    fn default() -> Self {
        CounterCheck { last: [None; 64] }
    }
}

impl CounterCheck {
    /// `true` when the counter follows the previous one (or is the first seen); messages
    /// without a counter always pass.
    pub fn check(&mut self, d: &Decoded) -> bool {
        let Some(c) = d.counter else {
            return true;
        };
        let slot = &mut self.last[d.index % 64];
        let ok = slot.is_none_or(|p| (p + 1) & 0x0F == c);
        *slot = Some(c);
        ok
    }
}

/// A Markdown table of every frame, generated from the DBC (committed as `dbc/FRAMES.md`).
pub fn frames_markdown() -> String {
    let mut s = String::from(
        "# agsteer CAN frames\n\nGenerated from `dbc/agsteer.dbc` by `agsteer dbc table`. J1939 29-bit identifiers with the DBC's default source address; frames are matched by PGN, so source addresses are configurable. Little-endian. Unused bits are 1.\n\n| frame | id | PGN | period | from | signals |\n|---|---|---|---|---|---|\n",
    );
    for m in MESSAGES {
        let sigs: Vec<String> = m
            .signals
            .iter()
            .map(|g| {
                let kind = match g.role {
                    Role::Counter => " (counter)".to_string(),
                    Role::Crc => " (CRC-8 J1850)".to_string(),
                    Role::Value => {
                        let unit = if g.unit.is_empty() {
                            String::new()
                        } else {
                            format!(" {}", g.unit)
                        };
                        let na = if g.not_available { ", n/a" } else { "" };
                        format!(
                            " {}{} ×{} [{}, {}]{unit}{na}",
                            if g.signed { "i" } else { "u" },
                            g.size,
                            g.factor,
                            g.min,
                            g.max
                        )
                    }
                };
                format!("`{}`{kind}", g.name)
            })
            .collect();
        let period = if m.cycle_ms == 0 {
            "event".to_string()
        } else {
            format!("{} ms", m.cycle_ms)
        };
        s.push_str(&format!(
            "| {} | `{:08X}` | {} (0x{:X}) | {} | {} | {} |\n",
            m.name,
            m.id,
            m.pgn,
            m.pgn,
            period,
            m.transmitter,
            sigs.join("; ")
        ));
    }
    s.push_str("\nNotes:\n\n");
    for m in MESSAGES {
        s.push_str(&format!("- **{}**: {}\n", m.name, m.comment));
    }
    s
}
