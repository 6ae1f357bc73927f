//! The checks on binaries whose contents are known: synthetic images for each rule, and the
//! test executable itself as a real ELF file.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::collections::BTreeSet;

use fmu_binary::{
    check_binary, fmi2_cosimulation_api, inspect, Architecture, BinaryFormat, BinaryInfo, Image,
    LinuxPolicy, Platform, Policy, Problem, SymbolVersion, VersionNeed,
};

fn need(library: &str, version: &str) -> VersionNeed {
    VersionNeed {
        library: library.into(),
        version: version.into(),
    }
}

/// A Linux x86-64 binary exporting the whole co-simulation API, needing `versions` of libc.so.6.
fn linux_binary(versions: &[&str]) -> BinaryInfo {
    BinaryInfo {
        format: BinaryFormat::Elf,
        universal: false,
        images: vec![Image {
            architecture: Architecture::X86_64,
            exports: fmi2_cosimulation_api()
                .into_iter()
                .map(String::from)
                .collect(),
            needed_libraries: vec!["libc.so.6".into(), "libm.so.6".into()],
            search_paths: Vec::new(),
            version_needs: versions.iter().map(|v| need("libc.so.6", v)).collect(),
        }],
    }
}

fn problems(info: &BinaryInfo, platform: Platform, policy: &Policy) -> Vec<Problem> {
    check_binary(info, platform, &fmi2_cosimulation_api(), policy)
}

#[test]
fn a_binary_within_the_baseline_passes_and_reports_its_newest_glibc() {
    let info = linux_binary(&["GLIBC_2.2.5", "GLIBC_2.14", "GLIBC_2.3.4"]);
    assert_eq!(info.newest_glibc(), Some(SymbolVersion::new(2, 14)));
    assert_eq!(problems(&info, Platform::Linux64, &Policy::baseline()), []);
}

#[test]
fn a_glibc_version_above_the_baseline_fails_naming_every_newer_version() {
    let info = linux_binary(&["GLIBC_2.2.5", "GLIBC_2.35", "GLIBC_2.18", "GLIBC_2.17"]);
    let found = problems(&info, Platform::Linux64, &Policy::baseline());
    assert_eq!(
        found,
        [Problem::GlibcTooNew {
            needed: SymbolVersion::new(2, 35),
            baseline: SymbolVersion::new(2, 17),
            versions: vec!["GLIBC_2.18".into(), "GLIBC_2.35".into()],
        }]
    );
    assert_eq!(
        found[0].to_string(),
        "needs glibc 2.35, newer than the baseline 2.17 (GLIBC_2.18, GLIBC_2.35)"
    );
    // The baseline is a setting: at 2.35 the same binary passes, and the native policy
    // does not look at glibc at all.
    let at_235 = Policy {
        linux: Some(LinuxPolicy::with_glibc(SymbolVersion::new(2, 35))),
    };
    assert_eq!(problems(&info, Platform::Linux64, &at_235), []);
    assert_eq!(problems(&info, Platform::Linux64, &Policy::native()), []);
}

#[test]
fn private_and_foreign_symbol_versions_libraries_and_search_paths_fail() {
    let mut info = linux_binary(&["GLIBC_PRIVATE", "GLIBC_2.14"]);
    let image = &mut info.images[0];
    image.version_needs.push(need("libgcc_s.so.1", "GCC_3.0"));
    image.version_needs.push(need("libgcc_s.so.1", "GCC_7.0.0"));
    image
        .version_needs
        .push(need("libstdc++.so.6", "GLIBCXX_3.4.29"));
    image.needed_libraries.push("libstdc++.so.6".into());
    image.needed_libraries.push("libgcc_s.so.1".into());
    image
        .search_paths
        .push(("RUNPATH", "$ORIGIN/../lib".into()));
    let found = problems(&info, Platform::Linux64, &Policy::baseline());
    let text: Vec<String> = found.iter().map(|p| p.to_string()).collect();
    assert_eq!(
        text,
        [
            "needs symbol version GLIBC_PRIVATE of libc.so.6, which is not allowed",
            "needs symbol version GCC_7.0.0 of libgcc_s.so.1, which is not allowed",
            "needs symbol version GLIBCXX_3.4.29 of libstdc++.so.6, which is not allowed",
            "needs libstdc++.so.6, which is not one of glibc's own libraries or libgcc_s",
            "has RUNPATH '$ORIGIN/../lib' (a portable binary has none)",
        ]
    );
}

#[test]
fn format_architecture_and_exports_are_checked_against_the_platform_folder() {
    let info = linux_binary(&["GLIBC_2.14"]);
    assert_eq!(
        problems(&info, Platform::Win64, &Policy::baseline()),
        [Problem::WrongFormat {
            platform: Platform::Win64,
            found: BinaryFormat::Elf
        }]
    );
    assert_eq!(
        problems(&info, Platform::Aarch64Linux, &Policy::baseline())[0].to_string(),
        "is built for x86-64, but aarch64-linux needs aarch64"
    );
    let mut partial = info.clone();
    partial.images[0].exports.remove("fmi2DoStep");
    partial.images[0].exports.remove("fmi2GetStatus");
    assert_eq!(
        problems(&partial, Platform::Linux64, &Policy::baseline())[0].to_string(),
        "does not export 2 of the 34 FMI 2.0 functions: fmi2DoStep, fmi2GetStatus"
    );
}

