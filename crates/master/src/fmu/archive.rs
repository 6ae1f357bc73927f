//! A checked FMU archive: the zip and its modelDescription.xml, read once.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use super::{count_extraction, platform_binary_dir, FmuError, FmuSlave, PreparedFmu};
use crate::model_description::ModelDescription;

/// A checked FMU archive (not yet unpacked or loaded).
#[derive(Debug, Clone)]
pub struct FmuArchive {
    pub path: PathBuf,
    pub model: ModelDescription,
}

impl FmuArchive {
    /// Opens and checks an FMU: zip, modelDescription.xml, FMI 2.0, co-simulation, GUID and the
    /// binary for this platform.
    pub fn open(path: &Path) -> Result<Self, FmuError> {
        use std::io::Read;
        let pb = path.to_path_buf();
        let file = std::fs::File::open(path).map_err(|source| {
            if source.kind() == std::io::ErrorKind::NotFound {
                FmuError::NotFound { path: pb.clone() }
            } else {
                FmuError::Io {
                    path: pb.clone(),
                    source,
                }
            }
        })?;
        let mut zip = zip::ZipArchive::new(file).map_err(|e| FmuError::NotAZip {
            path: pb.clone(),
            reason: e.to_string(),
        })?;
        let mut xml = String::new();
        {
            let mut entry = zip
                .by_name("modelDescription.xml")
                .map_err(|_| FmuError::NoModelDescription { path: pb.clone() })?;
            entry
                .read_to_string(&mut xml)
                .map_err(|source| FmuError::Io {
                    path: pb.clone(),
                    source,
                })?;
        }
        let model = ModelDescription::parse(&xml).map_err(|source| FmuError::ModelDescription {
            path: pb.clone(),
            source: Box::new(source),
        })?;
        if model.fmi_version.trim() != "2.0" {
            return Err(FmuError::UnsupportedVersion {
                path: pb,
                version: model.fmi_version.clone(),
            });
        }
        let Some(cs) = &model.co_simulation else {
            return Err(FmuError::NotCoSimulation { path: pb });
        };
        if model.guid.trim().is_empty() {
            return Err(FmuError::NoGuid { path: pb });
        }
        let (dir, suffix) = platform_binary_dir()?;
        let expected = format!("binaries/{dir}/{}{suffix}", cs.model_identifier);
        if zip.by_name(&expected).is_err() {
            let found: Vec<&str> = zip
                .file_names()
                .filter(|n| n.starts_with("binaries/") && !n.ends_with('/'))
                .collect();
            return Err(FmuError::NoBinary {
                path: pb,
                expected,
                found: found.join(", "),
            });
        }
        Ok(FmuArchive {
            path: path.to_path_buf(),
            model,
        })
    }

    /// Unpacks the whole archive into a new temporary folder (removed when dropped).
    pub(crate) fn unpack(&self) -> Result<tempfile::TempDir, FmuError> {
        let err = |reason: String| FmuError::Unpack {
            path: self.path.clone(),
            reason,
        };
        let file = std::fs::File::open(&self.path).map_err(|e| err(e.to_string()))?;
        let mut zip = zip::ZipArchive::new(file).map_err(|e| err(e.to_string()))?;
        let dir = tempfile::Builder::new()
            .prefix("fmu-")
            .tempdir()
            .map_err(|e| err(e.to_string()))?;
        zip.extract(dir.path()).map_err(|e| err(e.to_string()))?;
        count_extraction();
        Ok(dir)
    }

