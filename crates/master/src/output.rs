//! Atomic file output: every result file (CSV, SVG, JSON summary) is written to a temporary
//! file in the destination folder, fsync'ed and renamed over the destination, so a reader never
//! sees a half-written file and a failed run leaves nothing behind.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard, PoisonError};

use crate::coupling::{ColumnInfo, SimOutput};
use crate::slave::ScalarType;

/// Failure to write an output file.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    #[error("cannot write '{path}': {source}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("CSV '{path}': row {row} has {got} values but the header has {expected} columns")]
    RowLength {
        path: PathBuf,
        row: usize,
        got: usize,
        expected: usize,
    },
    #[error(
        "cannot write '{path}': it exists and is not a regular file (a device, FIFO, socket or \
         folder), which writing results would replace; choose another output path"
    )]
    NotAFile { path: PathBuf },
    #[error("cannot write '{path}': the folder '{folder}' does not exist")]
    NoFolder { path: PathBuf, folder: PathBuf },
    #[error("cannot write '{path}': '{folder}' is not a folder")]
    NotAFolder { path: PathBuf, folder: PathBuf },
    #[error(
        "cannot write '{path}': its name is {bytes} bytes long, more than the {NAME_MAX_BYTES} \
         a file name may have"
    )]
    NameTooLong { path: PathBuf, bytes: usize },
    #[error("cannot write into the folder '{folder}' (for '{path}'): {source}")]
    FolderNotWritable {
        path: PathBuf,
        folder: PathBuf,
        source: std::io::Error,
    },
    #[error("cannot write '{output}': it is the same file as {what} '{other}'")]
    SameFile {
        output: PathBuf,
        what: &'static str,
        other: PathBuf,
    },
    #[error("cannot serialise '{path}': {source}")]
    Json {
        path: PathBuf,
        #[source]
        source: serde_json::Error,
    },
}

fn io_err(path: &Path) -> impl FnOnce(std::io::Error) -> OutputError + '_ {
    move |source| OutputError::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// Removes `path` if it is a regular file or a symbolic link (an earlier result of that name);
/// a folder, FIFO or device of that name is left alone, and no file is no error.
pub fn remove_stale_file(path: &Path) -> std::io::Result<()> {
    let removable = std::fs::symlink_metadata(path)
        .is_ok_and(|m| m.file_type().is_file() || m.file_type().is_symlink());
    if !removable {
        return Ok(());
    }
    match std::fs::remove_file(path) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => Err(e),
        _ => Ok(()),
    }
}

/// Temporary files being written, not yet renamed onto their destination: a second Ctrl-C,
/// which ends the process at once, removes them ([`give_up_unfinished`]), so that an aborted
/// write leaves no partial file behind. `None` once given up: no file is created after that.
static UNFINISHED: Mutex<Option<Vec<PathBuf>>> = Mutex::new(Some(Vec::new()));

fn unfinished_files() -> MutexGuard<'static, Option<Vec<PathBuf>>> {
    UNFINISHED.lock().unwrap_or_else(PoisonError::into_inner)
}

/// Removes every temporary file still being written ([`write_unfinished`]) and refuses to
/// create any more; for a process about to exit without unwinding.
pub fn give_up_unfinished() {
    let files = unfinished_files().take().unwrap_or_default();
    for path in files {
        let _ = std::fs::remove_file(path);
    }
}

/// A file written in full to a temporary file in its destination's folder, flushed and
/// fsync'ed, waiting for [`Unfinished::commit`] to rename it onto the destination; dropped
/// uncommitted, the temporary file is removed and the destination left as it was. Several
/// files written this way and committed together replace the earlier ones only once all of
/// them are written.
pub struct Unfinished {
    path: PathBuf,
    tmp: tempfile::NamedTempFile,
    _listed: Listed,
}

/// A temporary file's entry in [`UNFINISHED`], removed when dropped.
struct Listed(PathBuf);

