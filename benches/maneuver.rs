//! Manoeuvre planning (docs/METHODS.md, Search): the whole seed-004 planner on each scenario of
//! tools/maneuvers/ with the default configuration plus the scenario's overlay, continuous
//! curvature. Target: < 100 ms each.

use agsteer::config::Config;
use agsteer::field::load_local_map;
use agsteer::job::maneuver::{collision_map, pose_of};
use agsteer::plan::maneuver::search::plan_maneuver;
use agsteer::plan::maneuver::steering::CcSteering;
use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;
use std::path::PathBuf;

#[derive(serde::Deserialize)]
struct Scenario {
    map: String,
    from: [f64; 3],
    to: [f64; 3],
    set: Vec<String>,
}

fn bench(c: &mut Criterion) {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tools/maneuvers");
    let mut g = c.benchmark_group("maneuver");
    // Every NAME.toml of tools/maneuvers/, sorted.
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .expect("tools/maneuvers")
        .filter_map(|e| {
            let path = e.expect("directory entry").path();
            if path.extension()? != "toml" {
                return None;
            }
            Some(path.file_stem()?.to_str()?.to_owned())
        })
        .collect();
    names.sort();
    for name in names {
        let text = std::fs::read_to_string(dir.join(format!("{name}.toml"))).expect("scenario");
        let s: Scenario = toml::from_str(&text).expect("scenario TOML");
        let cfg = Config::parse_with("", &s.set).expect("overlay");
        let field = load_local_map(&std::fs::read_to_string(dir.join(&s.map)).expect("map"))
            .expect("map GeoJSON");
        let map = collision_map(&cfg.planning().maneuver, Some(&field)).expect("map");
        let steer = CcSteering {
            params: cfg.maneuver_curve_params(),
        };
        let params = cfg.maneuver_params();
        let (from, to) = (pose_of(s.from), pose_of(s.to));
        g.bench_function(&name, |b| {
            b.iter(|| {
                let r = plan_maneuver(&map, &steer, &params, &from, &to).expect("valid");
                assert!(r.path.is_some());
                black_box(r)
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
