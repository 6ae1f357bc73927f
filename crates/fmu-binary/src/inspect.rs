//! Read one shared library with the `object` crate: no loading, any host can read any format.

use std::collections::BTreeSet;
use std::fmt;

use object::elf;
use object::read::elf::{Dyn, ElfFile, FileHeader, ProgramHeader};
use object::{FileKind, Object};

use crate::version::SymbolVersion;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BinaryFormat {
    Elf,
    Pe,
    MachO,
}

impl fmt::Display for BinaryFormat {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            BinaryFormat::Elf => "ELF (Linux)",
            BinaryFormat::Pe => "PE (Windows)",
            BinaryFormat::MachO => "Mach-O (macOS)",
        })
    }
}

#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Architecture {
    X86,
    X86_64,
    Aarch64,
    /// Any other architecture, as the `object` crate names it.
    Other(String),
}

impl fmt::Display for Architecture {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Architecture::X86 => f.write_str("x86 (32-bit)"),
            Architecture::X86_64 => f.write_str("x86-64"),
            Architecture::Aarch64 => f.write_str("aarch64"),
            Architecture::Other(name) => f.write_str(name),
        }
    }
}

/// A symbol version a binary needs from a library (ELF `.gnu.version_r`), e.g.
/// `libc.so.6` / `GLIBC_2.14`.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord)]
pub struct VersionNeed {
    pub library: String,
    pub version: String,
}

/// One architecture's image (a universal Mach-O binary has several, everything else one).
#[derive(Debug, Clone)]
pub struct Image {
    pub architecture: Architecture,
    /// Exported symbol names; Mach-O's leading underscore removed, so `fmi2DoStep` everywhere.
    pub exports: BTreeSet<String>,
    /// Libraries the image needs: ELF `DT_NEEDED`, PE import DLLs, Mach-O load commands.
    pub needed_libraries: Vec<String>,
    /// ELF `DT_RPATH` / `DT_RUNPATH` entries, as (`"RPATH"` or `"RUNPATH"`, value).
    pub search_paths: Vec<(&'static str, String)>,
    /// ELF symbol versions needed (empty for PE and Mach-O).
    pub version_needs: Vec<VersionNeed>,
}

impl Image {
    /// The newest `GLIBC_x.y` version the image needs, i.e. the oldest glibc it loads on.
    pub fn newest_glibc(&self) -> Option<SymbolVersion> {
        self.version_needs
            .iter()
            .filter_map(|n| SymbolVersion::from_symbol_version(&n.version, "GLIBC_"))
            .max()
    }
}

/// What [`inspect`] read from a shared library.
#[derive(Debug, Clone)]
pub struct BinaryInfo {
    pub format: BinaryFormat,
    /// True for a Mach-O universal ("fat") binary.
    pub universal: bool,
    pub images: Vec<Image>,
}

impl BinaryInfo {
    /// The newest glibc symbol version any image needs: the oldest glibc the binary loads on.
    /// `None` for non-ELF binaries and for ELF binaries without versioned glibc symbols.
    pub fn newest_glibc(&self) -> Option<SymbolVersion> {
        self.images.iter().filter_map(Image::newest_glibc).max()
    }

    /// The names of `functions` that some image does not export.
    pub fn missing_exports<'a>(&self, functions: &[&'a str]) -> Vec<&'a str> {
        functions
            .iter()
            .copied()
            .filter(|f| self.images.iter().any(|i| !i.exports.contains(*f)))
            .collect()
    }
}

#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum BinaryError {
    #[error("not a shared library this check can read (ELF, PE or Mach-O): {0}")]
    UnknownFormat(String),
    #[error("malformed {format} file: {reason}")]
    Malformed {
        format: &'static str,
        reason: String,
    },
}

fn malformed(format: &'static str) -> impl Fn(object::Error) -> BinaryError {
    move |e| BinaryError::Malformed {
        format,
        reason: e.to_string(),
    }
}

