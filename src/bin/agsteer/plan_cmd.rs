//! `agsteer plan`: plan coverage of a field (GeoJSON or ISO 11783-10 TASKDATA) and write
//! `plan.geojson`, `plan.svg` and `metrics.json` into the output directory.

use agsteer::config::Config;
use agsteer::field::load_field;
use agsteer::field::output::{plan_geojson, plan_svg, PlanSummary};
use agsteer::plan::coverage::metrics::plan_metrics;
use agsteer::plan::coverage::{CoverageParams, Field, FieldPlan};
use anyhow::{Context, Result};
use std::path::Path;
use std::time::{Duration, Instant};

/// Run a step, reporting on stderr if it takes more than a second.
pub fn timed<T>(what: &str, f: impl FnOnce() -> T) -> (T, Duration) {
    let start = Instant::now();
    let done = std::sync::atomic::AtomicBool::new(false);
    let out = std::thread::scope(|s| {
        s.spawn(|| {
            let mut waited = 0;
            while !done.load(std::sync::atomic::Ordering::Relaxed) {
                std::thread::sleep(Duration::from_millis(100));
                waited += 100;
                if waited % 1000 == 0 && !done.load(std::sync::atomic::Ordering::Relaxed) {
                    eprintln!("{what}: {} s …", waited / 1000);
                }
            }
        });
        let out = f();
        // Timed here: leaving the scope waits for the watcher's current sleep (up to 100 ms).
        let elapsed = start.elapsed();
        done.store(true, std::sync::atomic::Ordering::Relaxed);
        (out, elapsed)
    });
    out
}

/// `agsteer plan`, with the coverage planner passed in.
pub fn run<E>(
    field_path: &Path,
    cfg: &Config,
    out: &Path,
    json: bool,
    planner: impl FnOnce(&Field, &CoverageParams) -> Result<FieldPlan, E>,
) -> Result<u8>
where
    E: std::error::Error + Send + Sync + 'static,
{
    let text = std::fs::read_to_string(field_path)
        .with_context(|| format!("reading field {}", field_path.display()))?;
    let loaded = load_field(&text, &cfg.field_load_options())
        .with_context(|| format!("field {}", field_path.display()))?;
    let params = cfg.coverage_params();
    let (plan, plan_time) = timed("planning", || planner(&loaded.field, &params));
    let plan = plan.with_context(|| format!("planning {}", field_path.display()))?;
    let (metrics, metrics_time) = timed("metrics", || {
        plan_metrics(&loaded.field, &plan, params.line_width)
    });
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let title = loaded
        .name
        .clone()
        .unwrap_or_else(|| field_path.display().to_string());
    let write = |name: &str, body: String| {
        std::fs::write(out.join(name), body)
            .with_context(|| format!("writing {}/{name}", out.display()))
    };
    write(
        "plan.geojson",
        plan_geojson(&loaded.field, &plan, loaded.origin, Some(&metrics)),
    )?;
    write(
        "plan.svg",
        plan_svg(&loaded.field, &plan, loaded.origin, Some(&metrics), &title),
    )?;
    let s = PlanSummary::new(&loaded, &plan, &metrics, plan_time, metrics_time);
    let summary_json = serde_json::to_string_pretty(&s)?;
    write("metrics.json", format!("{summary_json}\n"))?;
    if json {
        println!("{summary_json}");
    } else {
        println!(
            "{title}: {} cells, {} swaths, {} turns, {:.0} m total; covered {:.2} % of the working area, {:.2} % of the field; outside {:.3} m²; {:.0} ms",
            s.cells,
            s.swaths,
            s.turns,
            s.total_length_m,
            100.0 * s.covered_fraction,
            100.0 * s.field_covered_fraction,
            s.outside_area_m2,
            s.plan_time_ms
        );
        println!(
            "boundary clean-up: {} → {} vertices, area {:.1} → {:.1} m² (error {:.2} m², {:.4} %)",
            s.cleanup.vertices_before,
            s.cleanup.vertices_after,
            s.cleanup.area_before_m2,
            s.cleanup.area_after_m2,
            s.cleanup.area_error_m2,
            s.cleanup.area_error_pct
        );
        println!(
            "wrote {0}/plan.geojson, {0}/plan.svg, {0}/metrics.json",
            out.display()
        );
    }
    Ok(0)
}
