//! Crash safety of the progress file: a writer killed (SIGKILL) at random moments while it
//! saves leaves the old or the new file, never a torn one, and the temp files it leaves are
//! swept on the next load.

use agsteer::guidance::progress::{Phase, Progress, PROGRESS_VERSION};
use agsteer::store::progress_file;
use rand::{Rng, SeedableRng};
use std::path::PathBuf;
use std::process::{Command, Stdio};
use std::time::Duration;

const CHILD_ENV: &str = "AGSTEER_STATE_FILES_CHILD_DIR";

/// The writer: saves the progress it finds with growing `lines_done`, as fast as it can, until
/// killed. Run by [`kill_during_write_leaves_old_or_new_file`] only.
#[test]
#[ignore = "the child process of kill_during_write_leaves_old_or_new_file"]
fn child_writer() {
    let Some(dir) = std::env::var_os(CHILD_ENV) else {
        return;
    };
    let path = progress_file::progress_path(&PathBuf::from(dir));
    let mut p = progress_file::load(&path).unwrap().expect("a template");
    loop {
        p.lines_done += 1;
        p.index_rank = p.lines_done % 7;
        progress_file::save(&path, &p).unwrap();
    }
}

#[test]
fn kill_during_write_leaves_old_or_new_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = progress_file::progress_path(dir.path());
    let template = Progress {
        version: PROGRESS_VERSION,
        job: agsteer::config::Config::default().job_definition(),
        index_block: 0,
        index_rank: 0,
        phase: Phase::Work,
        lines_done: 0,
        nudge_m: 0.0,
        line_worked_m: Some(12.5),
    };
    progress_file::save(&path, &template).unwrap();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(20);
    let mut last = 0;
    let mut temps_left = 0;
    // The writer's test name in this binary: its module path less the crate's name.
    let writer = match module_path!().split_once("::") {
        Some((_, module)) => format!("{module}::child_writer"),
        None => "child_writer".to_string(),
    };
    for kill in 0..20 {
        let mut child = Command::new(std::env::current_exe().unwrap())
            .args(["--ignored", "--exact", &writer, "--nocapture"])
            .env(CHILD_ENV, dir.path())
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        std::thread::sleep(Duration::from_millis(rng.gen_range(30..250)));
        child.kill().unwrap(); // SIGKILL
        child.wait().unwrap();
        temps_left += std::fs::read_dir(dir.path())
            .unwrap()
            .filter(|e| {
                e.as_ref()
                    .is_ok_and(|e| e.file_name().to_string_lossy().ends_with(".tmp"))
            })
            .count();
        let p = progress_file::load(&path)
            .unwrap_or_else(|e| panic!("kill {kill}: {e}"))
            .unwrap_or_else(|| panic!("kill {kill}: the progress file is gone"));
        assert!(
            p.lines_done >= last,
            "kill {kill}: went back from {last} to {}",
            p.lines_done
        );
        assert_eq!(p.index_rank, p.lines_done % 7 * u64::from(p.lines_done > 0));
        last = p.lines_done;
        assert!(
            std::fs::read_dir(dir.path()).unwrap().count() == 1,
            "kill {kill}: load left temp files"
        );
    }
    // The writers did write (each saves hundreds of times before it is killed).
    assert!(last > 20, "{last} saves");
    eprintln!("20 kills: {last} saves in all, {temps_left} temp files left by a kill and swept");
}
