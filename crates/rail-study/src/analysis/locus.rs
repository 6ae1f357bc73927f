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
    LinearDamper,
};
use fmu_bogie2dof::Params;
use fmu_damper::characterise::equivalent_stiffness_damping;
use fmu_damper::semi_active::SemiActiveParams;

use super::locus_figures::{speeds_line, LocusFigures, LocusSpeed};
use super::{AnalysisError, Artefacts, Table};

/// Seed R5: linear critical speed with the passive damper [km/h].
pub const SEED_R5_KMH: f64 = 270.0;
/// Seed R6: imaginary part of the hunting eigenvalue at onset [rad/s].
pub const SEED_R6_IM_RADPS: f64 = 21.0;
/// Seed R6: hunting frequency at onset \[Hz\].
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
    /// The hydraulic semi-active damper at a fixed opening, linearised at one stroke and
    /// frequency: a Kelvin-Voigt element with its first-harmonic stiffness and damping.
    Linearised(LinearisedDamper),
    /// No yaw dampers.
    None,
}

/// The semi-active damper model (fmu-damper's default parameters, the R1-R2 calibration) with
/// its valve fixed at `opening`, driven by `x = X sin(2 pi f t)` to a periodic steady state:
/// `k = Re(F1/X1)`, `c = Im(F1/X1) / w` (equivalent linearisation by the first harmonic, valid
/// at that stroke and frequency only: the hydraulic damper is strongly non-linear).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinearisedDamper {
    /// Valve opening, 0 (closed) to 1.
    pub opening: f64,
    /// Stroke amplitude X \[m\].
    pub stroke_m: f64,
    /// Stroke frequency f \[Hz\].
    pub freq_hz: f64,
    /// Equivalent stiffness [N/m].
    pub k_n_per_m: f64,
    /// Equivalent damping [N s/m].
    pub c_ns_per_m: f64,
}

/// Largest stroke amplitude a linearisation is asked for \[m\]: a yaw damper's stroke is a few
/// centimetres at most.
pub const MAX_LINEARISATION_STROKE_M: f64 = 0.05;
/// Frequency of a linearisation when none is given \[Hz\]: the hunting frequency of the seed's
/// bogie (R6: 3-4 Hz) and of the coach at its critical speed (4.0 Hz).
pub const DEFAULT_LINEARISATION_FREQ_HZ: f64 = 4.0;

/// `x` to four significant digits, in its shortest form (5 N s/m is 0.005 kN s/m, not 0.0).
fn sig(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return master::show::num(x).to_string();
    }
    let digits = 3 - x.abs().log10().floor() as i32;
    let scale = 10f64.powi(digits);
    master::show::num((x * scale).round() / scale).to_string()
}

impl LinearisedDamper {
    /// Measures the damper at `opening` (0..1), stroke amplitude `stroke_m` (1 um <= X <= 5 cm)
    /// and `freq_hz` (0.1 <= f <= 50 Hz: hunting lies at a few Hz; far below, a period of the
    /// periodic steady state would take hours to compute, and the damper's first harmonic
    /// vanishes to rounding).
    pub fn measure(opening: f64, stroke_m: f64, freq_hz: f64) -> Result<Self, String> {
        let num = master::show::num;
        if !(opening.is_finite() && (0.0..=1.0).contains(&opening)) {
            return Err(format!(
                "opening {}: must be within 0 (closed) and 1",
                num(opening)
            ));
        }
        if !(stroke_m.is_finite() && (1e-6..=MAX_LINEARISATION_STROKE_M).contains(&stroke_m)) {
            return Err(format!(
                "stroke {} m: must be at least 1e-6 m and at most {MAX_LINEARISATION_STROKE_M} m \
                 (an amplitude in metres, e.g. 3e-3)",
                num(stroke_m)
            ));
        }
        if !(freq_hz.is_finite() && (0.1..=50.0).contains(&freq_hz)) {
            return Err(format!(
                "frequency {} Hz: must be at least 0.1 and at most 50 Hz",
                num(freq_hz)
            ));
        }
        let (k, c) =
            equivalent_stiffness_damping(&SemiActiveParams::default(), opening, freq_hz, stroke_m)
                .map_err(|e| format!("the damper model cannot be linearised there: {e}"))?;
        if !(k.is_finite() && c.is_finite() && k >= 0.0 && c >= 0.0) {
            return Err(format!(
                "the damper's first harmonic gives k = {} N/m, c = {} N s/m: not a \
                 Kelvin-Voigt element",
                master::show::num(k),
                master::show::num(c)
            ));
        }
        Ok(Self {
            opening,
            stroke_m,
            freq_hz,
            k_n_per_m: k,
            c_ns_per_m: c,
        })
    }
}

