//! The exit statuses of the real binaries (`src/exit.rs`): each one `agsteer` can give from a
//! situation made here, agsteerd's configuration status, the `--help` tables and README.md's.
//! (4, a plan breaking its guarantees, needs a faulty planner: `agsteer plan` maps it in
//! `src/bin/agsteer/plan_cmd.rs`; 9 is checked in `tests/binaries/replay.rs`; agsteerd's 1 and 8 need a
//! CAN interface: the VM suite.)

use agsteer::exit::Exit;
use std::path::Path;
use std::process::Command;

struct Run {
    code: i32,
    stdout: String,
    stderr: String,
}

fn run(bin: &str, args: &[&str]) -> Run {
    let out = Command::new(bin)
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("the binary runs");
    Run {
        code: out.status.code().unwrap_or(-1),
        stdout: String::from_utf8_lossy(&out.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&out.stderr).into_owned(),
    }
}

fn agsteer(args: &[&str]) -> Run {
    run(env!("CARGO_BIN_EXE_agsteer"), args)
}

impl Run {
    /// The status is `e` and stderr names every needle.
    fn is(&self, e: Exit, needles: &[&str]) {
        assert_eq!(
            self.code,
            i32::from(e.code()),
            "expected {e:?}\nstdout: {}\nstderr: {}",
            self.stdout,
            self.stderr
        );
        for n in needles {
            assert!(self.stderr.contains(n), "{n:?} not in {}", self.stderr);
        }
    }
}

/// `agsteer demo` of two lines into `out`, with `set` on top of config/demo.toml.
fn demo(out: &Path, set: &[&str]) -> Run {
    let out = out.display().to_string();
    let mut args = vec!["demo", "--out", &out, "--set", "job.line_num=2"];
    for s in set {
        args.extend(["--set", s]);
    }
    agsteer(&args)
}

#[test]
fn the_demo_exits_with_what_happened_to_its_job() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("d");
    demo(&out, &[]).is(Exit::Success, &[]);
    // The time budget ends the job half-way: not finished, named with the lines done.
    demo(&out, &["sim.max_time_s=30"]).is(Exit::NotFinished, &["did not finish", "/2 lines"]);
    // Finished, but a limit tighter than the tracking: the figure and the limit named.
    demo(&out, &["acceptance.xte_max_limit_m=0.001"]).is(
        Exit::AccuracyNotMet,
        &[
            "true max |XTE| on work lines",
            "0.10 cm",
            "acceptance.xte_max_limit_m",
        ],
    );
    // A stop asked for with --stop-after is not a failure.
    let r = agsteer(&[
        "demo",
        "--out",
        &out.display().to_string(),
        "--stop-after",
        "1",
    ]);
    r.is(Exit::Success, &["stopped after 1 line(s) as asked"]);
    // Progress cannot be saved (a directory where the file goes): 8, before accuracy.
    let blocked = dir.path().join("blocked");
    std::fs::create_dir_all(blocked.join("progress.json")).unwrap();
    demo(&blocked, &["acceptance.xte_max_limit_m=0.001"]).is(
        Exit::ProgressNotSaved,
        &["progress not saved", "progress.json", "accuracy not met"],
    );
}

#[test]
fn the_accuracy_suite_holds_the_tracker_under_test_to_the_limits() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().display().to_string();
    let suite = |tracker: &str, set: &[&str]| {
        let mut args = vec![
            "accuracy",
            "--config",
            "tools/scenarios/straight_4kmh.toml",
            "--tracker",
            tracker,
            "--out",
            &out,
            "--set",
            "job.line_num=2",
        ];
        for s in set {
            args.extend(["--set", s]);
        }
        agsteer(&args)
    };
    suite("predictive", &[]).is(Exit::Success, &["1 run(s) held"]);
    suite("predictive", &["acceptance.xte_rms_limit_m=0.001"]).is(
        Exit::AccuracyNotMet,
        &["straight_4kmh / predictive: accuracy not met: true XTE RMS"],
    );
    suite("stanley", &["sim.max_time_s=30"]).is(
        Exit::NotFinished,
        &["straight_4kmh / stanley: the job did not finish"],
    );
}

#[test]
fn configuration_and_usage_errors_exit_2_and_unreadable_files_1() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("d");
    demo(&out, &["guidance.a=0"]).is(Exit::Invalid, &["guidance.a = 0"]);
    demo(&out, &["gnss.baud=4294967297"]).is(
        Exit::Invalid,
        &["gnss.baud = 4294967297: must be an integer in 0..=4294967295"],
    );
    agsteer(&["demo", "--no-such-flag"]).is(Exit::Invalid, &["--no-such-flag"]);
    let missing = dir.path().join("missing.toml").display().to_string();
    agsteer(&["demo", "--config", &missing]).is(Exit::Error, &["missing.toml"]);
    let r = run(
        env!("CARGO_BIN_EXE_agsteerd"),
        &[
            "--config",
            "config/demo.toml",
            "--set",
            "isobus.function=256",
        ],
    );
    r.is(
        Exit::Invalid,
        &["isobus.function = 256: must be an integer in 0..=255"],
    );
}

