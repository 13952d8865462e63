//! `agsteer status` against misbehaving status sockets: an overall deadline (a peer sending a
//! byte now and then cannot hold it), a reply size limit (a peer streaming without end cannot
//! grow it), and errors naming the socket and the limit.

use std::io::Write;
use std::os::unix::net::UnixListener;
use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

/// Serve one connection on `path` with `serve`, in a thread.
fn server(path: &Path, serve: fn(std::os::unix::net::UnixStream)) {
    let listener = UnixListener::bind(path).unwrap();
    std::thread::spawn(move || {
        if let Ok((s, _)) = listener.accept() {
            serve(s);
        }
    });
}

fn status(socket: &Path, timeout_s: &str) -> (i32, String, String, Duration) {
    let t0 = Instant::now();
    let out = Command::new(env!("CARGO_BIN_EXE_agsteer"))
        .args(["status", "--socket"])
        .arg(socket)
        .args(["--timeout-s", timeout_s])
        .output()
        .unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
        t0.elapsed(),
    )
}

#[test]
fn a_reply_is_printed() {
    let dir = tempfile::tempdir().unwrap();
    let sock = dir.path().join("status.sock");
    server(&sock, |mut s| {
        let _ = s.write_all(br#"{"state":"engaged","xte_m":0.01}"#);
    });
    let (code, out, err, _) = status(&sock, "2");
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("\"engaged\""), "{out}");
}

#[test]
fn a_trickling_peer_meets_the_overall_deadline() {
    let dir = tempfile::tempdir().unwrap();
    let sock = dir.path().join("status.sock");
    // One byte every 0.2 s for a minute: each read is quick, the whole never ends.
    server(&sock, |mut s| {
        for _ in 0..300 {
            if s.write_all(b" ").is_err() {
                return;
            }
            std::thread::sleep(Duration::from_millis(200));
        }
    });
    let (code, _, err, elapsed) = status(&sock, "1");
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains(&sock.display().to_string()) && err.contains("1 s"),
        "{err}"
    );
    // The deadline is 1 s; a loaded host gets 20 (the peer would go on for 60).
    assert!(elapsed < Duration::from_secs(20), "{elapsed:?}");
}

#[test]
fn a_silent_peer_meets_the_deadline() {
    let dir = tempfile::tempdir().unwrap();
    let sock = dir.path().join("status.sock");
    server(&sock, |_s| std::thread::sleep(Duration::from_secs(60)));
    let (code, _, err, elapsed) = status(&sock, "0.5");
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("0.5 s") && err.contains("status.sock"),
        "{err}"
    );
    assert!(elapsed < Duration::from_secs(20), "{elapsed:?}");
}

#[test]
fn an_endless_reply_is_cut_at_the_size_limit() {
    let dir = tempfile::tempdir().unwrap();
    let sock = dir.path().join("status.sock");
    server(&sock, |mut s| {
        let chunk = vec![b'x'; 64 * 1024];
        while s.write_all(&chunk).is_ok() {}
    });
    let (code, _, err, _) = status(&sock, "30");
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("1048576 bytes") && err.contains("status.sock"),
        "{err}"
    );
}

#[test]
fn no_socket_names_the_path() {
    let dir = tempfile::tempdir().unwrap();
    let sock = dir.path().join("absent.sock");
    let (code, _, err, _) = status(&sock, "2");
    assert_eq!(code, 1);
    assert!(err.contains("absent.sock"), "{err}");
}
