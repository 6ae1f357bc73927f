//! How messages show values a user gave: a long text by its beginning and its length (a 10 MB
//! String start value is not echoed whole), a number in a short form (1e308, not 309 digits).

use std::fmt;

/// A text longer than this many characters is shown by its first ones.
pub const SHOWN_CHARS: usize = 200;

/// A text as a message shows it ([`text`]).
#[derive(Clone, Copy)]
pub struct Text<'a>(&'a str);

/// `s` for a message: whole up to [`SHOWN_CHARS`] characters, else its first
/// [`SHOWN_CHARS`] characters followed by `... (N bytes)`. `{}` shows it plain, `{:?}` quoted
/// and escaped as Rust's `{:?}` of a `str`.
pub fn text(s: &str) -> Text<'_> {
    Text(s)
}

impl Text<'_> {
    /// The part shown and whether it is cut.
    fn head(&self) -> (&str, bool) {
        match self.0.char_indices().nth(SHOWN_CHARS) {
            Some((cut, _)) => (&self.0[..cut], true),
            None => (self.0, false),
        }
    }
}

impl fmt::Display for Text<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (head, cut) = self.head();
        f.write_str(head)?;
        if cut {
            write!(f, "... ({} bytes)", self.0.len())?;
        }
        Ok(())
    }
}

impl fmt::Debug for Text<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (head, cut) = self.head();
        write!(f, "{head:?}")?;
        if cut {
            write!(f, "... ({} bytes)", self.0.len())?;
        }
        Ok(())
    }
}

/// A number as a message shows it ([`num`]).
#[derive(Clone, Copy)]
pub struct Num(f64);

/// `x` for a message: as Rust's `{}` writes it from 1e-4 to 1e16 in magnitude (0.002, 380,
/// -1), else in exponential form (1e308, 2.5e-7); `NaN`, `inf` and `-inf` as they are.
pub fn num(x: f64) -> Num {
    Num(x)
}

impl fmt::Display for Num {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let x = self.0;
        let a = x.abs();
        if x == 0.0 || !x.is_finite() || (1e-4..1e16).contains(&a) {
            write!(f, "{x}")
        } else {
            write!(f, "{x:e}")
        }
    }
}

/// A Real value of a results file: [`num`]'s form, with `.0` on a whole number (`300.0`, not
/// `300`), so that a reader that infers a column's type from its text (pandas) reads a Real
/// column as floating point whatever its values, as from the Parquet file.
pub fn real(x: f64) -> Real {
    Real(x)
}

/// See [`real`].
pub struct Real(f64);

impl fmt::Display for Real {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let x = self.0;
        let plain = x == 0.0 || (1e-4..1e16).contains(&x.abs());
        if plain && x.fract() == 0.0 {
            write!(f, "{x}.0")
        } else {
            Num(x).fmt(f)
        }
    }
}

impl fmt::Debug for Num {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Display::fmt(self, f)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A whole Real keeps a decimal point (a reader inferring types takes `300` for an
    /// integer); others are written as [`num`] writes them.
    #[test]
    fn a_whole_real_keeps_its_decimal_point() {
        let shown = |x: f64| real(x).to_string();
        assert_eq!(shown(300.0), "300.0");
        assert_eq!(shown(0.0), "0.0");
        assert_eq!(shown(-0.0), "-0.0");
        assert_eq!(shown(-2.0), "-2.0");
        assert_eq!(shown(0.001), "0.001");
        assert_eq!(shown(1e20), "1e20");
        assert_eq!(shown(2.5e-7), "2.5e-7");
        assert_eq!(shown(f64::NAN), "NaN");
        for x in [300.0, 0.0, -2.0, 1e15, 1e20, 0.1] {
            assert_eq!(shown(x).parse::<f64>().unwrap(), x);
        }
    }

    #[test]
    fn a_long_text_is_shown_by_its_beginning_and_its_length() {
        assert_eq!(text("short").to_string(), "short");
        assert_eq!(format!("{:?}", text("a \"b\"")), r#""a \"b\"""#);
        let exact = "x".repeat(SHOWN_CHARS);
        assert_eq!(text(&exact).to_string(), exact);
        let long = "x".repeat(10 << 20);
        let shown = text(&long).to_string();
        assert_eq!(
            shown,
            format!("{}... (10485760 bytes)", "x".repeat(SHOWN_CHARS))
        );
        assert_eq!(
            format!("{:?}", text(&long)),
            format!("\"{}\"... (10485760 bytes)", "x".repeat(SHOWN_CHARS))
        );
        // cut at a character, not inside one
        let wide = "é".repeat(SHOWN_CHARS + 1);
        assert_eq!(
            text(&wide).to_string(),
            format!("{}... ({} bytes)", "é".repeat(SHOWN_CHARS), wide.len())
        );
    }

    #[test]
    fn a_number_is_shown_short() {
        for (x, shown) in [
            (1e308, "1e308"),
            (-1e308, "-1e308"),
            (f64::MAX, "1.7976931348623157e308"),
            (1e-308, "1e-308"),
            (2.5e-7, "2.5e-7"),
            (1e16, "1e16"),
            (0.002, "0.002"),
            (1e-4, "0.0001"),
            (380.0, "380"),
            (-1.0, "-1"),
            (0.0, "0"),
            (123456789012345.0, "123456789012345"),
            (f64::NAN, "NaN"),
            (f64::INFINITY, "inf"),
            (f64::NEG_INFINITY, "-inf"),
        ] {
            assert_eq!(num(x).to_string(), shown, "{x:?}");
        }
    }
}
