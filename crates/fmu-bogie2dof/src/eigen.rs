//! Eigen-analysis of the linear model (5.28)-(5.33): state matrix, root locus, hunting mode,
//! linear critical speed, with the yaw damper as a parameter.
//!
//! Damper sign convention (whole project): each yaw damper is longitudinal at lateral arm b;
//! its car-body end is AHEAD (towards +x, running direction) of its bogie-frame end.
//! Elongation positive = extension, force positive = tension. A nose-left yaw sigma moves the
//! left bogie end backwards and the right one forwards, so e_L = +b sigma, e_R = -b sigma,
//! and the yaw moment on the bogie is M = -b F_L + b F_R. A viscous damper (F = c e') gives
//! M = -2 c b^2 sigma', the seed's (5.17)-(5.18) term 2 c0 b^2.
//!
//! State z = (y', sigma', y, sigma) as in (5.29)-(5.30); the Maxwell representation adds the
//! symmetric damper force F_s = (F_L - F_R)/2 (spring k in series with dashpot c:
//! F_s' = k (b sigma' - F_s / c)); the antisymmetric combination is not excited by the bogie
//! and is left out (it would only add the eigenvalue -k/c).

use nalgebra::{Complex, DMatrix};
use serde::{Deserialize, Serialize};

use crate::params::{ParamError, Params};
pub use vehicle_elements::LinearDamper;
use vehicle_elements::{first_unstable_speed, Crossing};

/// One point of a frequency-dependent equivalent damper (per damper).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct DamperPoint {
    /// Frequency \[Hz\].
    pub freq_hz: f64,
    /// Equivalent stiffness k_eq [N/m].
    pub k_n_per_m: f64,
    /// Equivalent damping c_eq [N s/m].
    pub c_ns_per_m: f64,
}

/// How the two (identical) yaw dampers enter the linear model; values per damper.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum DamperRepresentation {
    /// A linear law with constant values (the coach's too): `None`, `Viscous` (the seed's
    /// (5.17)), `KelvinVoigt` (equivalent values at one frequency) or `Maxwell` (one extra
    /// state).
    Linear(LinearDamper),
    /// Kelvin-Voigt with k_eq(f), c_eq(f) interpolated linearly in a table (sorted by
    /// frequency, clamped at the ends), taken at the hunting mode's own frequency (iterated).
    FrequencyDependent(Vec<DamperPoint>),
}

/// Errors of the eigen-analysis.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum EigenError {
    /// Bad model parameters.
    #[error(transparent)]
    Param(#[from] ParamError),
    /// Bad damper representation.
    #[error("invalid damper representation: {0}")]
    Damper(String),
    /// No sign change of the largest real part in the speed range.
    #[error("no stability boundary between {lo_mps} and {hi_mps} m/s")]
    NoCrossing {
        /// Lower end [m/s].
        lo_mps: f64,
        /// Upper end [m/s].
        hi_mps: f64,
    },
    /// The fixed-point iteration on the hunting frequency did not converge.
    #[error("frequency iteration did not converge at {speed_mps} m/s")]
    NotConverged {
        /// Speed [m/s].
        speed_mps: f64,
    },
    /// The eigenvalue iteration did not converge.
    #[error("the eigenvalues of the state matrix at {speed_mps} m/s did not converge")]
    NoEigenvalues {
        /// Speed [m/s].
        speed_mps: f64,
    },
}

/// The least damped oscillatory mode (hunting).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct HuntingMode {
    /// Real part [1/s] (-alpha in (5.33)).
    pub re: f64,
    /// Imaginary part omega [rad/s].
    pub im: f64,
    /// omega / 2 pi \[Hz\].
    pub freq_hz: f64,
    /// -re/|lambda| [-] (negative = unstable).
    pub damping_ratio: f64,
}

impl HuntingMode {
    fn from_eig(l: Complex<f64>) -> Self {
        Self {
            re: l.re,
            im: l.im,
            freq_hz: l.im / (2.0 * std::f64::consts::PI),
            damping_ratio: vehicle_elements::eigenvalues::damping_ratio(l),
        }
    }
}

/// Eigenvalues at one speed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EigenResult {
    /// Speed [m/s].
    pub speed_mps: f64,
    /// All eigenvalues as (re, im), sorted by decreasing real part.
    pub eigenvalues: Vec<(f64, f64)>,
    /// Largest real part of all eigenvalues [1/s].
    pub max_re: f64,
    /// Hunting mode (`None` if no eigenvalue is oscillatory).
    pub hunting: Option<HuntingMode>,
    /// Damper values used (k, c per damper); for FrequencyDependent those at the hunting
    /// frequency.
    pub damper_k_c: (f64, f64),
}

