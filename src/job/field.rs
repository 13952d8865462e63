//! A field job (`job.kind = "field"`): the configured field read (through [`crate::store`]),
//! loaded, its coverage planned and the plan turned into the segment job the guidance drives.
//! Part of the one job set-up ([`crate::job::prepare`]) of `agsteerd`, `agsteer demo` and
//! `agsteer sim`.
//!
//! Takes the resolved [`FieldPlanning`]; the planning itself is timed ([`FieldJob::plan_time`])
//! for the reports.

use crate::config::{Config, FieldPlanning, JobKind};
use crate::envelope::FileKind;
use crate::field::{load_field, FieldError, LoadedField};
use crate::geo::wgs84::LatLon;
use crate::geo::Vec2;
use crate::guidance::progress::JobDefinition;
use crate::plan::coverage::metrics::{plan_metrics, PlanMetrics};
use crate::plan::coverage::narrow::refusal;
use crate::plan::coverage::{plan_field, CoverageParams, FieldPlan};
use crate::plan::job::{JobPlan, SegmentJob};
use crate::plan::types::PlanError;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// Why the field job could not be prepared. Every variant names the field file; the detail is
/// the error's source.
#[derive(Debug, thiserror::Error)]
pub enum FieldJobError {
    #[error("job.kind is not \"field\": there is no field to load")]
    NotAFieldJob,
    #[error("cannot read the field file {} (job.field_path)", path.display())]
    Read {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("field file {} (job.field_path)", path.display())]
    Field {
        path: PathBuf,
        #[source]
        source: FieldError,
    },
    #[error("cannot plan the coverage of {} ([field], job.line_width_m, vehicle.r_min_m)", path.display())]
    Plan {
        path: PathBuf,
        #[source]
        source: PlanError,
    },
    /// The plan breaks a guarantee (a path point outside the field or in an obstacle, a
    /// working pass's implement over an edge, a curve tighter than r_min): never driven.
    #[error(
        "the coverage plan of {} breaks {count} guarantee(s), first: {first}; it is not driven \
         (`agsteer plan --field {}` draws and lists them)",
        path.display(),
        path.display()
    )]
    Violates {
        path: PathBuf,
        count: usize,
        first: Box<crate::plan::coverage::metrics::checks::Violation>,
    },
    /// The plan has nothing to drive (no swath, no headland pass fits), or no swath and
    /// headland passes that work too little of the field
    /// ([`crate::plan::coverage::narrow::HEADLAND_ONLY_MIN_WORKED`]).
    #[error("nothing to drive in {}: {reason}", path.display())]
    Empty { path: PathBuf, reason: String },
    #[error("the coverage plan of {} cannot be driven as a segment job", path.display())]
    Job {
        path: PathBuf,
        #[source]
        source: PlanError,
    },
}

/// Read, load and plan the field of `planning` (`job.field_path`).
pub fn load(planning: &FieldPlanning) -> Result<FieldJob, FieldJobError> {
    let path = &planning.path;
    let text =
        crate::store::read_input(path, FileKind::Field).map_err(|e| FieldJobError::Read {
            path: path.clone(),
            source: e.into_io(),
        })?;
    FieldJob::from_text(planning, path, &text)
}

/// [`load`] the configuration's field job; [`FieldJobError::NotAFieldJob`] for another kind.
pub fn load_config(cfg: &Config) -> Result<FieldJob, FieldJobError> {
    if cfg.job.kind != JobKind::Field {
        return Err(FieldJobError::NotAFieldJob);
    }
    load(&cfg.planning().field)
}

/// Load the field text read from `path` with the `[field]` loading options.
pub fn load_text(
    planning: &FieldPlanning,
    path: &Path,
    text: &str,
) -> Result<LoadedField, FieldJobError> {
    load_field(text, &planning.load)
        .and_then(|loaded| {
            crate::field::check_plan_size(&loaded, &planning.coverage)?;
            Ok(loaded)
        })
        .map_err(|source| FieldJobError::Field {
            path: path.to_path_buf(),
            source,
        })
}

/// A planned field job.
#[derive(Debug, Clone)]
pub struct FieldJob {
    /// The field file it was read from.
    pub path: PathBuf,
    /// The field in local ENU metres about [`LoadedField::origin`].
    pub loaded: LoadedField,
    /// The planner's parameters (from the configuration).
    pub params: CoverageParams,
    pub plan: FieldPlan,
    /// `plan` as the guidance drives it.
    pub job: SegmentJob,
    /// How long the coverage planning took (loading not included).
    pub plan_time: Duration,
}

impl FieldJob {
    /// Load the field text read from `path` and plan it.
    pub fn from_text(
        planning: &FieldPlanning,
        path: &Path,
        text: &str,
    ) -> Result<FieldJob, FieldJobError> {
        let loaded = load_text(planning, path, text)?;
        FieldJob::plan(&planning.coverage, path, loaded)
    }

