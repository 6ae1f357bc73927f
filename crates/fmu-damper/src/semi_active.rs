//! Semi-active yaw damper: simplified Ferdek-Luczko model with a by-pass proportional
//! valve, seed section 3.3.2-3.3.3, equations (3.38)-(3.45).
//!
//! # Model
//! One hydraulic state, the pressure difference `dP = P_A - P_B` (rebound minus
//! compression chamber), plus the valve opening `x_v` when the valve is not ideal:
//!
//! ```text
//! F      = A_eff dP                                                   (3.38)
//! Q_f    = C_f  g(dP)                 piston (internal valve) flow    (3.42)
//! Q_v    = c_d A_v x_v sqrt(2/rho) g(dP)   by-pass valve flow         (3.44)
//! dP'    = K/V0 ( f(v) - Q_f - Q_v )                                  (3.43)/(3.45)
//! g(dP)  = dP / (dP^2 + dP_t^2)^(1/4)  ~ sqrt(|dP|) sign(dP) for |dP| >> dP_t
//! f(v)   = Q_ref v / ( v_ref^(1/3) (v^2 + v_lin^2)^(1/3) ) ~ Q_ref cbrt(v / v_ref)
//! ```
//!
//! Interpretations (the seed is wrong or silent):
//! * **(3.45) applies the square root twice** (`c_d A_v x_v sqrt(2 dP/rho) sqrt(dP)`),
//!   which is dimensionally wrong; we use the by-pass flow exactly as in (3.44).
//! * **Regularisation**: the orifice law `sqrt(|dP|) sign(dP)` has infinite slope at
//!   `dP = 0`; `g` replaces it by a laminar (linear) law for `|dP| << dP_t` and is
//!   smooth everywhere (`dP_t` = `laminar_pressure_pa`). The cubic-root velocity
//!   function of (3.43)/Fig. 3.8 is likewise given a linear core below `v_lin`.
//! * **Signs**: elongation velocity `v > 0` is extension; it compresses the rebound
//!   chamber A, so `f(v) > 0` raises `dP` and the force `F = A_eff dP` is positive in
//!   **tension** (opposing extension: `F ~ +c v`).
//! * The constants `C_f`, `K`, `f`, `c_d A_v` are not in the seed: they are calibrated
//!   (see [`SemiActiveParams::default`]) against R1-R2 with Table 3-1's area and a 1 l
//!   chamber; the effective bulk modulus is well below pure oil (entrained air, hoses).
//! * Outputs: `dissipated_power_w = dP (Q_f + Q_v) >= 0` (orifice losses) and
//!   `mechanical_power_w = F v` (power taken from the vehicle; momentarily negative when
//!   the oil compliance gives energy back). The simplified model is not
//!   energy-consistent (f is not `A v`), so their cycle means differ.
//! * The elongation input is not used by the simplified model (force depends on the
//!   velocity history only); it is accepted for interface uniformity.
//!
//! * **Mounting stiffness** (optional, `mounting_stiffness_n_per_m`, default rigid): a spring
//!   `k_m` in series with the damper, as the installation's brackets and bushes are (the seed
//!   names this series stiffness as what limits a closed valve; MPE 2019: about 10 MN/m). The
//!   spring carries the damper force, so the damper's own elongation is the imposed one less
//!   `F/k_m` and its own velocity `w` obeys `k_m (v - w) = A_eff dP'`; with (3.43) this is a
//!   strictly increasing scalar equation for `w`, solved inside every right-hand side
//!   evaluation (the spring deflection is `F/k_m`, not an independent state, because the
//!   mounting has no mass). Measured at 4 Hz, 1 mm, 10 MN/m: c_eq 95.6 -> 84.2 kN s/m at 30 %
//!   (series-spring formula `Z = Z_d k_m / (Z_d + k_m)` from the rigid k_eq/c_eq: 84.1),
//!   325.7 -> 72.7 kN s/m closed (formula 76.1: the closed damper is mostly a 9 MN/m spring).
//!
//! Numerics: see [`crate::ode`] (Rosenbrock ode23s with error control, inputs held).

use serde::{Deserialize, Serialize};

use crate::error::{finite_input, non_negative, positive, ParamError, StepError};
use crate::ode::{integrate, Rhs, SolverSettings};
use crate::valve::{check_opening, ValveModel, ValveParams};

