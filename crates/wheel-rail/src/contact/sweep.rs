//! The contact table over a uniform grid of lateral displacements: the reachable range up to
//! the flange limit (the rows the time-domain models use), the flange-climbing rows beyond it
//! (the equivalent conicity's Δr continues there, as EN 15302's reference values do up to
//! 7.5 mm for case E1), and the contact-point jumps (two-point contact) located between grid
//! points by bisection.

use serde::{Deserialize, Serialize};

use super::{prepare, solve_at, ContactError, ContactRow, ContactSetup, Prepared, WheelSide};
use crate::contact::RadiusConvention;
use crate::table::{write_csv, CsvNumbers, CsvRow, GeometryTable, TableError};

/// Most rows a contact table may have (a point every 0.02 um over +-10 mm).
pub const MAX_TABLE_ROWS: usize = 1_000_000;

/// Two adjacent rows whose contact point on one wheel moves by more than this [m] ...
const JUMP_CANDIDATE_M: f64 = 0.25e-3;
/// ... and by more than this times its movement in either neighbouring step are searched for a
/// jump. A continuous contact moves fast in nearly conformal zones (up to ~15 dy on the
/// EN 15302 profiles, wheel R14 against rail R13 at the flange root: 0.7-1.1 mm per 0.05 mm
/// step) but at a smoothly varying rate (at most ~1.2 times its neighbours' there); a jump adds
/// its size to one step (E1 flange: 1.85 mm against 1.1 mm next to it).
const JUMP_OUTLIER: f64 = 1.3;
/// A candidate whose first midpoint splits the movement with at least this share in the smaller
/// half moves continuously (a jump puts all of it in one half): one contact solve per
/// continuous candidate. A jump smaller than about 0.7 times the continuous movement of its grid
/// step is therefore taken for continuous motion (its Δr effect is below that of the step).
const JUMP_LINEAR_SHARE: f64 = 0.3;
/// The bisection stops when the bracket is this narrow [m], far below any profile sampling.
const JUMP_BRACKET_M: f64 = 1e-8;
/// A contact point that still moves by more than this across the final bracket jumps [m]
/// (a continuous one moves ~15 * JUMP_BRACKET_M at most). The bisection also stops as soon as
/// the movement across its bracket falls below this.
const JUMP_MIN_M: f64 = 0.1e-3;

/// Rolling-radius-difference table over a uniform grid of lateral displacements.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ContactTable {
    /// Rows, increasing `y`.
    pub rows: Vec<ContactRow>,
    /// Nominal radius of the left wheel \[m\].
    pub nominal_radius_left_m: f64,
    /// Nominal radius of the right wheel \[m\].
    pub nominal_radius_right_m: f64,
    /// Half the lateral distance between the left and right contact points at y = 0 \[m\].
    pub e0_m: f64,
    /// Smallest reachable `y` of the table (rows below repeat this one) \[m\].
    pub y_reachable_min_m: f64,
    /// Largest reachable `y` \[m\].
    pub y_reachable_max_m: f64,
    /// Convention of the radius difference the rows were computed with.
    pub radius_convention: RadiusConvention,
    /// Rows beyond the flange limit that were still solved (the wheel climbing its flange past
    /// the steepest point), increasing `y`, on grid points of the table. The search stops on each
    /// side at the first grid point where the contact reaches a profile end or is not found.
    /// `rows` repeats the last reachable row there instead; the equivalent conicity uses these.
    pub flange_climb_rows: Vec<ContactRow>,
    /// Jumps of a contact point between two grid points (two-point contact, tread or flange),
    /// increasing `y`.
    pub jumps: Vec<ContactJump>,
}

/// A jump of one wheel's contact point between two grid rows: at `y_m` that wheel touches its
/// rail at two points (two-point contact). Located by bisection on `y` to within
/// `after.y_m - before.y_m` (1e-8 m).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ContactJump {
    /// The wheel whose contact point jumps.
    pub side: WheelSide,
    /// Location of the two-point contact \[m\], midpoint of the final bracket.
    pub y_m: f64,
    /// State just below the jump.
    pub before: ContactRow,
    /// State just above the jump.
    pub after: ContactRow,
}

impl ContactJump {
    /// Distance between the two contact points on the wheel profile \[m\].
    pub fn wheel_distance_m(&self) -> f64 {
        (self.after.wheel(self.side).wheel_lateral_m - self.before.wheel(self.side).wheel_lateral_m)
            .abs()
    }

    /// True when either contact is on the flange (tanγ > 1), i.e. a tread-to-flange jump.
    pub fn involves_flange(&self) -> bool {
        self.before.wheel(self.side).tan_gamma.abs() > 1.0
            || self.after.wheel(self.side).tan_gamma.abs() > 1.0
    }
}

impl ContactTable {
    /// The table in the contact-table CSV format ([`crate::table`], header
    /// [`crate::table::BOGIE_CSV_HEADER`], [`CsvNumbers::Fixed`]), one row per grid point; rows beyond the
    /// flange limit repeat the last reachable values.
    pub fn to_bogie_csv(&self) -> String {
        write_csv(self.csv_rows(), CsvNumbers::Fixed)
    }

