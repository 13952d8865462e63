//! The one place trackers are registered: the kinds the configuration names (`track.kind`),
//! their names and their constructors.
//!
//! To add a tracker: a variant of [`TrackerKind`] (its configuration name follows from serde's
//! snake case), its entry in [`TrackerKind::ALL`] and [`TrackerKind::name`], and its arm in
//! [`law`].

use super::law::{LawParams, SteeringLaw};
use super::lqr::Lqr;
use super::pure_pursuit::PurePursuit;
use super::stanley::Stanley;
use super::TrackerParams;
use serde::{Deserialize, Serialize};

/// Which tracker steers.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum TrackerKind {
    /// Pure pursuit on a latency-compensated, dead-reckoned pose (the default).
    #[default]
    Predictive,
    /// Plain seed-000 pure pursuit on the latest fix: the reference.
    PurePursuit,
    /// Stanley steering on the same latency-compensated, dead-reckoned pose.
    Stanley,
    /// A speed-scheduled LQR on the path-frame error model with the steering's lag in the
    /// state, and curvature feed-forward, on the predicted pose with every compensation.
    Lqr,
}

impl TrackerKind {
    /// Every tracker, the default first.
    pub const ALL: &'static [TrackerKind] = &[
        TrackerKind::Predictive,
        TrackerKind::PurePursuit,
        TrackerKind::Stanley,
        TrackerKind::Lqr,
    ];

    /// The configuration name (`track.kind`).
    pub fn name(self) -> &'static str {
        match self {
            TrackerKind::Predictive => "predictive",
            TrackerKind::PurePursuit => "pure_pursuit",
            TrackerKind::Stanley => "stanley",
            TrackerKind::Lqr => "lqr",
        }
    }
}

/// The law of `kind` with its gains, for the vehicle and steering of `tracker` at the control
/// period `dt` (s). Called when a job starts and when it is re-tuned, never per control period.
pub fn law(
    kind: TrackerKind,
    params: &LawParams,
    tracker: &TrackerParams,
    dt: f64,
) -> Box<dyn SteeringLaw> {
    match kind {
        TrackerKind::Predictive => Box::new(PurePursuit::predictive(
            params.predictive_ld_max,
            params.feed_forward,
        )),
        TrackerKind::PurePursuit => Box::new(PurePursuit::plain()),
        TrackerKind::Stanley => Box::new(Stanley::new(params)),
        TrackerKind::Lqr => Box::new(Lqr::new(params, tracker, dt)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_the_configuration_names() {
        for &k in TrackerKind::ALL {
            let toml = format!("kind = \"{}\"", k.name());
            #[derive(Deserialize)]
            struct T {
                kind: TrackerKind,
            }
            let t: T = toml::from_str(&toml).expect("the name parses");
            assert_eq!(t.kind, k);
        }
    }

    #[test]
    fn only_the_model_based_trackers_use_every_compensation() {
        let p = LawParams {
            predictive_ld_max: 4.5,
            feed_forward: true,
            stanley_gain: 2.5,
            stanley_soft_speed: 1.0,
            lqr: Default::default(),
            curvature: Default::default(),
        };
        let tracker = TrackerParams {
            wheelbase: 3.0,
            ld_min: 3.0,
            ld_gain: 1.2,
            max_wheel_angle: 0.6,
            steering: Default::default(),
        };
        let needs = |k| law(k, &p, &tracker, 0.02).needs();
        let d = needs(TrackerKind::Predictive);
        assert!(d.prediction && d.observer && d.integral && d.lost_motion);
        let r = needs(TrackerKind::PurePursuit);
        assert!(!r.prediction && !r.observer && !r.integral && !r.lost_motion);
        let s = needs(TrackerKind::Stanley);
        assert!(s.prediction && s.integral && !s.observer && !s.lost_motion);
        let q = needs(TrackerKind::Lqr);
        assert!(q.prediction && q.observer && q.integral && q.lost_motion);
    }
}
