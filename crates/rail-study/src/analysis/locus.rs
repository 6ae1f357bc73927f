//! Root locus of the linear 2-dof bogie (seed 5.3.1, (5.28)-(5.33)) over speed, through
//! `fmu_bogie2dof::eigen`: every eigenvalue per speed, the hunting mode (least damped
//! oscillatory eigenvalue), the linear critical speed by bisection and the hunting frequency
//! at onset (R5, R6).
//!
//! The default damper is the crate's representation of the coupled passive damper
//! ([`fmu_bogie2dof::calibration::passive_damper`]: a Maxwell element fitted to the
//! fmu-damper characterisation at 30 % opening), with the calibrated default
//! [`fmu_bogie2dof::Params`].

use fmu_bogie2dof::calibration::{
    passive_damper, PASSIVE_MAXWELL_C_NS_PER_M, PASSIVE_MAXWELL_K_N_PER_M,
};
use fmu_bogie2dof::eigen::{
    analyse, critical_speed, CriticalSpeed, DamperRepresentation, EigenError, EigenResult,
};
use fmu_bogie2dof::Params;

use super::figures::ColourScatter;
use super::{AnalysisError, Artefacts, Table};
use crate::plot::Chart;

/// Seed R5: linear critical speed with the passive damper [km/h].
pub const SEED_R5_KMH: f64 = 270.0;
/// Seed R6: imaginary part of the hunting eigenvalue at onset [rad/s].
pub const SEED_R6_IM_RADPS: f64 = 21.0;
/// Seed R6: hunting frequency at onset [Hz].
pub const SEED_R6_HZ: (f64, f64) = (3.0, 4.0);
/// Speed range searched for the critical speed [m/s] (the bogie model accepts up to 200).
pub const CRITICAL_SEARCH_MPS: (f64, f64) = (5.0, 199.0);

/// Yaw damper of the linear model (values per damper, SI).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum DamperSpec {
    /// The crate's representation of the coupled passive damper (default).
    Passive,
    /// Pure dashpot c [N s/m].
    Viscous(f64),
    /// Spring k [N/m] in series with dashpot c [N s/m].
    Maxwell(f64, f64),
    /// Spring k [N/m] parallel to dashpot c [N s/m].
    KelvinVoigt(f64, f64),
    /// No yaw dampers.
    None,
}

/// Parses `passive`, `none`, `viscous:C`, `maxwell:K:C`, `kelvin:K:C` (SI: N/m, N s/m;
/// `120e3` or `120k` are both accepted).
pub fn parse_damper(s: &str) -> Result<DamperSpec, String> {
    let num = |t: &str| -> Result<f64, String> {
        let t = t.trim();
        let (body, scale) = match t.strip_suffix(['k', 'K']) {
            Some(b) => (b, 1e3),
            None => match t.strip_suffix('M') {
                Some(b) => (b, 1e6),
                None => (t, 1.0),
            },
        };
        match body.parse::<f64>() {
            Ok(v) if v.is_finite() && v >= 0.0 => Ok(v * scale),
            _ => Err(format!("'{t}' is not a non-negative number")),
        }
    };
    let parts: Vec<&str> = s.trim().split(':').collect();
    let usage = "use passive, none, viscous:C, maxwell:K:C or kelvin:K:C (N/m, N s/m)";
    match parts.as_slice() {
        ["passive"] => Ok(DamperSpec::Passive),
        ["none"] => Ok(DamperSpec::None),
        ["viscous", c] => Ok(DamperSpec::Viscous(num(c)?)),
        ["maxwell", k, c] => {
            let (k, c) = (num(k)?, num(c)?);
            if k > 0.0 && c > 0.0 {
                Ok(DamperSpec::Maxwell(k, c))
            } else {
                Err("maxwell:K:C needs K > 0 and C > 0".into())
            }
        }
        ["kelvin", k, c] => Ok(DamperSpec::KelvinVoigt(num(k)?, num(c)?)),
        _ => Err(format!("'{s}': {usage}")),
    }
}

impl DamperSpec {
    pub fn representation(&self) -> DamperRepresentation {
        match *self {
            DamperSpec::Passive => passive_damper(),
            DamperSpec::Viscous(c0) => DamperRepresentation::Viscous { c0 },
            DamperSpec::Maxwell(k, c) => DamperRepresentation::Maxwell { k, c },
            DamperSpec::KelvinVoigt(k, c) => DamperRepresentation::KelvinVoigt { k, c },
            DamperSpec::None => DamperRepresentation::None,
        }
    }

