//! agsteerd's side of the calibration mode (issue 15 point 4): the node runs the procedure
//! ([`crate::control::node`]'s calibration mode); when it ends, the recorded procedure is
//! fitted on a thread of its own (a second or so of CPU: never in the control loop), the
//! fragment and the figures are written atomically into the state directory
//! ([`crate::store::calibration_file`]), and the node answers `done` or `failed` on the bus.
//! `agsteer status` shows the calibration under way and the last result.

use crate::calibrate::{CalibrationError, Figures, Session};
use crate::control::node::{CalibrationProgress, ControllerNode};
use serde::Serialize;
use std::path::PathBuf;
use std::sync::mpsc;

/// How the last calibration ended.
#[derive(Debug, Clone, Serialize)]
pub struct CalibrationOutcome {
    /// "done" or "refused".
    pub result: &'static str,
    /// Why it was refused (or why its files could not be written).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub figures: Option<Figures>,
    /// The TOML fragment for the configuration.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fragment: Option<String>,
    /// The files written in the state directory.
    pub files: Vec<String>,
}

/// The calibration as the status socket shows it.
#[derive(Debug, Serialize)]
pub struct CalibrationReply<'a> {
    /// "running", "fitting", "done" or "refused".
    pub state: &'static str,
    #[serde(flatten, skip_serializing_if = "Option::is_none")]
    pub progress: Option<CalibrationProgress>,
    #[serde(flatten, skip_serializing_if = "Option::is_none")]
    pub last: Option<&'a CalibrationOutcome>,
}

/// Fits finished calibrations and keeps the last result.
pub struct CalibrationRunner {
    state_dir: PathBuf,
    fitting: Option<mpsc::Receiver<CalibrationOutcome>>,
    last: Option<CalibrationOutcome>,
}

/// Fit `session` and write its result into `state_dir` (blocking: on the fitting thread).
pub fn fit_and_save(session: &Session, state_dir: &std::path::Path) -> CalibrationOutcome {
    match session.finish() {
        Ok(c) => {
            let figures = c.figures();
            let fragment = c.toml_fragment();
            let json = serde_json::json!({ "figures": figures, "fragment": fragment });
            match crate::store::calibration_file::save(state_dir, &fragment, &json.to_string()) {
                Ok(paths) => CalibrationOutcome {
                    result: "done",
                    reason: None,
                    figures: Some(figures),
                    fragment: Some(fragment),
                    files: paths.iter().map(|p| p.display().to_string()).collect(),
                },
                Err(e) => CalibrationOutcome {
                    result: "done",
                    reason: Some(format!("the result could not be saved: {e}")),
                    figures: Some(figures),
                    fragment: Some(fragment),
                    files: Vec::new(),
                },
            }
        }
        Err(e) => refused(&e),
    }
}

/// The fit's thread under the normal scheduler, niced (see [`super::run::normal_scheduling`]).
fn normal_scheduling() {
    if let Err(e) = super::run::normal_scheduling(10) {
        tracing::warn!("calibration fit: cannot lower its scheduling: {e}");
    }
}

fn refused(e: &CalibrationError) -> CalibrationOutcome {
    CalibrationOutcome {
        result: "refused",
        reason: Some(e.to_string()),
        figures: None,
        fragment: None,
        files: Vec::new(),
    }
}

impl CalibrationRunner {
    pub fn new(state_dir: PathBuf) -> Self {
        CalibrationRunner {
            state_dir,
            fitting: None,
            last: None,
        }
    }

    /// After a control period: hand an ended calibration to the fitting thread; take the
    /// thread's result. Nothing to do (the common case) costs two checks.
    pub fn poll(&mut self, node: &mut ControllerNode) {
        if let Some(rx) = &self.fitting {
            match rx.try_recv() {
                Ok(outcome) => {
                    self.fitting = None;
                    let saved = outcome.result == "done" && outcome.reason.is_none();
                    match &outcome.reason {
                        None => tracing::info!(files = ?outcome.files, "calibration saved"),
                        Some(r) => tracing::warn!("calibration: {r}"),
                    }
                    self.last = Some(outcome);
                    node.calibration_fitted(saved);
                }
                Err(mpsc::TryRecvError::Empty) => {}
                Err(mpsc::TryRecvError::Disconnected) => {
                    self.fitting = None;
                    self.last = Some(refused(&CalibrationError::NoData(
                        "the fitting thread ended without a result".into(),
                    )));
                    node.calibration_fitted(false);
                }
            }
        }
        match node.take_calibration() {
            None => {}
            Some(Err(e)) => self.last = Some(refused(&e)),
            Some(Ok(session)) => {
                let (tx, rx) = mpsc::sync_channel(1);
                let dir = self.state_dir.clone();
                let spawned = std::thread::Builder::new()
                    .name("agsteer-calibration".into())
                    .spawn(move || {
                        normal_scheduling();
                        let _ = tx.send(fit_and_save(&session, &dir));
                    });
                match spawned {
                    Ok(_) => self.fitting = Some(rx),
                    Err(e) => {
                        self.last = Some(refused(&CalibrationError::NoData(format!(
                            "cannot start the fitting thread: {e}"
                        ))));
                        node.calibration_fitted(false);
                    }
                }
            }
        }
    }

    /// For the status socket: the calibration under way, being fitted, or the last result.
    pub fn reply<'a>(&'a self, node: &ControllerNode) -> Option<CalibrationReply<'a>> {
        if let Some(p) = node.calibration_progress() {
            return Some(CalibrationReply {
                state: "running",
                progress: Some(p),
                last: None,
            });
        }
        if self.fitting.is_some() {
            return Some(CalibrationReply {
                state: "fitting",
                progress: None,
                last: None,
            });
        }
        self.last.as_ref().map(|l| CalibrationReply {
            state: l.result,
            progress: None,
            last: Some(l),
        })
    }
}