impl Drop for Listed {
    fn drop(&mut self) {
        if let Some(files) = unfinished_files().as_mut() {
            files.retain(|p| p != &self.0);
        }
    }
}

/// The name prefix of the temporary files results are written to before they are renamed.
pub const UNFINISHED_PREFIX: &str = ".master-unfinished-";

/// How old an unlocked temporary file must be before another master removes it \[s\]: a file
/// just created is locked a moment later.
pub const ABANDONED_AFTER_S: u64 = 60;

/// Removes the temporary files in `dir` that a master killed while writing left behind
/// (SIGKILL, a closed terminal's SIGHUP): ours by their prefix, unlocked (no live process
/// writes them) and older than [`ABANDONED_AFTER_S`]. Returns how many.
pub fn remove_abandoned_files(dir: &Path) -> usize {
    if !cfg!(unix) {
        return 0;
    }
    let Ok(entries) = std::fs::read_dir(dir) else {
        return 0;
    };
    let mut removed = 0;
    for entry in entries.flatten() {
        let name = entry.file_name();
        if !name.to_string_lossy().starts_with(UNFINISHED_PREFIX) {
            continue;
        }
        let Ok(meta) = entry.metadata() else { continue };
        let old = crate::fmu::extract::age_s(&meta).is_some_and(|age| age >= ABANDONED_AFTER_S);
        if !(meta.is_file() && old) {
            continue;
        }
        let path = entry.path();
        // opened without blocking (a FIFO put there in the meantime is not waited on); a link
        // put there is removed itself, not its target
        let unlocked =
            crate::input::open_regular_file(&path).is_ok_and(|f| crate::fmu::extract::try_lock(&f));
        if unlocked && std::fs::remove_file(&path).is_ok() {
            removed += 1;
        }
    }
    removed
}

/// A temporary file in `dir`, created and listed in [`UNFINISHED`] under its lock, so that
/// [`give_up_unfinished`] sees every file created before it and none is created after it.
fn listed_temporary_file(dir: &Path) -> std::io::Result<(tempfile::NamedTempFile, Listed)> {
    // once per folder and process, outside the list's lock: a sweep writes a file per run into
    // one folder, and a second Ctrl-C must not wait for a scan
    static SCANNED: Mutex<Option<std::collections::HashSet<PathBuf>>> = Mutex::new(None);
    let first = SCANNED
        .lock()
        .unwrap_or_else(PoisonError::into_inner)
        .get_or_insert_with(Default::default)
        .insert(dir.to_path_buf());
    if first {
        remove_abandoned_files(dir);
    }
    let mut files = unfinished_files();
    let Some(list) = files.as_mut() else {
        return Err(std::io::Error::new(
            std::io::ErrorKind::Interrupted,
            "the process is ending (interrupted twice)",
        ));
    };
    let mut builder = tempfile::Builder::new();
    builder.prefix(UNFINISHED_PREFIX);
    // results are ordinary files: read-write for all as far as the user's umask allows (a
    // private umask keeps them private), where a temporary file would be 0600
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    let tmp = builder.tempfile_in(dir)?;
    // held while the file is written: another master tells it from one a dead master left
    crate::fmu::extract::try_lock(tmp.as_file());
    list.push(tmp.path().to_path_buf());
    let listed = Listed(tmp.path().to_path_buf());
    Ok((tmp, listed))
}

impl Unfinished {
    /// Where the file goes.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Renames the temporary file onto the destination.
    pub fn commit(self) -> Result<(), OutputError> {
        let Unfinished { path, tmp, _listed } = self;
        tmp.persist(&path).map(drop).map_err(|e| OutputError::Io {
            path,
            source: e.error,
        })
    }
}

