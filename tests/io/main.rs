//! Integration tests of the inputs and outputs: the codec against cantools, GNSS and NMEA 2000
//! logs, GNSS transports on a pty and UDP, the real-time GNSS closed loop, NTRIP.
//!
//! The integration tests are a few test binaries (tests/<group>/main.rs, one module per former
//! tests/<name>.rs) rather than one per file: each binary links the library and optimises its
//! generics once, which cut the release build of all targets (docs/CONVENTIONS.md, Tests). Run
//! one file's tests by module: `cargo test --release --test <group> <name>::` (or
//! `cargo nextest run --release -E 'test(/^<name>::/)'`).

// The NTRIP caster fixture (str2str), shared by ntrip and gnss_closed_loop.
#[path = "../common/caster.rs"]
mod caster;
mod codec_vectors;
mod gnss_closed_loop;
mod gnss_logs;
mod gnss_transport;
mod n2k_logs;
mod ntrip;
