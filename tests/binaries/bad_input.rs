//! The bad-input regression suite (issue 18): one case per class of bad input, each running the
//! release binary under an address-space cap (`setrlimit(RLIMIT_AS)`, as `prlimit --as` does)
//! and a time limit, asserting the exit status, that the message names the culprit, the CPU
//! time and the peak RSS (both from `wait4`). Time bounds are on CPU time (user + system), which
//! a loaded host does not inflate; the wall clock only kills a run that hangs (`HANG_FACTOR`
//! times its bound). Beyond the envelope (`agsteer::envelope`) the answer is a clear
//! error; never a panic, an out-of-memory kill or a hang.
//!
//! The corpora of the fuzz targets (`fuzz/corpus/<target>/`) are replayed through the same
//! entry points on stable Rust, and each target also gets arbitrary bytes from proptest.
//!
//! Run with `cargo test --release --test binaries bad_input::` (the time bounds assume a release build).

use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

#[allow(dead_code)]
#[path = "../../fuzz/src/entries.rs"]
mod entries;

/// Address-space cap of every run, bytes (the issue's 2 GB).
const AS_CAP: u64 = 2_000_000_000;
/// A refusal must come within this much CPU time, s (they take milliseconds in release).
const REFUSE_S: f64 = 20.0;
/// A run is killed as hung after this many times its bound of wall-clock time (generous: on a
/// loaded 2-core host the wall clock runs many times the CPU time).
const HANG_FACTOR: f64 = 10.0;
/// Peak RSS of a refusal, kB.
const REFUSE_RSS_KB: i64 = 300_000;

struct Outcome {
    code: Option<i32>,
    stdout: String,
    stderr: String,
    elapsed_s: f64,
    /// User + system CPU time of the run, s.
    cpu_s: f64,
    max_rss_kb: i64,
    timed_out: bool,
}

impl Outcome {
    /// A clear refusal: the given exit status, every `needles` in stderr, in time and memory.
    fn refused(&self, code: i32, needles: &[&str]) {
        let ctx = format!(
            "exit {:?} after {:.1} s ({:.1} s CPU), {} kB; stderr:\n{}\nstdout:\n{}",
            self.code,
            self.elapsed_s,
            self.cpu_s,
            self.max_rss_kb,
            self.stderr,
            &self.stdout[..self.stdout.len().min(2000)]
        );
        assert!(!self.timed_out, "timed out: {ctx}");
        assert_eq!(self.code, Some(code), "{ctx}");
        assert!(!self.stderr.contains("panicked"), "{ctx}");
        for n in needles {
            assert!(self.stderr.contains(n), "stderr lacks {n:?}: {ctx}");
        }
        assert!(self.cpu_s < REFUSE_S, "{ctx}");
        assert!(self.max_rss_kb < REFUSE_RSS_KB, "{ctx}");
    }
}

