//! Dotted version numbers as they appear in ELF symbol versions (`GLIBC_2.2.5`, `GCC_4.2.0`).

use std::cmp::Ordering;
use std::fmt;
use std::str::FromStr;

/// A version of up to three numbers; `2.17` and `2.17.0` compare equal, and it prints as given.
#[derive(Debug, Clone, Copy, Eq)]
pub struct SymbolVersion {
    numbers: [u32; 3],
    shown: u8,
}

impl SymbolVersion {
    pub const fn new(major: u32, minor: u32) -> Self {
        Self {
            numbers: [major, minor, 0],
            shown: 2,
        }
    }

    /// The number in a symbol version name with this prefix: `GLIBC_2.14` with `GLIBC_` -> 2.14.
    /// `None` for other names (`GLIBC_PRIVATE`, another prefix).
    pub fn from_symbol_version(name: &str, prefix: &str) -> Option<Self> {
        name.strip_prefix(prefix)?.parse().ok()
    }
}

impl PartialEq for SymbolVersion {
    fn eq(&self, other: &Self) -> bool {
        self.numbers == other.numbers
    }
}

impl Ord for SymbolVersion {
    fn cmp(&self, other: &Self) -> Ordering {
        self.numbers.cmp(&other.numbers)
    }
}

impl PartialOrd for SymbolVersion {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl fmt::Display for SymbolVersion {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let shown = usize::from(self.shown.clamp(1, 3));
        for (i, n) in self.numbers.iter().take(shown).enumerate() {
            if i > 0 {
                f.write_str(".")?;
            }
            write!(f, "{n}")?;
        }
        Ok(())
    }
}

#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("'{0}' is not a version of one to three numbers (e.g. 2.17)")]
pub struct ParseVersionError(pub String);

impl FromStr for SymbolVersion {
    type Err = ParseVersionError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let err = || ParseVersionError(s.to_string());
        let mut numbers = [0u32; 3];
        let mut shown = 0u8;
        for part in s.split('.') {
            let slot = numbers.get_mut(usize::from(shown)).ok_or_else(err)?;
            if part.is_empty() || !part.bytes().all(|b| b.is_ascii_digit()) {
                return Err(err());
            }
            *slot = part.parse().map_err(|_| err())?;
            shown += 1;
        }
        Ok(Self { numbers, shown })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_orders_and_prints_as_given() {
        let v: SymbolVersion = "2.2.5".parse().unwrap();
        assert_eq!(v.to_string(), "2.2.5");
        assert!(v < SymbolVersion::new(2, 17));
        assert!(SymbolVersion::new(2, 17) < SymbolVersion::new(2, 35));
        assert_eq!(
            "2.17.0".parse::<SymbolVersion>().unwrap(),
            SymbolVersion::new(2, 17)
        );
        assert_eq!(
            SymbolVersion::from_symbol_version("GLIBC_2.14", "GLIBC_"),
            Some(SymbolVersion::new(2, 14))
        );
        assert_eq!(
            SymbolVersion::from_symbol_version("GLIBC_PRIVATE", "GLIBC_"),
            None
        );
        assert_eq!(
            SymbolVersion::from_symbol_version("GCC_3.0", "GLIBC_"),
            None
        );
        for bad in ["", "2.", ".17", "2.17.0.1", "two", "2.-1", "2.+1"] {
            assert!(bad.parse::<SymbolVersion>().is_err(), "{bad}");
        }
    }
}
