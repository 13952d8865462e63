//! The daemon's I/O: the agsteerd runtime, progress files, systemd notifications.

pub mod notify;
pub mod progress_file;
pub mod run;
