//! The daemon's GNSS byte stream and NTRIP client (`[gnss]`): their tasks on the daemon's
//! `LocalSet`, the channel that brings their `Input`s to the control loop, and their state for
//! `agsteer status`.

use crate::config::Config;
use crate::input::Input;
use crate::io::ntrip::{run_ntrip, GgaSource, NtripPorts, NtripStatus};
use crate::io::transport::{run_rtcm_serial, run_stream, SharedStatus, StreamPorts, StreamStatus};
use serde::Serialize;
use std::sync::{Arc, Mutex};
use tokio::sync::{mpsc, watch};

/// Inputs waiting for the control loop at most (a full queue drops and counts).
const INPUT_QUEUE: usize = 256;

/// The running GNSS tasks, as the control loop sees them.
pub struct GnssLink {
    pub inputs: mpsc::Receiver<Input>,
    pub stream: SharedStatus,
    pub ntrip: Option<Arc<Mutex<NtripStatus>>>,
}

/// `agsteer status`'s `gnss` object.
#[derive(Debug, Clone, Serialize)]
pub struct GnssStatusReply {
    pub stream: StreamStatus,
    /// Age of the last byte, s.
    pub last_byte_age_s: Option<f64>,
    pub ntrip: Option<NtripReply>,
}

/// The NTRIP client's part of the status.
#[derive(Debug, Clone, Serialize)]
pub struct NtripReply {
    #[serde(flatten)]
    pub status: NtripStatus,
    pub correction_age_s: Option<f64>,
}

impl GnssLink {
    /// The status now (`now`: monotonic s).
    pub fn status(&self, now: f64) -> GnssStatusReply {
        let stream = self.stream.lock().map(|s| s.clone()).unwrap_or_default();
        let ntrip = self
            .ntrip
            .as_ref()
            .and_then(|n| n.lock().ok().map(|s| s.clone()))
            .map(|s| NtripReply {
                correction_age_s: s.correction_age_s(now),
                status: s,
            });
        GnssStatusReply {
            last_byte_age_s: stream.last_byte_t.map(|t| (now - t).max(0.0)),
            stream,
            ntrip,
        }
    }
}

/// Start the configured stream (and NTRIP client) on `local`; `None` when GNSS comes from
/// the bus. `password`: the NTRIP password, read once before the loop starts
/// ([`crate::job::startup::load`]).
pub fn spawn(cfg: &Config, password: String, local: &tokio::task::LocalSet) -> Option<GnssLink> {
    let stream_cfg = cfg.gnss.stream()?;
    let ntrip_cfg = cfg.gnss.ntrip(password);
    let (tx, inputs) = mpsc::channel(INPUT_QUEUE);
    let stream = Arc::new(Mutex::new(StreamStatus::default()));
    let (rtcm_tx, rtcm_rx) = mpsc::channel::<Vec<u8>>(64);
    let (last_rtcm_tx, last_rtcm_rx) = watch::channel(None);
    let (position_tx, position_rx) = watch::channel::<Option<GgaSource>>(None);
    let ntrip = ntrip_cfg.map(|n| {
        let status = Arc::new(Mutex::new(NtripStatus::default()));
        tracing::info!("NTRIP client for {}:{}/{}", n.host, n.port, n.mountpoint);
        local.spawn_local(run_ntrip(
            n,
            NtripPorts {
                rtcm: vec![rtcm_tx],
                last_rtcm: last_rtcm_tx,
                position: position_rx,
                status: status.clone(),
            },
        ));
        status
    });
    tracing::info!(
        "GNSS from {} ({:?})",
        stream_cfg.transport,
        stream_cfg.decoder.protocol
    );
    // Corrections to a separate serial port, or to the receiver's own.
    let rtcm_serial = cfg.gnss.rtcm_serial().filter(|_| ntrip.is_some());
    let rtcm_rx = match rtcm_serial {
        Some((device, baud)) => {
            tracing::info!("NTRIP corrections to {}", device.display());
            local.spawn_local(run_rtcm_serial(
                device,
                baud,
                rtcm_rx,
                stream.clone(),
                stream_cfg.backoff_min_s,
                stream_cfg.backoff_max_s,
            ));
            None
        }
        None => ntrip.is_some().then_some(rtcm_rx),
    };
    local.spawn_local(run_stream(
        stream_cfg,
        StreamPorts {
            inputs: tx,
            rtcm: rtcm_rx,
            last_rtcm: ntrip.is_some().then_some(last_rtcm_rx),
            position: ntrip.is_some().then_some(position_tx),
            status: stream.clone(),
        },
    ));
    Some(GnssLink {
        inputs,
        stream,
        ntrip,
    })
}
