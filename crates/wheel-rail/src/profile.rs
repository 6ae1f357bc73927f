//! Wheel and rail profiles: reading and basic queries.
//!
//! Accepted text format (one point per line):
//! - two numeric fields `lateral vertical` in **millimetres**, separated by whitespace (spaces/tabs),
//!   a comma or a semicolon (`-32.5 -14`, `-32.5,-14`, `-32.5; -14`);
//! - `#` starts a comment (whole line or end of line); blank lines are ignored; CRLF is fine and
//!   the last line may lack a line break;
//! - the first non-comment line may be a header if *none* of its fields is a number
//!   (`y_mm,z_mm`); any later non-numeric field is an error;
//! - the lateral coordinate must be strictly monotonic; increasing is the native order, a file that
//!   is strictly decreasing throughout is reversed on reading;
//! - at least [`MIN_POINTS`] points.
//!
//! Errors name the file (or the source name given to [`Profile::parse_str`]) and the 1-based line.
//!
//! Coordinates are converted to metres on reading. The meaning of the axes is the one of the
//! EN 15302 benchmark files, see the crate documentation: lateral positive towards the field side
//! (away from the track centre, so the wheel flange lies at negative lateral coordinates), vertical
//! positive upwards.

use std::path::Path;

use thiserror::Error;

/// Minimum number of points of a profile.
pub const MIN_POINTS: usize = 3;
/// Maximum number of points of a profile: a measured profile (MiniProf and the like) has a
/// few thousand; 100 000 is a point every micrometre over 100 mm. The contact search takes
/// about 26 us per point, so 1.5 million points (39 MB, within the file size limit) ran for
/// minutes.
pub const MAX_POINTS: usize = 100_000;

/// Lateral extent a wheel or rail profile in millimetres can have \[mm\]: a wheel spans about
/// 140 mm, a rail head about 75 (a synthetic crown a few); outside, the file is in another
/// unit (metres: 0.14, micrometres: 140 000).
pub const PLAUSIBLE_SPAN_MM: (f64, f64) = (1.0, 1000.0);

/// At most 80 characters of a field or line echoed in a message (a 10 MB line is not).
fn clip(text: &str) -> String {
    const MAX: usize = 80;
    match text.char_indices().nth(MAX) {
        Some((cut, _)) => format!("{}... ({} bytes)", &text[..cut], text.len()),
        None => text.to_string(),
    }
}

/// Errors of profile reading / construction.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum ProfileError {
    /// The file could not be read.
    #[error("{source_name}: cannot read file: {message}")]
    Io {
        /// File name.
        source_name: String,
        /// OS error message.
        message: String,
    },
    /// A field is not a finite number, or the line does not have exactly two fields.
    #[error("{source_name}:{line}: {message}")]
    Malformed {
        /// File name.
        source_name: String,
        /// 1-based line number.
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// The lateral coordinate is not strictly monotonic.
    #[error(
        "{source_name}:{line}: lateral coordinate {value_mm} mm is not strictly {direction} \
         (previous point {previous_mm} mm); profiles must be single-valued in the lateral coordinate"
    )]
    NonMonotonic {
        /// File name.
        source_name: String,
        /// 1-based line number of the offending point.
        line: usize,
        /// Offending lateral coordinate \[mm\].
        value_mm: f64,
        /// Previous lateral coordinate \[mm\].
        previous_mm: f64,
        /// "increasing" or "decreasing".
        direction: &'static str,
    },
    /// More points than [`MAX_POINTS`].
    #[error(
        "{source_name}:{line}: more than {max} points; a measured profile has a few thousand \
         (resample it)"
    )]
    TooManyPoints {
        /// File name.
        source_name: String,
        /// Line of the first point beyond the limit.
        line: usize,
        /// The limit.
        max: usize,
    },
    /// The lateral extent is no wheel's or rail's in millimetres ([`PLAUSIBLE_SPAN_MM`]).
    #[error(
        "{source_name}: the profile spans {} mm laterally; coordinates are read in \
         millimetres (a wheel spans about 140 mm, a rail head about 75 mm): is the file in \
         {unit}?",
        crate::contact::short(*.span_mm)
    )]
    ImplausibleSpan {
        /// File name.
        source_name: String,
        /// Lateral extent as read \[mm\].
        span_mm: f64,
        /// "metres" or "micrometres".
        unit: &'static str,
    },
    /// The vertical extent is no wheel's or rail's in millimetres (more than
    /// [`PLAUSIBLE_SPAN_MM`]'s upper end).
    #[error(
        "{source_name}: the profile spans {} mm vertically; coordinates are read in \
         millimetres (a wheel's flange is about 30 mm high, a whole rail about 170 mm): is the \
         file in micrometres, or does it hold a value that is no coordinate?",
        crate::contact::short(*.span_mm)
    )]
    ImplausibleHeight {
        /// File name.
        source_name: String,
        /// Vertical extent as read \[mm\].
        span_mm: f64,
    },
    /// Not enough points.
    #[error("{source_name}: only {count} point(s) (line {last_line} is the last), at least {min} needed")]
    TooFewPoints {
        /// File name.
        source_name: String,
        /// Number of points read.
        count: usize,
        /// Last line read.
        last_line: usize,
        /// Required minimum.
        min: usize,
    },
}

