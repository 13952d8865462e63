//! NMEA 0183 sentences → the seam's [`Input`]s, once per sentence, at the edge: degrees →
//! radians, clockwise-from-North → yaw counter-clockwise from East, knots and km/h → m/s,
//! altitude above the geoid + geoid separation → height above the ellipsoid.
//!
//! What each sentence gives:
//!
//! | sentence | Quality | Position | CourseSpeed | Heading | Attitude |
//! |---|---|---|---|---|---|
//! | GGA | quality, satellites, HDOP, age (+ GST's σ of the same epoch) | yes | | | |
//! | GNS | from the mode letters (R fixed, F float) | yes | | | |
//! | RMC | | | course, speed (status `A` only) | | |
//! | VTG | | | course, speed (mode not `N`) | | |
//! | HDT | | | | true heading | |
//! | GST | σ = √(σ_lat² + σ_lon²), with the epoch's GGA | | | | |
//! | PANDA | as GGA | yes | speed | — (the IMU's yaw has an arbitrary zero) | roll, pitch |
//! | PAOGI | as GGA | yes | speed | dual-antenna heading | roll |
//! | KSXT | position status | yes | course, speed | when its status is RTK fixed | — |
//!
//! One position per epoch: a receiver sending GGA and GNS (or an AgOpenGPS board passing GGA
//! through beside PANDA) gives the estimator one fix, not two. GGA quality mapping: 0 → none,
//! 4 → RTK fixed, 5 → RTK float, 7 (manual input) → none, any other (1 GNSS, 2 DGNSS, 3 PPS,
//! 6 dead reckoning, 8 simulator) → other.
//!
//! Dual-antenna headings are the heading of the antenna baseline; `baseline_angle` (the
//! baseline's direction relative to the vehicle's forward axis, counter-clockwise) turns them
//! into the vehicle's heading. Roll in `$KSXT` is left out: which of its two tilt fields is the
//! vehicle's roll depends on how the antennas are mounted.

use super::clock::{self, EpochClock, Latency, Receipt, DAY_S};
use super::{AgOpenGps, Gga, Gns, Ksxt, Sentence};
use crate::geo::wrap_angle;
use crate::input::{
    AttitudeInput, CourseSpeedInput, FixQuality, HeadingInput, HeadingReference, Input,
    PositionInput, QualityInput, SourceId,
};

/// Knots → m/s.
pub const KNOT_MPS: f64 = 1852.0 / 3600.0;
/// km/h → m/s.
pub const KMH_MPS: f64 = 1.0 / 3.6;

/// What a converter needs to know about its stream.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StreamParams {
    pub source: SourceId,
    /// Direction of the dual-antenna baseline relative to the vehicle's forward axis, rad,
    /// counter-clockwise (0: the baseline points forward; −π/2: it points to the right).
    pub baseline_angle: f64,
    /// An epoch arriving later than this beyond the link's best is stale, s.
    pub max_delay_s: f64,
}

/// GGA quality indicator → [`FixQuality`].
pub fn gga_quality(q: u8) -> FixQuality {
    match q {
        0 | 7 => FixQuality::None,
        4 => FixQuality::RtkFixed,
        5 => FixQuality::RtkFloat,
        _ => FixQuality::Other,
    }
}

/// FAA / GNS mode letter → [`FixQuality`] (`None` for an empty slot).
pub fn mode_quality(m: u8) -> Option<FixQuality> {
    match m {
        b'R' => Some(FixQuality::RtkFixed),
        b'F' => Some(FixQuality::RtkFloat),
        b'A' | b'D' | b'P' | b'E' | b'S' => Some(FixQuality::Other),
        b'N' | b'M' | b'V' => Some(FixQuality::None),
        _ => None,
    }
}

