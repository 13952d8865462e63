//! Buses: one trait for sending and receiving timestamped frames, an in-memory bus for the
//! in-process demo and tests, and SocketCAN (blocking and tokio) for the daemon and simulator.
//!
//! Receive timestamps are seconds on the receiver's monotonic clock ([`monotonic_s`]) for
//! SocketCAN, and the caller's simulated time for [`MemBus`].

use super::{Frame, TimedFrame};
use std::collections::VecDeque;
use std::sync::{Arc, Mutex};

/// Bus errors.
#[derive(Debug, thiserror::Error)]
pub enum BusError {
    /// The interface is down or gone (ENETDOWN, ENODEV, ENXIO): retry later.
    #[error("CAN interface is down: {0}")]
    Down(std::io::Error),
    /// The transmit queue is full (ENOBUFS, EAGAIN).
    #[error("CAN transmit queue full")]
    Full,
    #[error("CAN I/O error: {0}")]
    Io(std::io::Error),
}

impl From<std::io::Error> for BusError {
    fn from(e: std::io::Error) -> Self {
        match e.raw_os_error() {
            Some(libc::ENETDOWN) | Some(libc::ENODEV) | Some(libc::ENXIO) => BusError::Down(e),
            Some(libc::ENOBUFS) | Some(libc::EAGAIN) => BusError::Full,
            _ => BusError::Io(e),
        }
    }
}

/// Sending and receiving frames.
pub trait CanBus {
    /// Send one frame (non-blocking).
    fn send(&mut self, frame: &Frame) -> Result<(), BusError>;
    /// The next received frame, if any (non-blocking).
    fn try_recv(&mut self) -> Result<Option<TimedFrame>, BusError>;
}

/// Seconds on the monotonic clock (CLOCK_MONOTONIC), the daemon's time base.
pub fn monotonic_s() -> f64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: clock_gettime writes into the timespec we own.
    unsafe { libc::clock_gettime(libc::CLOCK_MONOTONIC, &mut ts) };
    ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9
}

#[derive(Debug, Default)]
struct Hub {
    queues: Vec<VecDeque<(usize, TimedFrame)>>,
    now: f64,
}

/// An in-memory bus: every node sees every frame the other nodes send, in send order,
/// stamped with the hub's time (set by the caller), so runs are deterministic and faster than
/// real time. A node sees only frames sent after it was attached. `clone()` gives another
/// handle on the same node (same receive queue); [`MemBus::node`] attaches a new node.
#[derive(Debug, Clone)]
pub struct MemBus {
    hub: Arc<Mutex<Hub>>,
    node: usize,
}

impl MemBus {
    /// A new bus with its first node.
    pub fn new() -> MemBus {
        let hub = Arc::new(Mutex::new(Hub::default()));
        let node = MemBus::attach(&hub);
        MemBus { hub, node }
    }
    fn attach(hub: &Arc<Mutex<Hub>>) -> usize {
        let mut h = hub.lock().unwrap_or_else(|e| e.into_inner());
        h.queues.push(VecDeque::with_capacity(256));
        h.queues.len() - 1
    }
    /// Another node on the same bus.
    pub fn node(&self) -> MemBus {
        MemBus {
            hub: self.hub.clone(),
            node: MemBus::attach(&self.hub),
        }
    }
    /// Set the bus time used to stamp frames sent from now on, s.
    pub fn set_time(&self, t: f64) {
        self.hub.lock().unwrap_or_else(|e| e.into_inner()).now = t;
    }
}

impl Default for MemBus {
    fn default() -> Self {
        MemBus::new()
    }
}

impl CanBus for MemBus {
    fn send(&mut self, frame: &Frame) -> Result<(), BusError> {
        let mut h = self.hub.lock().unwrap_or_else(|e| e.into_inner());
        let tf = TimedFrame {
            t: h.now,
            frame: *frame,
        };
        for (i, q) in h.queues.iter_mut().enumerate() {
            if i != self.node {
                q.push_back((self.node, tf));
            }
        }
        Ok(())
    }
    fn try_recv(&mut self) -> Result<Option<TimedFrame>, BusError> {
        let mut h = self.hub.lock().unwrap_or_else(|e| e.into_inner());
        Ok(h.queues[self.node].pop_front().map(|(_, f)| f))
    }
}

