//! Wheel/rail contact geometry from profiles, through crate `wheel-rail`:
//! the contact table in the bogie's CSV format, a detailed table, Δr(y), tanγ(y) and the
//! EN 15302 equivalent conicity over amplitude.
//!
//! Defaults: EN 15302 case E1 (wheel A and rail A both sides, 920 mm wheels, gauge
//! 1435.16 mm), with the benchmark profiles built in from `crates/wheel-rail/data/`. Rail A
//! already contains its inclination, so the default additional inclination is 0; a rail given
//! upright needs `1:40` (or `1:20`).
//!
//! Unequal wheel radii: the bogie-format table is always computed with the rigid wheelset's roll
//! (the time-domain models' geometry); Δr, the detailed table and the conicity follow the chosen
//! [`RadiusConvention`] (EN 15302's offset by default), named in their CSV headers. A conicity
//! the EN 15302 method does not define at some amplitude of the curve is an error naming the
//! amplitude and the reason, never a blank; a flat tread gives 0. [`fleet`] runs many wheel
//! profiles into one table.

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};

use wheel_rail::{
    compute_table_until, ContactRow, ContactSetup, ContactTable, DeltaR, Profile, RadiusConvention,
    WheelSide,
};

use super::{AnalysisError, Artefacts, Table};
use crate::plot::Chart;

pub mod fleet;

/// EN 15302 wheel profile A (built in).
pub const WHEEL_A: &str = include_str!("../../../wheel-rail/data/RUIC519A.dat");
/// EN 15302 rail profile A, 60E1 head with its inclination (built in).
pub const RAIL_A: &str = include_str!("../../../wheel-rail/data/SUIC519A.dat");
/// Gauge of case E1 \[mm\].
pub const E1_GAUGE_MM: f64 = 1435.16;
/// Nominal rolling radius of case E1 \[mm\] (920 mm wheels).
pub const E1_RADIUS_MM: f64 = 460.0;
/// EN 15302 Annex E equivalent conicity of case E1 at 1, 3, 5, 7 mm (as quoted by the
/// wheel-rail crate docs).
pub const E1_REFERENCE_CONICITY: [(f64, f64); 4] =
    [(1.0, 0.125), (3.0, 0.188), (5.0, 0.254), (7.0, 0.505)];
/// Amplitudes printed in the summary \[mm\].
pub const SUMMARY_AMPLITUDES_MM: [f64; 4] = [1.0, 3.0, 5.0, 7.0];

/// Where a profile comes from.
#[derive(Debug, Clone, PartialEq)]
pub enum ProfileSource {
    File(PathBuf),
    /// (name used in messages, text in mm)
    BuiltIn(&'static str, &'static str),
}

impl ProfileSource {
    pub fn load(&self) -> Result<Profile, AnalysisError> {
        Ok(match self {
            ProfileSource::File(p) => Profile::from_file(p)?,
            ProfileSource::BuiltIn(name, text) => Profile::parse_str(text, name)?,
        })
    }

    pub fn describe(&self) -> String {
        match self {
            ProfileSource::File(p) => p.display().to_string(),
            ProfileSource::BuiltIn(name, _) => (*name).to_string(),
        }
    }
}

/// Parses a rail inclination: `1:40`, `1/40`, a decimal tangent (`0.025`) or `0`.
pub fn parse_inclination(s: &str) -> Result<f64, String> {
    let t = s.trim();
    let bad = || {
        format!(
            "'{}' is not an inclination (use 1:40, 1:20, 0 or a tangent like 0.025)",
            master::show::text(s)
        )
    };
    let v = if let Some((a, b)) = t.split_once([':', '/']) {
        let a: f64 = a.trim().parse().map_err(|_| bad())?;
        let b: f64 = b.trim().parse().map_err(|_| bad())?;
        if b == 0.0 {
            return Err(bad());
        }
        a / b
    } else {
        t.parse().map_err(|_| bad())?
    };
    if v.is_finite() && v.abs() < 0.2 {
        Ok(v)
    } else {
        Err(format!(
            "{s}: inclination must be a small tangent (|tan| < 0.2)"
        ))
    }
}

/// Inputs of a contact-geometry run (SI where not stated).
#[derive(Debug, Clone, PartialEq)]
pub struct GeometryInputs {
    pub wheel_left: ProfileSource,
    pub wheel_right: ProfileSource,
    pub rail_left: ProfileSource,
    pub rail_right: ProfileSource,
    pub gauge_m: f64,
    /// Rail inclination to apply (tangent, positive towards the track centre).
    pub inclination: f64,
    pub radius_left_m: f64,
    pub radius_right_m: f64,
    /// Table covers -y_max..y_max.
    pub y_max_m: f64,
    pub step_m: f64,
    /// Conicity curve amplitudes: from 1 mm to `amplitude_max_m` in this step \[m\].
    pub conicity_step_m: f64,
    /// Largest amplitude of the conicity curve \[m\].
    pub amplitude_max_m: f64,
    /// Convention of Δr, the detailed table and the conicity (the bogie-format table is always
    /// [`RadiusConvention::RigidRoll`]).
    pub radius_convention: RadiusConvention,
    /// Where the wheels stand: `None`, the profile origins [`ORIGIN_DISTANCE_M`] apart (EN
    /// 15302's profiles); `Some((back_to_back_m, back_face_to_origin_m))`, the wheels' back
    /// faces that far apart and each profile's origin that far from its back face.
    pub back_to_back: Option<(f64, f64)>,
}

/// Distance between the wheel profiles' origins when no back-to-back distance is given \[m\]:
/// EN 15302's profiles, whose origins lie 70 mm from the back faces, at 1360 mm back to back.
pub const ORIGIN_DISTANCE_M: f64 = 1.5;