/// Parameters of the simplified semi-active damper (SI units).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SemiActiveParams {
    /// `A_eff` of (3.38), m^2. Table 3-1 piston (annulus) area 25.16 cm^2.
    pub effective_area_m2: f64,
    /// `V0` of (3.41), m^3. Table 3-1 chamber volume 1 l.
    pub chamber_volume_m3: f64,
    /// Effective bulk modulus `K`, Pa. Calibrated (R1-R2); pure oil is ~1.5e9 Pa.
    pub bulk_modulus_pa: f64,
    /// `C_f` of (3.42), m^3/(s Pa^0.5). Calibrated (R1 at 0 % opening).
    pub piston_flow_coeff: f64,
    /// `f(v_ref)` of the cubic-root velocity function (3.43), m^3/s. Calibrated.
    pub velocity_flow_ref_m3ps: f64,
    /// Reference velocity `v_ref` of `f`, m/s.
    pub velocity_ref_mps: f64,
    /// Linear-core velocity `v_lin` of `f`, m/s (regularisation).
    pub velocity_linear_mps: f64,
    /// `c_d` of (3.44), discharge (contraction) coefficient.
    pub valve_discharge_coeff: f64,
    /// `A_v` of (3.44), by-pass passage area when fully open, m^2. Calibrated (R1 at 100 %).
    pub valve_area_m2: f64,
    /// `rho` of (3.44), kg/m^3. Table 3-2 oil density 844.4.
    pub oil_density_kgpm3: f64,
    /// `dP_t`, laminar/turbulent transition pressure of the regularised orifices, Pa.
    pub laminar_pressure_pa: f64,
    /// If set, the valve is fixed at this opening (0..1) and the command is ignored
    /// (passive reference damper: 0.3, seed section 4.3).
    pub fixed_opening: Option<f64>,
    /// Command-to-opening dynamics.
    pub valve: ValveParams,
    /// Internal integrator settings.
    pub solver: SolverSettings,
    /// `k_m`: stiffness of the damper's installation (mountings, brackets, rubber bushes) in
    /// series with the damper, N/m; `None` = rigid. The seed names this series stiffness as
    /// what limits a closed valve; MPE 2019 gives about 10 MN/m for a yaw damper.
    pub mounting_stiffness_n_per_m: Option<f64>,
}

impl Default for SemiActiveParams {
    /// Calibrated (examples/search.rs, examples/calibrate.rs) so that at 4 Hz, +-1 mm
    /// and +-3 mm the peak force is 12-20 kN at 0 % and 0.5-1 kN at 100 % opening (R1)
    /// with the equivalent stiffness at 0 % peaking as high in frequency as R1 allows
    /// (4.76 Hz, with a margin inside R1; see the crate docs). Only the products `K Q_ref`, `K C_f`,
    /// `K c_d A_v` matter for `dP`; `K` is fixed at 3e8 Pa, a fifth of pure oil
    /// (entrained air and hose compliance, REFERENCE.md) and the rest follows.
    fn default() -> Self {
        Self {
            effective_area_m2: 25.16e-4,    // Table 3-1 piston (annulus) area
            chamber_volume_m3: 1e-3,        // Table 3-1 chamber volume
            bulk_modulus_pa: 3.0e8,         // chosen: ~K_oil/5 (air, hoses)
            piston_flow_coeff: 1.6e-7,      // calibrated, R1 at 0 %
            velocity_flow_ref_m3ps: 7.9e-4, // calibrated, R1 at 0 % and k_eq peak
            velocity_ref_mps: 0.1,          // scale of f only
            velocity_linear_mps: 1e-4,      // regularisation of the cubic root
            valve_discharge_coeff: 0.7,     // typical sharp-edged orifice
            valve_area_m2: 3.7e-5,          // calibrated, R1 at 100 % (~6.9 mm bore)
            oil_density_kgpm3: 844.4,       // Table 3-2
            laminar_pressure_pa: 3e5,       // 3 bar laminar core, R1 at 100 % (see docs)
            fixed_opening: None,
            valve: ValveParams::default(),
            solver: SolverSettings::default(),
            mounting_stiffness_n_per_m: None,
        }
    }
}

