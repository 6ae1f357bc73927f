//! Full-active hydraulic actuator (Ruderman), seed section 3.4: full-order model
//! (3.46)-(3.59), reduced-order model (3.60)-(3.66) and linearised transfer functions
//! (3.67)-(3.73). Defaults are Table 3-2.
//!
//! # State and models
//! State vector `y = [v, v', P_A, P_B, x, x']` (spool position m, spool velocity m/s,
//! chamber pressures Pa, rod position m, rod velocity m/s) for every mode:
//! * [`ActuatorModel::FullOrder`]: spool 2nd order (3.48) driven by `u`; orifice state
//!   `z = h(v)` (3.47); chamber flows (3.50)-(3.52); pressures with leakage
//!   (3.53)-(3.57); rod (3.58) with Stribeck friction (3.59).
//! * [`ActuatorModel::ReducedOrder`]: `v = u` (3.60) (spool states frozen at `u`, 0);
//!   one load-pressure equation (3.65) with load flow (3.63); `P_A`, `P_B` follow
//!   (3.64) so that `P_A - P_B = P_L` is the state; rod (3.66).
//! * [`RodMode::Free`]: the rod moves under the pressure force, friction and the
//!   external load `F_L` (input `load_force_n`, positive opposing extension, as in
//!   (3.58)). Used for the FRF characterisation.
//! * [`RodMode::Imposed`]: the rod follows the vehicle: `x = elongation_m` and
//!   `x' = elongation_velocity_mps` at the start of the step, `x` advances with the
//!   held velocity, and the rod inertia is carried by the vehicle model.
//! * Imposed with a mounting spring (`mounting_stiffness_n_per_m = Some(k_m)`): the vehicle
//!   moves the far end of a spring `k_m` (the installation's brackets and bushes); the piston
//!   and rod (`moving_mass_kg`, Table 3-2: 12.39 kg) move under (3.58) with the spring as the
//!   load, `m x'' = P_A A_A - P_B A_B - f(x') + k_m e`, and the spring's extension
//!   `e' = v_vehicle - x'` is one extra state; the force on the vehicle is the spring's
//!   `k_m e`. The run starts quasi-static (rod moving with the vehicle, spring carrying the
//!   force). Table 3-2's Stribeck drop (F_s = 900 N > F_c = 600 N) makes the friction slope
//!   negative at a few mm/s (down to about -13 kN s/m against c = 2 kN s/m): behind a mounting
//!   stiffer than about 1e8 N/m the rod mode then chatters when the rod velocity crosses that
//!   band, so a very stiff mounting does not tend to the rigid model (which has no rod
//!   inertia); without the drop it does (tests/mounting.rs). At the realistic 10 MN/m the
//!   rod mode (about 900 rad/s) runs smoothly.
//!
//! # Force output and signs
//! `push_force_n = P_A A_A - P_B A_B - f(x')` is the pressure force minus friction:
//! the force the actuator exerts on the bogie along the extension direction (in
//! imposed mode the rod mass is the vehicle's business; in free mode it is the force
//! on the load). `force_n = -push_force_n` follows the semi-active damper's
//! convention (positive = tension, opposing extension), so both dampers plug into the
//! vehicle the same way.
//!
//! # Units
//! The command `u` is the spool position demand in metres (unit static gain of (3.46));
//! the useful range is `|u| <= alpha + beta`: beyond it the orifice saturates at
//! `alpha` (Table 3-2: alpha = 1 mm, beta = 0.3 mm).
//!
//! # Interpretations (seed errors and gaps)
//! * (3.47) prints the dead-zone condition as `|v| >= beta`; it is `|v| < beta`
//!   (zero flow inside the dead zone). With Table 3-2, `|u| = 0.3 alpha = beta` gives no
//!   flow at all at low frequency.
//! * `C_L` of Table 3-2 (printed "l/s") is a leakage coefficient per pascal,
//!   m^3/(s Pa): 7e-10.
//! * **Factor 1/2 in (3.63)**: it follows from (3.50) with (3.64)
//!   (`P_S - P_A = (P_S - P_L)/2`), so we keep it (`load_flow_half_factor = true`) in
//!   the reduced model *and* in the linearised coefficients, i.e.
//!   `C_q = K sqrt((P_S - P_L)/2)`, `C_qp = K z / (2 sqrt(2 (P_S - P_L)))`, instead of
//!   (3.70)-(3.71) which drop it. Setting the flag to `false` reproduces the seed's
//!   (3.70)-(3.71) literally (then the reduced model flows sqrt(2) more than the full one).
//! * The square-root orifice laws are regularised with a laminar core
//!   (`orifice_laminar_pressure_pa`, see [`crate::semi_active::orifice_law`]); a
//!   negative pressure drop reverses the flow instead of giving NaN.
//! * `sign(x')` in (3.59) is regularised as `tanh(x'/friction_reg_velocity_mps)`.
//! * (3.64) assumes `P_T = 0`; the reduced model uses `P_A,B = (P_S + P_T +- P_L)/2`.
//! * No cavitation model: pressures may go below zero under violent imposed motion.
//!
//! Numerics: see [`crate::ode`].