/// Read a shared library's format, architecture(s), exports, needed libraries and (ELF)
/// symbol versions and search paths.
pub fn inspect(data: &[u8]) -> Result<BinaryInfo, BinaryError> {
    let kind = FileKind::parse(data).map_err(|e| BinaryError::UnknownFormat(e.to_string()))?;
    match kind {
        FileKind::Elf32 => {
            let file = object::read::elf::ElfFile32::<object::Endianness>::parse(data)
                .map_err(malformed("ELF"))?;
            Ok(single(BinaryFormat::Elf, elf_image(&file)?))
        }
        FileKind::Elf64 => {
            let file = object::read::elf::ElfFile64::<object::Endianness>::parse(data)
                .map_err(malformed("ELF"))?;
            Ok(single(BinaryFormat::Elf, elf_image(&file)?))
        }
        FileKind::Pe32 | FileKind::Pe64 => {
            let file = object::File::parse(data).map_err(malformed("PE"))?;
            Ok(single(BinaryFormat::Pe, generic_image(&file, "PE", false)?))
        }
        FileKind::MachO32 | FileKind::MachO64 => {
            let file = object::File::parse(data).map_err(malformed("Mach-O"))?;
            Ok(single(
                BinaryFormat::MachO,
                generic_image(&file, "Mach-O", true)?,
            ))
        }
        FileKind::MachOFat32 => {
            let fat = object::read::macho::MachOFatFile32::parse(data)
                .map_err(malformed("universal Mach-O"))?;
            universal(data, fat.arches())
        }
        FileKind::MachOFat64 => {
            let fat = object::read::macho::MachOFatFile64::parse(data)
                .map_err(malformed("universal Mach-O"))?;
            universal(data, fat.arches())
        }
        other => Err(BinaryError::UnknownFormat(format!("{other:?}"))),
    }
}

fn single(format: BinaryFormat, image: Image) -> BinaryInfo {
    BinaryInfo {
        format,
        universal: false,
        images: vec![image],
    }
}

fn universal<A: object::read::macho::FatArch>(
    data: &[u8],
    arches: &[A],
) -> Result<BinaryInfo, BinaryError> {
    let mut images = Vec::new();
    for arch in arches {
        let slice = arch.data(data).map_err(malformed("universal Mach-O"))?;
        let file = object::File::parse(slice).map_err(malformed("Mach-O"))?;
        if !matches!(file, object::File::MachO32(_) | object::File::MachO64(_)) {
            return Err(BinaryError::Malformed {
                format: "universal Mach-O",
                reason: "a slice is not a Mach-O image".into(),
            });
        }
        images.push(generic_image(&file, "Mach-O", true)?);
    }
    if images.is_empty() {
        return Err(BinaryError::Malformed {
            format: "universal Mach-O",
            reason: "no architecture in the file".into(),
        });
    }
    Ok(BinaryInfo {
        format: BinaryFormat::MachO,
        universal: true,
        images,
    })
}

fn architecture(arch: object::Architecture) -> Architecture {
    match arch {
        object::Architecture::I386 => Architecture::X86,
        object::Architecture::X86_64 => Architecture::X86_64,
        object::Architecture::Aarch64 => Architecture::Aarch64,
        other => Architecture::Other(format!("{other:?}")),
    }
}

/// PE and Mach-O through `object`'s common interface.
fn generic_image(
    file: &object::File<'_>,
    format: &'static str,
    strip_underscore: bool,
) -> Result<Image, BinaryError> {
    let exports = file
        .exports()
        .map_err(malformed(format))?
        .iter()
        .map(|e| {
            let name = String::from_utf8_lossy(e.name());
            match name.strip_prefix('_') {
                Some(stripped) if strip_underscore => stripped.to_string(),
                _ => name.into_owned(),
            }
        })
        .collect();
    let mut needed_libraries: Vec<String> = Vec::new();
    for import in file.imports().map_err(malformed(format))? {
        let library = String::from_utf8_lossy(import.library()).into_owned();
        if !library.is_empty() && !needed_libraries.contains(&library) {
            needed_libraries.push(library);
        }
    }
    Ok(Image {
        architecture: architecture(file.architecture()),
        exports,
        needed_libraries,
        search_paths: Vec::new(),
        version_needs: Vec::new(),
    })
}

