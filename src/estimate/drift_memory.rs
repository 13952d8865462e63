//! The drift learnt per direction of travel.
//!
//! The observer's drift is a world vector ([`super::Estimator::drift`]): right for a drift
//! fixed on the ground (downhill), which keeps its side of the field when the vehicle turns
//! round. A lateral velocity fixed on the *vehicle* keeps its side of the vehicle instead: the
//! crab of an implement's side draft, the sideways creep of tyres that carry a lateral load, the
//! residue of an antenna or wheel-angle error the other estimates have not yet taken. After a
//! headland turn the world vector learnt on the last pass then points the wrong way, and the
//! observer learns it again over its time constant, a pass long, on every pass.
//!
//! On a straight pass only the drift across the pass is observable, so one pass cannot tell a
//! ground drift from a vehicle one; two passes in opposite directions can, and work is driven
//! in few directions (the AB lines of a field, its headland sides). So the drift is kept per
//! sector of heading, for straight driving only (the guidance says when the path is straight,
//! [`Estimator::set_straight`]; a curve sweeps through the sectors and its drift is the curve's):
//! - while a sector is driven straight it keeps the current drift;
//! - the first straight in a sector [`NEW_DIRECTION_SECTORS`] or more from the last pass (a
//!   stay of [`MIN_LEARNT_S`]), the way back, learns the drift across the heading afresh (its
//!   variance back to the initial one) when the drift carried into it is above [`MIN_DRIFT`]
//!   (above 10 km/h: [`MIN_CRAB`] times the speed);
//! - a straight in a sector learnt for [`MIN_LEARNT_S`] takes its drift across the heading
//!   where the carried one points the other way, both above half [`MIN_DRIFT`].
//!
//! A ground drift gives every sector the same vector and is never swapped (a growing one keeps
//! its side, and its newest value is the right one); a vehicle drift gives each direction its
//! own, so from the third pass on each pass starts with its drift. Smaller drifts are left as
//! they were: what a straight pass learns from the other errors is a residue that restoring made
//! worse (the envelope's antenna-position and GNSS-latency rows). Sectors are [`SECTORS`] of
//! 45°; an active one is kept until the heading is [`HYSTERESIS`] past its edge, so a line along
//! an edge does not swap the drift on noise. Fixed arrays; nothing allocates.
//!
//! **Curves.** A curve sweeps the heading round, so a vehicle drift turns with it while the
//! world vector stays put (on an arc of R 15 m at 10 km/h a 5 kN side draft's 8 cm/s crab turns
//! a radian in 5 s, the drift's time constant half a minute). Where the drift is known to be the
//! vehicle's it turns with the heading ([`CurveDrift`], [`Estimator::set_work`]):
//! - on a curved work path, once the drift has been learnt on its curves for
//!   [`MIN_LEARNT_S`] (or was carried in, below), when it is one the memory acts on (above
//!   [`MIN_DRIFT`], [`MIN_CRAB`] times the speed);
//! - through a headland turn, when the work line that ends had such a drift and it is known to
//!   be the vehicle's: the line was curved (above), or the way back in the opposite sector kept
//!   the drift on the other side of the field. The turn then keeps it and does not learn (a
//!   turn's transient slip of dynamic tyres is not the line's drift), and the straight after it
//!   takes its sector's drift across the heading, if learnt, as the way back does above (the
//!   carried one is right only in its vehicle part; a slope adds a ground part).
//!
//! **Speed.** A lateral force on the tyres (an implement's side draft) makes a slip *angle*: the
//! crab's velocity is proportional to the speed. Where both directions of the pass are learnt,
//! their drifts across the heading are the vehicle's crab (on the same side of the vehicle)
//! plus the ground's drift (on opposite sides), so their sum gives the crab's angle
//! ([`DriftMemory::crab_angle`]); the drift's vehicle part then follows the speed fix to fix,
//! and a sector's drift restored at another speed than it was kept at is moved by the crab's
//! share of the difference. The ground's part stays a velocity. A sector keeps its drift across
//! the heading as the vehicle saw it, not as a world vector: a restore on a turn's last
//! straight, a few degrees off the line, took in a share of the unobservable drift along it.
//!
//! A ground drift goes through a turn as a world vector, as before. One not yet known (the first
//! turn: no way back learnt) is as likely the vehicle's as the ground's, so the next line starts
//! its drift across the heading from zero and learns it afresh (the expected value; half the
//! error either way: the side draft's first line at 15 km/h 15.9 → 12.7 cm max, a slope's
//! first line start a few millimetres worse). The understeering tyres' crab on an arc flips
//! with the arc's direction and is carried into the next arc wrong: tractor_b's R 15 m 3.27 →
//! 3.96 cm (Session 16 of docs/envelope.md).

