//! The `agsteer` binary: check-config, dbc encode/decode (with fast-packet reassembly across
//! lines), and the committed frame table.

use agsteer::can::fastpacket::split;
use agsteer::can::gnss::{fix_message, GnssPosition, METHOD_RTK_FLOAT};
use std::io::Write;
use std::process::{Command, Stdio};

fn agsteer(args: &[&str], stdin: &str) -> (i32, String, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_agsteer"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("agsteer runs");
    child
        .stdin
        .take()
        .unwrap()
        .write_all(stdin.as_bytes())
        .unwrap();
    let out = child.wait_with_output().unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn check_config_reports_every_problem_with_status_2() {
    let (code, out, _) = agsteer(&["check-config", "config/demo.toml"], "");
    assert_eq!(code, 0);
    assert!(out.contains("line_width_m = 3.0"));
    let (code, _, err) = agsteer(
        &[
            "check-config",
            "config/demo.toml",
            "--set",
            "guidance.a=0",
            "--set",
            "control.dt_s=2",
        ],
        "",
    );
    assert_eq!(code, 2);
    assert!(
        err.contains("guidance.a = 0: must be an integer >= 1"),
        "{err}"
    );
    assert!(
        err.contains("control.dt_s = 2: must be in 0.005..=0.3"),
        "{err}"
    );
    let (code, _, err) = agsteer(
        &["check-config", "config/demo.toml", "--set", "control.dtt=1"],
        "",
    );
    assert_eq!(code, 2);
    assert!(err.contains("dtt"), "{err}");
}

#[test]
fn dbc_encode_then_decode() {
    let (code, out, err) = agsteer(
        &[
            "dbc",
            "encode",
            "WheelAngle",
            "Angle=-12.34",
            "Status=2",
            "Counter=7",
        ],
        "",
    );
    assert_eq!(code, 0, "{err}");
    let line = format!("(12.5) vcan0 {}", out.trim());
    let (_, out, _) = agsteer(&["dbc", "decode"], &line);
    let v: serde_json::Value = serde_json::from_str(out.lines().next().unwrap()).unwrap();
    assert_eq!(v["name"], "WheelAngle");
    assert_eq!(v["t"], 12.5);
    assert!((v["signals"]["Angle"].as_f64().unwrap() + 12.34).abs() < 1e-9);
    assert_eq!(v["signals"]["Status"], 2.0);
    assert!(v.get("error").is_none());
    let (code, _, err) = agsteer(&["dbc", "encode", "WheelAngle", "Angle=123"], "");
    assert_ne!(code, 0);
    assert!(err.contains("out of range"), "{err}");
}

#[test]
fn dbc_decode_reassembles_129029_and_reports_bad_frames() {
    let g = GnssPosition {
        time_s: Some(1000.0),
        altitude_m: Some(10.0),
        satellites: Some(18),
        hdop: Some(0.8),
        pdop: Some(1.2),
        geoidal_separation_m: Some(45.0),
        ..fix_message(1, 52.000_000_123_4, 5.000_000_567_8, METHOD_RTK_FLOAT)
    };
    let mut frames = Vec::new();
    split(&g.encode(), 2, &mut frames);
    let hex = |f: &[u8; 8]| f.iter().map(|b| format!("{b:02X}")).collect::<String>();
    let mut log = String::new();
    for (k, f) in frames.iter().enumerate() {
        log.push_str(&format!("({}.0) vcan0 0DF8051C#{}\n", k, hex(f)));
    }
    // The same message with two frames swapped: rejected.
    split(&g.encode(), 3, &mut frames);
    let second: Vec<[u8; 8]> = frames[frames.len() / 2..].to_vec();
    for (k, f) in [0usize, 1, 3, 2, 4, 5, 6]
        .iter()
        .map(|&i| &second[i])
        .enumerate()
    {
        log.push_str(&format!("({}.5) vcan0 0DF8051C#{}\n", k, hex(f)));
    }
    let (code, out, _) = agsteer(&["dbc", "decode"], &log);
    assert_eq!(code, 0);
    let objs: Vec<serde_json::Value> = out
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    let whole: Vec<&serde_json::Value> = objs
        .iter()
        .filter(|o| o["name"] == "GnssPosition129029")
        .collect();
    assert_eq!(whole.len(), 1, "only the in-order message completes");
    assert!(
        (whole[0]["signals"]["latitude_deg"].as_f64().unwrap() - 52.000_000_123_4).abs() < 1e-12
    );
    assert_eq!(whole[0]["signals"]["method"], 5);
    assert!(objs
        .iter()
        .any(|o| o["error"].as_str().is_some_and(|e| e.contains("expected"))));
}

#[test]
fn dbc_decode_names_iso_11783_5_network_frames() {
    // A Request for Address Claimed, an Address Claimed (agsteer's default NAME) and a
    // Cannot Claim (from the null address): named, not "unknown".
    let log = "(1.0) can0 18EAFF2A#00EE00\n(1.1) can0 18EEFF2A#0100000000811420\n\
               (1.2) can0 18EEFFFE#0100000000811420\n";
    let (_, out, _) = agsteer(&["dbc", "decode"], log);
    let objs: Vec<serde_json::Value> = out
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(objs[0]["name"], "Request");
    assert_eq!(objs[0]["signals"]["pgn"], 0xEE00);
    assert_eq!(objs[1]["name"], "AddressClaimed");
    assert_eq!(objs[1]["signals"]["source"], 0x2A);
    assert_eq!(objs[1]["signals"]["function"], 129);
    assert_eq!(objs[1]["signals"]["identity_number"], 1);
    assert_eq!(objs[2]["name"], "CannotClaimAddress");
    assert!(objs.iter().all(|o| o.get("error").is_none()), "{out}");
}

#[test]
fn frames_table_is_up_to_date() {
    let committed =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/dbc/FRAMES.md")).unwrap();
    assert_eq!(
        committed,
        agsteer::can::codec::frames_markdown(),
        "dbc/FRAMES.md is stale: run `agsteer dbc table > dbc/FRAMES.md`"
    );
}

#[test]
fn maneuver_single_batch_and_bad_endpoint() {
    // Single: the three-point turn scenario, JSON.
    let (code, out, err) = agsteer(
        &[
            "maneuver",
            "--config",
            "config/demo.toml",
            "--map",
            "tools/maneuvers/three_point_turn.geojson",
            "--from",
            "20,3.5,0",
            "--to",
            "20,8.5,180",
            "--json",
        ],
        "",
    );
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["found"], true);
    assert!(v["cusps"].as_u64().unwrap() >= 1, "{v}");
    assert!(v["reverse_length_m"].as_f64().unwrap() > 0.0);
    let segs = v["segments"].as_array().unwrap();
    let sum: f64 = segs.iter().map(|s| s["length_m"].as_f64().unwrap()).sum();
    assert!((sum - v["length_m"].as_f64().unwrap()).abs() < 1e-6);
    assert!(segs.iter().any(|s| s["direction"] == "reverse"));
    assert!(v["max_curvature"].as_f64().unwrap() <= 0.2 + 1e-9);
    assert!(v["max_curvature_rate"].as_f64().unwrap() <= 0.1 + 1e-9);
    assert!(v["plan_time_ms"].as_f64().unwrap() >= 0.0);
    // --set reaches the planner: a larger radius is reported in the curvature.
    let (code, out, err) = agsteer(
        &[
            "maneuver",
            "--from",
            "0,0,0",
            "--to",
            "40,-20,-90",
            "--json",
            "--set",
            "vehicle.r_min_m=8",
            "--curve",
            "rs",
        ],
        "",
    );
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert!(
        (v["max_curvature"].as_f64().unwrap() - 0.125).abs() < 1e-9,
        "{v}"
    );
    assert_eq!(v["max_curvature_rate"], 0.0);

    // Batch: one JSON result per line, a bad endpoint reported in its line.
    let dir = tempfile::tempdir().unwrap();
    let batch = dir.path().join("b.jsonl");
    std::fs::write(
        &batch,
        "{\"from\":[20,3.5,0],\"to\":[20,8.5,180]}\n\n{\"from\":[5,6,0],\"to\":[40,6,0]}\n{\"from\":[5,6,0],\"to\":[59,6,0]}\n",
    )
    .unwrap();
    let (code, out, err) = agsteer(
        &[
            "maneuver",
            "--map",
            "tools/maneuvers/three_point_turn.geojson",
            "--batch",
            batch.to_str().unwrap(),
        ],
        "",
    );
    assert_eq!(code, 0, "{err}");
    let lines: Vec<serde_json::Value> = out
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(lines.len(), 3);
    assert_eq!(lines[0]["found"], true);
    assert_eq!(lines[1]["found"], true);
    assert_eq!(lines[1]["cusps"], 0);
    assert!((lines[1]["length_m"].as_f64().unwrap() - 35.0).abs() < 1e-6);
    assert_eq!(lines[2]["found"], false);
    assert_eq!(
        lines[2]["error"],
        "goal pose is invalid: the vehicle is not inside the map boundary"
    );

    // Single with a bad start: an error naming the endpoint, exit status 1.
    let (code, _, err) = agsteer(
        &[
            "maneuver",
            "--map",
            "tools/maneuvers/obstacle_slalom.geojson",
            "--from",
            "18,3,90",
            "--to",
            "66,10.5,0",
        ],
        "",
    );
    assert_eq!(code, 1);
    assert!(
        err.contains("start pose is invalid: the vehicle touches obstacle 0"),
        "{err}"
    );
}

