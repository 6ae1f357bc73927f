//! Linear eigen-analysis of the coach: state matrix with the four yaw dampers, eigenvalues,
//! the least-damped mode per speed (named by the eigenvector's kinetic-energy shares), root
//! locus, linear critical speed and frequency by bisection.
//!
//! State z = (q', q, F) with q the 17 dofs and F the forces of the dampers that carry a series
//! stiffness (one first-order state per damper, [`DamperRepresentation`]):
//! * M q'' = -C q' - K q - E^T F (tension F, elongations e = E q, see
//!   [`crate::layout::damper_rows`]);
//! * F' = a_e e + a_v e' - a_f F.
//!
//! Dampers without a series stiffness (viscous, Kelvin-Voigt) are added to C and K. The passive
//! reference damper is the Maxwell element of the 2-dof bogie's calibration (spring in series
//! with a dashpot), optionally behind a mounting stiffness (series spring of the installation).

use nalgebra::{Complex, DMatrix, DVector};
use serde::{Deserialize, Serialize};

use crate::layout::{damper_rows, mass_diagonal, N_DAMPERS, N_DOF};
use crate::params::{ParamError, VehicleParams};
use vehicle_elements::{first_unstable_speed, Crossing};

/// Linear representation of one yaw damper (all four identical), values per damper: the law the
/// closed loop evaluates too.
pub use vehicle_elements::LinearDamper as DamperRepresentation;

/// A yaw damper as the eigen-analysis sees it: its representation behind an optional mounting
/// (series) stiffness of the installation.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct YawDamperModel {
    /// The damper itself.
    pub representation: DamperRepresentation,
    /// Series stiffness of the mounting [N/m]; `None` = rigid mounting.
    pub mounting_stiffness_n_per_m: Option<f64>,
}

impl YawDamperModel {
    /// Rigidly mounted damper.
    pub fn rigid(representation: DamperRepresentation) -> Self {
        Self {
            representation,
            mounting_stiffness_n_per_m: None,
        }
    }
}

/// The damper resolved: parallel (k, c) added to the matrices, or a first-order force state.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Resolved {
    Parallel { k: f64, c: f64 },
    State { a_e: f64, a_v: f64, a_f: f64 },
}

/// Errors of the eigen-analysis.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum EigenError {
    /// Bad model parameters.
    #[error(transparent)]
    Param(#[from] ParamError),
    /// Bad damper representation.
    #[error("invalid yaw damper representation: {0}")]
    Damper(String),
    /// No stability boundary in the range.
    #[error("no stability boundary between {lo_mps} and {hi_mps} m/s")]
    NoCrossing {
        /// Lower end [m/s].
        lo_mps: f64,
        /// Upper end [m/s].
        hi_mps: f64,
    },
    /// Already unstable at the lower end of the range.
    #[error("unstable already at the lower end of the range, {lo_mps} m/s")]
    UnstableAtLowerEnd {
        /// Lower end [m/s].
        lo_mps: f64,
    },
    /// The eigenvalue iteration did not converge.
    #[error("the eigenvalues of the state matrix at {speed_mps} m/s did not converge")]
    NoEigenvalues {
        /// Speed [m/s].
        speed_mps: f64,
    },
}