use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

use crate::error::{finite_input, non_negative, positive, ParamError, StepError};
use crate::ode::{integrate, Rhs, SolverSettings};
use crate::semi_active::orifice_law;
use num_complex::Complex64;

/// `C_L` if Table 3-2's "7e-10 l/s" is read as litres per second per pascal
/// (7e-13 m^3/(s Pa), a typical servo-cylinder value). The default follows the
/// project's reading, 7e-10 m^3/(s Pa); see the crate docs for the consequence.
pub const LEAKAGE_LITRE_READING_M3PS_PER_PA: f64 = 7e-13;

/// Which actuator model to integrate.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum ActuatorModel {
    /// (3.46)-(3.59), spool dynamics included.
    #[default]
    FullOrder,
    /// (3.60)-(3.66), spool dynamics neglected.
    ReducedOrder,
}

/// How the rod moves.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum RodMode {
    /// Rod free under the external load F_L (characterisation).
    Free,
    /// Rod motion imposed by the vehicle (co-simulation).
    #[default]
    Imposed,
}

/// Actuator parameters (SI units). Defaults: Table 3-2 of the seed.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ActuatorParams {
    /// Model order.
    pub model: ActuatorModel,
    /// Rod mode.
    pub rod: RodMode,
    /// Orifice saturation `alpha`, m (Table 3-2: 1e-3).
    pub alpha_m: f64,
    /// Dead-zone size `beta`, m (Table 3-2: 3e-4).
    pub beta_m: f64,
    /// Spool loop eigenfrequency `omega_0`, rad/s (Table 3-2: 1200).
    pub valve_natural_freq_radps: f64,
    /// Spool loop damping `xi` (Table 3-2: 0.7).
    pub valve_damping_ratio: f64,
    /// Orifice discharge coefficient `C_d` (Table 3-2: 0.65).
    pub discharge_coeff: f64,
    /// Orifice area gradient `w`, m (Table 3-2: 0.02).
    pub orifice_width_m: f64,
    /// Oil density `rho`, kg/m^3 (Table 3-2: 844.4).
    pub oil_density_kgpm3: f64,
    /// Bulk modulus `E`, Pa (Table 3-2: 1e8).
    pub bulk_modulus_pa: f64,
    /// Supply pressure `P_S`, Pa (Table 3-2: 1e7).
    pub supply_pressure_pa: f64,
    /// Tank pressure `P_T`, Pa (Table 3-2: 0).
    pub tank_pressure_pa: f64,
    /// Internal leakage `C_L`, m^3/(s Pa) (Table 3-2: 7e-10, printed "l/s").
    pub leakage_coeff_m3ps_per_pa: f64,
    /// Piston area chamber A, m^2 (Table 3-2: 25.16e-4).
    pub area_a_m2: f64,
    /// Piston area chamber B, m^2 (Table 3-2: 25.16e-4).
    pub area_b_m2: f64,
    /// Chamber A volume at x = 0, m^3 (Table 3-2: 1e-3).
    pub volume_a0_m3: f64,
    /// Chamber B volume at x = 0, m^3 (Table 3-2: 1e-3).
    pub volume_b0_m3: f64,
    /// Piston + rod mass `m`, kg (Table 3-2: 12.39).
    pub moving_mass_kg: f64,
    /// Coulomb friction `F_c`, N (Table 3-2: 600).
    pub coulomb_friction_n: f64,
    /// Stribeck (static) friction `F_s`, N (Table 3-2: 900).
    pub stribeck_friction_n: f64,
    /// Viscous friction `c` (= sigma of (3.69), (3.73)), N s/m (Table 3-2: 2000).
    pub viscous_friction_nspm: f64,
    /// Stribeck velocity `chi`, m/s (Table 3-2: 0.02).
    pub stribeck_velocity_mps: f64,
    /// Stribeck shape exponent `delta` (Table 3-2: 0.8).
    pub stribeck_exponent: f64,
    /// Half stroke `h` of sat_h in (3.56)-(3.57), m (Table 3-2: 0.18).
    pub half_stroke_m: f64,
    /// Laminar core of the regularised orifice laws, Pa.
    pub orifice_laminar_pressure_pa: f64,
    /// Velocity scale of the regularised sign() in the friction law, m/s.
    pub friction_reg_velocity_mps: f64,
    /// Keep the 1/2 under the root of (3.63) (see module docs).
    pub load_flow_half_factor: bool,
    /// Internal integrator settings.
    pub solver: SolverSettings,
    /// `k_m`: stiffness of the actuator's installation in series with it, N/m; `None` =
    /// rigid. Imposed-rod mode only: the vehicle then moves the far end of the mounting
    /// spring, and the piston and rod (`moving_mass_kg`) move under pressure force, friction
    /// and the spring force (see the module docs).
    pub mounting_stiffness_n_per_m: Option<f64>,
}

