//! The range-check helpers every section's validation uses.
//!
//! A [`Checker`] collects [`Problem`]s (`key = value: rule`) in the order the checks run; it
//! never stops at the first one, so a technician sees every mistake of a file at once. Numbers
//! are printed as the technician wrote them (`2`, not `2.0`).

use super::Problem;

/// Collects the problems of one validation pass, in order.
#[derive(Default)]
pub(crate) struct Checker {
    pub(crate) problems: Vec<Problem>,
}

impl Checker {
    /// Record a problem with `key`, its `value` as printed and the `rule` it breaks.
    pub(crate) fn push(&mut self, key: &str, value: String, rule: &str) {
        self.problems.push(Problem {
            key: key.to_string(),
            value,
            rule: rule.to_string(),
        });
    }
    /// `v` must be finite and in `lo..=hi`.
    pub(crate) fn range(&mut self, key: &str, v: f64, lo: f64, hi: f64) {
        if !(v.is_finite() && v >= lo && v <= hi) {
            self.push(
                key,
                fmt_num(v),
                &format!("must be in {}..={}", fmt_num(lo), fmt_num(hi)),
            );
        }
    }
    /// `v` must be 0 (off) or finite and in `lo..=hi`.
    pub(crate) fn off_or_range(&mut self, key: &str, v: f64, lo: f64, hi: f64) {
        if !(v == 0.0 || (v.is_finite() && v >= lo && v <= hi)) {
            self.push(
                key,
                fmt_num(v),
                &format!("must be 0 (off) or in {}..={}", fmt_num(lo), fmt_num(hi)),
            );
        }
    }
    /// `v` must be two finite numbers (a local ENU point).
    pub(crate) fn finite2(&mut self, key: &str, v: [f64; 2]) {
        if !(v[0].is_finite() && v[1].is_finite()) {
            self.push(
                key,
                format!("{v:?}"),
                "must be two finite numbers [east, north]",
            );
        }
    }
}

/// The integer `v` must be in `lo..=hi`.
pub(crate) fn count(c: &mut Checker, key: &str, v: usize, lo: usize, hi: usize) {
    if !(lo..=hi).contains(&v) {
        c.push(
            key,
            v.to_string(),
            &format!("must be an integer in {lo}..={hi}"),
        );
    }
}

/// A number as a technician writes it: integers without a decimal point.
pub(crate) fn fmt_num(v: f64) -> String {
    if v.is_finite() && v == v.trunc() && v.abs() < 1e15 {
        format!("{}", v as i64)
    } else {
        format!("{v}")
    }
}