/// Writes `path`'s content into a temporary file beside it: `fill` writes into a buffered
/// temporary file in the same folder, which is flushed and fsync'ed; [`Unfinished::commit`]
/// renames it onto `path`. On any error the temporary file is removed and `path` is left
/// untouched. A `path` that exists and is not a regular file (or a symbolic link, which the
/// rename replaces) is refused: renaming onto it would replace a device such as /dev/null, or
/// a FIFO.
pub fn write_unfinished<F>(path: &Path, fill: F) -> Result<Unfinished, OutputError>
where
    F: FnOnce(&mut dyn Write) -> Result<(), OutputError>,
{
    check_file_or_absent(path)?;
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    // listed before it is filled; on an error both go (the entry first, then the file)
    let (tmp, listed) = listed_temporary_file(&dir).map_err(io_err(path))?;
    {
        let mut w = std::io::BufWriter::new(tmp.as_file());
        fill(&mut w)?;
        w.flush().map_err(io_err(path))?;
    }
    tmp.as_file().sync_all().map_err(io_err(path))?;
    Ok(Unfinished {
        path: path.to_path_buf(),
        tmp,
        _listed: listed,
    })
}

/// Writes `path` atomically ([`write_unfinished`], then committed at once).
pub fn write_atomic<F>(path: &Path, fill: F) -> Result<(), OutputError>
where
    F: FnOnce(&mut dyn Write) -> Result<(), OutputError>,
{
    write_unfinished(path, fill)?.commit()
}

/// The longest file name (in bytes) the master writes: Linux's NAME_MAX, which the common
/// file systems share.
pub const NAME_MAX_BYTES: usize = 255;

/// The outputs can be written: their folders exist, are folders and take a new file (a file is
/// created and removed again in each), and their names are not too long. Checked before a
/// command computes anything, so that a mistyped, read-only or full folder is named at once,
/// not after a long run.
pub fn check_folders_exist(outputs: &[PathBuf]) -> Result<(), OutputError> {
    for out in outputs {
        let folder = match out.parent() {
            Some(p) if !p.as_os_str().is_empty() => p,
            _ => Path::new("."),
        };
        let (path, folder_buf) = (out.clone(), folder.to_path_buf());
        if !folder.is_dir() {
            return Err(if folder.exists() {
                OutputError::NotAFolder {
                    path,
                    folder: folder_buf,
                }
            } else {
                OutputError::NoFolder {
                    path,
                    folder: folder_buf,
                }
            });
        }
        let bytes = out.file_name().map_or(0, |n| n.as_encoded_bytes().len());
        if bytes > NAME_MAX_BYTES {
            return Err(OutputError::NameTooLong { path, bytes });
        }
        // a probe file, removed when dropped
        tempfile::Builder::new()
            .prefix(".master-probe-")
            .tempfile_in(folder)
            .map_err(|source| OutputError::FolderNotWritable {
                path,
                folder: folder_buf,
                source,
            })?;
    }
    Ok(())
}

/// An output path that exists must be a regular file or a symbolic link (which the rename of
/// an atomic write replaces), not a device such as /dev/null, a FIFO or a folder.
fn check_file_or_absent(path: &Path) -> Result<(), OutputError> {
    match std::fs::symlink_metadata(path) {
        Ok(meta) if !(meta.file_type().is_file() || meta.file_type().is_symlink()) => {
            Err(OutputError::NotAFile {
                path: path.to_path_buf(),
            })
        }
        _ => Ok(()),
    }
}

/// What a path names, for telling whether two paths are the same file: the canonical path
/// of an existing file, else its canonical folder and its name (None: no such folder).
fn identity(p: &Path) -> Option<PathBuf> {
    if let Ok(c) = std::fs::canonicalize(p) {
        return Some(c);
    }
    let name = p.file_name()?;
    let parent = match p.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    std::fs::canonicalize(parent).ok().map(|d| d.join(name))
}

/// Two existing paths that are one file under two names (a hard link).
#[cfg(unix)]
fn same_inode(a: &Path, b: &Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    match (std::fs::metadata(a), std::fs::metadata(b)) {
        (Ok(x), Ok(y)) => x.dev() == y.dev() && x.ino() == y.ino(),
        _ => false,
    }
}

#[cfg(not(unix))]
fn same_inode(_: &Path, _: &Path) -> bool {
    false
}

