//! The railway study on top of the generic co-simulation master (crate `master`): EN 14363
//! stability assessment, the yaw-damper study of the seed's chapter 4, the offline analyses of
//! the physics crates, the figures, and the `master` binary that offers the generic
//! subcommands (run, sweep, inspect, export-ssp) together with the railway ones.
//!
//! * [`signal`], [`en14363`]: spectrum, sliding rms, EN 14363 stability assessment (the
//!   band-pass is `signal-processing`'s).
//! * [`en12299`]: lateral ride comfort of the car body (W_d weighting, N_y).
//! * [`plot`]: SVG charts.
//! * [`analysis`]: damper characterisation, root locus, contact geometry, assessment of
//!   recorded signals.
//! * [`study`]: the stability study and its report.
//! * [`commands`]: the railway subcommands.

pub mod analysis;
pub mod commands;
pub mod en12299;
pub mod en14363;
pub mod plot;
pub mod signal;
pub mod study;