impl SemiActiveParams {
    /// Passive reference damper: the semi-active damper with the valve fixed at 30 %
    /// (seed section 4.3).
    pub fn passive_reference() -> Self {
        Self::default().with_fixed_opening(0.3)
    }

    /// The same parameters with the valve fixed at `opening` (0..1), ideal valve.
    pub fn with_fixed_opening(self, opening: f64) -> Self {
        Self {
            fixed_opening: Some(opening),
            valve: ValveParams {
                model: ValveModel::Ideal,
                ..self.valve
            },
            ..self
        }
    }

    /// Checks every parameter; the error names the first bad one.
    pub fn validate(&self) -> Result<(), ParamError> {
        positive("effective_area_m2", self.effective_area_m2)?;
        positive("chamber_volume_m3", self.chamber_volume_m3)?;
        positive("bulk_modulus_pa", self.bulk_modulus_pa)?;
        non_negative("piston_flow_coeff", self.piston_flow_coeff)?;
        non_negative("velocity_flow_ref_m3ps", self.velocity_flow_ref_m3ps)?;
        positive("velocity_ref_mps", self.velocity_ref_mps)?;
        positive("velocity_linear_mps", self.velocity_linear_mps)?;
        non_negative("valve_discharge_coeff", self.valve_discharge_coeff)?;
        non_negative("valve_area_m2", self.valve_area_m2)?;
        positive("oil_density_kgpm3", self.oil_density_kgpm3)?;
        positive("laminar_pressure_pa", self.laminar_pressure_pa)?;
        if self.piston_flow_coeff == 0.0 && self.valve_area_m2 * self.valve_discharge_coeff == 0.0 {
            return Err(ParamError::OutOfRange {
                name: "piston_flow_coeff",
                value: 0.0,
                reason: "with a closed by-pass the damper needs C_f > 0",
            });
        }
        if let Some(x) = self.fixed_opening {
            check_opening("fixed_opening", x)?;
        }
        self.valve.validate()?;
        self.solver.validate()?;
        if let Some(k) = self.mounting_stiffness_n_per_m {
            positive("mounting_stiffness_n_per_m", k)?;
        }
        Ok(())
    }

    /// `K/V0`, 1/s per (m^3/s) -> Pa/s per m^3/s.
    pub fn stiffness_ratio(&self) -> f64 {
        self.bulk_modulus_pa / self.chamber_volume_m3
    }

    /// By-pass coefficient at full opening, `c_d A_v sqrt(2/rho)`, m^3/(s Pa^0.5).
    pub fn valve_flow_coeff(&self) -> f64 {
        self.valve_discharge_coeff * self.valve_area_m2 * (2.0 / self.oil_density_kgpm3).sqrt()
    }

    /// Regularised signed square root `g(dP)`, Pa^0.5.
    pub fn orifice_law(&self, dp: f64) -> f64 {
        orifice_law(dp, self.laminar_pressure_pa)
    }

    /// Velocity function `f(v)` of (3.43), m^3/s (cubic-root shaped).
    pub fn velocity_flow(&self, v: f64) -> f64 {
        self.velocity_flow_with(v, self.velocity_ref_mps.cbrt())
    }

    /// [`Self::velocity_flow`] with `v_ref^(1/3)` computed by the caller (once per damper).
    fn velocity_flow_with(&self, v: f64, velocity_ref_cbrt: f64) -> f64 {
        let vl = self.velocity_linear_mps;
        let m = v.abs().max(vl);
        if (SQUARE_TINY..SQUARE_SAFE).contains(&m) {
            self.velocity_flow_ref_m3ps * v / (velocity_ref_cbrt * (v * v + vl * vl).cbrt())
        } else if m == 0.0 {
            0.0
        } else {
            // v^2 would overflow (f = 0) or underflow (0/0 at rest with a tiny v_lin): scale by
            // m, (v^2 + vl^2)^(1/3) = m^(2/3) (..)^(1/3).
            let (a, b) = (v / m, vl / m);
            let c = m.cbrt();
            self.velocity_flow_ref_m3ps * (v / (c * c * velocity_ref_cbrt * (a * a + b * b).cbrt()))
        }
    }

