//! FMU shell of the full-active hydraulic actuator ([`FullActiveActuator`]), rod imposed by the
//! vehicle.

use model_description::{
    field_error, fmi_enum, DefaultExperiment, Diagnostics, FmuModel, InstanceContext, ModelError,
    ModelInfo, StepError, Variable,
};
use serde::{Deserialize, Serialize};

use super::{not_initialised, restored_physics, step_error, AUTHOR};
use crate::full_active::{
    Actuator, ActuatorInputs, ActuatorModel, ActuatorOutputs, ActuatorParams, RodMode,
    LEAKAGE_LITRE_READING_M3PS_PER_PA, SMOOTH_MOUNTING_LIMIT_N_PER_M,
};

fmi_enum! {
    ActuatorModel as "ActuatorOrder", "Order of the actuator model" {
        FullOrder = 0, "full_order", "(3.46)-(3.59): spool dynamics included";
        ReducedOrder = 1, "reduced_order", "(3.60)-(3.66): the spool follows the command at once";
    }
}

/// Full-active hydraulic actuator FMU (seed 3.4, Table 3-2), rod motion imposed by the vehicle.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct FullActiveActuator {
    params: ActuatorParams,
    inputs: ActuatorInputs,
    actuator: Option<Actuator>,
    out: ActuatorOutputs,
}

impl FullActiveActuator {
    /// The FMU's default parameters: Table 3-2 with the leakage read as litres
    /// (`C_L = 7e-13 m^3/(s Pa)`, see the documentation) and the rod imposed.
    pub fn default_params() -> ActuatorParams {
        ActuatorParams {
            rod: RodMode::Imposed,
            leakage_coeff_m3ps_per_pa: LEAKAGE_LITRE_READING_M3PS_PER_PA,
            ..ActuatorParams::default()
        }
    }

    /// Start values of the inputs (default experiment): rod at rest, spool command 1 mm
    /// (= alpha, the IDF controller's saturation).
    pub fn default_inputs() -> ActuatorInputs {
        ActuatorInputs {
            spool_command_m: 1e-3,
            ..ActuatorInputs::default()
        }
    }
}

impl FmuModel for FullActiveActuator {
    const INFO: ModelInfo = ModelInfo {
        name: "FullActiveActuator",
        description: "Full-active hydraulic yaw actuator (servo valve + double-acting cylinder, \
                      seed (3.46)-(3.66), Table 3-2), full- or reduced-order, rod motion imposed \
                      by the vehicle; force positive in tension",
        author: AUTHOR,
        version: "0.1.0",
        default_experiment: DefaultExperiment {
            start_time: 0.0,
            // 0.25 s is 2500 steps exactly in floating point (0.3 / 1e-4 is not).
            stop_time: 0.25,
            step_size: 1e-4,
        },
        documentation_html: ACTUATOR_DOC,
        resources: &[],
    };