fn bin() -> &'static str {
    env!("CARGO_BIN_EXE_agsteer")
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Run `agsteer args` in `cwd` under the address-space cap, killed as hung after `HANG_FACTOR`
/// times `limit_s` of wall-clock time.
fn run_in(cwd: &Path, args: &[&str], limit_s: f64) -> Outcome {
    let dir = tempfile::tempdir().unwrap();
    let (out_path, err_path) = (dir.path().join("stdout"), dir.path().join("stderr"));
    let mut cmd = Command::new(bin());
    cmd.args(args)
        .current_dir(cwd)
        .env("RUST_BACKTRACE", "0")
        .stdin(Stdio::null())
        .stdout(std::fs::File::create(&out_path).unwrap())
        .stderr(std::fs::File::create(&err_path).unwrap());
    // SAFETY: only setrlimit between fork and exec (async-signal-safe).
    unsafe {
        cmd.pre_exec(|| {
            let lim = libc::rlimit {
                rlim_cur: AS_CAP,
                rlim_max: AS_CAP,
            };
            if libc::setrlimit(libc::RLIMIT_AS, &lim) != 0 {
                return Err(std::io::Error::last_os_error());
            }
            Ok(())
        });
    }
    let start = Instant::now();
    // Reaped by wait4 below (for its rusage), not by Child::wait.
    #[allow(clippy::zombie_processes)]
    let pid = cmd.spawn().unwrap().id() as libc::pid_t;
    let mut status = 0;
    // SAFETY: a zeroed rusage is a valid value for wait4 to fill.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    let mut timed_out = false;
    loop {
        // SAFETY: wait4 on our own child with valid out-pointers.
        let r = unsafe { libc::wait4(pid, &mut status, libc::WNOHANG, &mut usage) };
        if r == pid {
            break;
        }
        assert!(r >= 0, "wait4: {}", std::io::Error::last_os_error());
        if start.elapsed().as_secs_f64() > limit_s * HANG_FACTOR && !timed_out {
            timed_out = true;
            // SAFETY: signalling our own child, still unreaped.
            unsafe { libc::kill(pid, libc::SIGKILL) };
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    let elapsed_s = start.elapsed().as_secs_f64();
    let seconds = |t: libc::timeval| t.tv_sec as f64 + t.tv_usec as f64 * 1e-6;
    let cpu_s = seconds(usage.ru_utime) + seconds(usage.ru_stime);
    let code = libc::WIFEXITED(status).then(|| libc::WEXITSTATUS(status));
    Outcome {
        code,
        stdout: String::from_utf8_lossy(&std::fs::read(&out_path).unwrap()).into_owned(),
        stderr: String::from_utf8_lossy(&std::fs::read(&err_path).unwrap()).into_owned(),
        elapsed_s,
        cpu_s,
        max_rss_kb: usage.ru_maxrss,
        timed_out,
    }
}

fn run(args: &[&str]) -> Outcome {
    run_in(&root(), args, REFUSE_S)
}

fn write(dir: &Path, name: &str, text: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p.display().to_string()
}

/// A GeoJSON polygon of the given ring (lon, lat degrees).
fn geojson_polygon(rings: &[Vec<(f64, f64)>], obstacle_parts: &[Vec<(f64, f64)>]) -> String {
    let ring = |r: &Vec<(f64, f64)>| {
        let mut pts: Vec<String> = r.iter().map(|(x, y)| format!("[{x},{y}]")).collect();
        pts.push(pts[0].clone());
        format!("[{}]", pts.join(","))
    };
    let boundary: Vec<String> = rings.iter().map(ring).collect();
    let mut features = vec![format!(
        r#"{{"type":"Feature","properties":{{"name":"bad"}},"geometry":{{"type":"Polygon","coordinates":[{}]}}}}"#,
        boundary.join(",")
    )];
    if !obstacle_parts.is_empty() {
        let parts: Vec<String> = obstacle_parts
            .iter()
            .map(|r| format!("[{}]", ring(r)))
            .collect();
        features.push(format!(
            r#"{{"type":"Feature","properties":{{"obstacle":true}},"geometry":{{"type":"MultiPolygon","coordinates":[{}]}}}}"#,
            parts.join(",")
        ));
    }
    format!(
        r#"{{"type":"FeatureCollection","features":[{}]}}"#,
        features.join(",")
    )
}

/// Metres to degrees at 52° N (approximately; enough for sizes).
const M_PER_DEG_LAT: f64 = 111_250.0;
const M_PER_DEG_LON: f64 = 68_500.0;

fn rect(w_m: f64, h_m: f64) -> Vec<(f64, f64)> {
    let (dx, dy) = (w_m / M_PER_DEG_LON, h_m / M_PER_DEG_LAT);
    vec![
        (5.0, 52.0),
        (5.0 + dx, 52.0),
        (5.0 + dx, 52.0 + dy),
        (5.0, 52.0 + dy),
    ]
}

fn circle(n: usize, r_m: f64) -> Vec<(f64, f64)> {
    (0..n)
        .map(|k| {
            let a = std::f64::consts::TAU * k as f64 / n as f64;
            (
                5.0 + r_m * a.cos() / M_PER_DEG_LON,
                52.0 + r_m * a.sin() / M_PER_DEG_LAT,
            )
        })
        .collect()
}

// ---- candump logs and the DBC decoder -------------------------------------------------------

#[test]
fn dbc_decode_survives_non_ascii_hex_and_garbage() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("bad.log");
    let mut bytes = b"can0 123#0\xc3\xa90\n".to_vec(); // é inside the hex
    bytes.extend("can0 123#\u{ff11}\u{ff12}\n".as_bytes()); // full-width digits
    bytes.extend(b"(1.5) can0 18EFFF1C#+1\ncan0 -1#00\n\xff\xfe\x00#\n(nan) x 1#1\n");
    bytes.extend(std::iter::repeat_n(b'7', 200_000)); // one line over the line limit
    bytes.extend(b"\ncan0 0CF00400#0102030405060708\n");
    std::fs::write(&log, &bytes).unwrap();
    let o = run(&["dbc", "decode", log.to_str().unwrap()]);
    o.refused(0, &[]);
    let lines: Vec<&str> = o.stdout.lines().collect();
    assert_eq!(lines.len(), 8, "{}", o.stdout);
    assert!(lines[0].contains("not a candump line"), "{}", lines[0]);
    assert!(lines[1].contains("not a candump line"), "{}", lines[1]);
    assert!(
        lines[6].contains("over the limit of 65536 bytes"),
        "{}",
        lines[6]
    );
    assert!(lines[7].contains("0CF00400"), "{}", lines[7]);
}

#[test]
fn dbc_decode_refuses_a_directory_at_once() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path().display().to_string();
    run(&["dbc", "decode", &d]).refused(1, &[&d, "is a directory"]);
}