/// Parses `passive`, `none`, `viscous:C`, `maxwell:K:C`, `kelvin:K:C` (SI: N/m, N s/m;
/// `120e3` or `120k` are both accepted) and `semi-active:OPENING:STROKE[:FREQ]` (valve opening
/// 0..1, stroke amplitude in m, frequency in Hz; without it 4 Hz, the start of
/// [`linearise_at_crossing`], which `master root-locus` then applies, see [`parse_damper_arg`]),
/// which measures the damper model there ([`LinearisedDamper::measure`]).
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
            _ => Err(format!(
                "'{}' is not a non-negative number",
                master::show::text(t)
            )),
        }
    };
    let parts: Vec<&str> = s.trim().split(':').collect();
    let usage = "use passive, none, viscous:C, maxwell:K:C, kelvin:K:C (N/m, N s/m) or \
                 semi-active:OPENING:STROKE[:FREQ] (0..1, m, Hz)";
    let plain = |t: &str| -> Result<f64, String> {
        t.trim()
            .parse::<f64>()
            .map_err(|_| format!("'{}' is not a number", master::show::text(t.trim())))
    };
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
        ["semi-active", opening, stroke, freq @ ..] if freq.len() <= 1 => {
            let freq = match freq.first() {
                Some(f) => plain(f)?,
                None => DEFAULT_LINEARISATION_FREQ_HZ,
            };
            Ok(DamperSpec::Linearised(LinearisedDamper::measure(
                plain(opening)?,
                plain(stroke)?,
                freq,
            )?))
        }
        _ => Err(format!("'{}': {usage}", master::show::text(s))),
    }
}

/// A `--damper` option: the spec, and whether a `semi-active:OPENING:STROKE` damper (no FREQ)
/// is to be linearised at the frequency of the mode that crosses ([`linearise_at_crossing`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DamperArg {
    pub spec: DamperSpec,
    pub at_crossing: bool,
}

/// [`parse_damper`], noting a `semi-active` damper given without its frequency.
pub fn parse_damper_arg(s: &str) -> Result<DamperArg, String> {
    let spec = parse_damper(s)?;
    let at_crossing = matches!(spec, DamperSpec::Linearised(_)) && s.trim().split(':').count() == 3;
    Ok(DamperArg { spec, at_crossing })
}

/// Rounds of [`linearise_at_crossing`] at most (the crossing frequency settles to 0.01 Hz
/// within three on the coach and the bogie).
pub const MAX_LINEARISATION_ROUNDS: usize = 8;

/// What the eigen-analysis says of one linearised damper, for [`linearise_at_crossing`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Onset {
    /// A mode crosses in the search range; its frequency \[Hz\].
    Crosses(f64),
    /// Nothing crosses; the frequency of the hunting mode at the top of the search range
    /// \[Hz\], if there is one.
    Stable(Option<f64>),
}

/// What [`linearise_at_crossing`] found.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AtCrossing {
    /// The damper linearised at the frequency it settled at.
    pub damper: LinearisedDamper,
    /// Eigen-analyses made.
    pub rounds: usize,
    /// Whether a mode crosses with it (else it is linearised at the hunting mode's frequency
    /// at the top of the search range; where it started when there is none, or when that
    /// frequency hops between modes without settling).
    pub crossed: bool,
    /// Whether the frequency settled (false: stable at every frequency tried, the damper
    /// where it started).
    pub settled: bool,
}