/// Linear critical speed and the mode there.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CriticalSpeed {
    /// V_cr [m/s].
    pub speed_mps: f64,
    /// V_cr [km/h].
    pub speed_kmh: f64,
    /// Hunting mode at V_cr (re ~ 0).
    pub hunting: HuntingMode,
}

fn check_damper(rep: &DamperRepresentation) -> Result<(), EigenError> {
    use vehicle_elements::damper::{check_damping, check_stiffness};
    match rep {
        DamperRepresentation::Linear(d) => d.check().map_err(EigenError::Damper),
        DamperRepresentation::FrequencyDependent(t) => {
            if t.is_empty() {
                return Err(EigenError::Damper("empty frequency table".into()));
            }
            for (i, pt) in t.iter().enumerate() {
                if !(pt.freq_hz.is_finite() && pt.freq_hz >= 0.0) {
                    return Err(EigenError::Damper(format!("table row {i}: negative/NaN")));
                }
                check_stiffness(&format!("table row {i}: stiffness"), pt.k_n_per_m, true)
                    .and_then(|()| {
                        check_damping(&format!("table row {i}: damping"), pt.c_ns_per_m, true)
                    })
                    .map_err(EigenError::Damper)?;
                if i > 0 && pt.freq_hz <= t[i - 1].freq_hz {
                    return Err(EigenError::Damper("table not sorted by frequency".into()));
                }
            }
            Ok(())
        }
    }
}

/// Linear interpolation of a frequency table (clamped).
pub fn interpolate_table(t: &[DamperPoint], freq_hz: f64) -> (f64, f64) {
    if t.is_empty() {
        return (0.0, 0.0);
    }
    if freq_hz <= t[0].freq_hz {
        return (t[0].k_n_per_m, t[0].c_ns_per_m);
    }
    for w in t.windows(2) {
        if freq_hz <= w[1].freq_hz {
            let u = (freq_hz - w[0].freq_hz) / (w[1].freq_hz - w[0].freq_hz);
            return (
                w[0].k_n_per_m + u * (w[1].k_n_per_m - w[0].k_n_per_m),
                w[0].c_ns_per_m + u * (w[1].c_ns_per_m - w[0].c_ns_per_m),
            );
        }
    }
    let l = t[t.len() - 1];
    (l.k_n_per_m, l.c_ns_per_m)
}

/// Damper as a Kelvin-Voigt pair or Maxwell, resolved at one frequency.
#[derive(Debug, Clone, Copy)]
enum Resolved {
    Kv { k: f64, c: f64 },
    Maxwell { k: f64, c: f64 },
}

/// State matrix A(V) (5.30) with z = (y', sigma', y, sigma[, F_s]).
fn state_matrix_resolved(p: &Params, v: f64, d: Resolved) -> DMatrix<f64> {
    let (m, mut c, mut k) = crate::linear::matrices(p, v);
    let b = p.damper_arm_m;
    let n = if matches!(d, Resolved::Maxwell { .. }) {
        5
    } else {
        4
    };
    if let Resolved::Kv { k: kd, c: cd } = d {
        // M = -b F_L + b F_R with F_L = kd b sigma + cd b sigma', F_R = -F_L
        c[(1, 1)] += 2.0 * cd * b * b;
        k[(1, 1)] += 2.0 * kd * b * b;
    }
    let mut a = DMatrix::<f64>::zeros(n, n);
    let minv = [1.0 / m[(0, 0)], 1.0 / m[(1, 1)]];
    for r in 0..2 {
        for col in 0..2 {
            a[(r, col)] = -minv[r] * c[(r, col)];
            a[(r, 2 + col)] = -minv[r] * k[(r, col)];
        }
        a[(2 + r, r)] = 1.0;
    }
    if let Resolved::Maxwell { k: kd, c: cd } = d {
        // J sigma'' += -2 b F_s ; F_s' = kd (b sigma' - F_s/cd)
        a[(1, 4)] = -2.0 * b * minv[1];
        a[(4, 1)] = kd * b;
        a[(4, 4)] = -kd / cd;
    }
    a
}

/// State matrix for a non-frequency-dependent representation (FrequencyDependent is
/// evaluated at `freq_hz`).
pub fn state_matrix(
    p: &Params,
    speed_mps: f64,
    rep: &DamperRepresentation,
    freq_hz: f64,
) -> Result<DMatrix<f64>, EigenError> {
    let mut q = p.clone();
    q.speed_mps = speed_mps;
    q.validate()?;
    check_damper(rep)?;
    Ok(state_matrix_resolved(p, speed_mps, resolve(rep, freq_hz)))
}