// ---- files given as configuration, field, log or progress ----------------------------------

#[test]
fn a_device_as_configuration_is_refused_before_reading() {
    run(&["check-config", "/dev/zero"]).refused(2, &["/dev/zero", "character device"]);
    run(&[
        "demo",
        "--config",
        "/dev/zero",
        "--out",
        "/nonexistent/never",
    ])
    .refused(1, &["/dev/zero", "character device"]);
}

#[test]
fn a_fifo_as_configuration_or_field_is_refused_without_waiting() {
    let dir = tempfile::tempdir().unwrap();
    let fifo = dir.path().join("fifo");
    let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
    // SAFETY: mkfifo on a NUL-terminated path we own.
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
    let f = fifo.display().to_string();
    run(&["check-config", &f]).refused(2, &[&f, "FIFO"]);
    let out = dir.path().join("out").display().to_string();
    run(&["plan", "--field", &f, "--out", &out]).refused(1, &[&f, "FIFO"]);
    run(&["dbc", "decode", &f]).refused(1, &[&f, "FIFO"]);
    assert!(
        !dir.path().join("out").exists(),
        "nothing written after a refusal"
    );
}

#[test]
fn a_huge_file_is_refused_from_its_size() {
    let dir = tempfile::tempdir().unwrap();
    let big = dir.path().join("big.toml");
    // Sparse: 100 MB that is never read.
    std::fs::File::create(&big)
        .unwrap()
        .set_len(100_000_000)
        .unwrap();
    let b = big.display().to_string();
    run(&["check-config", &b]).refused(2, &[&b, "100000000 bytes", "limit of 1048576"]);
    let out = dir.path().join("out").display().to_string();
    run(&["plan", "--field", &b, "--out", &out]).refused(1, &[&b, "limit of 16777216"]);
}

#[test]
fn a_directory_as_progress_file_is_refused_on_resume() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    std::fs::create_dir_all(out.join("progress.json")).unwrap();
    let o = out.display().to_string();
    run(&["demo", "--resume", "--out", &o]).refused(1, &["progress.json", "directory"]);
}

// ---- fields beyond the envelope ------------------------------------------------------------

fn plan_field(text: &str, set: &[&str]) -> Outcome {
    let dir = tempfile::tempdir().unwrap();
    let f = write(dir.path(), "field.geojson", text);
    let out = dir.path().join("out").display().to_string();
    let mut args = vec!["plan", "--field", &f, "--out", &out];
    for s in set {
        args.extend(["--set", s]);
    }
    run(&args)
}

#[test]
fn a_field_too_large_is_refused_naming_the_value_and_limit() {
    for (w, h) in [(100_000.0, 100_000.0), (100_000.0, 1_000.0)] {
        plan_field(&geojson_polygon(&[rect(w, h)], &[]), &[])
            .refused(1, &["extent", "over the limit of 20000 m"]);
    }
    // 20 × 5 km = 10 000 ha, inside the extent, but 3.3e7 points of work path at w 3 m.
    plan_field(&geojson_polygon(&[rect(19_900.0, 5_000.0)], &[]), &[])
        .refused(1, &["points", "4e6"]);
}

