//! A checked FMU archive: the zip and its modelDescription.xml, read once.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use super::extract::{self, ArchiveLimits, ExtractionDir};
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
        let pb = path.to_path_buf();
        let file = crate::input::open_regular_file(path).map_err(|source| {
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
        let limits = ArchiveLimits::from_env()?;
        let entries = extract::check_entries(path, &mut zip, &limits)?;
        if entries.model_description_bytes.is_none() {
            return Err(FmuError::NoModelDescription { path: pb });
        }
        let mut bytes = Vec::new();
        {
            let entry = zip
                .by_name("modelDescription.xml")
                .map_err(|_| FmuError::NoModelDescription { path: pb.clone() })?;
            let within =
                extract::read_limited(entry, limits.max_model_description_bytes, &mut bytes)
                    .map_err(|source| FmuError::Io {
                        path: pb.clone(),
                        source,
                    })?;
            if !within {
                return Err(FmuError::TooLarge {
                    path: pb,
                    what: "its modelDescription.xml inflates to more bytes than it declares".into(),
                    limit: limits.max_model_description_bytes,
                    variable: extract::MAX_MODEL_DESCRIPTION_BYTES_VAR,
                });
            }
        }
        let xml = String::from_utf8(bytes).map_err(|e| FmuError::ModelDescription {
            path: pb.clone(),
            source: Box::new(crate::model_description::ModelDescriptionError::Xml(
                format!("not UTF-8 text (byte {})", e.utf8_error().valid_up_to()),
            )),
        })?;
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

    /// Unpacks the whole archive into a new extraction folder (removed when dropped; a folder
    /// left by a process that died is removed by the next unpack, see [`extract`]).
    pub(crate) fn unpack(&self) -> Result<ExtractionDir, FmuError> {
        let limits = ArchiveLimits::from_env()?;
        let dir = extract::unpack(&self.path, &extract::extraction_root(), &limits)?;
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
    use std::io::{Read, Write};

    fn write_zip(path: &Path, files: &[(&str, &[u8])]) {
        write_zip_with(path, files, zip::write::SimpleFileOptions::default());
    }

    fn write_zip_with(
        path: &Path,
        files: &[(&str, &[u8])],
        options: zip::write::SimpleFileOptions,
    ) {
        let f = std::fs::File::create(path).unwrap();
        let mut z = zip::ZipWriter::new(f);
        for (name, data) in files {
            z.start_file(*name, options).unwrap();
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

    /// A damaged entry (its data no longer matches its CRC-32) stops the unpacking with an
    /// error that names the entry.
    #[test]
    fn a_damaged_entry_is_named() {
        let d = tempfile::tempdir().unwrap();
        let p = d.path().join("x.fmu");
        let (dir, suf) = platform_binary_dir().unwrap();
        let bin = format!("binaries/{dir}/MassSpring{suf}");
        let stored = zip::write::SimpleFileOptions::default()
            .compression_method(zip::CompressionMethod::Stored);
        write_zip_with(
            &p,
            &[
                ("modelDescription.xml", MD.as_bytes()),
                ("resources/table.csv", b"MARKER-0123456789"),
                (&bin, b""),
            ],
            stored,
        );
        let mut bytes = std::fs::read(&p).unwrap();
        let data = bytes.windows(6).position(|w| w == b"MARKER").unwrap();
        bytes[data] ^= 0x20;
        std::fs::write(&p, bytes).unwrap();
        let a = FmuArchive::open(&p).unwrap();
        let e = a.instantiate("ms", false).unwrap_err();
        assert!(matches!(e, FmuError::Unpack { .. }), "{e}");
        assert!(e.to_string().contains("entry 'resources/table.csv'"), "{e}");
    }

    #[test]
    fn oversized_model_description_is_refused_unread() {
        // 300 MB of spaces (above the default 256 MiB), deflated to a few hundred kB
        let d = tempfile::tempdir().unwrap();
        let p = d.path().join("big.fmu");
        let mut z = zip::ZipWriter::new(std::fs::File::create(&p).unwrap());
        let o = zip::write::SimpleFileOptions::default()
            .compression_level(Some(1))
            .large_file(true);
        z.start_file("modelDescription.xml", o).unwrap();
        std::io::copy(&mut std::io::repeat(b' ').take(300_000_000), &mut z).unwrap();
        z.finish().unwrap();
        assert!(std::fs::metadata(&p).unwrap().len() < 3_000_000);
        let e = FmuArchive::open(&p).unwrap_err();
        assert!(
            matches!(e, FmuError::TooLarge { limit, .. } if limit == 256 << 20),
            "{e}"
        );
        assert!(
            e.to_string()
                .contains("modelDescription.xml has 300000000 bytes"),
            "{e}"
        );
    }

    #[test]
    fn unsafe_entries_are_refused_at_open() {
        let d = tempfile::tempdir().unwrap();
        let p = d.path().join("x.fmu");
        let (dir, suf) = platform_binary_dir().unwrap();
        let bin = format!("binaries/{dir}/MassSpring{suf}");
        for (entry, reason) in [
            ("../evil.so", "leaves the archive"),
            ("/etc/cron.d/evil", "leaves the archive"),
            ("resources\\..\\..\\evil", "not a plain path"),
        ] {
            write_zip(
                &p,
                &[
                    ("modelDescription.xml", MD.as_bytes()),
                    (&bin, b""),
                    (entry, b"x"),
                ],
            );
            let e = FmuArchive::open(&p).unwrap_err();
            assert!(
                matches!(&e, FmuError::UnsafeEntry { .. }) && e.to_string().contains(reason),
                "{entry}: {e}"
            );
        }
    }

    /// A valid FMU archive of a few kB: deflated and stored entries, a folder entry.
    fn small_fmu() -> Vec<u8> {
        let (dir, suf) = platform_binary_dir().unwrap();
        let mut z = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
        let deflated = zip::write::SimpleFileOptions::default();
        let stored = deflated.compression_method(zip::CompressionMethod::Stored);
        z.start_file("modelDescription.xml", deflated).unwrap();
        z.write_all(MD.as_bytes()).unwrap();
        z.start_file(format!("binaries/{dir}/MassSpring{suf}"), stored)
            .unwrap();
        z.write_all(&[0x7f, b'E', b'L', b'F', 2, 1, 1, 0]).unwrap();
        z.add_directory("resources/", deflated).unwrap();
        z.start_file("resources/table.csv", deflated).unwrap();
        z.write_all("y,r\n0,0.46\n0.001,0.4601\n".repeat(20).as_bytes())
            .unwrap();
        z.finish().unwrap().into_inner()
    }

    #[derive(Debug, Clone)]
    enum ByteMutation {
        Replace {
            at: usize,
            byte: u8,
        },
        /// a 32-bit field (sizes, offsets, counts) set to an extreme value
        Field {
            at: usize,
            value: u32,
        },
        Delete {
            at: usize,
            len: usize,
        },
        Duplicate {
            at: usize,
            len: usize,
        },
    }

    fn byte_mutation() -> impl proptest::strategy::Strategy<Value = ByteMutation> {
        use proptest::prelude::*;
        prop_oneof![
            (any::<usize>(), any::<u8>()).prop_map(|(at, byte)| ByteMutation::Replace { at, byte }),
            (
                any::<usize>(),
                prop_oneof![
                    Just(0u32),
                    Just(1),
                    Just(u32::MAX),
                    Just(0x7fff_ffff),
                    any::<u32>()
                ]
            )
                .prop_map(|(at, value)| ByteMutation::Field { at, value }),
            (any::<usize>(), 1usize..64).prop_map(|(at, len)| ByteMutation::Delete { at, len }),
            (any::<usize>(), 1usize..256).prop_map(|(at, len)| ByteMutation::Duplicate { at, len }),
        ]
    }

    fn mutate_bytes(mut b: Vec<u8>, mutations: &[ByteMutation]) -> Vec<u8> {
        for m in mutations {
            let n = b.len().max(1);
            match *m {
                ByteMutation::Replace { at, byte } => {
                    if !b.is_empty() {
                        let at = at % b.len();
                        b[at] = byte;
                    }
                }
                ByteMutation::Field { at, value } => {
                    if b.len() >= 4 {
                        let at = at % (b.len() - 3);
                        b[at..at + 4].copy_from_slice(&value.to_le_bytes());
                    }
                }
                ByteMutation::Delete { at, len } => {
                    let at = at % n;
                    let end = (at + len).min(b.len());
                    if at < end {
                        b.drain(at..end);
                    }
                }
                ByteMutation::Duplicate { at, len } => {
                    let at = at % n;
                    let end = (at + len).min(b.len());
                    let piece = b[at.min(b.len())..end].to_vec();
                    b.splice(end..end, piece);
                }
            }
        }
        b
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig { cases: 1500, ..Default::default() })]

        /// Property: whatever bytes an .fmu holds, opening and unpacking it is a typed error or
        /// a success, never a panic, and unpacking writes only inside its extraction folder.
        #[test]
        fn mutated_archives_are_read_or_refused_never_panic(
            ms in proptest::collection::vec(byte_mutation(), 1..5)
        ) {
            let d = tempfile::tempdir().unwrap();
            let p = d.path().join("x.fmu");
            std::fs::write(&p, mutate_bytes(small_fmu(), &ms)).unwrap();
            let root = d.path().join("extract");
            std::fs::create_dir(&root).unwrap();
            if FmuArchive::open(&p).is_ok() {
                if let Ok(dir) = extract::unpack(&p, &root, &ArchiveLimits::default()) {
                    let inside: Vec<_> = std::fs::read_dir(&root).unwrap().map(|e| e.unwrap().path()).collect();
                    proptest::prop_assert_eq!(inside, vec![dir.path().to_path_buf()]);
                }
            }
            // the archive's own folder holds only what the test put there
            let mut names: Vec<_> = std::fs::read_dir(d.path()).unwrap()
                .map(|e| e.unwrap().file_name().into_string().unwrap()).collect();
            names.sort();
            proptest::prop_assert_eq!(names, vec!["extract".to_string(), "x.fmu".to_string()]);
        }
    }

    #[test]
    fn the_unmutated_small_fmu_opens_and_unpacks() {
        // the property above starts from an archive that passes, so mutations probe real paths
        let d = tempfile::tempdir().unwrap();
        let p = d.path().join("x.fmu");
        std::fs::write(&p, small_fmu()).unwrap();
        let a = FmuArchive::open(&p).unwrap();
        assert_eq!(a.model.model_name, "MassSpring");
        let dir = extract::unpack(&p, d.path(), &ArchiveLimits::default()).unwrap();
        let csv = std::fs::read_to_string(dir.path().join("resources/table.csv")).unwrap();
        assert!(csv.starts_with("y,r\n0,0.46"));
    }

    #[test]
    fn stale_extraction_folders_are_removed_live_ones_kept() {
        let root = tempfile::tempdir().unwrap();
        // a folder whose owner died: its lock file is unlocked
        let stale = root.path().join("master-fmu-dead");
        std::fs::create_dir_all(stale.join("binaries")).unwrap();
        std::fs::write(stale.join(".lock"), b"").unwrap();
        // a folder in use: locked through another descriptor
        let live = root.path().join("master-fmu-live");
        std::fs::create_dir_all(&live).unwrap();
        let lock = std::fs::File::create(live.join(".lock")).unwrap();
        assert!(super::extract::try_lock(&lock));
        // someone else's folder and a fresh lockless one are never touched
        std::fs::create_dir_all(root.path().join("fmu-other")).unwrap();
        std::fs::create_dir_all(root.path().join("master-fmu-new")).unwrap();
        assert_eq!(crate::fmu::remove_stale_extractions(root.path()), 1);
        assert!(!stale.exists());
        assert!(live.exists() && root.path().join("fmu-other").exists());
        assert!(root.path().join("master-fmu-new").exists());
        drop(lock);
        assert_eq!(crate::fmu::remove_stale_extractions(root.path()), 1);
        assert!(!live.exists());
        // lockless and older than the grace period: removed only if empty and named as an
        // extraction is (a killed master left it before taking its lock)
        let hour_ago = std::time::SystemTime::now() - std::time::Duration::from_secs(3600);
        let old = |name: &str, with_file: bool| {
            let dir = root.path().join(name);
            std::fs::create_dir_all(&dir).unwrap();
            if with_file {
                std::fs::write(dir.join("notes.txt"), b"the user's").unwrap();
            }
            std::fs::File::open(&dir)
                .unwrap()
                .set_modified(hour_ago)
                .unwrap();
            dir
        };
        let empty = old("master-fmu-a1B2c3", false);
        let users = old("master-fmu-study", true);
        let full = old("master-fmu-x9Y8z7", true);
        assert_eq!(crate::fmu::remove_stale_extractions(root.path()), 1);
        assert!(!empty.exists() && users.exists() && full.exists());
    }
}
