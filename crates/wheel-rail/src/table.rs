//! Contact-geometry table of one wheelset, as the time-domain models use it: rolling-radius
//! differences and contact angles over the lateral displacement, read from / written to one CSV
//! format, interpolated on the step path.
//!
//! CSV format (header first, SI units, `#` lines and blank lines ignored):
//! `y_m,delta_r_left_m,delta_r_right_m,tan_gamma_left,tan_gamma_right` ([`BOGIE_CSV_HEADER`])
//! * `y_m`: wheelset lateral displacement RELATIVE TO THE TRACK, positive to the right,
//!   strictly increasing;
//! * `delta_r_right_m` grows for y > 0 (r_R = r0 + delta_r_right), `delta_r_left_m` falls;
//! * `tan_gamma_*` are the contact angles' tangents, signed: positive where the contact plane
//!   leans towards the track centre (the tread's cone, large on the flange), negative where
//!   it leans the other way (a hollow-worn tread, the field side of a new profile: the E1
//!   table has 240 such rows of 401), used with their sign below.
//!
//! The format is written by [`write_csv`] alone, with [`CsvNumbers`] choosing how numbers are
//! printed; [`GeometryTable::to_csv`] and [`crate::ContactTable::to_bogie_csv`] (the profile
//! contact search) both go through it.
//!
//! Lateral force of the normal load (5.20), with these signs: the rail pushes each wheel
//! towards the track centre, so F_BL = +P tan(gamma_L), F_BR = -P tan(gamma_R) (y to the
//! right); the net P (tan gamma_L - tan gamma_R) restores. Beyond the table range the last
//! segment is extrapolated linearly (a flange keeps getting steeper rather than letting go).
//!
//! Sharing: a [`GeometryTable`] is immutable after construction and [`GeometryTable::lookup`]
//! takes `&self`, so several wheelsets share one table behind an `Arc` or a borrow. Each
//! wheelset may keep its own [`SegmentHint`] for [`GeometryTable::lookup_with_hint`], which
//! starts from the last segment used and gives bit for bit the result of the plain lookup.

use std::path::Path;

use serde::{Deserialize, Serialize};
use thiserror::Error;

/// Exact header line of the CSV format.
pub const BOGIE_CSV_HEADER: &str =
    "y_m,delta_r_left_m,delta_r_right_m,tan_gamma_left,tan_gamma_right";

/// Source name of tables built by [`GeometryTable::from_columns`] (then `line` = 1-based row).
pub const COLUMNS_SOURCE: &str = "contact table columns";

