//! Equivalent conicity (EN 15302).
//!
//! EN 15302 is not public; what follows is our reading of it, with each interpretation marked.
//! Its benchmark (Annex E reference values with the Annex F tolerance ±min(0.05, 0.5 tanγe),
//! as tabulated in the public criogenox/B_ECC-Equivalent-Conicity-Calculation data) is what the
//! tests check against.
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
//! S is the potential of the motion: the wheelset oscillates in the well of S around its
//! equilibrium (the minimum of S, where Δr crosses zero upwards). The turning points y1 < y2 of
//! an oscillation of amplitude ŷ satisfy y2 - y1 = 2 ŷ, S(y1) = S(y2), and S <= S(y1) between
//! them, with the equilibrium between them (for a symmetric Δr, y1 = -ŷ). Half a wavelength is
//! the travel from y1 to y2:
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
//! mean nominal radius. Δr between states is linearly interpolated and S(y) is its exact
//! integral. Interpretations where the standard's text is not available to us:
//! * **Flat tread.** Where S(y) reaches the turning-point level inside the oscillation (Δr = 0
//!   over the whole oscillation, as on a cylindrical or flat-worn tread at small amplitude, or a
//!   separatrix), I diverges: the wavelength is infinite and (K4) gives tanγe = 0, which is what
//!   we report (wavelength `f64::INFINITY`), not "no value".
//! * **Amplitude range.** Δr is taken from every solved state of the table: the reachable rows,
//!   the rows beyond the flange limit where the wheel climbs its flange (so the method gives a
//!   value up to flange contact, as the Annex E values do: up to 7.5 mm for E1, whose flange
//!   limit on our grid is 7.44 mm; and 7 mm for E5, whose turning point lies about 0.3 mm past
//!   the steepest flange point), and the two states at each located contact-point jump (so a
//!   two-point contact is a step of Δr at its own y, not a ramp across one grid step).
//!   [`Conicity::beyond_flange_limit`] says when a turning point lies in the climbing range.
//! * **Unequal radii.** The radius convention is the table's
//!   ([`crate::contact::RadiusConvention`]; EN 15302's offset by default).
//! * **No value.** Only when Δr has no equilibrium (it does not cross zero upwards), when the
//!   oscillation would leave the range where the contact search found a contact, or when Δr does
//!   not restore the wheelset between the turning points (S rises above their level in between:
//!   a double-well Δr at an amplitude between the wells); the error says which.
//!
//! **Linear regression (EN 15302 Annex C, [`linear_regression`]).** Interpretation: the
//! least-squares straight line Δr ≈ c + 2 tanγe (y - ym) over the range the wheelset sweeps,
//! [y1, y2] = [ym - ŷ, ym + ŷ] from the reference method (for a symmetric Δr, -ŷ to +ŷ, the
//! classical UIC 519 regression), uniformly weighted in y (the limit of a regression over
//! equally spaced samples). For the piecewise-linear Δr the integrals are exact:
//! tanγe = (3 / (4 ŷ³)) ∫_{-ŷ}^{ŷ} u Δr(ym + u) du. Centring on the turning points rather than
//! on the equilibrium keeps the interval off a flange the oscillation never reaches when Δr is
//! asymmetric (unequal radii: the E5 equilibrium lies at -2.7 mm, its 5 mm oscillation spans
//! -6.6 to +3.4 mm).
//!
//! **Harmonic linearisation** ([`harmonic_linearisation`]): least-squares straight line
//! Δr ≈ c + 2 tanγ (y - ym) over one period of a sinusoid y = ym + ŷ sin θ (a regression weighted
//! by the time a sinusoidal oscillation spends at each y):
//! tanγ = (1 / (2π ŷ)) ∫_0^{2π} Δr(ym + ŷ sin θ) sin θ dθ, with ym the centre found by the reference
//! method. It is cheap and exact for linear Δr.

mod delta_r;

pub use delta_r::DeltaR;

use thiserror::Error;

use crate::contact::ContactTable;

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
    /// Δr does not cross zero upwards: nothing centres the wheelset.
    #[error(
        "no equilibrium: Δr does not cross zero from negative to positive between y = {:.3} and \
         {:.3} mm (Δr there {:.3} and {:.3} mm); the radius difference or the profile pair does \
         not centre the wheelset",
        .y_min_m * 1e3,
        .y_max_m * 1e3,
        .delta_r_min_m * 1e3,
        .delta_r_max_m * 1e3
    )]
    NoEquilibrium {
        /// Range where Δr is known \[m\].
        y_min_m: f64,
        /// Range where Δr is known \[m\].
        y_max_m: f64,
        /// Δr at `y_min_m` \[m\].
        delta_r_min_m: f64,
        /// Δr at `y_max_m` \[m\].
        delta_r_max_m: f64,
    },
    /// No kinematic oscillation of this amplitude exists on the known Δr.
    #[error(
        "no kinematic oscillation of amplitude {:.2} mm (Δr known for y from {:.3} to {:.3} mm): \
         {reason}",
        .amplitude_m * 1e3,
        .y_min_m * 1e3,
        .y_max_m * 1e3
    )]
    NoOscillation {
        /// Requested amplitude.
        amplitude_m: f64,
        /// Range where Δr is known.
        y_min_m: f64,
        /// Range where Δr is known.
        y_max_m: f64,
        /// Why, with the numbers concerned.
        reason: String,
    },
}