#[test]
fn a_universal_macos_binary_needs_every_slice_to_fit() {
    let slice = |architecture| Image {
        architecture,
        exports: fmi2_cosimulation_api()
            .into_iter()
            .map(String::from)
            .collect(),
        needed_libraries: vec!["/usr/lib/libSystem.B.dylib".into()],
        search_paths: Vec::new(),
        version_needs: Vec::new(),
    };
    let mut info = BinaryInfo {
        format: BinaryFormat::MachO,
        universal: true,
        images: vec![slice(Architecture::X86_64), slice(Architecture::Aarch64)],
    };
    assert_eq!(problems(&info, Platform::Darwin64, &Policy::baseline()), []);
    assert_eq!(
        problems(&info, Platform::Aarch64Darwin, &Policy::baseline())[0].to_string(),
        "is built for x86-64, but aarch64-darwin needs aarch64"
    );
    info.images[1].exports = BTreeSet::new();
    assert_eq!(
        problems(&info, Platform::Darwin64, &Policy::baseline())[0].to_string(),
        "exports none of the 34 FMI 2.0 functions"
    );
}

#[test]
fn the_test_executable_reads_as_an_elf_file_of_this_machine() {
    let bytes = std::fs::read(std::env::current_exe().unwrap()).unwrap();
    let info = inspect(&bytes).unwrap();
    assert_eq!(info.format, BinaryFormat::Elf);
    let host = Platform::host().unwrap();
    assert!(host.architectures().contains(&info.images[0].architecture));
    assert!(info.images[0]
        .needed_libraries
        .iter()
        .any(|l| l == "libc.so.6"));
    // Built by the machine's own toolchain, it needs some glibc version of it.
    assert!(info
        .newest_glibc()
        .is_some_and(|v| v >= SymbolVersion::new(2, 2)));
}

#[test]
fn what_is_no_shared_library_is_an_error() {
    assert!(inspect(b"not a binary at all").is_err());
    assert!(inspect(b"\x7fELF\x02\x01\x01").is_err());
}

/// The test executable (a position-independent ELF file, with a dynamic segment as a shared
/// library has) without its section table, as a stripped library may come: what is left for a
/// check is what the loader reads, the program headers.
#[cfg(all(
    target_os = "linux",
    target_pointer_width = "64",
    target_endian = "little"
))]
fn test_executable_without_sections() -> Vec<u8> {
    let mut bytes = std::fs::read(std::env::current_exe().unwrap()).unwrap();
    assert_eq!(&bytes[..5], b"\x7fELF\x02", "a 64-bit ELF file");
    // e_shoff, e_shnum, e_shstrndx
    bytes[0x28..0x30].fill(0);
    bytes[0x3c..0x40].fill(0);
    inspect(&bytes).unwrap();
    bytes
}

/// (type, offset, size in the file) of each program header of a little-endian ELF64 file.
#[cfg(all(
    target_os = "linux",
    target_pointer_width = "64",
    target_endian = "little"
))]
fn program_headers(bytes: &[u8]) -> Vec<(u32, usize, usize)> {
    let u = |at: usize, n: usize| {
        bytes[at..at + n]
            .iter()
            .rev()
            .fold(0usize, |v, b| (v << 8) | usize::from(*b))
    };
    let (phoff, phentsize, phnum) = (u(0x20, 8), u(0x36, 2), u(0x38, 2));
    (0..phnum)
        .map(|k| {
            let h = phoff + k * phentsize;
            (u(h, 4) as u32, u(h + 8, 8), u(h + 32, 8))
        })
        .collect()
}

// the offsets read are those of a little-endian ELF64 file, as the test executable is here
#[cfg(all(
    target_os = "linux",
    target_pointer_width = "64",
    target_endian = "little"
))]
#[test]
fn a_truncated_library_is_malformed_before_a_loader_maps_past_its_end() {
    let bytes = test_executable_without_sections();
    let (_, offset, size) = program_headers(&bytes)
        .into_iter()
        .filter(|h| h.0 == 1) // PT_LOAD
        .max_by_key(|h| h.1 + h.2)
        .unwrap();
    let cut = &bytes[..offset + size - 1];
    let e = inspect(cut).unwrap_err().to_string();
    assert!(
        e.contains("malformed ELF file") && e.contains("reaches past the file's end"),
        "{e}"
    );
}

// the offsets read are those of a little-endian ELF64 file, as the test executable is here
#[cfg(all(
    target_os = "linux",
    target_pointer_width = "64",
    target_endian = "little"
))]
#[test]
fn a_zeroed_dynamic_segment_is_malformed() {
    let mut bytes = test_executable_without_sections();
    let (_, offset, size) = program_headers(&bytes)
        .into_iter()
        .find(|h| h.0 == 2) // PT_DYNAMIC
        .unwrap();
    bytes[offset..offset + size].fill(0);
    let e = inspect(&bytes).unwrap_err().to_string();
    assert!(e.contains("names no symbol table"), "{e}");
}
