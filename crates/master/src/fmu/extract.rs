//! Safe unpacking of FMU archives: size and entry limits, refused paths, and extraction folders
//! that never pile up.
//!
//! * [`ArchiveLimits`]: an archive is refused when it has more entries, more unpacked bytes or
//!   a larger modelDescription.xml than the limits allow. The limits are checked on the sizes
//!   the archive declares before anything is read (so a zip bomb is refused, not extracted)
//!   and again on the bytes actually inflated (an entry that inflates to more than it
//!   declares is refused). Defaults: 65 536 entries, 4 GiB unpacked, 256 MiB of
//!   modelDescription.xml; each is raised with an environment variable (see
//!   [`ArchiveLimits::from_env`]).
//! * Entries with absolute paths, `..` components, NUL bytes, symbolic links or a name used
//!   twice are refused: nothing of such an archive is written.
//! * Each extraction folder (`<temp>/master-fmu-XXXXXX`) holds an exclusive lock on its
//!   `.lock` file for as long as the FMU is in use. The kernel drops the lock when the process
//!   ends in any way (SIGKILL, a segfaulting FMU, a second Ctrl-C), so the next process that
//!   unpacks an FMU removes every extraction folder whose lock it can take: folders never pile
//!   up in the temporary directory.

use std::collections::HashSet;
use std::io::{Read, Write};
use std::path::{Path, PathBuf};

use super::FmuError;

/// Environment variable raising [`ArchiveLimits::max_entries`].
pub const MAX_ENTRIES_VAR: &str = "MASTER_FMU_MAX_ENTRIES";
/// Environment variable raising [`ArchiveLimits::max_unpacked_bytes`].
pub const MAX_UNPACKED_BYTES_VAR: &str = "MASTER_FMU_MAX_UNPACKED_BYTES";
/// Environment variable raising [`ArchiveLimits::max_model_description_bytes`].
pub const MAX_MODEL_DESCRIPTION_BYTES_VAR: &str = "MASTER_FMU_MAX_MODEL_DESCRIPTION_BYTES";

/// Prefix of extraction folders in the temporary directory.
const EXTRACTION_PREFIX: &str = "master-fmu-";
/// A folder without a lock file is only taken for stale when it is older than this (it may be
/// one another process has just created).
const LOCKLESS_GRACE_S: u64 = 600;

/// How large an FMU archive may be once unpacked.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ArchiveLimits {
    /// Entries (files and folders) in the archive.
    pub max_entries: u64,
    /// Sum of the unpacked sizes of all entries [bytes].
    pub max_unpacked_bytes: u64,
    /// Unpacked size of modelDescription.xml [bytes].
    pub max_model_description_bytes: u64,
}

impl Default for ArchiveLimits {
    fn default() -> Self {
        ArchiveLimits {
            max_entries: 65_536,
            max_unpacked_bytes: 4 << 30,
            max_model_description_bytes: 256 << 20,
        }
    }
}

impl ArchiveLimits {
    /// The defaults, each replaced by its environment variable when set
    /// ([`MAX_ENTRIES_VAR`], [`MAX_UNPACKED_BYTES_VAR`], [`MAX_MODEL_DESCRIPTION_BYTES_VAR`]:
    /// a plain integer). A variable that is set but not an integer is an error, not ignored.
    pub fn from_env() -> Result<Self, FmuError> {
        let mut limits = ArchiveLimits::default();
        for (var, field) in [
            (MAX_ENTRIES_VAR, &mut limits.max_entries),
            (MAX_UNPACKED_BYTES_VAR, &mut limits.max_unpacked_bytes),
            (
                MAX_MODEL_DESCRIPTION_BYTES_VAR,
                &mut limits.max_model_description_bytes,
            ),
        ] {
            if let Some(v) = std::env::var_os(var) {
                let s = v.to_string_lossy();
                *field = s
                    .trim()
                    .parse::<u64>()
                    .map_err(|_| FmuError::LimitSetting {
                        variable: var,
                        value: s.to_string(),
                    })?;
            }
        }
        Ok(limits)
    }
}

/// What is known of an archive's entries after [`check_entries`].
pub(crate) struct EntryCheck {
    /// Declared unpacked size of modelDescription.xml, if present.
    pub model_description_bytes: Option<u64>,
}