impl Default for ActuatorParams {
    fn default() -> Self {
        Self {
            model: ActuatorModel::FullOrder,
            rod: RodMode::Imposed,
            alpha_m: 1e-3,
            beta_m: 3e-4,
            valve_natural_freq_radps: 1200.0,
            valve_damping_ratio: 0.7,
            discharge_coeff: 0.65,
            orifice_width_m: 0.02,
            oil_density_kgpm3: 844.4,
            bulk_modulus_pa: 1e8,
            supply_pressure_pa: 1e7,
            tank_pressure_pa: 0.0,
            leakage_coeff_m3ps_per_pa: 7e-10,
            area_a_m2: 25.16e-4,
            area_b_m2: 25.16e-4,
            volume_a0_m3: 1e-3,
            volume_b0_m3: 1e-3,
            moving_mass_kg: 12.39,
            coulomb_friction_n: 600.0,
            stribeck_friction_n: 900.0,
            viscous_friction_nspm: 2000.0,
            stribeck_velocity_mps: 0.02,
            stribeck_exponent: 0.8,
            half_stroke_m: 0.18,
            orifice_laminar_pressure_pa: 1e4,
            friction_reg_velocity_mps: 1e-3,
            load_flow_half_factor: true,
            solver: SolverSettings {
                rtol: 1e-6,
                ..SolverSettings::default()
            },
            mounting_stiffness_n_per_m: None,
        }
    }
}

/// Stiffest mounting behind which the rod mode runs smoothly with a Stribeck drop
/// (F_s > F_c) \[N/m\]: stiffer, the negative friction slope at a few mm/s makes the rod mode
/// chatter (see the module docs and tests/mounting.rs).
pub const SMOOTH_MOUNTING_LIMIT_N_PER_M: f64 = 1e8;

impl ActuatorParams {
    /// Whether the imposed rod sits behind a mounting stiffer than
    /// [`SMOOTH_MOUNTING_LIMIT_N_PER_M`] with a friction that drops with speed: its force then
    /// chatters and is not a rigid mounting's (the caller warns; rigid is `None`).
    pub fn mounting_chatters(&self) -> bool {
        self.rod == RodMode::Imposed
            && self.stribeck_friction_n > self.coulomb_friction_n
            && self
                .mounting_stiffness_n_per_m
                .is_some_and(|k| k > SMOOTH_MOUNTING_LIMIT_N_PER_M)
    }

    /// Checks every parameter; the error names the first bad one.
    pub fn validate(&self) -> Result<(), ParamError> {
        positive("alpha_m", self.alpha_m)?;
        non_negative("beta_m", self.beta_m)?;
        positive("valve_natural_freq_radps", self.valve_natural_freq_radps)?;
        positive("valve_damping_ratio", self.valve_damping_ratio)?;
        positive("discharge_coeff", self.discharge_coeff)?;
        positive("orifice_width_m", self.orifice_width_m)?;
        positive("oil_density_kgpm3", self.oil_density_kgpm3)?;
        positive("bulk_modulus_pa", self.bulk_modulus_pa)?;
        positive("supply_pressure_pa", self.supply_pressure_pa)?;
        non_negative("tank_pressure_pa", self.tank_pressure_pa)?;
        if self.tank_pressure_pa >= self.supply_pressure_pa {
            return Err(ParamError::OutOfRange {
                name: "tank_pressure_pa",
                value: self.tank_pressure_pa,
                reason: "must be below supply_pressure_pa",
            });
        }
        non_negative("leakage_coeff_m3ps_per_pa", self.leakage_coeff_m3ps_per_pa)?;
        positive("area_a_m2", self.area_a_m2)?;
        positive("area_b_m2", self.area_b_m2)?;
        positive("volume_a0_m3", self.volume_a0_m3)?;
        positive("volume_b0_m3", self.volume_b0_m3)?;
        positive("moving_mass_kg", self.moving_mass_kg)?;
        if let Some(k) = self.mounting_stiffness_n_per_m {
            positive("mounting_stiffness_n_per_m", k)?;
        }
        non_negative("coulomb_friction_n", self.coulomb_friction_n)?;
        non_negative("stribeck_friction_n", self.stribeck_friction_n)?;
        non_negative("viscous_friction_nspm", self.viscous_friction_nspm)?;
        positive("stribeck_velocity_mps", self.stribeck_velocity_mps)?;
        positive("stribeck_exponent", self.stribeck_exponent)?;
        positive("half_stroke_m", self.half_stroke_m)?;
        positive(
            "orifice_laminar_pressure_pa",
            self.orifice_laminar_pressure_pa,
        )?;
        positive("friction_reg_velocity_mps", self.friction_reg_velocity_mps)?;
        if self.volume_a0_m3 <= self.area_a_m2 * self.half_stroke_m {
            return Err(ParamError::OutOfRange {
                name: "volume_a0_m3",
                value: self.volume_a0_m3,
                reason:
                    "chamber A volume must stay > 0 over the stroke (> area_a_m2 * half_stroke_m)",
            });
        }
        if self.volume_b0_m3 <= self.area_b_m2 * self.half_stroke_m {
            return Err(ParamError::OutOfRange {
                name: "volume_b0_m3",
                value: self.volume_b0_m3,
                reason:
                    "chamber B volume must stay > 0 over the stroke (> area_b_m2 * half_stroke_m)",
            });
        }
        self.solver.validate()?;
        Ok(())
    }

