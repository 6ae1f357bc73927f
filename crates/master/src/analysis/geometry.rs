//! Wheel/rail contact geometry from profiles (issue 8 item 4), through crate `wheel-rail`:
//! the contact table in the bogie's CSV format, a detailed table, Δr(y), tanγ(y) and the
//! EN 15302 equivalent conicity over amplitude.
//!
//! Defaults: EN 15302 case E1 (wheel A and rail A both sides, 920 mm wheels, gauge
//! 1435.16 mm), with the benchmark profiles built in from `crates/wheel-rail/data/`. Rail A
//! already contains its inclination, so the default additional inclination is 0; a rail given
//! upright needs `1:40` (or `1:20`).

use std::path::PathBuf;

use wheel_rail::{
    compute_table, equivalent_conicity, harmonic_linearisation, ContactSetup, ContactTable, Profile,
};

use super::{AnalysisError, Artefacts, Table};
use crate::plot::Chart;

/// EN 15302 wheel profile A (built in).
pub const WHEEL_A: &str = include_str!("../../../wheel-rail/data/RUIC519A.dat");
/// EN 15302 rail profile A, 60E1 head with its inclination (built in).
pub const RAIL_A: &str = include_str!("../../../wheel-rail/data/SUIC519A.dat");
/// Gauge of case E1 [mm].
pub const E1_GAUGE_MM: f64 = 1435.16;
/// Nominal rolling radius of case E1 [mm] (920 mm wheels).
pub const E1_RADIUS_MM: f64 = 460.0;
/// EN 15302 Annex E equivalent conicity of case E1 at 1, 3, 5, 7 mm (as quoted by the
/// wheel-rail crate docs).
pub const E1_REFERENCE_CONICITY: [(f64, f64); 4] =
    [(1.0, 0.125), (3.0, 0.188), (5.0, 0.254), (7.0, 0.505)];
/// Amplitudes printed in the summary [mm].
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
    let bad = || format!("'{s}' is not an inclination (use 1:40, 1:20, 0 or a tangent like 0.025)");
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
    /// Conicity curve amplitudes: 1 to 7 mm in this step [m].
    pub conicity_step_m: f64,
}

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
        }
    }
}

/// Conicity at one amplitude, or why it could not be computed.
#[derive(Debug, Clone, PartialEq)]
pub struct ConicityPoint {
    pub amplitude_m: f64,
    /// Reference method (EN 15302 Annex B): (tanγe, wavelength [m]).
    pub reference: Result<(f64, f64), String>,
    /// Harmonic linearisation tanγ.
    pub harmonic: Option<f64>,
}

/// Result of a contact-geometry run.
#[derive(Debug, Clone, PartialEq)]
pub struct GeometryResults {
    pub inputs: GeometryInputs,
    pub table: ContactTable,
    /// 1 to 7 mm.
    pub conicity: Vec<ConicityPoint>,
    /// At [`SUMMARY_AMPLITUDES_MM`].
    pub summary_conicity: Vec<ConicityPoint>,
}

fn conicity_at(table: &ContactTable, a: f64) -> ConicityPoint {
    ConicityPoint {
        amplitude_m: a,
        reference: equivalent_conicity(table, a)
            .map(|c| (c.tan_gamma_e, c.wavelength_m))
            .map_err(|e| e.to_string()),
        harmonic: harmonic_linearisation(table, a).ok(),
    }
}

/// Reads the profiles, computes the table and the conicity curve. Profile errors name the
/// file and line; nothing is written here.
pub fn contact_geometry(inputs: &GeometryInputs) -> Result<GeometryResults, AnalysisError> {
    let bad = |option: &'static str, v: f64, reason: &str| AnalysisError::Option {
        option,
        value: v.to_string(),
        reason: reason.to_string(),
    };
    if !(inputs.step_m.is_finite() && inputs.step_m > 0.0) {
        return Err(bad("--step", inputs.step_m * 1e3, "must be > 0 mm"));
    }
    if !(inputs.y_max_m.is_finite() && inputs.y_max_m >= 3.0 * inputs.step_m) {
        return Err(bad(
            "--y-max",
            inputs.y_max_m * 1e3,
            "must be at least 3 steps",
        ));
    }
    if !(inputs.conicity_step_m.is_finite() && inputs.conicity_step_m > 0.0) {
        return Err(bad(
            "conicity step",
            inputs.conicity_step_m * 1e3,
            "must be > 0 mm",
        ));
    }
    let mut setup = ContactSetup::symmetric(
        inputs.wheel_left.load()?,
        inputs.rail_left.load()?,
        inputs.radius_left_m,
        inputs.gauge_m,
    );
    setup.wheel_right = inputs.wheel_right.load()?;
    setup.rail_right = inputs.rail_right.load()?;
    setup.nominal_radius_right_m = inputs.radius_right_m;
    setup.rail_inclination = inputs.inclination;
    setup.validate()?;
    let table = compute_table(&setup, -inputs.y_max_m, inputs.y_max_m, inputs.step_m)?;
    let n = ((6e-3 / inputs.conicity_step_m).round() as usize).max(1);
    let conicity: Vec<ConicityPoint> = (0..=n)
        .map(|i| conicity_at(&table, 1e-3 + 6e-3 * i as f64 / n as f64))
        .collect();
    if let Some(Err(why)) = conicity
        .iter()
        .all(|c| c.reference.is_err())
        .then(|| conicity.first().map(|c| c.reference.clone()))
        .flatten()
    {
        return Err(AnalysisError::Geometry(format!(
            "no amplitude from 1 to 7 mm gives a kinematic oscillation (at 1 mm: {why})"
        )));
    }
    let summary_conicity = SUMMARY_AMPLITUDES_MM
        .iter()
        .map(|a| conicity_at(&table, a * 1e-3))
        .collect();
    Ok(GeometryResults {
        inputs: inputs.clone(),
        table,
        conicity,
        summary_conicity,
    })
}

