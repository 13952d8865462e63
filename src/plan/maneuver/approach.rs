//! The approach path (issue 6 part 5b): from the vehicle's pose when the operator engages
//! away from the first line, to the start of that line, with reversing where it is shorter.
//!
//! A pure function: the analytic connection only (a few µs, so it may run when the engage
//! request arrives without stalling the control loop), checked against the field when one is
//! known. The hybrid-A* search, which can take tens of milliseconds, is not run here.

use super::drive::{split_at_cusps, DrivenPart};
use super::path::{CurveParams, CurvePath};
use crate::geo::Pose;

/// Why no approach path was made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ApproachError {
    #[error("no continuous-curvature connection from the vehicle to the line start")]
    NoConnection,
    #[error("the approach path leaves the field or meets an obstacle")]
    Blocked,
    #[error("invalid curve limits: kappa_max {kappa_max} 1/m, sigma_max {sigma_max} 1/m²")]
    Limits { kappa_max: f64, sigma_max: f64 },
}

/// The approach from `from` to `to` as parts between cusps, points every `spacing_m`.
/// `clear` says whether a sampled path keeps the vehicle inside the field and off the
/// obstacles (pass `|_| true` when no field is known).
pub fn approach_path(
    from: &Pose,
    to: &Pose,
    curve: &CurveParams,
    spacing_m: f64,
    clear: &dyn Fn(&CurvePath) -> bool,
) -> Result<(CurvePath, Vec<DrivenPart>), ApproachError> {
    if !(curve.kappa_max.is_finite()
        && curve.kappa_max > 0.0
        && curve.sigma_max.is_finite()
        && curve.sigma_max > 0.0)
    {
        return Err(ApproachError::Limits {
            kappa_max: curve.kappa_max,
            sigma_max: curve.sigma_max,
        });
    }
    let path = connect(from, to, curve).ok_or(ApproachError::NoConnection)?;
    if !clear(&path) {
        return Err(ApproachError::Blocked);
    }
    let parts = split_at_cusps(&path, spacing_m);
    Ok((path, parts))
}

fn connect(from: &Pose, to: &Pose, curve: &CurveParams) -> Option<CurvePath> {
    super::cc_reeds_shepp::cc_reeds_shepp_shortest(from, to, curve)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geo::{wrap_angle, Direction};

    #[test]
    fn reaches_the_line_start_and_splits_at_cusps() {
        let curve = CurveParams {
            kappa_max: 0.2,
            sigma_max: 0.1,
        };
        let from = Pose::new(-3.0, -12.0, 0.0);
        let to = Pose::new(0.0, 0.0, std::f64::consts::FRAC_PI_2);
        let (path, parts) = approach_path(&from, &to, &curve, 0.5, &|_| true).unwrap();
        let end = path.end_pose();
        assert!((end.pos - to.pos).norm() < 1e-6);
        assert!(wrap_angle(end.heading - to.heading).abs() < 1e-6);
        assert_eq!(parts.len(), path.cusps() + 1);
        for w in parts.windows(2) {
            assert_ne!(w[0].direction, w[1].direction);
            assert!((w[0].points.last().unwrap() - w[1].points[0]).norm() < 1e-9);
        }
        assert!((parts.last().unwrap().points.last().unwrap() - to.pos).norm() < 1e-6);
        // Behind the start, facing away: the shortest way in reverses.
        let behind = Pose::new(0.0, 8.0, std::f64::consts::FRAC_PI_2);
        let (p2, parts2) = approach_path(&behind, &to, &curve, 0.5, &|_| true).unwrap();
        assert!(p2.reverse_length() > 7.0);
        assert_eq!(parts2[0].direction, Direction::Reverse);
        assert_eq!(
            approach_path(&from, &to, &curve, 0.5, &|_| false).unwrap_err(),
            ApproachError::Blocked
        );
    }
}