    fn variables() -> Vec<Variable<Self>> {
        let mut v: Vec<Variable<Self>> = Vec::new();
        model_description::declare! { v;
            /// Full order (3.46)-(3.59), spool dynamics included, or reduced order (3.60)-(3.66),
            /// spool follows the command at once
            parameter "actuator.model" => params.model;
            /// alpha of (3.47): orifice opening saturation, Table 3-2
            parameter "valve.saturation" [unit = "m", display_unit = "mm", min = 0.0] => params.alpha_m;
            /// beta of (3.47): spool dead zone (no flow for |v| < beta), Table 3-2
            parameter "valve.dead_zone" [unit = "m", display_unit = "mm", min = 0.0] => params.beta_m;
            /// omega_0 of (3.46): spool loop eigenfrequency, Table 3-2
            parameter "valve.natural_frequency" [unit = "rad/s", min = 0.0] => params.valve_natural_freq_radps;
            /// xi of (3.46): spool loop damping ratio, Table 3-2
            parameter "valve.damping_ratio" [unit = "1", min = 0.0] => params.valve_damping_ratio;
            /// C_d of (3.52), Table 3-2
            parameter "valve.discharge_coefficient" [unit = "1", range = 0.0..=1.0] => params.discharge_coeff;
            /// w of (3.52): orifice area gradient (width), Table 3-2
            parameter "valve.area_gradient" [unit = "m", display_unit = "mm", min = 0.0] => params.orifice_width_m;
            /// Laminar core of the regularised orifice laws (3.50)-(3.51), (3.63)
            parameter "valve.laminar_pressure" [unit = "Pa", display_unit = "bar", min = 0.0] => params.orifice_laminar_pressure_pa;
            /// Reduced order: keep the 1/2 under the root of (3.63) (consistent with (3.50) and
            /// (3.64)); false = drop it as (3.70)-(3.71) do
            parameter "valve.load_flow_half_factor" => params.load_flow_half_factor;
            /// rho of (3.52), Table 3-2
            parameter "oil.density" [unit = "kg/m3", min = 0.0] => params.oil_density_kgpm3;
            /// E of (3.53)-(3.55), Table 3-2
            parameter "oil.bulk_modulus" [unit = "Pa", display_unit = "bar", min = 0.0] => params.bulk_modulus_pa;
            /// P_S of (3.50)-(3.51), Table 3-2
            parameter "supply.pressure" [unit = "Pa", display_unit = "bar", min = 0.0] => params.supply_pressure_pa;
            /// P_T of (3.50)-(3.51), Table 3-2 (must be below supply.pressure)
            parameter "tank.pressure" [unit = "Pa", display_unit = "bar", min = 0.0] => params.tank_pressure_pa;
            /// C_L of (3.53)-(3.54), (3.65): internal leakage per pascal. Table 3-2 prints
            /// "7e-10 l/s": read as litres, 7e-13 m3/(s Pa) (see documentation)
            parameter "cylinder.leakage_coefficient" [unit = "m3/(s.Pa)", min = 0.0] => params.leakage_coeff_m3ps_per_pa;
            /// A_A of (3.53), (3.56): piston area on the chamber A side, Table 3-2
            parameter "cylinder.area_a" [unit = "m2", display_unit = "cm2", min = 0.0] => params.area_a_m2;
            /// A_B of (3.54), (3.57): piston area on the chamber B side, Table 3-2
            parameter "cylinder.area_b" [unit = "m2", display_unit = "cm2", min = 0.0] => params.area_b_m2;
            /// V_A^0 of (3.56): chamber A volume at x = 0, Table 3-2 (must exceed A_A h)
            parameter "cylinder.volume_a0" [unit = "m3", display_unit = "l", min = 0.0] => params.volume_a0_m3;
            /// V_B^0 of (3.57): chamber B volume at x = 0, Table 3-2 (must exceed A_B h)
            parameter "cylinder.volume_b0" [unit = "m3", display_unit = "l", min = 0.0] => params.volume_b0_m3;
            /// h of sat_h in (3.56)-(3.57), Table 3-2
            parameter "cylinder.half_stroke" [unit = "m", display_unit = "mm", min = 0.0] => params.half_stroke_m;
            /// F_c of (3.59), Table 3-2
            parameter "friction.coulomb" [unit = "N", min = 0.0] => params.coulomb_friction_n;
            /// F_s of (3.59): static (Stribeck) friction, Table 3-2
            parameter "friction.stribeck" [unit = "N", min = 0.0] => params.stribeck_friction_n;
            /// c of (3.59): viscous friction, Table 3-2
            parameter "friction.viscous" [unit = "N.s/m", min = 0.0] => params.viscous_friction_nspm;
            /// chi of (3.59): Stribeck velocity, Table 3-2
            parameter "friction.stribeck_velocity" [unit = "m/s", display_unit = "mm/s", min = 0.0] => params.stribeck_velocity_mps;
            /// delta of (3.59): Stribeck shape exponent, Table 3-2
            parameter "friction.stribeck_exponent" [unit = "1", min = 0.0] => params.stribeck_exponent;
            /// Velocity scale of the regularised sign() of (3.59): tanh(x'/v_reg)
            parameter "friction.regularisation_velocity" [unit = "m/s", display_unit = "mm/s", min = 0.0] => params.friction_reg_velocity_mps;

            /// Spool position demand u of (3.46), m; positive feeds chamber A and pushes the rod
            /// out (decreases the tension); beyond alpha + beta the orifice saturates. Its start
            /// value, 1 mm, is the default experiment's step: left unconnected, the actuator
            /// pushes at its force bound
            input "spool.command" [unit = "m", display_unit = "mm"] => inputs.spool_command_m;
            /// Rod position x imposed by the vehicle, positive = extension (chamber A grows)
            input "damper.elongation" [unit = "m", display_unit = "mm"] => inputs.elongation_m;
            /// Rod velocity x' imposed by the vehicle, positive = extension
            input "damper.elongation_velocity" [unit = "m/s", display_unit = "mm/s"] => inputs.elongation_velocity_mps;

            /// Actuator force, positive in tension: -(P_A A_A - P_B A_B - f(x')); the friction
            /// f(x') (3.59) is algebraic in the imposed velocity
            output "damper.force" [unit = "N", display_unit = "kN", depends_on = &["damper.elongation_velocity"]] => out.force_n;
            /// Load pressure P_L = P_A - P_B (3.61)
            output "damper.load_pressure" [unit = "Pa", display_unit = "bar"] => out.load_pressure_pa;
            /// P_A (3.53); reduced order: (P_S + P_T + P_L)/2 (3.64)
            output "chamber_a.pressure" [unit = "Pa", display_unit = "bar"] => out.pressure_a_pa;
            /// P_B (3.54); reduced order: (P_S + P_T - P_L)/2 (3.64)
            output "chamber_b.pressure" [unit = "Pa", display_unit = "bar"] => out.pressure_b_pa;
            /// Spool position v (3.48); reduced order: v = u (3.60)
            output "spool.position" [unit = "m", display_unit = "mm", depends_on = &["spool.command"]] => out.spool_position_m;
            /// Hydraulic power drawn from the supply, P_S Q_S - P_T Q_T
            output "damper.hydraulic_power" [unit = "W", display_unit = "kW", depends_on = &["spool.command"]] => out.hydraulic_power_w;
            /// Friction f(x') of (3.59) at the imposed velocity
            output "damper.friction_force" [unit = "N", depends_on = &["damper.elongation_velocity"]] => out.friction_force_n;
            /// Mechanical power taken from the vehicle, damper.force x damper.elongation_velocity
            /// (negative when the actuator drives the vehicle)
            output "damper.power" [unit = "W", display_unit = "kW", depends_on = &["damper.elongation_velocity"]]
                // 0 - x, not -x: no -0.0 when the power is zero.
                => |m| 0.0 - m.out.mechanical_power_w;
        }
        super::declare_appended_parameters!(v, params);
        v
    }