/// Refuses to start a command whose output files would replace one of its inputs, or each
/// other, or that cannot be written as files: each output is compared with every input and
/// every other output (symbolic links resolved, hard links too), and one that exists must be
/// a file (or a link, which the write replaces), not a folder, FIFO or device. Called before
/// anything is written, so that a command never writes some of its outputs and then fails on
/// another.
pub fn check_outputs_apart(inputs: &[PathBuf], outputs: &[PathBuf]) -> Result<(), OutputError> {
    for out in outputs {
        check_file_or_absent(out)?;
    }
    let ids = |ps: &[PathBuf]| ps.iter().map(|p| identity(p)).collect::<Vec<_>>();
    let (input_ids, output_ids) = (ids(inputs), ids(outputs));
    for (k, (out, id)) in outputs.iter().zip(&output_ids).enumerate() {
        let same = |other: &Path, other_id: &Option<PathBuf>| {
            (id.is_some() && id == other_id) || same_inode(out, other)
        };
        if let Some(i) = (0..inputs.len()).find(|&i| same(&inputs[i], &input_ids[i])) {
            return Err(OutputError::SameFile {
                output: out.clone(),
                what: "the input",
                other: inputs[i].clone(),
            });
        }
        if let Some(j) = (0..k).find(|&j| same(&outputs[j], &output_ids[j])) {
            return Err(OutputError::SameFile {
                output: out.clone(),
                what: "the output",
                other: outputs[j].clone(),
            });
        }
    }
    Ok(())
}

/// Writes a whole byte string atomically.
pub fn write_bytes_atomic(path: &Path, bytes: &[u8]) -> Result<(), OutputError> {
    bytes_unfinished(path, bytes)?.commit()
}

/// A whole byte string written beside `path`, not yet committed ([`write_unfinished`]).
pub fn bytes_unfinished(path: &Path, bytes: &[u8]) -> Result<Unfinished, OutputError> {
    write_unfinished(path, |w| w.write_all(bytes).map_err(io_err(path)))
}

/// Writes a value as pretty JSON atomically.
pub fn write_json_atomic<T: serde::Serialize>(path: &Path, value: &T) -> Result<(), OutputError> {
    json_unfinished(path, value)?.commit()
}

/// A value as pretty JSON written beside `path`, not yet committed ([`write_unfinished`]).
pub fn json_unfinished<T: serde::Serialize>(
    path: &Path,
    value: &T,
) -> Result<Unfinished, OutputError> {
    let text = serde_json::to_string_pretty(value).map_err(|source| OutputError::Json {
        path: path.to_path_buf(),
        source,
    })?;
    bytes_unfinished(path, text.as_bytes())
}

/// Quotes a CSV field if it contains a separator, quote or newline (RFC 4180).
pub fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// Writes a numeric CSV table atomically. Every row must have `header.len()` values.
/// Numbers are written with Rust's shortest round-trip formatting (no precision loss), in
/// exponential form outside 1e-4..1e16 in magnitude ([`crate::show::num`]).
pub fn write_csv_atomic<'a, I>(path: &Path, header: &[String], rows: I) -> Result<(), OutputError>
where
    I: IntoIterator<Item = &'a [f64]>,
{
    write_atomic(path, |w| {
        let head: Vec<String> = header.iter().map(|h| csv_field(h)).collect();
        writeln!(w, "{}", head.join(",")).map_err(io_err(path))?;
        for (i, row) in rows.into_iter().enumerate() {
            if row.len() != header.len() {
                return Err(OutputError::RowLength {
                    path: path.to_path_buf(),
                    row: i,
                    got: row.len(),
                    expected: header.len(),
                });
            }
            let mut first = true;
            for v in row {
                if !first {
                    w.write_all(b",").map_err(io_err(path))?;
                }
                first = false;
                // 1e-300 as such, not as 300 zeros and a 1; exact as before
                write!(w, "{}", crate::show::num(*v)).map_err(io_err(path))?;
            }
            w.write_all(b"\n").map_err(io_err(path))?;
        }
        Ok(())
    })
}

