//! The daemon's I/O: progress files, and (with the bus) the control loop runtime.

pub mod progress_file;