/// Errors reading or building a contact-geometry table. Each names the source (file path or
/// the name given to [`GeometryTable::parse_csv`]) and, where one exists, the 1-based line.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum TableError {
    /// The file could not be read.
    #[error("{source_name}: cannot read contact table: {message}")]
    Io {
        /// File name.
        source_name: String,
        /// OS error message.
        message: String,
    },
    /// The first non-comment line is not [`BOGIE_CSV_HEADER`].
    #[error("{source_name}:{line}: header must be `{BOGIE_CSV_HEADER}`, got `{found}`")]
    Header {
        /// Source name.
        source_name: String,
        /// 1-based line.
        line: usize,
        /// The line found.
        found: String,
    },
    /// A data line does not have exactly five fields.
    #[error("{source_name}:{line}: expected 5 fields, got {found}")]
    FieldCount {
        /// Source name.
        source_name: String,
        /// 1-based line.
        line: usize,
        /// Number of fields found.
        found: usize,
    },
    /// A field is not a number.
    #[error("{source_name}:{line}: not a number: `{field}`")]
    NotANumber {
        /// Source name.
        source_name: String,
        /// 1-based line.
        line: usize,
        /// The field.
        field: String,
    },
    /// A value is NaN or infinite.
    #[error("{source_name}:{line}: non-finite value")]
    NonFinite {
        /// Source name.
        source_name: String,
        /// 1-based line.
        line: usize,
    },
    /// `y_m` does not increase strictly.
    #[error(
        "{source_name}:{line}: y_m = {y_m} m does not exceed the previous row's {previous_m} m \
         (y_m must be strictly increasing)"
    )]
    NotIncreasing {
        /// Source name.
        source_name: String,
        /// 1-based line.
        line: usize,
        /// Offending value \[m\].
        y_m: f64,
        /// Value of the row before \[m\].
        previous_m: f64,
    },
    /// Fewer than two data rows (no segment to interpolate on).
    #[error("{source_name}: {rows} data rows, at least 2 needed")]
    TooFewRows {
        /// Source name.
        source_name: String,
        /// Rows found.
        rows: usize,
    },
    /// [`GeometryTable::from_columns`] got columns of different lengths.
    #[error("contact table columns of unequal length {lengths:?}")]
    ColumnLengths {
        /// Lengths of y, delta_r_left, delta_r_right, tan_gamma_left, tan_gamma_right.
        lengths: [usize; 5],
    },
    /// The table reaches farther from the track centre than a wheel can stand on its rail
    /// ([`MAX_TABLE_REACH_M`]): its end, where a wheelset counts as derailed, would be
    /// meaningless.
    #[error(
        "contact table reaches {reach_mm:.1} mm from the track centre, beyond {} mm: a \
         wheelset that far out has left its rails (write the table to at most {} mm, e.g. \
         contact-geometry --y-max)",
        MAX_TABLE_REACH_M * 1e3,
        MAX_TABLE_REACH_M * 1e3
    )]
    Reach {
        /// The larger of |y| at the two ends \[mm\].
        reach_mm: f64,
    },
    /// A rolling-radius difference of the table takes a wheel's rolling radius below half
    /// its nominal radius (a table in mm taken as m, or of another wheel).
    #[error(
        "contact table gives the {side} wheel a rolling radius of {radius_m:.4} m at y = \
         {y_mm:.2} mm (nominal {nominal_m:.4} m, delta_r {delta_r_m:.4} m): below half the \
         nominal radius, no wheel's"
    )]
    RollingRadius {
        /// "left" or "right".
        side: &'static str,
        /// y of the row \[mm\].
        y_mm: f64,
        /// Nominal rolling radius \[m\].
        nominal_m: f64,
        /// The row's rolling-radius difference \[m\].
        delta_r_m: f64,
        /// nominal + delta_r \[m\].
        radius_m: f64,
    },
}

/// Farthest a contact table may reach from the track centre \[m\]: the linear model's
/// derailment limit; flange contact begins within about 10 mm.
pub const MAX_TABLE_REACH_M: f64 = 0.05;

/// How [`write_csv`] prints the numbers.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CsvNumbers {
    /// Fixed decimals at the resolution of a profile contact search: y to 0.1 µm, delta r to
    /// 1 nm, tan gamma to 1e-6 (`-0.0100000,0.014353256,...`).
    Fixed,
    /// Seven significant digits in exponent form (`-1.000000e-2,1.377260e-2,...`), for tables
    /// derived by arithmetic (e.g. [`GeometryTable::with_tread_cone`]).
    Scientific,
}

/// One row of the format: y, delta_r_left, delta_r_right, tan_gamma_left, tan_gamma_right.
pub type CsvRow = [f64; 5];

/// tan(gamma) a table must reach on each side to cover the flange: beyond it the flange
/// guides the wheelset, and the end of the table is where a wheel climbs it (derailment).
pub const FLANGE_TAN_GAMMA: f64 = 1.0;

/// A contact table that does not reach flange contact on one side.
#[derive(Debug, Clone, PartialEq, Error)]
#[error(
    "contact table does not cover the flange: on the {side} wheel tan(gamma) reaches only \
     {max_tan_gamma:.3} within the table's range ({range_mm:.2} mm), flange contact needs \
     at least {FLANGE_TAN_GAMMA}"
)]
pub struct FlangeNotCovered {
    /// "left" or "right".
    pub side: &'static str,
    /// Largest tan(gamma) of that side.
    pub max_tan_gamma: f64,
    /// Range end on that side \[mm\].
    pub range_mm: f64,
}