/// Receive filter: accept ids with `id & mask == wanted & mask` (29-bit ids).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Filter {
    pub id: u32,
    pub mask: u32,
}

fn to_socketcan(frame: &Frame) -> Result<socketcan::CanFrame, BusError> {
    use socketcan::EmbeddedFrame;
    let id = socketcan::ExtendedId::new(frame.id & 0x1FFF_FFFF)
        .ok_or_else(|| BusError::Io(std::io::Error::other("id out of range")))?;
    socketcan::CanFrame::new(id, frame.payload())
        .ok_or_else(|| BusError::Io(std::io::Error::other("bad frame")))
}

fn from_socketcan(f: &socketcan::CanFrame) -> Option<Frame> {
    use socketcan::{EmbeddedFrame, Id};
    match f.id() {
        Id::Extended(id) if f.is_data_frame() => Some(Frame::new(id.as_raw(), f.data())),
        _ => None,
    }
}

fn socketcan_filters(filters: &[Filter]) -> Vec<socketcan::CanFilter> {
    const EFF: u32 = 0x8000_0000;
    filters
        .iter()
        .map(|f| socketcan::CanFilter::new(f.id | EFF, f.mask | EFF))
        .collect()
}

/// A blocking-or-not SocketCAN bus (for the simulator and tests).
pub struct SocketCanBus {
    sock: socketcan::CanSocket,
}

impl SocketCanBus {
    /// Open `iface` (non-blocking), with receive filters (empty = everything).
    pub fn open(iface: &str, filters: &[Filter]) -> Result<Self, BusError> {
        use socketcan::{Socket, SocketOptions};
        let sock = socketcan::CanSocket::open(iface)?;
        sock.set_nonblocking(true)?;
        if !filters.is_empty() {
            sock.set_filters(&socketcan_filters(filters))?;
        }
        Ok(SocketCanBus { sock })
    }
}

impl CanBus for SocketCanBus {
    fn send(&mut self, frame: &Frame) -> Result<(), BusError> {
        use socketcan::Socket;
        let f = to_socketcan(frame)?;
        self.sock.write_frame(&f).map_err(BusError::from)
    }
    fn try_recv(&mut self) -> Result<Option<TimedFrame>, BusError> {
        use socketcan::Socket;
        loop {
            match self.sock.read_frame() {
                Ok(f) => {
                    if let Some(frame) = from_socketcan(&f) {
                        return Ok(Some(TimedFrame {
                            t: monotonic_s(),
                            frame,
                        }));
                    }
                }
                Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => return Ok(None),
                Err(e) => return Err(e.into()),
            }
        }
    }
}

/// The daemon's tokio SocketCAN bus.
pub struct AsyncSocketCan {
    sock: socketcan::tokio::CanSocket,
}

