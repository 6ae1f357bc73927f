//! Equivalent conicity (EN 15302).
//!
//! **Reference method (EN 15302 Annex B, integration of the non-linear kinematic equation).**
//! A free wheelset rolling at constant speed without slip follows (Klingel, x = distance travelled)
//!
//! ```text
//!     d²y/dx² = -Δr(y) / (2 e0 r0)                                       (K1)
//! ```
//!
//! with Δr = r_right - r_left, r0 the mean nominal rolling radius and 2 e0 the lateral distance
//! between the contact points. Multiplying by dy/dx and integrating gives, with S(y) = ∫ Δr dy,
//!
//! ```text
//!     (dy/dx)² = (S(y1) - S(y)) / (e0 r0)                               (K2)
//! ```
//!
//! The turning points y1 < y2 of a kinematic oscillation of amplitude ŷ satisfy y2 - y1 = 2 ŷ and
//! S(y1) = S(y2) (found by bisection; for a symmetric Δr, y1 = -ŷ). Half a wavelength is the
//! travel from y1 to y2:
//!
//! ```text
//!     λ = 2 sqrt(e0 r0) I,   I = ∫_{y1}^{y2} dy / sqrt(S(y1) - S(y))     (K3)
//! ```
//!
//! evaluated with y = ym - ŷ cos θ (θ in [0, π], midpoint rule, which removes the inverse-square-root
//! end singularities). Klingel's formula for a cone, λ = 2π sqrt(r0 e0 / tanγ), then defines
//!
//! ```text
//!     tanγe = (2π / λ)² r0 e0 = (π / I)²                                 (K4)
//! ```
//!
//! so e0 and r0 cancel: the equivalent conicity depends only on the Δr(y) function. The reported
//! wavelength uses e0 from the table (half distance between the contact points at y = 0) and the
//! mean nominal radius. Δr between table rows is linearly interpolated and S(y) is its exact
//! integral.
//!
//! **Harmonic linearisation** ([`harmonic_linearisation`]): least-squares straight line
//! Δr ≈ c + 2 tanγ (y - ym) over one period of a sinusoid y = ym + ŷ sin θ (i.e. a linear regression
//! weighted by the time a sinusoidal oscillation spends at each y):
//! tanγ = (1 / (2π ŷ)) ∫_0^{2π} Δr(ym + ŷ sin θ) sin θ dθ, with ym the centre found by the reference
//! method. It is cheap and exact for linear Δr; EN 15302 Annex C describes a regression variant
//! whose exact weighting is not reproduced here.

use thiserror::Error;

use crate::contact::ContactTable;

/// Number of midpoint-rule panels for the integrals.
const N_QUAD: usize = 4000;

/// Errors of the conicity evaluation.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum ConicityError {
    /// Bad Δr samples.
    #[error(
        "invalid Δr samples: need >= 3 finite points, strictly increasing y, equal lengths, \
         e0_m > 0, r0_m > 0"
    )]
    Samples,
    /// Bad amplitude.
    #[error("invalid amplitude_m = {0}: must be finite and > 0")]
    Amplitude(f64),
    /// The oscillation does not fit the reachable part of the table.
    #[error(
        "amplitude {amplitude_m} m: no kinematic oscillation within the reachable range \
         [{y_min_m}, {y_max_m}] m of the table ({reason})"
    )]
    NoOscillation {
        /// Requested amplitude.
        amplitude_m: f64,
        /// Reachable range.
        y_min_m: f64,
        /// Reachable range.
        y_max_m: f64,
        /// Reason.
        reason: &'static str,
    },
}

/// Result of the reference (Klingel) method.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Conicity {
    /// Amplitude ŷ [m].
    pub amplitude_m: f64,
    /// Equivalent conicity tanγe [-].
    pub tan_gamma_e: f64,
    /// Wavelength of the kinematic oscillation [m] (with `e0_m`, `r0_m`).
    pub wavelength_m: f64,
    /// Left turning point y1 [m].
    pub y1_m: f64,
    /// Right turning point y2 = y1 + 2ŷ [m].
    pub y2_m: f64,
    /// Half distance between contact points used for the wavelength [m].
    pub e0_m: f64,
    /// Mean nominal rolling radius used for the wavelength [m].
    pub r0_m: f64,
}