    fn instantiate(_ctx: &InstanceContext) -> Result<Self, ModelError> {
        Ok(Self {
            params: Self::default_params(),
            inputs: Self::default_inputs(),
            actuator: None,
            out: ActuatorOutputs::default(),
        })
    }

    fn exit_initialization(&mut self, diag: &mut Diagnostics) -> Result<(), ModelError> {
        let mut a = Actuator::new(self.params).map_err(|e| field_error::<Self>(&e))?;
        if self.params.mounting_chatters() {
            diag.warn(format!(
                "damper.mounting_stiffness = {:e} N/m is stiffer than {:e} N/m: with \
                 friction.stribeck above friction.coulomb the rod chatters behind so stiff a \
                 mounting and damper.force is not a rigid mounting's; 0 is rigid",
                self.params.mounting_stiffness_n_per_m.unwrap_or(f64::NAN),
                SMOOTH_MOUNTING_LIMIT_N_PER_M
            ));
        }
        a.set_inputs(&self.inputs)
            .map_err(|e| field_error::<Self>(&e))?;
        self.out = a.outputs().map_err(|e| field_error::<Self>(&e))?;
        self.actuator = Some(a);
        Ok(())
    }

    fn check_restored(&self) -> Result<(), String> {
        restored_physics(
            self.actuator
                .as_ref()
                .map(|a| a.is_built_from(&self.params)),
            "actuator",
        )
    }

