//! The TASKDATA.XML `agsteer plan` writes, read back by an independent ISOXML reader (the
//! `isoxml` package from PyPI, which `.ci/run` installs) and by our own reader: the same field
//! boundary, obstacles and guidance lines.

use agsteer::config::Config;
use agsteer::field::output::plan_taskdata;
use agsteer::field::{load_field, GuidanceKind, LoadOptions};
use agsteer::plan::coverage::{plan_field, SegmentKind};
use std::path::Path;
use std::process::Command;

const READ_BACK: &str = r#"
import json, sys
from isoxml.util.isoxml_io import isoxml_from_text
task = isoxml_from_text(open(sys.argv[1], encoding="utf-8").read())
pfd = task.partfields[0]
pln = pfd.polygons[0]
rings = [[[float(p.north), float(p.east)] for p in lsg.points] for lsg in pln.line_strings]
lines = []
for ggp in pfd.guidance_groups:
    for gpn in ggp.guidance_patterns:
        pts = [[float(p.north), float(p.east)] for p in gpn.line_strings[0].points]
        lines.append({"type": int(gpn.type.value), "points": pts})
print(json.dumps({"name": pfd.designator, "area": int(pfd.area), "rings": rings, "lines": lines}))
"#;

fn python_isoxml() -> bool {
    Command::new("python3")
        .args(["-c", "import isoxml"])
        .output()
        .map(|o| o.status.success())
        .unwrap_or(false)
}

#[test]
fn exported_taskdata_reads_back_with_the_same_geometry() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tools/fields/pentagon_TASKDATA.XML");
    let loaded = load_field(
        &std::fs::read_to_string(&path).unwrap(),
        &LoadOptions::default(),
    )
    .unwrap();
    let plan = plan_field(&loaded.field, &Config::default().coverage_params()).unwrap();
    let xml = plan_taskdata(&loaded.field, &plan, loaded.origin, "pentagon");
    let frame = loaded.frame();
    let to_local = |lat: f64, lon: f64| {
        frame.to_enu(agsteer::geo::wgs84::LatLon {
            lat_deg: lat,
            lon_deg: lon,
        })
    };
    let passes: Vec<_> = plan
        .segments
        .iter()
        .filter(|s| matches!(s.kind, SegmentKind::Work | SegmentKind::Headland))
        .collect();

    // Our own reader: the same boundary and obstacles, one guidance line per pass.
    let opts = LoadOptions {
        origin: Some(loaded.origin),
        boundary_tolerance_m: 0.0,
    };
    let back = load_field(&xml, &opts).unwrap();
    assert_eq!(back.field.obstacles.len(), loaded.field.obstacles.len());
    for (a, b) in back.field.boundary.iter().zip(&loaded.field.boundary) {
        assert!((a - b).norm() < 1e-3, "{a:?} vs {b:?}");
    }
    assert_eq!(back.guidance.len(), passes.len());
    assert!(back.guidance.iter().any(|g| g.kind == GuidanceKind::AbLine));
    assert!(back.guidance.iter().any(|g| g.kind == GuidanceKind::Curve));

    if !python_isoxml() {
        eprintln!(
            "SKIPPED the independent reader: python3 with the `isoxml` package is not installed \
             (pip install isoxml; .ci/run installs it)"
        );
        return;
    }
    let dir = std::env::temp_dir().join(format!("agsteer_isoxml_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("TASKDATA.XML");
    std::fs::write(&file, &xml).unwrap();
    let out = Command::new("python3")
        .args(["-c", READ_BACK])
        .arg(&file)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "isoxml could not read the export: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(doc["name"], "pentagon");
    let rings = doc["rings"].as_array().unwrap();
    assert_eq!(rings.len(), 1 + loaded.field.obstacles.len());
    let expected = std::iter::once(&loaded.field.boundary).chain(loaded.field.obstacles.iter());
    for (ring, want) in rings.iter().zip(expected) {
        let pts = ring.as_array().unwrap();
        // Closed rings: the first point repeated last.
        assert_eq!(pts.len(), want.len() + 1);
        for (p, q) in pts.iter().zip(want) {
            let got = to_local(p[0].as_f64().unwrap(), p[1].as_f64().unwrap());
            assert!((got - q).norm() < 1e-3, "{got:?} vs {q:?}");
        }
    }
    let lines = doc["lines"].as_array().unwrap();
    assert_eq!(lines.len(), passes.len());
    for (line, seg) in lines.iter().zip(&passes) {
        let pts = line["points"].as_array().unwrap();
        let at = |v: &serde_json::Value| to_local(v[0].as_f64().unwrap(), v[1].as_f64().unwrap());
        match seg.kind {
            SegmentKind::Work => {
                assert_eq!(line["type"], 1);
                assert_eq!(pts.len(), 2);
                assert!((at(&pts[0]) - seg.points[0]).norm() < 1e-3);
                assert!((at(&pts[1]) - seg.points[seg.points.len() - 1]).norm() < 1e-3);
            }
            _ => {
                assert_eq!(line["type"], 3);
                assert_eq!(pts.len(), seg.points.len());
                for (p, q) in pts.iter().zip(&seg.points) {
                    assert!((at(p) - q).norm() < 1e-3);
                }
            }
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}