#[test]
fn a_fine_width_on_a_large_field_is_refused_naming_the_points() {
    // 1 000 ha at w 0.1 m: 1e8 points of work path.
    plan_field(
        &geojson_polygon(&[rect(3_162.0, 3_162.0)], &[]),
        &["job.line_width_m=0.1"],
    )
    .refused(1, &["job.line_width_m = 0.1", "points"]);
}

#[test]
fn a_boundary_of_too_many_vertices_is_refused_at_once() {
    plan_field(&geojson_polygon(&[circle(200_000, 500.0)], &[]), &[])
        .refused(1, &["positions in the file: 200001", "limit of 100000"]);
}

#[test]
fn a_boundary_of_many_vertices_is_simplified_and_planned() {
    let o = plan_field(
        &geojson_polygon(&[circle(50_000, 300.0)], &[]),
        &["job.line_width_m=12"],
    );
    assert_eq!(o.code, Some(0), "{}", o.stderr);
    assert!(o.cpu_s < 60.0, "{:.1} s CPU", o.cpu_s);
    assert!(o.stdout.contains("50001 →"), "{}", o.stdout);
}

#[test]
fn taskdata_of_too_many_points_is_refused_at_once() {
    let pts: String = (0..200_000)
        .map(|k| {
            let a = std::f64::consts::TAU * k as f64 / 200_000.0;
            format!(
                "<PNT A=\"2\" C=\"{}\" D=\"{}\"/>",
                52.0 + 500.0 * a.sin() / M_PER_DEG_LAT,
                5.0 + 500.0 * a.cos() / M_PER_DEG_LON
            )
        })
        .collect();
    let xml = format!(
        "<ISO11783_TaskData><PFD A=\"PFD1\" C=\"big\"><PLN A=\"1\"><LSG A=\"1\">{pts}</LSG></PLN></PFD></ISO11783_TaskData>"
    );
    let dir = tempfile::tempdir().unwrap();
    let f = write(dir.path(), "TASKDATA.XML", &xml);
    let out = dir.path().join("out").display().to_string();
    run(&["plan", "--field", &f, "--out", &out])
        .refused(1, &[&f, "positions in the file: 200000", "limit of 100000"]);
}

#[test]
fn too_many_obstacles_are_refused() {
    let field = rect(2_000.0, 2_000.0);
    let parts: Vec<Vec<(f64, f64)>> = (0..2_000)
        .map(|k| {
            let (x, y) = (
                5.0 + (50.0 + 40.0 * (k % 40) as f64) / M_PER_DEG_LON,
                52.0 + (50.0 + 35.0 * (k / 40) as f64) / M_PER_DEG_LAT,
            );
            let d = 5.0;
            vec![
                (x, y),
                (x + d / M_PER_DEG_LON, y),
                (x + d / M_PER_DEG_LON, y + d / M_PER_DEG_LAT),
            ]
        })
        .collect();
    plan_field(&geojson_polygon(&[field], &parts), &[])
        .refused(1, &["obstacles", "2000", "limit of 200"]);
}

#[test]
fn taskdata_entity_expansion_and_deep_nesting_are_refused() {
    let mut laughs = String::from("<?xml version=\"1.0\"?>\n<!DOCTYPE l [\n<!ENTITY l0 \"lol\">\n");
    for k in 1..10 {
        let prev = format!("&l{};", k - 1);
        laughs.push_str(&format!("<!ENTITY l{k} \"{}\">\n", prev.repeat(10)));
    }
    laughs.push_str("]>\n<ISO11783_TaskData>&l9;</ISO11783_TaskData>\n");
    let deep = format!("{}{}", "<a>".repeat(100_000), "</a>".repeat(100_000));
    // roxmltree refuses a DTD (so no entity is ever expanded) and parses deep nesting without
    // recursion (which then holds no boundary).
    for (text, why) in [
        (laughs, "XML with DTD detected"),
        (deep, "no partfield with a boundary"),
    ] {
        let dir = tempfile::tempdir().unwrap();
        let f = write(dir.path(), "TASKDATA.XML", &text);
        let out = dir.path().join("out").display().to_string();
        run(&["plan", "--field", &f, "--out", &out]).refused(1, &[&f, why]);
    }
}

