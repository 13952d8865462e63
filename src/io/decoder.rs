//! One GNSS byte stream → [`Input`]s: the [`Framer`], the NMEA 0183 and UBX parsers and their
//! converters, the correction-age cap and the stream's counters. Pure (no I/O, no clock: the
//! transport stamps each chunk with its [`Receipt`]); no allocation per chunk or frame.
//!
//! **Correction age.** When the receiver's own age of corrections (GGA/GNS/PANDA/PAOGI/KSXT
//! age, NAV-PVT `lastCorrectionAge`) or the NTRIP client's (time since the caster last sent
//! RTCM, [`GnssDecoder::set_link_correction_age`]) exceeds `max_correction_age_s`, an RTK
//! fixed solution is passed on as RTK float: the corrections are too old for a fixed
//! solution to be trusted at centimetre level, and the controller's RTK-float handling takes
//! over.

use super::framer::{Frame, Framer, FramerCounters};
use crate::input::nmea0183::clock::Receipt;
use crate::input::nmea0183::convert::{ConvertCounters, NmeaConverter, StreamParams};
use crate::input::nmea0183::{self, NmeaError};
use crate::input::ubx::{self, convert::UbxConverter, UbxError};
use crate::input::{FixQuality, Input};

/// Which protocol a stream's fixes are taken from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Protocol {
    /// NMEA 0183 sentences (UBX frames on the same stream are counted and ignored).
    Nmea0183,
    /// UBX messages (NMEA sentences on the same stream are counted and ignored).
    Ubx,
}

/// Parameters of one stream's decoder.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DecoderParams {
    pub protocol: Protocol,
    pub stream: StreamParams,
    /// Corrections older than this turn an RTK fixed solution into RTK float, s.
    pub max_correction_age_s: f64,
}

/// Everything counted on one stream (for `agsteer status`).
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize)]
pub struct StreamCounters {
    #[serde(flatten)]
    pub framer: FramerCounters,
    /// Sentences and UBX messages decoded into inputs.
    pub decoded: u64,
    /// NMEA sentences with a wrong or missing checksum.
    pub nmea_checksum_errors: u64,
    /// Frames with a valid checksum but a field out of range or malformed.
    pub malformed: u64,
    /// Valid frames agsteer does not use (GSV, GSA, other UBX messages, the other protocol).
    pub unused: u64,
    #[serde(flatten)]
    pub convert: ConvertCounters,
    /// Fixes (positions) whose RTK fixed quality was passed on as float because the corrections
    /// were too old: the position's own quality, or, for a position without one, its epoch's
    /// quality report. Counted once per fix, however many inputs carried the quality.
    pub degraded_fixes: u64,
    /// Inputs passed on.
    pub inputs: u64,
}

impl StreamCounters {
    /// All checksum and CRC failures.
    pub fn checksum_errors(&self) -> u64 {
        self.nmea_checksum_errors + self.framer.ubx_checksum_errors + self.framer.rtcm_crc_errors
    }
}

/// The decoder of one stream (see the module doc).
pub struct GnssDecoder {
    params: DecoderParams,
    framer: Framer,
    nmea: NmeaConverter,
    ubx: UbxConverter,
    counters: StreamCounters,
    /// The receiver's age of corrections from the latest quality report, s.
    receiver_age_s: Option<f64>,
    link_age_s: Option<f64>,
    /// The latest quality report was degraded (for a position that carries no quality).
    quality_degraded: bool,
}

impl GnssDecoder {
    pub fn new(params: DecoderParams) -> Self {
        GnssDecoder {
            params,
            framer: Framer::new(),
            nmea: NmeaConverter::new(params.stream),
            ubx: UbxConverter::new(params.stream),
            counters: StreamCounters::default(),
            receiver_age_s: None,
            link_age_s: None,
            quality_degraded: false,
        }
    }

    pub fn params(&self) -> &DecoderParams {
        &self.params
    }

    /// The NTRIP link's age of corrections (time since the caster's last RTCM), s; `None`
    /// when no NTRIP client feeds this receiver.
    pub fn set_link_correction_age(&mut self, age_s: Option<f64>) {
        self.link_age_s = age_s;
    }