/// The better of two qualities.
pub fn best(a: FixQuality, b: FixQuality) -> FixQuality {
    let rank = |q| match q {
        FixQuality::RtkFixed => 3,
        FixQuality::RtkFloat => 2,
        FixQuality::Other => 1,
        FixQuality::None => 0,
    };
    if rank(b) > rank(a) {
        b
    } else {
        a
    }
}

/// Counts kept by a converter.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct ConvertCounters {
    /// Sentences/messages of a stale epoch (late or replayed), dropped.
    pub stale: u64,
    /// Sender clock resets (the freshness reference restarted).
    pub clock_jumps: u64,
    /// Fixes whose latency disagreed with the host clock (reported as unknown).
    pub clock_mismatch: u64,
}

/// The quality details of the current epoch, for GST arriving after its GGA.
#[derive(Debug, Clone, Copy)]
struct EpochQuality {
    time_s: f64,
    input: QualityInput,
}

/// Sentences → inputs for one stream.
#[derive(Debug, Clone)]
pub struct NmeaConverter {
    params: StreamParams,
    epochs: EpochClock,
    /// Time of validity of the last epoch that gave a position.
    position_epoch: Option<f64>,
    quality: Option<EpochQuality>,
    /// GST σ waiting for its GGA: (time of day, m).
    sigma: Option<(f64, f64)>,
    pub counters: ConvertCounters,
}

fn yaw_deg_cw(deg: f64, baseline_angle: f64) -> f64 {
    wrap_angle(std::f64::consts::FRAC_PI_2 - deg.to_radians() - baseline_angle)
}

impl NmeaConverter {
    pub fn new(params: StreamParams) -> Self {
        NmeaConverter {
            params,
            epochs: EpochClock::new(DAY_S, params.max_delay_s),
            position_epoch: None,
            quality: None,
            sigma: None,
            counters: ConvertCounters::default(),
        }
    }

    pub fn params(&self) -> &StreamParams {
        &self.params
    }

    /// Check a sentence's time of validity; false when its epoch is stale.
    fn fresh(&mut self, t: f64, time_s: Option<f64>) -> bool {
        let fresh = match time_s {
            Some(ts) => match self.epochs.observe(t, ts) {
                clock::Epoch::ClockJump => {
                    self.counters.clock_jumps += 1;
                    self.position_epoch = None;
                    true
                }
                e => e.fresh(),
            },
            None => self.epochs.current_fresh(),
        };
        if !fresh {
            self.counters.stale += 1;
        }
        fresh
    }

    fn latency(&mut self, l: Latency) -> Option<f64> {
        if l == Latency::ClockMismatch {
            self.counters.clock_mismatch += 1;
        }
        l.seconds()
    }

    /// Whether this epoch still owes a position (and claim it).
    fn first_position(&mut self, time_s: Option<f64>) -> bool {
        match time_s {
            Some(ts) if self.position_epoch.is_some_and(|p| (p - ts).abs() < 5e-4) => false,
            _ => {
                self.position_epoch = time_s;
                true
            }
        }
    }