    /// Total orifice coefficient at opening `x` (piston + by-pass), m^3/(s Pa^0.5).
    pub fn total_flow_coeff(&self, x: f64) -> f64 {
        self.piston_flow_coeff + self.valve_flow_coeff() * x.clamp(0.0, 1.0)
    }
}

/// `g(dP) = dP / (dP^2 + dP_t^2)^(1/4)`: signed square root with a laminar core.
pub fn orifice_law(dp: f64, dp_t: f64) -> f64 {
    let m = dp.abs().max(dp_t.abs());
    if (SQUARE_TINY..SQUARE_SAFE).contains(&m) {
        dp / (dp * dp + dp_t * dp_t).sqrt().sqrt()
    } else if m == 0.0 {
        0.0
    } else {
        // dp^2 would overflow (g = 0) or underflow (0/0 at dP = 0 with a tiny dP_t): scale by m.
        let (a, b) = (dp / m, dp_t / m);
        dp / (m.sqrt() * (a * a + b * b).sqrt().sqrt())
    }
}

/// Between these magnitudes a square neither overflows nor underflows (the plain formulas are
/// used, bit for bit); outside, the regularised laws are evaluated in scaled form instead of
/// silently returning 0, or 0/0, for absurd but finite inputs and parameters.
const SQUARE_SAFE: f64 = 1e150;
const SQUARE_TINY: f64 = 1e-150;

/// Inputs of one communication step (held constant over the step).
#[derive(Clone, Copy, Debug, PartialEq, Default, Serialize, Deserialize)]
pub struct SemiActiveInputs {
    /// Damper elongation, m (positive = extension). Not used by the simplified model.
    pub elongation_m: f64,
    /// Elongation velocity, m/s (positive = extension).
    pub elongation_velocity_mps: f64,
    /// Valve command, V (0 = closed, 10 = fully open).
    pub valve_command_v: f64,
}

/// Outputs at the current time.
#[derive(Clone, Copy, Debug, PartialEq, Default, Serialize, Deserialize)]
pub struct SemiActiveOutputs {
    /// Damper force, N, positive in tension (opposes extension).
    pub force_n: f64,
    /// Pressure difference `P_A - P_B`, Pa.
    pub pressure_difference_pa: f64,
    /// Actual valve opening, 0..1.
    pub valve_opening: f64,
    /// Commanded valve opening after clamping, 0..1.
    pub valve_opening_command: f64,
    /// True if the last command was outside 0..10 V and was clamped (log a warning).
    pub command_clamped: bool,
    /// Orifice loss power `dP (Q_f + Q_v)`, W (>= 0).
    pub dissipated_power_w: f64,
    /// Power taken from the vehicle `F v`, W.
    pub mechanical_power_w: f64,
}

/// Semi-active (or passive, with a fixed opening) yaw damper: parameters + state.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SemiActiveDamper {
    params: SemiActiveParams,
    /// Pressure difference `dP`, Pa.
    dp_pa: f64,
    /// Actual valve opening, 0..1.
    opening: f64,
    /// Simulated time, s.
    time_s: f64,
    /// Last proposed internal step size, s.
    h_internal_s: f64,
    /// Inputs used for the outputs (last step's).
    inputs: SemiActiveInputs,
    /// Last commanded opening and clamp flag.
    opening_command: f64,
    command_clamped: bool,
    /// `v_ref^(1/3)` of the velocity function, derived from the parameters once.
    velocity_ref_cbrt: f64,
}

struct SemiRhs<'a> {
    p: &'a SemiActiveParams,
    k_over_v: f64,
    cf: f64,
    cv: f64,
    /// `f(v)` of the imposed velocity (rigid mounting).
    q_in: f64,
    /// Imposed elongation velocity `v`, m/s.
    v_in: f64,
    /// `k_m / A_eff`, Pa/m, with a mounting spring.
    mount_pa_per_m: Option<f64>,
    x_cmd: f64,
}