use super::Estimator;
use crate::geo::{heading_vec, left_normal, v2, wrap_angle, Vec2};
use std::f64::consts::TAU;

/// Sectors of heading.
pub const SECTORS: usize = 8;
/// How far past the current sector's edge the heading must be to leave it, rad (15°).
pub const HYSTERESIS: f64 = 0.2618;
/// A sector's drift is restored once the observer has learnt there this long, s.
pub const MIN_LEARNT_S: f64 = 10.0;
/// The smallest drift across the heading the memory acts on, m/s (module docs). The drifts a
/// straight pass learns from the other errors (an antenna mounted 0.3 m off along the vehicle,
/// tyre transients, GNSS noise) were 0.3–0.8 cm/s in the envelope; a 5 kN side draft's crab
/// 8 cm/s.
pub const MIN_DRIFT: f64 = 0.02;
/// Above 10 km/h the smallest drift grows with the speed, as this crab angle, rad (0.41°: 2 cm/s
/// at 10 km/h): the lateral slip of dynamic tyres at a line's start grows with it (soft tyres
/// and tractor_b at 15 km/h had been relearnt on every way back at 2 cm/s: 3.0 → 3.7 and 3.9 →
/// 6.3 cm RMS; with the angle 3.0 and 5.1 cm, the side draft's 1.8 → 1.5 cm).
pub const MIN_CRAB: f64 = 0.0072;
/// A sector at least this many sectors (135°) from the last pass's is a new direction of
/// work (the way back): its drift is learnt afresh.
pub const NEW_DIRECTION_SECTORS: usize = 3;

#[derive(Debug, Clone, Copy, PartialEq)]
struct Slot {
    /// The drift across the heading it was kept at (the vehicle's lateral velocity: positive
    /// to its left), m/s. Kept as the vehicle saw it, not as a world vector taken across the
    /// heading at the restore: a restore made on a turn's last straight, a few degrees off the
    /// line, took a share of the unobservable drift along the heading with it (the side
    /// draft's 15 km/h lines started 0.02–0.03 m/s short of their crab and kept a 2–3 cm
    /// standing error for a pass).
    across: f64,
    /// The speed it was kept at, m/s (≥ 0).
    speed: f64,
    /// Time learnt in this sector, s.
    learnt: f64,
}

/// What entering a heading does to the drift.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Entered {
    /// Still the same sector: as it is.
    Same,
    /// A sector learnt before: its drift across the heading, m/s (positive left; along the
    /// heading a pass does not observe it), and the speed it was kept at, m/s.
    Learnt { across: f64, speed: f64 },
    /// A sector not learnt yet, [`NEW_DIRECTION_SECTORS`] or more from the last pass: the
    /// drift as it is, learnt afresh (a new direction's drift is as uncertain as the first one
    /// was). Any other sector not learnt yet goes on as it is ([`Entered::Same`]).
    New,
}

/// The drift per sector of heading (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DriftMemory {
    slots: [Slot; SECTORS],
    /// The sector of the heading (with the hysteresis).
    current: Option<usize>,
    /// The current sector's drift is in place: it has been driven straight since it was
    /// entered.
    active: bool,
    /// Time learnt driving straight since the current sector became active, s.
    stay: f64,
    /// The last sector driven straight for [`MIN_LEARNT_S`] at a stretch (a pass).
    last_pass: Option<usize>,
}