fn resolve(rep: &DamperRepresentation, freq_hz: f64) -> Resolved {
    match rep {
        DamperRepresentation::Linear(d) => match *d {
            LinearDamper::None => Resolved::Kv { k: 0.0, c: 0.0 },
            LinearDamper::Viscous { c } => Resolved::Kv { k: 0.0, c },
            LinearDamper::KelvinVoigt { k, c } => Resolved::Kv { k, c },
            LinearDamper::Maxwell { k, c } => Resolved::Maxwell { k, c },
        },
        DamperRepresentation::FrequencyDependent(t) => {
            let (k, c) = interpolate_table(t, freq_hz);
            Resolved::Kv { k, c }
        }
    }
}

fn analyse_resolved(p: &Params, v: f64, d: Resolved) -> Result<EigenResult, EigenError> {
    let a = state_matrix_resolved(p, v, d);
    let ev = vehicle_elements::eigenvalues::eigenvalues(&a)
        .ok_or(EigenError::NoEigenvalues { speed_mps: v })?;
    let mut list: Vec<(f64, f64)> = ev.iter().map(|l| (l.re, l.im)).collect();
    list.sort_by(|x, y| y.0.total_cmp(&x.0));
    let max_re = list.first().map(|x| x.0).unwrap_or(f64::NEG_INFINITY);
    let hunting = ev
        .iter()
        .filter(|l| l.im > 1e-6)
        .max_by(|x, y| x.re.total_cmp(&y.re))
        .map(|l| HuntingMode::from_eig(*l));
    let damper_k_c = match d {
        Resolved::Kv { k, c } | Resolved::Maxwell { k, c } => (k, c),
    };
    Ok(EigenResult {
        speed_mps: v,
        eigenvalues: list,
        max_re,
        hunting,
        damper_k_c,
    })
}

/// Frequency-dependent Kelvin-Voigt damper given as a function f_hz -> (k, c): iterates
/// until the values are taken at the hunting mode's own frequency.
pub fn analyse_with_fn(
    p: &Params,
    speed_mps: f64,
    damper: &dyn Fn(f64) -> (f64, f64),
) -> Result<EigenResult, EigenError> {
    let mut q = p.clone();
    q.speed_mps = speed_mps;
    q.validate()?;
    let mut f = 3.5; // start at a typical hunting frequency [Hz]
    for _ in 0..100 {
        let (k, c) = damper(f);
        LinearDamper::KelvinVoigt { k, c }
            .check()
            .map_err(|e| EigenError::Damper(format!("at {f} Hz: {e}")))?;
        let r = analyse_resolved(p, speed_mps, Resolved::Kv { k, c })?;
        let Some(h) = r.hunting else {
            return Ok(r);
        };
        if (h.freq_hz - f).abs() <= 1e-9 * f.max(1.0) {
            return Ok(r);
        }
        // damped update: robust when k_eq(f) is steep
        f = 0.5 * (f + h.freq_hz);
    }
    Err(EigenError::NotConverged { speed_mps })
}

/// Eigenvalues and hunting mode at one speed.
pub fn analyse(
    p: &Params,
    speed_mps: f64,
    rep: &DamperRepresentation,
) -> Result<EigenResult, EigenError> {
    let mut q = p.clone();
    q.speed_mps = speed_mps;
    q.validate()?;
    check_damper(rep)?;
    match rep {
        DamperRepresentation::FrequencyDependent(t) => {
            analyse_with_fn(p, speed_mps, &|f| interpolate_table(t, f))
        }
        _ => analyse_resolved(p, speed_mps, resolve(rep, 0.0)),
    }
}

/// Root locus data over the given speeds.
pub fn root_locus(
    p: &Params,
    rep: &DamperRepresentation,
    speeds_mps: &[f64],
) -> Result<Vec<EigenResult>, EigenError> {
    speeds_mps.iter().map(|&v| analyse(p, v, rep)).collect()
}

/// Linear critical speed: first speed in [lo, hi] where the largest real part crosses zero
/// (scan with 0.5 m/s steps, then bisection to 1e-6 m/s).
pub fn critical_speed(
    p: &Params,
    rep: &DamperRepresentation,
    lo_mps: f64,
    hi_mps: f64,
) -> Result<CriticalSpeed, EigenError> {
    critical_speed_by(lo_mps, hi_mps, &|v| analyse(p, v, rep))
}