impl SemiRhs<'_> {
    /// The damper's own elongation velocity `w` behind a mounting spring `k_m`: the spring
    /// carries the damper force, `k_m (v - w) = A_eff dP'`, and `dP' = K/V0 (f(w) - q_out)`
    /// (3.43), so `w` is the root of the strictly increasing
    /// `phi(w) = K/V0 f(w) + k_m/A_eff w - (K/V0 q_out + k_m/A_eff v)`.
    /// `phi(v) = K/V0 (f(v) - q_out)`, and `lo = v - phi(v) / (k_m/A_eff)` has the opposite
    /// sign (`phi(lo) = K/V0 (f(lo) - f(v))`), so the root is bracketed; it is found by the
    /// Illinois variant of regula falsi to a few ulps (deterministic, allocation-free).
    fn damper_velocity(&self, b: f64, q_out: f64) -> f64 {
        let a = self.k_over_v;
        let v = self.v_in;
        let phi = |w: f64| a * (self.p.velocity_flow(w) - q_out) + b * (w - v);
        let phi_v = phi(v);
        if phi_v == 0.0 || !phi_v.is_finite() {
            return v;
        }
        let other = v - phi_v / b;
        let (mut lo, mut hi) = if phi_v > 0.0 { (other, v) } else { (v, other) };
        let (mut f_lo, mut f_hi) = (phi(lo), phi(hi));
        let mut side = 0i8;
        for _ in 0..200 {
            if f_lo >= 0.0 {
                return lo;
            }
            if f_hi <= 0.0 {
                return hi;
            }
            let w = (lo * f_hi - hi * f_lo) / (f_hi - f_lo);
            let w = if w > lo && w < hi { w } else { 0.5 * (lo + hi) };
            if w <= lo || w >= hi {
                // The bracket is a few ulps wide.
                return w.clamp(lo, hi);
            }
            let f = phi(w);
            if f == 0.0 {
                return w;
            }
            if f < 0.0 {
                lo = w;
                f_lo = f;
                if side == -1 {
                    f_hi *= 0.5;
                }
                side = -1;
            } else {
                hi = w;
                f_hi = f;
                if side == 1 {
                    f_lo *= 0.5;
                }
                side = 1;
            }
        }
        0.5 * (lo + hi)
    }
}

impl SemiRhs<'_> {
    /// `dP'` at pressure difference `dp` and valve opening `x` (clamped to 0..1).
    fn pressure_rate(&self, dp: f64, x: f64) -> f64 {
        let x = x.clamp(0.0, 1.0);
        let g = orifice_law(dp, self.p.laminar_pressure_pa);
        // (3.43) + (3.44): piston flow and by-pass flow leave the pressure difference.
        let q_out = (self.cf + self.cv * x) * g;
        let q_in = match self.mount_pa_per_m {
            None => self.q_in,
            Some(b) => self.p.velocity_flow(self.damper_velocity(b, q_out)),
        };
        self.k_over_v * (q_in - q_out)
    }
}

impl Rhs<2> for SemiRhs<'_> {
    fn rhs(&self, y: &[f64; 2]) -> [f64; 2] {
        [
            self.pressure_rate(y[0], y[1]),
            self.p.valve.opening_rate(y[1], self.x_cmd),
        ]
    }

    fn frozen(&self) -> [bool; 2] {
        // an ideal valve's opening is held at the command (opening_rate = 0)
        [false, self.p.valve.model == ValveModel::Ideal]
    }
}

/// The damper with an ideal valve: the opening is the command over the whole step, so the
/// pressure difference is the only state. Integrated alone it gives bit for bit the two-state
/// step (the opening's row and column of `W = I - h d J` are those of the identity, its stage
/// increments and error are exactly zero) at a quarter of the linear algebra.
struct IdealValveRhs<'a> {
    sys: SemiRhs<'a>,
    opening: f64,
}

impl Rhs<1> for IdealValveRhs<'_> {
    fn rhs(&self, y: &[f64; 1]) -> [f64; 1] {
        [self.sys.pressure_rate(y[0], self.opening)]
    }
}

impl SemiActiveDamper {
    /// New damper at rest (`dP = 0`), valve at the fixed opening or closed.
    pub fn new(params: SemiActiveParams) -> Result<Self, ParamError> {
        params.validate()?;
        let opening = params.fixed_opening.unwrap_or(0.0);
        Ok(Self {
            params,
            dp_pa: 0.0,
            opening,
            time_s: 0.0,
            h_internal_s: 1e-4,
            inputs: SemiActiveInputs::default(),
            opening_command: opening,
            command_clamped: false,
            velocity_ref_cbrt: params.velocity_ref_mps.cbrt(),
        })
    }

