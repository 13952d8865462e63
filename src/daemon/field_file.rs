//! Reading the field of a field job (`job.kind = "field"`, `job.field_path`). Done once at
//! start-up, before any control loop runs.
//!
//! A relative `job.field_path` is taken from the working directory, like every other path in
//! the configuration (`progress.state_dir`, `bus.status_socket`). Under systemd that is `/`
//! unless the unit sets `WorkingDirectory=`, so installed configurations use absolute paths.

use crate::config::{Config, JobKind};
use crate::field::job::{FieldJob, FieldJobError};
use std::path::PathBuf;

/// The field file of the configuration's job (`job.field_path`, as given).
pub fn field_path(cfg: &Config) -> PathBuf {
    PathBuf::from(&cfg.job.field_path)
}

/// Read `job.field_path`: the path and the text.
pub fn read_text(cfg: &Config) -> Result<(PathBuf, String), FieldJobError> {
    if cfg.job.kind != JobKind::Field {
        return Err(FieldJobError::NotAFieldJob);
    }
    let path = field_path(cfg);
    match crate::envelope::read_text(&path, crate::envelope::FileKind::Field) {
        Ok(text) => Ok((path, text)),
        Err(e) => Err(FieldJobError::Read {
            path,
            source: e.into_io(),
        }),
    }
}

/// Read, load and plan the configuration's field job.
pub fn load(cfg: &Config) -> Result<FieldJob, FieldJobError> {
    let (path, text) = read_text(cfg)?;
    FieldJob::from_text(cfg, &path, &text)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_missing_field_file_is_named() {
        let cfg = Config::parse_with(
            "[job]\nkind = \"field\"\nfield_path = \"/nonexistent/agsteer/field.geojson\"\n",
            &[],
        )
        .unwrap();
        let e = load(&cfg).unwrap_err();
        assert!(matches!(e, FieldJobError::Read { .. }), "{e:?}");
        assert!(
            e.to_string().contains("/nonexistent/agsteer/field.geojson"),
            "{e}"
        );
    }

    #[test]
    fn an_ab_job_has_no_field() {
        assert!(matches!(
            load(&Config::default()),
            Err(FieldJobError::NotAFieldJob)
        ));
    }
}
