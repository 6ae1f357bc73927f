//! Where the files of an SSP come from: a .ssp zip (SystemStructure.ssd at its root, FMUs,
//! .ssv and .ssm files inside) or a bare .ssd in a folder (its references relative to that
//! folder). References are relative URIs; in a zip none may leave the archive.

use std::io::{Read, Write};
use std::path::{Path, PathBuf};

use super::SspError;

/// Largest .ssd/.ssv/.ssm read (a parameter set of a large model is a few MB).
const MAX_XML_BYTES: u64 = 64 << 20;

pub(super) enum Package {
    Zip {
        path: PathBuf,
        zip: Box<zip::ZipArchive<std::fs::File>>,
        /// Bytes the FMUs unpacked from the archive may take together: the unpacked-size limit
        /// of an FMU (`MASTER_FMU_MAX_UNPACKED_BYTES`), for the archive as a whole (each
        /// member unpacked counts once).
        budget: u64,
        /// The FMU members unpacked so far, by reference: one file per member, shared by the
        /// components that use it as the instances of one FMU file of a JSON system are (which
        /// gives an FMU that can be instantiated only once per process a copy per instance).
        unpacked: std::collections::HashMap<String, PathBuf>,
    },
    Dir {
        ssd: PathBuf,
        dir: PathBuf,
        /// The parameter and mapping files read beside the .ssd (inputs a run must not
        /// overwrite with its results).
        read: Vec<PathBuf>,
    },
}

