//! Geometry shared by every stage: local ENU vectors, poses, angles and path points.
//!
//! Conventions (docs/CONVENTIONS.md, Units, Frames, Heading and Signs): metres and radians inside;
//! the local frame is ENU (x = East, y = North); heading is counter-clockwise from East in (-π, π];
//! positive curvature and positive front-wheel angle turn left.

pub mod polygon;
pub mod svg;
pub mod wgs84;

use serde::{Deserialize, Serialize};

/// A vector or point in the local ENU frame, metres (`x` = East, `y` = North).
pub type Vec2 = nalgebra::Vector2<f64>;

/// Shorthand constructor for [`Vec2`].
#[inline]
pub fn v2(x: f64, y: f64) -> Vec2 {
    Vec2::new(x, y)
}

/// The axis-aligned rectangle `[x0, x1] × [y0, y1]` as a counter-clockwise ring (a test
/// fixture shared by the planners' and the field reader's tests).
#[cfg(test)]
pub(crate) fn rect(x0: f64, y0: f64, x1: f64, y1: f64) -> Vec<Vec2> {
    vec![v2(x0, y0), v2(x1, y0), v2(x1, y1), v2(x0, y1)]
}

/// Wrap an angle to (-π, π].
#[inline]
pub fn wrap_angle(a: f64) -> f64 {
    use std::f64::consts::{PI, TAU};
    if a > -PI && a <= PI {
        return a;
    }
    let r = (a + PI).rem_euclid(TAU) - PI;
    if r <= -PI {
        r + TAU
    } else {
        r
    }
}

/// Unit vector of a heading (radians, CCW from East).
#[inline]
pub fn heading_vec(heading: f64) -> Vec2 {
    v2(heading.cos(), heading.sin())
}

/// Heading of a vector (radians, CCW from East).
#[inline]
pub fn vec_heading(v: &Vec2) -> f64 {
    v.y.atan2(v.x)
}

/// 2-D cross product (z component): positive when `b` is counter-clockwise of `a`.
#[inline]
pub fn cross(a: &Vec2, b: &Vec2) -> f64 {
    a.x * b.y - a.y * b.x
}

/// Sine and cosine of `a` (rad): a Taylor series while |a| ≤ 0.05 (a prediction step's heading
/// change; the error is below 1e-19 there), else `sin_cos`.
pub fn small_sin_cos(a: f64) -> (f64, f64) {
    if a.abs() > 0.05 {
        return a.sin_cos();
    }
    let a2 = a * a;
    let sin = a * (1.0 - a2 / 6.0 * (1.0 - a2 / 20.0 * (1.0 - a2 / 42.0 * (1.0 - a2 / 72.0))));
    let cos = 1.0 - a2 / 2.0 * (1.0 - a2 / 12.0 * (1.0 - a2 / 30.0 * (1.0 - a2 / 56.0)));
    (sin, cos)
}

/// `(sin θ, cos θ)` turned by the angle whose sine and cosine are `by`: (sin, cos) of θ + α.
pub fn rotate((sin, cos): (f64, f64), by: (f64, f64)) -> (f64, f64) {
    (sin * by.1 + cos * by.0, cos * by.1 - sin * by.0)
}

/// Left-hand normal (rotate +90°).
#[inline]
pub fn left_normal(v: &Vec2) -> Vec2 {
    v2(-v.y, v.x)
}

/// Position and heading of the vehicle reference point (centre of the rear axle).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Pose {
    /// Position in the local ENU frame, metres.
    pub pos: Vec2,
    /// Heading, radians CCW from East, in (-π, π].
    pub heading: f64,
}

impl Pose {
    pub fn new(x: f64, y: f64, heading: f64) -> Self {
        Pose {
            pos: v2(x, y),
            heading: wrap_angle(heading),
        }
    }
}

/// What a path point belongs to. The numeric values are the seed's tags.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
#[repr(u8)]
pub enum Tag {
    /// A work line (tag 0).
    Work = 0,
    /// A turn between work lines (tag 1).
    Turn = 1,
}

/// Driving direction along a path.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Direction {
    #[default]
    Forward,
    Reverse,
}

/// One point of a global path.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathPoint {
    /// Position, local ENU metres.
    pub pos: Vec2,
    /// Work or turn.
    pub tag: Tag,
    /// Driving direction at this point.
    pub direction: Direction,
}

impl PathPoint {
    pub fn work(pos: Vec2) -> Self {
        PathPoint {
            pos,
            tag: Tag::Work,
            direction: Direction::Forward,
        }
    }
    pub fn turn(pos: Vec2) -> Self {
        PathPoint {
            pos,
            tag: Tag::Turn,
            direction: Direction::Forward,
        }
    }
}

/// Length along a path of [`PathPoint`]s, m.
pub fn path_length(points: &[PathPoint]) -> f64 {
    points
        .windows(2)
        .map(|w| (w[1].pos - w[0].pos).norm())
        .sum()
}

/// Signed lateral offset of `p` from the infinite line through `a` with unit direction `dir`:
/// positive to the left of the direction of travel.
#[inline]
pub fn signed_offset(p: &Vec2, a: &Vec2, dir: &Vec2) -> f64 {
    cross(dir, &(p - a))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn wrap_angle_range() {
        for k in -10..10 {
            let a = 0.3 + k as f64 * 2.0 * PI;
            assert!((wrap_angle(a) - 0.3).abs() < 1e-9, "{a}");
        }
        assert_eq!(wrap_angle(PI), PI);
        assert!((wrap_angle(-PI) - PI).abs() < 1e-12);
        assert!((wrap_angle(3.0 * PI) - PI).abs() < 1e-9);
    }

    #[test]
    fn offset_sign_left_positive() {
        let a = v2(0.0, 0.0);
        let d = v2(1.0, 0.0);
        assert!(signed_offset(&v2(5.0, 1.0), &a, &d) > 0.0);
        assert!(signed_offset(&v2(5.0, -1.0), &a, &d) < 0.0);
    }
}