fn too_large(path: &Path, what: String, limit: u64, var: &'static str) -> FmuError {
    FmuError::TooLarge {
        path: path.to_path_buf(),
        what,
        limit,
        variable: var,
    }
}

/// The first entry name stored twice in the central directory of the zip at `path`, read
/// from the file itself: the zip reader keeps one entry per name (the last), so a second
/// `modelDescription.xml` or `SystemStructure.ssd` would be read silently in place of the
/// first. Reads the fixed-size headers and names only, at most `max_entries` of them.
pub(crate) fn duplicate_entry_name<R: Read + std::io::Seek>(
    path: &Path,
    zip: &zip::ZipArchive<R>,
    max_entries: u64,
) -> std::io::Result<Option<String>> {
    use std::io::{BufReader, Seek, SeekFrom};
    const CENTRAL_HEADER: u32 = 0x0201_4b50;
    let mut file = BufReader::new(crate::input::open_regular_file(path)?);
    // the directory's offset as the reader gives it, or past data prepended to the archive
    let mut found = false;
    for start in [
        zip.central_directory_start(),
        zip.offset().saturating_add(zip.central_directory_start()),
    ] {
        let mut signature = [0u8; 4];
        file.seek(SeekFrom::Start(start))?;
        if file.read_exact(&mut signature).is_ok()
            && u32::from_le_bytes(signature) == CENTRAL_HEADER
        {
            file.seek(SeekFrom::Start(start))?;
            found = true;
            break;
        }
    }
    if !found {
        return Ok(None);
    }
    let mut names: HashSet<Vec<u8>> = HashSet::new();
    let mut header = [0u8; 46];
    for _ in 0..max_entries.saturating_add(1) {
        if file.read_exact(&mut header).is_err()
            || u32::from_le_bytes([header[0], header[1], header[2], header[3]]) != CENTRAL_HEADER
        {
            break;
        }
        let field = |at: usize| usize::from(u16::from_le_bytes([header[at], header[at + 1]]));
        let (name_len, extra_len, comment_len) = (field(28), field(30), field(32));
        let mut name = vec![0u8; name_len];
        file.read_exact(&mut name)?;
        file.seek_relative((extra_len + comment_len) as i64)?;
        // a folder entry `x/` and a file `x` count as one name, as in `check_entries`
        let key = name.strip_suffix(b"/").unwrap_or(&name).to_vec();
        if !names.insert(key) {
            return Ok(Some(String::from_utf8_lossy(&name).into_owned()));
        }
    }
    Ok(None)
}

/// Checks every entry's name and declared size against `limits` (reads only the central
/// directory, nothing is inflated).
pub(crate) fn check_entries<R: Read + std::io::Seek>(
    path: &Path,
    zip: &mut zip::ZipArchive<R>,
    limits: &ArchiveLimits,
) -> Result<EntryCheck, FmuError> {
    let n = zip.len() as u64;
    if n > limits.max_entries {
        return Err(too_large(
            path,
            format!("it has {n} entries"),
            limits.max_entries,
            MAX_ENTRIES_VAR,
        ));
    }
    let stored_twice =
        duplicate_entry_name(path, zip, limits.max_entries).map_err(|e| FmuError::NotAZip {
            path: path.to_path_buf(),
            reason: e.to_string(),
        })?;
    if let Some(name) = stored_twice {
        return Err(FmuError::UnsafeEntry {
            path: path.to_path_buf(),
            entry: name.escape_debug().to_string(),
            reason: "the name is used twice (which copy would be used is undefined)".into(),
        });
    }
    let mut total: u64 = 0;
    let mut names = HashSet::new();
    let mut md = None;
    for i in 0..zip.len() {
        let entry = zip.by_index_raw(i).map_err(|e| FmuError::NotAZip {
            path: path.to_path_buf(),
            reason: e.to_string(),
        })?;
        let name = entry.name().to_string();
        let refused = |reason: &str| FmuError::UnsafeEntry {
            path: path.to_path_buf(),
            entry: name.escape_debug().to_string(),
            reason: reason.to_string(),
        };
        if entry.enclosed_name().is_none() || name.contains('\\') {
            return Err(refused(
                "its path is absolute, leaves the archive ('..') or is not a plain path",
            ));
        }
        if entry.is_symlink() {
            return Err(refused("symbolic links are not allowed in an FMU"));
        }
        if !names.insert(name.trim_end_matches('/').to_string()) {
            return Err(refused(
                "the name is used twice (which copy would be used is undefined)",
            ));
        }
        total = total.saturating_add(entry.size());
        if name == "modelDescription.xml" {
            md = Some(entry.size());
        }
    }
    if total > limits.max_unpacked_bytes {
        return Err(too_large(
            path,
            format!("it unpacks to {total} bytes"),
            limits.max_unpacked_bytes,
            MAX_UNPACKED_BYTES_VAR,
        ));
    }
    if let Some(size) = md {
        if size > limits.max_model_description_bytes {
            return Err(too_large(
                path,
                format!("its modelDescription.xml has {size} bytes"),
                limits.max_model_description_bytes,
                MAX_MODEL_DESCRIPTION_BYTES_VAR,
            ));
        }
    }
    Ok(EntryCheck {
        model_description_bytes: md,
    })
}

