//! The `railfmu` Python package's native module (`railfmu._railfmu`): a thin pyo3 layer over
//! the generic master (`master` crate). The Python side (`python/railfmu/`) builds the user
//! API on it: results as NumPy/pandas, run sets on threads or on a Dask cluster.
//!
//! Only the `py` module needs pyo3 (feature `python`, set by maturin); the helpers below are plain Rust,
//! so `cargo test --workspace` checks them without a Python installation.
//!
//! * [`assess`]: the EN 14363 stability assessment of results, as `master assess` makes it.
//! * [`results`]: results tables with the columns of the master's files (Strings and
//!   Enumeration item names as texts), read back exactly and turned back into a run's output
//!   for the master's writers.
//! * [`runs`]: which runs of a run set are complete in an output folder (resuming a set) and
//!   a job's wire format.

pub mod assess;
pub mod results;
pub mod runs;

#[cfg(feature = "python")]
mod py;

/// An error with the messages of its causes that it does not already contain, joined by
/// `": "` (the master's `thiserror(transparent)` errors repeat their cause's message).
pub fn error_message(e: &dyn std::error::Error) -> String {
    let mut msg = e.to_string();
    let mut source = e.source();
    while let Some(s) = source {
        let m = s.to_string();
        if !msg.contains(&m) {
            msg.push_str(": ");
            msg.push_str(&m);
        }
        source = s.source();
    }
    msg
}

/// Native-endian `f64` bytes (NumPy's `frombuffer(dtype=float64)` reads them back).
pub fn f64_bytes(data: &[f64]) -> Vec<u8> {
    data.iter().flat_map(|x| x.to_ne_bytes()).collect()
}

/// [`f64_bytes`] written straight into a Python `bytes` object (no intermediate copy: the
/// results of a long run are held once in Rust and once in Python, not three times).
#[cfg(feature = "python")]
pub fn f64_pybytes<'py>(
    py: pyo3::Python<'py>,
    data: &[f64],
) -> pyo3::PyResult<pyo3::Bound<'py, pyo3::types::PyBytes>> {
    pyo3::types::PyBytes::new_with(py, data.len() * 8, |buf| {
        for (chunk, x) in buf.chunks_exact_mut(8).zip(data) {
            chunk.copy_from_slice(&x.to_ne_bytes());
        }
        Ok(())
    })
}

/// The inverse of [`f64_bytes`]; `Err` when the length is not a multiple of 8.
pub fn f64_from_bytes(bytes: &[u8]) -> Result<Vec<f64>, String> {
    if !bytes.len().is_multiple_of(8) {
        return Err(format!(
            "{} bytes are not a whole number of 8-byte floats",
            bytes.len()
        ));
    }
    Ok(bytes
        .chunks_exact(8)
        .map(|c| {
            let mut b = [0u8; 8];
            b.copy_from_slice(c);
            f64::from_ne_bytes(b)
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bytes_round_trip_and_reject_partial_floats() {
        let x = [0.0, -0.0, 1.0 / 3.0, f64::INFINITY, 5e-324];
        let back = f64_from_bytes(&f64_bytes(&x)).unwrap();
        assert_eq!(
            back.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
            x.iter().map(|v| v.to_bits()).collect::<Vec<_>>()
        );
        assert!(f64_from_bytes(&[0u8; 12]).unwrap_err().contains("12 bytes"));
    }

    #[test]
    fn error_messages_keep_new_causes_only() {
        #[derive(Debug)]
        struct Outer(std::io::Error);
        impl std::fmt::Display for Outer {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                write!(f, "cannot read 'a.fmu'")
            }
        }
        impl std::error::Error for Outer {
            fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
                Some(&self.0)
            }
        }
        let e = Outer(std::io::Error::other("not a zip archive"));
        assert_eq!(error_message(&e), "cannot read 'a.fmu': not a zip archive");
        let io = std::io::Error::other("disk full");
        assert_eq!(error_message(&io), "disk full");
    }
}
