//! Packaging: read the models a built binary carries (its `rfmi_manifest`), check binaries
//! for their platform folders, and write one reproducible `.fmu` per model with the binaries
//! of every platform at hand.

use std::collections::BTreeMap;
use std::io::Write;
use std::path::{Path, PathBuf};

pub use fmu_binary::{Platform, Policy};
use zip::write::SimpleFileOptions;

use crate::capi::PackagedModel;

#[derive(Debug, thiserror::Error)]
pub enum PackageError {
    #[error("{path}: cannot load library: {reason}")]
    Load { path: PathBuf, reason: String },
    #[error("{path}: manifest cannot be decoded: {reason}")]
    Manifest { path: PathBuf, reason: String },
    #[error("{path}: model declaration error: {reason}")]
    Declaration { path: PathBuf, reason: String },
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{path}: zip: {source}")]
    Zip {
        path: PathBuf,
        source: zip::result::ZipError,
    },
    #[error("{}", list_problems(.0))]
    Binaries(Vec<String>),
}

fn list_problems(problems: &[String]) -> String {
    let mut s = format!(
        "{} problem(s) with the binaries, no FMU written:",
        problems.len()
    );
    for p in problems {
        s.push_str("\n  ");
        s.push_str(p);
    }
    s
}

/// One model's binary for one platform folder.
#[derive(Debug, Clone)]
pub struct PlatformBinary {
    pub platform: Platform,
    pub bytes: Vec<u8>,
    /// Where it was read from (for messages).
    pub source: PathBuf,
}

/// The problems of `bytes` as `model`'s binary in `platform`'s folder: format, architecture,
/// the FMI 2.0 functions its modelDescription.xml requires, and `policy`'s Linux rules. Each
/// problem is one line naming `source`; an empty list means it fits.
pub fn binary_problems_for(
    source: &Path,
    bytes: &[u8],
    platform: Platform,
    model: &PackagedModel,
    policy: &Policy,
) -> Vec<String> {
    let name = source.display();
    let required = match fmu_binary::required_functions(&model.model_description_xml) {
        Ok(r) => r,
        Err(e) => return vec![format!("{}: modelDescription.xml: {e}", model.identifier)],
    };
    let exports: &[&str] = required
        .get(&model.identifier)
        .map(Vec::as_slice)
        .unwrap_or(&[]);
    match fmu_binary::inspect(bytes) {
        Ok(info) => fmu_binary::check_binary(&info, platform, exports, policy)
            .into_iter()
            .map(|p| format!("{name} (for {platform}): {p}"))
            .collect(),
        Err(e) => vec![format!("{name} (for {platform}): {e}")],
    }
}

/// Read binaries built elsewhere from `dir`, laid out as `<platform>/<modelIdentifier>.<ext>`
/// (the `binaries/` folder of an FMU; `dir/binaries/` is used when it exists), for the
/// `models` being packaged. Every file must be a known model's binary in a known platform
/// folder other than `own_platform` (built here), fit that folder and export the FMI 2.0
/// functions; all problems are reported together and nothing is returned on any.
pub fn read_binaries_dir(
    dir: &Path,
    models: &[&PackagedModel],
    own_platform: Platform,
    policy: &Policy,
) -> Result<BTreeMap<String, Vec<PlatformBinary>>, PackageError> {
    let root = if dir.join("binaries").is_dir() {
        dir.join("binaries")
    } else {
        dir.to_path_buf()
    };
    let io = |path: &Path| {
        let path = path.to_path_buf();
        move |source| PackageError::Io { path, source }
    };
    let mut problems = Vec::new();
    let mut out: BTreeMap<String, Vec<PlatformBinary>> = BTreeMap::new();
    let mut folders: Vec<PathBuf> = std::fs::read_dir(&root)
        .map_err(io(&root))?
        .map(|e| e.map(|e| e.path()))
        .collect::<Result<_, _>>()
        .map_err(io(&root))?;
    folders.sort();
    for folder in folders {
        let folder_name = folder
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        if !folder.is_dir() {
            problems.push(format!(
                "{}: expected only platform folders in {}",
                folder.display(),
                root.display()
            ));
            continue;
        }
        let Some(platform) = Platform::from_folder(&folder_name) else {
            let known: Vec<&str> = Platform::ALL.iter().map(|p| p.folder()).collect();
            problems.push(format!(
                "{}: '{folder_name}' is no platform folder ({})",
                folder.display(),
                known.join(", ")
            ));
            continue;
        };
        if platform == own_platform {
            problems.push(format!(
                "{}: {platform} is built here; remove the folder or package on another platform",
                folder.display()
            ));
            continue;
        }
        let mut files: Vec<PathBuf> = std::fs::read_dir(&folder)
            .map_err(io(&folder))?
            .map(|e| e.map(|e| e.path()))
            .collect::<Result<_, _>>()
            .map_err(io(&folder))?;
        files.sort();
        for file in files {
            let file_name = file
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default();
            let model = models
                .iter()
                .find(|m| platform.library_file_name(&m.identifier) == file_name);
            let Some(model) = model else {
                let expected: Vec<String> = models
                    .iter()
                    .map(|m| platform.library_file_name(&m.identifier))
                    .collect();
                problems.push(format!(
                    "{}: not a binary of a model packaged here (expected one of {})",
                    file.display(),
                    expected.join(", ")
                ));
                continue;
            };
            let bytes = std::fs::read(&file).map_err(io(&file))?;
            let found = binary_problems_for(&file, &bytes, platform, model, policy);
            if found.is_empty() {
                out.entry(model.identifier.clone())
                    .or_default()
                    .push(PlatformBinary {
                        platform,
                        bytes,
                        source: file,
                    });
            } else {
                problems.extend(found);
            }
        }
    }
    if problems.is_empty() {
        Ok(out)
    } else {
        Err(PackageError::Binaries(problems))
    }
}

