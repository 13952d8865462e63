//! Changes of driving direction (docs/METHODS.md, Manoeuvres at work): before a cusp and at the
//! job's end the node asks the tractor to stop (the direction-request frame), waits until it
//! has stopped within reach of the cusp, moves the guidance on to the next segment and asks
//! for its direction. The braking starts where the stopping distance reaches the cusp, also
//! across segments driven the same way before it
//! ([`crate::guidance::Guidance::stop_after_within`]).

use super::ControllerNode;
use crate::can::codec::DirectionRequestDirection;
use crate::geo::Direction;

/// How the node handles a change of driving direction (docs/METHODS.md, Manoeuvres at work: the
/// daemon asks for it on the bus before each cusp, waits until the vehicle has stopped and turned,
/// then steers on).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct CuspParams {
    pub(super) decel: f64,
    pub(super) stopped_speed: f64,
    pub(super) capture: f64,
    /// Control period, s.
    pub(super) dt: f64,
    pub(super) min_speed: f64,
}

fn request_of(d: Direction) -> DirectionRequestDirection {
    match d {
        Direction::Forward => DirectionRequestDirection::Forward,
        Direction::Reverse => DirectionRequestDirection::Reverse,
    }
}

impl ControllerNode {
    /// The direction to request this period, for segment jobs and approach paths (AB jobs
    /// are driven forward and send none unless an approach path came first). Before a cusp:
    /// stop once within the stopping distance of it, counted across the segments driven the
    /// same way before it; when stopped near the cusp, move on to the next segment and request
    /// its direction.
    pub(super) fn direction_request(
        &mut self,
        c: &crate::control::ControlOutput,
    ) -> Option<DirectionRequestDirection> {
        const STOP: DirectionRequestDirection = DirectionRequestDirection::Stop;
        let p = self.cusps;
        let g = self.ctrl.guidance();
        // AB jobs send none, unless an approach path has made the node ask for a direction.
        if !matches!(g.job_plan(), crate::guidance::JobPlan::Segments(_))
            && !g.is_approaching()
            && self.last_request.is_none()
        {
            return None;
        }
        if g.is_finished() {
            self.cusp = false;
            return Some(STOP);
        }
        let v = self.speed;
        let stopped = v.abs() < p.stopped_speed;
        let want = c.direction;
        let moving = if v < 0.0 {
            Direction::Reverse
        } else {
            Direction::Forward
        };
        // The stopping distance, with a control period's travel before the request acts, m.
        let braking = v * v / (2.0 * p.decel) + v.abs() * p.dt;
        // A cusp ahead, or the end of the job: stop there.
        let next = g.next_direction();
        if let Some(est) = c.estimate.filter(|_| next != Some(want)) {
            let remaining = g.remaining(&est.pose.pos);
            if remaining <= braking {
                self.cusp = next.is_some();
                if stopped && remaining <= p.capture {
                    self.ctrl.guidance_mut().advance_segment();
                    return Some(next.map(request_of).unwrap_or(STOP));
                }
                return Some(STOP);
            }
        }
        // A cusp or the job's end beyond short segments driven the same way: brake for it
        // from here (the guidance moves on to those segments by itself).
        if let Some(est) = c.estimate.filter(|_| next == Some(want) && moving == want) {
            if let Some((after, cusp)) = g.stop_after_within(braking) {
                if g.remaining(&est.pose.pos) + after <= braking {
                    self.cusp = cusp;
                    return Some(STOP);
                }
            }
        }
        if self.cusp && moving == want && v.abs() >= p.min_speed {
            self.cusp = false;
        }
        if !stopped && moving != want {
            // Still rolling the old way (e.g. past a cusp): stop first.
            self.cusp = true;
            return Some(STOP);
        }
        Some(request_of(want))
    }
}