    fn update_outputs(&mut self, _diag: &mut Diagnostics) -> Result<(), ModelError> {
        if let Some(a) = &mut self.actuator {
            a.set_inputs(&self.inputs)
                .map_err(|e| field_error::<Self>(&e))?;
            self.out = a.outputs().map_err(|e| field_error::<Self>(&e))?;
        }
        Ok(())
    }

    fn do_step(&mut self, _time: f64, step: f64, _diag: &mut Diagnostics) -> Result<(), StepError> {
        let Some(a) = &mut self.actuator else {
            return Err(not_initialised());
        };
        // Step a copy (plain data, no allocation) and commit on success only.
        let mut next = a.clone();
        let out = next
            .step(step, &self.inputs)
            .map_err(|e| step_error::<Self>(&e))?;
        *a = next;
        self.out = out;
        Ok(())
    }
}

const ACTUATOR_DOC: &str = concat!(
    r#"
<h1>FullActiveActuator</h1>
<p>Full-active hydraulic yaw actuator (Ruderman's model, seed section 3.4): a servo (directional
control) valve feeding a double-acting cylinder. The rod motion is imposed by the vehicle
(inputs <code>damper.elongation</code>, <code>damper.elongation_velocity</code>); the spool command
<code>spool.command</code> comes from the force controller (IDF, (3.14)-(3.15)); the output is the
actuator force, positive in tension like the semi-active damper. The default experiment holds
the rod at rest and commands u = 1 mm: the spool settles within about 5 ms, chamber A fills
through the orifice and chamber B empties within about 0.15 s, and the actuator then pushes
with about -25 kN (P_A near P_S, P_B near P_T: damper.force = -P_S A).</p>

<h2>Full-order model (<code>actuator.model</code> = full_order), (3.46)-(3.59)</h2>
<pre>
v'' + 2 xi omega_0 v' + omega_0^2 v = omega_0^2 u                       (3.46), (3.48)
z = h(v):  alpha sign(v)      if |v| &gt;= alpha + beta
           0                  if |v| &lt;  beta          (dead zone)
           v - beta sign(v)   otherwise                                 (3.47), (3.49)
Q_A = z K sqrt(P_S - P_A) (z &gt; 0),  z K sqrt(P_A - P_T) (z &lt; 0)          (3.50)
Q_B = -z K sqrt(P_B - P_T) (z &gt; 0), -z K sqrt(P_S - P_B) (z &lt; 0)         (3.51)
K   = C_d w sqrt(2/rho)                                                 (3.52)
P_A' = E/V_A (Q_A - A_A x' - C_L (P_A - P_B))                           (3.53)
P_B' = E/V_B (Q_B + A_B x' - C_L (P_B - P_A))                           (3.54)
V_A = V_A^0 + A_A sat_h(x),  V_B = V_B^0 - A_B sat_h(x)                 (3.56), (3.57)
f(x') = sign(x') (F_c + (F_s - F_c) exp(-(|x'|/chi)^delta)) + c x'      (3.59)
damper.force = -(P_A A_A - P_B A_B - f(x'))                             from (3.58)
</pre>
<h2>Reduced-order model (<code>actuator.model</code> = reduced_order), (3.60)-(3.66)</h2>
<pre>
v = u, z = h(u)                                                         (3.60)
P_L = P_A - P_B                                                         (3.61)
Q_L = z K sqrt( 1/2 (P_S - sign(z) P_L) )                               (3.63)
P_A = (P_S + P_T + P_L)/2,  P_B = (P_S + P_T - P_L)/2                   (3.64)
P_L' = 4E/V_t (Q_L - A_bar x' - C_L P_L),  V_t = V_A^0 + V_B^0, A_bar = (A_A + A_B)/2   (3.65)
damper.force = -(P_L A_bar - f(x'))                                     from (3.66)
</pre>
<p>Rod imposed: x = <code>damper.elongation</code> at the start of each communication step,
advanced with the held <code>damper.elongation_velocity</code> x'; the rod mass m and the load F_L
of (3.58)/(3.66) belong to the vehicle model (the rod inertia is the vehicle's business), so
they are not parameters here.</p>

<h2>Interpretations (where the seed is wrong or silent)</h2>
<ul>
<li><b>(3.47) dead zone</b>: the seed prints the condition as |v| &gt;= beta; it is |v| &lt; beta
(zero flow inside the dead zone). With Table 3-2, beta = 0.3 alpha, so |u| &lt;= 0.3 mm gives no
flow at all at low frequency.</li>
<li><b>Factor 1/2 in (3.63)</b>: it follows from (3.50) with (3.64) (P_S - P_A = (P_S - P_L)/2), so
it is kept (<code>valve.load_flow_half_factor</code> = true); (3.70)-(3.71) drop it. Setting the flag
to false reproduces the seed's linearisation literally (the reduced model then flows sqrt(2)
more than the full one).</li>
<li><b>Leakage C_L</b>: Table 3-2 prints "7e-10 l/s" for a coefficient per pascal. Read as
7e-10 m^3/(s Pa), the leakage at 1.3 MPa already equals the full valve flow: a blocked actuator
holds only about 13 bar (about 3.3 kN), which contradicts the 20-25 kN peak forces of Table 4-3
(R14) and makes the IDF results (R13) unreachable. This FMU therefore reads the litres literally:
<b>C_L = 7e-10 l/(s Pa) = 7e-13 m^3/(s Pa)</b> (default of
<code>cylinder.leakage_coefficient</code>), a typical servo-cylinder value that leaves the full
force P_S A = 25 kN available. (The physics crate's own default keeps 7e-10 for its
characterisation tests.)</li>
<li>The square-root orifice laws are regularised with a laminar core
(<code>valve.laminar_pressure</code>, 0.1 bar): a negative pressure drop reverses the flow instead
of giving NaN. sign(x') in (3.59) is regularised as tanh(x'/v_reg), v_reg = 1 mm/s.</li>
<li>No cavitation model: chamber pressures may go below zero under violent imposed motion.</li>
</ul>

<h2>Signs</h2>
<p><code>damper.elongation</code> and its velocity are positive in extension, which grows chamber A
(3.56). <code>damper.force</code> is positive in <b>tension</b> (opposing extension), the semi-active
damper's convention. A <b>positive spool command feeds chamber A</b> (z &gt; 0, Q_A &gt; 0), whose
pressure pushes the rod out: it <b>decreases</b> <code>damper.force</code> (towards compression). A
force controller u = k_p (F_ref - F) on this actuator therefore needs a command sign of -1
(<code>force_loop.command_sign = -1</code> in the project's IDF controller FMU); with +1 the loop runs away to
the saturation. <code>damper.power</code> = F x' is the power taken from the vehicle (negative when the
actuator drives it); <code>damper.hydraulic_power</code> = P_S Q_S - P_T Q_T is drawn from the
supply.</p>

<h2>Table 3-2 (defaults)</h2>
<table border="1">
<tr><th>symbol</th><th>value</th><th>variable</th></tr>
<tr><td>alpha, beta</td><td>1 mm, 0.3 mm</td><td>valve.saturation, valve.dead_zone</td></tr>
<tr><td>omega_0, xi</td><td>1200 rad/s, 0.7</td><td>valve.natural_frequency, valve.damping_ratio</td></tr>
<tr><td>C_d, w</td><td>0.65, 0.02 m</td><td>valve.discharge_coefficient, valve.area_gradient</td></tr>
<tr><td>rho, E</td><td>844.4 kg/m^3, 1e8 Pa</td><td>oil.density, oil.bulk_modulus</td></tr>
<tr><td>P_S, P_T</td><td>100 bar, 0</td><td>supply.pressure, tank.pressure</td></tr>
<tr><td>C_L</td><td>7e-13 m^3/(s Pa) (see above)</td><td>cylinder.leakage_coefficient</td></tr>
<tr><td>A_A = A_B</td><td>25.16 cm^2</td><td>cylinder.area_a, cylinder.area_b</td></tr>
<tr><td>V_A^0 = V_B^0</td><td>1 l</td><td>cylinder.volume_a0, cylinder.volume_b0</td></tr>
<tr><td>h</td><td>0.18 m</td><td>cylinder.half_stroke</td></tr>
<tr><td>F_c, F_s, c</td><td>600 N, 900 N, 2000 N s/m</td><td>friction.coulomb, friction.stribeck, friction.viscous</td></tr>
<tr><td>chi, delta</td><td>0.02 m/s, 0.8</td><td>friction.stribeck_velocity, friction.stribeck_exponent</td></tr>
</table>
<p>Cylinder eigenfrequency (3.68): omega_c = 2 A_bar sqrt(E/(V_t m)) = 319.7 rad/s with m = 12.39 kg
(R3); up to 600 rad/s the full and reduced order moduli agree within about 1 dB wherever the
response is above a tenth of its low-frequency value, and within 3.7 dB in the steep fall near
74 Hz, where the reduced model's fall lies 1.5 % higher in frequency (R4; the seed: close up to
about 600-1000 rad/s); both checked in the physics crate's tests.</p>

<h2>Mounting stiffness</h2>
<p><code>damper.mounting_stiffness</code> k_m (default 0 = rigid) puts a spring between the
vehicle and the rod, as the installation's brackets and bushes are (MPE 2019: about 10 MN/m).
The piston and rod (m = 12.39 kg, Table 3-2) then move under (3.58) with the spring as the load,
m x'' = P_A A_A - P_B A_B - f(x') + k_m e, the spring's extension e' = x'_vehicle - x' is one
extra state, and <code>damper.force</code> is the spring's tension k_m e (no direct feedthrough
any more; the declaration keeps the rigid case's). The run starts quasi-static. Table 3-2's
Stribeck drop (F_s &gt; F_c) gives the friction a negative slope at a few mm/s; behind a mounting
stiffer than about 1e8 N/m the rod mode then chatters, so do not use k_m as a "nearly rigid"
switch: 0 is rigid. fmi2ExitInitializationMode returns fmi2Warning, with the reason, for a
mounting above 1e8 N/m while friction.stribeck exceeds friction.coulomb. At 10 MN/m the rod
mode (about 900 rad/s) is smooth.</p>

<h2>Direct feedthrough</h2>
<p><code>damper.force</code>, <code>damper.friction_force</code> and <code>damper.power</code> depend on
<code>damper.elongation_velocity</code> at the same instant through the friction law (3.59) (the
pressure part comes from states). <code>spool.position</code> and <code>damper.hydraulic_power</code>
depend on <code>spool.command</code> at once in the reduced-order model (v = u, (3.60)); in the full
order they are states, the declaration covers both. The pressures have no feedthrough.</p>

<h2>Integrator</h2>
<p>Pressure states with the regularised orifices and the regularised Coulomb friction are stiff;
each communication step is integrated with the linearly implicit, L-stable Rosenbrock pair of
Shampine and Reichelt (1997, MATLAB's ode23s), second order with a third-order error estimate,
relative tolerance 1e-6 (absolute tolerances scaled from it: 10 Pa on pressures, 1e-8 m and
1.2e-5 m/s on the spool, 1e-9 m and 1e-7 m/s on the rod), allocation-free, the
internal step chosen by error control. Inputs are held over a communication step (zero-order
hold).</p>

"#,
    super::failed_steps_doc!(),
    r#"
<h2>Initialisation</h2>
<p>Spool centred and at rest, P_A = P_B = (P_S + P_T)/2, rod at the imposed elongation.</p>
"#
);