/// The models carried by the library at `path`, or `Ok(None)` if it is not one of ours.
pub fn read_manifest(path: &Path) -> Result<Option<Vec<PackagedModel>>, PackageError> {
    // SAFETY: loading a library runs its initialisers; we only load our own build outputs.
    let lib = unsafe { libloading::Library::new(path) }.map_err(|e| PackageError::Load {
        path: path.to_path_buf(),
        reason: e.to_string(),
    })?;
    type ManifestFn = unsafe extern "C" fn(*mut usize) -> *const u8;
    // SAFETY: the symbol, when present, has this signature (defined by `export_fmus!`).
    let bytes = unsafe {
        let Ok(f) = lib.get::<ManifestFn>(b"rfmi_manifest\0") else {
            return Ok(None);
        };
        let mut len = 0usize;
        let ptr = f(&mut len);
        if ptr.is_null() {
            return Err(PackageError::Manifest {
                path: path.to_path_buf(),
                reason: "null manifest".into(),
            });
        }
        std::slice::from_raw_parts(ptr, len).to_vec()
    };
    let models: Vec<Result<PackagedModel, String>> =
        bincode::deserialize(&bytes).map_err(|e| PackageError::Manifest {
            path: path.to_path_buf(),
            reason: e.to_string(),
        })?;
    models
        .into_iter()
        .map(|m| {
            m.map_err(|reason| PackageError::Declaration {
                path: path.to_path_buf(),
                reason,
            })
        })
        .collect::<Result<Vec<_>, _>>()
        .map(Some)
}

/// Write `<out_dir>/<identifier>.fmu` with `binaries/<platform>/<identifier>.<ext>` for each
/// of `binaries`. Entries are sorted and time-stamped 1980-01-01 so the same binaries give the
/// same bytes; the file is written to a temporary name and renamed. The modelDescription.xml
/// (and its GUID) is the same whatever the platforms.
pub fn write_fmu(
    out_dir: &Path,
    model: &PackagedModel,
    binaries: &[(Platform, &[u8])],
) -> Result<PathBuf, PackageError> {
    let target = out_dir.join(format!("{}.fmu", model.identifier));
    let tmp = out_dir.join(format!(".{}.fmu.tmp", model.identifier));
    let io = |source| PackageError::Io {
        path: tmp.clone(),
        source,
    };
    let zerr = |source| PackageError::Zip {
        path: tmp.clone(),
        source,
    };
    std::fs::create_dir_all(out_dir).map_err(io)?;
    let file = std::fs::File::create(&tmp).map_err(io)?;
    let mut zip = zip::ZipWriter::new(file);
    let base = SimpleFileOptions::default()
        .compression_method(zip::CompressionMethod::Deflated)
        .last_modified_time(zip::DateTime::default());
    let mut entries: Vec<(String, &[u8], u32)> = vec![
        (
            "modelDescription.xml".into(),
            model.model_description_xml.as_bytes(),
            0o644,
        ),
        (
            "documentation/index.html".into(),
            model.documentation_html.as_bytes(),
            0o644,
        ),
        // the licence texts travel with the binary they cover
        (
            "documentation/LICENSE-MIT.txt".into(),
            crate::xml::LICENSE_MIT.as_bytes(),
            0o644,
        ),
        (
            "documentation/LICENSE-APACHE.txt".into(),
            crate::xml::LICENSE_APACHE.as_bytes(),
            0o644,
        ),
    ];
    for (platform, bytes) in binaries {
        entries.push((
            format!(
                "binaries/{platform}/{}",
                platform.library_file_name(&model.identifier)
            ),
            bytes,
            0o755,
        ));
    }
    for (name, bytes) in &model.resources {
        entries.push((format!("resources/{name}"), bytes.as_slice(), 0o644));
    }
    entries.sort_by(|a, b| a.0.cmp(&b.0));
    for (name, bytes, mode) in entries {
        zip.start_file(name, base.unix_permissions(mode))
            .map_err(zerr)?;
        zip.write_all(bytes).map_err(io)?;
    }
    let file = zip.finish().map_err(zerr)?;
    file.sync_all().map_err(io)?;
    drop(file);
    std::fs::rename(&tmp, &target).map_err(io)?;
    Ok(target)
}