/// Piecewise-linear Δr(y) = r_right - r_left and its exact integral.
#[derive(Debug, Clone, PartialEq)]
pub struct DeltaR {
    y: Vec<f64>,
    dr: Vec<f64>,
    s: Vec<f64>,
    e0_m: f64,
    r0_m: f64,
}

impl DeltaR {
    /// From the reachable rows of a contact table.
    pub fn from_table(table: &ContactTable) -> Self {
        let (y, dr): (Vec<f64>, Vec<f64>) =
            table.reachable_rows().map(|r| (r.y_m, r.delta_r_m)).unzip();
        Self::build(y, dr, table.e0_m, table.nominal_radius_mean_m())
    }

    /// From sampled values (e.g. a reference Δr function): `y_m` strictly increasing, same length
    /// as `delta_r_m`, at least 3 points; `e0_m`, `r0_m` only scale the reported wavelength.
    pub fn from_samples(
        y_m: &[f64],
        delta_r_m: &[f64],
        e0_m: f64,
        r0_m: f64,
    ) -> Result<Self, ConicityError> {
        let ok = y_m.len() == delta_r_m.len()
            && y_m.len() >= 3
            && y_m.windows(2).all(|w| w[1] > w[0])
            && y_m.iter().chain(delta_r_m).all(|v| v.is_finite())
            && e0_m.is_finite()
            && e0_m > 0.0
            && r0_m.is_finite()
            && r0_m > 0.0;
        if !ok {
            return Err(ConicityError::Samples);
        }
        Ok(Self::build(y_m.to_vec(), delta_r_m.to_vec(), e0_m, r0_m))
    }

    fn build(y: Vec<f64>, dr: Vec<f64>, e0_m: f64, r0_m: f64) -> Self {
        let mut s = vec![0.0; y.len()];
        for i in 1..y.len() {
            s[i] = s[i - 1] + 0.5 * (dr[i] + dr[i - 1]) * (y[i] - y[i - 1]);
        }
        Self {
            y,
            dr,
            s,
            e0_m,
            r0_m,
        }
    }
    fn seg(&self, y: f64) -> usize {
        self.y
            .partition_point(|&v| v <= y)
            .clamp(1, self.y.len() - 1)
            - 1
    }
    fn dr_at(&self, y: f64) -> f64 {
        let i = self.seg(y);
        let t = (y - self.y[i]) / (self.y[i + 1] - self.y[i]);
        self.dr[i] + t * (self.dr[i + 1] - self.dr[i])
    }
    fn s_at(&self, y: f64) -> f64 {
        let i = self.seg(y);
        let u = y - self.y[i];
        let k = (self.dr[i + 1] - self.dr[i]) / (self.y[i + 1] - self.y[i]);
        self.s[i] + self.dr[i] * u + 0.5 * k * u * u
    }
}

fn turning_points(d: &DeltaR, a: f64) -> Result<(f64, f64), ConicityError> {
    let no = |reason| ConicityError::NoOscillation {
        amplitude_m: a,
        y_min_m: d.y.first().copied().unwrap_or(f64::NAN),
        y_max_m: d.y.last().copied().unwrap_or(f64::NAN),
        reason,
    };
    if d.y.len() < 3 {
        return Err(no("fewer than 3 reachable rows"));
    }
    let (ylo, yhi) = (d.y[0], d.y[d.y.len() - 1]);
    if yhi - ylo < 2.0 * a {
        return Err(no("range narrower than 2 * amplitude"));
    }
    // H(y1) = S(y1 + 2a) - S(y1), increasing for increasing Δr
    let h = |y1: f64| d.s_at(y1 + 2.0 * a) - d.s_at(y1);
    let (mut lo, mut hi) = (ylo, yhi - 2.0 * a);
    if h(lo) > 0.0 || h(hi) < 0.0 {
        return Err(no(
            "energy balance S(y1) = S(y1 + 2 amplitude) has no solution",
        ));
    }
    for _ in 0..200 {
        let m = 0.5 * (lo + hi);
        if h(m) < 0.0 {
            lo = m;
        } else {
            hi = m;
        }
        if hi - lo < 1e-15 {
            break;
        }
    }
    let y1 = 0.5 * (lo + hi);
    Ok((y1, y1 + 2.0 * a))
}

