//! UBX messages → the seam's [`Input`]s.
//!
//! | message | inputs |
//! |---|---|
//! | NAV-PVT | Quality (fix and carrier solution, satellites, hAcc as σ, correction age); Position (unless NAV-HPPOSLLH is being received); CourseSpeed (gSpeed, headMot); Heading when `headVehValid` (dead-reckoning receivers) |
//! | NAV-HPPOSLLH | Position to 0.1 mm, with the quality of the NAV-PVT of the same epoch |
//! | NAV-RELPOSNED | Heading of the moving-base baseline, when valid and carrier-fixed |
//!
//! Quality: no fix (`gnssFixOK` clear, fix type 0 or 5 "time only") → none; carrier solution
//! fixed → RTK fixed, float → RTK float; any other fix (incl. dead reckoning) → other.
//! A float moving-base heading can be off by degrees: only fixed ones are passed on.
//!
//! Time: epochs are the GPS time of week (`iTOW`); NAV-PVT carries UTC, which gives the
//! latency (the rule in [`clock`](crate::input::nmea0183::clock)); NAV-HPPOSLLH and
//! NAV-RELPOSNED of the same epoch take the latency of its NAV-PVT.

use super::{NavHpPosLlh, NavPvt, NavRelPosNed, UbxMessage};
use crate::geo::wrap_angle;
use crate::input::nmea0183::clock::{self, EpochClock, Latency, Receipt};
use crate::input::nmea0183::convert::{ConvertCounters, StreamParams};
use crate::input::{
    CourseSpeedInput, FixQuality, HeadingInput, HeadingReference, Input, PositionInput,
    QualityInput,
};

/// A GPS week, s (iTOW wraps at it).
pub const WEEK_S: f64 = 604_800.0;
/// NAV-PVT gives positions again when no NAV-HPPOSLLH came for this long, s.
const HP_TIMEOUT_S: f64 = 2.0;

/// NAV-PVT → [`FixQuality`].
pub fn pvt_quality(p: &NavPvt) -> FixQuality {
    if !p.gnss_fix_ok || matches!(p.fix_type, 0 | 5) {
        FixQuality::None
    } else {
        match p.carr_soln {
            2 => FixQuality::RtkFixed,
            1 => FixQuality::RtkFloat,
            _ => FixQuality::Other,
        }
    }
}

/// What the epoch's NAV-PVT said, for the other messages of the epoch.
#[derive(Debug, Clone, Copy)]
struct PvtEpoch {
    itow_ms: u32,
    utc_s: Option<f64>,
    quality: FixQuality,
}

/// UBX messages → inputs for one stream.
#[derive(Debug, Clone)]
pub struct UbxConverter {
    params: StreamParams,
    epochs: EpochClock,
    pvt: Option<PvtEpoch>,
    /// Receipt time of the last NAV-HPPOSLLH.
    hp_t: Option<f64>,
    /// iTOW of the last epoch that gave a position.
    position_itow: Option<u32>,
    pub counters: ConvertCounters,
}

impl UbxConverter {
    pub fn new(params: StreamParams) -> Self {
        UbxConverter {
            params,
            epochs: EpochClock::new(WEEK_S, params.max_delay_s),
            pvt: None,
            hp_t: None,
            position_itow: None,
            counters: ConvertCounters::default(),
        }
    }

    fn fresh(&mut self, t: f64, itow_ms: u32) -> bool {
        let fresh = match self.epochs.observe(t, f64::from(itow_ms) * 1e-3) {
            clock::Epoch::ClockJump => {
                self.counters.clock_jumps += 1;
                self.position_itow = None;
                self.pvt = None;
                true
            }
            e => e.fresh(),
        };
        if !fresh {
            self.counters.stale += 1;
        }
        fresh
    }

    /// The epoch's NAV-PVT, if it came.
    fn pvt_of(&self, itow_ms: u32) -> Option<PvtEpoch> {
        self.pvt.filter(|p| p.itow_ms == itow_ms)
    }

    fn latency(&mut self, receipt: &Receipt, itow_ms: u32) -> Option<f64> {
        let l = match self.pvt {
            Some(PvtEpoch {
                itow_ms: pi,
                utc_s: Some(u),
                ..
            }) => {
                let dt = clock::wrap_half((f64::from(itow_ms) - f64::from(pi)) * 1e-3, WEEK_S);
                if dt.abs() <= 2.0 {
                    clock::latency_from_utc(receipt, u + dt)
                } else {
                    Latency::Unknown
                }
            }
            _ => Latency::Unknown,
        };
        if l == Latency::ClockMismatch {
            self.counters.clock_mismatch += 1;
        }
        l.seconds()
    }

