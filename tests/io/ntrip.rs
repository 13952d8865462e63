//! The NTRIP client against a real caster: RTKLIB's `str2str` (Debian package `rtklib`)
//! started here as an NTRIP caster on a local port, serving a recorded RTCM 3 stream
//! (tools/gnss/logs/rtcm3.2.log, IGS MGEX station STFU7, via gpsd) that this test writes to its
//! standard input at a steady pace. Revisions 1 and 2, a wrong password, an unknown
//! mountpoint, and the caster killed mid-stream and started again.
//!
//! Only loopback: the client connects to 127.0.0.1. (str2str's caster listens on the port on
//! every local address; nothing else on this host talks to it, and the test stops it.)
//!
//! Skipped, saying so, when `str2str` is not installed (CI installs it: `.ci/run`).

use agsteer::input::FixQuality;
use agsteer::io::ntrip::{
    run_ntrip, CasterState, GgaSource, NtripConfig, NtripPorts, NtripStatus, NtripVersion,
};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};
use tokio::sync::{mpsc, watch};

use crate::caster::*;

fn free_port() -> u16 {
    std::net::TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port()
}

struct Client {
    status: Arc<Mutex<NtripStatus>>,
    rtcm: mpsc::Receiver<Vec<u8>>,
    last_rtcm: watch::Receiver<Option<f64>>,
    _position: watch::Sender<Option<GgaSource>>,
    task: tokio::task::JoinHandle<()>,
}

impl Drop for Client {
    fn drop(&mut self) {
        self.task.abort();
    }
}

fn client(port: u16, mount: &str, password: &str, version: NtripVersion) -> Client {
    let cfg = NtripConfig {
        host: "127.0.0.1".into(),
        port,
        mountpoint: mount.into(),
        user: USER.into(),
        password: password.into(),
        version,
        gga_interval_s: 0.5,
        timeout_s: 2.0,
        backoff_min_s: 0.2,
        backoff_max_s: 0.5,
    };
    let status = Arc::new(Mutex::new(NtripStatus::default()));
    let (tx, rtcm) = mpsc::channel(4096);
    let (last_tx, last_rtcm) = watch::channel(None);
    let (position, position_rx) = watch::channel(Some(GgaSource {
        lat_deg: 44.06,
        lon_deg: -121.31,
        altitude_m: 1100.0,
        quality: FixQuality::RtkFloat,
        satellites: 20,
        hdop: 0.7,
    }));
    let task = tokio::spawn(run_ntrip(
        cfg,
        NtripPorts {
            rtcm: vec![tx],
            last_rtcm: last_tx,
            position: position_rx,
            status: status.clone(),
        },
    ));
    Client {
        status,
        rtcm,
        last_rtcm,
        _position: position,
        task,
    }
}

fn status(c: &Client) -> NtripStatus {
    c.status.lock().unwrap().clone()
}

async fn wait_for(c: &Client, within: Duration, what: impl Fn(&NtripStatus) -> bool) -> bool {
    let end = Instant::now() + within;
    while Instant::now() < end {
        if what(&status(c)) {
            return true;
        }
        tokio::time::sleep(Duration::from_millis(20)).await;
    }
    false
}

#[tokio::test(flavor = "current_thread")]
async fn ntrip_against_rtklib_str2str() {
    if !str2str_installed() {
        println!("skipped: str2str (Debian package rtklib) is not installed");
        return;
    }
    let port = free_port();
    let mut caster = Caster::start(port);
    let recorded = recorded_frames();

    for version in [NtripVersion::V1, NtripVersion::V2] {
        let mut c = client(port, MOUNT, PASSWORD, version);
        assert!(
            wait_for(&c, Duration::from_secs(3), |s| s.state
                == CasterState::Streaming
                && s.rtcm_frames > 20)
            .await,
            "{version:?}: {:?}",
            status(&c)
        );
        // The frames that reached the receiver's queue are the recorded ones, whole.
        let mut got = Vec::new();
        while let Ok(f) = c.rtcm.try_recv() {
            got.push(f);
        }
        assert!(got.len() > 20);
        assert!(
            got.iter().all(|f| recorded.contains(f)),
            "{version:?}: a frame that was not sent"
        );
        let s = status(&c);
        assert!(s.bytes_per_s > 0.0 && s.crc_errors == 0, "{s:?}");
        assert!(s.message_types.contains(&1077), "{s:?}");
        assert!(c.last_rtcm.borrow().is_some());
        assert!(
            wait_for(&c, Duration::from_secs(2), |s| s.gga_sent >= 2).await,
            "{:?}",
            status(&c)
        );
        println!("{version:?}: {s:?}");
    }

    // Wrong password.
    let c = client(port, MOUNT, "wrong", NtripVersion::V1);
    assert!(
        wait_for(&c, Duration::from_secs(3), |s| s.state
            == CasterState::Unauthorized)
        .await,
        "{:?}",
        status(&c)
    );
    assert_eq!(status(&c).rtcm_frames, 0);
    drop(c);

    // Unknown mountpoint (rev 1 and 2).
    for version in [NtripVersion::V1, NtripVersion::V2] {
        let c = client(port, "NOSUCH", PASSWORD, version);
        assert!(
            wait_for(&c, Duration::from_secs(3), |s| s.state
                == CasterState::UnknownMountpoint)
            .await,
            "{version:?}: {:?}",
            status(&c)
        );
    }

    // The caster goes away mid-stream, then comes back.
    let c = client(port, MOUNT, PASSWORD, NtripVersion::V1);
    assert!(
        wait_for(&c, Duration::from_secs(3), |s| s.state
            == CasterState::Streaming
            && s.rtcm_frames > 0)
        .await
    );
    caster.kill();
    let killed = agsteer::can::bus::monotonic_s();
    assert!(
        wait_for(&c, Duration::from_secs(4), |s| s.state
            != CasterState::Streaming
            && s.reconnects >= 1)
        .await,
        "{:?}",
        status(&c)
    );
    // The corrections age from the last frame on.
    tokio::time::sleep(Duration::from_millis(1000)).await;
    let s = status(&c);
    let age = s
        .correction_age_s(agsteer::can::bus::monotonic_s())
        .unwrap();
    assert!(age >= 1.0, "{age}");
    println!(
        "caster gone: {:?}, age of corrections {age:.1} s",
        s.last_error
    );
    let back = Instant::now();
    let _caster = Caster::start(port);
    assert!(
        wait_for(&c, Duration::from_secs(4), |s| s.state
            == CasterState::Streaming
            && s.last_rtcm_t.is_some_and(|t| t > killed))
        .await,
        "{:?}",
        status(&c)
    );
    println!(
        "streaming again {:.0} ms after the caster restarted",
        back.elapsed().as_secs_f64() * 1e3
    );
}