#[test]
fn accuracy_runs_the_chosen_scenarios_and_writes_json_and_svgs() {
    let out = std::env::temp_dir().join(format!("agsteer-accuracy-{}", std::process::id()));
    let out_s = out.to_string_lossy().into_owned();
    let (code, stdout, err) = agsteer(
        &[
            "accuracy",
            "--config",
            "tools/scenarios/straight_4kmh.toml",
            "--tracker",
            "all",
            "--json",
            "--out",
            &out_s,
            "--set",
            "job.line_num=3",
        ],
        "",
    );
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(&stdout).expect("JSON on stdout");
    let rows = v.as_array().expect("an array");
    let trackers: Vec<&str> = rows.iter().filter_map(|r| r["tracker"].as_str()).collect();
    assert_eq!(trackers, ["predictive", "pure_pursuit", "stanley"]);
    for r in rows {
        assert_eq!(r["scenario"], "straight_4kmh");
        assert!(
            r["xte_rms_m"].as_f64().is_some_and(|x| x > 0.0 && x < 0.05),
            "{r}"
        );
        assert!(r["pass_to_pass_p95_m"].as_f64().is_some(), "{r}");
    }
    let svg = std::fs::read_to_string(out.join("straight_4kmh.svg")).expect("the SVG");
    assert_eq!(svg.matches("<path").count(), 3);
    assert!(out.join("accuracy.json").exists());
    let (code, _, err) = agsteer(&["accuracy", "--tracker", "nope", "--out", &out_s], "");
    assert_eq!(code, 1);
    assert!(err.contains("unknown tracker"), "{err}");
    let _ = std::fs::remove_dir_all(&out);
}

fn agsteerd(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_agsteerd"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("agsteerd runs");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// `agsteerd --check` sets the job up as the daemon would: a manoeuvre job's map is read and
/// the manoeuvre planned, and a missing map fails the check naming the file and the key.
#[test]
fn agsteerd_check_sets_up_the_manoeuvre_and_names_a_missing_map() {
    let (code, out, err) = agsteerd(&["--config", "config/demo-maneuver.toml", "--check"]);
    assert_eq!(code, 0, "{out}{err}");
    assert!(out.contains("manoeuvre on its map plans into"), "{out}");
    assert!(out.contains("valid"), "{out}");
    let (code, out, err) = agsteerd(&[
        "--config",
        "config/demo-maneuver.toml",
        "--check",
        "--set",
        "job.maneuver_map_path=\"/nonexistent/agsteer/map.geojson\"",
    ]);
    assert_eq!(code, 2, "{out}{err}");
    assert!(err.contains("/nonexistent/agsteer/map.geojson"), "{err}");
    assert!(err.contains("job.maneuver_map_path"), "{err}");
    assert!(!out.contains("valid"), "{out}");
}
