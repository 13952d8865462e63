//! What the node tells the supervisor about the path each period: which work line is driven
//! (its tracking supervised: [`crate::safety::tracking`]), on every other path how far the
//! vehicle is from it (`off_path`), and a gap in the plan before the segment just started
//! (`path_gap`: the steering given back there, not steered across ground the planner found no
//! clear way over).

use super::ControllerNode;
use crate::estimate::VehicleEstimate;
use crate::geo::Direction;
use crate::safety::FaultCode;

impl ControllerNode {
    /// Tells the supervisor which work line is driven (work lines driven forward; not turns,
    /// approaches or reversing) and, when it changes, the line's sharpest curvature; and the
    /// vehicle's distance from the path being driven, whatever it is.
    pub(super) fn supervise_path(&mut self, estimate: Option<&VehicleEstimate>) {
        let g = self.ctrl.guidance();
        let distance = estimate.and_then(|e| g.distance_from_path(&e.pose));
        self.supervisor.set_path_distance(distance);
        let line = (g.tag() == crate::geo::Tag::Work
            && !g.is_approaching()
            && !g.is_finished()
            && g.direction() == Direction::Forward)
            .then(|| g.current_line());
        if line != self.supervised_line {
            self.supervised_line = line;
            let k = if line.is_some() {
                crate::safety::tracking::sharpest_curvature(
                    g.global_path().iter().map(|p| p.pos),
                    1.0,
                )
            } else {
                0.0
            };
            self.supervisor.set_line(line, k);
        }
        // A gap in the plan before the segment just started: not steered across.
        let g = self.ctrl.guidance();
        let segment = (!g.is_approaching()).then(|| g.index_rank());
        if segment != self.supervised_segment {
            if let (Some(_), Some(gap)) = (self.supervised_segment, g.gap_before()) {
                tracing::warn!(
                    segment = g.index_rank(),
                    gap_m = format_args!("{gap:.1}"),
                    "the plan has a gap here: steering given back (drive to the segment's start)"
                );
                self.supervisor.give_back(FaultCode::PathGap);
            }
            self.supervised_segment = segment;
        }
    }
}
