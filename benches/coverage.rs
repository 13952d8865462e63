//! Field coverage planning: each stage and the whole plan for a 100 ha irregular 12-gon with
//! one obstacle (w = r_min = 6 m, 3 headland passes = 18 m), the whole plan at 10, 100 and
//! 1000 ha to show how it scales with field size, and the whole plan of every real field of
//! tools/fields/real/ up to 100 ha at widths 3, 6, 12 and 36 m and r_min 5 and 8 m with the
//! configuration's other defaults (issue 17 point 6: plan only, metrics separate).
//! `cargo bench --bench coverage -- coverage_real/FIELD` runs one field.

use agsteer::geo::{v2, Vec2};
use agsteer::plan::coverage::{
    decompose, headland, plan_field, swath_angle, swaths, CoverageParams, Field, RouteOrder,
    SwathAngle,
};
use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use std::hint::black_box;

/// A convex irregular 12-gon of about `hectares` ha with a 20 × 14 m obstacle inside.
fn twelve_gon(hectares: f64) -> Field {
    let radii = [
        1.00, 0.93, 1.08, 0.97, 1.05, 0.9, 1.02, 0.95, 1.1, 0.92, 1.0, 0.96,
    ];
    let pts: Vec<Vec2> = radii
        .iter()
        .enumerate()
        .map(|(i, r)| {
            let a = i as f64 * std::f64::consts::TAU / 12.0 + 0.1 * (i % 3) as f64;
            v2(r * a.cos() * 1.4, r * a.sin())
        })
        .collect();
    let hull = agsteer::plan::coverage::geometry::convex_hull(&pts);
    let area = agsteer::geo::polygon::signed_area(&hull);
    let k = (hectares * 1e4 / area).sqrt();
    let boundary: Vec<Vec2> = hull.iter().map(|p| p * k).collect();
    let c = v2(0.2 * k, 0.1 * k);
    let obstacle = vec![
        c + v2(-10.0, -7.0),
        c + v2(10.0, -7.0),
        c + v2(10.0, 7.0),
        c + v2(-10.0, 7.0),
    ];
    Field {
        boundary,
        obstacles: vec![obstacle],
    }
}

fn params() -> CoverageParams {
    CoverageParams {
        line_width: 6.0,
        r_min: 6.0,
        headland_passes: 3,
        point_spacing: 1.0,
        swath_angle: SwathAngle::MinTurns,
        route: RouteOrder::Auto,
        small_obstacle_max_m: 0.0,
        max_curvature_rate: 0.0,
        headland_order: Default::default(),
    }
}

fn stages(c: &mut Criterion) {
    let field = twelve_gon(100.0);
    let p = params();
    let mut g = c.benchmark_group("coverage_100ha");
    g.sample_size(20);
    g.bench_function("headland_tracks", |b| {
        b.iter(|| headland::headland_tracks(black_box(&field.boundary), &p))
    });
    g.bench_function("obstacle_tracks", |b| {
        b.iter(|| headland::obstacle_tracks(black_box(&field.obstacles), &p))
    });
    let working = headland::working_area(&field.boundary, &field.obstacles, &p);
    g.bench_function("working_area", |b| {
        b.iter(|| headland::working_area(black_box(&field.boundary), &field.obstacles, &p))
    });
    g.bench_function("swath_angle", |b| {
        b.iter(|| swath_angle::min_span(black_box(&working[0].0)))
    });
    g.bench_function("decompose", |b| {
        b.iter(|| decompose::convex_cells(black_box(&working[0].0)))
    });
    let angle = swath_angle::min_span(&working[0].0)
        .map(|s| s.0)
        .unwrap_or(0.0);
    g.bench_function("swaths", |b| {
        b.iter(|| swaths::swath_lines(black_box(&working[0]), &working, angle, 6.0))
    });
    g.bench_function("whole_plan", |b| {
        b.iter(|| plan_field(black_box(&field), &p))
    });
    // The same field with its 20 × 14 m obstacle passed on detours instead.
    let detour_params = CoverageParams {
        small_obstacle_max_m: 30.0,
        ..p.clone()
    };
    g.bench_function("whole_plan_obstacle_detoured", |b| {
        b.iter(|| plan_field(black_box(&field), &detour_params))
    });
    g.finish();
}

fn scaling(c: &mut Criterion) {
    let p = params();
    let mut g = c.benchmark_group("coverage_scaling");
    g.sample_size(10);
    for ha in [10.0, 100.0, 1000.0] {
        let field = twelve_gon(ha);
        g.bench_with_input(
            BenchmarkId::new("whole_plan_ha", ha as u64),
            &field,
            |b, f| b.iter(|| plan_field(black_box(f), &p)),
        );
    }
    g.finish();
}

fn real_fields(c: &mut Criterion) {
    let dir = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/tools/fields/real"));
    let mut files: Vec<std::path::PathBuf> = std::fs::read_dir(dir)
        .map(|d| d.filter_map(|e| e.ok().map(|e| e.path())).collect())
        .unwrap_or_default();
    files.retain(|p| p.extension().is_some_and(|e| e == "geojson"));
    files.sort();
    let cfg = agsteer::config::Config::default();
    let mut g = c.benchmark_group("coverage_real");
    g.sample_size(10);
    g.measurement_time(std::time::Duration::from_secs(1));
    g.warm_up_time(std::time::Duration::from_millis(200));
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
        for w in [3.0, 6.0, 12.0, 36.0] {
            for r in [5.0, 8.0] {
                let mut p = cfg.coverage_params();
                p.line_width = w;
                p.r_min = r;
                g.bench_with_input(
                    BenchmarkId::new(&name, format!("w{w}_r{r}")),
                    &loaded.field,
                    |b, f| b.iter(|| plan_field(black_box(f), &p)),
                );
            }
        }
    }
    g.finish();
}

criterion_group!(benches, stages, scaling, real_fields);
criterion_main!(benches);