    /// Valve flow coefficient `K = C_d w sqrt(2/rho)` (3.52), m^2/sqrt(kg/m^3).
    pub fn valve_gain(&self) -> f64 {
        self.discharge_coeff * self.orifice_width_m * (2.0 / self.oil_density_kgpm3).sqrt()
    }

    /// Dead zone + saturation `z = h(v)` (3.47), with the dead-zone condition corrected
    /// to `|v| < beta`.
    pub fn dead_zone(&self, v: f64) -> f64 {
        let a = v.abs();
        if a >= self.alpha_m + self.beta_m {
            self.alpha_m * v.signum()
        } else if a < self.beta_m {
            0.0
        } else {
            v - self.beta_m * v.signum()
        }
    }

    /// Stribeck friction (3.59), sign() regularised, N.
    pub fn friction(&self, xd: f64) -> f64 {
        let s = (xd / self.friction_reg_velocity_mps).tanh();
        let strib = (-(xd.abs() / self.stribeck_velocity_mps).powf(self.stribeck_exponent)).exp();
        s * (self.coulomb_friction_n + (self.stribeck_friction_n - self.coulomb_friction_n) * strib)
            + self.viscous_friction_nspm * xd
    }

    /// Average piston area `A_bar` of (3.65), m^2.
    pub fn mean_area_m2(&self) -> f64 {
        0.5 * (self.area_a_m2 + self.area_b_m2)
    }

    /// Total volume `V_t` of (3.65), m^3.
    pub fn total_volume_m3(&self) -> f64 {
        self.volume_a0_m3 + self.volume_b0_m3
    }

    /// Cylinder eigenfrequency `omega_c = 2 A_bar sqrt(E / (V_t m))` (3.68), rad/s.
    pub fn cylinder_eigenfrequency_radps(&self) -> f64 {
        2.0 * self.mean_area_m2()
            * (self.bulk_modulus_pa / (self.total_volume_m3() * self.moving_mass_kg)).sqrt()
    }

    /// Cylinder damping ratio `sigma/(4 A_bar) sqrt(V_t/(E m))` (3.69), sigma = viscous c.
    pub fn cylinder_damping_ratio(&self) -> f64 {
        self.viscous_friction_nspm / (4.0 * self.mean_area_m2())
            * (self.total_volume_m3() / (self.bulk_modulus_pa * self.moving_mass_kg)).sqrt()
    }

    fn load_flow_factor(&self) -> f64 {
        if self.load_flow_half_factor {
            0.5
        } else {
            1.0
        }
    }

    /// Load flow (3.63), m^3/s (regularised root).
    pub fn load_flow(&self, z: f64, p_l: f64) -> f64 {
        self.load_flow_with_gain(self.valve_gain(), z, p_l)
    }

    /// [`Self::load_flow`] with the valve gain `k` computed by the caller.
    fn load_flow_with_gain(&self, k: f64, z: f64, p_l: f64) -> f64 {
        let dp = self.supply_pressure_pa - self.tank_pressure_pa - z.signum() * p_l;
        z * k
            * orifice_law(
                self.load_flow_factor() * dp,
                self.orifice_laminar_pressure_pa,
            )
    }

    /// Flow gain `C_q` at `P_L_hat` ((3.70), with the 1/2 per `load_flow_half_factor`).
    pub fn flow_gain(&self, p_l_hat: f64) -> f64 {
        let d = (self.load_flow_factor() * (self.supply_pressure_pa - p_l_hat)).max(0.0);
        self.valve_gain() * d.sqrt()
    }

    /// Flow-pressure coefficient `C_qp` at `(z_hat, P_L_hat)` ((3.71), same convention).
    pub fn flow_pressure_coeff(&self, z_hat: f64, p_l_hat: f64) -> f64 {
        let f = self.load_flow_factor();
        let d = (f * (self.supply_pressure_pa - p_l_hat)).max(1e-300);
        self.valve_gain() * z_hat.abs() * f / (2.0 * d.sqrt())
    }

    /// Spool loop transfer function `v/u` (3.46).
    pub fn valve_tf(&self, s: Complex64) -> Complex64 {
        let w0 = self.valve_natural_freq_radps;
        let w2 = Complex64::from(w0 * w0);
        w2 / (s * s + s.scale(2.0 * self.valve_damping_ratio * w0) + w2)
    }

    /// Cylinder transfer function `x'/Q_L` (3.67), (m/s)/(m^3/s).
    pub fn cylinder_tf(&self, s: Complex64) -> Complex64 {
        let wc = self.cylinder_eigenfrequency_radps();
        let xi = self.cylinder_damping_ratio();
        let den = (s * s).scale(1.0 / (wc * wc)) + s.scale(2.0 * xi / wc) + Complex64::from(1.0);
        Complex64::from(1.0 / self.mean_area_m2()) / den
    }