#[test]
fn planning_commands_exit_with_their_own_statuses() {
    let dir = tempfile::tempdir().unwrap();
    // A corridor 4 m wide: no room to turn round.
    let map = dir.path().join("corridor.geojson");
    std::fs::write(
        &map,
        r#"{"type":"Feature","properties":{},"geometry":{"type":"Polygon","coordinates":[[[-20,-2],[20,-2],[20,2],[-20,2],[-20,-2]]]}}"#,
    )
    .unwrap();
    let map = map.display().to_string();
    let r = agsteer(&[
        "maneuver", "--map", &map, "--from", "0,0,0", "--to", "5,0,180",
    ]);
    assert!(r.stdout.contains("no path"), "{}", r.stdout);
    r.is(Exit::NoPath, &[]);
    // A field file of `dir` with the polygon `ring` (lon, lat), its path.
    let field_file = |name: &str, ring: &str| {
        let path = dir.path().join(name);
        let text = format!(
            r#"{{"type":"Feature","properties":{{}},"geometry":{{"type":"Polygon","coordinates":[{ring}]}}}}"#
        );
        std::fs::write(&path, text).unwrap();
        path.display().to_string()
    };
    let out = dir.path().join("plan").display().to_string();
    let demo_out = dir.path().join("demo").display().to_string();
    // The field demo on the field file at `field`.
    let demo = |field: &str| {
        let field_path = format!("job.field_path={field}");
        agsteer(&[
            "demo",
            "--config",
            "config/demo-field.toml",
            "--set",
            &field_path,
            "--out",
            &demo_out,
        ])
    };
    // A strip 3.3 m wide: no swath fits.
    let field = field_file(
        "strip.geojson",
        "[[5.0,52.0],[5.0015,52.0],[5.0015,52.00003],[5.0,52.00003],[5.0,52.0]]",
    );
    agsteer(&["plan", "--field", &field, "--out", &out]).is(Exit::NoSwath, &["no swath fits"]);
    // The same field as a field job: nothing to drive, the same status and reason (not "a
    // segment job needs at least one segment").
    let r = demo(&field);
    r.is(Exit::NoSwath, &["nothing to drive in", "no swath fits"]);
    assert!(!r.stderr.contains("segment job"), "{}", r.stderr);
    // A field 30 m by 41 m at w 12 m: no swath fits, and the one headland pass that does would
    // work 81 % of it. `plan` refuses it, and so does the field job (before session 39 the
    // demo drove the pass and exited 0).
    let small = field_file(
        "small.geojson",
        "[[5.0,52.0],[5.0006,52.0],[5.0006,52.00027],[5.0,52.00027],[5.0,52.0]]",
    );
    let words = [
        "no swath fits",
        "headland passes alone would work",
        "< 97 %",
    ];
    let config = "config/demo-field.toml";
    agsteer(&["plan", "--config", config, "--field", &small, "--out", &out])
        .is(Exit::NoSwath, &words);
    demo(&small).is(Exit::NoSwath, &words);
}

#[test]
fn the_tables_in_the_help_and_the_readme_are_the_code() {
    let help = agsteer::exit::help_table();
    for args in [
        &["--help"][..],
        &["demo", "--help"],
        &["accuracy", "--help"],
    ] {
        let r = agsteer(args);
        assert_eq!(r.code, 0);
        assert!(r.stdout.contains(&help), "{args:?}: {}", r.stdout);
    }
    let r = run(env!("CARGO_BIN_EXE_agsteerd"), &["--help"]);
    assert!(r.stdout.contains(&help), "{}", r.stdout);
    let readme =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("README.md")).unwrap();
    assert!(
        readme.contains(&agsteer::exit::markdown_table()),
        "README.md's exit-status table differs from src/exit.rs:\n{}",
        agsteer::exit::markdown_table()
    );
}

/// A field job is driven only when its plan keeps every guarantee: for each field, `agsteer
/// plan` (which writes a breaking plan for inspection and exits 4) and the job set-up of the
/// demo and of `agsteerd --check` agree — a plan that breaks a guarantee is refused with 4
/// (demo) or 2 (the daemon's check), naming the first violation; a clean plan is driven (its
/// first line started).
/// The fields are real parcels at the demo-field's implement (12 m, r_min 6 m); whichever of
/// them the planner gets right, the two answers must be the same.
#[test]
fn a_field_job_whose_plan_breaks_a_guarantee_is_refused_not_driven() {
    let dir = tempfile::tempdir().unwrap();
    let mut refused = 0;
    for name in ["at_invekos_hole", "ch_lwb_hole", "nl_brp_rect"] {
        let field = format!("tools/fields/real/{name}.geojson");
        let path = format!("job.field_path={field:?}");
        let out = dir.path().join(name).display().to_string();
        let plan = agsteer(&[
            "plan",
            "--config",
            "config/demo-field.toml",
            "--field",
            &field,
            "--out",
            &out,
        ]);
        let demo = agsteer(&[
            "demo",
            "--config",
            "config/demo-field.toml",
            "--out",
            &out,
            "--stop-after",
            "1",
            "--set",
            &path,
        ]);
        let state = dir.path().join(name).join("state").display().to_string();
        let socket = dir.path().join(name).join("s.sock").display().to_string();
        let check = run(
            env!("CARGO_BIN_EXE_agsteerd"),
            &[
                "--config",
                "config/demo-field.toml",
                "--check",
                "--set",
                &path,
                "--set",
                &format!("progress.state_dir={state:?}"),
                "--set",
                &format!("bus.status_socket={socket:?}"),
            ],
        );
        if plan.code == i32::from(Exit::PlanViolation.code()) {
            refused += 1;
            demo.is(Exit::PlanViolation, &["breaks", "guarantee", &field]);
            check.is(Exit::Invalid, &["breaks", "guarantee"]);
        } else {
            assert_eq!(plan.code, 0, "{name}: plan\n{}", plan.stderr);
            // Driven: how well is the tracker's business (exit 0, 6 or 7), not the plan's.
            assert!(
                demo.stderr.contains("line started") && demo.code != 4 && demo.code != 2,
                "{name}: demo exit {}\n{}",
                demo.code,
                demo.stderr
            );
            assert_eq!(check.code, 0, "{name}: check\n{}", check.stderr);
        }
    }
    eprintln!("{refused} of 3 field plans break a guarantee and were refused");
}
