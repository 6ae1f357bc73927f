//! The platform folders of an FMU's `binaries/` and what each must hold.

use std::fmt;

use crate::inspect::{Architecture, BinaryFormat};

/// A folder `binaries/<platform>/` of an FMI 2.0 FMU.
///
/// FMI 2.0 names `win32`, `win64`, `linux32`, `linux64`, `darwin64` (2.0.4, 2.4); 64-bit ARM has
/// no FMI 2.0 name, so `aarch64-linux` and `aarch64-darwin` use FMI 3.0's platform tuples, as
/// hosts that load FMI 2.0 FMUs on ARM look for them. `darwin64` may hold an x86-64, an arm64 or
/// a universal (both) Mach-O binary: FMI 2.0 hosts on Apple silicon load `darwin64` too.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Platform {
    // In the alphabetical order of the folder names (the order of the entries in an FMU).
    Aarch64Darwin,
    Aarch64Linux,
    Darwin64,
    Linux32,
    Linux64,
    Win32,
    Win64,
}

impl Platform {
    pub const ALL: [Platform; 7] = [
        Platform::Aarch64Darwin,
        Platform::Aarch64Linux,
        Platform::Darwin64,
        Platform::Linux32,
        Platform::Linux64,
        Platform::Win32,
        Platform::Win64,
    ];

    /// The folder name under `binaries/`.
    pub fn folder(self) -> &'static str {
        match self {
            Platform::Win32 => "win32",
            Platform::Win64 => "win64",
            Platform::Linux32 => "linux32",
            Platform::Linux64 => "linux64",
            Platform::Darwin64 => "darwin64",
            Platform::Aarch64Linux => "aarch64-linux",
            Platform::Aarch64Darwin => "aarch64-darwin",
        }
    }

    pub fn from_folder(folder: &str) -> Option<Platform> {
        Platform::ALL.into_iter().find(|p| p.folder() == folder)
    }

    /// File extension of a shared library on this platform, without the dot.
    pub fn extension(self) -> &'static str {
        match self.format() {
            BinaryFormat::Pe => "dll",
            BinaryFormat::Elf => "so",
            BinaryFormat::MachO => "dylib",
        }
    }

    /// `<model_identifier>.<extension>`: the file a host loads from this folder.
    pub fn library_file_name(self, model_identifier: &str) -> String {
        format!("{model_identifier}.{}", self.extension())
    }

    pub fn format(self) -> BinaryFormat {
        match self {
            Platform::Win32 | Platform::Win64 => BinaryFormat::Pe,
            Platform::Linux32 | Platform::Linux64 | Platform::Aarch64Linux => BinaryFormat::Elf,
            Platform::Darwin64 | Platform::Aarch64Darwin => BinaryFormat::MachO,
        }
    }

    /// Architectures a binary in this folder may be built for (a universal Mach-O binary in
    /// `darwin64` may carry both).
    pub fn architectures(self) -> &'static [Architecture] {
        match self {
            Platform::Win32 | Platform::Linux32 => &[Architecture::X86],
            Platform::Win64 | Platform::Linux64 => &[Architecture::X86_64],
            Platform::Darwin64 => &[Architecture::X86_64, Architecture::Aarch64],
            Platform::Aarch64Linux | Platform::Aarch64Darwin => &[Architecture::Aarch64],
        }
    }

    /// The folder for a Rust target triple (`x86_64-unknown-linux-gnu`, `aarch64-apple-darwin`,
    /// `x86_64-pc-windows-msvc`, ...); a glibc suffix (`.2.17`) is ignored.
    pub fn from_target_triple(triple: &str) -> Option<Platform> {
        let mut parts = triple.split('-');
        let arch = parts.next()?;
        let rest: Vec<&str> = parts.collect();
        let has = |s: &str| rest.iter().any(|p| p.starts_with(s));
        let arch = match arch {
            "x86_64" => Architecture::X86_64,
            "i686" | "i586" | "i386" => Architecture::X86,
            "aarch64" | "arm64" => Architecture::Aarch64,
            _ => return None,
        };
        if has("windows") {
            match arch {
                Architecture::X86_64 => Some(Platform::Win64),
                Architecture::X86 => Some(Platform::Win32),
                _ => None,
            }
        } else if has("linux") {
            match arch {
                Architecture::X86_64 => Some(Platform::Linux64),
                Architecture::X86 => Some(Platform::Linux32),
                _ => Some(Platform::Aarch64Linux),
            }
        } else if has("darwin") {
            match arch {
                Architecture::X86 => None,
                // darwin64, not aarch64-darwin: FMI 2.0 hosts on Apple silicon look there.
                _ => Some(Platform::Darwin64),
            }
        } else {
            None
        }
    }

    /// The platform this program was compiled for.
    pub fn host() -> Option<Platform> {
        let os = std::env::consts::OS;
        let arch = std::env::consts::ARCH;
        let os = match os {
            "macos" => "darwin",
            other => other,
        };
        Platform::from_target_triple(&format!("{arch}-unknown-{os}"))
    }
}

impl fmt::Display for Platform {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.folder())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn folders_round_trip_and_triples_map() {
        for p in Platform::ALL {
            assert_eq!(Platform::from_folder(p.folder()), Some(p));
        }
        let mut sorted = Platform::ALL;
        sorted.sort_by_key(|p| p.folder());
        assert_eq!(sorted, Platform::ALL, "Ord follows the folder names");
        assert_eq!(Platform::from_folder("linux"), None);
        let cases = [
            ("x86_64-unknown-linux-gnu.2.17", Some(Platform::Linux64)),
            ("x86_64-unknown-linux-gnu", Some(Platform::Linux64)),
            ("aarch64-unknown-linux-gnu", Some(Platform::Aarch64Linux)),
            ("x86_64-pc-windows-msvc", Some(Platform::Win64)),
            ("i686-pc-windows-gnu", Some(Platform::Win32)),
            ("aarch64-apple-darwin", Some(Platform::Darwin64)),
            ("x86_64-apple-darwin", Some(Platform::Darwin64)),
            ("wasm32-unknown-unknown", None),
        ];
        for (triple, platform) in cases {
            assert_eq!(Platform::from_target_triple(triple), platform, "{triple}");
        }
        assert_eq!(
            Platform::Win64.library_file_name("Bogie2Dof"),
            "Bogie2Dof.dll"
        );
        assert!(Platform::host().is_some());
    }
}