    /// Linearised reduced-order transfer function `x'/z` (3.73) at `(z_hat, P_L_hat)`.
    pub fn linearised_tf(&self, s: Complex64, z_hat: f64, p_l_hat: f64) -> Complex64 {
        let g = self.cylinder_tf(s);
        let cq = self.flow_gain(p_l_hat);
        let cqp = self.flow_pressure_coeff(z_hat, p_l_hat);
        let ms = s.scale(self.moving_mass_kg) + Complex64::from(self.viscous_friction_nspm);
        let den = Complex64::from(1.0) + (ms * g).scale(cqp / self.mean_area_m2());
        g.scale(cq) / den
    }

    /// Frequency in Hz of an angular frequency (helper for reports).
    pub fn hz(omega: f64) -> f64 {
        omega / (2.0 * PI)
    }
}

/// Describing-function gain of the dead zone + saturation (3.47) for a sinusoid of
/// amplitude `amp`: `N = N_dz(beta) - N_dz(alpha + beta)`, with the classic dead-zone
/// describing function `N_dz(d) = 1 - 2/pi (asin(d/A) + d/A sqrt(1 - (d/A)^2))`.
pub fn dead_zone_describing_gain(p: &ActuatorParams, amp: f64) -> f64 {
    fn ndz(d: f64, a: f64) -> f64 {
        if a <= d {
            0.0
        } else {
            let r = d / a;
            1.0 - 2.0 / PI * (r.asin() + r * (1.0 - r * r).sqrt())
        }
    }
    let a = amp.abs();
    ndz(p.beta_m, a) - ndz(p.alpha_m + p.beta_m, a)
}

/// Inputs of one communication step (held constant over the step).
#[derive(Clone, Copy, Debug, PartialEq, Default, Serialize, Deserialize)]
pub struct ActuatorInputs {
    /// Spool command `u`, m (spool position demand; |u| <= alpha + beta is useful).
    pub spool_command_m: f64,
    /// External load `F_L` of (3.58), N (rod-free mode only).
    pub load_force_n: f64,
    /// Rod elongation, m (imposed mode only; positive = extension, chamber A grows).
    pub elongation_m: f64,
    /// Rod elongation velocity, m/s (imposed mode only).
    pub elongation_velocity_mps: f64,
}

/// Outputs at the current time.
#[derive(Clone, Copy, Debug, PartialEq, Default, Serialize, Deserialize)]
pub struct ActuatorOutputs {
    /// Force, N, positive in tension (same convention as the semi-active damper):
    /// `-(pressure force - friction)`.
    pub force_n: f64,
    /// Pressure force minus friction along the extension direction, N.
    pub push_force_n: f64,
    /// Friction force (3.59), N.
    pub friction_force_n: f64,
    /// Load pressure `P_L = P_A - P_B`, Pa.
    pub load_pressure_pa: f64,
    /// Chamber A pressure, Pa.
    pub pressure_a_pa: f64,
    /// Chamber B pressure, Pa.
    pub pressure_b_pa: f64,
    /// Spool position `v`, m.
    pub spool_position_m: f64,
    /// Orifice state `z`, m.
    pub orifice_state_m: f64,
    /// Rod position `x`, m.
    pub rod_position_m: f64,
    /// Rod velocity `x'`, m/s.
    pub rod_velocity_mps: f64,
    /// Load flow (flow into chamber A), m^3/s.
    pub load_flow_m3ps: f64,
    /// Hydraulic power drawn from the supply, `P_S Q_S - P_T Q_T`, W.
    pub hydraulic_power_w: f64,
    /// Mechanical power delivered to the rod/vehicle `push_force x'`, W.
    pub mechanical_power_w: f64,
}

/// Hydraulic actuator: parameters + state.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Actuator {
    params: ActuatorParams,
    /// `[v, v', P_A, P_B, x, x']`.
    y: [f64; 6],
    /// Extension `e` of the mounting spring (vehicle elongation minus rod position), m; 0
    /// without a mounting spring.
    mount_extension_m: f64,
    time_s: f64,
    h_internal_s: f64,
    inputs: ActuatorInputs,
}

struct ActRhs<'a> {
    p: &'a ActuatorParams,
    /// [`ActuatorParams::valve_gain`], computed once per step.
    valve_gain: f64,
    u: f64,
    f_load: f64,
    xd_in: f64,
}

/// Flows into chambers A and B, and from the supply / to the tank (3.50)-(3.51); `k` is
/// [`ActuatorParams::valve_gain`].
fn chamber_flows(p: &ActuatorParams, k: f64, z: f64, pa: f64, pb: f64) -> (f64, f64, f64, f64) {
    let lam = p.orifice_laminar_pressure_pa;
    let (ps, pt) = (p.supply_pressure_pa, p.tank_pressure_pa);
    if z > 0.0 {
        let qa = z * k * orifice_law(ps - pa, lam);
        let qb = -z * k * orifice_law(pb - pt, lam);
        (qa, qb, qa, -qb)
    } else if z < 0.0 {
        let qa = z * k * orifice_law(pa - pt, lam);
        let qb = -z * k * orifice_law(ps - pb, lam);
        (qa, qb, qb, -qa)
    } else {
        (0.0, 0.0, 0.0, 0.0)
    }
}