fn resolve(d: &YawDamperModel) -> Result<Resolved, EigenError> {
    d.representation.check().map_err(EigenError::Damper)?;
    let mount = d.mounting_stiffness_n_per_m;
    if let Some(km) = mount {
        vehicle_elements::damper::check_stiffness("mounting stiffness", km, false)
            .map_err(EigenError::Damper)?;
    }
    let series = |k: f64, km: Option<f64>| match km {
        Some(km) => k * km / (k + km),
        None => k,
    };
    let maxwell = |k: f64, c: f64| Resolved::State {
        a_e: 0.0,
        a_v: k,
        a_f: k / c,
    };
    Ok(match d.representation {
        DamperRepresentation::None => Resolved::Parallel { k: 0.0, c: 0.0 },
        DamperRepresentation::Viscous { c } => match mount {
            Some(km) if c > 0.0 => maxwell(km, c),
            _ => Resolved::Parallel { k: 0.0, c },
        },
        DamperRepresentation::KelvinVoigt { k, c } => match mount {
            None => Resolved::Parallel { k, c },
            Some(km) if c == 0.0 => Resolved::Parallel {
                k: series(k, Some(km)),
                c: 0.0,
            },
            // F = km (e - u), c u' = F - k u  =>  F' = km e' - (km/c)(F - k e + k F/km)
            Some(km) => Resolved::State {
                a_e: km * k / c,
                a_v: km,
                a_f: (km + k) / c,
            },
        },
        DamperRepresentation::Maxwell { k, c } => maxwell(series(k, mount), c),
    })
}

/// State matrix A(V) with z = (q', q[, F]).
pub fn state_matrix(
    p: &VehicleParams,
    speed_mps: f64,
    damper: &YawDamperModel,
) -> Result<DMatrix<f64>, EigenError> {
    let mut q = p.clone();
    q.speed_mps = speed_mps;
    q.validate()?;
    Ok(build(&q, speed_mps, resolve(damper)?))
}

fn build(p: &VehicleParams, v: f64, d: Resolved) -> DMatrix<f64> {
    let (_, mut c, mut k) = crate::linear::matrices(p, v);
    let minv = mass_diagonal(p).map(|m| 1.0 / m);
    let rows = damper_rows(p);
    let nf = if matches!(d, Resolved::State { .. }) {
        N_DAMPERS
    } else {
        0
    };
    if let Resolved::Parallel { k: kd, c: cd } = d {
        for row in &rows {
            for &(i, ai) in row {
                for &(j, aj) in row {
                    k[(i, j)] += kd * ai * aj;
                    c[(i, j)] += cd * ai * aj;
                }
            }
        }
    }
    let n = 2 * N_DOF + nf;
    let mut a = DMatrix::<f64>::zeros(n, n);
    for r in 0..N_DOF {
        for col in 0..N_DOF {
            a[(r, col)] = -minv[r] * c[(r, col)];
            a[(r, N_DOF + col)] = -minv[r] * k[(r, col)];
        }
        a[(N_DOF + r, r)] = 1.0;
    }
    if let Resolved::State { a_e, a_v, a_f } = d {
        for (di, row) in rows.iter().enumerate() {
            let fi = 2 * N_DOF + di;
            for &(i, ai) in row {
                // M q'' += -E^T F
                a[(i, fi)] -= minv[i] * ai;
                // F' = a_e e + a_v e' - a_f F
                a[(fi, N_DOF + i)] += a_e * ai;
                a[(fi, i)] += a_v * ai;
            }
            a[(fi, fi)] = -a_f;
        }
    }
    a
}

/// Which part of the coach a mode moves (by kinetic-energy share of its eigenvector).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum ModeKind {
    /// Car body holds at least half of the kinetic energy (car-body hunting, "primary hunting").
    CarBody,
    /// Front bogie (frame and wheelsets 1, 2) holds at least twice the rear bogie's share.
    FrontBogie,
    /// Rear bogie holds at least twice the front bogie's share.
    RearBogie,
    /// Both bogies take part about equally.
    BothBogies,
}

impl ModeKind {
    /// Name for tables and plots.
    pub fn label(self) -> &'static str {
        match self {
            ModeKind::CarBody => "car-body hunting",
            ModeKind::FrontBogie => "bogie hunting, front",
            ModeKind::RearBogie => "bogie hunting, rear",
            ModeKind::BothBogies => "bogie hunting, both bogies",
        }
    }
}