// ---- configuration beyond the envelope -----------------------------------------------------

fn check(set: &[&str]) -> Outcome {
    let mut args = vec!["check-config", "config/demo.toml"];
    for s in set {
        args.extend(["--set", s]);
    }
    run(&args)
}

#[test]
fn nan_and_infinite_keys_are_refused() {
    check(&["maneuver.implement_width_m=nan"]).refused(2, &["maneuver.implement_width_m = NaN"]);
    check(&["maneuver.implement_width_m=inf"]).refused(2, &["maneuver.implement_width_m"]);
    check(&["sim.speed_min_kmh=nan"])
        .refused(2, &["sim.speed_min_kmh = NaN: must be a finite number"]);
    check(&["sim.speed_max_kmh=-inf"]).refused(2, &["sim.speed_max_kmh"]);
}

#[test]
fn integers_that_do_not_fit_are_refused_not_wrapped() {
    check(&["guidance.a=4294967297"]).refused(2, &["guidance.a = 4294967297"]);
    check(&["job.line_num=9223372036854775807"]).refused(2, &["job.line_num"]);
    check(&["daemon.realtime_priority=256"]).refused(2, &["realtime_priority"]);
}

#[test]
fn ab_lines_beyond_the_envelope_are_refused() {
    check(&["job.point_b_m=[0.0, 1e9]"]).refused(2, &["job.point_b_m", "20000"]);
    check(&["job.point_a_m=[1e15, 0.0]", "job.point_b_m=[1e15, 150.0]"])
        .refused(2, &["job.point_a_m", "50000"]);
    check(&["job.line_order=\"sequential\"", "job.line_num=100000"])
        .refused(2, &["job.line_num = 100000"]);
    check(&[
        "job.kind=\"arcs\"",
        "job.line_num=1000",
        "job.arc_radius_m=10000",
    ])
    .refused(2, &["job.line_num", "points"]);
    check(&["vehicle.r_min_m=100", "job.line_width_m=0.1"]).refused(2, &["lines per block"]);
}

#[test]
fn too_many_float_windows_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let windows: Vec<String> = (0..5_000).map(|k| format!("[{}.0, 1.0]", k * 10)).collect();
    let f = write(
        dir.path(),
        "c.toml",
        &format!("[sim]\ngnss_float_windows_s = [{}]\n", windows.join(", ")),
    );
    run(&["check-config", &f]).refused(2, &["sim.gnss_float_windows_s", "5000", "1000"]);
}

// ---- legitimately large work: progress and a memory bound ---------------------------------

/// Peak RSS bound of planning a 100 ha field at w 3 m (plan and metrics), kB.
const PLAN_100HA_RSS_KB: i64 = 600_000;

#[test]
fn a_large_legitimate_field_is_planned_within_the_memory_bound() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out").display().to_string();
    let f = root().join("tools/fields/irregular_100ha.geojson");
    let o = run_in(
        &root(),
        &[
            "plan",
            "--field",
            f.to_str().unwrap(),
            "--out",
            &out,
            "--set",
            "job.line_width_m=3",
        ],
        30.0,
    );
    assert_eq!(o.code, Some(0), "{}", o.stderr);
    assert!(o.max_rss_kb < PLAN_100HA_RSS_KB, "{} kB", o.max_rss_kb);
}

/// The README's figure: 1 000 ha at w 3 m shows progress on stderr and stays under 2 GB
/// (measured 1.34 GB peak RSS, about 70 s on the shared 2-core host). Takes minutes: run with
/// `cargo test --release --test binaries bad_input:: -- --ignored`.
#[test]
#[ignore]
fn the_1000_ha_field_at_3_m_shows_progress_under_the_memory_bound() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out").display().to_string();
    let f = root().join("tools/fields/large_1000ha.geojson");
    let o = run_in(
        &root(),
        &[
            "plan",
            "--field",
            f.to_str().unwrap(),
            "--out",
            &out,
            "--set",
            "job.line_width_m=3",
        ],
        90.0,
    );
    assert_eq!(o.code, Some(0), "{}", o.stderr);
    assert!(o.stderr.contains(" s …"), "no progress shown: {}", o.stderr);
    assert!(o.max_rss_kb < 1_900_000, "{} kB", o.max_rss_kb);
    eprintln!(
        "1000 ha at 3 m: {:.1} s, peak RSS {} kB",
        o.elapsed_s, o.max_rss_kb
    );
}