/// Writes the CSV format: header line, then one line per row.
pub fn write_csv(rows: impl IntoIterator<Item = CsvRow>, numbers: CsvNumbers) -> String {
    use std::fmt::Write;
    let rows = rows.into_iter();
    let mut out = String::with_capacity(64 * (rows.size_hint().0 + 1));
    out.push_str(BOGIE_CSV_HEADER);
    out.push('\n');
    for [y, dl, dr, tl, tr] in rows {
        // Writing into a String cannot fail.
        let _ = match numbers {
            CsvNumbers::Fixed => writeln!(out, "{y:.7},{dl:.9},{dr:.9},{tl:.6},{tr:.6}"),
            CsvNumbers::Scientific => writeln!(out, "{y:.6e},{dl:.6e},{dr:.6e},{tl:.6e},{tr:.6e}"),
        };
    }
    out
}

/// Contact geometry of one wheelset as functions of its lateral displacement relative to the
/// track (format and conventions in the module docs). Immutable once built.
/// A deserialised table (a saved FMU state, say) is checked as [`GeometryTable::from_columns`]
/// checks a built one, so that no lookup can index out of its rows.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "TableColumns")]
pub struct GeometryTable {
    y: Vec<f64>,
    dr_l: Vec<f64>,
    dr_r: Vec<f64>,
    tg_l: Vec<f64>,
    tg_r: Vec<f64>,
}

/// The serialised form of [`GeometryTable`] before its checks.
#[derive(Deserialize)]
struct TableColumns {
    y: Vec<f64>,
    dr_l: Vec<f64>,
    dr_r: Vec<f64>,
    tg_l: Vec<f64>,
    tg_r: Vec<f64>,
}

impl TryFrom<TableColumns> for GeometryTable {
    type Error = TableError;
    fn try_from(c: TableColumns) -> Result<Self, TableError> {
        Self::from_columns(c.y, c.dr_l, c.dr_r, c.tg_l, c.tg_r)
    }
}

/// Interpolated contact geometry at one lateral displacement.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactGeometry {
    /// r_L - r0 \[m\].
    pub delta_r_left_m: f64,
    /// r_R - r0 \[m\].
    pub delta_r_right_m: f64,
    /// tan(gamma_L) >= 0.
    pub tan_gamma_left: f64,
    /// tan(gamma_R) >= 0.
    pub tan_gamma_right: f64,
}

/// The table segment of the last lookup, kept by the caller (one per wheelset) to start the next
/// [`GeometryTable::lookup_with_hint`] there. Any value is safe: a stale or foreign hint only
/// costs a search.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct SegmentHint(usize);

fn check_row(
    source_name: &str,
    line: usize,
    row: &CsvRow,
    previous_y: Option<f64>,
) -> Result<(), TableError> {
    if row.iter().any(|v| !v.is_finite()) {
        return Err(TableError::NonFinite {
            source_name: source_name.to_string(),
            line,
        });
    }
    match previous_y {
        Some(previous_m) if row[0] <= previous_m => Err(TableError::NotIncreasing {
            source_name: source_name.to_string(),
            line,
            y_m: row[0],
            previous_m,
        }),
        _ => Ok(()),
    }
}

impl GeometryTable {
    /// Builds a table from columns; checks lengths, finiteness and strictly increasing y
    /// (errors name [`COLUMNS_SOURCE`] and the 1-based row as `line`).
    pub fn from_columns(
        y: Vec<f64>,
        dr_l: Vec<f64>,
        dr_r: Vec<f64>,
        tg_l: Vec<f64>,
        tg_r: Vec<f64>,
    ) -> Result<Self, TableError> {
        let lengths = [y.len(), dr_l.len(), dr_r.len(), tg_l.len(), tg_r.len()];
        if lengths.iter().any(|&l| l != lengths[0]) {
            return Err(TableError::ColumnLengths { lengths });
        }
        if y.len() < 2 {
            return Err(TableError::TooFewRows {
                source_name: COLUMNS_SOURCE.to_string(),
                rows: y.len(),
            });
        }
        for i in 0..y.len() {
            let row = [y[i], dr_l[i], dr_r[i], tg_l[i], tg_r[i]];
            let previous = i.checked_sub(1).map(|k| y[k]);
            check_row(COLUMNS_SOURCE, i + 1, &row, previous)?;
        }
        Ok(Self {
            y,
            dr_l,
            dr_r,
            tg_l,
            tg_r,
        })
    }