impl Default for DriftMemory {
    fn default() -> Self {
        DriftMemory {
            slots: [Slot {
                across: 0.0,
                speed: 0.0,
                learnt: 0.0,
            }; SECTORS],
            current: None,
            active: false,
            stay: 0.0,
            last_pass: None,
        }
    }
}

/// The sector of `heading` (rad).
fn sector_of(heading: f64) -> usize {
    let width = TAU / SECTORS as f64;
    let i = (heading.rem_euclid(TAU) / width + 0.5).floor() as usize;
    i % SECTORS
}

/// How many sectors apart `a` and `b` are (0 to [`SECTORS`] / 2).
fn sector_distance(a: usize, b: usize) -> usize {
    let d = a.abs_diff(b) % SECTORS;
    d.min(SECTORS - d)
}

/// The centre of sector `i`, rad.
fn centre(i: usize) -> f64 {
    i as f64 * TAU / SECTORS as f64
}

impl DriftMemory {
    /// The observer learnt for `dt` s, driving straight or not.
    pub fn learnt(&mut self, dt: f64, straight: bool) {
        let learning = self.active && straight && dt.is_finite() && dt > 0.0;
        if let (Some(c), true) = (self.current, learning) {
            self.slots[c].learnt += dt;
            self.stay += dt;
        }
    }

    /// The drift across the heading kept driving straight the other way (the sector of
    /// `heading` + π, rad; m/s, positive to that way's left), if learnt there for
    /// [`MIN_LEARNT_S`].
    pub fn opposite(&self, heading: f64) -> Option<f64> {
        let slot = &self.slots[sector_of(heading + std::f64::consts::PI)];
        (slot.learnt >= MIN_LEARNT_S).then_some(slot.across)
    }

    /// The vehicle's own crab as an angle, rad (positive to its left), where the two
    /// directions of the current pass (or, between passes, the last one) are both learnt:
    /// each direction's drift across the heading is the vehicle's crab (the same side of the
    /// vehicle, its velocity the angle times the speed) plus the ground's drift (the other
    /// side of the vehicle on the way back), so their sum is the crab's alone:
    /// `across_a + across_b = angle · (speed_a + speed_b)`. `None` below [`MIN_CRAB`].
    pub fn crab_angle(&self) -> Option<f64> {
        let sector = self.current.filter(|_| self.active).or(self.last_pass)?;
        let (a, b) = (
            &self.slots[sector],
            &self.slots[(sector + SECTORS / 2) % SECTORS],
        );
        let learnt = a.learnt >= MIN_LEARNT_S && b.learnt >= MIN_LEARNT_S;
        let speeds = a.speed + b.speed;
        // A crab smaller than MIN_CRAB is a residue of the other errors, as for the memory's
        // own restores (a soft tyre's slope and wheel-angle-sensor bias left ±0.2°, whose
        // change with the speed moved a 20 s RTK float's dead reckoning 20 cm).
        let angle = (a.across + b.across) / speeds;
        (learnt && speeds > 0.0 && angle.abs() >= MIN_CRAB).then_some(angle)
    }

    /// The vehicle now heads `heading` (rad) at `speed` (m/s), driving straight or not
    /// (`straight`), with the observer's drift `drift` (world, m/s): what to go on with.
    /// Only straight driving takes a sector's drift: a curve sweeps through the sectors and
    /// its drift is the curve's (tyre slip, a curvature bias), not a direction's.
    pub fn on_heading(&mut self, heading: f64, straight: bool, drift: Vec2, speed: f64) -> Entered {
        if !heading.is_finite() {
            return Entered::Same;
        }
        let half = 0.5 * TAU / SECTORS as f64;
        // The hysteresis holds an active sector only: a sector is taken where the heading
        // is when the straight begins.
        let sector = match self.current {
            Some(c)
                if self.active && wrap_angle(heading - centre(c)).abs() <= half + HYSTERESIS =>
            {
                c
            }
            _ => sector_of(heading),
        };
        if self.current != Some(sector) {
            if let (Some(c), true) = (self.current, self.active && self.stay >= MIN_LEARNT_S) {
                self.last_pass = Some(c);
            }
            self.current = Some(sector);
            self.active = false;
        }
        if !straight {
            return Entered::Same;
        }
        if self.active {
            // The sector keeps the drift of its straight driving (not of a turn's start).
            self.slots[sector].across = left_normal(&heading_vec(heading)).dot(&drift);
            self.slots[sector].speed = speed.abs();
            return Entered::Same;
        }
        self.active = true;
        self.stay = 0.0;
        let slot = &self.slots[sector];
        if slot.learnt >= MIN_LEARNT_S {
            Entered::Learnt {
                across: slot.across,
                speed: slot.speed,
            }
        } else if self
            .last_pass
            .is_some_and(|p| sector_distance(p, sector) >= NEW_DIRECTION_SECTORS)
        {
            Entered::New
        } else {
            Entered::Same
        }
    }
}