    fn position(&mut self, receipt: &Receipt, p: Pos, emit: &mut dyn FnMut(Input)) {
        if self.position_itow == Some(p.itow_ms) {
            return;
        }
        self.position_itow = Some(p.itow_ms);
        let latency_s = self.latency(receipt, p.itow_ms);
        emit(Input::Position(PositionInput {
            t: receipt.t,
            source: self.params.source,
            lat_deg: p.lat_deg,
            lon_deg: p.lon_deg,
            altitude_m: Some(p.height_m),
            latency_s,
            quality: p.quality,
        }));
    }

    /// Convert one message received at `receipt`, passing each input to `emit`.
    pub fn convert(&mut self, m: &UbxMessage, receipt: &Receipt, emit: &mut dyn FnMut(Input)) {
        match m {
            UbxMessage::NavPvt(p) => self.pvt(p, receipt, emit),
            UbxMessage::NavHpPosLlh(h) => self.hp(h, receipt, emit),
            UbxMessage::NavRelPosNed(r) => self.relposned(r, receipt, emit),
        }
    }

    fn pvt(&mut self, p: &NavPvt, receipt: &Receipt, emit: &mut dyn FnMut(Input)) {
        let t = receipt.t;
        if !self.fresh(t, p.itow_ms) {
            return;
        }
        let quality = pvt_quality(p);
        self.pvt = Some(PvtEpoch {
            itow_ms: p.itow_ms,
            utc_s: p.utc_s,
            quality,
        });
        let source = self.params.source;
        emit(Input::Quality(QualityInput {
            t,
            source,
            quality,
            satellites: Some(p.satellites),
            hdop: None,
            correction_age_s: p.correction_age_s,
            horizontal_sigma_m: Some(p.h_acc_m),
        }));
        let hp_live = self.hp_t.is_some_and(|h| t - h <= HP_TIMEOUT_S);
        if quality != FixQuality::None && !p.invalid_llh && !hp_live {
            self.position(
                receipt,
                Pos {
                    itow_ms: p.itow_ms,
                    lat_deg: p.lat_deg,
                    lon_deg: p.lon_deg,
                    height_m: p.height_m,
                    quality: Some(quality),
                },
                emit,
            );
        }
        if quality != FixQuality::None {
            emit(Input::CourseSpeed(CourseSpeedInput {
                t,
                source,
                course: Some(wrap_angle(
                    std::f64::consts::FRAC_PI_2 - p.head_motion_deg.to_radians(),
                )),
                speed_mps: Some(p.ground_speed_mps.abs()),
            }));
        }
        if let Some(h) = p.head_vehicle_deg {
            emit(Input::Heading(HeadingInput {
                t,
                source,
                heading: wrap_angle(std::f64::consts::FRAC_PI_2 - h.to_radians()),
                reference: HeadingReference::True,
                variation: None,
            }));
        }
    }

    fn hp(&mut self, h: &NavHpPosLlh, receipt: &Receipt, emit: &mut dyn FnMut(Input)) {
        if !self.fresh(receipt.t, h.itow_ms) || h.invalid_llh {
            return;
        }
        self.hp_t = Some(receipt.t);
        let quality = self.pvt_of(h.itow_ms).map(|p| p.quality);
        if quality == Some(FixQuality::None) {
            return;
        }
        self.position(
            receipt,
            Pos {
                itow_ms: h.itow_ms,
                lat_deg: h.lat_deg,
                lon_deg: h.lon_deg,
                height_m: h.height_m,
                quality,
            },
            emit,
        );
    }

    fn relposned(&mut self, r: &NavRelPosNed, receipt: &Receipt, emit: &mut dyn FnMut(Input)) {
        if !self.fresh(receipt.t, r.itow_ms) {
            return;
        }
        if let (true, true, 2, Some(h)) =
            (r.gnss_fix_ok, r.rel_pos_valid, r.carr_soln, r.heading_deg)
        {
            emit(Input::Heading(HeadingInput {
                t: receipt.t,
                source: self.params.source,
                heading: wrap_angle(
                    std::f64::consts::FRAC_PI_2 - h.to_radians() - self.params.baseline_angle,
                ),
                reference: HeadingReference::True,
                variation: None,
            }));
        }
    }
}

/// A position to pass on.
struct Pos {
    itow_ms: u32,
    lat_deg: f64,
    lon_deg: f64,
    height_m: f64,
    quality: Option<FixQuality>,
}
