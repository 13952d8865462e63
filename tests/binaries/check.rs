//! `agsteerd --check` loads everything the daemon loads at start-up through the daemon's own
//! start-up ([`agsteer::job::startup::load`]) and changes nothing on disk: one test per kind
//! of bad input, each naming the file (and the key) at fault.

use std::os::unix::fs::PermissionsExt;
use std::path::Path;
use std::process::Command;

/// `agsteerd --check --config CONFIG --set …` in the package root, with the state directory
/// and the status socket in `dir` unless `set` says otherwise: (exit code, stdout, stderr).
fn check(config: &str, dir: &Path, set: &[String]) -> (i32, String, String) {
    let mut args: Vec<String> = vec!["--config".into(), config.into(), "--check".into()];
    let mut all = vec![
        format!(
            "progress.state_dir={:?}",
            dir.join("state").display().to_string()
        ),
        format!(
            "bus.status_socket={:?}",
            dir.join("run/status.sock").display().to_string()
        ),
    ];
    all.extend(set.iter().cloned());
    for s in all {
        args.push("--set".into());
        args.push(s);
    }
    let out = Command::new(env!("CARGO_BIN_EXE_agsteerd"))
        .args(&args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("agsteerd runs");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn set(key: &str, path: &Path) -> String {
    format!("{key}={:?}", path.display().to_string())
}

/// The check fails (exit 2, not "valid") and its message names `what` and `key`.
fn fails_naming(r: (i32, String, String), what: &Path, key: &str) {
    let (code, out, err) = r;
    assert_eq!(code, 2, "{out}{err}");
    assert!(!out.contains(": valid"), "{out}");
    assert!(err.contains(&what.display().to_string()), "{err}");
    assert!(err.contains(key), "{err}");
}

#[test]
fn a_good_configuration_is_valid_and_says_what_the_daemon_would_do() {
    let dir = tempfile::tempdir().unwrap();
    let (code, out, err) = check("config/demo-field.toml", dir.path(), &[]);
    assert_eq!(code, 0, "{out}{err}");
    assert!(
        out.contains("field config/demo-field.geojson plans into"),
        "{out}"
    );
    assert!(out.contains("no progress in"), "{out}");
    assert!(out.contains(": valid"), "{out}");
    assert!(!out.contains("warning"), "{out}");
    // Nothing was created.
    assert!(!dir.path().join("state").exists());
    assert!(!dir.path().join("run").exists());
}

#[test]
fn a_bad_configuration_key_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let (code, out, err) = check(
        "config/demo.toml",
        dir.path(),
        &["vehicle.wheelbase_m=-1.0".into()],
    );
    assert_eq!(code, 2, "{out}{err}");
    assert!(err.contains("config/demo.toml"), "{err}");
    assert!(err.contains("vehicle.wheelbase_m"), "{err}");
}

#[test]
fn a_missing_or_malformed_field_file_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("none.geojson");
    fails_naming(
        check(
            "config/demo-field.toml",
            dir.path(),
            &[set("job.field_path", &missing)],
        ),
        &missing,
        "job.field_path",
    );
    let bad = dir.path().join("bad.geojson");
    std::fs::write(&bad, "{\"type\": \"FeatureCollection\", \"features\": [").unwrap();
    fails_naming(
        check(
            "config/demo-field.toml",
            dir.path(),
            &[set("job.field_path", &bad)],
        ),
        &bad,
        "job.field_path",
    );
}

#[test]
fn a_malformed_taskdata_file_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("TASKDATA.XML");
    std::fs::write(
        &bad,
        "<?xml version=\"1.0\"?>\n<ISO11783_TaskData><PFD A=\"PFD1\"",
    )
    .unwrap();
    fails_naming(
        check(
            "config/demo-field.toml",
            dir.path(),
            &[set("job.field_path", &bad)],
        ),
        &bad,
        "job.field_path",
    );
}

#[test]
fn a_malformed_manoeuvre_map_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("map.geojson");
    std::fs::write(&bad, "not json").unwrap();
    fails_naming(
        check(
            "config/demo-maneuver.toml",
            dir.path(),
            &[set("job.maneuver_map_path", &bad)],
        ),
        &bad,
        "job.maneuver_map_path",
    );
}