/// Kinetic-energy shares of a mode (sum 1).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct EnergyShares {
    /// Car body.
    pub carbody: f64,
    /// Front frame and wheelsets 1, 2.
    pub front_bogie: f64,
    /// Rear frame and wheelsets 3, 4.
    pub rear_bogie: f64,
}

/// One eigenvalue with its mode.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Mode {
    /// Real part [1/s].
    pub re: f64,
    /// Imaginary part omega [rad/s].
    pub im: f64,
    /// omega / 2 pi \[Hz\].
    pub freq_hz: f64,
    /// -re / |lambda| (negative = unstable).
    pub damping_ratio: f64,
    /// Energy shares of the eigenvector.
    pub shares: EnergyShares,
    /// Name by the shares.
    pub kind: ModeKind,
}

/// Eigenvalues at one speed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EigenResult {
    /// Speed [m/s].
    pub speed_mps: f64,
    /// All eigenvalues (re, im), sorted by decreasing real part.
    pub eigenvalues: Vec<(f64, f64)>,
    /// Largest real part [1/s].
    pub max_re: f64,
    /// The oscillatory eigenvalue (im > 0) with the largest real part, with its mode.
    pub least_stable: Option<Mode>,
    /// The oscillatory eigenvalue with the smallest damping ratio, with its mode.
    pub least_damped: Option<Mode>,
}

/// Linear critical speed and the mode that crosses there.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CriticalSpeed {
    /// V_cr [m/s].
    pub speed_mps: f64,
    /// V_cr [km/h].
    pub speed_kmh: f64,
    /// The crossing mode (re ~ 0).
    pub mode: Mode,
}

/// Eigenvector of `a` for eigenvalue `l` by inverse iteration (complex LU).
fn eigenvector(a: &DMatrix<f64>, l: Complex<f64>) -> DVector<Complex<f64>> {
    let n = a.nrows();
    // shift slightly off the eigenvalue so that the matrix stays invertible
    let shift = l + Complex::new(1e-9 * (1.0 + l.norm()), 1e-9 * (1.0 + l.norm()));
    let mut m = a.map(|x| Complex::new(x, 0.0));
    for i in 0..n {
        m[(i, i)] -= shift;
    }
    let lu = m.lu();
    let mut v = DVector::from_element(n, Complex::new(1.0, 0.0));
    for _ in 0..3 {
        if let Some(w) = lu.solve(&v) {
            let norm = w.norm();
            if norm > 0.0 && norm.is_finite() {
                v = w / Complex::new(norm, 0.0);
            }
        }
    }
    v
}

fn shares_of(p: &VehicleParams, v: &DVector<Complex<f64>>) -> EnergyShares {
    let m = mass_diagonal(p);
    let e = |i: usize| 0.5 * m[i] * v[i].norm_sqr();
    let carbody: f64 = (0..3).map(e).sum();
    let front: f64 = (3..6).chain(9..13).map(e).sum();
    let rear: f64 = (6..9).chain(13..17).map(e).sum();
    let total = carbody + front + rear;
    if !(total > 0.0 && total.is_finite()) {
        return EnergyShares {
            carbody: 0.0,
            front_bogie: 0.0,
            rear_bogie: 0.0,
        };
    }
    EnergyShares {
        carbody: carbody / total,
        front_bogie: front / total,
        rear_bogie: rear / total,
    }
}

impl ModeKind {
    /// Name by the shares: car body if it holds at least half the kinetic energy, else the
    /// bogie holding at least twice the other's share, else both bogies.
    pub fn from_shares(s: &EnergyShares) -> Self {
        kind_of(s)
    }
}

fn kind_of(s: &EnergyShares) -> ModeKind {
    if s.carbody >= 0.5 {
        ModeKind::CarBody
    } else if s.front_bogie >= 2.0 * s.rear_bogie {
        ModeKind::FrontBogie
    } else if s.rear_bogie >= 2.0 * s.front_bogie {
        ModeKind::RearBogie
    } else {
        ModeKind::BothBogies
    }
}

