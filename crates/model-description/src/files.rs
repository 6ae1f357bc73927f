//! Reading a file named by a String parameter (e.g. a contact table) inside a host's process:
//! only a regular file (no FIFO, device or directory), only up to a size cap, and the metadata
//! is checked before the file is opened, so a FIFO cannot block initialisation and `/dev/zero`
//! cannot exhaust memory.

use std::io::Read;
use std::path::Path;

/// Largest parameter file the glue reads: 64 MiB (a contact table of a fine grid is ~1 MB).
pub const MAX_PARAMETER_FILE_BYTES: u64 = 64 * 1024 * 1024;

/// Why a parameter file was refused.
#[derive(Debug, thiserror::Error)]
pub enum ParameterFileError {
    #[error("cannot read '{path}': {source}")]
    Io {
        path: String,
        source: std::io::Error,
    },
    #[error("'{path}' is not a regular file ({kind})")]
    NotRegular { path: String, kind: &'static str },
    #[error("'{path}' is {size} bytes, more than the {max} bytes a parameter file may have")]
    TooLarge { path: String, size: u64, max: u64 },
    #[error("'{path}' is not UTF-8 text")]
    NotText { path: String },
}

fn kind_of(ft: std::fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if ft.is_fifo() {
            return "a FIFO";
        }
        if ft.is_char_device() {
            return "a character device";
        }
        if ft.is_block_device() {
            return "a block device";
        }
        if ft.is_socket() {
            return "a socket";
        }
    }
    if ft.is_dir() {
        "a directory"
    } else {
        "not a regular file"
    }
}

/// The text of the regular file at `path`, at most `max_bytes` long. Symbolic links are
/// followed; the type and size come from the metadata before the file is opened, and the read
/// itself stops after `max_bytes + 1` bytes in case the file grew in between.
pub fn read_parameter_file(path: &Path, max_bytes: u64) -> Result<String, ParameterFileError> {
    let shown = path.display().to_string();
    let io = |source| ParameterFileError::Io {
        path: shown.clone(),
        source,
    };
    let meta = std::fs::metadata(path).map_err(io)?;
    if !meta.file_type().is_file() {
        return Err(ParameterFileError::NotRegular {
            path: shown,
            kind: kind_of(meta.file_type()),
        });
    }
    let too_large = |size| ParameterFileError::TooLarge {
        path: shown.clone(),
        size,
        max: max_bytes,
    };
    if meta.len() > max_bytes {
        return Err(too_large(meta.len()));
    }
    let file = std::fs::File::open(path).map_err(io)?;
    let mut bytes = Vec::with_capacity(usize::try_from(meta.len()).unwrap_or(0));
    file.take(max_bytes.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(io)?;
    if bytes.len() as u64 > max_bytes {
        return Err(too_large(bytes.len() as u64));
    }
    String::from_utf8(bytes).map_err(|_| ParameterFileError::NotText { path: shown })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn regular_files_are_read_and_others_refused() {
        let dir = std::env::temp_dir().join(format!("md-files-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let f = dir.join("t.csv");
        std::fs::write(&f, "a,b\n1,2\n").unwrap();
        assert_eq!(
            read_parameter_file(&f, 100).ok().as_deref(),
            Some("a,b\n1,2\n")
        );
        assert!(matches!(
            read_parameter_file(&f, 4),
            Err(ParameterFileError::TooLarge {
                size: 8,
                max: 4,
                ..
            })
        ));
        assert!(matches!(
            read_parameter_file(&dir, 100),
            Err(ParameterFileError::NotRegular {
                kind: "a directory",
                ..
            })
        ));
        #[cfg(unix)]
        assert!(matches!(
            read_parameter_file(Path::new("/dev/zero"), 100),
            Err(ParameterFileError::NotRegular {
                kind: "a character device",
                ..
            })
        ));
        assert!(matches!(
            read_parameter_file(&dir.join("missing"), 100),
            Err(ParameterFileError::Io { .. })
        ));
        let _ = std::fs::remove_dir_all(&dir);
    }
}