    /// Convert one sentence received at `receipt`, passing each input to `emit`.
    pub fn convert(&mut self, s: &Sentence, receipt: &Receipt, emit: &mut dyn FnMut(Input)) {
        let t = receipt.t;
        let source = self.params.source;
        match s {
            Sentence::Gga(g) => {
                self.fix(receipt, &Fix::from_gga(g), emit);
            }
            Sentence::Gns(g) => {
                self.fix(receipt, &Fix::from_gns(g), emit);
            }
            Sentence::Panda(a) | Sentence::Paogi(a) => {
                let dual = matches!(s, Sentence::Paogi(_));
                if !self.fix(receipt, &Fix::from_agopengps(a), emit) {
                    return;
                }
                if let Some(v) = a.speed_knots {
                    emit(Input::CourseSpeed(CourseSpeedInput {
                        t,
                        source,
                        course: None,
                        speed_mps: Some(v * KNOT_MPS),
                    }));
                }
                if let (true, Some(h)) = (dual, a.heading_deg) {
                    emit(self.heading(t, h));
                }
                let pitch = if dual { None } else { a.pitch_deg };
                if a.roll_deg.is_some() || pitch.is_some() {
                    emit(Input::Attitude(AttitudeInput {
                        t,
                        source,
                        roll: a.roll_deg.map(f64::to_radians),
                        pitch: pitch.map(f64::to_radians),
                    }));
                }
            }
            Sentence::Ksxt(k) => self.ksxt(receipt, k, emit),
            Sentence::Rmc(r) => {
                if !self.fresh(t, r.time_s) || !r.valid || r.mode == Some(b'N') {
                    return;
                }
                emit(Input::CourseSpeed(CourseSpeedInput {
                    t,
                    source,
                    course: r.course_deg.map(|c| yaw_deg_cw(c, 0.0)),
                    speed_mps: r.speed_knots.map(|v| v * KNOT_MPS),
                }));
            }
            Sentence::Vtg(v) => {
                if !self.fresh(t, None) || v.mode == Some(b'N') {
                    return;
                }
                let speed = v
                    .speed_kmh
                    .map(|s| s * KMH_MPS)
                    .or(v.speed_knots.map(|s| s * KNOT_MPS));
                if speed.is_none() && v.course_true_deg.is_none() {
                    return;
                }
                emit(Input::CourseSpeed(CourseSpeedInput {
                    t,
                    source,
                    course: v.course_true_deg.map(|c| yaw_deg_cw(c, 0.0)),
                    speed_mps: speed,
                }));
            }
            Sentence::Hdt(h) => {
                if let (true, Some(deg)) = (self.fresh(t, None), h.heading_deg) {
                    emit(self.heading(t, deg));
                }
            }
            Sentence::Gst(g) => {
                if !self.fresh(t, g.time_s) {
                    return;
                }
                let (Some(ts), Some(la), Some(lo)) = (g.time_s, g.sigma_lat_m, g.sigma_lon_m)
                else {
                    return;
                };
                let sigma = la.hypot(lo);
                match self.quality {
                    Some(q) if (q.time_s - ts).abs() < 5e-4 => emit(Input::Quality(QualityInput {
                        t,
                        horizontal_sigma_m: Some(sigma),
                        ..q.input
                    })),
                    _ => self.sigma = Some((ts, sigma)),
                }
            }
        }
    }

    fn heading(&self, t: f64, deg: f64) -> Input {
        Input::Heading(HeadingInput {
            t,
            source: self.params.source,
            heading: yaw_deg_cw(deg, self.params.baseline_angle),
            reference: HeadingReference::True,
            variation: None,
        })
    }

    /// Quality then position of a GGA-like fix. Returns whether the epoch is fresh.
    fn fix(&mut self, receipt: &Receipt, f: &Fix, emit: &mut dyn FnMut(Input)) -> bool {
        let t = receipt.t;
        if !self.fresh(t, f.time_s) {
            return false;
        }
        let sigma = match (self.sigma, f.time_s) {
            (Some((ts, s)), Some(ft)) if (ts - ft).abs() < 5e-4 => Some(s),
            _ => None,
        };
        let q = QualityInput {
            t,
            source: self.params.source,
            quality: f.quality,
            satellites: f.satellites,
            hdop: f.hdop,
            correction_age_s: f.correction_age_s,
            horizontal_sigma_m: sigma,
        };
        emit(Input::Quality(q));
        if let Some(ts) = f.time_s {
            self.quality = Some(EpochQuality {
                time_s: ts,
                input: q,
            });
        }
        if let (Some(lat), Some(lon), false) = (f.lat_deg, f.lon_deg, f.quality == FixQuality::None)
        {
            if self.first_position(f.time_s) {
                let latency = match (f.utc_s, f.time_s) {
                    (Some(u), _) => clock::latency_from_utc(receipt, u),
                    (None, Some(ts)) => clock::latency_from_time_of_day(receipt, ts),
                    _ => Latency::Unknown,
                };
                let latency_s = self.latency(latency);
                emit(Input::Position(PositionInput {
                    t,
                    source: self.params.source,
                    lat_deg: lat,
                    lon_deg: lon,
                    altitude_m: f.height_m,
                    latency_s,
                    quality: Some(f.quality),
                }));
            }
        }
        true
    }

