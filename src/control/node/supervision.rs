//! What the node tells the supervisor about the path each period: which work line is driven
//! (its tracking supervised: [`crate::safety::tracking`]) and, on every other path, how far the
//! vehicle is from it (`off_path`).

use super::ControllerNode;
use crate::estimate::VehicleEstimate;
use crate::geo::Direction;

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
    }
}
