//! A generic FMI 2.0 co-simulation master: import any co-simulation FMU, couple several per a
//! JSON system description, run parameter sweeps in parallel, write the results. It knows
//! nothing of the models it couples (no model crate is linked); the railway study and its
//! analyses live in `rail-study`, whose `master` binary composes [`cli`] with its own
//! subcommands.
//!
//! * [`fmu`]: open and check a `.fmu`, instantiate it (through the `fmi-sys` bindings), drive it.
//! * [`model_description`]: the parts of modelDescription.xml the master needs.
//! * [`system`]: JSON system description -> validated [`coupling::CouplingPlan`] -> run.
//! * [`ssp`]: SSP 1.0/2.0 import (a `.ssp` or `.ssd` becomes a system) and export.
//! * [`coupling`]: Jacobi / Gauss-Seidel fixed-step master over any [`slave::Slave`].
//! * [`runset`]: parameter sweeps in parallel.
//! * [`input`]: input files read without hanging (regular files only) or filling memory.
//! * [`decimation`]: results decimated without aliasing, and the sampling record of a file.
//! * [`output`]: atomic CSV/JSON output.
//! * [`show`]: how messages show values a user gave (long texts cut, numbers short).
//! * [`results`]: results files, CSV or Parquet ([`parquet_file`]), and their metadata.
//! * [`cli`]: the generic subcommands (run, sweep, inspect, export-ssp) and the binary's common main.
//!
//! A coupled run in a test is three lines:
//! ```no_run
//! # use master::{system::LoadedSystem, coupling::RunOptions};
//! let sys = LoadedSystem::load(std::path::Path::new("system.json"))?;
//! let out = sys.run(&RunOptions::default())?;
//! let x = out.column("ms.position").unwrap_or_default();
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod cli;
pub mod coupling;
pub mod csv_records;
pub mod decimation;
pub mod fmu;
pub mod input;
pub mod model_description;
pub mod output;
pub mod parquet_file;
pub mod results;
pub mod runset;
pub mod show;
pub mod slave;
pub mod ssp;
pub mod system;
