//! Field coverage planning: each stage and the whole plan for a 100 ha irregular 12-gon with
//! one obstacle (w = r_min = 6 m, 3 headland passes = 18 m), the whole plan at 10, 100 and
//! 1000 ha to show how it scales with field size, and the whole plan of every real field of
//! tools/fields/real/ up to 100 ha at widths 3, 6, 12 and 36 m and r_min 5 and 8 m with the
//! configuration's other defaults (issue 17 point 6: plan only, metrics separate; thread CPU
//! time, with a summary line of the median and the worst).
//! `cargo bench --bench coverage -- coverage_real/FIELD` runs one field.

use agsteer::geo::{v2, Vec2};
use agsteer::plan::coverage::{
    decompose, headland, plan_field, swath_angle, swaths, CoverageParams, Field, RouteOrder,
    SwathAngle,
};
use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use std::hint::black_box;

#[path = "common/real_fields.rs"]
mod real_fields;
#[path = "common/thread_cpu.rs"]
mod thread_cpu;
use real_fields::{real_cases, REAL_R_MINS, REAL_WIDTHS};
use thread_cpu::ThreadCpu;

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
        sections: 1,
        overlap: 0.0,
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
        b.iter(|| {
            swaths::swath_lines(
                black_box(&working[0]),
                &working,
                angle,
                6.0,
                swaths::BAND_WIDENING,
                false,
            )
        })
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

/// Whole plans (no metrics) of every real field ≤ 100 ha at every width and r_min, in thread
/// CPU time; prints the median and the worst case over them after the group. Under `cargo
/// bench` every case; in test mode (`cargo test --benches`, nextest: each benchmark once)
/// every field at one of the width × r_min pairs in turn, so all fields and all pairs still
/// run, at an eighth of the cost.
fn real_fields(c: &mut Criterion<ThreadCpu>) {
    let args: Vec<String> = std::env::args().collect();
    let full = args.iter().any(|a| a == "--bench") && !args.iter().any(|a| a == "--test");
    let pairs = REAL_WIDTHS.len() * REAL_R_MINS.len();
    let mut g = c.benchmark_group("coverage_real");
    g.sample_size(10);
    g.measurement_time(std::time::Duration::from_secs(1));
    g.warm_up_time(std::time::Duration::from_millis(200));
    // Per case: thread CPU time per plan of every sample, s.
    let times: std::cell::RefCell<Vec<(String, Vec<f64>)>> = Default::default();
    for (k, (name, field, p)) in real_cases().into_iter().enumerate() {
        if !full && k % pairs != (k / pairs) % pairs {
            continue;
        }
        let id = format!("w{}_r{}", p.line_width, p.r_min);
        let slot = {
            let mut t = times.borrow_mut();
            t.push((format!("{name} {id}"), Vec::new()));
            t.len() - 1
        };
        g.bench_with_input(BenchmarkId::new(&name, id), &field, |b, f| {
            b.iter_custom(|iters| {
                let start = thread_cpu::thread_cpu();
                for _ in 0..iters {
                    let _ = black_box(plan_field(black_box(f), &p));
                }
                let spent = thread_cpu::thread_cpu().saturating_sub(start);
                times.borrow_mut()[slot]
                    .1
                    .push(spent.as_secs_f64() / iters.max(1) as f64);
                spent
            })
        });
    }
    g.finish();
    // The median sample of each case, then the median and the worst over the cases.
    let mut per_case: Vec<(f64, String)> = times
        .into_inner()
        .into_iter()
        .filter_map(|(id, mut t)| {
            t.sort_by(f64::total_cmp);
            t.get(t.len() / 2).map(|&m| (m, id))
        })
        .collect();
    per_case.sort_by(|a, b| a.0.total_cmp(&b.0));
    if let (Some(mid), Some(worst)) = (per_case.get(per_case.len() / 2), per_case.last()) {
        // Issue 17 point 6's target: every plan within 20 ms.
        let within = per_case.iter().filter(|c| c.0 <= 0.020).count();
        println!(
            "coverage_real: {} plans, median {:.2} ms, worst {:.2} ms ({}), {within} within 20 ms, thread CPU time",
            per_case.len(),
            mid.0 * 1e3,
            worst.0 * 1e3,
            worst.1
        );
    }
}

criterion_group!(benches, stages, scaling);
criterion_group! {
    name = real;
    config = Criterion::default().with_measurement(ThreadCpu);
    targets = real_fields
}
criterion_main!(benches, real);
