//! Helpers for the vcan tests: the interface, spawning programs, candump captures, link
//! up/down, and an echo latency baseline.

use agsteer::can::bus::{CanBus, SocketCanBus};
use agsteer::can::Frame;
use std::io::{BufRead, BufReader};
use std::process::{Child, Command, Stdio};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// The interface under test, or `None` (test skipped) outside the VM.
pub fn vcan() -> Option<String> {
    match std::env::var("AGSTEER_VCAN") {
        Ok(i) if !i.is_empty() => Some(i),
        _ => {
            println!("skipped: no AGSTEER_VCAN (run tools/vcan-vm)");
            None
        }
    }
}

/// Run a program to completion, asserting success.
pub fn run_ok(prog: &str, args: &[&str]) -> String {
    let out = Command::new(prog)
        .args(args)
        .output()
        .unwrap_or_else(|e| panic!("{prog}: {e}"));
    assert!(
        out.status.success(),
        "{prog} {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// Bring the interface down or up.
pub fn link(iface: &str, up: bool) {
    run_ok(
        "ip",
        &["link", "set", iface, if up { "up" } else { "down" }],
    );
}

/// A running `candump -L` capture.
pub struct Candump {
    child: Child,
    lines: Arc<Mutex<Vec<String>>>,
    reader: Option<std::thread::JoinHandle<()>>,
}

impl Candump {
    pub fn start(iface: &str) -> Candump {
        let mut child = Command::new("candump")
            .args(["-L", iface])
            .stdout(Stdio::piped())
            .spawn()
            .expect("candump");
        let out = child.stdout.take().expect("stdout");
        let lines = Arc::new(Mutex::new(Vec::new()));
        let l2 = lines.clone();
        let reader = std::thread::spawn(move || {
            for line in BufReader::new(out).lines().map_while(Result::ok) {
                l2.lock().unwrap().push(line);
            }
        });
        Candump {
            child,
            lines,
            reader: Some(reader),
        }
    }
    pub fn stop(mut self) -> Vec<String> {
        let _ = self.child.kill();
        let _ = self.child.wait();
        if let Some(r) = self.reader.take() {
            let _ = r.join();
        }
        let v = self.lines.lock().unwrap().clone();
        v
    }
}

/// Round-trip latency (s) of a trivial echo on the bus: a thread re-sends every frame with
/// id + 1. Returns (median, p99).
pub fn echo_latency(iface: &str, n: usize) -> (f64, f64) {
    let mut echo = SocketCanBus::open(
        iface,
        &[agsteer::can::bus::Filter {
            id: 0x0CFF5000,
            mask: 0x1FFFFFFF,
        }],
    )
    .unwrap();
    let stop = Arc::new(std::sync::atomic::AtomicBool::new(false));
    let s2 = stop.clone();
    let h = std::thread::spawn(move || {
        while !s2.load(std::sync::atomic::Ordering::Relaxed) {
            match echo.try_recv() {
                Ok(Some(f)) => {
                    let _ = echo.send(&Frame::new(f.frame.id + 1, f.frame.payload()));
                }
                _ => std::hint::spin_loop(),
            }
        }
    });
    let mut bus = SocketCanBus::open(
        iface,
        &[agsteer::can::bus::Filter {
            id: 0x0CFF5001,
            mask: 0x1FFFFFFF,
        }],
    )
    .unwrap();
    let mut lat = Vec::with_capacity(n);
    for k in 0..n {
        let t0 = Instant::now();
        bus.send(&Frame::new(0x0CFF5000, &(k as u64).to_le_bytes()))
            .unwrap();
        loop {
            if let Ok(Some(_)) = bus.try_recv() {
                break;
            }
            if t0.elapsed() > Duration::from_secs(1) {
                break;
            }
        }
        lat.push(t0.elapsed().as_secs_f64());
    }
    stop.store(true, std::sync::atomic::Ordering::Relaxed);
    let _ = h.join();
    lat.sort_by(|a, b| a.total_cmp(b));
    (lat[n / 2], lat[(n * 99) / 100])
}
