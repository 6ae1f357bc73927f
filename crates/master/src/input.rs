//! Reading input files (system descriptions, run sets) without hanging or filling memory:
//! only regular files are read (a FIFO or a device such as /dev/zero is refused before it is
//! read, so it can neither block the master nor feed it without end) and at most
//! [`MAX_TEXT_FILE_BYTES`].

use std::io::Read;
use std::path::Path;

/// Largest system description or run-set file read [bytes].
pub const MAX_TEXT_FILE_BYTES: u64 = 256 << 20;

/// Why a path that is not a regular file is not read.
pub const NOT_A_REGULAR_FILE: &str = "not a regular file (a FIFO, device, socket or folder)";

/// Opens `path` for reading if it is a regular file. On Unix it is opened non-blocking, so
/// opening a FIFO returns at once and is then refused.
pub fn open_regular_file(path: &Path) -> std::io::Result<std::fs::File> {
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        options.custom_flags(libc::O_NONBLOCK);
    }
    let file = options.open(path)?;
    if !file.metadata()?.is_file() {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            NOT_A_REGULAR_FILE,
        ));
    }
    Ok(file)
}

/// The UTF-8 text of a regular file of at most `max_bytes`.
pub fn read_text_file(path: &Path, max_bytes: u64) -> std::io::Result<String> {
    let file = open_regular_file(path)?;
    let mut text = String::new();
    file.take(max_bytes.saturating_add(1))
        .read_to_string(&mut text)?;
    if text.len() as u64 > max_bytes {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!("larger than the {max_bytes} bytes allowed"),
        ));
    }
    // the byte-order mark some Windows editors and spreadsheet exports put first is no text
    // (a JSON reader would stop at it, a CSV's first column would carry it in its name)
    if text.starts_with('\u{feff}') {
        text.drain(..'\u{feff}'.len_utf8());
    }
    Ok(text)
}

/// Deserialises a JSON object into a map, refusing a key given twice (serde_json's maps keep
/// the last one silently: `{"vehicle.speed": 500, "vehicle.speed": 83.3}` would run at 83.3
/// and never report the 500). For `#[serde(deserialize_with = "...")]`.
pub fn unique_keys<'de, D, V>(d: D) -> Result<std::collections::BTreeMap<String, V>, D::Error>
where
    D: serde::Deserializer<'de>,
    V: serde::Deserialize<'de>,
{
    struct Keys<V>(std::marker::PhantomData<V>);
    impl<'de, V: serde::Deserialize<'de>> serde::de::Visitor<'de> for Keys<V> {
        type Value = std::collections::BTreeMap<String, V>;

        fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
            f.write_str("an object of variable names")
        }

        fn visit_map<A: serde::de::MapAccess<'de>>(
            self,
            mut m: A,
        ) -> Result<Self::Value, A::Error> {
            let mut out = std::collections::BTreeMap::new();
            while let Some(key) = m.next_key::<String>()? {
                if out.contains_key(&key) {
                    return Err(serde::de::Error::custom(format!("`{key}` is given twice")));
                }
                let value = m.next_value()?;
                out.insert(key, value);
            }
            Ok(out)
        }
    }
    d.deserialize_map(Keys(std::marker::PhantomData))
}

/// What tells a file's content changed without reading it: size, modification time and, on
/// Unix, inode and status-change time (which a copy that keeps the modification time, `cp -p`,
/// still sets).
fn file_stamp(meta: &std::fs::Metadata) -> Option<(u64, std::time::SystemTime, u64, i64, i64)> {
    #[cfg(unix)]
    let (ino, ctime, ctime_ns) = {
        use std::os::unix::fs::MetadataExt;
        (meta.ino(), meta.ctime(), meta.ctime_nsec())
    };
    #[cfg(not(unix))]
    let (ino, ctime, ctime_ns) = (0, 0, 0);
    Some((meta.len(), meta.modified().ok()?, ino, ctime, ctime_ns))
}

/// The SHA-1 (hex) of the file at `path`, `None` if it cannot be read. Kept per path and
/// its size, modification time, inode and status-change time, so that the runs of a set sharing
/// an FMU read it once.
pub fn file_digest(path: &Path) -> Option<String> {
    type Stamp = (u64, std::time::SystemTime, u64, i64, i64);
    type Cache = std::collections::HashMap<std::path::PathBuf, (Stamp, String)>;
    static CACHE: std::sync::Mutex<Option<Cache>> = std::sync::Mutex::new(None);
    let meta = std::fs::metadata(path).ok()?;
    let key = file_stamp(&meta)?;
    if let Ok(cache) = CACHE.lock() {
        if let Some((stamp, digest)) = cache.as_ref().and_then(|c| c.get(path)) {
            if *stamp == key {
                return Some(digest.clone());
            }
        }
    }
    let mut hasher = sha1_smol::Sha1::new();
    let mut file = std::fs::File::open(path).ok()?;
    let mut buf = vec![0u8; 1 << 16];
    loop {
        let n = std::io::Read::read(&mut file, &mut buf).ok()?;
        if n == 0 {
            break;
        }
        hasher.update(&buf[..n]);
    }
    let digest = hasher.digest().to_string();
    if let Ok(mut cache) = CACHE.lock() {
        cache
            .get_or_insert_with(std::collections::HashMap::new)
            .insert(path.to_path_buf(), (key, digest.clone()));
    }
    Some(digest)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A file saved with a byte-order mark reads as its text: a system description from a
    /// Windows editor was refused ("line 1, column 1: expected value").
    #[test]
    fn a_byte_order_mark_is_not_part_of_the_text() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("bom.json");
        std::fs::write(&path, "\u{feff}{\"a\": 1}").unwrap();
        let text = read_text_file(&path, 1 << 20).unwrap();
        assert_eq!(text, "{\"a\": 1}");
        let v: serde_json::Value = serde_json::from_str(&text).unwrap();
        assert_eq!(v["a"], 1);
        // a mark inside the text is the text's
        std::fs::write(&path, "x\u{feff}").unwrap();
        assert_eq!(read_text_file(&path, 1 << 20).unwrap(), "x\u{feff}");
    }
}
