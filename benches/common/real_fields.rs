//! The real-field cases of issue 17 point 6: every field of tools/fields/real/ up to 100 ha at
//! every implement width and turning radius. Shared by benches/coverage.rs and
//! examples/plan_times.rs (the same plans, timed by criterion or once each).

use agsteer::plan::coverage::{CoverageParams, Field};

/// Every real field of tools/fields/real/ up to 100 ha at every width and turning radius:
/// (name, field, params) in file order.
pub fn real_cases() -> Vec<(String, Field, CoverageParams)> {
    let dir = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/tools/fields/real"));
    let mut files: Vec<std::path::PathBuf> = std::fs::read_dir(dir)
        .map(|d| d.filter_map(|e| e.ok().map(|e| e.path())).collect())
        .unwrap_or_default();
    files.retain(|p| p.extension().is_some_and(|e| e == "geojson"));
    files.sort();
    let cfg = agsteer::config::Config::default();
    let mut cases = Vec::new();
    for path in files {
        let Ok(text) = std::fs::read_to_string(&path) else {
            continue;
        };
        let Ok(loaded) = agsteer::field::load_field(&text, &cfg.field_load_options()) else {
            continue;
        };
        if loaded.cleanup.area_after_m2 > 100e4 {
            continue;
        }
        let name = path
            .file_stem()
            .map(|s| s.to_string_lossy().to_string())
            .unwrap_or_default();
        for w in REAL_WIDTHS {
            for r in REAL_R_MINS {
                let mut p = cfg.coverage_params();
                p.line_width = w;
                p.r_min = r;
                cases.push((name.clone(), loaded.field.clone(), p));
            }
        }
    }
    cases
}

/// Implement widths and turning radii of the real-field group (issue 17 point 6), m.
pub const REAL_WIDTHS: [f64; 4] = [3.0, 6.0, 12.0, 36.0];
pub const REAL_R_MINS: [f64; 2] = [5.0, 8.0];