    /// Unpacks, loads and instantiates one co-simulation instance that owns its unpacked copy
    /// (for a single instance; systems and run sets share one [`PreparedFmu`] instead).
    /// `logging_on` is passed to fmi2Instantiate (FMU debug logging).
    pub fn instantiate(&self, instance_name: &str, logging_on: bool) -> Result<FmuSlave, FmuError> {
        super::instance::check_instance_name(instance_name)?;
        let prepared = Arc::new(PreparedFmu::prepare(self.clone(), instance_name)?);
        prepared.instantiate(instance_name, logging_on)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Write;

    fn write_zip(path: &Path, files: &[(&str, &[u8])]) {
        let f = std::fs::File::create(path).unwrap();
        let mut z = zip::ZipWriter::new(f);
        for (name, data) in files {
            z.start_file(*name, zip::write::SimpleFileOptions::default())
                .unwrap();
            z.write_all(data).unwrap();
        }
        z.finish().unwrap();
    }

    const MD: &str = crate::model_description::tests::MASS_SPRING;

    #[test]
    fn missing_file() {
        let e = FmuArchive::open(Path::new("/no/such/thing.fmu")).unwrap_err();
        assert!(matches!(e, FmuError::NotFound { .. }));
        assert!(e.to_string().contains("/no/such/thing.fmu"));
    }

    #[test]
    fn garbage_is_not_a_zip() {
        let d = tempfile::tempdir().unwrap();
        let p = d.path().join("bad.fmu");
        std::fs::write(&p, b"this is not a zip file at all").unwrap();
        let e = FmuArchive::open(&p).unwrap_err();
        assert!(matches!(e, FmuError::NotAZip { .. }), "{e}");
        assert!(e.to_string().contains("bad.fmu"));
    }

    #[test]
    fn zip_checks() {
        let d = tempfile::tempdir().unwrap();
        let p = d.path().join("x.fmu");
        let (dir, suf) = platform_binary_dir().unwrap();
        let bin = format!("binaries/{dir}/MassSpring{suf}");

        write_zip(&p, &[("readme.txt", b"hi")]);
        assert!(matches!(
            FmuArchive::open(&p).unwrap_err(),
            FmuError::NoModelDescription { .. }
        ));

        write_zip(&p, &[("modelDescription.xml", b"<fmiModelDescription <<")]);
        let e = FmuArchive::open(&p).unwrap_err();
        assert!(matches!(e, FmuError::ModelDescription { .. }), "{e}");

        let v1 = MD.replace("fmiVersion=\"2.0\"", "fmiVersion=\"3.0\"");
        write_zip(&p, &[("modelDescription.xml", v1.as_bytes()), (&bin, b"")]);
        let e = FmuArchive::open(&p).unwrap_err();
        assert!(matches!(e, FmuError::UnsupportedVersion { ref version, .. } if version == "3.0"));

        let me = MD.replace(
            "<CoSimulation modelIdentifier=\"MassSpring\" canGetAndSetFMUstate=\"true\"/>",
            "<ModelExchange modelIdentifier=\"MassSpring\"/>",
        );
        write_zip(&p, &[("modelDescription.xml", me.as_bytes()), (&bin, b"")]);
        assert!(matches!(
            FmuArchive::open(&p).unwrap_err(),
            FmuError::NotCoSimulation { .. }
        ));

        let ng = MD.replace("guid=\"{abc}\"", "guid=\"\"");
        write_zip(&p, &[("modelDescription.xml", ng.as_bytes()), (&bin, b"")]);
        assert!(matches!(
            FmuArchive::open(&p).unwrap_err(),
            FmuError::NoGuid { .. }
        ));

        write_zip(
            &p,
            &[
                ("modelDescription.xml", MD.as_bytes()),
                ("binaries/win64/MassSpring.dll", b""),
            ],
        );
        let e = FmuArchive::open(&p).unwrap_err();
        let msg = e.to_string();
        assert!(
            msg.contains(&bin) && msg.contains("binaries/win64/MassSpring.dll"),
            "{msg}"
        );

        write_zip(&p, &[("modelDescription.xml", MD.as_bytes()), (&bin, b"")]);
        let a = FmuArchive::open(&p).unwrap();
        assert_eq!(a.model.model_name, "MassSpring");
        // an empty "binary" cannot be loaded: a typed error, no panic
        let e = a.instantiate("ms", false).unwrap_err();
        assert!(matches!(e, FmuError::Load { .. }), "{e}");
        let e = a.instantiate("bad\0name", false).unwrap_err();
        assert!(matches!(e, FmuError::InstanceName { .. }));
    }
}