    /// Passive reference damper (30 % fixed opening).
    pub fn passive_reference() -> Result<Self, ParamError> {
        Self::new(SemiActiveParams::passive_reference())
    }

    /// Whether this damper is one [`Self::new`] can give with `params` (and steps since): the
    /// same parameters, valid, and what was derived from them at construction. A damper
    /// decoded from bytes someone altered is refused by this before it steps.
    pub fn is_built_from(&self, params: &SemiActiveParams) -> bool {
        self.params == *params
            && params.validate().is_ok()
            && self.velocity_ref_cbrt.to_bits() == params.velocity_ref_mps.cbrt().to_bits()
    }

    /// Parameters in use.
    pub fn params(&self) -> &SemiActiveParams {
        &self.params
    }

    /// Simulated time, s.
    pub fn time_s(&self) -> f64 {
        self.time_s
    }

    /// Sets the actual valve opening (initialisation), 0..1.
    pub fn set_opening(&mut self, opening: f64) -> Result<(), ParamError> {
        check_opening("opening", opening)?;
        self.opening = opening;
        self.opening_command = opening;
        Ok(())
    }

    /// Sets the pressure difference state (initialisation), Pa.
    pub fn set_pressure_difference(&mut self, dp_pa: f64) -> Result<(), ParamError> {
        if !dp_pa.is_finite() {
            return Err(ParamError::NotFinite {
                name: "pressure_difference_pa",
                value: dp_pa,
            });
        }
        self.dp_pa = dp_pa;
        Ok(())
    }

    /// Sets the inputs seen by [`Self::outputs`] without stepping (initialisation).
    /// Also applies the command to an ideal valve.
    pub fn set_inputs(&mut self, inputs: &SemiActiveInputs) -> Result<(), StepError> {
        let x_cmd = self.check_inputs(inputs)?;
        self.inputs = *inputs;
        if self.params.valve.model == ValveModel::Ideal {
            self.opening = x_cmd;
        }
        Ok(())
    }

    fn check_inputs(&mut self, inputs: &SemiActiveInputs) -> Result<f64, StepError> {
        finite_input("elongation_m", inputs.elongation_m)?;
        finite_input("elongation_velocity_mps", inputs.elongation_velocity_mps)?;
        let (x_cmd, clamped) = match self.params.fixed_opening {
            Some(x) => (x, false),
            None => {
                let c = self.params.valve.command(inputs.valve_command_v)?;
                (c.opening, c.clamped)
            }
        };
        self.opening_command = x_cmd;
        self.command_clamped = clamped;
        Ok(x_cmd)
    }

    /// Advances the model by `h` seconds with inputs held constant.
    ///
    /// Atomic: on error (bad input, integrator failure such as
    /// `solver.max_internal_steps` reached, non-finite state or output) the model is left
    /// exactly as it was, so [`Self::outputs`] still returns the last (finite) outputs and
    /// the caller may retry with a smaller step or other inputs.
    pub fn step(
        &mut self,
        h: f64,
        inputs: &SemiActiveInputs,
    ) -> Result<SemiActiveOutputs, StepError> {
        // Plain data: the copy is a memcpy, no allocation.
        let mut next = self.clone();
        let out = next.advance(h, inputs)?;
        *self = next;
        Ok(out)
    }

