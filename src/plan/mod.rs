//! Global path planning. Every planner here is a pure function of its inputs: no I/O, no
//! clocks, no globals.

pub mod abline;
pub mod arcs;
pub mod coverage;
pub mod maneuver;
pub mod turns;

/// Why a plan cannot be made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PlanError {
    #[error("{name} = {value}: {rule}")]
    Invalid {
        name: &'static str,
        value: f64,
        rule: &'static str,
    },
    #[error("turn impossible ({reason}); lateral distance {distance:.3} m")]
    Turn { reason: &'static str, distance: f64 },
}

impl PlanError {
    /// `Ok` when `ok` and `value` is finite, else an `Invalid` error for `name`.
    pub(crate) fn check(name: &'static str, value: f64, ok: bool) -> Result<(), PlanError> {
        if ok && value.is_finite() {
            Ok(())
        } else {
            Err(PlanError::Invalid {
                name,
                value,
                rule: "must be finite and in range",
            })
        }
    }
}