/// Equivalent conicity for amplitude `amplitude_m` by the EN 15302 reference method (module docs,
/// (K1)-(K4)).
pub fn equivalent_conicity(
    table: &ContactTable,
    amplitude_m: f64,
) -> Result<Conicity, ConicityError> {
    DeltaR::from_table(table).equivalent_conicity(amplitude_m)
}

/// Equivalent conicity by harmonic linearisation (sinusoid-weighted linear regression of Δr),
/// centred on the oscillation centre of the reference method.
pub fn harmonic_linearisation(
    table: &ContactTable,
    amplitude_m: f64,
) -> Result<f64, ConicityError> {
    DeltaR::from_table(table).harmonic_linearisation(amplitude_m)
}

impl DeltaR {
    /// Reference method, see [`equivalent_conicity`].
    pub fn equivalent_conicity(&self, amplitude_m: f64) -> Result<Conicity, ConicityError> {
        if !(amplitude_m.is_finite() && amplitude_m > 0.0) {
            return Err(ConicityError::Amplitude(amplitude_m));
        }
        let d = self;
        let (y1, y2) = turning_points(d, amplitude_m)?;
        let ym = 0.5 * (y1 + y2);
        let s1 = 0.5 * (d.s_at(y1) + d.s_at(y2));
        let dth = std::f64::consts::PI / N_QUAD as f64;
        let mut integral = 0.0;
        for k in 0..N_QUAD {
            let th = (k as f64 + 0.5) * dth;
            let y = ym - amplitude_m * th.cos();
            let e = s1 - d.s_at(y);
            if e <= 0.0 {
                return Err(ConicityError::NoOscillation {
                    amplitude_m,
                    y_min_m: d.y[0],
                    y_max_m: d.y[d.y.len() - 1],
                    reason: "Δr does not restore the wheelset between the turning points",
                });
            }
            integral += amplitude_m * th.sin() / e.sqrt() * dth;
        }
        let r0 = self.r0_m;
        let e0 = self.e0_m;
        let pi = std::f64::consts::PI;
        Ok(Conicity {
            amplitude_m,
            tan_gamma_e: (pi / integral).powi(2),
            wavelength_m: 2.0 * (e0 * r0).sqrt() * integral,
            y1_m: y1,
            y2_m: y2,
            e0_m: e0,
            r0_m: r0,
        })
    }

    /// Harmonic linearisation, see [`harmonic_linearisation`].
    pub fn harmonic_linearisation(&self, amplitude_m: f64) -> Result<f64, ConicityError> {
        if !(amplitude_m.is_finite() && amplitude_m > 0.0) {
            return Err(ConicityError::Amplitude(amplitude_m));
        }
        let d = self;
        let (y1, y2) = turning_points(d, amplitude_m)?;
        let ym = 0.5 * (y1 + y2);
        let n = 2 * N_QUAD;
        let dth = 2.0 * std::f64::consts::PI / n as f64;
        let mut acc = 0.0;
        for k in 0..n {
            let th = (k as f64 + 0.5) * dth;
            acc += d.dr_at(ym + amplitude_m * th.sin()) * th.sin() * dth;
        }
        Ok(acc / (2.0 * std::f64::consts::PI * amplitude_m))
    }
}