/// Reads an entry, refusing it when it inflates to more than `limit` bytes (whatever it
/// declares).
pub(crate) fn read_limited<R: Read>(
    mut reader: R,
    limit: u64,
    out: &mut Vec<u8>,
) -> std::io::Result<bool> {
    let got = reader.by_ref().take(limit).read_to_end(out)? as u64;
    if got < limit {
        return Ok(true);
    }
    // exactly at the limit: fine only if nothing follows
    let mut probe = [0u8; 1];
    Ok(reader.read(&mut probe)? == 0)
}

/// An extraction folder and the lock that marks it as in use.
#[derive(Debug)]
pub(crate) struct ExtractionDir {
    // Field order: the folder is removed while the lock is still held.
    dir: tempfile::TempDir,
    _lock: std::fs::File,
}

impl ExtractionDir {
    pub fn path(&self) -> &Path {
        self.dir.path()
    }

    /// A new extraction folder in `root`, locked while it lives, after removing the stale
    /// ones there (left by a master that was killed): an FMU's files, or the FMU members of an
    /// SSP archive.
    pub(crate) fn create(root: &Path) -> Result<Self, String> {
        remove_stale_extractions(root);
        let dir = tempfile::Builder::new()
            .prefix(EXTRACTION_PREFIX)
            .rand_bytes(6)
            .tempdir_in(root)
            .map_err(|e| format!("cannot create a folder in '{}': {e}", root.display()))?;
        let lock = std::fs::File::create(dir.path().join(".lock"))
            .map_err(|e| format!("cannot create the lock file: {e}"))?;
        if !try_lock(&lock) {
            return Err("cannot lock the new extraction folder".into());
        }
        Ok(ExtractionDir { dir, _lock: lock })
    }
}

#[cfg(unix)]
pub(crate) fn try_lock(file: &std::fs::File) -> bool {
    use std::os::unix::io::AsRawFd;
    // SAFETY: flock on a descriptor we own; no memory is passed.
    unsafe { libc::flock(file.as_raw_fd(), libc::LOCK_EX | libc::LOCK_NB) == 0 }
}

#[cfg(not(unix))]
pub(crate) fn try_lock(_file: &std::fs::File) -> bool {
    // Elsewhere a folder in use cannot be removed anyway; the lock file only marks it.
    true
}

/// Whole seconds since the file was last modified (`None` if the system does not say, or the
/// time lies ahead): how the leftovers of a dead master are told from files just created.
pub(crate) fn age_s(meta: &std::fs::Metadata) -> Option<u64> {
    Some(meta.modified().ok()?.elapsed().ok()?.as_secs())
}

/// Whether `name` is an extraction folder's: the prefix and the 6 random letters or digits
/// `unpack` gives it.
fn is_extraction_name(name: &str) -> bool {
    name.strip_prefix(EXTRACTION_PREFIX)
        .is_some_and(|rest| rest.len() == 6 && rest.chars().all(|c| c.is_ascii_alphanumeric()))
}