    pub fn describe(&self) -> String {
        match *self {
            DamperSpec::Passive => format!(
                "passive (Maxwell {:.1} MN/m in series with {:.0} kN s/m per damper, fmu-bogie2dof calibration of the 30 % damper)",
                PASSIVE_MAXWELL_K_N_PER_M * 1e-6,
                PASSIVE_MAXWELL_C_NS_PER_M * 1e-3
            ),
            DamperSpec::Viscous(c) => format!("viscous {:.1} kN s/m per damper", c * 1e-3),
            DamperSpec::Maxwell(k, c) => format!(
                "Maxwell {:.2} MN/m in series with {:.1} kN s/m per damper",
                k * 1e-6,
                c * 1e-3
            ),
            DamperSpec::KelvinVoigt(k, c) => format!(
                "Kelvin-Voigt {:.2} MN/m parallel to {:.1} kN s/m per damper",
                k * 1e-6,
                c * 1e-3
            ),
            DamperSpec::None => "no yaw dampers".into(),
        }
    }
}

/// Speeds `from, from + step, ..., to` [km/h] (the last one included when the step divides
/// the range within 1e-9).
pub fn speed_grid_kmh(from: f64, to: f64, step: f64) -> Result<Vec<f64>, AnalysisError> {
    let bad = |option: &'static str, v: f64, reason: &str| AnalysisError::Option {
        option,
        value: v.to_string(),
        reason: reason.to_string(),
    };
    let max = CRITICAL_SEARCH_MPS.1 * 3.6;
    if !(from.is_finite() && from > 0.0) {
        return Err(bad("--from", from, "must be > 0 km/h"));
    }
    if !(to.is_finite() && to > from && to <= max) {
        return Err(bad(
            "--to",
            to,
            &format!("must be above --from and at most {max:.0} km/h"),
        ));
    }
    if !(step.is_finite() && step > 0.0) {
        return Err(bad("--step", step, "must be > 0 km/h"));
    }
    let n = ((to - from) / step + 1e-9).floor();
    if n > 20_000.0 {
        return Err(bad("--step", step, "gives more than 20 000 speeds"));
    }
    Ok((0..=n as usize).map(|i| from + i as f64 * step).collect())
}

/// Result of a root-locus run.
#[derive(Debug, Clone, PartialEq)]
pub struct LocusResults {
    pub damper: DamperSpec,
    pub conicity: f64,
    pub speeds_kmh: Vec<f64>,
    pub results: Vec<EigenResult>,
    /// Linear critical speed in [`CRITICAL_SEARCH_MPS`], or why there is none.
    pub critical: Result<CriticalSpeed, String>,
}

fn bogie_err(e: EigenError) -> AnalysisError {
    AnalysisError::Bogie(e.to_string())
}

/// Eigenvalues over the speed grid and the linear critical speed. `params` is usually
/// `Params::default()` (calibrated).
pub fn root_locus(
    params: &Params,
    damper: DamperSpec,
    speeds_kmh: &[f64],
) -> Result<LocusResults, AnalysisError> {
    let rep = damper.representation();
    let results = speeds_kmh
        .iter()
        .map(|v| analyse(params, v / 3.6, &rep))
        .collect::<Result<Vec<_>, _>>()
        .map_err(bogie_err)?;
    let critical = match critical_speed(params, &rep, CRITICAL_SEARCH_MPS.0, CRITICAL_SEARCH_MPS.1)
    {
        Ok(c) => Ok(c),
        Err(EigenError::NoCrossing { .. }) => Err(
            if results.first().is_some_and(|r| r.max_re >= 0.0)
                && analyse(params, CRITICAL_SEARCH_MPS.0, &rep)
                    .map(|r| r.max_re >= 0.0)
                    .unwrap_or(false)
            {
                format!(
                    "unstable already at {:.0} km/h",
                    CRITICAL_SEARCH_MPS.0 * 3.6
                )
            } else {
                format!(
                    "stable up to {:.0} km/h (no stability boundary found)",
                    CRITICAL_SEARCH_MPS.1 * 3.6
                )
            },
        ),
        Err(e) => return Err(bogie_err(e)),
    };
    Ok(LocusResults {
        damper,
        conicity: params.conicity,
        speeds_kmh: speeds_kmh.to_vec(),
        results,
        critical,
    })
}

