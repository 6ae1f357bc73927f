//! Packaging: read the models a built binary carries (its `rfmi_manifest`) and write one
//! reproducible `.fmu` per model.

use std::io::Write;
use std::path::{Path, PathBuf};

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

/// Write `<out_dir>/<identifier>.fmu`. Entries are sorted and time-stamped 1980-01-01 so the
/// same build gives the same bytes; the file is written to a temporary name and renamed.
pub fn write_fmu(
    out_dir: &Path,
    model: &PackagedModel,
    binary: &[u8],
    platform: &str,
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
            format!("binaries/{platform}/{}.so", model.identifier),
            binary,
            0o755,
        ),
        (
            "documentation/index.html".into(),
            model.documentation_html.as_bytes(),
            0o644,
        ),
    ];
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