fn elf_image<'data, H: FileHeader<Endian = object::Endianness>>(
    file: &ElfFile<'data, H, &'data [u8]>,
) -> Result<Image, BinaryError> {
    let m = malformed("ELF");
    let endian = file.endian();
    let data = file.data();
    // the loader maps each loadable segment from the file: one that reaches past the file's
    // end (a truncated library) faults (SIGBUS) when touched, inside dlopen, before any error
    // can be returned
    let segments = file.elf_program_headers();
    if !segments.iter().any(|p| p.p_type(endian) == elf::PT_LOAD) {
        return Err(BinaryError::Malformed {
            format: "ELF",
            reason: "no loadable segment".into(),
        });
    }
    for (k, p) in segments.iter().enumerate() {
        if p.p_type(endian) != elf::PT_LOAD {
            continue;
        }
        let (offset, size): (u64, u64) = (p.p_offset(endian).into(), p.p_filesz(endian).into());
        // a segment with nothing in the file (zero-filled memory only) maps no file byte
        if size > 0
            && offset
                .checked_add(size)
                .is_none_or(|end| end > data.len() as u64)
        {
            return Err(BinaryError::Malformed {
                format: "ELF",
                reason: format!(
                    "loadable segment {k} (bytes {offset}..{}) reaches past the file's end \
                     ({} bytes): a truncated library",
                    offset.saturating_add(size),
                    data.len()
                ),
            });
        }
    }
    // a shared library's dynamic segment names its symbol and string tables, which the loader
    // follows (a zeroed one, as in a damaged file of the right size, crashes it)
    let mut dynamic_found = false;
    for p in segments.iter() {
        if let Some(entries) = p.dynamic(endian, data).map_err(&m)? {
            dynamic_found = true;
            let has = |tag: u32| {
                entries
                    .iter()
                    .take_while(|e| e.tag32(endian) != Some(elf::DT_NULL))
                    .any(|e| e.tag32(endian) == Some(tag))
            };
            if !has(elf::DT_SYMTAB) || !has(elf::DT_STRTAB) {
                return Err(BinaryError::Malformed {
                    format: "ELF",
                    reason: "its dynamic segment names no symbol table (DT_SYMTAB, DT_STRTAB)"
                        .into(),
                });
            }
        }
    }
    if !dynamic_found {
        return Err(BinaryError::Malformed {
            format: "ELF",
            reason: "no dynamic segment: not a shared library".into(),
        });
    }
    let sections = file.elf_section_table();
    let exports = file
        .exports()
        .map_err(&m)?
        .iter()
        .map(|e| String::from_utf8_lossy(e.name()).into_owned())
        .collect();

    let mut needed_libraries = Vec::new();
    let mut search_paths = Vec::new();
    if let Some((entries, link)) = sections.dynamic(endian, data).map_err(&m)? {
        let strings = sections.strings(endian, data, link).map_err(&m)?;
        for entry in entries {
            let Some(tag) = entry.tag32(endian) else {
                continue;
            };
            let kind = match tag {
                elf::DT_NEEDED => None,
                elf::DT_RPATH => Some("RPATH"),
                elf::DT_RUNPATH => Some("RUNPATH"),
                _ => continue,
            };
            let value =
                String::from_utf8_lossy(entry.string(endian, strings).map_err(&m)?).into_owned();
            match kind {
                None => needed_libraries.push(value),
                Some(k) => search_paths.push((k, value)),
            }
        }
    }

    let mut version_needs = Vec::new();
    if let Some((mut needs, link)) = sections.gnu_verneed(endian, data).map_err(&m)? {
        let strings = sections.strings(endian, data, link).map_err(&m)?;
        while let Some((need, mut aux)) = needs.next().map_err(&m)? {
            let library =
                String::from_utf8_lossy(need.file(endian, strings).map_err(&m)?).into_owned();
            while let Some(a) = aux.next().map_err(&m)? {
                let version =
                    String::from_utf8_lossy(a.name(endian, strings).map_err(&m)?).into_owned();
                version_needs.push(VersionNeed {
                    library: library.clone(),
                    version,
                });
            }
        }
    }
    version_needs.sort();

    Ok(Image {
        architecture: architecture(file.architecture()),
        exports,
        needed_libraries,
        search_paths,
        version_needs,
    })
}
