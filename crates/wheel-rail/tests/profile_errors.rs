//! Profile reading errors name the file and the line.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)] // test code

use std::io::Write;
use wheel_rail::{Profile, ProfileError};

fn write(content: &str) -> tempfile::NamedTempFile {
    let mut f = tempfile::NamedTempFile::new().unwrap();
    f.write_all(content.as_bytes()).unwrap();
    f
}

#[test]
fn malformed_number_names_file_and_line() {
    let f = write("# wheel\n0.0 0.0\n1.0 0.1\n2.0 0,2x\n3.0 0.3\n");
    let e = Profile::from_file(f.path()).unwrap_err();
    let msg = e.to_string();
    let path = f.path().display().to_string();
    assert!(msg.contains(&path) && msg.contains(":4:"), "{msg}");
    assert!(
        matches!(e, ProfileError::Malformed { line: 4, .. }),
        "{e:?}"
    );
    let e = Profile::from_file(write("0 0\n1 nan\n2 2\n3 3\n").path()).unwrap_err();
    assert!(
        matches!(e, ProfileError::Malformed { line: 2, .. }),
        "{e:?}"
    );
    let e = Profile::from_file(write("0 0\n1 1 1\n2 2\n").path()).unwrap_err();
    assert!(
        matches!(e, ProfileError::Malformed { line: 2, .. }),
        "{e:?}"
    );
    // a line of a million numbers is refused on its third field, not split whole
    let long = format!("0 0\n{}\n", vec!["1.5"; 1_000_000].join(" "));
    let e = Profile::from_file(write(&long).path())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains(":2: expected 2 fields (lateral vertical, mm), found more"),
        "{}",
        &e[..e.len().min(300)]
    );
}

#[test]
fn non_monotonic_names_file_and_line() {
    let f = write("-2 0\n-1 0\n\n# gap\n-1.5 0\n0 0\n");
    let e = Profile::from_file(f.path()).unwrap_err();
    let msg = e.to_string();
    assert!(
        msg.contains(&f.path().display().to_string()) && msg.contains(":5:"),
        "{msg}"
    );
    assert!(matches!(e, ProfileError::NonMonotonic { line: 5, .. }));
    // repeated lateral coordinate is not strictly monotonic either
    let e = Profile::from_file(write("0 0\n1 0\n1 1\n").path()).unwrap_err();
    assert!(matches!(e, ProfileError::NonMonotonic { line: 3, .. }));
}

#[test]
fn too_few_points_names_file() {
    let f = write("# only two\n0 0\n1 1\n");
    let e = Profile::from_file(f.path()).unwrap_err();
    let msg = e.to_string();
    assert!(msg.contains(&f.path().display().to_string()), "{msg}");
    assert!(
        matches!(
            e,
            ProfileError::TooFewPoints {
                count: 2,
                last_line: 3,
                ..
            }
        ),
        "{e:?}"
    );
}

#[test]
fn missing_file_is_an_io_error_naming_it() {
    let e = Profile::from_file("/nonexistent/profile.dat").unwrap_err();
    assert!(e.to_string().contains("/nonexistent/profile.dat"));
}

#[test]
fn benchmark_files_read() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/data");
    let w = Profile::from_file(format!("{dir}/RUIC519A.dat")).unwrap();
    let r = Profile::from_file(format!("{dir}/SUIC519A.dat")).unwrap();
    assert_eq!(w.len(), 1001); // 1000 line breaks, last line without one
    assert_eq!(r.len(), 1001);
    assert!((w.lateral_m[0] + 0.070).abs() < 1e-12);
    assert!((r.lateral_m[1000] - 0.039).abs() < 1e-12);
}

/// A profile whose lateral extent is no wheel's or rail's in millimetres is in another unit: the
/// E1 wheel in micrometres gave conicity 0.055 at every amplitude without a word.
#[test]
fn a_profile_in_another_unit_is_refused() {
    let wheel =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/data/RUIC519A.dat")).unwrap();
    let scaled = |factor: f64| -> String {
        wheel
            .lines()
            .filter_map(|l| {
                let mut it = l.split_whitespace().map(|f| f.parse::<f64>());
                match (it.next(), it.next()) {
                    (Some(Ok(y)), Some(Ok(z))) => Some(format!("{} {}\n", y * factor, z * factor)),
                    _ => None,
                }
            })
            .collect()
    };
    assert!(Profile::parse_str(&scaled(1.0), "mm.dat").is_ok());
    for (factor, unit) in [(1e3, "micrometres"), (1e-3, "metres")] {
        let e = Profile::parse_str(&scaled(factor), "w.dat").unwrap_err();
        assert!(matches!(e, ProfileError::ImplausibleSpan { .. }), "{e:?}");
        assert!(
            e.to_string().contains(unit) && e.to_string().contains("w.dat"),
            "{e}"
        );
    }
}

/// A vertical extent no profile in millimetres has (a value of 1e300, or micrometres) is
/// refused as such, not found later as a rolled wheel that is not single-valued.
#[test]
fn an_implausible_height_is_named() {
    let e = Profile::parse_str("0 0\n10 1e300\n20 0\n", "tall.dat").unwrap_err();
    assert!(matches!(e, ProfileError::ImplausibleHeight { .. }), "{e:?}");
    assert!(e.to_string().contains("tall.dat: the profile spans"), "{e}");
    // a flat crown spans nothing vertically: fine
    assert!(Profile::parse_str("0 0\n10 0\n20 0\n", "flat.dat").is_ok());
}

/// A 10 MB field is not echoed whole in the message.
#[test]
fn a_huge_field_is_clipped_in_the_message() {
    let long = "x".repeat(10_000_000);
    let e = Profile::parse_str(&format!("0 0\n1 {long}\n2 2\n"), "long.dat").unwrap_err();
    let msg = e.to_string();
    assert!(
        msg.len() < 300 && msg.contains("10000000 bytes"),
        "{}",
        &msg[..200]
    );
    let e = Profile::parse_str(&format!("0 0\n1 1 {long}\n2 2\n"), "long.dat").unwrap_err();
    assert!(e.to_string().len() < 300);
}
