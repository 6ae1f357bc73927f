//! FMI 2.0 co-simulation master for the bogie / yaw damper FMUs.
//!
//! * [`fmu`]: open and check a `.fmu`, instantiate it (through the `fmi` crate), drive it.
//! * [`model_description`]: the parts of modelDescription.xml the master needs.
//! * [`system`]: JSON system description -> validated [`coupling::CouplingPlan`] -> run.
//! * [`coupling`]: Jacobi / Gauss-Seidel fixed-step master over any [`slave::Slave`].
//! * [`runset`]: parameter sweeps in parallel.
//! * [`signal`], [`en14363`]: band-pass, sliding rms, EN 14363 stability assessment.
//! * [`plot`], [`output`]: SVG charts and atomic CSV/JSON output.
//! * [`commands`]: the `master` subcommands.
//!
//! A coupled run in a test is three lines:
//! ```no_run
//! # use master::{system::LoadedSystem, coupling::RunOptions};
//! let sys = LoadedSystem::load(std::path::Path::new("system.json"))?;
//! let out = sys.run(&RunOptions::default())?;
//! let x = out.column("ms.position").unwrap_or_default();
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod analysis;
pub mod commands;
pub mod coupling;
pub mod en14363;
pub mod fmu;
pub mod model_description;
pub mod output;
pub mod plot;
pub mod runset;
pub mod signal;
pub mod slave;
pub mod study;
pub mod system;
