//! Every real-set plan of `benches/coverage.rs` (tools/fields/real/ ≤ 100 ha at widths 3, 6,
//! 12, 36 m and r_min 5, 8 m), each planned once (or `AGSTEER_REPS` times, the least kept), in
//! thread CPU time: per plan its ms, segment count, length, warnings and a fingerprint of every
//! point (equal fingerprints: the same plan), then the total, median, worst and how many are
//! over 20 ms. Seconds where the criterion bench takes minutes, for A/B runs of two builds.
//! `cargo run --release --example plan_times [-- FILTER]` (FILTER: part of "field wW_rR").
use agsteer::plan::coverage::plan_field;

#[path = "../benches/common/real_fields.rs"]
mod real_fields;
use real_fields::real_cases;

/// The calling thread's CPU time, s.
fn thread_cpu() -> f64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: clock_gettime writes the given timespec.
    unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9
}

fn main() {
    let filter = std::env::args().nth(1).unwrap_or_default();
    let reps: usize = std::env::var("AGSTEER_REPS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1);
    let mut all = Vec::new();
    let mut total = 0.0;
    for (name, field, p) in real_cases() {
        let id = format!("{name} w{}_r{}", p.line_width, p.r_min);
        if !id.contains(&filter) {
            continue;
        }
        let mut best = f64::INFINITY;
        let mut segs = 0;
        let mut len = 0.0;
        let mut warns = 0;
        let mut fp = 0u64;
        let mut err = String::new();
        for _ in 0..reps {
            let t0 = thread_cpu();
            let plan = plan_field(&field, &p);
            let dt = thread_cpu() - t0;
            best = best.min(dt);
            match &plan {
                Ok(plan) => {
                    segs = plan.segments.len();
                    len = plan.segments.iter().map(|s| s.length()).sum::<f64>();
                    warns = plan.warnings.len();
                    fp = plan
                        .segments
                        .iter()
                        .flat_map(|s| s.points.iter())
                        .enumerate()
                        .fold(0u64, |h, (i, q)| {
                            h.rotate_left(5)
                                ^ (q.x.to_bits().wrapping_mul(31) ^ q.y.to_bits())
                                    .wrapping_add(i as u64)
                        });
                }
                Err(e) => err = format!("{e}"),
            }
            std::hint::black_box(&plan);
        }
        total += best;
        println!(
            "{:9.2} ms  {id}  segs {segs} len {len:.1} warn {warns} fp {fp:016x} {err}",
            best * 1e3
        );
        all.push(best);
    }
    all.sort_by(f64::total_cmp);
    if let (Some(m), Some(w)) = (all.get(all.len() / 2), all.last()) {
        println!(
            "SUMMARY n {} total {:.2} s median {:.2} ms worst {:.2} ms over20 {}",
            all.len(),
            total,
            m * 1e3,
            w * 1e3,
            all.iter().filter(|&&t| t > 0.020).count()
        );
    }
}
