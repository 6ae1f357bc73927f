//! The byte form of a serialised FMU state (fmi2SerializeFMUstate): strict bincode sealed by a
//! CRC-32, so that a damaged or forged state is refused before any of it is used.

/// Appends the CRC-32 of a serialised state's bytes (little-endian), which [`unseal`] checks.
pub(crate) fn seal(bytes: &mut Vec<u8>) {
    let sum = crc32fast::hash(bytes);
    bytes.extend_from_slice(&sum.to_le_bytes());
}

/// The bytes before the checksum [`seal`] appended, if it matches.
pub(crate) fn unseal(bytes: &[u8]) -> Option<&[u8]> {
    let (body, sum) = bytes.split_at_checked(bytes.len().checked_sub(4)?)?;
    (crc32fast::hash(body).to_le_bytes() == sum).then_some(body)
}

/// Decode bincode bytes (the legacy fixed-integer format `bincode::serialize` writes) strictly:
/// every byte must belong to the value (no trailing bytes), and no length prefix may make the
/// decoder allocate more than the input's size.
pub(crate) fn strict_bincode<T: serde::de::DeserializeOwned>(
    bytes: &[u8],
) -> Result<T, bincode::Error> {
    use bincode::Options;
    bincode::DefaultOptions::new()
        .with_fixint_encoding()
        .with_limit(bytes.len() as u64)
        .reject_trailing_bytes()
        .deserialize(bytes)
}