// ---- the command line ----------------------------------------------------------------------

#[test]
fn a_manoeuvre_beyond_the_envelope_is_refused() {
    run(&["maneuver", "--from", "0,0,0", "--to", "1e9,0,0"]).refused(
        1,
        &["(1000000000, 0) m: outside the local frame's ±50000 m"],
    );
    run(&["maneuver", "--from", "0,0,0", "--to", "0,3000,0"])
        .refused(1, &["3000 m apart", "at most 2000 m"]);
    run(&["maneuver", "--from", "1e15,0,0", "--to", "1e15,10,0"])
        .refused(1, &["outside the local frame"]);
}

// ---- nothing written outside the output directory ------------------------------------------

#[test]
fn an_svg_into_a_missing_directory_fails_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let svg = dir.path().join("missing/dir/m.svg").display().to_string();
    let o = run_in(
        dir.path(),
        &[
            "maneuver",
            "--config",
            root().join("config/demo.toml").to_str().unwrap(),
            "--from",
            "0,0,0",
            "--to",
            "20,0,0",
            "--svg",
            &svg,
        ],
        REFUSE_S,
    );
    o.refused(1, &["missing/dir/m.svg"]);
    let left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
    assert!(left.is_empty(), "{left:?}");
}

// ---- the README ----------------------------------------------------------------------------

#[test]
fn the_readme_shows_the_envelope_as_enforced() {
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    let table = agsteer::envelope::markdown_table();
    assert!(
        readme.contains(&table),
        "README.md lacks the envelope table:\n{table}"
    );
    for (name, _) in entries::TARGETS {
        assert!(
            readme.contains(&format!("`{name}`")),
            "README.md lacks fuzz target {name}"
        );
    }
}

#[test]
fn a_demo_writes_only_into_its_output_directory() {
    let dir = tempfile::tempdir().unwrap();
    let o = run_in(
        dir.path(),
        &[
            "demo",
            "--config",
            root().join("config/demo.toml").to_str().unwrap(),
            "--out",
            "out",
            "--set",
            "job.line_num=2",
        ],
        30.0,
    );
    assert_eq!(o.code, Some(0), "{}", o.stderr);
    let left: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(left, ["out"], "{left:?}");
    let mut written: Vec<_> = std::fs::read_dir(dir.path().join("out"))
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    written.sort();
    assert_eq!(written, ["progress.json", "report.json", "trace.svg"]);
}

// ---- the fuzz corpora and arbitrary bytes through every decoder ----------------------------

#[test]
fn every_fuzz_corpus_replays_without_panic() {
    let mut total = 0;
    for (name, f) in entries::TARGETS {
        let dir = root().join("fuzz/corpus").join(name);
        let Ok(files) = std::fs::read_dir(&dir) else {
            panic!("no corpus {}", dir.display());
        };
        let mut n = 0;
        for e in files {
            let p = e.unwrap().path();
            f(&std::fs::read(&p).unwrap());
            n += 1;
        }
        assert!(n > 0, "empty corpus {}", dir.display());
        total += n;
    }
    assert!(total >= entries::TARGETS.len());
}

mod arbitrary_bytes {
    use super::entries;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

        #[test]
        fn no_decoder_panics(target in 0..entries::TARGETS.len(), bytes in proptest::collection::vec(any::<u8>(), 0..512)) {
            (entries::TARGETS[target].1)(&bytes);
        }

        #[test]
        fn no_decoder_panics_on_mutated_corpus(target in 0..entries::TARGETS.len(), seed in any::<u64>(), flips in proptest::collection::vec((any::<u16>(), any::<u8>()), 1..8)) {
            let (name, f) = entries::TARGETS[target];
            let dir = super::root().join("fuzz/corpus").join(name);
            let mut files: Vec<_> = std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().path()).collect();
            files.sort();
            let mut bytes = std::fs::read(&files[(seed % files.len() as u64) as usize]).unwrap();
            for (at, b) in flips {
                if !bytes.is_empty() {
                    let i = at as usize % bytes.len();
                    bytes[i] = b;
                }
            }
            f(&bytes);
        }
    }
}