impl ActRhs<'_> {
    /// Spool and chamber derivatives `[v', v'', P_A', P_B']` and the pressure force along the
    /// extension direction, for the rod at `x` moving at `xd`.
    fn hydraulics(&self, y: &[f64; 6]) -> ([f64; 4], f64) {
        let p = self.p;
        let [v, vd, pa, pb, x, xd] = *y;
        let mut dy = [0.0; 4];
        let push;
        match p.model {
            ActuatorModel::FullOrder => {
                let w0 = p.valve_natural_freq_radps;
                dy[0] = vd;
                dy[1] = w0 * w0 * (self.u - v) - 2.0 * p.valve_damping_ratio * w0 * vd; // (3.48)
                let z = p.dead_zone(v); // (3.49)
                let (qa, qb, _, _) = chamber_flows(p, self.valve_gain, z, pa, pb);
                let xs = x.clamp(-p.half_stroke_m, p.half_stroke_m);
                let va = p.volume_a0_m3 + p.area_a_m2 * xs; // (3.56)
                let vb = p.volume_b0_m3 - p.area_b_m2 * xs; // (3.57)
                let leak = p.leakage_coeff_m3ps_per_pa * (pa - pb);
                dy[2] = p.bulk_modulus_pa / va * (qa - p.area_a_m2 * xd - leak); // (3.53)
                dy[3] = p.bulk_modulus_pa / vb * (qb + p.area_b_m2 * xd + leak); // (3.54)
                push = pa * p.area_a_m2 - pb * p.area_b_m2;
            }
            ActuatorModel::ReducedOrder => {
                let z = p.dead_zone(self.u); // (3.60)
                let pl = pa - pb;
                let ql = p.load_flow_with_gain(self.valve_gain, z, pl); // (3.63)
                let a = p.mean_area_m2();
                let pl_dot = 4.0 * p.bulk_modulus_pa / p.total_volume_m3()
                    * (ql - a * xd - p.leakage_coeff_m3ps_per_pa * pl); // (3.65)
                dy[2] = 0.5 * pl_dot; // keeps (3.64)
                dy[3] = -0.5 * pl_dot;
                push = pl * a;
            }
        }
        (dy, push)
    }
}

impl Rhs<6> for ActRhs<'_> {
    fn rhs(&self, y: &[f64; 6]) -> [f64; 6] {
        let p = self.p;
        let xd = y[5];
        let (h, push) = self.hydraulics(y);
        let mut dy = [h[0], h[1], h[2], h[3], 0.0, 0.0];
        match p.rod {
            RodMode::Free => {
                dy[4] = xd;
                dy[5] = (push - p.friction(xd) - self.f_load) / p.moving_mass_kg;
                // (3.58)/(3.66)
            }
            RodMode::Imposed => {
                dy[4] = self.xd_in;
                dy[5] = 0.0;
            }
        }
        dy
    }

    fn frozen(&self) -> [bool; 6] {
        let reduced = self.p.model == ActuatorModel::ReducedOrder;
        // reduced order: the spool sits at the command; imposed rod: the velocity is an input
        [
            reduced,
            reduced,
            false,
            false,
            false,
            self.p.rod == RodMode::Imposed,
        ]
    }
}

/// The imposed-rod actuator behind a mounting spring `k_m`: state `[v, v', P_A, P_B, x, x',
/// e]` with `x`, `x'` the piston/rod position and velocity and `e` the spring's extension
/// (vehicle elongation minus rod position). The rod obeys (3.58) with the spring as load,
/// `m x'' = P_A A_A - P_B A_B - f(x') + k_m e`, and `e' = v_vehicle - x'`.
struct MountedRhs<'a> {
    act: ActRhs<'a>,
    k_m: f64,
}

impl Rhs<7> for MountedRhs<'_> {
    fn rhs(&self, y: &[f64; 7]) -> [f64; 7] {
        let p = self.act.p;
        let rod = [y[0], y[1], y[2], y[3], y[4], y[5]];
        let (h, push) = self.act.hydraulics(&rod);
        let xd = y[5];
        let acc = (push - p.friction(xd) + self.k_m * y[6]) / p.moving_mass_kg;
        [h[0], h[1], h[2], h[3], xd, acc, self.act.xd_in - xd]
    }

    fn frozen(&self) -> [bool; 7] {
        // reduced order: the spool sits at the command
        let reduced = self.act.p.model == ActuatorModel::ReducedOrder;
        [reduced, reduced, false, false, false, false, false]
    }
}