    /// The table as the time-domain models' [`GeometryTable`] (full precision, no CSV round
    /// trip).
    pub fn geometry_table(&self) -> Result<GeometryTable, TableError> {
        let mut cols: [Vec<f64>; 5] = Default::default();
        for row in self.csv_rows() {
            for (col, value) in cols.iter_mut().zip(row) {
                col.push(value);
            }
        }
        let [y, dr_l, dr_r, tg_l, tg_r] = cols;
        GeometryTable::from_columns(y, dr_l, dr_r, tg_l, tg_r)
    }

    fn csv_rows(&self) -> impl Iterator<Item = CsvRow> + '_ {
        self.rows.iter().map(|r| {
            [
                r.y_m,
                r.left.delta_radius_m,
                r.right.delta_radius_m,
                r.left.tan_gamma,
                r.right.tan_gamma,
            ]
        })
    }

    /// Rows within the reachable range.
    pub fn reachable_rows(&self) -> impl Iterator<Item = &ContactRow> {
        self.rows.iter().filter(|r| !r.beyond_flange_limit)
    }

    /// Every solved state in increasing `y`: the reachable rows, the flange-climbing rows and, at
    /// each jump, the states just below and just above it. This is the Δr(y) of the equivalent
    /// conicity ([`crate::conicity::DeltaR::from_table`]).
    pub fn solved_states(&self) -> Vec<ContactRow> {
        let mut all: Vec<ContactRow> = self
            .reachable_rows()
            .chain(&self.flange_climb_rows)
            .copied()
            .chain(self.jumps.iter().flat_map(|j| [j.before, j.after]))
            .collect();
        all.sort_by(|a, b| a.y_m.total_cmp(&b.y_m));
        all.dedup_by(|b, a| b.y_m == a.y_m);
        all
    }

    /// Mean nominal radius \[m\].
    pub fn nominal_radius_mean_m(&self) -> f64 {
        0.5 * (self.nominal_radius_left_m + self.nominal_radius_right_m)
    }
}

/// Contact table on the uniform grid `y_min_m, y_min_m + step_m, ..., y_max_m`.
///
/// The search marches outwards from the grid point nearest to y = 0. On each side, the first row
/// whose contact lies beyond the flange limit (contact point past the steepest point of the
/// flange, i.e. flange climbing) or at the end of a profile, or where no contact is found, ends
/// the reachable range: it and all rows further out repeat the last reachable row (with their
/// own `y_m` and `beyond_flange_limit = true`). Beyond the flange limit the search goes on while
/// the wheel climbs its flange ([`ContactTable::flange_climb_rows`]). Between adjacent solved
/// rows where a contact point moves by more than 0.25 mm and by more than 1.3 times its
/// movement in the neighbouring steps, the change is bisected on `y` down to 1e-8 m (unless
/// the first midpoint already splits it, which is continuous motion); if the contact point
/// still moves by more than 0.1 mm across that bracket, it jumps there
/// ([`ContactTable::jumps`]). The grid rows themselves do not depend on the jumps.
pub fn compute_table(
    setup: &ContactSetup,
    y_min_m: f64,
    y_max_m: f64,
    step_m: f64,
) -> Result<ContactTable, ContactError> {
    compute_table_until(setup, y_min_m, y_max_m, step_m, &|| false)
}