fn freq_hz(im: f64) -> f64 {
    im.abs() / (2.0 * std::f64::consts::PI)
}

fn damping_ratio(re: f64, im: f64) -> f64 {
    let n = re.hypot(im);
    if n > 0.0 {
        -re / n
    } else {
        0.0
    }
}

impl LocusResults {
    /// Hunting-mode points (Re, Im) at the grid speeds.
    fn hunting_points(&self) -> Vec<(f64, f64, f64)> {
        self.speeds_kmh
            .iter()
            .zip(&self.results)
            .filter_map(|(v, r)| r.hunting.map(|h| (h.re, h.im, *v)))
            .collect()
    }

    pub fn add_artefacts(&self, a: &mut Artefacts) -> Result<(), AnalysisError> {
        let mut all = Table::new(&[
            "speed [km/h]",
            "eigenvalue index",
            "real part [1/s]",
            "imaginary part [rad/s]",
            "frequency [Hz]",
            "damping ratio [-]",
            "hunting mode",
        ]);
        for (v, r) in self.speeds_kmh.iter().zip(&self.results) {
            for (i, &(re, im)) in r.eigenvalues.iter().enumerate() {
                let is_hunting = r
                    .hunting
                    .is_some_and(|h| h.re == re && h.im.abs() == im.abs());
                all.rows.push(vec![
                    *v,
                    i as f64,
                    re,
                    im,
                    freq_hz(im),
                    damping_ratio(re, im),
                    if is_hunting { 1.0 } else { 0.0 },
                ]);
            }
        }
        a.add_table("root_locus_eigenvalues.csv", &all)?;
        let mut hunt = Table::new(&[
            "speed [km/h]",
            "real part [1/s]",
            "imaginary part [rad/s]",
            "frequency [Hz]",
            "damping ratio [-]",
            "damper k [N/m]",
            "damper c [N s/m]",
        ]);
        for (v, r) in self.speeds_kmh.iter().zip(&self.results) {
            if let Some(h) = r.hunting {
                hunt.rows.push(vec![
                    *v,
                    h.re,
                    h.im,
                    h.freq_hz,
                    h.damping_ratio,
                    r.damper_k_c.0,
                    r.damper_k_c.1,
                ]);
            }
        }
        a.add_table("root_locus_hunting.csv", &hunt)?;

        // upper half-plane only (conjugates carry no information)
        let upper: Vec<(f64, f64, f64)> = self
            .speeds_kmh
            .iter()
            .zip(&self.results)
            .flat_map(|(v, r)| {
                r.eigenvalues
                    .iter()
                    .filter(|e| e.1 >= 0.0)
                    .map(move |&(re, im)| (re, im, *v))
            })
            .collect();
        let hp = self.hunting_points();
        let title = format!(
            "Root locus of the linear bogie, {} to {} km/h ({})",
            self.speeds_kmh.first().copied().unwrap_or(0.0),
            self.speeds_kmh.last().copied().unwrap_or(0.0),
            match self.damper {
                DamperSpec::Passive => "passive damper".to_string(),
                d => d.describe(),
            }
        );
        let mut full =
            ColourScatter::new(&title, "real part [1/s]", "imaginary part [rad/s]", "km/h");
        full.points = upper.clone();
        full.highlight = Some((
            "hunting mode".into(),
            hp.iter().map(|p| (p.0, p.1)).collect(),
        ));
        full.zero_line_x = true;
        a.add_text("root_locus.svg", full.to_svg()?);
        // zoom on the hunting mode: real parts within a few times its excursion
        if !hp.is_empty() {
            let span = hp.iter().map(|p| p.0.abs()).fold(0.0, f64::max).max(1.0);
            let im_max = hp.iter().map(|p| p.1).fold(0.0, f64::max);
            let mut zoom = full.clone();
            zoom.title = format!("{title}: zoom on the hunting mode");
            zoom.points = upper
                .into_iter()
                .filter(|p| p.0 >= -3.0 * span && p.1 <= 2.0 * im_max)
                .collect();
            a.add_text("root_locus_zoom.svg", zoom.to_svg()?);
        }
        let series = |f: fn(&(f64, f64, f64)) -> f64| -> Vec<(f64, f64)> {
            hp.iter().map(|p| (p.2, f(p))).collect()
        };
        let zeta = Chart::new(
            "Damping ratio of the hunting mode vs speed (linear bogie)",
            "speed [km/h]",
            "damping ratio -Re/|lambda| [-]",
        )
        .with_series("hunting mode", series(|p| damping_ratio(p.0, p.1)))
        .with_limit(0.0, "stability limit");
        a.add_lines("damping_ratio.svg", &zeta)?;
        let freq = Chart::new(
            "Hunting frequency vs speed (linear bogie)",
            "speed [km/h]",
            "frequency [Hz]",
        )
        .with_series("hunting mode", series(|p| freq_hz(p.1)));
        a.add_lines("hunting_frequency.svg", &freq)?;
        Ok(())
    }