    /// The stream was reopened: drop a partial frame.
    pub fn reset(&mut self) {
        self.framer.reset();
    }

    pub fn counters(&self) -> StreamCounters {
        StreamCounters {
            framer: self.framer.counters,
            convert: add(self.nmea.counters, self.ubx.counters),
            ..self.counters
        }
    }

    /// Take a chunk received at `receipt`; each input goes to `emit`. RTCM frames found in
    /// the stream go to `rtcm` (a receiver echoing its corrections, or a base's output).
    pub fn push(
        &mut self,
        chunk: &[u8],
        receipt: &Receipt,
        emit: &mut dyn FnMut(Input),
        rtcm: &mut dyn FnMut(&[u8]),
    ) {
        let GnssDecoder {
            params,
            framer,
            nmea,
            ubx,
            counters,
            receiver_age_s,
            link_age_s,
            quality_degraded,
        } = self;
        framer.push(chunk, &mut |frame| match frame {
            Frame::Nmea(line) => match nmea0183::parse(line) {
                Ok(s) if params.protocol == Protocol::Nmea0183 => {
                    counters.decoded += 1;
                    let mut ages = Ages {
                        max: params.max_correction_age_s,
                        receiver: &mut *receiver_age_s,
                        link: *link_age_s,
                        quality_degraded: &mut *quality_degraded,
                    };
                    nmea.convert(&s, receipt, &mut |i| emit(cap(i, &mut ages, counters)));
                }
                Ok(_) | Err(NmeaError::Unsupported) => counters.unused += 1,
                Err(e) if e.is_checksum() => counters.nmea_checksum_errors += 1,
                Err(_) => counters.malformed += 1,
            },
            Frame::Ubx { class, id, payload } => match ubx::decode(class, id, payload) {
                Ok(m) if params.protocol == Protocol::Ubx => {
                    counters.decoded += 1;
                    let mut ages = Ages {
                        max: params.max_correction_age_s,
                        receiver: &mut *receiver_age_s,
                        link: *link_age_s,
                        quality_degraded: &mut *quality_degraded,
                    };
                    ubx.convert(&m, receipt, &mut |i| emit(cap(i, &mut ages, counters)));
                }
                Ok(_) | Err(UbxError::Unsupported) => counters.unused += 1,
                Err(_) => counters.malformed += 1,
            },
            Frame::Rtcm(f) => rtcm(f),
            Frame::Text(_) => counters.unused += 1,
        });
    }
}

fn add(a: ConvertCounters, b: ConvertCounters) -> ConvertCounters {
    ConvertCounters {
        stale: a.stale + b.stale,
        clock_jumps: a.clock_jumps + b.clock_jumps,
        clock_mismatch: a.clock_mismatch + b.clock_mismatch,
    }
}

/// What the correction-age cap needs: the limit, the receiver's and the link's ages, and
/// whether the latest quality report was degraded.
struct Ages<'a> {
    max: f64,
    receiver: &'a mut Option<f64>,
    link: Option<f64>,
    quality_degraded: &'a mut bool,
}

/// Apply the correction-age cap to one input (see the module doc) and count it: one degraded
/// fix per position, not one per input carrying the quality (a GGA gives a Quality and a
/// Position of the same epoch).
fn cap(mut i: Input, ages: &mut Ages<'_>, counters: &mut StreamCounters) -> Input {
    if let Input::Quality(q) = &i {
        *ages.receiver = q.correction_age_s;
    }
    counters.inputs += 1;
    let too_old =
        ages.receiver.is_some_and(|a| a > ages.max) || ages.link.is_some_and(|a| a > ages.max);
    let degrade = |q: &mut FixQuality| {
        let fixed = *q == FixQuality::RtkFixed;
        if fixed && too_old {
            *q = FixQuality::RtkFloat;
        }
        fixed && too_old
    };
    match &mut i {
        Input::Quality(q) => *ages.quality_degraded = degrade(&mut q.quality),
        Input::Position(p) => {
            let degraded = match p.quality.as_mut() {
                Some(q) => degrade(q),
                None => *ages.quality_degraded,
            };
            if degraded {
                counters.degraded_fixes += 1;
            }
        }
        _ => {}
    }
    i
}