/// The nominal back-to-back distance of standard-gauge wheelsets \[m\] and the distance from
/// an S1002 wheel's back face to its taping line (the profiles' origin) \[m\].
pub const NOMINAL_BACK_TO_BACK_M: (f64, f64) = (1.360, 0.070);

impl Default for GeometryInputs {
    /// EN 15302 case E1 with the built-in profiles; y in -10..10 mm every 0.05 mm as the
    /// bogie's built-in table.
    fn default() -> Self {
        let wheel = ProfileSource::BuiltIn(
            "built-in wheel A (crates/wheel-rail/data/RUIC519A.dat)",
            WHEEL_A,
        );
        let rail = ProfileSource::BuiltIn(
            "built-in rail A (crates/wheel-rail/data/SUIC519A.dat)",
            RAIL_A,
        );
        GeometryInputs {
            wheel_left: wheel.clone(),
            wheel_right: wheel,
            rail_left: rail.clone(),
            rail_right: rail,
            gauge_m: E1_GAUGE_MM * 1e-3,
            inclination: 0.0,
            radius_left_m: E1_RADIUS_MM * 1e-3,
            radius_right_m: E1_RADIUS_MM * 1e-3,
            y_max_m: 10e-3,
            step_m: 0.05e-3,
            conicity_step_m: 0.25e-3,
            amplitude_max_m: 7e-3,
            radius_convention: RadiusConvention::En15302Offset,
            back_to_back: None,
        }
    }
}

/// The conicity chart's legend for the reference method at amplitudes whose turning point
/// lies beyond the flange limit.
pub const BEYOND_FLANGE_LIMIT: &str = "Annex B, turning point on the climbing flange";

/// Conicity at one amplitude by the three methods (they share the turning points).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ConicityPoint {
    pub amplitude_m: f64,
    /// EN 15302 Annex B tanγe; 0 where Δr does not restore (flat tread).
    pub tan_gamma_e: f64,
    /// Wavelength of the kinematic oscillation \[m\] (infinite where tanγe = 0).
    pub wavelength_m: f64,
    /// EN 15302 Annex C (linear regression of Δr over the turning points' range) tanγe.
    pub regression: f64,
    /// Harmonic linearisation tanγ.
    pub harmonic: f64,
    /// Turning points \[m\].
    pub y1_m: f64,
    pub y2_m: f64,
    /// A turning point lies beyond the flange limit (the wheel climbs its flange).
    pub beyond_flange_limit: bool,
}

/// Result of a contact-geometry run.
#[derive(Debug, Clone, PartialEq)]
pub struct GeometryResults {
    pub inputs: GeometryInputs,
    /// In the chosen convention ([`GeometryInputs::radius_convention`]).
    pub table: ContactTable,
    /// The bogie-format table, rigid roll (the same as `table` for equal radii).
    pub bogie_table: ContactTable,
    /// From 1 mm to the largest amplitude.
    pub conicity: Vec<ConicityPoint>,
    /// At [`SUMMARY_AMPLITUDES_MM`] up to the largest amplitude.
    pub summary_conicity: Vec<ConicityPoint>,
}

/// The three methods at amplitude `a` on Δr; an amplitude the EN 15302 method does not define
/// is an error with its reason.
pub fn conicity_at(d: &DeltaR, a: f64) -> Result<ConicityPoint, AnalysisError> {
    let c = d.equivalent_conicity(a)?;
    let regression = d.linear_regression(a)?.tan_gamma_e;
    let harmonic = d.harmonic_linearisation(a)?;
    Ok(ConicityPoint {
        amplitude_m: a,
        tan_gamma_e: c.tan_gamma_e,
        wavelength_m: c.wavelength_m,
        regression,
        harmonic,
        y1_m: c.y1_m,
        y2_m: c.y2_m,
        beyond_flange_limit: c.beyond_flange_limit,
    })
}

/// The smallest amplitude with an equivalent conicity worth the name on a table of `step_m`:
/// an oscillation of a few table steps has none (at 0.0001 mm Annex B gave tan(gamma_e) = 0
/// beside 0.107 from the other two methods; at 1 mm on a 5 mm step all three gave 0.298
/// against EN 15302's 0.125): 0.5 mm and 10 steps.
pub fn lowest_amplitude_m(step_m: f64) -> f64 {
    (0.5e-3f64).max(10.0 * step_m)
}

/// Amplitudes of the conicity curve: from 1 mm (or the largest amplitude, if smaller) in
/// steps of `step` \[m\] on the grid 1 mm + k step (so that 3 mm, the standard's figure, is
/// one of them whenever the step divides 2 mm), the largest amplitude last even off the grid;
/// each to the nanometre (no 2.2500000000000004 mm in the table).
pub fn curve_amplitudes(amplitude_max_m: f64, step_m: f64) -> Vec<f64> {
    let start = amplitude_max_m.min(1e-3);
    let nm = |a: f64| (a * 1e9).round() / 1e9;
    let n = ((amplitude_max_m - start) / step_m + 1e-9).floor().max(0.0) as usize;
    let mut out: Vec<f64> = (0..=n).map(|k| nm(start + k as f64 * step_m)).collect();
    if out.last().is_some_and(|&a| a < nm(amplitude_max_m)) {
        out.push(nm(amplitude_max_m));
    }
    out
}

