//! agsteerd's calibration result in its state directory (issue 15 point 4): `calibration.toml`,
//! the fragment the technician copies into the configuration, and `calibration.json`, the
//! figures with their standard deviations and the fragment. Each written atomically
//! ([`super::progress_file::save`]'s temp file, fsync and rename), on the daemon's fitting
//! thread, never in the control loop.

use super::progress_file::{save_bytes, ProgressFileError};
use std::path::{Path, PathBuf};

/// The fragment's file name in the state directory.
pub const TOML_FILE_NAME: &str = "calibration.toml";
/// The figures' file name in the state directory.
pub const JSON_FILE_NAME: &str = "calibration.json";

/// Write the fragment and the figures (`json`) into `state_dir`; the two paths written.
pub fn save(
    state_dir: &Path,
    fragment: &str,
    json: &str,
) -> Result<[PathBuf; 2], ProgressFileError> {
    let toml = state_dir.join(TOML_FILE_NAME);
    let figures = state_dir.join(JSON_FILE_NAME);
    save_bytes(&toml, ".calibration.toml.", fragment.as_bytes())?;
    save_bytes(&figures, ".calibration.json.", json.as_bytes())?;
    Ok([toml, figures])
}