fn mode(p: &VehicleParams, a: &DMatrix<f64>, l: Complex<f64>) -> Mode {
    let v = eigenvector(a, l);
    let shares = shares_of(p, &v);
    Mode {
        re: l.re,
        im: l.im,
        freq_hz: l.im / (2.0 * std::f64::consts::PI),
        damping_ratio: vehicle_elements::eigenvalues::damping_ratio(l),
        shares,
        kind: kind_of(&shares),
    }
}

/// Below this imaginary part an eigenvalue counts as real [rad/s].
const OSCILLATORY_MIN_IM: f64 = 1e-3;

fn eigenvalues_at(a: &DMatrix<f64>, speed_mps: f64) -> Result<Vec<Complex<f64>>, EigenError> {
    vehicle_elements::eigenvalues::eigenvalues(a).ok_or(EigenError::NoEigenvalues { speed_mps })
}

fn analyse_validated(p: &VehicleParams, v: f64, d: Resolved) -> Result<EigenResult, EigenError> {
    let a = build(p, v, d);
    let ev = eigenvalues_at(&a, v)?;
    let mut list: Vec<(f64, f64)> = ev.iter().map(|l| (l.re, l.im)).collect();
    list.sort_by(|x, y| y.0.total_cmp(&x.0));
    let max_re = list.first().map_or(f64::NEG_INFINITY, |x| x.0);
    let osc = || ev.iter().filter(|l| l.im > OSCILLATORY_MIN_IM);
    let least_stable = osc().max_by(|x, y| x.re.total_cmp(&y.re)).copied();
    let least_damped = osc()
        .max_by(|x, y| (x.re / x.norm()).total_cmp(&(y.re / y.norm())))
        .copied();
    Ok(EigenResult {
        speed_mps: v,
        eigenvalues: list,
        max_re,
        least_stable: least_stable.map(|l| mode(p, &a, l)),
        least_damped: least_damped.map(|l| mode(p, &a, l)),
    })
}

/// Eigenvalues and modes at one speed.
pub fn analyse(
    p: &VehicleParams,
    speed_mps: f64,
    damper: &YawDamperModel,
) -> Result<EigenResult, EigenError> {
    let mut q = p.clone();
    q.speed_mps = speed_mps;
    q.validate()?;
    analyse_validated(&q, speed_mps, resolve(damper)?)
}

/// Root locus: eigenvalues and modes over the given speeds (the `master root-locus` data).
pub fn root_locus(
    p: &VehicleParams,
    damper: &YawDamperModel,
    speeds_mps: &[f64],
) -> Result<Vec<EigenResult>, EigenError> {
    speeds_mps.iter().map(|&v| analyse(p, v, damper)).collect()
}

/// Largest real part of all eigenvalues at one speed (no modes: for the bisection).
fn max_re(p: &VehicleParams, v: f64, d: Resolved) -> Result<f64, EigenError> {
    Ok(eigenvalues_at(&build(p, v, d), v)?
        .iter()
        .map(|l| l.re)
        .fold(f64::NEG_INFINITY, f64::max))
}

