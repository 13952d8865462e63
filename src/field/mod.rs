//! Field input: GeoJSON and ISO 11783-10 TASKDATA boundaries (WGS-84) into a local
//! [`Field`](crate::plan::coverage::Field), with an ENU origin and boundary clean-up.
//!
//! Parsing works on strings; reading files is the binaries' job.