impl Actuator {
    /// New actuator at rest: spool centred, `P_A = P_B = (P_S + P_T)/2`, rod at 0.
    pub fn new(params: ActuatorParams) -> Result<Self, ParamError> {
        params.validate()?;
        let p0 = 0.5 * (params.supply_pressure_pa + params.tank_pressure_pa);
        Ok(Self {
            params,
            y: [0.0, 0.0, p0, p0, 0.0, 0.0],
            mount_extension_m: 0.0,
            time_s: 0.0,
            h_internal_s: 1e-5,
            inputs: ActuatorInputs::default(),
        })
    }

    /// Whether this actuator is one [`Self::new`] can give with `params` (and steps since):
    /// the same parameters, and valid. An actuator decoded from bytes someone altered is
    /// refused by this before it steps.
    pub fn is_built_from(&self, params: &ActuatorParams) -> bool {
        self.params == *params && params.validate().is_ok()
    }

    /// Parameters in use.
    pub fn params(&self) -> &ActuatorParams {
        &self.params
    }

    /// Simulated time, s.
    pub fn time_s(&self) -> f64 {
        self.time_s
    }

    /// Raw state `[v, v', P_A, P_B, x, x']`.
    pub fn state(&self) -> [f64; 6] {
        self.y
    }

    fn check_inputs(&self, inputs: &ActuatorInputs) -> Result<(), StepError> {
        finite_input("spool_command_m", inputs.spool_command_m)?;
        finite_input("load_force_n", inputs.load_force_n)?;
        finite_input("elongation_m", inputs.elongation_m)?;
        finite_input("elongation_velocity_mps", inputs.elongation_velocity_mps)?;
        Ok(())
    }

    fn apply_inputs(&mut self, inputs: &ActuatorInputs) {
        self.inputs = *inputs;
        if self.params.model == ActuatorModel::ReducedOrder {
            self.y[0] = inputs.spool_command_m;
            self.y[1] = 0.0;
        }
        if self.params.rod == RodMode::Imposed {
            match self.params.mounting_stiffness_n_per_m {
                None => {
                    self.y[4] = inputs.elongation_m;
                    self.y[5] = inputs.elongation_velocity_mps;
                }
                // The rod's velocity is a state; its position follows the vehicle's elongation
                // less the spring's extension. At the start the rod moves with the vehicle and
                // the spring carries the actuator's force (quasi-static), so a run does not
                // begin with a spring-mass transient nobody asked for.
                Some(k_m) => {
                    if self.time_s == 0.0 {
                        let v = inputs.elongation_velocity_mps;
                        self.y[4] = inputs.elongation_m;
                        self.y[5] = v;
                        let pressure_force = self.pressure_force(inputs.spool_command_m);
                        self.mount_extension_m = -(pressure_force - self.params.friction(v)) / k_m;
                    }
                    self.y[4] = inputs.elongation_m - self.mount_extension_m;
                }
            }
        }
    }

    /// Pressure force on the piston along the extension direction, N.
    fn pressure_force(&self, spool_command_m: f64) -> f64 {
        let rhs = ActRhs {
            p: &self.params,
            valve_gain: self.params.valve_gain(),
            u: spool_command_m,
            f_load: 0.0,
            xd_in: 0.0,
        };
        rhs.hydraulics(&self.y).1
    }

    /// The mounting spring's stiffness if it acts (imposed rod with a mounting), N/m.
    fn mounting(&self) -> Option<f64> {
        match self.params.rod {
            RodMode::Imposed => self.params.mounting_stiffness_n_per_m,
            RodMode::Free => None,
        }
    }

    /// Sets the inputs seen by [`Self::outputs`] without stepping (initialisation).
    pub fn set_inputs(&mut self, inputs: &ActuatorInputs) -> Result<(), StepError> {
        self.check_inputs(inputs)?;
        self.apply_inputs(inputs);
        Ok(())
    }

    /// Advances the model by `h` seconds with inputs held constant.
    ///
    /// Atomic: on error (bad input, integrator failure such as
    /// `solver.max_internal_steps` reached, non-finite state or output) the model is left
    /// exactly as it was, so [`Self::outputs`] still returns the last (finite) outputs and
    /// the caller may retry with a smaller step or other inputs.
    pub fn step(&mut self, h: f64, inputs: &ActuatorInputs) -> Result<ActuatorOutputs, StepError> {
        // Plain data: the copy is a memcpy, no allocation.
        let mut next = self.clone();
        let out = next.advance(h, inputs)?;
        *self = next;
        Ok(out)
    }