/// Linear critical speed: the first speed in [lo, hi] where the largest real part of all
/// eigenvalues crosses zero (scan in 1 m/s steps, then bisection to 1e-6 m/s), with the mode
/// that crosses.
pub fn critical_speed(
    p: &VehicleParams,
    damper: &YawDamperModel,
    lo_mps: f64,
    hi_mps: f64,
) -> Result<CriticalSpeed, EigenError> {
    let no = EigenError::NoCrossing { lo_mps, hi_mps };
    if !(lo_mps > 0.0 && hi_mps > lo_mps && hi_mps.is_finite()) {
        return Err(no);
    }
    let d = resolve(damper)?;
    let at = |v: f64| -> Result<(VehicleParams, f64), EigenError> {
        let mut q = p.clone();
        q.speed_mps = v;
        q.validate()?;
        let r = max_re(&q, v, d)?;
        Ok((q, r))
    };
    let b = match first_unstable_speed(lo_mps, hi_mps, 1.0, 1e-6, |v| {
        Ok::<_, EigenError>(at(v)?.1 >= 0.0)
    })? {
        Crossing::At(b) => b,
        Crossing::UnstableAtStart => return Err(EigenError::UnstableAtLowerEnd { lo_mps }),
        Crossing::None => return Err(no),
    };
    let (q, _) = at(b)?;
    let r = analyse_validated(&q, b, d)?;
    let mode = r.least_stable.ok_or(no)?;
    Ok(CriticalSpeed {
        speed_mps: b,
        speed_kmh: b * 3.6,
        mode,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stiff_maxwell_tends_to_viscous_and_kelvin_voigt_adds_up() {
        let p = VehicleParams::default();
        let v = analyse(
            &p,
            60.0,
            &YawDamperModel::rigid(DamperRepresentation::Viscous { c: 1e5 }),
        )
        .unwrap();
        let m = analyse(
            &p,
            60.0,
            &YawDamperModel::rigid(DamperRepresentation::Maxwell { k: 1e9, c: 1e5 }),
        )
        .unwrap();
        let (a, b) = (v.least_stable.unwrap(), m.least_stable.unwrap());
        assert!((a.re - b.re).abs() < 1e-3 * a.im, "{a:?} {b:?}");
        // viscous behind a mounting = Maxwell with the mounting stiffness
        let vm = analyse(
            &p,
            60.0,
            &YawDamperModel {
                representation: DamperRepresentation::Viscous { c: 1e5 },
                mounting_stiffness_n_per_m: Some(5e6),
            },
        )
        .unwrap();
        let mm = analyse(
            &p,
            60.0,
            &YawDamperModel::rigid(DamperRepresentation::Maxwell { k: 5e6, c: 1e5 }),
        )
        .unwrap();
        assert_eq!(vm.eigenvalues, mm.eigenvalues);
    }

    #[test]
    fn mounting_of_a_kelvin_voigt_damper() {
        // KV behind a very stiff mounting equals the rigid KV
        let p = VehicleParams::default();
        let kv = DamperRepresentation::KelvinVoigt { k: 4e5, c: 1e5 };
        let a = analyse(&p, 60.0, &YawDamperModel::rigid(kv)).unwrap();
        let b = analyse(
            &p,
            60.0,
            &YawDamperModel {
                representation: kv,
                mounting_stiffness_n_per_m: Some(1e8),
            },
        )
        .unwrap();
        let (x, y) = (a.least_stable.unwrap(), b.least_stable.unwrap());
        assert!(
            (x.re - y.re).abs() < 1e-3 * x.im && (x.im - y.im).abs() < 1e-3 * x.im,
            "{x:?} {y:?}"
        );
    }

    #[test]
    fn bad_damper_rejected() {
        let p = VehicleParams::default();
        for d in [
            YawDamperModel::rigid(DamperRepresentation::Viscous { c: -1.0 }),
            YawDamperModel::rigid(DamperRepresentation::Maxwell { k: 0.0, c: 1.0 }),
            YawDamperModel {
                representation: DamperRepresentation::Viscous { c: 1.0 },
                mounting_stiffness_n_per_m: Some(f64::NAN),
            },
            // beyond any installation: the eigenvalues would not be trusted
            YawDamperModel::rigid(DamperRepresentation::Viscous { c: 1e20 }),
            YawDamperModel::rigid(DamperRepresentation::KelvinVoigt { k: 1e11, c: 0.0 }),
            YawDamperModel {
                representation: DamperRepresentation::Viscous { c: 1e5 },
                mounting_stiffness_n_per_m: Some(1e305),
            },
        ] {
            assert!(matches!(analyse(&p, 60.0, &d), Err(EigenError::Damper(_))));
        }
    }
}