    fn advance(
        &mut self,
        h: f64,
        inputs: &SemiActiveInputs,
    ) -> Result<SemiActiveOutputs, StepError> {
        if !(h.is_finite() && h > 0.0) {
            return Err(StepError::BadStepSize { h });
        }
        let x_cmd = self.check_inputs(inputs)?;
        self.inputs = *inputs;
        if self.params.valve.model == ValveModel::Ideal {
            self.opening = x_cmd;
        }
        let p = &self.params;
        let sys = SemiRhs {
            p,
            k_over_v: p.stiffness_ratio(),
            cf: p.piston_flow_coeff,
            cv: p.valve_flow_coeff(),
            q_in: p.velocity_flow_with(inputs.elongation_velocity_mps, self.velocity_ref_cbrt),
            v_in: inputs.elongation_velocity_mps,
            mount_pa_per_m: p
                .mounting_stiffness_n_per_m
                .map(|k| k / p.effective_area_m2),
            x_cmd,
        };
        // Absolute tolerances: 1 Pa (0.0025 N of force), 1e-9 of opening.
        let (atol_pa, atol_opening) = (1.0, 1e-9);
        let mut h_int = self.h_internal_s;
        let y = if p.valve.model == ValveModel::Ideal {
            let sys = IdealValveRhs {
                sys,
                opening: self.opening,
            };
            let mut y = [self.dp_pa];
            integrate(&sys, &mut y, &[atol_pa], h, &mut h_int, &p.solver)?;
            [y[0], self.opening]
        } else {
            let mut y = [self.dp_pa, self.opening];
            integrate(
                &sys,
                &mut y,
                &[atol_pa, atol_opening],
                h,
                &mut h_int,
                &p.solver,
            )?;
            y
        };
        if !(y[0].is_finite() && y[1].is_finite()) {
            return Err(StepError::NonFinite {
                name: "pressure_difference_pa",
            });
        }
        self.dp_pa = y[0];
        self.opening = y[1].clamp(0.0, 1.0);
        self.h_internal_s = h_int;
        self.time_s += h;
        self.outputs()
    }

    /// Outputs at the current time (no stepping).
    pub fn outputs(&self) -> Result<SemiActiveOutputs, StepError> {
        let p = &self.params;
        let dp = self.dp_pa;
        let force = p.effective_area_m2 * dp; // (3.38)
        let q = p.total_flow_coeff(self.opening) * orifice_law(dp, p.laminar_pressure_pa);
        let out = SemiActiveOutputs {
            force_n: force,
            pressure_difference_pa: dp,
            valve_opening: self.opening,
            valve_opening_command: self.opening_command,
            command_clamped: self.command_clamped,
            dissipated_power_w: dp * q,
            mechanical_power_w: force * self.inputs.elongation_velocity_mps,
        };
        for (name, v) in [
            ("force_n", out.force_n),
            ("dissipated_power_w", out.dissipated_power_w),
            ("mechanical_power_w", out.mechanical_power_w),
        ] {
            if !v.is_finite() {
                return Err(StepError::NonFinite { name });
            }
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The ideal valve's one-state step against the two-state one it replaces: equal bits over
    /// a stroke with sign changes, at a fixed opening and with a mounting spring.
    #[test]
    fn ideal_valve_one_state_step_is_the_two_state_step_bit_for_bit() {
        for p in [
            SemiActiveParams::passive_reference(),
            SemiActiveParams {
                mounting_stiffness_n_per_m: Some(1e7),
                ..SemiActiveParams::default().with_fixed_opening(0.6)
            },
        ] {
            let opening = p.fixed_opening.unwrap_or(0.0);
            let (mut one, mut two) = ([0.0], [0.0, opening]);
            let (mut h_one, mut h_two) = (1e-4, 1e-4);
            for k in 0..400 {
                let t = k as f64 * 1e-3;
                let v = 0.075 * (25.0 * t).cos() + 0.02 * (107.0 * t).cos();
                let sys = || SemiRhs {
                    p: &p,
                    k_over_v: p.stiffness_ratio(),
                    cf: p.piston_flow_coeff,
                    cv: p.valve_flow_coeff(),
                    q_in: p.velocity_flow(v),
                    v_in: v,
                    mount_pa_per_m: p
                        .mounting_stiffness_n_per_m
                        .map(|k| k / p.effective_area_m2),
                    x_cmd: opening,
                };
                let single = IdealValveRhs {
                    sys: sys(),
                    opening,
                };
                integrate(&single, &mut one, &[1.0], 1e-3, &mut h_one, &p.solver).unwrap();
                integrate(&sys(), &mut two, &[1.0, 1e-9], 1e-3, &mut h_two, &p.solver).unwrap();
                assert_eq!(one[0].to_bits(), two[0].to_bits(), "step {k}");
                assert_eq!(h_one.to_bits(), h_two.to_bits(), "step {k}");
                assert_eq!(two[1], opening);
            }
            assert!(
                one[0].abs() > 1e5,
                "the stroke loads the damper: {}",
                one[0]
            );
        }
    }
}