impl AsyncSocketCan {
    /// Open `iface` with receive filters (empty = everything).
    pub fn open(iface: &str, filters: &[Filter]) -> Result<Self, BusError> {
        use socketcan::SocketOptions;
        let sock = socketcan::tokio::CanSocket::open(iface)?;
        if !filters.is_empty() {
            sock.set_filters(&socketcan_filters(filters))?;
        }
        Ok(AsyncSocketCan { sock })
    }
    /// Wait for the next extended data frame.
    pub async fn recv(&self) -> Result<TimedFrame, BusError> {
        loop {
            let f = self.sock.read_frame().await?;
            if let Some(frame) = from_socketcan(&f) {
                return Ok(TimedFrame {
                    t: monotonic_s(),
                    frame,
                });
            }
        }
    }
    /// Send without waiting: a full queue is an error, never a stall of the control loop.
    pub fn try_send(&self, frame: &Frame) -> Result<(), BusError> {
        let f = to_socketcan(frame)?;
        self.sock.try_write_frame(f).map_err(BusError::from)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mem_bus_delivers_to_the_other_nodes_only() {
        let mut a = MemBus::new();
        let mut b = a.node();
        let mut c = a.node();
        a.set_time(1.5);
        a.send(&Frame::new(0x0CFF2000, &[1, 2, 3])).unwrap();
        assert!(a.try_recv().unwrap().is_none());
        let fb = b.try_recv().unwrap().unwrap();
        assert_eq!(fb.frame.payload(), &[1, 2, 3]);
        assert_eq!(fb.t, 1.5);
        assert!(c.try_recv().unwrap().is_some());
        assert!(c.try_recv().unwrap().is_none());
    }

    #[test]
    fn mem_bus_keeps_send_order_across_senders() {
        let mut a = MemBus::new();
        let mut b = a.node();
        let mut c = a.node();
        a.send(&Frame::new(0x100, &[1])).unwrap();
        b.send(&Frame::new(0x200, &[2])).unwrap();
        a.send(&Frame::new(0x101, &[3])).unwrap();
        let ids = |bus: &mut MemBus| {
            std::iter::from_fn(|| bus.try_recv().unwrap())
                .map(|f| f.frame.id)
                .collect::<Vec<_>>()
        };
        assert_eq!(ids(&mut c), vec![0x100, 0x200, 0x101]);
        assert_eq!(ids(&mut b), vec![0x100, 0x101]);
        assert_eq!(ids(&mut a), vec![0x200]);
    }

    #[test]
    fn mem_bus_stamps_each_frame_with_the_time_at_sending() {
        let mut a = MemBus::new();
        let mut b = a.node();
        a.set_time(0.25);
        a.send(&Frame::new(0x100, &[])).unwrap();
        b.set_time(0.5);
        a.send(&Frame::new(0x101, &[])).unwrap();
        let t: Vec<f64> = std::iter::from_fn(|| b.try_recv().unwrap())
            .map(|f| f.t)
            .collect();
        assert_eq!(t, vec![0.25, 0.5]);
    }

    #[test]
    fn mem_bus_late_node_sees_only_later_frames_and_clones_share_a_node() {
        let mut a = MemBus::new();
        a.send(&Frame::new(0x100, &[1])).unwrap();
        let mut late = a.node();
        assert!(late.try_recv().unwrap().is_none());
        let mut same = late.clone();
        a.send(&Frame::new(0x101, &[2])).unwrap();
        same.send(&Frame::new(0x300, &[3])).unwrap();
        assert_eq!(late.try_recv().unwrap().map(|f| f.frame.id), Some(0x101));
        assert!(same.try_recv().unwrap().is_none(), "one queue per node");
        assert_eq!(a.try_recv().unwrap().map(|f| f.frame.id), Some(0x300));
    }

    #[test]
    fn frame_new_masks_the_id_and_truncates_the_payload() {
        let f = Frame::new(0xFFFF_FFFF, &[1, 2, 3, 4, 5, 6, 7, 8, 9]);
        assert_eq!(f.id, 0x1FFF_FFFF);
        assert_eq!(f.len, 8);
        assert_eq!(f.payload(), &[1, 2, 3, 4, 5, 6, 7, 8]);
    }

    #[test]
    fn filters_carry_the_extended_frame_flag() {
        let f = socketcan_filters(&[Filter {
            id: 0x00FF_2000,
            mask: 0x03FF_FF00,
        }]);
        assert_eq!(f.len(), 1);
        // The EFF flag in both id and mask: only extended frames with matching bits pass.
        let raw: &libc::can_filter = f[0].as_ref();
        assert_eq!(raw.can_id, 0x80FF_2000);
        assert_eq!(raw.can_mask, 0x83FF_FF00);
    }

    #[test]
    fn other_io_errors_stay_io_errors() {
        let other = BusError::from(std::io::Error::from_raw_os_error(libc::EINVAL));
        assert!(matches!(other, BusError::Io(_)));
    }

    #[test]
    fn io_errors_map_to_down_and_full() {
        let down = std::io::Error::from_raw_os_error(libc::ENETDOWN);
        assert!(matches!(BusError::from(down), BusError::Down(_)));
        let full = std::io::Error::from_raw_os_error(libc::ENOBUFS);
        assert!(matches!(BusError::from(full), BusError::Full));
    }

    #[test]
    fn candump_format() {
        let f = Frame::new(
            0x0CADFF1C,
            &[0x80, 0x7D, 0xFD, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF],
        );
        assert_eq!(f.to_candump(), "0CADFF1C#807DFDFFFFFFFFFF");
    }
}