/// The contact set-up of a run (profiles read, options applied and checked).
pub fn setup_of(inputs: &GeometryInputs) -> Result<ContactSetup, AnalysisError> {
    let mut setup = ContactSetup::symmetric(
        inputs.wheel_left.load()?,
        inputs.rail_left.load()?,
        inputs.radius_left_m,
        inputs.gauge_m,
    );
    setup.wheel_right = inputs.wheel_right.load()?;
    setup.rail_right = inputs.rail_right.load()?;
    setup.nominal_radius_right_m = inputs.radius_right_m;
    // rail A stands at 1:20 in its own coordinates: an inclination added to it compounds (1:40
    // on it is about 1:13, and tan gamma_e at 3 mm falls from 0.18 to 0.013 without a word)
    if inputs.inclination != 0.0 {
        let rail_a = Profile::parse_str(RAIL_A, "rail A")?;
        let same =
            |r: &Profile| r.lateral_m == rail_a.lateral_m && r.vertical_m == rail_a.vertical_m;
        if same(&setup.rail_left) || same(&setup.rail_right) {
            return Err(AnalysisError::Option {
                option: "--inclination",
                value: master::show::num(inputs.inclination).to_string(),
                reason: "rail A (EN 15302's benchmark rail, built in and in \
                         data/wheel-rail/SUIC519A.dat) is already inclined at 1:20 in its \
                         coordinates, and an inclination added to it compounds: leave \
                         --inclination out for rail A, or give a rail profile in upright \
                         coordinates"
                    .to_string(),
            });
        }
    }
    setup.rail_inclination = inputs.inclination;
    setup.radius_convention = inputs.radius_convention;
    if let Some((back_to_back_m, back_face_to_origin_m)) = inputs.back_to_back {
        setup.wheel_placement = wheel_rail::WheelPlacement::BackToBack {
            back_to_back_m,
            back_face_to_origin_m,
        };
    }
    setup.validate()?;
    Ok(setup)
}

/// Where the wheels of `inputs` stand, for a summary (one line, no newline).
pub fn placement_text(inputs: &GeometryInputs) -> String {
    match inputs.back_to_back {
        None => "wheel profile origins 1500 mm apart: back-to-back 1360 mm for origins 70 mm \
                 from the back faces (EN 15302's, S1002's taping line)"
            .to_string(),
        Some((b, o)) => format!(
            "wheels {:.2} mm back to back, each profile origin {:.2} mm from its back face \
             (origins {:.2} mm apart)",
            b * 1e3,
            o * 1e3,
            (b + 2.0 * o) * 1e3
        ),
    }
}

/// Checks the numeric options shared by the single and the fleet run.
pub fn check_options(inputs: &GeometryInputs) -> Result<(), AnalysisError> {
    // the value as the user gave it in mm: 15 significant digits drop the round-off of its
    // trip through metres (1400 mm, not 1400.0000000000002) and keep what was typed
    // (1480.0000000001 stays out of range in the message too)
    let bad = |option: &'static str, v: f64, reason: &str| AnalysisError::Option {
        option,
        value: master::show::num(format!("{v:.14e}").parse().unwrap_or(v)).to_string(),
        reason: reason.to_string(),
    };
    // the ranges of wheel_rail's ContactSetup::validate, in the options' millimetres
    for (option, radius_m) in [
        ("--radius", inputs.radius_left_m),
        ("--radius-right", inputs.radius_right_m),
    ] {
        if !(radius_m.is_finite() && radius_m > 0.1 && radius_m < 2.0) {
            return Err(bad(
                option,
                radius_m * 1e3,
                "must be a rolling radius in (100, 2000) mm",
            ));
        }
    }
    // the wheelset is a standard-gauge one (rolling circles 1500 mm apart, flanges about
    // 1425 mm across): 1000, 1067 or 1668 mm track found no overlap, 1520 mm a wheel without
    // flange contact, 1420 mm a wheelset already on its flanges
    if !(inputs.gauge_m.is_finite() && inputs.gauge_m >= 1.425 && inputs.gauge_m <= 1.48) {
        return Err(bad(
            "--gauge",
            inputs.gauge_m * 1e3,
            "must be a standard track gauge, tight to wide, in [1425, 1480] mm (the wheelset's \
             rolling circles are 1500 mm apart, its flanges about 1425 mm)",
        ));
    }
    // a standard-gauge wheelset: 1357-1363 mm in service (EN 15313), wider for a study; the
    // origin near the taping line, 70 mm from the back face on S1002
    if let Some((b, o)) = inputs.back_to_back {
        if !(b.is_finite() && (1.340..=1.380).contains(&b)) {
            return Err(bad(
                "--back-to-back",
                b * 1e3,
                "must be a standard-gauge back-to-back distance in [1340, 1380] mm",
            ));
        }
        if !(o.is_finite() && (0.040..=0.100).contains(&o)) {
            return Err(bad(
                "--back-face-offset",
                o * 1e3,
                "must be the back face's distance from the profile origin, in [40, 100] mm",
            ));
        }
    }
    // the table's y column has 0.1 um resolution: finer steps would write rows of equal y,
    // which the vehicle models refuse
    if !(inputs.step_m.is_finite() && inputs.step_m >= 1e-6) {
        return Err(bad(
            "--step",
            inputs.step_m * 1e3,
            "must be at least 0.001 mm (the table gives y to 0.1 um)",
        ));
    }
    if !(inputs.y_max_m.is_finite() && inputs.y_max_m >= 3.0 * inputs.step_m) {
        return Err(bad(
            "--y-max",
            inputs.y_max_m * 1e3,
            "must be at least 3 steps",
        ));
    }
    // a table from -y_max to y_max in whole steps, with a row at 0 (9.99 mm in 0.1 mm steps
    // ran to 10.01 mm without one)
    let steps = inputs.y_max_m / inputs.step_m;
    if (steps - steps.round()).abs() > 1e-6 * steps.max(1.0) {
        return Err(bad(
            "--y-max",
            inputs.y_max_m * 1e3,
            &format!(
                "must be a whole number of --step {} mm",
                master::show::num(inputs.step_m * 1e3)
            ),
        ));
    }
    // the table's rows, -y_max to y_max in steps (the contact search refuses more), refused
    // here to name the options
    let rows = 2.0 * inputs.y_max_m / inputs.step_m;
    if rows > wheel_rail::contact::MAX_TABLE_ROWS as f64 {
        return Err(bad(
            "--step",
            inputs.step_m * 1e3,
            &format!(
                "with --y-max {} mm gives {} table rows, more than 1 000 000",
                master::show::num(inputs.y_max_m * 1e3),
                master::show::num(rows.round())
            ),
        ));
    }
    if !(inputs.conicity_step_m.is_finite() && inputs.conicity_step_m > 0.0) {
        return Err(bad(
            "conicity step",
            inputs.conicity_step_m * 1e3,
            "must be > 0 mm",
        ));
    }
    let lowest_m = lowest_amplitude_m(inputs.step_m);
    if !(inputs.amplitude_max_m.is_finite()
        && inputs.amplitude_max_m >= lowest_m - 1e-12
        && inputs.amplitude_max_m < inputs.y_max_m)
    {
        return Err(bad(
            "--amplitude-max",
            inputs.amplitude_max_m * 1e3,
            &format!(
                "must be at least {} mm (0.5 mm and 10 table steps of --step) and below --y-max",
                master::show::num(lowest_m * 1e3)
            ),
        ));
    }
    Ok(())
}

