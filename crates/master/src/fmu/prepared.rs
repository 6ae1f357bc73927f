//! An FMU unpacked and loaded once, shared by all its instances.

use std::ffi::CString;
use std::sync::Arc;

use super::library::Fmi2Library;
use super::{platform_binary_dir, FmuArchive, FmuError, FmuSlave};
use crate::model_description::ModelDescription;

/// A checked FMU, unpacked into a temporary folder with its binary loaded. Instances
/// ([`PreparedFmu::instantiate`]) hold an `Arc` to it, so the library and the folder (its
/// resources) outlive every instance; it is `Send + Sync`, so the workers of a run set share
/// one.
pub struct PreparedFmu {
    archive: FmuArchive,
    // Field order matters: the library is unloaded before the folder it came from is removed.
    library: Fmi2Library,
    resource_url: CString,
    dir: super::extract::ExtractionDir,
}

impl std::fmt::Debug for PreparedFmu {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "PreparedFmu({} in {})",
            self.archive.path.display(),
            self.dir.path().display()
        )
    }
}

impl PreparedFmu {
    /// Unpacks the archive and loads its binary. `instance` names the instance this is for
    /// in error messages.
    pub fn prepare(archive: FmuArchive, instance: &str) -> Result<Self, FmuError> {
        let load_err = |reason: String| FmuError::Load {
            path: archive.path.clone(),
            instance: instance.to_string(),
            reason,
        };
        let Some(cs) = &archive.model.co_simulation else {
            return Err(FmuError::NotCoSimulation { path: archive.path });
        };
        let dir = archive.unpack()?;
        let (platform, suffix) = platform_binary_dir()?;
        let binary = dir
            .path()
            .join("binaries")
            .join(platform)
            .join(format!("{}{suffix}", cs.model_identifier));
        // read before loading: the loader faults (SIGBUS, SIGSEGV) on some malformed
        // libraries, e.g. a truncated one, taking the whole process down with it; a file that
        // cannot be read is left to the loader, whose error names it
        if let Ok(data) = std::fs::read(&binary) {
            fmu_binary::inspect(&data).map_err(|e| {
                load_err(format!(
                    "its binary binaries/{platform}/{}{suffix} is not a loadable shared \
                     library: {e}",
                    cs.model_identifier
                ))
            })?;
        }
        let library =
            Fmi2Library::load(&binary, cs.can_get_and_set_fmu_state).map_err(&load_err)?;
        // FMI 2.0 (2.1.5): fmuResourceLocation is a URI of the unpacked resources folder
        let resources = std::path::absolute(dir.path().join("resources"))
            .map_err(|e| load_err(e.to_string()))?;
        let url = url::Url::from_file_path(&resources)
            .map_err(|()| load_err(format!("no file URL for '{}'", resources.display())))?;
        let resource_url = CString::new(url.as_str()).map_err(|e| load_err(e.to_string()))?;
        Ok(PreparedFmu {
            archive,
            library,
            resource_url,
            dir,
        })
    }

    pub fn archive(&self) -> &FmuArchive {
        &self.archive
    }

    pub fn model(&self) -> &ModelDescription {
        &self.archive.model
    }

    pub(crate) fn library(&self) -> &Fmi2Library {
        &self.library
    }

    pub(crate) fn resource_url(&self) -> &CString {
        &self.resource_url
    }

    /// Whether every instance needs its own unpacked copy (canBeInstantiatedOnlyOncePerProcess:
    /// two instances must not share one library image).
    pub fn needs_private_copy(&self) -> bool {
        self.archive
            .model
            .co_simulation
            .as_ref()
            .is_some_and(|c| c.can_be_instantiated_only_once_per_process)
    }

    /// One co-simulation instance (fmi2Instantiate). An FMU that can be instantiated only once
    /// per process is unpacked and loaded again for the instance.
    pub fn instantiate(
        self: &Arc<Self>,
        instance_name: &str,
        logging_on: bool,
    ) -> Result<FmuSlave, FmuError> {
        let fmu = if self.needs_private_copy() {
            Arc::new(PreparedFmu::prepare(self.archive.clone(), instance_name)?)
        } else {
            Arc::clone(self)
        };
        FmuSlave::new(fmu, instance_name, logging_on)
    }
}