    /// Plan a loaded field with the coverage parameters `params`.
    pub fn plan(
        params: &CoverageParams,
        path: &Path,
        loaded: LoadedField,
    ) -> Result<FieldJob, FieldJobError> {
        let start = Instant::now();
        let plan = plan_field(&loaded.field, params).map_err(|source| FieldJobError::Plan {
            path: path.to_path_buf(),
            source,
        })?;
        let plan_time = start.elapsed();
        // No swath: refused as `agsteer plan` refuses it, when nothing is planned or the
        // headland passes alone work less than `HEADLAND_ONLY_MIN_WORKED` of the field (their
        // metrics are cheap: such fields are small).
        let worked = (plan.swaths == 0 && !plan.segments.is_empty())
            .then(|| plan_metrics(&loaded.field, &plan, params.line_width).covered_fraction);
        if let Some(reason) = refusal(&loaded.field, params, &plan, worked) {
            return Err(FieldJobError::Empty {
                path: path.to_path_buf(),
                reason,
            });
        }
        // The independent checks (issue 17 point 2): the daemon, the demo and the simulator
        // never drive a plan that breaks a guarantee; `agsteer plan` writes it for inspection.
        let violations = crate::plan::coverage::metrics::checks::check_plan(
            &loaded.field,
            &plan,
            params.line_width,
            params.r_min,
        );
        if let Some(first) = violations.first() {
            return Err(FieldJobError::Violates {
                path: path.to_path_buf(),
                count: violations.len(),
                first: Box::new(first.clone()),
            });
        }
        let mut job = FieldJob::from_plan(path, loaded, params.clone(), plan)?;
        job.plan_time = plan_time;
        Ok(job)
    }

    /// A job from a plan made elsewhere (for example timed by the caller).
    pub fn from_plan(
        path: &Path,
        loaded: LoadedField,
        params: CoverageParams,
        plan: FieldPlan,
    ) -> Result<FieldJob, FieldJobError> {
        let job =
            SegmentJob::from_plan_segments(plan.segments.iter().cloned()).map_err(|source| {
                FieldJobError::Job {
                    path: path.to_path_buf(),
                    source,
                }
            })?;
        Ok(FieldJob {
            path: path.to_path_buf(),
            loaded,
            params,
            plan,
            job,
            plan_time: Duration::ZERO,
        })
    }

    /// The plan the guidance drives.
    pub fn job_plan(&self) -> JobPlan {
        JobPlan::Segments(self.job.clone())
    }

    /// The job definition saved with progress: the configuration's job keys and this plan's
    /// checksum. Progress saved under another definition must not be resumed.
    pub fn job_definition(&self, cfg: &Config) -> JobDefinition {
        super::identity::define(&cfg.planning(), &self.job_plan(), Some(self.origin()))
    }

    /// The ENU origin of the plan's coordinates. GNSS positions must be converted about this
    /// origin (it is `job.origin_*` only when `field.origin = "config"`).
    pub fn origin(&self) -> LatLon {
        self.loaded.origin
    }

    /// Outlines for drawing under a trace: the field boundary, the obstacles, then the
    /// working area's rings (outer rings and holes), local m.
    pub fn outlines(&self) -> Vec<Vec<Vec2>> {
        let field = &self.loaded.field;
        let mut out = vec![field.boundary.clone()];
        out.extend(field.obstacles.iter().cloned());
        for (outer, holes) in &self.plan.working_area {
            out.push(outer.clone());
            out.extend(holes.iter().cloned());
        }
        out
    }

    /// The plan's metrics (coverage from the implement footprint, lengths, curvature).
    pub fn metrics(&self) -> PlanMetrics {
        plan_metrics(&self.loaded.field, &self.plan, self.params.line_width)
    }

    /// A title for outputs: the field's name, else its file.
    pub fn title(&self) -> String {
        self.loaded
            .name
            .clone()
            .unwrap_or_else(|| self.path.display().to_string())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn demo_field_config() -> Config {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/config/demo-field.toml");
        Config::load(Path::new(path), &[]).expect("config/demo-field.toml is valid")
    }

    fn demo_field_text() -> String {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/config/demo-field.geojson");
        std::fs::read_to_string(path).expect("config/demo-field.geojson")
    }

    #[test]
    fn demo_field_config_loads_plans_and_builds_a_segment_job() {
        let cfg = demo_field_config();
        assert_eq!(cfg.job.kind, crate::config::JobKind::Field);
        let path = Path::new("demo-field.geojson");
        let fj = FieldJob::from_text(&cfg.planning().field, path, &demo_field_text())
            .expect("demo field plans");
        assert_eq!(fj.loaded.field.obstacles.len(), 1, "one power pole");
        assert!(
            fj.plan.swaths > 0 && fj.plan.cells > 0,
            "{:?}",
            fj.plan.cells
        );
        assert_eq!(fj.job.len(), fj.plan.segments.len());
        assert!(fj.job.len() > 10, "{} segments", fj.job.len());
        // Boundary, obstacle and at least one working-area ring.
        assert!(fj.outlines().len() >= 3);
        // The job definition carries this plan's checksum, and a controller accepts the job.
        let def = fj.job_definition(&cfg);
        assert_eq!(def.plan_checksum, Some(fj.job.checksum()));
        crate::control::Controller::new(&cfg.control_params(), fj.job_plan(), def, None)
            .expect("the controller takes the field job");
    }

    #[test]
    fn errors_name_the_file() {
        let cfg = demo_field_config();
        let path = Path::new("fields/broken.geojson");
        let e = FieldJob::from_text(&cfg.planning().field, path, "not a field").unwrap_err();
        assert!(matches!(e, FieldJobError::Field { .. }), "{e:?}");
        assert!(e.to_string().contains("fields/broken.geojson"), "{e}");
        assert!(e.to_string().contains("job.field_path"), "{e}");
    }

    #[test]
    fn a_missing_field_file_is_named() {
        let cfg = Config::parse_with(
            "[job]\nkind = \"field\"\nfield_path = \"/nonexistent/agsteer/field.geojson\"\n",
            &[],
        )
        .unwrap();
        let e = load_config(&cfg).unwrap_err();
        assert!(matches!(e, FieldJobError::Read { .. }), "{e:?}");
        assert!(
            e.to_string().contains("/nonexistent/agsteer/field.geojson"),
            "{e}"
        );
    }

    #[test]
    fn an_ab_job_has_no_field() {
        assert!(matches!(
            load_config(&Config::default()),
            Err(FieldJobError::NotAFieldJob)
        ));
    }
}