/// The drift on curves ([the module](self)).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(super) struct CurveDrift {
    /// The path is a work path driven forward.
    work: bool,
    /// The current headland turn carries the last work line's drift as the vehicle's.
    turn_carries_crab: bool,
    /// The current work path started with a drift a turn carried as the vehicle's.
    carried_in: bool,
    /// The current headland turn came from a line whose drift was not known to be the
    /// vehicle's or the ground's.
    turn_unknown: bool,
    /// Time the drift has been learnt on curves of this work path, s.
    line_learnt: f64,
}

impl CurveDrift {
    /// The drift was learnt for `dt` (s) on a straight path or not (`straight`).
    pub(super) fn learnt(&mut self, dt: f64, straight: bool) {
        if !straight && self.work && dt.is_finite() && dt > 0.0 {
            self.line_learnt += dt;
        }
    }
}

impl Estimator {
    /// Whether the vehicle follows a straight path (the guidance's; the drift is kept per
    /// direction of straight driving, [the module](self)).
    pub fn set_straight(&mut self, straight: bool) {
        self.straight = straight;
    }

    /// Whether the vehicle follows a work path forward (the guidance's). Leaving one decides
    /// whether the headland turn carries its drift as the vehicle's ([the module](self)).
    pub fn set_work(&mut self, work: bool) {
        if self.curve.work && !work {
            // Carried: a curved line whose drift already turned with the vehicle, or a
            // straight one whose way back kept the drift on the other side. Unknown: a
            // straight one with no way back learnt yet.
            let curved = self.curve.line_learnt >= MIN_LEARNT_S;
            let (carries, unknown) = match self.fix_pose {
                Some(pose) if self.drift_is_vehicles(pose.heading) => (
                    curved || self.crab_known(pose.heading),
                    !curved && self.drift_memory.opposite(pose.heading).is_none(),
                ),
                _ => (false, false),
            };
            self.curve.turn_carries_crab = carries;
            self.curve.turn_unknown = unknown;
        } else if work && !self.curve.work {
            // After a turn from a line whose drift was neither known to be the vehicle's nor
            // the ground's, the drift across the new line is as likely the carried one as its
            // opposite: start it from zero and learn it afresh.
            if let (true, Some(pose)) = (self.curve.turn_unknown, self.fix_pose) {
                let n = left_normal(&heading_vec(pose.heading));
                self.drift -= n * n.dot(&self.drift);
                self.lateral.relearn_across(&n);
            }
            self.curve.carried_in = self.curve.turn_carries_crab;
            self.curve.line_learnt = 0.0;
        }
        self.curve.work = work;
    }

    /// Whether the last headland turn carried the drift as the vehicle's.
    #[cfg(test)]
    pub(super) fn curve_carried(&self) -> bool {
        self.curve.turn_carries_crab
    }

    /// Whether the drift across `heading` (rad) is one the memory acts on: above
    /// [`MIN_DRIFT`], and above 10 km/h above [`MIN_CRAB`] times the speed.
    fn drift_is_vehicles(&self, heading: f64) -> bool {
        let across = left_normal(&heading_vec(heading)).dot(&self.drift).abs();
        across > (MIN_CRAB * self.fix_speed.abs()).max(MIN_DRIFT)
    }

