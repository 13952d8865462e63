//! The exit statuses of `agsteer` and `agsteerd`, in one place.
//!
//! Every status but 0 says something went wrong, and each says what: a script (or a
//! technician) can tell "the job did not finish" from "the job finished but not within the
//! documented accuracy" from "progress was not saved" without reading the messages, which name
//! the cause on stderr. `agsteer --help`, `agsteerd --help` and README.md ("Exit statuses")
//! show [`TABLE`]; `tests/binaries/exit_codes.rs` checks each status from the real binaries and that
//! README.md shows this table.
//!
//! When a run has more than one of these outcomes, the status is the first in this order:
//! [`Exit::ProgressNotSaved`], [`Exit::NotFinished`], [`Exit::AccuracyNotMet`] (every one of
//! them is reported on stderr).

/// An exit status. The numbers are part of the interface: never renumber one.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u8)]
pub enum Exit {
    /// Done as asked.
    Success = 0,
    /// A run-time error: a file, socket, CAN interface or planner failed (the message names
    /// it).
    Error = 1,
    /// Usage or configuration: bad arguments, or an invalid configuration or file it names
    /// (key, value and limit named). `check-config` and `agsteerd --check` exit 2 on any
    /// problem.
    Invalid = 2,
    /// `agsteer maneuver`: no path found.
    NoPath = 3,
    /// `agsteer plan`: the plan breaks one of its guarantees (written for inspection, must not
    /// be driven).
    PlanViolation = 4,
    /// `agsteer plan`: no swath fits the field; a command that sets up a field job (`demo`): a
    /// field job with nothing to drive for that reason.
    NoSwath = 5,
    /// `agsteer demo`: the job did not finish (a fault stopped it, or time ran out);
    /// `agsteer accuracy`: a scenario of a tracker held to the limits did not finish.
    NotFinished = 6,
    /// `agsteer demo` / `accuracy`: the job finished, but the true XTE on work lines is
    /// outside the documented accuracy (`[acceptance]` limits, the figure and the limit
    /// named).
    AccuracyNotMet = 7,
    /// `agsteer demo`, `agsteerd` at shutdown: the job's progress could not be saved, so a
    /// resume would repeat or skip work.
    ProgressNotSaved = 8,
    /// `agsteer replay --strict`: a control period sends other frames than the log.
    ReplayDiffers = 9,
    /// `agsteer calibrate`: calibration refused (the vehicle moved too fast, the operator
    /// intervened, or the responses were inconsistent; the reason printed).
    CalibrationRefused = 10,
}

impl Exit {
    /// Every status, in numeric order.
    pub const ALL: [Exit; 11] = [
        Exit::Success,
        Exit::Error,
        Exit::Invalid,
        Exit::NoPath,
        Exit::PlanViolation,
        Exit::NoSwath,
        Exit::NotFinished,
        Exit::AccuracyNotMet,
        Exit::ProgressNotSaved,
        Exit::ReplayDiffers,
        Exit::CalibrationRefused,
    ];

    /// The number the process exits with.
    pub const fn code(self) -> u8 {
        self as u8
    }

    /// One line: what the status means.
    pub fn meaning(self) -> &'static str {
        match self {
            Exit::Success => "done as asked",
            Exit::Error => "run-time error (a file, socket, CAN interface or planner failed)",
            Exit::Invalid => "usage or configuration error (the key, value and limit named)",
            Exit::NoPath => "maneuver: no path found",
            Exit::PlanViolation => "plan: the plan breaks a guarantee (written, not to be driven)",
            Exit::NoSwath => "plan, demo: no swath fits the field",
            Exit::NotFinished => "demo, accuracy: the job did not finish",
            Exit::AccuracyNotMet => {
                "demo, accuracy: finished outside the documented accuracy ([acceptance])"
            }
            Exit::ProgressNotSaved => "demo, agsteerd: progress could not be saved",
            Exit::ReplayDiffers => "replay --strict: a control period differs from the log",
            Exit::CalibrationRefused => "calibrate: refused (the reason printed)",
        }
    }

    /// Which binaries exit with it.
    pub fn binaries(self) -> &'static str {
        match self {
            Exit::Success | Exit::Error | Exit::Invalid | Exit::ProgressNotSaved => {
                "agsteer, agsteerd"
            }
            _ => "agsteer",
        }
    }
}

impl From<Exit> for std::process::ExitCode {
    fn from(e: Exit) -> Self {
        std::process::ExitCode::from(e.code())
    }
}

/// The table for `--help` (plain text, one status a line).
pub fn help_table() -> String {
    let mut s = String::from("Exit status:\n");
    for e in Exit::ALL {
        s.push_str(&format!("  {}  {}\n", e.code(), e.meaning()));
    }
    s
}

/// The table for README.md (Markdown).
pub fn markdown_table() -> String {
    let mut s = String::from("| status | meaning | binaries |\n|---|---|---|\n");
    for e in Exit::ALL {
        s.push_str(&format!(
            "| {} | {} | {} |\n",
            e.code(),
            e.meaning(),
            e.binaries()
        ));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_status_is_listed_once_in_order() {
        for (i, e) in Exit::ALL.iter().enumerate() {
            assert_eq!(usize::from(e.code()), i, "{e:?}");
        }
        assert!(help_table().lines().count() == Exit::ALL.len() + 1);
    }
}
