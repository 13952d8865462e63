//! ISO 11783-5 network management frames: the NAME, Request (PGN 59904) and Address Claimed
//! (PGN 60928), built and read by hand — they are protocol frames with a 64-bit identity
//! compared as a whole, not signals (the DBC's codec handles the application's frames).
//!
//! The NAME's bit layout is ISO 11783-5's (as AgIsoStack++'s `can_NAME.cpp` reads it):
//! identity number bits 0–20, manufacturer code 21–31, ECU instance 32–34, function instance
//! 35–39, function 40–47, reserved 48, device class 49–55, device class instance 56–59,
//! industry group 60–62, self-configurable address 63; sent least significant byte first.

use super::Frame;

/// PGN 59904 (0xEA00): Request.
pub const PGN_REQUEST: u32 = 0xEA00;
/// PGN 60928 (0xEE00): Address Claimed (and Cannot Claim from the null address).
pub const PGN_ADDRESS_CLAIMED: u32 = 0xEE00;
/// The null address: a device without one (Request for Address Claimed, Cannot Claim).
pub const NULL_ADDRESS: u8 = 254;
/// The global (broadcast) destination.
pub const GLOBAL_ADDRESS: u8 = 255;
/// Network management frames go at the default priority 6.
const PRIORITY: u32 = 6;

/// The parameter group number of a 29-bit identifier (a PDU1 PGN without its destination).
pub fn pgn_of(id: u32) -> u32 {
    let pf = (id >> 16) & 0xFF;
    let dp = (id >> 24) & 0x3;
    if pf < 0xF0 {
        (dp << 16) | (pf << 8)
    } else {
        (dp << 16) | ((id >> 8) & 0xFFFF)
    }
}

/// The destination of a PDU1 identifier (`None` for a PDU2, broadcast one).
pub fn destination_of(id: u32) -> Option<u8> {
    (((id >> 16) & 0xFF) < 0xF0).then_some(((id >> 8) & 0xFF) as u8)
}

/// `id` sent to `dest` (PDU1 identifiers only; a PDU2 identifier is returned unchanged).
pub fn with_destination(id: u32, dest: u8) -> u32 {
    if ((id >> 16) & 0xFF) < 0xF0 {
        (id & !0xFF00) | ((dest as u32) << 8)
    } else {
        id
    }
}

fn pdu1_id(pgn: u32, dest: u8, source: u8) -> u32 {
    (PRIORITY << 26) | ((pgn & 0x3FF00) << 8) | ((dest as u32) << 8) | source as u32
}

/// An ISO 11783-5 NAME: the 64-bit identity of a control function. A lower NAME has the
/// higher priority in address contention.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Name(pub u64);

/// The fields of a NAME.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct NameFields {
    /// The device can take another address from a range (bit 63).
    pub self_configurable: bool,
    /// 0 global, 1 on-highway, 2 agricultural and forestry, 3 construction, 4 marine, 5
    /// industrial (3 bits).
    pub industry_group: u8,
    /// 4 bits.
    pub device_class_instance: u8,
    /// 7 bits.
    pub device_class: u8,
    /// 8 bits; 0–127 mean the same in every industry group.
    pub function: u8,
    /// 5 bits.
    pub function_instance: u8,
    /// 3 bits.
    pub ecu_instance: u8,
    /// Assigned by SAE, 11 bits.
    pub manufacturer_code: u16,
    /// Unique among the manufacturer's devices of this kind, 21 bits.
    pub identity_number: u32,
}

impl NameFields {
    /// agsteer's default NAME: a self-configurable vehicle-navigation controller (function 23)
    /// of the agricultural industry group, manufacturer code 0 until the integrator sets the
    /// SAE-assigned one, identity number 1 (the `[isobus]` keys' defaults).
    pub const GUIDANCE_CONTROLLER: NameFields = NameFields {
        self_configurable: true,
        industry_group: 2,
        device_class_instance: 0,
        device_class: 0,
        function: 23,
        function_instance: 0,
        ecu_instance: 0,
        manufacturer_code: 0,
        identity_number: 1,
    };

    /// The largest value of each field (for range checks at the edges).
    pub const MAX_INDUSTRY_GROUP: u8 = 7;
    pub const MAX_DEVICE_CLASS_INSTANCE: u8 = 15;
    pub const MAX_DEVICE_CLASS: u8 = 127;
    pub const MAX_FUNCTION_INSTANCE: u8 = 31;
    pub const MAX_ECU_INSTANCE: u8 = 7;
    pub const MAX_MANUFACTURER_CODE: u16 = 2047;
    pub const MAX_IDENTITY_NUMBER: u32 = 0x1F_FFFF;
}

impl Name {
    /// The NAME of `f` (fields wider than their bits are masked).
    pub fn new(f: &NameFields) -> Name {
        Name(
            (f.self_configurable as u64) << 63
                | (f.industry_group as u64 & 0x7) << 60
                | (f.device_class_instance as u64 & 0xF) << 56
                | (f.device_class as u64 & 0x7F) << 49
                | (f.function as u64) << 40
                | (f.function_instance as u64 & 0x1F) << 35
                | (f.ecu_instance as u64 & 0x7) << 32
                | (f.manufacturer_code as u64 & 0x7FF) << 21
                | (f.identity_number as u64 & 0x1F_FFFF),
        )
    }
    pub fn fields(&self) -> NameFields {
        let n = self.0;
        NameFields {
            self_configurable: n >> 63 != 0,
            industry_group: ((n >> 60) & 0x7) as u8,
            device_class_instance: ((n >> 56) & 0xF) as u8,
            device_class: ((n >> 49) & 0x7F) as u8,
            function: ((n >> 40) & 0xFF) as u8,
            function_instance: ((n >> 35) & 0x1F) as u8,
            ecu_instance: ((n >> 32) & 0x7) as u8,
            manufacturer_code: ((n >> 21) & 0x7FF) as u16,
            identity_number: (n & 0x1F_FFFF) as u32,
        }
    }
    pub fn function(&self) -> u8 {
        ((self.0 >> 40) & 0xFF) as u8
    }
    pub fn self_configurable(&self) -> bool {
        self.0 >> 63 != 0
    }
}