    /// Whether the drift across `heading` (rad) is known to be the vehicle's: the way back
    /// (the opposite direction, learnt) kept it on the other side of the field, so on the same
    /// side of the vehicle.
    fn crab_known(&self, heading: f64) -> bool {
        let n = left_normal(&heading_vec(heading));
        let (here, there) = (n.dot(&self.drift), self.drift_memory.opposite(heading));
        there.is_some_and(|across| across * here > 0.0)
    }

    /// In a headland turn that carries the last line's drift as the vehicle's: the drift is
    /// kept as it is, turning with the vehicle, and not learnt (the turn's transient slip is
    /// not the line's drift).
    pub(super) fn turn_keeps_drift(&self) -> bool {
        !self.straight && !self.curve.work && self.curve.turn_carries_crab
    }

    /// On a curve from the fix heading `previous` to `heading` (rad): the drift turns with the
    /// vehicle where it is the vehicle's (on a work path, a drift the memory acts on, carried
    /// in as the vehicle's or learnt on its curves for [`MIN_LEARNT_S`]; in a headland turn
    /// that carries one).
    pub(super) fn drift_through_curve(&mut self, previous: f64, heading: f64) {
        let c = self.curve;
        let turns = !self.straight
            && if c.work {
                // A drift carried through the turn as the vehicle's is known from the start.
                (c.carried_in || c.line_learnt >= MIN_LEARNT_S) && self.drift_is_vehicles(previous)
            } else {
                c.turn_carries_crab
            };
        if turns {
            let (sin, cos) = wrap_angle(heading - previous).sin_cos();
            self.drift = v2(
                cos * self.drift.x - sin * self.drift.y,
                sin * self.drift.x + cos * self.drift.y,
            );
            self.lateral.rotate_drift(cos, sin);
        }
    }

    /// The vehicle's part of the drift follows the speed from `v_prev` to `v_now` (m/s, both
    /// above the observer's least speed) at the fix heading `heading` (rad), where the memory
    /// knows the vehicle's crab angle ([`DriftMemory::crab_angle`]): a lateral force on the
    /// tyres (an implement's side draft) makes a slip *angle*, so its crab's velocity is
    /// proportional to the speed, and the velocity learnt at 15 km/h is almost four times the
    /// crab of the 4 km/h turn after it. The ground's part (a slope's slip) is left as it is.
    pub(super) fn drift_with_speed(&mut self, heading: f64, v_prev: f64, v_now: f64) {
        let min = self.params.observer.min_speed;
        if v_prev.abs() < min || v_now.abs() < min {
            return;
        }
        if let Some(angle) = self.drift_memory.crab_angle() {
            let n = left_normal(&heading_vec(heading));
            self.add_drift(n * (angle * (v_now.abs() - v_prev.abs())));
        }
    }

    /// Move the drift estimate by `step` (world, m/s), within the observer's drift limit.
    pub(super) fn add_drift(&mut self, step: Vec2) {
        self.drift += step;
        let (norm, limit) = (self.drift.norm(), self.params.observer.drift_limit);
        if norm > limit {
            self.drift *= limit / norm;
        }
    }