    /// Parses CSV text in the format of the module docs; `source_name` (a file name, or e.g.
    /// "built-in A/A table") is what errors name beside the line.
    pub fn parse_csv(text: &str, source_name: &str) -> Result<Self, TableError> {
        let mut cols: [Vec<f64>; 5] = Default::default();
        let mut header_seen = false;
        for (i, raw) in text.lines().enumerate() {
            let line_no = i + 1;
            let line = raw.trim();
            if line.is_empty() || line.starts_with('#') {
                continue;
            }
            if !header_seen {
                let h: String = line.chars().filter(|c| !c.is_whitespace()).collect();
                if h != BOGIE_CSV_HEADER {
                    return Err(TableError::Header {
                        source_name: source_name.to_string(),
                        line: line_no,
                        found: echo(line),
                    });
                }
                header_seen = true;
                continue;
            }
            let fields: Vec<&str> = line.split(',').map(str::trim).collect();
            if fields.len() != 5 {
                return Err(TableError::FieldCount {
                    source_name: source_name.to_string(),
                    line: line_no,
                    found: fields.len(),
                });
            }
            let mut row = [0.0; 5];
            for (value, field) in row.iter_mut().zip(&fields) {
                *value = field.parse().map_err(|_| TableError::NotANumber {
                    source_name: source_name.to_string(),
                    line: line_no,
                    field: (*field).to_string(),
                })?;
            }
            check_row(source_name, line_no, &row, cols[0].last().copied())?;
            for (col, value) in cols.iter_mut().zip(row) {
                col.push(value);
            }
        }
        if cols[0].len() < 2 {
            return Err(TableError::TooFewRows {
                source_name: source_name.to_string(),
                rows: cols[0].len(),
            });
        }
        let [y, dr_l, dr_r, tg_l, tg_r] = cols;
        Ok(Self {
            y,
            dr_l,
            dr_r,
            tg_l,
            tg_r,
        })
    }

    /// Reads a CSV file; errors name the path.
    pub fn load(path: impl AsRef<Path>) -> Result<Self, TableError> {
        let path = path.as_ref();
        let name = path.display().to_string();
        let text = crate::text_file::read_text_file(path, crate::text_file::MAX_TEXT_FILE_BYTES)
            .map_err(|message| TableError::Io {
                source_name: name.clone(),
                message,
            })?;
        Self::parse_csv(&text, &name)
    }

