//! The daemon: the agsteerd runtime (SocketCAN in and out, the control loop on a timer, the
//! status socket, progress saving on a writer thread, SIGHUP re-tuning, signals), the GNSS
//! byte stream and NTRIP client tasks, and systemd notifications.
//!
//! Contract: the only place the control loop meets I/O. It sets the job up through the job
//! layer ([`crate::job`]), reads and writes progress through [`crate::store`], and hands the
//! controller node frames and ticks; the node itself never blocks.

pub mod bus_log;
pub mod calibration;
pub mod fix_trace;
pub mod gnss;
pub mod loop_stats;
pub mod notify;
pub mod run;
pub mod sources;
pub mod tick;