impl GeometryResults {
    /// y of the first reachable row (from the centre outwards) with tanγ > 1 on the right
    /// (flange contact) [m].
    pub fn flange_contact_y_m(&self) -> Option<f64> {
        self.table
            .reachable_rows()
            .filter(|r| r.y_m > 0.0 && r.right.tan_gamma > 1.0)
            .map(|r| r.y_m)
            .reduce(f64::min)
    }

    pub fn add_artefacts(&self, a: &mut Artefacts) -> Result<(), AnalysisError> {
        a.add_text("wheel_rail_table.csv", self.table.to_bogie_csv());
        let mut d = Table::new(&[
            "y [mm]",
            "delta r = r_right - r_left [mm]",
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
        ]);
        for r in &self.table.rows {
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
                if r.beyond_flange_limit { 1.0 } else { 0.0 },
            ]);
        }
        a.add_table("contact_detail.csv", &d)?;
        let mut c = Table::new(&[
            "amplitude [mm]",
            "equivalent conicity (EN 15302 reference method)",
            "wavelength [m]",
            "harmonic linearisation tan gamma",
        ]);
        for p in &self.conicity {
            let (tg, wl) = p.reference.clone().unwrap_or((f64::NAN, f64::NAN));
            c.rows.push(vec![
                p.amplitude_m * 1e3,
                tg,
                wl,
                p.harmonic.unwrap_or(f64::NAN),
            ]);
        }
        a.add_table("conicity.csv", &c)?;

        let reach: Vec<_> = self.table.reachable_rows().collect();
        let range = format!(
            "reachable y {:.2} to {:.2} mm",
            self.table.y_reachable_min_m * 1e3,
            self.table.y_reachable_max_m * 1e3
        );
        let dr = Chart::new(
            &format!("Rolling radius difference ({range})"),
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
        let pts = |f: fn(&ConicityPoint) -> Option<f64>| -> Vec<(f64, f64)> {
            self.conicity
                .iter()
                .filter_map(|p| f(p).map(|v| (p.amplitude_m * 1e3, v)))
                .collect()
        };
        let con = Chart::new(
            "Equivalent conicity (EN 15302)",
            "amplitude [mm]",
            "equivalent conicity tan gamma_e [-]",
        )
        .with_series(
            "reference method (Annex B)",
            pts(|p| p.reference.as_ref().ok().map(|r| r.0)),
        )
        .with_series("harmonic linearisation", pts(|p| p.harmonic));
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
        s.push_str("equivalent conicity (EN 15302 reference method):\n");
        for p in &self.summary_conicity {
            let a_mm = p.amplitude_m * 1e3;
            match &p.reference {
                Ok((tg, wl)) => {
                    s.push_str(&format!(
                        "  tan gamma_e at {a_mm:.0} mm: {tg:.4} (wavelength {wl:.1} m)"
                    ));
                    if is_e1 {
                        if let Some((_, r)) =
                            E1_REFERENCE_CONICITY.iter().find(|(aa, _)| *aa == a_mm)
                        {
                            s.push_str(&format!("; EN 15302 E1 reference {r:.3}"));
                        }
                    }
                }
                Err(e) => s.push_str(&format!("  tan gamma_e at {a_mm:.0} mm: n/a ({e})")),
            }
            s.push('\n');
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
        let e = contact_geometry(&i).unwrap_err();
        assert!(e.to_string().contains("--step"), "{e}");
    }
}