/// The contact table of `setup` over the grid of `inputs`, stopping between rows once `cancel`
/// is set (Ctrl-C).
pub(crate) fn table_over_grid(
    setup: &ContactSetup,
    inputs: &GeometryInputs,
    cancel: &AtomicBool,
) -> Result<ContactTable, wheel_rail::ContactError> {
    let stop = || cancel.load(Ordering::SeqCst);
    compute_table_until(setup, -inputs.y_max_m, inputs.y_max_m, inputs.step_m, &stop)
}

/// A contact search stopped by the caller is the command's cancellation.
pub(crate) fn stopped(e: wheel_rail::ContactError) -> AnalysisError {
    match e {
        wheel_rail::ContactError::Stopped => AnalysisError::Cancelled,
        e => e.into(),
    }
}

/// Reads the profiles, computes the tables and the conicity curve. Profile errors name the
/// file and line; an amplitude without a conicity is an error; nothing is written here.
pub fn contact_geometry(
    inputs: &GeometryInputs,
    cancel: &AtomicBool,
) -> Result<GeometryResults, AnalysisError> {
    check_options(inputs)?;
    let setup = setup_of(inputs)?;
    // a failed search names the profiles (the same message came for a swapped, mirrored or
    // flangeless profile)
    let profiles = |e: wheel_rail::ContactError| {
        let pair = |w: &ProfileSource, r: &ProfileSource| {
            format!("wheel {} on rail {}", w.describe(), r.describe())
        };
        let left = pair(&inputs.wheel_left, &inputs.rail_left);
        let right = pair(&inputs.wheel_right, &inputs.rail_right);
        let both = if left == right {
            left
        } else {
            format!("left {left}, right {right}")
        };
        // a reference point lost, or a rail no longer single-valued, once the rails are
        // inclined: the option that inclined them is named
        let inclined = inputs.inclination != 0.0
            && matches!(
                e,
                wheel_rail::ContactError::ReferencePoint { .. }
                    | wheel_rail::ContactError::Profile(_)
            );
        match e {
            wheel_rail::ContactError::Stopped => AnalysisError::Cancelled,
            e if inclined => AnalysisError::Option {
                option: "--inclination",
                value: master::show::num(inputs.inclination).to_string(),
                reason: format!("the rails inclined by it give no contact geometry ({both}: {e})"),
            },
            e => AnalysisError::Geometry(format!("{both}: {e}")),
        }
    };
    let table = table_over_grid(&setup, inputs, cancel).map_err(profiles)?;
    let bogie_table = if setup.radius_convention == RadiusConvention::RigidRoll
        || setup.nominal_radius_left_m == setup.nominal_radius_right_m
    {
        table.clone()
    } else {
        let rigid = ContactSetup {
            radius_convention: RadiusConvention::RigidRoll,
            ..setup
        };
        table_over_grid(&rigid, inputs, cancel).map_err(profiles)?
    };
    let d = DeltaR::from_table(&table);
    let lowest_m = lowest_amplitude_m(inputs.step_m) - 1e-12;
    let amplitudes = curve_amplitudes(inputs.amplitude_max_m, inputs.conicity_step_m);
    let last = amplitudes.last().copied();
    let conicity = amplitudes
        .into_iter()
        // the largest amplitude, checked against the same bound, stays whatever its rounding
        .filter(|&a| a >= lowest_m || Some(a) == last)
        .map(|a| {
            conicity_at(&d, a).map_err(|e| {
                AnalysisError::Input(format!(
                    "{e}\n  (the conicity curve runs to --amplitude-max {:.2} mm; a smaller one, \
                     or a wider --y-max, gives a complete curve)",
                    inputs.amplitude_max_m * 1e3
                ))
            })
        })
        .collect::<Result<Vec<_>, _>>()?;
    let summary_conicity = SUMMARY_AMPLITUDES_MM
        .iter()
        .filter(|a| **a * 1e-3 <= inputs.amplitude_max_m + 1e-12 && **a * 1e-3 >= lowest_m)
        .map(|a| conicity_at(&d, a * 1e-3))
        .collect::<Result<Vec<_>, _>>()?;
    Ok(GeometryResults {
        inputs: inputs.clone(),
        table,
        bogie_table,
        conicity,
        summary_conicity,
    })
}

/// One line of the detailed table: a grid row (beyond the flange limit the flange-climbing
/// state, where the search found one) or a state at a two-point contact.
struct DetailRow {
    row: ContactRow,
    two_point: Option<WheelSide>,
}