/// [`compute_table`] that asks `stop` before each row and ends with [`ContactError::Stopped`]
/// when it says so (a command interrupted by Ctrl-C: a fine grid on a dense profile takes
/// minutes).
pub fn compute_table_until(
    setup: &ContactSetup,
    y_min_m: f64,
    y_max_m: f64,
    step_m: f64,
    stop: &dyn Fn() -> bool,
) -> Result<ContactTable, ContactError> {
    let bad = |name, value, reason| ContactError::Param {
        name,
        value,
        reason,
    };
    if !(step_m.is_finite() && step_m > 0.0) {
        return Err(bad("step_m", step_m, "must be finite and > 0"));
    }
    if !(y_min_m.is_finite() && y_max_m.is_finite() && y_max_m >= y_min_m) {
        return Err(bad("y_max_m", y_max_m, "must be finite and >= y_min_m"));
    }
    let nf = ((y_max_m - y_min_m) / step_m).round();
    if nf > MAX_TABLE_ROWS as f64 {
        return Err(bad("step_m", step_m, "gives more than 1e6 rows"));
    }
    let n = nf as usize + 1;
    let p = prepare(setup)?;
    let ys: Vec<f64> = (0..n).map(|i| y_min_m + i as f64 * step_m).collect();
    let centre = ys
        .iter()
        .enumerate()
        .min_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
        .map(|(i, _)| i)
        .unwrap_or(0);
    let first = solve_at(&p, ys[centre], 0.0)?;
    if first.beyond {
        return Err(ContactError::NoContact {
            side: "either side",
            y_m: ys[centre],
            reason: "the central row already lies beyond the flange limit (are the wheel \
                     and rail profiles swapped?)",
        });
    }
    let mut rows: Vec<Option<ContactRow>> = vec![None; n];
    rows[centre] = Some(first.row);
    let mut reach = [ys[centre], ys[centre]];
    let mut climb: Vec<ContactRow> = Vec::new();
    for (dir, range) in [
        (0usize, (centre + 1..n).collect::<Vec<_>>()),
        (1usize, (0..centre).rev().collect::<Vec<_>>()),
    ] {
        let mut last = first.row;
        let mut last_solved = first.row;
        let mut clamped = false;
        let mut climbing = true;
        for i in range {
            if stop() {
                return Err(ContactError::Stopped);
            }
            if !clamped || climbing {
                match solve_at(&p, ys[i], last_solved.roll_rad) {
                    Ok(s) if !clamped && !s.beyond => {
                        last = s.row;
                        last_solved = s.row;
                        reach[dir] = ys[i];
                        rows[i] = Some(s.row);
                        continue;
                    }
                    Ok(s) if !s.at_end => {
                        clamped = true;
                        last_solved = s.row;
                        climb.push(ContactRow {
                            beyond_flange_limit: true,
                            ..s.row
                        });
                    }
                    _ => {
                        clamped = true;
                        climbing = false;
                    }
                }
            }
            rows[i] = Some(ContactRow {
                y_m: ys[i],
                beyond_flange_limit: true,
                ..last
            });
        }
    }
    let rows: Vec<ContactRow> = rows.into_iter().flatten().collect();
    climb.sort_by(|a, b| a.y_m.total_cmp(&b.y_m));
    let jumps = locate_jumps(&p, &rows, &climb);
    let at0 = solve_at(&p, 0.0, 0.0)?.row;
    Ok(ContactTable {
        rows,
        nominal_radius_left_m: setup.nominal_radius_left_m,
        nominal_radius_right_m: setup.nominal_radius_right_m,
        e0_m: 0.5 * (at0.right.track_lateral_m - at0.left.track_lateral_m),
        y_reachable_min_m: reach[1],
        y_reachable_max_m: reach[0],
        radius_convention: setup.radius_convention,
        flange_climb_rows: climb,
        jumps,
    })
}

/// Jumps of the contact points between adjacent solved rows (reachable and flange-climbing),
/// see [`compute_table`]. A bisection step whose contact search fails ends that search without a
/// jump (the rows around it are kept as they are).
fn locate_jumps(p: &Prepared, rows: &[ContactRow], climb: &[ContactRow]) -> Vec<ContactJump> {
    let mut solved: Vec<&ContactRow> = rows
        .iter()
        .filter(|r| !r.beyond_flange_limit)
        .chain(climb)
        .collect();
    solved.sort_by(|a, b| a.y_m.total_cmp(&b.y_m));
    let mut jumps = Vec::new();
    for side in [WheelSide::Left, WheelSide::Right] {
        let moved = |a: &ContactRow, b: &ContactRow| {
            (b.wheel(side).wheel_lateral_m - a.wheel(side).wheel_lateral_m).abs()
        };
        let steps: Vec<f64> = solved.windows(2).map(|w| moved(w[0], w[1])).collect();
        for (i, w) in solved.windows(2).enumerate() {
            // a jump stands out of the movement in the neighbouring steps
            let neighbours = [i.checked_sub(1), Some(i + 1)]
                .into_iter()
                .flatten()
                .filter_map(|k| steps.get(k))
                .fold(0.0_f64, |m, &v| m.max(v));
            if steps[i] <= JUMP_CANDIDATE_M || steps[i] <= JUMP_OUTLIER * neighbours {
                continue;
            }
            let (mut a, mut b) = (*w[0], *w[1]);
            let mut failed = false;
            let mut first = true;
            let mut continuous = false;
            // follow the half that carries the larger movement; a continuous contact soon
            // moves less than JUMP_MIN_M across the bracket, a jump never does
            while b.y_m - a.y_m > JUMP_BRACKET_M && moved(&a, &b) > JUMP_MIN_M {
                let y = 0.5 * (a.y_m + b.y_m);
                let Ok(m) = solve_at(p, y, 0.5 * (a.roll_rad + b.roll_rad)) else {
                    failed = true;
                    break;
                };
                let m = ContactRow {
                    beyond_flange_limit: a.beyond_flange_limit && b.beyond_flange_limit,
                    ..m.row
                };
                // a continuous contact passes the midpoint near half-way; a jump lies wholly in
                // one half (JUMP_LINEAR_SHARE)
                let (left, right) = (moved(&a, &m), moved(&m, &b));
                if first && left.min(right) > JUMP_LINEAR_SHARE * (left + right) {
                    continuous = true;
                    break;
                }
                first = false;
                if left >= right {
                    b = m;
                } else {
                    a = m;
                }
            }
            if !failed && !continuous && moved(&a, &b) > JUMP_MIN_M {
                jumps.push(ContactJump {
                    side,
                    y_m: 0.5 * (a.y_m + b.y_m),
                    before: a,
                    after: b,
                });
            }
        }
    }
    jumps.sort_by(|a, b| a.y_m.total_cmp(&b.y_m));
    jumps
}