/// A wheel or rail profile: a polyline with strictly increasing lateral coordinate, in metres.
#[derive(Debug, Clone, PartialEq)]
pub struct Profile {
    /// Where the profile came from (file name or a label), used in error messages.
    pub name: String,
    /// Lateral coordinate \[m\], strictly increasing, positive towards the field side.
    pub lateral_m: Vec<f64>,
    /// Vertical coordinate \[m\], positive upwards.
    pub vertical_m: Vec<f64>,
}

impl Profile {
    /// Reads a profile file (millimetres, format in the module docs).
    pub fn from_file(path: impl AsRef<Path>) -> Result<Self, ProfileError> {
        let path = path.as_ref();
        let name = path.display().to_string();
        let text = crate::text_file::read_text_file(path, crate::text_file::MAX_TEXT_FILE_BYTES)
            .map_err(|message| ProfileError::Io {
                source_name: name.clone(),
                message,
            })?;
        Self::parse_str(&text, &name)
    }

    /// Parses profile text (millimetres); `source_name` is used in error messages.
    pub fn parse_str(text: &str, source_name: &str) -> Result<Self, ProfileError> {
        let malformed = |line: usize, message: String| ProfileError::Malformed {
            source_name: source_name.to_string(),
            line,
            message,
        };
        // (line number, lateral mm, vertical mm)
        let mut pts: Vec<(usize, f64, f64)> = Vec::new();
        let mut seen_content = false;
        let mut last_line = 0;
        // a byte-order mark, as some Windows editors write, is not part of the first field
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        for (idx, raw) in text.lines().enumerate() {
            let line_no = idx + 1;
            last_line = line_no;
            let content = raw.split('#').next().unwrap_or("").trim();
            if content.is_empty() {
                continue;
            }
            // three fields at most: a third says the line is wrong (a 64 MB line of numbers
            // took 1 GB split and parsed whole)
            let fields: Vec<&str> = content
                .split(|c: char| c.is_whitespace() || c == ',' || c == ';')
                .filter(|f| !f.is_empty())
                .take(3)
                .collect();
            let parsed: Vec<Result<f64, _>> = fields.iter().map(|f| f.parse::<f64>()).collect();
            let first_content = !seen_content;
            seen_content = true;
            if first_content && parsed.iter().all(|p| p.is_err()) {
                continue; // header line
            }
            if fields.len() != 2 {
                return Err(malformed(
                    line_no,
                    format!(
                        "expected 2 fields (lateral vertical, mm), found {}: {:?}",
                        if fields.len() > 2 {
                            "more".to_string()
                        } else {
                            fields.len().to_string()
                        },
                        clip(content)
                    ),
                ));
            }
            let mut vals = [0.0; 2];
            for (k, (f, p)) in fields.iter().zip(parsed.iter()).enumerate() {
                match p {
                    Ok(v) if v.is_finite() => vals[k] = *v,
                    _ => {
                        let which = if k == 0 { "lateral" } else { "vertical" };
                        return Err(malformed(
                            line_no,
                            format!("{which} coordinate {:?} is not a finite number", clip(f)),
                        ));
                    }
                }
            }
            if pts.len() == MAX_POINTS {
                return Err(ProfileError::TooManyPoints {
                    source_name: source_name.to_string(),
                    line: line_no,
                    max: MAX_POINTS,
                });
            }
            pts.push((line_no, vals[0], vals[1]));
        }
        if pts.len() < MIN_POINTS {
            return Err(ProfileError::TooFewPoints {
                source_name: source_name.to_string(),
                count: pts.len(),
                last_line,
                min: MIN_POINTS,
            });
        }
        let increasing = pts[1].1 > pts[0].1;
        for w in pts.windows(2) {
            let ok = if increasing {
                w[1].1 > w[0].1
            } else {
                w[1].1 < w[0].1
            };
            if !ok {
                return Err(ProfileError::NonMonotonic {
                    source_name: source_name.to_string(),
                    line: w[1].0,
                    value_mm: w[1].1,
                    previous_mm: w[0].1,
                    direction: if increasing {
                        "increasing"
                    } else {
                        "decreasing"
                    },
                });
            }
        }
        if !increasing {
            pts.reverse();
        }
        let span_mm = pts[pts.len() - 1].1 - pts[0].1;
        if !(PLAUSIBLE_SPAN_MM.0..=PLAUSIBLE_SPAN_MM.1).contains(&span_mm) {
            return Err(ProfileError::ImplausibleSpan {
                source_name: source_name.to_string(),
                span_mm,
                unit: if span_mm < PLAUSIBLE_SPAN_MM.0 {
                    "metres"
                } else {
                    "micrometres"
                },
            });
        }
        let (low, high) = pts
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(p.2), hi.max(p.2))
            });
        if high - low > PLAUSIBLE_SPAN_MM.1 {
            return Err(ProfileError::ImplausibleHeight {
                source_name: source_name.to_string(),
                span_mm: high - low,
            });
        }
        Ok(Self {
            name: source_name.to_string(),
            lateral_m: pts.iter().map(|p| p.1 * 1e-3).collect(),
            vertical_m: pts.iter().map(|p| p.2 * 1e-3).collect(),
        })
    }

    /// Builds a profile from points in metres (e.g. synthetic profiles). Same checks as the reader;
    /// the "line" in errors is the 1-based point index.
    pub fn from_points(name: &str, points_m: &[(f64, f64)]) -> Result<Self, ProfileError> {
        let text: String = points_m
            .iter()
            .map(|(y, z)| format!("{} {}\n", y * 1e3, z * 1e3))
            .collect();
        Self::parse_str(&text, name)
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.lateral_m.len()
    }

    /// True if the profile has no points (never the case for a constructed profile).
    pub fn is_empty(&self) -> bool {
        self.lateral_m.is_empty()
    }

    /// Vertical coordinate at lateral `s` \[m\] by linear interpolation, `None` outside the profile.
    pub fn vertical_at(&self, s: f64) -> Option<f64> {
        let xs = &self.lateral_m;
        let n = xs.len();
        if n < 2 || !(s >= xs[0] && s <= xs[n - 1]) {
            return None;
        }
        let i = xs.partition_point(|&x| x <= s).clamp(1, n - 1);
        let t = (s - xs[i - 1]) / (xs[i] - xs[i - 1]);
        Some(self.vertical_m[i - 1] + t * (self.vertical_m[i] - self.vertical_m[i - 1]))
    }

    /// Slope dz/ds at `s` by a central difference over +-`half_window_m` (clamped to the profile).
    pub fn slope_at(&self, s: f64, half_window_m: f64) -> Option<f64> {
        let n = self.len();
        if n < 2 {
            return None;
        }
        let lo = (s - half_window_m).max(self.lateral_m[0]);
        let hi = (s + half_window_m).min(self.lateral_m[n - 1]);
        if hi <= lo {
            return None;
        }
        Some((self.vertical_at(hi)? - self.vertical_at(lo)?) / (hi - lo))
    }

    /// Lateral position and value of the steepest rising segment (max dz/ds). On a flanged wheel
    /// profile this is the steepest point of the active flange face.
    pub fn max_slope(&self) -> (f64, f64) {
        self.max_slope_within(f64::NEG_INFINITY, f64::INFINITY)
    }

    /// [`Self::max_slope`] over the segments whose middle lies in `lo..hi` \[m\] (the flange
    /// side of a wheel: negative lateral values, so that its outer rim face or chamfer, on the
    /// field side, is not taken for its flange); `(lo, -inf)` when no segment lies there.
    pub fn max_slope_within(&self, lo: f64, hi: f64) -> (f64, f64) {
        self.steepest_within(lo, hi, 1.0)
    }

    /// Lateral position and value of the steepest falling segment (max -dz/ds) whose middle
    /// lies in `lo..hi` \[m\] (a mirrored wheel's flange); `(lo, -inf)` when none lies there.
    pub fn steepest_fall_within(&self, lo: f64, hi: f64) -> (f64, f64) {
        self.steepest_within(lo, hi, -1.0)
    }

    /// The segment in `lo..hi` with the largest `sign * dz/ds`, and that value.
    fn steepest_within(&self, lo: f64, hi: f64, sign: f64) -> (f64, f64) {
        let mut best = (lo, f64::NEG_INFINITY);
        for i in 1..self.len() {
            let mid = 0.5 * (self.lateral_m[i] + self.lateral_m[i - 1]);
            if !(lo..hi).contains(&mid) {
                continue;
            }
            let ds = self.lateral_m[i] - self.lateral_m[i - 1];
            let m = sign * (self.vertical_m[i] - self.vertical_m[i - 1]) / ds;
            if m > best.1 {
                best = (mid, m);
            }
        }
        best
    }

    /// The profile rotated by `angle_rad` about its origin (counter-clockwise in the
    /// (lateral towards field side, vertical up) plane, i.e. positive tilts the top towards the
    /// track centre). Fails if the result is no longer single-valued in the lateral coordinate.
    pub fn rotated(&self, angle_rad: f64) -> Result<Self, ProfileError> {
        let (s, c) = angle_rad.sin_cos();
        let pts: Vec<(f64, f64)> = self
            .lateral_m
            .iter()
            .zip(&self.vertical_m)
            .map(|(&y, &z)| (y * c - z * s, y * s + z * c))
            .collect();
        Self::from_points(&format!("{} rotated by {angle_rad} rad", self.name), &pts)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_byte_order_mark_is_skipped_and_a_huge_profile_refused() {
        let p = Profile::parse_str("\u{feff}-70 0\n0 1\n70 0\n", "bom.dat").unwrap();
        assert_eq!(p.len(), 3);
        let many: String = (0..=MAX_POINTS)
            .map(|i| format!("{} 0\n", i as f64 * 1e-3))
            .collect();
        let e = Profile::parse_str(&many, "many.dat").unwrap_err();
        assert!(
            matches!(e, ProfileError::TooManyPoints { line, .. } if line == MAX_POINTS + 1),
            "{e}"
        );
    }

    #[test]
    fn parses_whitespace_comma_comments_header() {
        let txt = "# comment\ny_mm, z_mm\n-10.0 0.5 # tail\n\n0,0\r\n10;\t-0.5";
        let p = Profile::parse_str(txt, "t").unwrap();
        assert_eq!(p.len(), 3);
        assert!((p.lateral_m[0] + 10e-3).abs() < 1e-15);
        assert!((p.vertical_m[2] + 0.5e-3).abs() < 1e-15);
    }

    #[test]
    fn decreasing_file_is_reversed() {
        let p = Profile::parse_str("20 0\n10 1\n0 2\n", "t").unwrap();
        assert!(p.lateral_m[0] < p.lateral_m[2]);
        assert!((p.vertical_m[0] - 2e-3).abs() < 1e-15);
    }

    #[test]
    fn interpolation_and_slope() {
        let p = Profile::from_points("lin", &[(-0.01, -0.001), (0.0, 0.0), (0.01, 0.001)]).unwrap();
        assert!((p.vertical_at(0.005).unwrap() - 0.0005).abs() < 1e-12);
        assert!(p.vertical_at(0.02).is_none());
        assert!((p.slope_at(0.0, 0.001).unwrap() - 0.1).abs() < 1e-12);
    }
}
