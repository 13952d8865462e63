//! RTKLIB's `str2str` as an NTRIP caster on a local port, serving a recorded RTCM 3 stream
//! (tools/gnss/logs/rtcm3.2.log, IGS MGEX station STFU7, via gpsd) written to its standard
//! input at a steady pace (tests/io/ntrip.rs, tests/io/gnss_closed_loop.rs).

use agsteer::io::framer::{Frame, Framer};
use std::io::Write;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

pub const MOUNT: &str = "AGSTEER";
pub const USER: &str = "farmer";
pub const PASSWORD: &str = "s3cret";

pub fn str2str_installed() -> bool {
    Command::new("str2str")
        .arg("-h")
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok()
}

/// The RTCM frames of the recorded stream.
pub fn recorded_frames() -> Vec<Vec<u8>> {
    let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tools/gnss/logs/rtcm3.2.log");
    let data = std::fs::read(p).unwrap();
    let mut frames = Vec::new();
    Framer::new().push(&data, &mut |f| {
        if let Frame::Rtcm(r) = f {
            frames.push(r.to_vec());
        }
    });
    assert!(frames.len() > 150);
    frames
}

/// str2str as an NTRIP caster on `port`, fed by a thread that writes the recorded frames to
/// its stdin, ten frames every 100 ms, until the caster goes away.
pub struct Caster {
    child: Child,
    feeder: Option<std::thread::JoinHandle<()>>,
}

impl Caster {
    pub fn start(port: u16) -> Caster {
        let mut child = Command::new("str2str")
            .arg("-out")
            .arg(format!("ntripc://{USER}:{PASSWORD}@:{port}/{MOUNT}"))
            .stdin(Stdio::piped())
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .expect("str2str");
        let mut stdin = child.stdin.take().unwrap();
        let frames = recorded_frames();
        let feeder = std::thread::spawn(move || {
            let start = Instant::now();
            // Bounded: at most 60 s, whatever happens.
            for (k, f) in frames.iter().cycle().enumerate() {
                if stdin.write_all(f).is_err() || start.elapsed() > Duration::from_secs(60) {
                    return;
                }
                if k % 10 == 9 {
                    let _ = stdin.flush();
                    std::thread::sleep(Duration::from_millis(100));
                }
            }
        });
        // Let it listen.
        std::thread::sleep(Duration::from_millis(300));
        Caster {
            child,
            feeder: Some(feeder),
        }
    }

    pub fn kill(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
        if let Some(f) = self.feeder.take() {
            let _ = f.join();
        }
    }
}

impl Drop for Caster {
    fn drop(&mut self) {
        self.kill();
    }
}