impl Package {
    /// Opens `path`: a `.ssp` zip or an `.ssd` file.
    pub fn open(path: &Path) -> Result<Self, SspError> {
        let read_err = |reason: String| SspError::Read {
            path: path.to_path_buf(),
            reason,
        };
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("ssp") => {
                // a FIFO or device is refused without blocking on it or reading it
                let f =
                    crate::input::open_regular_file(path).map_err(|e| read_err(e.to_string()))?;
                let zip = zip::ZipArchive::new(f)
                    .map_err(|e| read_err(format!("not a zip archive: {e}")))?;
                let limits =
                    crate::fmu::ArchiveLimits::from_env().map_err(|e| read_err(e.to_string()))?;
                // the search for a name stored twice reads at most this many entries: one
                // beyond could hide a second SystemStructure.ssd
                let n = zip.len() as u64;
                if n > limits.max_entries {
                    return Err(read_err(format!(
                        "it has {n} entries, more than the limit of {} (raise it with {})",
                        limits.max_entries,
                        crate::fmu::extract::MAX_ENTRIES_VAR
                    )));
                }
                let twice =
                    crate::fmu::extract::duplicate_entry_name(path, &zip, limits.max_entries)
                        .map_err(|e| read_err(e.to_string()))?;
                if let Some(name) = twice {
                    return Err(read_err(format!(
                        "the entry '{}' is stored twice (which copy would be read is undefined)",
                        name.escape_debug()
                    )));
                }
                Ok(Package::Zip {
                    path: path.to_path_buf(),
                    zip: Box::new(zip),
                    budget: limits.max_unpacked_bytes,
                    unpacked: std::collections::HashMap::new(),
                })
            }
            Some("ssd") => {
                // the .ssd itself is read later (read_ssd); here only what it is
                match std::fs::metadata(path) {
                    Err(e) => return Err(read_err(e.to_string())),
                    Ok(m) if !m.is_file() => {
                        return Err(read_err(crate::input::NOT_A_REGULAR_FILE.into()))
                    }
                    Ok(_) => {}
                }
                Ok(Package::Dir {
                    ssd: path.to_path_buf(),
                    dir: path.parent().map(Path::to_path_buf).unwrap_or_default(),
                    read: Vec::new(),
                })
            }
            _ => Err(read_err(
                "an SSP is a .ssp archive or a .ssd file".to_string(),
            )),
        }
    }

    /// How the package is named in messages.
    pub fn label(&self) -> String {
        match self {
            Package::Zip { path, .. } => path.display().to_string(),
            Package::Dir { ssd, .. } => ssd.display().to_string(),
        }
    }

    /// How file `rel` of the package is named in messages.
    pub fn file_label(&self, rel: &str) -> String {
        match self {
            Package::Zip { path, .. } => format!("{}:{rel}", path.display()),
            Package::Dir { dir, .. } => dir.join(rel).display().to_string(),
        }
    }

    /// Where file `rel` of the package comes from, for the record of a run: the archive's
    /// absolute path and the member (`/work/x.ssp:resources/a.fmu`), or the file's absolute
    /// path beside a bare .ssd.
    pub fn source_of(&self, rel: &str) -> PathBuf {
        let absolute = |p: &Path| std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf());
        match self {
            Package::Zip { path, .. } => {
                PathBuf::from(format!("{}:{rel}", absolute(path).display()))
            }
            Package::Dir { dir, .. } => absolute(&dir.join(rel)),
        }
    }

    /// The SSD's text and its label.
    pub fn read_ssd(&mut self) -> Result<(String, String), SspError> {
        match self {
            Package::Zip { .. } => {
                let label = self.file_label("SystemStructure.ssd");
                let text = self.read_text("SystemStructure.ssd")?;
                Ok((text, label))
            }
            Package::Dir { ssd, .. } => {
                let ssd = ssd.clone();
                let text = read_file_limited(&ssd, MAX_XML_BYTES)?;
                Ok((text, ssd.display().to_string()))
            }
        }
    }

    /// Reads the XML file at the normalised reference `rel`.
    pub fn read_text(&mut self, rel: &str) -> Result<String, SspError> {
        match self {
            Package::Zip { path, zip, .. } => {
                let label = format!("{}:{rel}", path.display());
                let entry = zip.by_name(rel).map_err(|e| SspError::Read {
                    path: PathBuf::from(&label),
                    reason: member_error(e),
                })?;
                let mut buf = Vec::new();
                entry
                    .take(MAX_XML_BYTES + 1)
                    .read_to_end(&mut buf)
                    .map_err(|e| SspError::Read {
                        path: PathBuf::from(&label),
                        reason: e.to_string(),
                    })?;
                if buf.len() as u64 > MAX_XML_BYTES {
                    return Err(SspError::Read {
                        path: PathBuf::from(&label),
                        reason: format!("larger than {MAX_XML_BYTES} bytes"),
                    });
                }
                String::from_utf8(buf).map_err(|_| SspError::Read {
                    path: PathBuf::from(&label),
                    reason: "not UTF-8 text".into(),
                })
            }
            Package::Dir { dir, read, .. } => {
                let file = dir.join(rel);
                let text = read_file_limited(&file, MAX_XML_BYTES)?;
                read.push(file);
                Ok(text)
            }
        }
    }

    /// The files other than the .ssd and the FMUs read from a folder (none from an archive,
    /// whose members are not files of their own).
    pub fn files_read(&self) -> &[PathBuf] {
        match self {
            Package::Zip { .. } => &[],
            Package::Dir { read, .. } => read,
        }
    }

    /// The FMU at reference `rel` as a file: unpacked into `dest` from a zip once per member (in
    /// a folder named by the first component that uses it; the components that share the member
    /// share the file, and the loading gives an FMU that can be instantiated only once per
    /// process a copy per instance), the file itself next to a bare .ssd. The FMUs of an
    /// archive unpack within one budget, checked against each entry's declared size before a
    /// byte is written and against what it really gives (a small archive must not fill the
    /// disk first and be refused after).
    pub fn fmu_file(&mut self, rel: &str, dest: &Path, index: usize) -> Result<PathBuf, SspError> {
        match self {
            Package::Zip {
                path,
                zip,
                budget,
                unpacked,
            } => {
                if let Some(out) = unpacked.get(rel) {
                    return Ok(out.clone());
                }
                let label = PathBuf::from(format!("{}:{rel}", path.display()));
                let too_large = |what: String| SspError::Read {
                    path: label.clone(),
                    reason: format!(
                        "{what}, more than the {budget} bytes left of the FMUs' limit \
                         (MASTER_FMU_MAX_UNPACKED_BYTES)"
                    ),
                };
                let mut entry = zip.by_name(rel).map_err(|e| SspError::Read {
                    path: label.clone(),
                    reason: member_error(e),
                })?;
                if entry.size() > *budget {
                    return Err(too_large(format!("declares {} bytes", entry.size())));
                }
                let file_name = rel.rsplit('/').next().unwrap_or("component.fmu");
                // a folder per member, named by its first component: two members may share a
                // file name
                let dir = dest.join(index.to_string());
                let out = dir.join(file_name);
                let io = |e: std::io::Error| SspError::Read {
                    path: label.clone(),
                    reason: format!("cannot unpack: {e}"),
                };
                // an FMU is a zip archive: its first bytes are a local file header (a member
                // of gigabytes of zeros is refused here, not after it was written out)
                let mut head = [0u8; 4];
                let begun = match entry.read_exact(&mut head) {
                    Ok(()) => head == *b"PK\x03\x04",
                    Err(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => false,
                    Err(e) => return Err(io(e)),
                };
                if !begun {
                    return Err(SspError::Read {
                        path: label.clone(),
                        reason: "not an FMU: it does not begin as a zip archive".into(),
                    });
                }
                std::fs::create_dir_all(&dir).map_err(io)?;
                let mut f = std::fs::File::create(&out).map_err(io)?;
                let copied = f
                    .write_all(&head)
                    .and_then(|()| {
                        let rest = budget.saturating_sub(head.len() as u64) + 1;
                        std::io::copy(&mut (&mut entry).take(rest), &mut f)
                    })
                    .map(|n| n + 4);
                let n = match copied {
                    Ok(n) if n <= *budget => n,
                    Ok(n) => {
                        drop(f);
                        let _ = std::fs::remove_file(&out);
                        return Err(too_large(format!("unpacks to more than {}", n - 1)));
                    }
                    Err(e) => {
                        drop(f);
                        let _ = std::fs::remove_file(&out);
                        return Err(io(e));
                    }
                };
                *budget -= n;
                unpacked.insert(rel.to_string(), out.clone());
                Ok(out)
            }
            // relative to the folder, which is the system's base folder
            Package::Dir { .. } => Ok(PathBuf::from(rel)),
        }
    }

    /// Normalises a relative URI reference of the SSD: percent-decoded, `.` and `..`
    /// resolved; `Err` is the reason it is refused.
    pub fn resolve(&self, reference: &str) -> Result<String, String> {
        let shown = crate::show::text(reference);
        let r = reference.trim();
        if r.contains('#') {
            return Err(format!(
                "'{shown}' has a fragment (references into other SSDs are not supported)"
            ));
        }
        if let Some((scheme, _)) = r.split_once(':') {
            if !scheme.is_empty()
                && scheme
                    .chars()
                    .all(|c| c.is_ascii_alphanumeric() || "+-.".contains(c))
            {
                return Err(format!(
                    "'{shown}' is an absolute URI (only references relative to the SSD)"
                ));
            }
        }
        if r.starts_with('/') || r.is_empty() {
            return Err(format!("'{shown}' is not a relative reference to a file"));
        }
        let decoded = percent_decode(r)
            .ok_or_else(|| format!("'{shown}' has an invalid percent-encoding"))?;
        let mut parts: Vec<&str> = Vec::new();
        let in_zip = matches!(self, Package::Zip { .. });
        let mut ups = 0usize;
        for seg in decoded.split('/') {
            match seg {
                "" | "." => {}
                ".." => {
                    if parts.pop().is_none() {
                        if in_zip {
                            return Err(format!("'{shown}' points outside the archive"));
                        }
                        ups += 1;
                    }
                }
                s => parts.push(s),
            }
        }
        if parts.is_empty() {
            return Err(format!("'{shown}' names no file"));
        }
        let mut out = "../".repeat(ups);
        out.push_str(&parts.join("/"));
        Ok(out)
    }
}