    fn advance(&mut self, h: f64, inputs: &ActuatorInputs) -> Result<ActuatorOutputs, StepError> {
        if !(h.is_finite() && h > 0.0) {
            return Err(StepError::BadStepSize { h });
        }
        self.check_inputs(inputs)?;
        self.apply_inputs(inputs);
        let sys = ActRhs {
            p: &self.params,
            valve_gain: self.params.valve_gain(),
            u: inputs.spool_command_m,
            f_load: inputs.load_force_n,
            xd_in: inputs.elongation_velocity_mps,
        };
        let mut y = self.y;
        let atol = self.absolute_tolerances();
        let mut h_int = self.h_internal_s;
        let mut e = self.mount_extension_m;
        match self.mounting() {
            None => integrate(&sys, &mut y, &atol, h, &mut h_int, &self.params.solver)?,
            Some(k_m) => {
                let mounted = MountedRhs { act: sys, k_m };
                let mut y7 = [y[0], y[1], y[2], y[3], y[4], y[5], e];
                let [a0, a1, a2, a3, a4, a5] = atol;
                let atol7 = [a0, a1, a2, a3, a4, a5, 1e-10];
                let n = integrate(
                    &mounted,
                    &mut y7,
                    &atol7,
                    h,
                    &mut h_int,
                    &self.params.solver,
                )?;
                y = [y7[0], y7[1], y7[2], y7[3], y7[4], y7[5]];
                e = y7[6];
                n
            }
        };
        if y.iter().any(|v| !v.is_finite()) || !e.is_finite() {
            return Err(StepError::NonFinite {
                name: "actuator state",
            });
        }
        // an elongation of 100 m gave a normal-looking force with fmi2OK
        if y[4].abs() > self.params.half_stroke_m {
            return Err(StepError::BeyondStroke {
                rod_mm: y[4] * 1e3,
                half_stroke_mm: self.params.half_stroke_m * 1e3,
            });
        }
        self.y = y;
        self.mount_extension_m = e;
        self.h_internal_s = h_int;
        self.time_s += h;
        self.outputs()
    }

    /// Absolute tolerances of the internal error test, per state `[v, v', P_A, P_B, x, x']`:
    /// `solver.rtol` times each state's scale, so that one setting tightens them all. The
    /// spool's scale is 10 times its travel `alpha` and that over its time scale `1/w0`, the
    /// pressures' the supply pressure, the rod's 1 mm and 0.1 m/s. With Table 3-2 and the
    /// default rtol: 1e-8 m, 1.2e-5 m/s, 10 Pa, 1e-9 m, 1e-7 m/s. The spool's set the internal
    /// step: 1e-9 m and 1e-6 m/s took 12.2 internal steps per 1 ms step on the reference
    /// stroke (`perf`), these 6.2, with the force within 8.4e-5 of its amplitude of a run at
    /// rtol 1e-8 (1.7e-5 before; `tests/actuator.rs`).
    fn absolute_tolerances(&self) -> [f64; 6] {
        let p = &self.params;
        let r = p.solver.rtol;
        let spool_m = r * 10.0 * p.alpha_m;
        [
            spool_m,
            spool_m * p.valve_natural_freq_radps,
            r * p.supply_pressure_pa,
            r * p.supply_pressure_pa,
            r * 1e-3,
            r * 0.1,
        ]
    }

    /// The velocity of the point the force acts on: the rod, or the vehicle's end of the
    /// mounting spring.
    fn vehicle_velocity(&self, rod_velocity: f64) -> f64 {
        match self.mounting() {
            None => rod_velocity,
            Some(_) => self.inputs.elongation_velocity_mps,
        }
    }

    /// Outputs at the current time (no stepping).
    pub fn outputs(&self) -> Result<ActuatorOutputs, StepError> {
        let p = &self.params;
        let [v, _, pa, pb, x, xd] = self.y;
        let fr = p.friction(xd);
        let (z, pressure_force, q_load, q_s, q_t) = match p.model {
            ActuatorModel::FullOrder => {
                let z = p.dead_zone(v);
                let (qa, _, qs, qt) = chamber_flows(p, p.valve_gain(), z, pa, pb);
                (z, pa * p.area_a_m2 - pb * p.area_b_m2, qa, qs, qt)
            }
            ActuatorModel::ReducedOrder => {
                let z = p.dead_zone(self.inputs.spool_command_m);
                let ql = p.load_flow(z, pa - pb);
                let qs = z.signum() * ql;
                ((z), (pa - pb) * p.mean_area_m2(), ql, qs, qs)
            }
        };
        // With a mounting spring the vehicle feels the spring, whose tension is k_m e.
        let push = match self.mounting() {
            None => pressure_force - fr,
            Some(k_m) => -(k_m * self.mount_extension_m),
        };
        let out = ActuatorOutputs {
            force_n: -push,
            push_force_n: push,
            friction_force_n: fr,
            load_pressure_pa: pa - pb,
            pressure_a_pa: pa,
            pressure_b_pa: pb,
            spool_position_m: v,
            orifice_state_m: z,
            rod_position_m: x,
            rod_velocity_mps: xd,
            load_flow_m3ps: q_load,
            hydraulic_power_w: p.supply_pressure_pa * q_s - p.tank_pressure_pa * q_t,
            mechanical_power_w: push * self.vehicle_velocity(xd),
        };
        for (name, val) in [
            ("force_n", out.force_n),
            ("load_pressure_pa", out.load_pressure_pa),
            ("hydraulic_power_w", out.hydraulic_power_w),
            ("mechanical_power_w", out.mechanical_power_w),
        ] {
            if !val.is_finite() {
                return Err(StepError::NonFinite { name });
            }
        }
        Ok(out)
    }
}