/// The damper `d` linearised again at the frequency of the mode that crosses with it, until
/// that frequency moves by less than 0.01 Hz: a first-harmonic linearisation holds at one
/// frequency, and the one that matters is the crossing mode's. When nothing crosses, at the
/// hunting mode's frequency at the top of the search range: a damper that is stiff at 4 Hz
/// may let the coach cross at the 5.7 Hz it hunts at. `onset` gives the eigen-analysis of a
/// damper. An error when the frequency has not settled after [`MAX_LINEARISATION_ROUNDS`].
pub fn linearise_at_crossing(
    mut d: LinearisedDamper,
    mut onset: impl FnMut(DamperSpec) -> Result<Onset, String>,
) -> Result<AtCrossing, String> {
    let first = d;
    let mut ever_crossed = false;
    for rounds in 1..=MAX_LINEARISATION_ROUNDS {
        let (target_hz, crossed) = match onset(DamperSpec::Linearised(d))? {
            Onset::Crosses(f) => (Some(f), true),
            Onset::Stable(f) => (f, false),
        };
        ever_crossed |= crossed;
        let settled = |d: LinearisedDamper| {
            Ok(AtCrossing {
                damper: d,
                rounds,
                crossed,
                settled: true,
            })
        };
        // the linearisation's own range (0.1-50 Hz)
        let Some(f) = target_hz.map(|f| f.clamp(0.1, 50.0)) else {
            return settled(d);
        };
        if (f - d.freq_hz).abs() < 0.01 {
            return settled(d);
        }
        d = LinearisedDamper::measure(d.opening, d.stroke_m, f)?;
    }
    if !ever_crossed {
        // stable at every frequency tried, the least-damped mode hopping between modes (a
        // very stiff damper): stable, at the frequency it started from
        return Ok(AtCrossing {
            damper: first,
            rounds: MAX_LINEARISATION_ROUNDS,
            crossed: false,
            settled: false,
        });
    }
    Err(format!(
        "the crossing mode's frequency did not settle within {MAX_LINEARISATION_ROUNDS} \
         linearisations (last {} Hz): give the frequency, semi-active:OPENING:STROKE:FREQ",
        master::show::num((d.freq_hz * 100.0).round() / 100.0)
    ))
}

/// [`Onset`] of the linear 2-dof bogie with `spec` (the hunting mode at the top of
/// [`CRITICAL_SEARCH_MPS`] when nothing crosses).
pub fn bogie_onset(params: &Params, spec: DamperSpec) -> Result<Onset, String> {
    let (lo, hi) = CRITICAL_SEARCH_MPS;
    let rep = spec.representation();
    match critical_speed(params, &rep, lo, hi) {
        Ok(c) => Ok(Onset::Crosses(c.hunting.freq_hz)),
        Err(EigenError::NoCrossing { .. }) => {
            let top = analyse(params, hi, &rep).map_err(|e| e.to_string())?;
            Ok(Onset::Stable(top.hunting.map(|h| h.freq_hz)))
        }
        Err(e) => Err(e.to_string()),
    }
}

impl DamperSpec {
    pub fn representation(&self) -> DamperRepresentation {
        self.linear()
            .map_or_else(passive_damper, DamperRepresentation::Linear)
    }

    /// The linear law of the spec, the one both models' eigen-analyses take; `None` for
    /// [`DamperSpec::Passive`], whose representation each model keeps for itself.
    pub fn linear(&self) -> Option<LinearDamper> {
        Some(match *self {
            DamperSpec::Passive => return None,
            DamperSpec::Viscous(c) => LinearDamper::Viscous { c },
            DamperSpec::Maxwell(k, c) => LinearDamper::Maxwell { k, c },
            DamperSpec::KelvinVoigt(k, c) => LinearDamper::KelvinVoigt { k, c },
            DamperSpec::Linearised(l) => LinearDamper::KelvinVoigt {
                k: l.k_n_per_m,
                c: l.c_ns_per_m,
            },
            DamperSpec::None => LinearDamper::None,
        })
    }