/// As [`critical_speed`] for a damper given as a function f_hz -> (k, c).
pub fn critical_speed_with_fn(
    p: &Params,
    damper: &dyn Fn(f64) -> (f64, f64),
    lo_mps: f64,
    hi_mps: f64,
) -> Result<CriticalSpeed, EigenError> {
    critical_speed_by(lo_mps, hi_mps, &|v| analyse_with_fn(p, v, damper))
}

fn critical_speed_by(
    lo_mps: f64,
    hi_mps: f64,
    f: &dyn Fn(f64) -> Result<EigenResult, EigenError>,
) -> Result<CriticalSpeed, EigenError> {
    let no = EigenError::NoCrossing { lo_mps, hi_mps };
    if !(lo_mps > 0.0 && hi_mps > lo_mps && hi_mps.is_finite()) {
        return Err(no);
    }
    let crossing = first_unstable_speed(lo_mps, hi_mps, 0.5, 1e-6, |v| {
        Ok::<_, EigenError>(f(v)?.max_re >= 0.0)
    })?;
    let Crossing::At(b) = crossing else {
        return Err(no);
    };
    let r = f(b)?;
    let hunting = r.hunting.ok_or(no)?;
    Ok(CriticalSpeed {
        speed_mps: b,
        speed_kmh: b * 3.6,
        hunting,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn viscous_equals_kelvin_voigt_with_zero_k() {
        let p = Params::default();
        let a = analyse(
            &p,
            70.0,
            &DamperRepresentation::Linear(LinearDamper::Viscous { c: 1e5 }),
        )
        .unwrap();
        let b = analyse(
            &p,
            70.0,
            &DamperRepresentation::Linear(LinearDamper::KelvinVoigt { k: 0.0, c: 1e5 }),
        )
        .unwrap();
        assert_eq!(a.eigenvalues, b.eigenvalues);
    }

    #[test]
    fn frequency_dependent_constant_table_equals_kelvin_voigt() {
        let p = Params::default();
        let t = vec![
            DamperPoint {
                freq_hz: 1.0,
                k_n_per_m: 2e6,
                c_ns_per_m: 1.2e5,
            },
            DamperPoint {
                freq_hz: 10.0,
                k_n_per_m: 2e6,
                c_ns_per_m: 1.2e5,
            },
        ];
        let a = analyse(&p, 70.0, &DamperRepresentation::FrequencyDependent(t)).unwrap();
        let b = analyse(
            &p,
            70.0,
            &DamperRepresentation::Linear(LinearDamper::KelvinVoigt { k: 2e6, c: 1.2e5 }),
        )
        .unwrap();
        assert!((a.max_re - b.max_re).abs() < 1e-9);
    }

    #[test]
    fn frequency_dependent_is_taken_at_mode_frequency() {
        let p = Params::default();
        // stiffness rising with frequency: the result must use k at the converged frequency
        let damper = |f: f64| (0.5e6 + 0.4e6 * f, 1.2e5);
        let r = analyse_with_fn(&p, 70.0, &damper).unwrap();
        let h = r.hunting.unwrap();
        let (k, _) = damper(h.freq_hz);
        assert!((r.damper_k_c.0 - k).abs() / k < 1e-6);
    }

    #[test]
    fn stiff_maxwell_tends_to_viscous() {
        let p = Params::default();
        let v = analyse(
            &p,
            70.0,
            &DamperRepresentation::Linear(LinearDamper::Viscous { c: 1.2e5 }),
        )
        .unwrap();
        let m = analyse(
            &p,
            70.0,
            &DamperRepresentation::Linear(LinearDamper::Maxwell { k: 1e10, c: 1.2e5 }),
        )
        .unwrap();
        let (hv, hm) = (v.hunting.unwrap(), m.hunting.unwrap());
        assert!((hv.re - hm.re).abs() < 1e-3 * hv.im && (hv.im - hm.im).abs() < 1e-3 * hv.im);
    }

    #[test]
    fn bad_damper_rejected() {
        let p = Params::default();
        assert!(analyse(
            &p,
            70.0,
            &DamperRepresentation::Linear(LinearDamper::Viscous { c: -1.0 })
        )
        .is_err());
        assert!(analyse(
            &p,
            70.0,
            &DamperRepresentation::Linear(LinearDamper::Maxwell { k: 0.0, c: 1.0 })
        )
        .is_err());
        assert!(analyse(&p, 0.0, &DamperRepresentation::Linear(LinearDamper::None)).is_err());
    }
}