fn read_file_limited(path: &Path, limit: u64) -> Result<String, SspError> {
    let err = |reason: String| SspError::Read {
        path: path.to_path_buf(),
        reason,
    };
    let f = crate::input::open_regular_file(path).map_err(|e| err(e.to_string()))?;
    let mut buf = Vec::new();
    f.take(limit + 1)
        .read_to_end(&mut buf)
        .map_err(|e| err(e.to_string()))?;
    if buf.len() as u64 > limit {
        return Err(err(format!("larger than {limit} bytes")));
    }
    String::from_utf8(buf).map_err(|_| err("not UTF-8 text".into()))
}

fn percent_decode(s: &str) -> Option<String> {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' {
            let hex = s.get(i + 1..i + 3)?;
            out.push(u8::from_str_radix(hex, 16).ok()?);
            i += 3;
        } else {
            out.push(b[i]);
            i += 1;
        }
    }
    String::from_utf8(out).ok()
}

/// Why a member could not be opened: missing, or stored in a way the reader does not support
/// (LZMA, bzip2, encryption), which the zip reader names.
fn member_error(e: zip::result::ZipError) -> String {
    match e {
        zip::result::ZipError::FileNotFound => "no such file in the archive".into(),
        other => format!("cannot read it from the archive: {other}"),
    }
}