/// The CSV header of results: each column's label, and after an Enumeration column one
/// holding its item names (`label (item)`).
pub fn results_header(out: &SimOutput) -> Vec<String> {
    let mut head = Vec::with_capacity(out.header.len());
    for (c, h) in out.header.iter().enumerate() {
        head.push(h.clone());
        if out.column_info(c).scalar_type() == ScalarType::Enumeration {
            head.push(format!("{h} (item)"));
        }
    }
    head
}

/// Writes results as CSV atomically, each value as its type reads: Reals in Rust's shortest
/// round-trip form (a whole one with `.0`), Integers and Enumerations as integers (an Enumeration followed by its item
/// name), Booleans as 0/1, Strings quoted (RFC 4180).
pub fn write_results_csv(path: &Path, out: &SimOutput) -> Result<(), OutputError> {
    results_csv_unfinished(path, out)?.commit()
}

/// [`write_results_csv`], not yet committed ([`write_unfinished`]).
pub fn results_csv_unfinished(path: &Path, out: &SimOutput) -> Result<Unfinished, OutputError> {
    let types: Vec<ColumnInfo> = (0..out.header.len()).map(|c| out.column_info(c)).collect();
    write_unfinished(path, |w| {
        let head: Vec<String> = results_header(out).iter().map(|h| csv_field(h)).collect();
        writeln!(w, "{}", head.join(",")).map_err(io_err(path))?;
        let mut line = String::new();
        for row in out.rows() {
            line.clear();
            for (c, (&v, info)) in row.iter().zip(&types).enumerate() {
                if c > 0 {
                    line.push(',');
                }
                match info.scalar_type() {
                    // the shortest text that reads back as the same number, in exponent
                    // form beyond 1e16 (1e300 would print as 301 digits, which pandas reads as
                    // a Python integer) and below 1e-4; a whole Real with its decimal point
                    ScalarType::Real => {
                        let _ = std::fmt::Write::write_fmt(
                            &mut line,
                            format_args!("{}", crate::show::real(v)),
                        );
                    }
                    ScalarType::Integer => {
                        let _ = std::fmt::Write::write_fmt(
                            &mut line,
                            format_args!("{}", crate::show::num(v)),
                        );
                    }
                    ScalarType::Boolean => line.push(if v != 0.0 { '1' } else { '0' }),
                    ScalarType::Enumeration => {
                        let _ = std::fmt::Write::write_fmt(&mut line, format_args!("{v},"));
                        line.push_str(&csv_field(info.item(v).unwrap_or("")));
                    }
                    ScalarType::String => {
                        let t = out.text(v).unwrap_or("");
                        line.push('"');
                        line.push_str(&t.replace('"', "\"\""));
                        line.push('"');
                    }
                }
            }
            line.push('\n');
            w.write_all(line.as_bytes()).map_err(io_err(path))?;
        }
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A temporary file a killed master left (old, unlocked) is removed by the next write into
    /// its folder; one a live master writes (locked) or one just created stays, and so do a
    /// user's files.
    #[cfg(unix)]
    #[test]
    fn a_killed_masters_unfinished_files_are_removed_by_the_next() {
        let dir = tempfile::tempdir().unwrap();
        let hour_ago = std::time::SystemTime::now() - std::time::Duration::from_secs(3600);
        let file = |name: &str, age: Option<std::time::SystemTime>| {
            let f = std::fs::File::create(dir.path().join(name)).unwrap();
            if let Some(t) = age {
                f.set_modified(t).unwrap();
            }
            f
        };
        file(&format!("{UNFINISHED_PREFIX}dead"), Some(hour_ago));
        let live = file(&format!("{UNFINISHED_PREFIX}live"), Some(hour_ago));
        assert!(crate::fmu::extract::try_lock(&live));
        file(&format!("{UNFINISHED_PREFIX}new"), None);
        file(".tmp-users", Some(hour_ago));
        write_atomic(&dir.path().join("r.csv"), |w| {
            w.write_all(b"x").map_err(io_err(Path::new("r.csv")))
        })
        .unwrap();
        let mut names: Vec<String> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        let expected = [
            ".master-unfinished-live",
            ".master-unfinished-new",
            ".tmp-users",
            "r.csv",
        ];
        assert_eq!(names, expected);
        drop(live);
    }

    /// Before a run: a folder that is a file, a name longer than a file system takes, and a
    /// folder that is missing are each named; a writable folder passes and keeps no probe.
    #[test]
    fn outputs_are_checked_writable_before_a_run() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("afile");
        std::fs::write(&file, b"x").unwrap();
        let e = check_folders_exist(&[file.join("x.csv")]).unwrap_err();
        assert!(matches!(e, OutputError::NotAFolder { .. }), "{e}");
        assert!(e.to_string().contains("is not a folder"), "{e}");
        let e = check_folders_exist(&[dir.path().join("no/x.csv")]).unwrap_err();
        assert!(matches!(e, OutputError::NoFolder { .. }), "{e}");
        let long = dir.path().join(format!("{}.meta.json", "x".repeat(250)));
        let e = check_folders_exist(&[long]).unwrap_err();
        assert!(e.to_string().contains("260 bytes long"), "{e}");
        check_folders_exist(&[dir.path().join("r.csv"), PathBuf::from("r.csv")]).unwrap();
        let left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
        assert_eq!(left.len(), 1, "{left:?}");
    }

    #[test]
    fn csv_round_trip_and_quoting() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a.csv");
        let header = vec!["time [s]".to_string(), "x,y [m]".to_string()];
        let tiny = 4.785669883657919e-300;
        let rows = [
            vec![0.0, 1.5],
            vec![0.1, -2.25e-7],
            vec![0.2, tiny],
            vec![1e300, 0.001],
        ];
        write_csv_atomic(&p, &header, rows.iter().map(|r| r.as_slice())).unwrap();
        let text = std::fs::read_to_string(&p).unwrap();
        assert_eq!(
            text,
            "time [s],\"x,y [m]\"\n0,1.5\n0.1,-2.25e-7\n0.2,4.785669883657919e-300\n1e300,0.001\n"
        );
        // every value reads back exactly
        let back: Vec<f64> = text
            .lines()
            .skip(1)
            .flat_map(|l| l.split(',').map(|v| v.parse::<f64>().unwrap()))
            .collect();
        assert_eq!(back, rows.concat());
        // only the result is left in the folder, no temporary file
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[cfg(unix)]
    #[test]
    fn a_fifo_or_a_folder_is_not_replaced_by_results() {
        let dir = tempfile::tempdir().unwrap();
        let fifo = dir.path().join("fifo");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status();
        assert!(made.is_ok_and(|s| s.success()), "mkfifo");
        let folder = dir.path().join("folder");
        std::fs::create_dir(&folder).unwrap();
        for p in [&fifo, &folder] {
            let err = write_bytes_atomic(p, b"results").unwrap_err();
            assert!(matches!(err, OutputError::NotAFile { .. }), "{err}");
            assert!(err.to_string().contains("not a regular file"), "{err}");
        }
        use std::os::unix::fs::FileTypeExt;
        assert!(std::fs::symlink_metadata(&fifo)
            .unwrap()
            .file_type()
            .is_fifo());
        assert!(folder.is_dir());
        // a regular file is replaced as before, and nothing else is left in the folder
        let file = dir.path().join("r.csv");
        std::fs::write(&file, "old").unwrap();
        write_bytes_atomic(&file, b"new").unwrap();
        assert_eq!(std::fs::read_to_string(&file).unwrap(), "new");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 3);
    }

    #[test]
    fn an_output_that_is_an_input_or_another_output_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let system = dir.path().join("sys.json");
        std::fs::write(&system, "{}").unwrap();
        let results = dir.path().join("r.csv");
        // the same file under another spelling
        let spelled = dir.path().join(".").join("sys.json");
        let err = check_outputs_apart(std::slice::from_ref(&system), &[results.clone(), spelled])
            .unwrap_err();
        assert!(
            matches!(
                &err,
                OutputError::SameFile {
                    what: "the input",
                    ..
                }
            ),
            "{err}"
        );
        assert!(err.to_string().contains("same file as the input"), "{err}");
        // two outputs that do not exist yet, one name
        let twice = [results.clone(), dir.path().join("./r.csv")];
        let err = check_outputs_apart(std::slice::from_ref(&system), &twice).unwrap_err();
        assert!(
            matches!(
                &err,
                OutputError::SameFile {
                    what: "the output",
                    ..
                }
            ),
            "{err}"
        );
        // a hard link to the input
        #[cfg(unix)]
        {
            let link = dir.path().join("link.csv");
            std::fs::hard_link(&system, &link).unwrap();
            assert!(check_outputs_apart(std::slice::from_ref(&system), &[link]).is_err());
        }
        let meta = dir.path().join("r.meta.json");
        check_outputs_apart(&[system], &[results, meta]).unwrap();
    }

    #[test]
    fn failed_write_leaves_no_file_and_keeps_old_content() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a.csv");
        let header = vec!["t".to_string(), "x".to_string()];
        let bad = [vec![0.0, 1.0], vec![1.0]];
        let err = write_csv_atomic(&p, &header, bad.iter().map(|r| r.as_slice())).unwrap_err();
        assert!(matches!(
            err,
            OutputError::RowLength {
                row: 1,
                got: 1,
                expected: 2,
                ..
            }
        ));
        assert!(!p.exists());
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
        // an existing file survives a failed rewrite untouched
        std::fs::write(&p, "old").unwrap();
        let _ = write_csv_atomic(&p, &header, bad.iter().map(|r| r.as_slice()));
        assert_eq!(std::fs::read_to_string(&p).unwrap(), "old");
    }

    #[test]
    fn results_csv_writes_every_type() {
        use crate::coupling::Summary;
        let col = |ty, items: Vec<(i32, String)>| ColumnInfo {
            ty: Some(ty),
            items,
            ..Default::default()
        };
        let out = SimOutput {
            header: vec![
                "time [s]".into(),
                "a.x [m]".into(),
                "a.n".into(),
                "a.b".into(),
                "a.e".into(),
                "a.s".into(),
            ],
            data: vec![0.0, 1.5, 3.0, 1.0, 2.0, 0.0, 0.5, -2.0, -4.0, 0.0, 1.0, 1.0],
            summary: Summary {
                steps: 1,
                rejected_steps: 0,
                simulated_time_s: 0.5,
                wall_time_s: 0.0,
                realtime_ratio: 0.0,
                terminated: None,
                failed: None,
            },
            columns: vec![
                col(ScalarType::Real, vec![]),
                col(ScalarType::Integer, vec![]),
                col(ScalarType::Boolean, vec![]),
                col(
                    ScalarType::Enumeration,
                    vec![(1, "Option 1".into()), (2, "Option, 2".into())],
                ),
                col(ScalarType::String, vec![]),
            ],
            strings: vec!["Set me!".into(), "say \"hi\"".into()],
            decimation: None,
        };
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("r.csv");
        write_results_csv(&p, &out).unwrap();
        assert_eq!(
            std::fs::read_to_string(&p).unwrap(),
            "time [s],a.x [m],a.n,a.b,a.e,a.e (item),a.s\n\
             0.0,1.5,3,1,2,\"Option, 2\",\"Set me!\"\n\
             0.5,-2.0,-4,0,1,Option 1,\"say \"\"hi\"\"\"\n"
        );
    }

    #[test]
    fn missing_folder_is_an_io_error_naming_the_path() {
        let err = write_bytes_atomic(Path::new("/nonexistent-dir-xyz/a.csv"), b"x").unwrap_err();
        assert!(err.to_string().contains("/nonexistent-dir-xyz/a.csv"));
    }
}