    fn ksxt(&mut self, receipt: &Receipt, k: &Ksxt, emit: &mut dyn FnMut(Input)) {
        if !self.fix(receipt, &Fix::from_ksxt(k), emit) {
            return;
        }
        let t = receipt.t;
        if k.course_deg.is_some() || k.speed_kmh.is_some() {
            emit(Input::CourseSpeed(CourseSpeedInput {
                t,
                source: self.params.source,
                course: k.course_deg.map(|c| yaw_deg_cw(c, 0.0)),
                speed_mps: k.speed_kmh.map(|v| v * KMH_MPS),
            }));
        }
        if let (3, Some(h)) = (k.heading_status, k.heading_deg) {
            emit(self.heading(t, h));
        }
    }
}

/// The GGA-like part of a sentence.
struct Fix {
    time_s: Option<f64>,
    /// Full UTC when the sentence has a date.
    utc_s: Option<f64>,
    lat_deg: Option<f64>,
    lon_deg: Option<f64>,
    quality: FixQuality,
    satellites: Option<u8>,
    hdop: Option<f64>,
    correction_age_s: Option<f64>,
    /// Height above the ellipsoid.
    height_m: Option<f64>,
}

impl Fix {
    fn from_gga(g: &Gga) -> Self {
        Fix {
            time_s: g.time_s,
            utc_s: None,
            lat_deg: g.lat_deg,
            lon_deg: g.lon_deg,
            quality: gga_quality(g.quality),
            satellites: g.satellites,
            hdop: g.hdop,
            correction_age_s: g.correction_age_s,
            height_m: g
                .altitude_msl_m
                .zip(g.geoid_separation_m)
                .map(|(a, n)| a + n),
        }
    }

    fn from_gns(g: &Gns) -> Self {
        let quality = g
            .modes
            .iter()
            .filter_map(|&m| mode_quality(m))
            .fold(FixQuality::None, best);
        Fix {
            time_s: g.time_s,
            utc_s: None,
            lat_deg: g.lat_deg,
            lon_deg: g.lon_deg,
            quality,
            satellites: g.satellites,
            hdop: g.hdop,
            correction_age_s: g.correction_age_s,
            height_m: g
                .altitude_msl_m
                .zip(g.geoid_separation_m)
                .map(|(a, n)| a + n),
        }
    }

    fn from_agopengps(a: &AgOpenGps) -> Self {
        Fix {
            time_s: a.time_s,
            utc_s: None,
            lat_deg: a.lat_deg,
            lon_deg: a.lon_deg,
            quality: gga_quality(a.quality),
            satellites: a.satellites,
            hdop: a.hdop,
            correction_age_s: a.correction_age_s,
            // Altitude above the geoid only: the ellipsoidal height is not known.
            height_m: None,
        }
    }

    fn from_ksxt(k: &Ksxt) -> Self {
        let quality = match k.position_status {
            3 => FixQuality::RtkFixed,
            2 => FixQuality::RtkFloat,
            1 => FixQuality::Other,
            _ => FixQuality::None,
        };
        Fix {
            time_s: k.utc_s.map(|u| u.rem_euclid(DAY_S)),
            utc_s: k.utc_s,
            lat_deg: k.lat_deg,
            lon_deg: k.lon_deg,
            quality,
            satellites: k.satellites,
            hdop: None,
            correction_age_s: k.correction_age_s,
            // The reference of KSXT's height (ellipsoid or geoid) is not documented.
            height_m: None,
        }
    }
}