/// The Address Claimed frame of `name` from `source` (Cannot Claim when `source` is the null
/// address), to the global address.
pub fn address_claimed(name: Name, source: u8) -> Frame {
    Frame::new(
        pdu1_id(PGN_ADDRESS_CLAIMED, GLOBAL_ADDRESS, source),
        &name.0.to_le_bytes(),
    )
}

/// A Request for `pgn` from `source` to `dest`.
pub fn request(pgn: u32, source: u8, dest: u8) -> Frame {
    let b = pgn.to_le_bytes();
    Frame::new(pdu1_id(PGN_REQUEST, dest, source), &b[..3])
}

/// A network management frame, read.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NetworkFrame {
    /// A Request for `pgn` sent to `dest`.
    Request { pgn: u32, dest: u8, source: u8 },
    /// `name` claims `source` (or cannot claim any: `source` = the null address).
    AddressClaimed { name: Name, source: u8 },
}

/// The network management content of `f`, if it is a Request or an Address Claimed (a frame
/// of another PGN or of a wrong length is `None`).
pub fn read(f: &Frame) -> Option<NetworkFrame> {
    let pgn = pgn_of(f.id);
    let p = f.payload();
    match pgn {
        PGN_REQUEST => {
            let b: [u8; 3] = p.try_into().ok()?;
            Some(NetworkFrame::Request {
                pgn: u32::from_le_bytes([b[0], b[1], b[2], 0]),
                dest: destination_of(f.id)?,
                source: f.source(),
            })
        }
        PGN_ADDRESS_CLAIMED => {
            let b: [u8; 8] = p.try_into().ok()?;
            Some(NetworkFrame::AddressClaimed {
                name: Name(u64::from_le_bytes(b)),
                source: f.source(),
            })
        }
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn name_fields_round_trip_and_sit_where_iso_11783_5_puts_them() {
        let f = NameFields {
            self_configurable: true,
            industry_group: 2,
            device_class_instance: 3,
            device_class: 4,
            function: 23,
            function_instance: 5,
            ecu_instance: 6,
            manufacturer_code: 1407,
            identity_number: 0x12345,
        };
        let n = Name::new(&f);
        assert_eq!(n.fields(), f);
        assert_eq!(n.function(), 23);
        assert!(n.self_configurable());
        // Hand-assembled from the bit positions.
        let expect: u64 = (1 << 63)
            | (2 << 60)
            | (3 << 56)
            | (4 << 49)
            | (23 << 40)
            | (5 << 35)
            | (6 << 32)
            | (1407 << 21)
            | 0x12345;
        assert_eq!(n.0, expect);
        // Every field at its maximum fills the 63 bits but the reserved bit 48.
        let all = Name::new(&NameFields {
            self_configurable: true,
            industry_group: 7,
            device_class_instance: 15,
            device_class: 127,
            function: 255,
            function_instance: 31,
            ecu_instance: 7,
            manufacturer_code: 2047,
            identity_number: 0x1F_FFFF,
        });
        assert_eq!(all.0, !(1 << 48));
    }

    #[test]
    fn address_claimed_and_request_frames() {
        let n = Name(0x8123_4567_89AB_CDEF);
        let f = address_claimed(n, 0x2A);
        assert_eq!(f.id, 0x18EE_FF2A);
        assert_eq!(
            f.payload(),
            &[0xEF, 0xCD, 0xAB, 0x89, 0x67, 0x45, 0x23, 0x81]
        );
        assert_eq!(
            read(&f),
            Some(NetworkFrame::AddressClaimed {
                name: n,
                source: 0x2A
            })
        );
        assert_eq!(address_claimed(n, NULL_ADDRESS).id, 0x18EE_FFFE);
        let r = request(PGN_ADDRESS_CLAIMED, NULL_ADDRESS, GLOBAL_ADDRESS);
        assert_eq!(r.id, 0x18EA_FFFE);
        assert_eq!(r.payload(), &[0x00, 0xEE, 0x00]);
        assert_eq!(
            read(&r),
            Some(NetworkFrame::Request {
                pgn: PGN_ADDRESS_CLAIMED,
                dest: GLOBAL_ADDRESS,
                source: NULL_ADDRESS
            })
        );
        // Wrong lengths are not read.
        assert_eq!(read(&Frame::new(0x18EA_FFFE, &[0, 0xEE])), None);
        assert_eq!(read(&Frame::new(0x18EE_FF2A, &[0; 7])), None);
        // Another PGN.
        assert_eq!(read(&Frame::new(0x0CAD_FF2A, &[0; 8])), None);
    }

    #[test]
    fn pgn_and_destination_of_pdu1_and_pdu2_identifiers() {
        assert_eq!(pgn_of(0x0CAD_1C2A), 0xAD00);
        assert_eq!(destination_of(0x0CAD_1C2A), Some(0x1C));
        assert_eq!(pgn_of(0x09F8_011C), 0x1F801);
        assert_eq!(destination_of(0x09F8_011C), None);
        assert_eq!(with_destination(0x0CAD_FF2A, 0x1C), 0x0CAD_1C2A);
        assert_eq!(with_destination(0x18FF_212A, 0x1C), 0x18FF_212A);
    }
}