    /// Critical speed and hunting frequency at onset next to the seed's.
    pub fn summary(&self) -> String {
        let mut s = format!(
            "linear bogie (calibrated fmu-bogie2dof defaults, conicity {:.3}), damper: {}\n",
            self.conicity,
            self.damper.describe()
        );
        s.push_str(&format!(
            "speeds {} to {} km/h, {} points\n",
            self.speeds_kmh.first().copied().unwrap_or(0.0),
            self.speeds_kmh.last().copied().unwrap_or(0.0),
            self.speeds_kmh.len()
        ));
        match &self.critical {
            Ok(c) => {
                s.push_str(&format!(
                    "linear critical speed: {:.1} km/h (seed R5: {SEED_R5_KMH} km/h with the passive damper)\n",
                    c.speed_kmh
                ));
                s.push_str(&format!(
                    "hunting at onset: Im {:.1} rad/s, frequency {:.2} Hz (seed R6: about {SEED_R6_IM_RADPS} rad/s, {}-{} Hz)\n",
                    c.hunting.im, c.hunting.freq_hz, SEED_R6_HZ.0, SEED_R6_HZ.1
                ));
            }
            Err(why) => s.push_str(&format!("linear critical speed: none, {why}\n")),
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn damper_spec_parsing() {
        assert_eq!(parse_damper("passive").unwrap(), DamperSpec::Passive);
        assert_eq!(parse_damper("none").unwrap(), DamperSpec::None);
        assert_eq!(
            parse_damper("viscous:120k").unwrap(),
            DamperSpec::Viscous(120e3)
        );
        assert_eq!(
            parse_damper("maxwell:16.9M:104e3").unwrap(),
            DamperSpec::Maxwell(16.9e6, 104e3)
        );
        assert_eq!(
            parse_damper("kelvin:1e6:5e4").unwrap(),
            DamperSpec::KelvinVoigt(1e6, 5e4)
        );
        assert!(parse_damper("viscous:-1").is_err());
        assert!(parse_damper("maxwell:0:1").is_err());
        assert!(parse_damper("hydraulic").is_err());
    }

    #[test]
    fn speed_grid() {
        assert_eq!(
            speed_grid_kmh(100.0, 120.0, 10.0).unwrap(),
            vec![100.0, 110.0, 120.0]
        );
        assert_eq!(speed_grid_kmh(100.0, 125.0, 10.0).unwrap().len(), 3);
        assert!(speed_grid_kmh(100.0, 90.0, 10.0).is_err());
        assert!(speed_grid_kmh(100.0, 900.0, 10.0).is_err());
        assert!(speed_grid_kmh(100.0, 200.0, 0.0).is_err());
    }

    #[test]
    fn passive_root_locus_near_r5() {
        let speeds = speed_grid_kmh(200.0, 320.0, 40.0).unwrap();
        let r = root_locus(&Params::default(), DamperSpec::Passive, &speeds).unwrap();
        let c = r.critical.as_ref().unwrap();
        // R5 is what fmu-bogie2dof is calibrated to; allow for recalibration noise
        assert!((250.0..=290.0).contains(&c.speed_kmh), "{}", c.speed_kmh);
        let mut a = Artefacts::default();
        r.add_artefacts(&mut a).unwrap();
        assert!(a.names().contains(&"root_locus.svg"));
        assert!(r.summary().contains("critical speed"));
    }
}