    /// The rows (y, delta_r_left, delta_r_right, tan_gamma_left, tan_gamma_right).
    pub fn rows(&self) -> impl ExactSizeIterator<Item = CsvRow> + '_ {
        (0..self.y.len()).map(|i| {
            [
                self.y[i],
                self.dr_l[i],
                self.dr_r[i],
                self.tg_l[i],
                self.tg_r[i],
            ]
        })
    }

    /// The table as CSV ([`write_csv`]).
    pub fn to_csv(&self, numbers: CsvNumbers) -> String {
        write_csv(self.rows(), numbers)
    }

    /// Synthetic, symmetric profile: a cone of conicity `conicity` (contact angle
    /// tan gamma = conicity on the tread) and a flange that starts at `flange_clearance_m`,
    /// where the radius difference and the contact angle rise over `ramp_m` to
    /// tan gamma = `flange_tan` (about 70 deg) and delta r grows with slope `flange_tan`.
    /// Grid 0.1 mm over +-(clearance + ramp + 3 mm).
    pub fn synthetic(
        conicity: f64,
        flange_clearance_m: f64,
        ramp_m: f64,
        flange_tan: f64,
    ) -> Result<Self, TableError> {
        let step = 1e-4;
        let y_max = flange_clearance_m + ramp_m + 3e-3;
        let n = (2.0 * y_max / step).round() as i64;
        let (mut y, mut dl, mut dr, mut tl, mut tr) = (vec![], vec![], vec![], vec![], vec![]);
        // Flange side: tan gamma ramps smoothly (cosine) from the cone value to flange_tan;
        // delta r is the integral of that slope, so r and gamma stay consistent.
        let slope = |u: f64| -> f64 {
            // u = distance beyond flange clearance
            if u <= 0.0 {
                conicity
            } else if u >= ramp_m {
                flange_tan
            } else {
                let w = 0.5 - 0.5 * (std::f64::consts::PI * u / ramp_m).cos();
                conicity + (flange_tan - conicity) * w
            }
        };
        let dr_flange = |u: f64| -> f64 {
            // integral of (slope - conicity) over [0, u], trapezoid with fine steps
            if u <= 0.0 {
                return 0.0;
            }
            let k = 200;
            let du = u / k as f64;
            let mut acc = 0.0;
            for j in 0..k {
                let a = slope(j as f64 * du) - conicity;
                let b = slope((j + 1) as f64 * du) - conicity;
                acc += 0.5 * (a + b) * du;
            }
            acc
        };
        for i in 0..=n {
            let yi = -y_max + i as f64 * step;
            let ur = yi - flange_clearance_m; // right flange engages for y > 0
            let ul = -yi - flange_clearance_m;
            y.push(yi);
            dr.push(conicity * yi + dr_flange(ur));
            dl.push(-conicity * yi + dr_flange(ul));
            tr.push(slope(ur));
            tl.push(slope(ul));
        }
        Self::from_columns(y, dl, dr, tl, tr)
    }

    /// Copy whose tread is replaced by a cone: for |y| <= `y_flange_m` the rolling-radius
    /// difference is delta_r(0) +- `conicity` y; beyond, the table's own rise (flange) is
    /// appended continuously: delta_r_R(y) = delta_r(0) + conicity y_f + (dr_R(y) - dr_R(y_f))
    /// (left side mirrored the same way). Contact angles are kept. (The bogie's worn-profile
    /// surrogate is the A/A table with a 0.25 cone over +-3.5 mm.)
    pub fn with_tread_cone(&self, conicity: f64, y_flange_m: f64) -> Self {
        let c0 = self.lookup(0.0);
        let yf = y_flange_m.abs();
        let (at_pos, at_neg) = (self.lookup(yf), self.lookup(-yf));
        let mut dr_l = Vec::with_capacity(self.y.len());
        let mut dr_r = Vec::with_capacity(self.y.len());
        for (i, &y) in self.y.iter().enumerate() {
            let r = if y <= yf {
                c0.delta_r_right_m + conicity * y
            } else {
                c0.delta_r_right_m + conicity * yf + (self.dr_r[i] - at_pos.delta_r_right_m)
            };
            let l = if y >= -yf {
                c0.delta_r_left_m - conicity * y
            } else {
                c0.delta_r_left_m + conicity * yf + (self.dr_l[i] - at_neg.delta_r_left_m)
            };
            dr_r.push(r);
            dr_l.push(l);
        }
        Self {
            y: self.y.clone(),
            dr_l,
            dr_r,
            tg_l: self.tg_l.clone(),
            tg_r: self.tg_r.clone(),
        }
    }

    /// Number of rows (at least 2).
    pub fn len(&self) -> usize {
        self.y.len()
    }

    /// Always false: a table has at least two rows.
    pub fn is_empty(&self) -> bool {
        self.y.is_empty()
    }

    /// Range of y covered by the table \[m\].
    pub fn y_range(&self) -> (f64, f64) {
        (self.y[0], self.y[self.y.len() - 1])
    }

    /// The table reaches flange contact ([`FLANGE_TAN_GAMMA`]) on both sides, so that a
    /// wheelset leaving its range has climbed a flange: the left wheel's flange on the side of
    /// negative y (the wheelset moved towards the left rail), the right wheel's on the side of
    /// positive y.
    pub fn check_flange(&self) -> Result<(), FlangeNotCovered> {
        let (lo, hi) = self.y_range();
        let (mut left, mut right) = (f64::NEG_INFINITY, f64::NEG_INFINITY);
        for [y, _, _, tl, tr] in self.rows() {
            if y <= 0.0 {
                left = left.max(tl);
            }
            if y >= 0.0 {
                right = right.max(tr);
            }
        }
        for (side, max_tan_gamma, range) in [("left", left, lo), ("right", right, hi)] {
            if max_tan_gamma < FLANGE_TAN_GAMMA {
                return Err(FlangeNotCovered {
                    side,
                    max_tan_gamma,
                    range_mm: range * 1e3,
                });
            }
        }
        Ok(())
    }

    /// The table fits a wheelset of nominal rolling radius `wheel_radius_m`: it reaches no
    /// farther than [`MAX_TABLE_REACH_M`] from the track centre, and no row takes a wheel's
    /// rolling radius below half the nominal one.
    pub fn check_for_wheel(&self, wheel_radius_m: f64) -> Result<(), TableError> {
        let (lo, hi) = self.y_range();
        let reach = lo.abs().max(hi.abs());
        if reach > MAX_TABLE_REACH_M {
            return Err(TableError::Reach {
                reach_mm: reach * 1e3,
            });
        }
        for [y, dl, dr, _, _] in self.rows() {
            for (side, delta_r) in [("left", dl), ("right", dr)] {
                let radius = wheel_radius_m + delta_r;
                if radius.is_nan() || radius < 0.5 * wheel_radius_m {
                    return Err(TableError::RollingRadius {
                        side,
                        y_mm: y * 1e3,
                        nominal_m: wheel_radius_m,
                        delta_r_m: delta_r,
                        radius_m: radius,
                    });
                }
            }
        }
        Ok(())
    }

    /// Segment [i, i+1] used for y: the last row at or below y, clamped to the end segments
    /// (so the end segments extrapolate linearly; NaN gives segment 0).
    #[inline]
    fn segment(&self, y: f64) -> usize {
        let n = self.y.len();
        match self.y.partition_point(|&v| v <= y) {
            0 => 0,
            k if k >= n => n - 2,
            k => k - 1,
        }
    }

    /// True if [`Self::segment`] would return `i` for y.
    #[inline]
    fn segment_holds(&self, i: usize, y: f64) -> bool {
        let last = self.y.len() - 2;
        i <= last && (i == 0 || self.y[i] <= y) && (i == last || y < self.y[i + 1])
    }

    #[inline]
    fn interpolate(&self, i: usize, y: f64) -> ContactGeometry {
        let y0 = self.y[i];
        let t = (y - y0) / (self.y[i + 1] - y0);
        let lerp = |c: &[f64]| c[i] + t * (c[i + 1] - c[i]);
        ContactGeometry {
            delta_r_left_m: lerp(&self.dr_l),
            delta_r_right_m: lerp(&self.dr_r),
            tan_gamma_left: lerp(&self.tg_l),
            tan_gamma_right: lerp(&self.tg_r),
        }
    }

    /// Linear interpolation at y \[m\] (linear extrapolation of the end segments); binary
    /// search, no allocation.
    #[inline]
    pub fn lookup(&self, y: f64) -> ContactGeometry {
        self.interpolate(self.segment(y), y)
    }

    /// As [`Self::lookup`] (bit for bit the same result), starting from the segment of the
    /// previous call: the hint's segment and its two neighbours are tried before a binary
    /// search; the hint is updated.
    #[inline]
    pub fn lookup_with_hint(&self, hint: &mut SegmentHint, y: f64) -> ContactGeometry {
        let h = hint.0;
        let i = if self.segment_holds(h, y) {
            h
        } else if self.segment_holds(h.wrapping_add(1), y) {
            h + 1
        } else if h > 0 && self.segment_holds(h - 1, y) {
            h - 1
        } else {
            self.segment(y)
        };
        hint.0 = i;
        self.interpolate(i, y)
    }

    /// Largest |d tan(gamma)/dy| in the table [1/m]: bounds the flange contact stiffness.
    pub fn max_tan_gamma_slope(&self) -> f64 {
        let mut m: f64 = 0.0;
        for i in 0..self.y.len() - 1 {
            let dy = self.y[i + 1] - self.y[i];
            m = m.max(((self.tg_l[i + 1] - self.tg_l[i]) / dy).abs());
            m = m.max(((self.tg_r[i + 1] - self.tg_r[i]) / dy).abs());
        }
        m
    }

    /// Equivalent linear parameters for a harmonic wheelset motion of amplitude `amp_m`
    /// (first-harmonic / describing-function fit):
    /// conicity = fundamental of (delta r_R - delta r_L)/2 divided by amp, and gravitational
    /// stiffness per wheelset = -P * fundamental of (tan g_L - tan g_R) / amp.
    /// Returns (conicity, gravity_stiffness_per_wheelset / P) so the caller multiplies by P.
    pub fn linearise(&self, amp_m: f64) -> (f64, f64) {
        let n = 256;
        let (mut a_r, mut a_g) = (0.0, 0.0);
        for k in 0..n {
            let th = 2.0 * std::f64::consts::PI * (k as f64 + 0.5) / n as f64;
            let y = amp_m * th.sin();
            let c = self.lookup(y);
            a_r += 0.5 * (c.delta_r_right_m - c.delta_r_left_m) * th.sin();
            a_g += (c.tan_gamma_left - c.tan_gamma_right) * th.sin();
        }
        let scale = 2.0 / n as f64 / amp_m;
        (a_r * scale, -a_g * scale)
    }
}