#[test]
fn a_missing_or_public_password_file_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let password = dir.path().join("ntrip-password");
    let ntrip = |file: &Path| {
        vec![
            "gnss.source=\"nmea0183\"".to_string(),
            "gnss.ntrip_host=\"caster.example\"".to_string(),
            "gnss.ntrip_mountpoint=\"MOUNT\"".to_string(),
            set("gnss.ntrip_password_file", file),
        ]
    };
    fails_naming(
        check("config/demo.toml", dir.path(), &ntrip(&password)),
        &password,
        "gnss.ntrip_password_file",
    );
    std::fs::write(&password, "secret\n").unwrap();
    std::fs::set_permissions(&password, std::fs::Permissions::from_mode(0o644)).unwrap();
    let r = check("config/demo.toml", dir.path(), &ntrip(&password));
    assert!(r.2.contains("chmod 600"), "{}", r.2);
    assert!(!r.2.contains("secret"), "the password was printed: {}", r.2);
    fails_naming(r, &password, "gnss.ntrip_password_file");
    std::fs::set_permissions(&password, std::fs::Permissions::from_mode(0o600)).unwrap();
    let (code, out, err) = check("config/demo.toml", dir.path(), &ntrip(&password));
    assert_eq!(code, 0, "{out}{err}");
    assert!(!out.contains("secret") && !err.contains("secret"));
}

#[test]
fn a_state_directory_that_is_a_file_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("state-file");
    std::fs::write(&file, "").unwrap();
    fails_naming(
        check(
            "config/demo.toml",
            dir.path(),
            &[set("progress.state_dir", &file)],
        ),
        &file,
        "progress.state_dir",
    );
    // Below a file, it can never be created either.
    fails_naming(
        check(
            "config/demo.toml",
            dir.path(),
            &[set("progress.state_dir", &file.join("agsteer"))],
        ),
        &file,
        "progress.state_dir",
    );
    // A directory every user may write in: saving refuses it, so progress is lost (warned).
    let open = dir.path().join("open");
    std::fs::create_dir(&open).unwrap();
    std::fs::set_permissions(&open, std::fs::Permissions::from_mode(0o777)).unwrap();
    let (code, out, err) = check(
        "config/demo.toml",
        dir.path(),
        &[set("progress.state_dir", &open)],
    );
    assert_eq!(code, 0, "{out}{err}");
    assert!(
        out.contains("warning: progress.state_dir") && out.contains(&open.display().to_string()),
        "{out}"
    );
    assert!(out.contains("777"), "{out}");
}

#[test]
fn a_corrupt_progress_file_is_named_and_left_alone() {
    let dir = tempfile::tempdir().unwrap();
    let state = dir.path().join("state");
    std::fs::create_dir(&state).unwrap();
    let progress = state.join("progress.json");
    std::fs::write(&progress, "{\"version\": 1, \"trunc").unwrap();
    let (code, out, err) = check("config/demo.toml", dir.path(), &[]);
    // The daemon would start (afresh, disengaged): a warning, not a failure.
    assert_eq!(code, 0, "{out}{err}");
    assert!(out.contains("warning"), "{out}");
    assert!(out.contains(&progress.display().to_string()), "{out}");
    assert!(out.contains("corrupt"), "{out}");
    assert_eq!(
        std::fs::read_to_string(&progress).unwrap(),
        "{\"version\": 1, \"trunc",
        "--check changed the progress file"
    );
    assert_eq!(std::fs::read_dir(&state).unwrap().count(), 1, "moved aside");
}

#[test]
fn a_status_socket_path_taken_by_a_file_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("status.sock");
    std::fs::write(&file, "not a socket").unwrap();
    fails_naming(
        check(
            "config/demo.toml",
            dir.path(),
            &[set("bus.status_socket", &file)],
        ),
        &file,
        "bus.status_socket",
    );
    assert!(file.exists(), "--check removed a file");
}
