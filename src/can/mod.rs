//! The bus side: the DBC-derived codec, NMEA 2000 fast-packet, and the bus implementations.
//!
//! Every frame agsteer reads or writes is defined once, in `dbc/agsteer.dbc`; `build.rs`
//! generates the codec tables and typed messages from it.

pub mod address_claim;
pub mod bus;
pub mod candump;
pub mod codec;
pub mod fastpacket;
pub mod gnss;
pub mod isobus;

/// One classic CAN frame with a 29-bit extended identifier.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Frame {
    /// 29-bit identifier (no flag bits).
    pub id: u32,
    /// Data length, 0..=8.
    pub len: u8,
    pub data: [u8; 8],
}

impl Frame {
    pub fn new(id: u32, bytes: &[u8]) -> Frame {
        let mut data = [0u8; 8];
        let len = bytes.len().min(8);
        data[..len].copy_from_slice(&bytes[..len]);
        Frame {
            id: id & 0x1FFF_FFFF,
            len: len as u8,
            data,
        }
    }
    /// The payload.
    pub fn payload(&self) -> &[u8] {
        &self.data[..(self.len as usize).min(8)]
    }
    /// J1939 source address.
    pub fn source(&self) -> u8 {
        (self.id & 0xFF) as u8
    }
    /// `ID#HEX`, as cansend takes it.
    pub fn to_candump(&self) -> String {
        let mut s = format!("{:08X}#", self.id);
        for b in self.payload() {
            s.push_str(&format!("{b:02X}"));
        }
        s
    }
}

/// A frame with its receive time (s, monotonic clock of the receiver).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TimedFrame {
    pub t: f64,
    pub frame: Frame,
}
