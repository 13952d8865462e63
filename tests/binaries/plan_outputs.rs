//! `agsteer plan` as a user runs it: the summary line names every violation and warning,
//! metrics.json holds the independent metrics and findings, plan.svg draws unworked and
//! unreachable ground; TASKDATA as terminals write it (issue 17 points 4 and 7).
//!
//! Plans at w 12 m (a few seconds in release, most of it the metrics).

use std::path::Path;
use std::process::Command;

struct Run {
    code: i32,
    stdout: String,
    stderr: String,
}

fn agsteer(args: &[&str]) -> Run {
    let out = Command::new(env!("CARGO_BIN_EXE_agsteer"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("agsteer runs");
    Run {
        code: out.status.code().unwrap_or(-1),
        stdout: String::from_utf8_lossy(&out.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&out.stderr).into_owned(),
    }
}

/// Plan `field` (relative to the crate) at w 12 m into a temporary directory; returns the run
/// and metrics.json (Null when not written).
fn plan(field: &str, extra: &[&str]) -> (Run, serde_json::Value, String, tempfile::TempDir) {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().display().to_string();
    let mut args = vec![
        "plan",
        "--field",
        field,
        "--out",
        &out,
        "--set",
        "job.line_width_m=12",
    ];
    args.extend_from_slice(extra);
    let run = agsteer(&args);
    let metrics = std::fs::read_to_string(dir.path().join("metrics.json"))
        .map(|t| serde_json::from_str(&t).unwrap())
        .unwrap_or(serde_json::Value::Null);
    let svg = std::fs::read_to_string(dir.path().join("plan.svg")).unwrap_or_default();
    (run, metrics, svg, dir)
}

/// The summary line names every warning and violation of metrics.json; a violation is
/// never exit 0.
fn summary_names_every_finding(run: &Run, m: &serde_json::Value) {
    let line = run.stdout.lines().next().unwrap_or("");
    for w in m["warnings"].as_array().unwrap() {
        assert!(line.contains(w.as_str().unwrap()), "{w} not in {line}");
    }
    let violations = m["violations"].as_array().unwrap();
    if violations.is_empty() {
        assert!(line.contains("violations: none"), "{line}");
        assert_eq!(run.code, 0, "{}", run.stderr);
    } else {
        assert!(
            line.contains(&format!("VIOLATIONS {}", violations.len())),
            "{line}"
        );
        assert_eq!(run.code, 4, "a violation exits 4: {}", run.stderr);
        assert_eq!(
            run.stderr.matches("violation: ").count(),
            violations.len(),
            "each violation on stderr"
        );
    }
}

#[test]
fn the_outputs_name_every_figure_and_finding() {
    let (run, m, svg, _dir) = plan("tools/fields/rectangle.geojson", &[]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    summary_names_every_finding(&run, &m);
    // The independent metrics under their own names.
    for key in [
        "covered_fraction",
        "working_area_covered_fraction",
        "unworked_area_m2",
        "overlap_fraction",
        "outside_area_m2",
        "outside_length_m",
        "obstacle_intrusions",
        "obstacle_length_m",
        "obstacle_footprint_m2",
        "max_curvature",
        "turn_points_outside",
        "unworked_pieces",
    ] {
        assert!(m[key].is_number(), "{key} missing: {m}");
    }
    assert_eq!(m["line_width_m"], 12.0);
    let counts = &m["violation_counts"];
    for kind in [
        "outside_boundary",
        "inside_obstacle",
        "footprint_not_clear",
        "curvature",
    ] {
        assert_eq!(counts[kind], 0, "{kind}");
    }
    // Four right-angle corners the implement cannot reach turning at r_min 5 m:
    // 4·(1 − π/4)·(5 + 6)² = 104 m², each named and hatched.
    assert_eq!(m["unreachable_pieces"], 4, "{m}");
    let unreachable = m["unreachable_area_m2"].as_f64().unwrap();
    assert!((unreachable - 104.0).abs() < 3.0, "{unreachable}");
    let line = run.stdout.lines().next().unwrap();
    assert!(line.contains("unreachable 104 m² in 4 place(s)"), "{line}");
    assert!(line.contains("in 4 places cannot be reached"), "{line}");
    assert!(svg.contains(r#"fill="url(#unreachable)""#));
    assert!(svg.contains(">violations: none</text>"));
    // Unworked ground is drawn red where there is some.
    let unworked = m["unworked_area_m2"].as_f64().unwrap();
    assert_eq!(
        svg.contains("fill-opacity=\"0.6\""),
        m["unworked_pieces"] != 0
    );
    assert!(unworked > 0.0);
}

fn taskdata(dir: &str) -> String {
    format!("tools/fields/taskdata/{dir}/TASKDATA.XML")
}

#[test]
fn taskdata_fields_are_listed_and_chosen_by_id_or_name() {
    let file = taskdata("topcon_farmfacts_2021");
    // --list: every partfield of the main file and its external files (XFR).
    let run = agsteer(&["plan", "--field", &file, "--list"]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    assert!(run.stdout.contains("15 fields"), "{}", run.stdout);
    assert!(run.stdout.contains("20 Arezzo Field 2019"));
    assert!(run.stdout.contains("PFD00000"), "the external file named");
    // Several fields and none chosen: refused naming them.
    let (run, m, _, _dir) = plan(&file, &[]);
    assert_eq!(run.code, 1);
    assert!(m.is_null());
    assert!(
        run.stderr.contains("9 fields with a boundary"),
        "{}",
        run.stderr
    );
    assert!(run.stderr.contains("--field-id"), "{}", run.stderr);
    // By name (any case): the field's AB line sets the swaths (12.6° north of east).
    let (run, m, _, _dir) = plan(&file, &["--field-id", "PFD1"]);
    assert!(run.stderr.contains("TestTrans_AB_2"), "{}", run.stderr);
    summary_names_every_finding(&run, &m);
    let angle = m["swath_angles_deg"][0].as_f64().unwrap().rem_euclid(180.0);
    assert!((angle - 12.6).abs() < 0.5, "{angle}");
    let (run, m, _, _dir) = plan(&file, &["--field-id", "20 arezzo field 2019"]);
    assert!(
        run.stdout.starts_with("20 Arezzo Field 2019: "),
        "{}",
        run.stdout
    );
    summary_names_every_finding(&run, &m);
    let run = agsteer(&["plan", "--field", &file, "--field-id", "PFD99"]);
    assert_eq!(run.code, 1);
    assert!(run.stderr.contains("no field \"PFD99\""), "{}", run.stderr);
    // A task file without a partfield: --list says so and fails, as planning it does.
    let dir = tempfile::tempdir().unwrap();
    let none = dir.path().join("TASKDATA.XML");
    std::fs::write(
        &none,
        r#"<ISO11783_TaskData VersionMajor="4"><CTR A="CTR1"/></ISO11783_TaskData>"#,
    )
    .unwrap();
    let none = none.to_string_lossy().to_string();
    let run = agsteer(&["plan", "--field", &none, "--list"]);
    assert_eq!(run.code, 1, "{}", run.stdout);
    assert!(
        run.stderr.contains("no partfield (PFD) in the file"),
        "{}",
        run.stderr
    );
    assert!(run.stdout.is_empty(), "{}", run.stdout);
}

#[test]
fn byte_order_marks_utf16_and_unused_elements_read_with_warnings() {
    for (dir, id) in [
        ("dev4ag_partfields_bom", Some("PFD12")),
        ("utf16_test1", Some("PFD2")),
        ("obstacle_line", None),
    ] {
        let file = taskdata(dir);
        let bytes = std::fs::read(Path::new(env!("CARGO_MANIFEST_DIR")).join(&file)).unwrap();
        let choose: Vec<&str> = id.map(|i| vec!["--field-id", i]).unwrap_or_default();
        let (run, m, svg, _dir) = plan(&file, &choose);
        assert!(!m.is_null(), "{dir}: {}", run.stderr);
        summary_names_every_finding(&run, &m);
        assert!(svg.starts_with("<svg"));
        match dir {
            "dev4ag_partfields_bom" => assert_eq!(&bytes[..3], [0xEF, 0xBB, 0xBF]),
            "utf16_test1" => assert_eq!(&bytes[..2], [0xFF, 0xFE]),
            _ => {
                // Skipped elements: warned on stderr, on the summary line, in metrics.json.
                let fence = "LSG 1 of type 7 (fence) skipped";
                assert!(run.stderr.contains(fence), "{}", run.stderr);
                let warnings = m["warnings"].to_string();
                assert!(warnings.contains(fence), "{warnings}");
                assert!(
                    warnings.contains("\\\"ditch\\\": no polygon exterior"),
                    "{warnings}"
                );
            }
        }
    }
}

/// `field.sections`: the summary line, the SVG and metrics.json say what the overlap counts,
/// and on a real parcel whose headland edges slant to the swaths (w 12 m) the sections lay
/// less twice and leave no more unworked.
#[test]
fn an_implement_with_sections_is_planned_and_measured_with_them() {
    let field = "tools/fields/real/be_vlg_concave.geojson";
    let (whole, mw, svg_whole, _d1) = plan(field, &[]);
    let (sectioned, ms, svg, _d2) = plan(field, &["--set", "field.sections=8"]);
    assert_eq!((whole.code, sectioned.code), (0, 0), "{}", sectioned.stderr);
    assert_eq!(mw["sections"], 1);
    assert_eq!(ms["sections"], 8);
    let line = sectioned.stdout.lines().next().unwrap_or("");
    assert!(line.contains("% (with 8 sections);"), "{line}");
    assert!(svg.contains("(with 8 sections)"));
    assert!(!svg_whole.contains("sections"));
    let f = |m: &serde_json::Value, k: &str| m[k].as_f64().unwrap();
    assert!(
        f(&ms, "overlap_fraction") < f(&mw, "overlap_fraction") - 0.02,
        "overlap {} → {}",
        f(&mw, "overlap_fraction"),
        f(&ms, "overlap_fraction")
    );
    assert!(f(&ms, "covered_fraction") >= f(&mw, "covered_fraction") - 1e-9);
    assert_eq!(f(&ms, "pass_overlap_m"), 0.0);
    // With passes over each other too, both are named and the overlap is the larger.
    let (both, mb, svg_both, _d3) = plan(
        field,
        &["--set", "field.sections=8", "--set", "field.overlap_m=0.2"],
    );
    assert_eq!(both.code, 0, "{}", both.stderr);
    assert_eq!(f(&mb, "pass_overlap_m"), 0.2);
    let line = both.stdout.lines().next().unwrap_or("");
    assert!(
        line.contains("% (with 8 sections, passes 0.20 m over each other);"),
        "{line}"
    );
    assert!(svg_both.contains("passes 0.20 m over each other"));
    assert!(f(&mb, "overlap_fraction") > f(&ms, "overlap_fraction"));
}