/// Removes the extraction folders in `root` that no live process holds (their lock can be
/// taken, or they have no lock file, are empty and older than the grace period). Returns how
/// many.
pub fn remove_stale_extractions(root: &Path) -> usize {
    let Ok(entries) = std::fs::read_dir(root) else {
        return 0;
    };
    let mut removed = 0;
    for entry in entries.flatten() {
        let name = entry.file_name();
        if !name.to_string_lossy().starts_with(EXTRACTION_PREFIX) {
            continue;
        }
        let dir = entry.path();
        // never follow a link planted under our prefix
        if !entry.file_type().is_ok_and(|t| t.is_dir()) {
            continue;
        }
        let stale = match std::fs::File::open(dir.join(".lock")) {
            Ok(lock) => try_lock(&lock),
            // a master killed between creating the folder and its lock left it empty; a
            // folder of someone else's under our prefix (not our name pattern, or not empty)
            // is left alone
            Err(_) => {
                is_extraction_name(&name.to_string_lossy())
                    && std::fs::read_dir(&dir).is_ok_and(|mut d| d.next().is_none())
                    && entry
                        .metadata()
                        .ok()
                        .and_then(|m| age_s(&m))
                        .is_some_and(|age| age > LOCKLESS_GRACE_S)
            }
        };
        if stale && std::fs::remove_dir_all(&dir).is_ok() {
            removed += 1;
        }
    }
    removed
}

/// Unpacks the archive at `path` into a new locked extraction folder under `root`, after
/// removing stale ones there. Every entry is checked again (names, links, sizes as inflated).
pub(crate) fn unpack(
    path: &Path,
    root: &Path,
    limits: &ArchiveLimits,
) -> Result<ExtractionDir, FmuError> {
    let err = |reason: String| FmuError::Unpack {
        path: path.to_path_buf(),
        reason,
    };
    let file = crate::input::open_regular_file(path).map_err(|e| err(e.to_string()))?;
    let mut zip = zip::ZipArchive::new(file).map_err(|e| err(e.to_string()))?;
    check_entries(path, &mut zip, limits)?;
    let folder = ExtractionDir::create(root).map_err(err)?;
    let mut left = limits.max_unpacked_bytes;
    for i in 0..zip.len() {
        // every failure names the entry (as the archive spells it until it is read)
        let listed = zip.name_for_index(i).unwrap_or("?").to_string();
        let mut entry = zip
            .by_index(i)
            .map_err(|e| err(format!("entry '{}': {e}", listed.escape_debug())))?;
        let Some(rel) = entry.enclosed_name() else {
            return Err(err(format!(
                "entry '{}' leaves the archive",
                entry.name().escape_debug()
            )));
        };
        // a hostile name's control characters are shown escaped, not sent to the terminal
        let shown = || rel.display().to_string().escape_debug().to_string();
        let at = |e: std::io::Error| err(format!("entry '{}': {e}", shown()));
        let target = folder.path().join(&rel);
        if entry.is_dir() {
            std::fs::create_dir_all(&target).map_err(at)?;
            continue;
        }
        if let Some(parent) = target.parent() {
            std::fs::create_dir_all(parent).map_err(at)?;
        }
        let declared = entry.size();
        let mut out = std::fs::File::create(&target).map_err(at)?;
        // at most what it declares and what is left of the total
        let cap = declared.min(left);
        let copied = std::io::copy(&mut entry.by_ref().take(cap), &mut out).map_err(at)?;
        let mut probe = [0u8; 1];
        let more = entry.read(&mut probe).map_err(at)?;
        if more > 0 {
            return Err(err(format!(
                "entry '{}' inflates to more than the {declared} bytes it declares \
                 (or beyond the {} bytes allowed in total, {MAX_UNPACKED_BYTES_VAR})",
                shown(),
                limits.max_unpacked_bytes
            )));
        }
        left -= copied;
        out.flush().map_err(at)?;
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            // keep the execute bits of binaries; never setuid/setgid/sticky or world-writable
            let mode = entry.unix_mode().unwrap_or(0o644) & 0o755 | 0o600;
            std::fs::set_permissions(&target, std::fs::Permissions::from_mode(mode)).map_err(at)?;
        }
    }
    Ok(folder)
}

/// The folder extraction folders are made in: the system's temporary directory.
pub(crate) fn extraction_root() -> PathBuf {
    std::env::temp_dir()
}