/// Result of the reference (Klingel) method.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Conicity {
    /// Amplitude ŷ \[m\].
    pub amplitude_m: f64,
    /// Equivalent conicity tanγe [-]; 0 where Δr does not restore (flat tread).
    pub tan_gamma_e: f64,
    /// Wavelength of the kinematic oscillation \[m\] (with `e0_m`, `r0_m`); `f64::INFINITY` when
    /// tanγe = 0.
    pub wavelength_m: f64,
    /// Left turning point y1 \[m\].
    pub y1_m: f64,
    /// Right turning point y2 = y1 + 2ŷ \[m\].
    pub y2_m: f64,
    /// Half distance between contact points used for the wavelength \[m\].
    pub e0_m: f64,
    /// Mean nominal rolling radius used for the wavelength \[m\].
    pub r0_m: f64,
    /// A turning point lies beyond the table's flange limit (the wheel climbs its flange there).
    pub beyond_flange_limit: bool,
}

/// Result of the linear-regression method (Annex C).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinearRegression {
    /// Amplitude ŷ \[m\].
    pub amplitude_m: f64,
    /// Equivalent conicity tanγe = slope / 2 [-].
    pub tan_gamma_e: f64,
    /// Centre of the regression interval, ym = (y1 + y2) / 2 of the reference method \[m\].
    pub centre_m: f64,
    /// Δr of the regression line at the centre \[m\].
    pub intercept_m: f64,
}

/// Number of midpoint-rule panels for the integrals.
const N_QUAD: usize = 4000;

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

/// Equivalent conicity by linear regression of Δr (EN 15302 Annex C as read in the module docs).
pub fn linear_regression(
    table: &ContactTable,
    amplitude_m: f64,
) -> Result<LinearRegression, ConicityError> {
    DeltaR::from_table(table).linear_regression(amplitude_m)
}

fn check_amplitude(amplitude_m: f64) -> Result<(), ConicityError> {
    if amplitude_m.is_finite() && amplitude_m > 0.0 {
        Ok(())
    } else {
        Err(ConicityError::Amplitude(amplitude_m))
    }
}

impl DeltaR {
    /// Reference method, see [`equivalent_conicity`].
    pub fn equivalent_conicity(&self, amplitude_m: f64) -> Result<Conicity, ConicityError> {
        check_amplitude(amplitude_m)?;
        let a = amplitude_m;
        let osc = self.oscillation(a)?;
        let ym = 0.5 * (osc.y1 + osc.y2);
        let depth = osc.level - osc.bottom;
        // S reaching the turning-point level inside the oscillation: I diverges (flat tread)
        let touch = 1e-12 * depth;
        let dth = std::f64::consts::PI / N_QUAD as f64;
        let mut integral = 0.0;
        for k in 0..N_QUAD {
            let th = (k as f64 + 0.5) * dth;
            let e = osc.level - self.s_at(ym - a * th.cos());
            if e <= touch {
                integral = f64::INFINITY;
                break;
            }
            integral += a * th.sin() / e.sqrt() * dth;
        }
        let pi = std::f64::consts::PI;
        let beyond = self
            .flange_limits_m()
            .is_some_and(|(l, r)| osc.y1 < l - 1e-12 || osc.y2 > r + 1e-12);
        Ok(Conicity {
            amplitude_m: a,
            tan_gamma_e: if integral.is_finite() {
                (pi / integral).powi(2)
            } else {
                0.0
            },
            wavelength_m: 2.0 * (self.e0_m() * self.r0_m()).sqrt() * integral,
            y1_m: osc.y1,
            y2_m: osc.y2,
            e0_m: self.e0_m(),
            r0_m: self.r0_m(),
            beyond_flange_limit: beyond,
        })
    }

    /// Harmonic linearisation, see [`harmonic_linearisation`].
    pub fn harmonic_linearisation(&self, amplitude_m: f64) -> Result<f64, ConicityError> {
        check_amplitude(amplitude_m)?;
        let osc = self.oscillation(amplitude_m)?;
        let ym = 0.5 * (osc.y1 + osc.y2);
        let n = 2 * N_QUAD;
        let dth = 2.0 * std::f64::consts::PI / n as f64;
        let mut acc = 0.0;
        for k in 0..n {
            let th = (k as f64 + 0.5) * dth;
            acc += self.delta_r_at(ym + amplitude_m * th.sin()) * th.sin() * dth;
        }
        Ok(acc / (2.0 * std::f64::consts::PI * amplitude_m))
    }

    /// Linear regression, see [`linear_regression`].
    pub fn linear_regression(&self, amplitude_m: f64) -> Result<LinearRegression, ConicityError> {
        check_amplitude(amplitude_m)?;
        let a = amplitude_m;
        let osc = self.oscillation(a)?;
        let c = 0.5 * (osc.y1 + osc.y2);
        // breakpoints of the piecewise-linear Δr inside (c - a, c + a), as offsets u
        let mut us = vec![-a, a];
        us.extend(
            self.samples_y()
                .iter()
                .filter(|&&y| y > c - a && y < c + a)
                .map(|&y| y - c),
        );
        us.sort_by(f64::total_cmp);
        let (mut first, mut zeroth) = (0.0, 0.0);
        for w in us.windows(2) {
            let (u0, u1) = (w[0], w[1]);
            if u1 <= u0 {
                continue;
            }
            let d0 = self.delta_r_at(c + u0);
            let d1 = self.delta_r_at(c + u1);
            let k = (d1 - d0) / (u1 - u0);
            first +=
                (d0 - k * u0) * (u1 * u1 - u0 * u0) / 2.0 + k * (u1.powi(3) - u0.powi(3)) / 3.0;
            zeroth += 0.5 * (d0 + d1) * (u1 - u0);
        }
        let slope = 3.0 * first / (2.0 * a.powi(3));
        Ok(LinearRegression {
            amplitude_m: a,
            tan_gamma_e: 0.5 * slope,
            centre_m: c,
            intercept_m: zeroth / (2.0 * a),
        })
    }
}
