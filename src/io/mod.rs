//! Byte-stream GNSS inputs: the framer and decoder that turn a receiver's bytes into the
//! seam's [`Input`](crate::input::Input)s, the transports that carry them (serial / USB CDC,
//! UDP, TCP client) and the NTRIP client that brings RTK corrections.
//!
//! The framer and decoder are pure; the transports and the NTRIP client are the only code
//! here doing I/O (tokio, on the daemon's single-threaded runtime).

pub mod decoder;
pub mod framer;
pub mod ntrip;
pub mod pty;
#[cfg(test)]
mod tests;
pub mod transport;
pub mod tty;