fn detail_rows(table: &ContactTable) -> Vec<DetailRow> {
    // the flange-climbing state by y (a scan of them per row was quadratic: minutes for a
    // fine --step over a wide --y-max); + 0.0 makes -0 and 0 one key, as == does
    let key = |y: f64| (y + 0.0).to_bits();
    let mut climbs: std::collections::HashMap<u64, &ContactRow> = std::collections::HashMap::new();
    for c in &table.flange_climb_rows {
        climbs.entry(key(c.y_m)).or_insert(c);
    }
    let mut out: Vec<DetailRow> = table
        .rows
        .iter()
        .map(|r| {
            let climb = climbs
                .get(&key(r.y_m))
                .filter(|_| r.beyond_flange_limit)
                .copied();
            DetailRow {
                row: *climb.unwrap_or(r),
                two_point: None,
            }
        })
        .collect();
    for j in &table.jumps {
        for row in [j.before, j.after] {
            out.push(DetailRow {
                row: ContactRow { y_m: j.y_m, ..row },
                two_point: Some(j.side),
            });
        }
    }
    out.sort_by(|a, b| a.row.y_m.total_cmp(&b.row.y_m));
    out
}

impl GeometryResults {
    /// y of the first reachable row (from the centre outwards) with tanγ > 1 on the right
    /// (flange contact) \[m\].
    pub fn flange_contact_y_m(&self) -> Option<f64> {
        self.table
            .reachable_rows()
            .filter(|r| r.y_m > 0.0 && r.right.tan_gamma > 1.0)
            .map(|r| r.y_m)
            .reduce(f64::min)
    }

    pub fn add_artefacts(&self, a: &mut Artefacts) -> Result<(), AnalysisError> {
        a.add_text("wheel_rail_table.csv", self.bogie_table.to_bogie_csv());
        let conv = self.table.radius_convention.name();
        let mut d = Table::new(&[
            "y [mm]",
            &format!("delta r = r_right - r_left [mm] ({conv})"),
            "r_left [mm]",
            "r_right [mm]",
            "tan gamma left",
            "tan gamma right",
            "roll [mrad]",
            "contact left on wheel [mm]",
            "contact left on rail [mm]",
            "contact right on wheel [mm]",
            "contact right on rail [mm]",
            "contact left track lateral [mm]",
            "contact right track lateral [mm]",
            "beyond flange limit",
            "two-point contact left",
            "two-point contact right",
        ]);
        for DetailRow { row: r, two_point } in detail_rows(&self.table) {
            let flag = |b: bool| if b { 1.0 } else { 0.0 };
            d.rows.push(vec![
                r.y_m * 1e3,
                r.delta_r_m * 1e3,
                r.left.rolling_radius_m * 1e3,
                r.right.rolling_radius_m * 1e3,
                r.left.tan_gamma,
                r.right.tan_gamma,
                r.roll_rad * 1e3,
                r.left.wheel_lateral_m * 1e3,
                r.left.rail_lateral_m * 1e3,
                r.right.wheel_lateral_m * 1e3,
                r.right.rail_lateral_m * 1e3,
                r.left.track_lateral_m * 1e3,
                r.right.track_lateral_m * 1e3,
                flag(r.beyond_flange_limit),
                flag(two_point == Some(WheelSide::Left)),
                flag(two_point == Some(WheelSide::Right)),
            ]);
        }
        a.add_table("contact_detail.csv", &d)?;
        let mut c = Table::new(&[
            "amplitude [mm]",
            &format!("equivalent conicity EN 15302 Annex B ({conv})"),
            "wavelength [m] (inf: not restored)",
            &format!("equivalent conicity EN 15302 Annex C regression ({conv})"),
            "harmonic linearisation tan gamma",
            "turning point y1 [mm]",
            "turning point y2 [mm]",
            "turning point beyond flange limit",
        ]);
        for p in &self.conicity {
            c.rows.push(vec![
                // to the micrometre: the metres' round-off does not reach the file
                (p.amplitude_m * 1e6).round() / 1e3,
                p.tan_gamma_e,
                p.wavelength_m,
                p.regression,
                p.harmonic,
                p.y1_m * 1e3,
                p.y2_m * 1e3,
                if p.beyond_flange_limit { 1.0 } else { 0.0 },
            ]);
        }
        a.add_table("conicity.csv", &c)?;

        let (lo, hi) = (self.table.y_reachable_min_m, self.table.y_reachable_max_m);
        let reach: Vec<ContactRow> = self
            .table
            .solved_states()
            .into_iter()
            .filter(|r| r.y_m >= lo && r.y_m <= hi)
            .collect();
        let range = format!("reachable y {:.2} to {:.2} mm", lo * 1e3, hi * 1e3);
        let dr = Chart::new(
            &format!("Rolling radius difference ({range}, {conv})"),
            "wheelset lateral displacement y [mm]",
            "delta r = r_right - r_left [mm]",
        )
        .with_series(
            "delta r",
            reach
                .iter()
                .map(|r| (r.y_m * 1e3, r.delta_r_m * 1e3))
                .collect(),
        );
        a.add_lines("delta_r.svg", &dr)?;
        let tg = Chart::new(
            &format!("Contact angle ({range})"),
            "wheelset lateral displacement y [mm]",
            "tan gamma [-]",
        )
        .with_series(
            "left wheel",
            reach
                .iter()
                .map(|r| (r.y_m * 1e3, r.left.tan_gamma))
                .collect(),
        )
        .with_series(
            "right wheel",
            reach
                .iter()
                .map(|r| (r.y_m * 1e3, r.right.tan_gamma))
                .collect(),
        );
        a.add_lines("tan_gamma.svg", &tg)?;
        // an amplitude whose turning point lies on the climbing flange gives the geometry's
        // number, not a running wheelset's: the three methods are drawn up to the flange
        // limit (when at least two amplitudes lie within it), the reference method beyond it
        // in grey (every value is in conicity.csv)
        let within: Vec<&ConicityPoint> = self
            .conicity
            .iter()
            .filter(|p| !p.beyond_flange_limit)
            .collect();
        let any_beyond = within.len() < self.conicity.len();
        let lines = !any_beyond || within.len() >= 2;
        let pts = |f: fn(&ConicityPoint) -> f64| -> Vec<(f64, f64)> {
            self.conicity
                .iter()
                .filter(|p| !any_beyond || !p.beyond_flange_limit)
                .map(|p| (p.amplitude_m * 1e3, f(p)))
                .collect()
        };
        let title =
            if lines {
                format!("Equivalent conicity (EN 15302, {conv})")
            } else {
                format!(
                "Equivalent conicity (EN 15302, {conv}): the turning points lie on the climbing \
                 flange at {} amplitudes",
                if within.is_empty() { "all" } else { "all but one" }
            )
            };
        let mut con = Chart::new(
            &title,
            "amplitude [mm]",
            "equivalent conicity tan gamma_e [-]",
        );
        if lines {
            con = con
                .with_series("reference method (Annex B)", pts(|p| p.tan_gamma_e))
                .with_series("linear regression (Annex C)", pts(|p| p.regression))
                .with_series("harmonic linearisation", pts(|p| p.harmonic));
        }
        if any_beyond {
            // from the last amplitude within the limit, so that the grey line continues it
            let beyond = within
                .last()
                .into_iter()
                .copied()
                .chain(self.conicity.iter().filter(|p| p.beyond_flange_limit))
                .map(|p| (p.amplitude_m * 1e3, p.tan_gamma_e))
                .collect();
            con = con.with_reference(BEYOND_FLANGE_LIMIT, beyond);
        }
        a.add_lines("conicity.svg", &con)?;
        Ok(())
    }

