//! `[acceptance]`: the documented accuracy a simulated run (`agsteer demo`, `agsteer accuracy`)
//! is held to. A run that finishes with its true XTE on work lines beyond one of these limits is
//! reported as a failure naming the figure and the limit (exit status 7), not as "finished".
//! The daemon does not read them.
//!
//! Owns the section's keys, their defaults and their range checks.

use super::check::Checker;
use serde::{Deserialize, Serialize};

/// `[acceptance]`: limits on the true |XTE| on work lines past the first 10 m of each (the
/// figures `agsteer demo` and `agsteer accuracy` report), m.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct AcceptanceConfig {
    /// RMS limit, m (0.001..=10). Default 0.02: the accuracy target of README.md
    /// ("Accuracy": RMS ≤ 2 cm).
    pub xte_rms_limit_m: f64,
    /// 95th-percentile limit, m (0.001..=10). Default 0.04 (p95 ≤ 4 cm).
    pub xte_p95_limit_m: f64,
    /// Largest |XTE| allowed, m (0.001..=10). Default 0.10.
    pub xte_max_limit_m: f64,
}

impl Default for AcceptanceConfig {
    fn default() -> Self {
        AcceptanceConfig {
            xte_rms_limit_m: 0.02,
            xte_p95_limit_m: 0.04,
            xte_max_limit_m: 0.10,
        }
    }
}

/// One figure of a run beyond its limit.
#[derive(Debug, Clone, PartialEq)]
pub struct AccuracyMiss {
    /// What was measured, e.g. "XTE RMS".
    pub figure: &'static str,
    /// The key of the limit.
    pub key: &'static str,
    pub value_m: f64,
    pub limit_m: f64,
}

impl std::fmt::Display for AccuracyMiss {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "true {} on work lines {:.2} cm is over the limit of {:.2} cm (acceptance.{})",
            self.figure,
            100.0 * self.value_m,
            100.0 * self.limit_m,
            self.key
        )
    }
}

impl AcceptanceConfig {
    /// Range checks of `[acceptance]`.
    pub(crate) fn validate(&self, c: &mut Checker) {
        c.range(
            "acceptance.xte_rms_limit_m",
            self.xte_rms_limit_m,
            0.001,
            10.0,
        );
        c.range(
            "acceptance.xte_p95_limit_m",
            self.xte_p95_limit_m,
            0.001,
            10.0,
        );
        c.range(
            "acceptance.xte_max_limit_m",
            self.xte_max_limit_m,
            0.001,
            10.0,
        );
    }

    /// The figures (m) beyond their limits; empty when the run is within all of them. A
    /// figure that is not a number counts as beyond.
    pub fn misses(&self, rms_m: f64, p95_m: f64, max_m: f64) -> Vec<AccuracyMiss> {
        [
            ("XTE RMS", "xte_rms_limit_m", rms_m, self.xte_rms_limit_m),
            ("XTE p95", "xte_p95_limit_m", p95_m, self.xte_p95_limit_m),
            ("max |XTE|", "xte_max_limit_m", max_m, self.xte_max_limit_m),
        ]
        .into_iter()
        .filter(|&(_, _, v, limit)| v.is_nan() || v > limit)
        .map(|(figure, key, value_m, limit_m)| AccuracyMiss {
            figure,
            key,
            value_m,
            limit_m,
        })
        .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_figure_over_its_limit_is_named_with_the_limit() {
        let a = AcceptanceConfig::default();
        assert!(a.misses(0.003, 0.006, 0.016).is_empty());
        let m = a.misses(2.44, 0.01, f64::NAN);
        assert_eq!(m.len(), 2, "{m:?}");
        assert_eq!(
            m[0].to_string(),
            "true XTE RMS on work lines 244.00 cm is over the limit of 2.00 cm (acceptance.xte_rms_limit_m)"
        );
        assert_eq!(m[1].key, "xte_max_limit_m");
    }
}
