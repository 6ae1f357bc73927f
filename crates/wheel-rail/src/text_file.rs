//! Reading a profile or contact-table file without hanging or filling memory: only a regular
//! file is read (a FIFO would block, a device such as /dev/zero would never end), and at most a
//! given size. The check runs inside an FMU too (a contact table named by a parameter).

use std::io::Read;
use std::path::Path;

/// Largest profile or contact-table file read, in bytes (a measured profile is some kB, a table
/// some MB).
pub const MAX_TEXT_FILE_BYTES: u64 = 64 << 20;

/// The UTF-8 text of `path`, if it is a regular file of at most `max_bytes`; the error says
/// why not.
pub fn read_text_file(path: &Path, max_bytes: u64) -> Result<String, String> {
    let meta = std::fs::metadata(path).map_err(|e| e.to_string())?;
    if !meta.is_file() {
        return Err("not a regular file (a FIFO, device or folder is not read)".into());
    }
    if meta.len() > max_bytes {
        return Err(format!(
            "{} bytes, larger than the {max_bytes} bytes allowed",
            meta.len()
        ));
    }
    let mut text = String::new();
    std::fs::File::open(path)
        .and_then(|f| {
            f.take(max_bytes.saturating_add(1))
                .read_to_string(&mut text)
        })
        .map_err(|e| e.to_string())?;
    if text.len() as u64 > max_bytes {
        return Err(format!("larger than the {max_bytes} bytes allowed"));
    }
    Ok(text)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_regular_files_of_bounded_size_are_read() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("p.txt");
        std::fs::write(&file, "0 0\n1 1\n").unwrap();
        assert_eq!(read_text_file(&file, 100).unwrap(), "0 0\n1 1\n");
        let e = read_text_file(&file, 4).unwrap_err();
        assert!(e.contains("larger than the 4 bytes"), "{e}");
        let e = read_text_file(dir.path(), 100).unwrap_err();
        assert!(e.contains("not a regular file"), "{e}");
        #[cfg(unix)]
        {
            let e = read_text_file(Path::new("/dev/zero"), 100).unwrap_err();
            assert!(e.contains("not a regular file"), "{e}");
            let fifo = dir.path().join("fifo");
            let made = std::process::Command::new("mkfifo").arg(&fifo).status();
            assert!(made.is_ok_and(|s| s.success()));
            // refused before opening: opening a FIFO without a writer would block
            let e = read_text_file(&fifo, 100).unwrap_err();
            assert!(e.contains("not a regular file"), "{e}");
        }
    }
}