    /// Set-up, reachable range, flange contact and conicity at 1, 3, 5, 7 mm (with the
    /// EN 15302 E1 reference values when the defaults are used).
    pub fn summary(&self) -> String {
        let i = &self.inputs;
        let is_e1 = *i
            == GeometryInputs {
                y_max_m: i.y_max_m,
                step_m: i.step_m,
                conicity_step_m: i.conicity_step_m,
                amplitude_max_m: i.amplitude_max_m,
                radius_convention: i.radius_convention,
                ..GeometryInputs::default()
            };
        let mut s = format!(
            "wheels: {} / {}\nrails: {} / {}\nnominal radius {:.1} / {:.1} mm, gauge {:.2} mm, added rail inclination {}\n",
            i.wheel_left.describe(),
            i.wheel_right.describe(),
            i.rail_left.describe(),
            i.rail_right.describe(),
            i.radius_left_m * 1e3,
            i.radius_right_m * 1e3,
            i.gauge_m * 1e3,
            if i.inclination == 0.0 {
                "0 (as in the rail file)".to_string()
            } else {
                format!("1:{:.0}", 1.0 / i.inclination)
            }
        );
        // where the wheels stand is set by the profiles' datum, which the user must know
        s.push_str(&placement_text(i));
        s.push('\n');
        s.push_str(&format!(
            "reachable y: {:.2} to {:.2} mm (flange limit), e0 = {:.2} mm",
            self.table.y_reachable_min_m * 1e3,
            self.table.y_reachable_max_m * 1e3,
            self.table.e0_m * 1e3
        ));
        if let Some(y) = self.flange_contact_y_m() {
            s.push_str(&format!(
                ", flange contact (tan gamma > 1) from y = {:.2} mm",
                y * 1e3
            ));
        }
        s.push('\n');
        // --y-max is no physical limit, but the models read the table's end as one
        if i.y_max_m
            > self
                .table
                .y_reachable_max_m
                .max(-self.table.y_reachable_min_m)
                + 1e-9
        {
            s.push_str(&format!(
                "wheel_rail_table.csv: rows beyond the flange limit to +-{:.2} mm (--y-max) repeat \
                 the limit's values; the vehicle FMUs take the table's end as derailment\n",
                i.y_max_m * 1e3
            ));
        }
        let conv = self.table.radius_convention.name();
        if i.radius_left_m != i.radius_right_m {
            s.push_str(&format!(
                "radius difference: delta r, contact_detail.csv and the conicity in the {conv} \
                 convention; wheel_rail_table.csv (bogie format) in the rigid-roll convention\n"
            ));
        }
        for j in &self.table.jumps {
            s.push_str(&format!(
                "two-point contact on the {} wheel at y = {:.3} mm ({}, contact points {:.2} mm \
                 apart on the wheel; delta r {:.3} -> {:.3} mm)\n",
                j.side.name(),
                j.y_m * 1e3,
                if j.involves_flange() {
                    "tread to flange"
                } else {
                    "on the tread"
                },
                j.wheel_distance_m() * 1e3,
                j.before.delta_r_m * 1e3,
                j.after.delta_r_m * 1e3
            ));
        }
        s.push_str(&format!(
            "equivalent conicity (EN 15302 Annex B; Annex C regression in brackets; {conv}):\n"
        ));
        let lowest = lowest_amplitude_m(i.step_m);
        if lowest > 1e-3 + 1e-12 {
            s.push_str(&format!(
                "  none below {} mm: 10 table steps of --step {} mm (a finer --step gives the \
                 smaller amplitudes)\n",
                master::show::num(lowest * 1e3),
                master::show::num(i.step_m * 1e3)
            ));
        }
        for p in &self.summary_conicity {
            let a_mm = p.amplitude_m * 1e3;
            s.push_str(&format!(
                "  tan gamma_e at {a_mm:.0} mm: {:.4} ({:.4}), wavelength {}",
                p.tan_gamma_e,
                p.regression,
                if p.wavelength_m.is_finite() {
                    format!("{:.1} m", p.wavelength_m)
                } else {
                    "infinite (delta r does not restore)".to_string()
                }
            ));
            if p.beyond_flange_limit {
                s.push_str(", turning point on the climbing flange");
            }
            if is_e1 {
                if let Some((_, r)) = E1_REFERENCE_CONICITY.iter().find(|(aa, _)| *aa == a_mm) {
                    s.push_str(&format!("; EN 15302 E1 reference {r:.3}"));
                }
            }
            s.push('\n');
        }
        // the vehicle FMUs take a table only if it reaches flange contact on both sides (its
        // end is their derailment limit): said now, not when a simulation refuses it
        if let Ok(Err(e)) = self.bogie_table.geometry_table().map(|t| t.check_flange()) {
            s.push_str(&format!(
                "note: wheel_rail_table.csv does not reach flange contact ({e}): the vehicle \
                 FMUs refuse it as their contact.table (a wider --y-max, or a wheel with a \
                 flange)\n"
            ));
        }
        if i.y_max_m > wheel_rail::MAX_TABLE_REACH_M {
            s.push_str(&format!(
                "note: wheel_rail_table.csv reaches +-{:.2} mm (--y-max), beyond the {} mm the \
                 vehicle FMUs take as a contact table's reach: they refuse it as their \
                 contact.table\n",
                i.y_max_m * 1e3,
                wheel_rail::MAX_TABLE_REACH_M * 1e3
            ));
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The curve's amplitudes lie on the grid 1 mm + k step, 3 mm among them, the largest last
    /// (with 7.6 mm a spacing of 0.2538 mm had left out 3 mm), without float noise.
    #[test]
    fn curve_amplitudes_keep_the_standards_3_mm() {
        let mm = |v: Vec<f64>| {
            v.iter()
                .map(|a| (a * 1e6).round() / 1e3)
                .collect::<Vec<_>>()
        };
        let a = curve_amplitudes(7.6e-3, 0.25e-3);
        assert!(a.contains(&3e-3), "{a:?}");
        assert_eq!(*a.last().unwrap(), 7.6e-3);
        assert_eq!(mm(a.clone())[5], 2.25);
        assert_eq!(a.len(), 28);
        assert_eq!(mm(curve_amplitudes(7e-3, 0.25e-3)).len(), 25);
        assert_eq!(curve_amplitudes(0.5e-3, 0.25e-3), vec![0.5e-3]);
    }

    /// The conicity chart draws the three methods up to the flange limit and the reference
    /// method beyond it in grey, named in the legend (the values stay in conicity.csv); a
    /// curve within the limit has no such line.
    #[test]
    fn the_conicity_chart_marks_amplitudes_beyond_the_flange_limit() {
        // (the chart, the amplitudes beyond the flange limit, the amplitudes)
        let chart = |i: GeometryInputs| {
            let r = contact_geometry(&i, &AtomicBool::new(false)).unwrap();
            let mut a = Artefacts::default();
            r.add_artefacts(&mut a).unwrap();
            let svg = a.files.iter().find(|(n, _)| n == "conicity.svg").unwrap();
            let beyond = r.conicity.iter().filter(|p| p.beyond_flange_limit).count();
            (
                String::from_utf8_lossy(&svg.1).into_owned(),
                beyond,
                r.conicity.len(),
            )
        };
        let up_to = |amplitude_max_m| GeometryInputs {
            amplitude_max_m,
            ..GeometryInputs::default()
        };
        let (svg, beyond, _) = chart(up_to(7e-3));
        assert_eq!(beyond, 0);
        assert!(!svg.contains(BEYOND_FLANGE_LIMIT));
        let (svg, beyond, rows) = chart(up_to(9e-3));
        assert!(beyond > 0 && beyond < rows, "{beyond} of {rows}");
        assert!(svg.contains(BEYOND_FLANGE_LIMIT), "{svg}");
        // a wheelset so narrow in this gauge that every amplitude's turning point lies on the
        // flange: the grey line alone, and the title says so
        let (svg, beyond, rows) = chart(GeometryInputs {
            gauge_m: 1.425,
            back_to_back: Some((1.364, NOMINAL_BACK_TO_BACK_M.1)),
            amplitude_max_m: 6e-3,
            ..GeometryInputs::default()
        });
        assert_eq!(beyond, rows);
        assert!(svg.contains(BEYOND_FLANGE_LIMIT), "{svg}");
        assert!(
            svg.contains("flange at all amplitudes") && !svg.contains("Annex C"),
            "{svg}"
        );
    }

    /// A table that stops short of flange contact (here a --y-max of 3 mm) is written, with a
    /// note that the vehicle FMUs refuse it; the default one reaches the flange.
    #[test]
    fn a_table_without_flange_contact_is_noted() {
        let short = GeometryInputs {
            y_max_m: 3e-3,
            amplitude_max_m: 2e-3,
            ..GeometryInputs::default()
        };
        let r = contact_geometry(&short, &AtomicBool::new(false)).unwrap();
        let s = r.summary();
        assert!(
            s.contains("note: wheel_rail_table.csv does not reach flange contact")
                && s.contains("the vehicle FMUs refuse it"),
            "{s}"
        );
        let r = contact_geometry(&GeometryInputs::default(), &AtomicBool::new(false)).unwrap();
        assert!(!r.summary().contains("does not reach flange contact"));
    }

    /// The wheels placed by their back faces: 1360 mm with origins 70 mm from the back faces
    /// is EN 15302's placement (the same conicity); a tighter wheelset, 1357 mm, another one;
    /// values outside a standard-gauge wheelset are refused, named.
    #[test]
    fn wheels_placed_back_to_back() {
        let at3 = |back_to_back| {
            let i = GeometryInputs {
                back_to_back,
                ..GeometryInputs::default()
            };
            let r = contact_geometry(&i, &AtomicBool::new(false)).unwrap();
            let p = r
                .summary_conicity
                .iter()
                .find(|p| (p.amplitude_m - 3e-3).abs() < 1e-12)
                .unwrap()
                .tan_gamma_e;
            (p, r.summary())
        };
        let (origins, _) = at3(None);
        let (nominal, summary) = at3(Some(NOMINAL_BACK_TO_BACK_M));
        assert!((nominal - origins).abs() < 1e-9, "{nominal} vs {origins}");
        assert!(
            summary.contains("wheels 1360.00 mm back to back"),
            "{summary}"
        );
        let (tight, _) = at3(Some((1.357, 0.070)));
        assert!((tight - origins).abs() > 0.01, "{tight} vs {origins}");
        for (b, o, option) in [
            (1.2, 0.07, "--back-to-back = 1200"),
            (1.36, 0.3, "--back-face-offset = 300"),
            (f64::NAN, 0.07, "--back-to-back = NaN"),
        ] {
            let i = GeometryInputs {
                back_to_back: Some((b, o)),
                ..GeometryInputs::default()
            };
            let e = check_options(&i).unwrap_err().to_string();
            assert!(e.contains(option), "{e}");
        }
    }

    /// A measured wheel profile with its outer rim face (steeper than its flange, on the field
    /// side) gives wheel A's geometry: the flange is sought on the flange side only (it was
    /// refused, "are the wheel and rail profiles swapped?"); a mirrored wheel is named as one.
    #[test]
    fn a_rim_face_is_no_flange_and_a_mirrored_wheel_is_named() {
        let dir = tempfile::tempdir().unwrap();
        let with_rim = dir.path().join("rim.dat");
        std::fs::write(&with_rim, format!("{WHEEL_A}\n70.1 12.0\n70.2 20.0\n")).unwrap();
        let run = |wheel: &std::path::Path| {
            let w = ProfileSource::File(wheel.to_path_buf());
            let i = GeometryInputs {
                wheel_left: w.clone(),
                wheel_right: w,
                ..GeometryInputs::default()
            };
            contact_geometry(&i, &AtomicBool::new(false))
        };
        let at3 = |r: &GeometryResults| {
            r.summary_conicity
                .iter()
                .find(|p| (p.amplitude_m - 3e-3).abs() < 1e-12)
                .unwrap()
                .tan_gamma_e
        };
        let rim = run(&with_rim).unwrap();
        let a = contact_geometry(&GeometryInputs::default(), &AtomicBool::new(false)).unwrap();
        assert!(
            (at3(&rim) - at3(&a)).abs() < 1e-9,
            "{} vs {}",
            at3(&rim),
            at3(&a)
        );
        let mirrored = dir.path().join("mirrored.dat");
        let mut points: Vec<String> = WHEEL_A
            .lines()
            .filter_map(|l| {
                let mut it = l.split_whitespace().map(|v| v.parse::<f64>());
                match (it.next(), it.next()) {
                    (Some(Ok(x)), Some(Ok(z))) => Some(format!("{} {z}", -x)),
                    _ => None,
                }
            })
            .collect();
        points.reverse();
        std::fs::write(&mirrored, points.join("\n")).unwrap();
        let e = run(&mirrored).unwrap_err().to_string();
        assert!(e.contains("is the wheel profile mirrored?"), "{e}");
    }

    #[test]
    fn inclination_parsing() {
        assert_eq!(parse_inclination("1:40").unwrap(), 0.025);
        assert_eq!(parse_inclination("1/20").unwrap(), 0.05);
        assert_eq!(parse_inclination("0").unwrap(), 0.0);
        assert_eq!(parse_inclination(" 0.025 ").unwrap(), 0.025);
        assert!(parse_inclination("1:0").is_err());
        assert!(parse_inclination("steep").is_err());
        assert!(parse_inclination("1:2").is_err());
    }

    /// Rail A already stands at 1:20: an inclination added to it is refused (1:40 on it gave
    /// tan gamma_e 0.013 at 3 mm, exit status 0), from its file as well as built in.
    #[test]
    fn an_inclination_on_rail_a_is_refused() {
        let from_file = tempfile::NamedTempFile::new().unwrap();
        std::fs::write(from_file.path(), RAIL_A).unwrap();
        for rail in [
            GeometryInputs::default().rail_left,
            ProfileSource::File(from_file.path().to_path_buf()),
        ] {
            let i = GeometryInputs {
                inclination: 0.025,
                rail_left: rail.clone(),
                rail_right: rail,
                ..GeometryInputs::default()
            };
            let e = contact_geometry(&i, &AtomicBool::new(false))
                .unwrap_err()
                .to_string();
            assert!(
                e.starts_with("invalid option --inclination = 0.025")
                    && e.contains("already inclined at 1:20"),
                "{e}"
            );
        }
    }

    #[test]
    fn built_in_profiles_parse() {
        let i = GeometryInputs::default();
        assert!(i.wheel_left.load().unwrap().len() > 100);
        assert!(i.rail_left.load().unwrap().len() > 100);
    }

    #[test]
    fn bad_step_is_an_option_error() {
        let i = GeometryInputs {
            step_m: 0.0,
            ..GeometryInputs::default()
        };
        let e = contact_geometry(&i, &AtomicBool::new(false)).unwrap_err();
        assert!(e.to_string().contains("--step"), "{e}");
        // rails inclined the wrong way lose their gauge point: the option is named
        let i = GeometryInputs {
            inclination: -0.025,
            ..GeometryInputs::default()
        };
        let e = contact_geometry(&i, &AtomicBool::new(false)).unwrap_err();
        assert!(
            e.to_string()
                .starts_with("invalid option --inclination = -0.025"),
            "{e}"
        );
        // a value is named as given in mm, without the round-off of its trip through metres
        let i = GeometryInputs {
            gauge_m: 1400.0 * 1e-3,
            ..GeometryInputs::default()
        };
        let e = check_options(&i).unwrap_err().to_string();
        assert!(e.contains("--gauge = 1400:"), "{e}");
        let i = GeometryInputs {
            gauge_m: 1480.0000000001 * 1e-3,
            ..GeometryInputs::default()
        };
        let e = check_options(&i).unwrap_err().to_string();
        assert!(e.contains("--gauge = 1480.0000000001:"), "{e}");
    }
}
