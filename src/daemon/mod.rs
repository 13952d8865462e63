//! The daemon's I/O: the agsteerd runtime, progress files, the field file, systemd
//! notifications.

pub mod bus_log;
pub mod field_file;
pub mod gnss;
pub mod maneuver_file;
pub mod notify;
pub mod progress_file;
pub mod run;