    pub fn describe(&self) -> String {
        match *self {
            DamperSpec::Passive => format!(
                "passive (Maxwell {:.1} MN/m in series with {:.0} kN s/m per damper, fmu-bogie2dof calibration of the 30 % damper)",
                PASSIVE_MAXWELL_K_N_PER_M * 1e-6,
                PASSIVE_MAXWELL_C_NS_PER_M * 1e-3
            ),
            DamperSpec::Viscous(c) => format!("viscous {} kN s/m per damper", sig(c * 1e-3)),
            DamperSpec::Maxwell(k, c) => format!(
                "Maxwell {} MN/m in series with {} kN s/m per damper",
                sig(k * 1e-6),
                sig(c * 1e-3)
            ),
            DamperSpec::KelvinVoigt(k, c) => format!(
                "Kelvin-Voigt {} MN/m parallel to {} kN s/m per damper",
                sig(k * 1e-6),
                sig(c * 1e-3)
            ),
            DamperSpec::Linearised(l) => format!(
                "semi-active damper at {} % opening linearised at +-{} mm, {} Hz \
                 (first harmonic of the fmu-damper model): Kelvin-Voigt {} MN/m parallel \
                 to {} kN s/m per damper",
                sig(l.opening * 100.0),
                sig(l.stroke_m * 1e3),
                sig(l.freq_hz),
                sig(l.k_n_per_m * 1e-6),
                sig(l.c_ns_per_m * 1e-3)
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
        value: master::show::num(v).to_string(),
        reason: reason.to_string(),
    };
    let max = CRITICAL_SEARCH_MPS.1 * 3.6;
    // both linear models divide the creepages by V; the coach accepts 1 m/s and more
    if !(from.is_finite() && from >= 3.6) {
        return Err(bad("--from", from, "must be at least 3.6 km/h (1 m/s)"));
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
    if n < 1.0 {
        return Err(bad(
            "--step",
            step,
            "must leave at least two speeds between --from and --to (the figures draw lines)",
        ));
    }
    Ok((0..=n as usize).map(|i| from + i as f64 * step).collect())
}

/// The `critical` and `no_crossing` fields of a locus' key numbers: the crossing's `fields`, or
/// null with the reason nothing crosses.
pub(super) fn critical_json<C>(
    critical: &Result<C, String>,
    fields: impl FnOnce(&C) -> serde_json::Value,
) -> (serde_json::Value, serde_json::Value) {
    match critical {
        Ok(c) => (fields(c), serde_json::Value::Null),
        Err(why) => (serde_json::Value::Null, serde_json::json!(why)),
    }
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
    AnalysisError::LinearModel(format!("2-dof bogie: {e}"))
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

impl LocusResults {
    /// The eigenvalues per speed and the hunting mode, as the shared figures take them.
    fn figures(&self) -> LocusFigures<'_> {
        LocusFigures {
            model: "bogie",
            damper: match self.damper {
                DamperSpec::Passive => "passive damper".to_string(),
                d => d.describe(),
            },
            mode: "hunting mode",
            mode_column: "hunting mode",
            frequency_title: "Hunting frequency vs speed (linear bogie)".into(),
            speeds: LocusSpeed::over(
                &self.speeds_kmh,
                self.results
                    .iter()
                    .map(|r| (r.eigenvalues.as_slice(), r.hunting.map(|h| (h.re, h.im)))),
            ),
        }
    }

    pub fn add_artefacts(&self, a: &mut Artefacts) -> Result<(), AnalysisError> {
        let figures = self.figures();
        figures.add_eigenvalue_table(a)?;
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
        figures.add_figures(a)
    }

    /// Critical speed and hunting frequency at onset next to the seed's.
    /// The key numbers for `root-locus.json`: the linear critical speed (null, with the
    /// reason, when nothing crosses), the hunting mode's frequency at onset, the set-up.
    pub fn results_json(&self) -> serde_json::Value {
        let (critical, reason) = critical_json(&self.critical, |c| {
            serde_json::json!({
                "speed_kmh": c.speed_kmh,
                "frequency_hz": c.hunting.freq_hz,
                "im_rad_per_s": c.hunting.im,
                "mode": "hunting",
            })
        });
        serde_json::json!({
            "model": "bogie2dof",
            "damper": self.damper.describe(),
            "conicity": self.conicity,
            "critical": critical,
            "no_crossing": reason,
        })
    }

    pub fn summary(&self) -> String {
        let mut s = format!(
            "linear bogie (calibrated fmu-bogie2dof defaults, conicity {:.3}), damper: {}\n",
            self.conicity,
            self.damper.describe()
        );
        s.push_str(&speeds_line(&self.speeds_kmh));
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

    /// A `semi-active` damper without FREQ is marked for the crossing frequency; the iteration
    /// stops once the frequency settles, keeps the damper when nothing crosses, and refuses a
    /// frequency that does not settle.
    #[test]
    fn linearisation_at_the_crossing_frequency() {
        assert!(parse_damper_arg("semi-active:0:5e-3").unwrap().at_crossing);
        assert!(
            !parse_damper_arg("semi-active:0:5e-3:4")
                .unwrap()
                .at_crossing
        );
        assert!(!parse_damper_arg("passive").unwrap().at_crossing);
        let d = LinearisedDamper::measure(0.0, 5e-3, 4.0).unwrap();
        let settled = linearise_at_crossing(d, |_| Ok(Onset::Crosses(5.0))).unwrap();
        assert!(settled.crossed && settled.rounds == 2);
        assert_eq!(settled.damper.freq_hz, 5.0);
        let none = linearise_at_crossing(d, |_| Ok(Onset::Stable(None))).unwrap();
        assert!(!none.crossed && none.rounds == 1 && none.damper == d);
        // stable at 4 Hz, crossing once linearised at the hunting frequency
        let found = linearise_at_crossing(d, |spec| match spec {
            DamperSpec::Linearised(l) if l.freq_hz < 5.0 => Ok(Onset::Stable(Some(5.7))),
            _ => Ok(Onset::Crosses(5.65)),
        })
        .unwrap();
        assert!(found.crossed && found.rounds == 3 && found.damper.freq_hz == 5.65);
        // stable at every frequency, the hunting candidate hopping: stable where it started
        let mut hop = false;
        let stable = linearise_at_crossing(d, |_| {
            hop = !hop;
            Ok(Onset::Stable(Some(if hop { 19.0 } else { 7.0 })))
        })
        .unwrap();
        assert!(!stable.crossed && !stable.settled && stable.damper == d);
        let mut flip = false;
        let e = linearise_at_crossing(d, |_| {
            flip = !flip;
            Ok(Onset::Crosses(if flip { 5.0 } else { 6.0 }))
        })
        .unwrap_err();
        assert!(e.contains("did not settle"), "{e}");
        let e = linearise_at_crossing(d, |_| Err("no eigenvalues".into())).unwrap_err();
        assert_eq!(e, "no eigenvalues");
    }

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

    /// The semi-active damper linearised by its first harmonic: the frequency defaults to 4 Hz,
    /// a closed valve is stiffer and damps more than the 30 % opening at the same stroke, and
    /// the 30 % damper at +-1 mm, 4 Hz gives the values its Maxwell representation was fitted
    /// to.
    #[test]
    fn semi_active_spec_is_the_damper_model_linearised() {
        let Ok(DamperSpec::Linearised(open)) = parse_damper("semi-active:0.3:1e-3") else {
            panic!("semi-active:0.3:1e-3 not parsed");
        };
        assert_eq!(
            (open.opening, open.stroke_m, open.freq_hz),
            (0.3, 1e-3, DEFAULT_LINEARISATION_FREQ_HZ)
        );
        let Ok(DamperSpec::Linearised(closed)) = parse_damper("semi-active:0:1e-3:4") else {
            panic!("semi-active:0:1e-3:4 not parsed");
        };
        assert!(
            closed.k_n_per_m > 5.0 * open.k_n_per_m,
            "{closed:?} {open:?}"
        );
        assert!(
            closed.c_ns_per_m > 2.0 * open.c_ns_per_m,
            "{closed:?} {open:?}"
        );
        // the passive damper's characterisation in fmu-bogie2dof's calibration (1 mm, 4 Hz:
        // 386 kN/m, 95.6 kNs/m), which its Maxwell representation was fitted to
        assert!((open.k_n_per_m / 386e3 - 1.0).abs() < 0.01, "{open:?}");
        assert!((open.c_ns_per_m / 95.6e3 - 1.0).abs() < 0.01, "{open:?}");
        match DamperSpec::Linearised(closed).representation() {
            DamperRepresentation::Linear(LinearDamper::KelvinVoigt { k, c }) => {
                assert_eq!((k, c), (closed.k_n_per_m, closed.c_ns_per_m))
            }
            other => panic!("{other:?}"),
        }
        for bad in [
            "semi-active:1.5:1e-3",
            "semi-active:-0.1:1e-3",
            "semi-active:0:0",
            "semi-active:0:0.2",
            "semi-active:0:nan",
            "semi-active:0:1e-3:0",
            "semi-active:0:1e-3:inf",
            "semi-active:0:1e-3:1e9",
            "semi-active:x:1e-3",
            "semi-active:0",
            "semi-active:0:1e-3:4:5",
        ] {
            assert!(parse_damper(bad).is_err(), "{bad} accepted");
        }
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
