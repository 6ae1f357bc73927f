//! SSP (System Structure and Parameterization, Modelica Association, versions 1.0 and 2.0):
//! systems of FMUs exchanged between tools.
//!
//! * [`import`]: a `.ssp` archive (SystemStructure.ssd at its root, FMUs, `.ssv` parameter sets
//!   and `.ssm` parameter mappings inside) or a bare `.ssd` next to its files becomes a
//!   [`LoadedSystem`] that runs like a JSON system description. Components, connectors (type,
//!   kind and unit checked against the FMU), connections, parameter bindings (inline and
//!   `.ssv`, on components and on the system, with `prefix` and `.ssm` mappings and their
//!   transformations), units, the default experiment and the communication step of libcosim's
//!   and OMSimulator's annotations are read. Whatever the master cannot honour is an error
//!   naming the file, the line and the element: nested systems, system connectors, signal
//!   dictionaries, connection transformations, unit conversions, arrays, FMI 3.0 types, other
//!   component types. A parameter that matches no variable is an error too (SSP lets a tool
//!   ignore it; silently dropped parameters give plausible but wrong results).
//! * [`export`]: a system description becomes a self-contained SSP 1.0 archive (the
//!   version every host reads; valid against the 1.0 and 2.0 schemas): the FMUs under
//!   `resources/`, one parameter set per component (`resources/INSTANCE.ssv`, bound on the
//!   component, where libcosim and Ecos look; all named [`PARAMETER_SET_NAME`]; Enumeration
//!   values as `ssv:Integer`, since libcosim aborts on `ssv:Enumeration`), connectors for every connected or recorded
//!   input and output, units from the FMUs' UnitDefinitions, the default experiment, and the
//!   step as libcosim (`osp:FixedStepAlgorithm`) and OMSimulator (`oms:FixedStepMaster`)
//!   annotations.

use std::path::{Path, PathBuf};

use crate::coupling::Algorithm;
use crate::fmu::FmuError;
use crate::system::{LoadedSystem, SystemError};

mod export;
mod import;
mod package;
mod ssd;
mod ssv;
mod xml;

pub use export::{ExportSummary, PARAMETER_SET_NAME};

/// A problem with an SSP: always names the file (a member of an archive as `x.ssp:member`).
#[derive(Debug, thiserror::Error)]
pub enum SspError {
    #[error("cannot read '{path}': {reason}")]
    Read { path: PathBuf, reason: String },
    #[error("{file}{}: {message}", .line.map(|l| format!(" line {l}")).unwrap_or_default())]
    Invalid {
        file: String,
        line: Option<usize>,
        message: String,
    },
    #[error("{file}{}: not supported: {what}", .line.map(|l| format!(" line {l}")).unwrap_or_default())]
    Unsupported {
        file: String,
        line: Option<usize>,
        what: String,
    },
    #[error("{message}")]
    Parameter { message: String },
    /// `message` is the FMU error's, the FMU named as the archive's member (not as the
    /// temporary file it was unpacked to, which is gone when the message is read).
    #[error("{file}: component '{component}': {message}")]
    Fmu {
        file: String,
        component: String,
        message: String,
        /// The FMU error itself (not a `source`: its message names the temporary file).
        fmu_error: Box<FmuError>,
    },
    #[error(transparent)]
    System(#[from] SystemError),
    #[error("cannot export: {0}")]
    Export(String),
    #[error(transparent)]
    Output(#[from] crate::output::OutputError),
}

/// Choices an SSP does not make (or that the user overrides).
#[derive(Debug, Clone, Copy, Default)]
pub struct ImportOptions {
    /// Communication step \[s\]; default: the SSP's libcosim or OMSimulator annotation.
    pub step: Option<f64>,
    /// Stop time \[s\]; default: the DefaultExperiment's stopTime.
    pub stop_time: Option<f64>,
    /// Default: the algorithm the master's annotation keeps (an SSP `master export-ssp`
    /// wrote), else Jacobi (SSP does not say; libcosim, Ecos and fmpy exchange Jacobi-style).
    pub algorithm: Option<Algorithm>,
}

/// An imported SSP: the system, and the folder its FMUs were unpacked into (removed on drop).
#[derive(Debug)]
pub struct ImportedSsp {
    pub system: LoadedSystem,
    /// The SSD's `version` attribute.
    pub version: String,
    /// The parameter (.ssv) and mapping (.ssm) files read beside a bare .ssd: inputs of a run
    /// as much as the .ssd and the FMUs.
    pub files_read: Vec<PathBuf>,
    /// Where each instance's FMU comes from, as messages name it (`x.ssp:resources/a.fmu`, or
    /// the file beside a bare .ssd): the system's own FMU paths name the unpacked copies,
    /// which go with the import.
    pub fmu_sources: Vec<PathBuf>,
    _unpacked: Option<crate::fmu::extract::ExtractionDir>,
}

impl ImportedSsp {
    /// `desc` (this SSP's system, as run) with each instance's FMU named by the archive and
    /// member it comes from ([`Self::fmu_sources`]), not by its unpacked copy, which goes with
    /// the import: the record of a run.
    pub fn name_fmu_sources(&self, desc: &mut crate::system::SystemDescription) {
        for (inst, source) in desc.instances.iter_mut().zip(&self.fmu_sources) {
            inst.fmu.clone_from(source);
        }
    }
}

/// Whether `path` names an SSP (`.ssp` or `.ssd`) rather than a JSON system description.
pub fn is_ssp_path(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("ssp") || e.eq_ignore_ascii_case("ssd"))
}

/// Reads a `.ssp` archive or a bare `.ssd` into a runnable system.
pub fn import(path: &Path, opts: &ImportOptions) -> Result<ImportedSsp, SspError> {
    import::import(path, opts)
}

/// Writes `sys` as a self-contained SSP 1.0 archive at `out` (atomically).
pub fn export(sys: &LoadedSystem, out: &Path) -> Result<ExportSummary, SspError> {
    export::export(sys, out)
}

#[cfg(test)]
mod tests;