/// At most the first 80 characters of a line read from a file, for an error message: enough to
/// recognise a wrong file, not a copy of whatever file a parameter named.
fn echo(line: &str) -> String {
    const MAX_CHARS: usize = 80;
    match line.char_indices().nth(MAX_CHARS) {
        Some((cut, _)) => format!("{}... ({} bytes)", &line[..cut], line.len()),
        None => line.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_deserialised_table_is_checked_as_a_built_one() {
        let t = synthetic();
        let good = serde_json::to_value(&t).unwrap();
        let back: GeometryTable = serde_json::from_value(good.clone()).unwrap();
        assert_eq!(back, t);
        let mut short = good.clone();
        short["dr_l"] = serde_json::json!([0.0]);
        let e = serde_json::from_value::<GeometryTable>(short).unwrap_err();
        assert!(e.to_string().contains("unequal length"), "{e}");
        let mut one_row = good.clone();
        for c in ["y", "dr_l", "dr_r", "tg_l", "tg_r"] {
            one_row[c] = serde_json::json!([0.0]);
        }
        let e = serde_json::from_value::<GeometryTable>(one_row).unwrap_err();
        assert!(e.to_string().contains("at least 2 needed"), "{e}");
        let mut unordered = good;
        unordered["y"][1] = unordered["y"][0].clone();
        let e = serde_json::from_value::<GeometryTable>(unordered).unwrap_err();
        assert!(e.to_string().contains("increas"), "{e}");
    }

    fn synthetic() -> GeometryTable {
        GeometryTable::synthetic(0.15, 7e-3, 0.5e-3, 2.7).unwrap()
    }

    #[test]
    fn synthetic_table_and_roundtrip() {
        let t = synthetic();
        let c = t.lookup(3e-3);
        assert!((c.delta_r_right_m - 0.15 * 3e-3).abs() < 1e-9);
        assert!((c.delta_r_left_m + 0.15 * 3e-3).abs() < 1e-9);
        assert!((c.tan_gamma_right - 0.15).abs() < 1e-9);
        let f = t.lookup(8e-3);
        assert!(f.tan_gamma_right > 2.6 && f.delta_r_right_m > 2e-3);
        let (lam, g) = t.linearise(2e-3);
        assert!((lam - 0.15).abs() < 1e-6 && g.abs() < 1e-9);
        for numbers in [CsvNumbers::Scientific, CsvNumbers::Fixed] {
            let t2 = GeometryTable::parse_csv(&t.to_csv(numbers), "roundtrip").unwrap();
            let c2 = t2.lookup(7.3e-3);
            let c1 = t.lookup(7.3e-3);
            assert!((c2.tan_gamma_right - c1.tan_gamma_right).abs() < 1e-5);
            assert_eq!(t2.len(), t.len());
        }
    }

    #[test]
    fn writer_number_styles() {
        let rows = [[-0.01, 0.014353256, -0.000491999, 2.788702, -0.00211]];
        let fixed = write_csv(rows, CsvNumbers::Fixed);
        assert_eq!(
            fixed,
            format!("{BOGIE_CSV_HEADER}\n-0.0100000,0.014353256,-0.000491999,2.788702,-0.002110\n")
        );
        let sci = write_csv(rows, CsvNumbers::Scientific);
        assert_eq!(
            sci,
            format!(
                "{BOGIE_CSV_HEADER}\n-1.000000e-2,1.435326e-2,-4.919990e-4,2.788702e0,-2.110000e-3\n"
            )
        );
    }

    #[test]
    fn hint_gives_the_plain_lookup_bit_for_bit() {
        let t = synthetic();
        let (lo, hi) = t.y_range();
        let mut hint = SegmentHint::default();
        // a slow sweep, jumps, both extrapolated ends, exact grid points, NaN
        let mut ys: Vec<f64> = (0..4000).map(|k| -12e-3 + k as f64 * 6e-6).collect();
        ys.extend([
            lo,
            hi,
            lo - 1e-3,
            hi + 1e-3,
            0.0,
            7e-3,
            -7e-3,
            1e-4,
            f64::NAN,
            3e-3,
        ]);
        ys.extend((0..500).map(|k| ((k * 7919) % 1000) as f64 * 2.4e-5 - 12e-3));
        for &y in &ys {
            let a = t.lookup(y);
            let b = t.lookup_with_hint(&mut hint, y);
            for (u, v) in [
                (a.delta_r_left_m, b.delta_r_left_m),
                (a.delta_r_right_m, b.delta_r_right_m),
                (a.tan_gamma_left, b.tan_gamma_left),
                (a.tan_gamma_right, b.tan_gamma_right),
            ] {
                assert_eq!(u.to_bits(), v.to_bits(), "y = {y}");
            }
        }
        // a hint from a longer table is harmless
        let mut foreign = SegmentHint(1_000_000);
        assert_eq!(t.lookup_with_hint(&mut foreign, 1e-3), t.lookup(1e-3));
    }

    #[test]
    fn bad_tables_name_source_and_line() {
        let h = BOGIE_CSV_HEADER;
        let e = GeometryTable::parse_csv("y,a\n1,2", "t.csv").unwrap_err();
        assert!(matches!(e, TableError::Header { line: 1, .. }), "{e:?}");
        assert!(e.to_string().starts_with("t.csv:1: "), "{e}");
        assert!(e.to_string().ends_with("got `y,a`"), "{e}");
        // a long first line (any file a parameter may name) is echoed in part only
        let long = "é".repeat(100_000);
        let e = GeometryTable::parse_csv(&long, "t.csv")
            .unwrap_err()
            .to_string();
        assert!(e.len() < 300, "{} bytes", e.len());
        assert!(e.ends_with("... (200000 bytes)`"), "{e}");
        let e = GeometryTable::parse_csv(&format!("{h}\n0,0,0,0,0\n"), "t.csv").unwrap_err();
        assert!(matches!(e, TableError::TooFewRows { rows: 1, .. }), "{e:?}");
        let text = format!("# comment\n{h}\n0,0,0,0,0\n0,0,0,0,0\n");
        let e = GeometryTable::parse_csv(&text, "t.csv").unwrap_err();
        assert!(
            matches!(e, TableError::NotIncreasing { line: 4, .. }),
            "{e:?}"
        );
        assert!(e.to_string().starts_with("t.csv:4: "), "{e}");
        let e =
            GeometryTable::parse_csv(&format!("{h}\n0,0,0,0,0\n1,0,x,0,0\n"), "t.csv").unwrap_err();
        assert!(
            matches!(&e, TableError::NotANumber { line: 3, field, .. } if field == "x"),
            "{e:?}"
        );
        let e = GeometryTable::parse_csv(&format!("{h}\n0,0,0,0\n"), "t.csv").unwrap_err();
        assert!(
            matches!(
                e,
                TableError::FieldCount {
                    line: 2,
                    found: 4,
                    ..
                }
            ),
            "{e:?}"
        );
        let e = GeometryTable::parse_csv(&format!("{h}\n0,0,0,0,0\n1,0,inf,0,0\n"), "t.csv")
            .unwrap_err();
        assert!(matches!(e, TableError::NonFinite { line: 3, .. }), "{e:?}");
        let e = GeometryTable::load("/nonexistent/table.csv").unwrap_err();
        assert!(matches!(e, TableError::Io { .. }), "{e:?}");
        assert!(e.to_string().contains("/nonexistent/table.csv"), "{e}");
        let e = GeometryTable::from_columns(vec![0.0, 1.0], vec![0.0], vec![], vec![], vec![])
            .unwrap_err();
        assert!(matches!(e, TableError::ColumnLengths { .. }), "{e:?}");
    }
}