    /// The drift per direction of straight driving ([the module](self)) at a fix heading
    /// `heading` (rad).
    pub(super) fn drift_by_direction(&mut self, heading: f64, speed: f64) {
        let entered = self
            .drift_memory
            .on_heading(heading, self.straight, self.drift, speed);
        // Only the drift across the heading is a direction's: a pass does not observe the rest.
        let n = left_normal(&heading_vec(heading));
        let carried = n.dot(&self.drift);
        let min_drift = (MIN_CRAB * self.fix_speed.abs()).max(MIN_DRIFT);
        match entered {
            Entered::Same => {}
            Entered::Learnt {
                across,
                speed: kept,
            } => {
                // Its vehicle part at this speed (see `drift_with_speed`).
                let min = self.params.observer.min_speed;
                let stored = match self.drift_memory.crab_angle() {
                    Some(angle) if kept >= min && speed.abs() >= min => {
                        across + angle * (speed.abs() - kept)
                    }
                    _ => across,
                };
                // The sector's own drift where the carried one points the other way across the
                // heading: a drift of the vehicle, not of the ground (a ground drift that grows
                // keeps its side, and its newest value is the right one). After a turn that
                // carried the drift as the vehicle's, the sector's own: the carried one is
                // right only in its vehicle part.
                let swapped =
                    stored * carried < 0.0 && stored.abs().min(carried.abs()) > 0.5 * min_drift;
                if swapped || self.curve.turn_carries_crab {
                    self.add_drift(n * (stored - carried));
                }
            }
            Entered::New => {
                if carried.abs() > min_drift {
                    self.lateral.relearn_across(&n);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geo::v2;
    use std::f64::consts::PI;

    /// The drift `d` (world, m/s) across `heading` (rad), positive left.
    fn across(heading: f64, d: Vec2) -> f64 {
        left_normal(&heading_vec(heading)).dot(&d)
    }

    #[test]
    fn sectors_cover_the_circle() {
        assert_eq!(sector_of(0.0), 0);
        assert_eq!(sector_of(-0.1), 0);
        assert_eq!(sector_of(PI), 4);
        assert_eq!(sector_of(-PI), 4);
        assert_eq!(sector_of(-PI / 2.0), 6);
        assert_eq!(sector_of(3.0 * PI / 8.0 + 0.01), 2);
    }

    #[test]
    fn each_direction_gets_back_what_it_learnt() {
        let mut m = DriftMemory::default();
        let north = PI / 2.0;
        let (a, b) = (v2(0.03, 0.0), v2(-0.03, 0.0));
        // Northwards: learns a (each straight fix keeps the current drift).
        assert_eq!(m.on_heading(north, true, Vec2::zeros(), 1.0), Entered::Same);
        m.learnt(30.0, true);
        assert_eq!(m.on_heading(north, true, a, 1.0), Entered::Same);
        // Southwards for the first time: learns afresh, b.
        assert_eq!(m.on_heading(-north, true, a, 1.0), Entered::New);
        m.learnt(30.0, true);
        assert_eq!(m.on_heading(-north, true, b, 1.0), Entered::Same);
        // Northwards again: a, whatever the drift now is; southwards: b.
        assert_eq!(
            m.on_heading(north, true, b, 1.0),
            Entered::Learnt {
                across: across(north, a),
                speed: 1.0
            }
        );
        assert_eq!(
            m.on_heading(-north, true, v2(0.01, 0.0), 1.0),
            Entered::Learnt {
                across: across(-north, b),
                speed: 1.0
            }
        );
    }

    #[test]
    fn a_sector_gives_back_the_crab_it_kept_whatever_the_heading_it_is_entered_at() {
        let mut m = DriftMemory::default();
        let north = PI / 2.0;
        // Kept driving north: 0.1 m/s to the right, and 0.2 m/s along the heading that a
        // straight pass does not observe.
        let kept = v2(0.1, 0.2);
        m.on_heading(north, true, Vec2::zeros(), 1.0);
        m.learnt(30.0, true);
        m.on_heading(north, true, kept, 1.0);
        m.on_heading(-north, true, kept, 1.0);
        m.learnt(30.0, true);
        // Back north on a turn's last straight 20° off the line: the crab kept, not the world
        // vector taken across this heading (−0.03 m/s, the along part leaking in).
        let off = north + 20f64.to_radians();
        let Entered::Learnt {
            across: across_kept,
            ..
        } = m.on_heading(off, true, Vec2::zeros(), 1.0)
        else {
            panic!("the sector was learnt");
        };
        assert!((across_kept - -0.1).abs() < 1e-12, "{across_kept}");
        assert!((across(off, kept) - across_kept).abs() > 0.05);
    }

    #[test]
    fn the_crab_angle_is_the_part_both_directions_share() {
        let north = PI / 2.0;
        // Northwards at 4 m/s, then southwards at 2 m/s, each learnt 30 s; `north_left` and
        // `south_left` the drifts across the heading, m/s.
        let memory = |north_left: f64, south_left: f64| {
            let mut m = DriftMemory::default();
            let world = |heading: f64, left: f64| left_normal(&heading_vec(heading)) * left;
            m.on_heading(north, true, Vec2::zeros(), 4.0);
            m.learnt(30.0, true);
            m.on_heading(north, true, world(north, north_left), 4.0);
            m.on_heading(-north, true, Vec2::zeros(), 2.0);
            m.learnt(30.0, true);
            m.on_heading(-north, true, world(-north, south_left), 2.0);
            m
        };
        // A crab of 0.03 rad to the right: 0.12 m/s at 4 m/s, 0.06 at 2.
        let crab = memory(-0.12, -0.06).crab_angle().expect("learnt both ways");
        assert!((crab - -0.03).abs() < 1e-12, "{crab}");
        // The same with a ground drift of 0.05 m/s to the east on top (left going south).
        let crab = memory(-0.17, -0.01).crab_angle().expect("learnt both ways");
        assert!((crab - -0.03).abs() < 1e-12, "{crab}");
        // A ground drift alone, and a crab below MIN_CRAB: none.
        assert_eq!(memory(-0.05, 0.05).crab_angle(), None);
        let small = 0.5 * MIN_CRAB;
        assert_eq!(memory(4.0 * small, 2.0 * small).crab_angle(), None);
        // One way only: none.
        let mut m = DriftMemory::default();
        m.on_heading(north, true, Vec2::zeros(), 4.0);
        m.learnt(30.0, true);
        assert_eq!(m.crab_angle(), None);
    }

    #[test]
    fn a_sector_learnt_briefly_and_the_edge_keep_the_drift() {
        let mut m = DriftMemory::default();
        let d = v2(0.02, 0.01);
        m.on_heading(0.0, true, Vec2::zeros(), 1.0);
        m.learnt(MIN_LEARNT_S - 1.0, true);
        // West after a short stay east (not a pass): as it is.
        assert_eq!(m.on_heading(PI, true, d, 1.0), Entered::Same);
        // Back east: its sector was learnt too briefly to be restored.
        assert_eq!(m.on_heading(0.0, true, d * 2.0, 1.0), Entered::Same);
        m.learnt(MIN_LEARNT_S, true);
        // Just past the edge of sector 0 (22.5°) but within the hysteresis: no swap.
        assert_eq!(m.on_heading(0.5, true, d * 3.0, 1.0), Entered::Same);
        assert_eq!(m.on_heading(-0.5, true, d * 3.0, 1.0), Entered::Same);
        // Not finite: as it is.
        assert_eq!(m.on_heading(f64::NAN, true, d, 1.0), Entered::Same);
    }

    #[test]
    fn a_curve_takes_no_sector_drift_until_it_runs_straight() {
        let mut m = DriftMemory::default();
        let a = v2(0.0, 0.03);
        m.on_heading(0.0, true, Vec2::zeros(), 1.0);
        m.learnt(30.0, true);
        m.on_heading(0.0, true, a, 1.0);
        // Round a curve through the sectors and back east: nothing swapped, nothing stored
        // from the curve.
        for i in 1..=16 {
            let heading = i as f64 * PI / 8.0;
            assert_eq!(
                m.on_heading(heading, false, v2(0.05, 0.0), 1.0),
                Entered::Same
            );
        }
        // Straight again, east: what was learnt there before the curve.
        assert_eq!(
            m.on_heading(0.0, true, v2(0.05, 0.0), 1.0),
            Entered::Learnt {
                across: across(0.0, a),
                speed: 1.0
            }
        );
        // West, curving: learning there does not count, and it is a new direction once
        // straight.
        m.on_heading(PI, false, a, 1.0);
        m.learnt(30.0, false);
        assert_eq!(m.on_heading(PI, true, a, 1.0), Entered::New);
        // A quarter turn from the last pass (east, learnt 30 s) is not the way back.
        let mut m = DriftMemory::default();
        m.on_heading(0.0, true, a, 1.0);
        m.learnt(30.0, true);
        assert_eq!(m.on_heading(PI / 2.0, true, a, 1.0), Entered::Same);
    }
}
