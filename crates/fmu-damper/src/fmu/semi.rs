//! FMU shells of the semi-active damper ([`SemiActiveDamper`]) and of the passive reference
//! damper ([`PassiveYawDamper`], the same physics at a fixed opening).

use model_description::{
    field_error, fmi_enum, AlwaysSome, DefaultExperiment, Diagnostics, FmuModel, InstanceContext,
    ModelError, ModelInfo, StepError, Variable,
};
use serde::{Deserialize, Serialize};

use super::{not_initialised, restored_physics, step_error, AUTHOR};
use crate::semi_active::{
    SemiActiveDamper as Physics, SemiActiveInputs, SemiActiveOutputs, SemiActiveParams,
};
use crate::valve::ValveModel;

fmi_enum! {
    ValveModel as "ValveDynamics", "Command-to-opening dynamics of the by-pass valve" {
        Ideal = 0, "ideal", "The opening follows the command at once (the seed's simulations, R11)";
        Real = 1, "real", "First-order lag plus rate limit (the seed's HIL valve, R12)";
    }
}

/// What both semi-active shells hold: parameters, current inputs, the physics (built at
/// initialisation) and its last outputs.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SemiShell {
    params: SemiActiveParams,
    inputs: SemiActiveInputs,
    damper: Option<Physics>,
    out: SemiActiveOutputs,
    /// The command was clamped at the last step: warn only on entry into the clamped state.
    clamp_active: bool,
    /// The elongation velocity was beyond [`PLAUSIBLE_VELOCITY_MPS`] at the last step: warn
    /// only on entry.
    #[serde(default)]
    overspeed_active: bool,
}

/// Largest elongation velocity a yaw damper plausibly sees \[m/s\]: hunting at 4 Hz and
/// +-6 mm at the damper is 0.15 m/s. Beyond it the model still computes (its orifice laws hold),
/// but the input is more likely a unit slip (mm/s for m/s) or a broken signal, so the step warns.
pub const PLAUSIBLE_VELOCITY_MPS: f64 = 5.0;

impl SemiShell {
    fn new(params: SemiActiveParams, inputs: SemiActiveInputs) -> Self {
        let mut out = SemiActiveOutputs::default();
        if let Some(x) = params.fixed_opening {
            out.valve_opening = x;
            out.valve_opening_command = x;
        }
        Self {
            params,
            inputs,
            damper: None,
            out,
            clamp_active: false,
            overspeed_active: false,
        }
    }

    /// `M` is the model holding this shell: physics errors are named by its declaration.
    fn exit_initialization<M: FmuModel>(
        &mut self,
        diag: &mut Diagnostics,
    ) -> Result<(), ModelError> {
        let mut d = Physics::new(self.params).map_err(|e| field_error::<M>(&e))?;
        if self.params.fixed_opening.is_none() && self.params.valve.model == ValveModel::Real {
            // A real valve starts at rest at the opening commanded at the start time, so a run
            // does not begin with an opening transient the vehicle never asked for.
            let c = self
                .params
                .valve
                .command(self.inputs.valve_command_v)
                .map_err(|e| field_error::<M>(&e))?;
            d.set_opening(c.opening).map_err(|e| field_error::<M>(&e))?;
        }
        d.set_inputs(&self.inputs)
            .map_err(|e| field_error::<M>(&e))?;
        self.out = d.outputs().map_err(|e| field_error::<M>(&e))?;
        self.damper = Some(d);
        self.report_clamp(diag);
        Ok(())
    }

    /// Outputs at the current instant with the current inputs (ideal valve opening, power).
    fn update_outputs<M: FmuModel>(&mut self) -> Result<(), ModelError> {
        if let Some(d) = &mut self.damper {
            d.set_inputs(&self.inputs)
                .map_err(|e| field_error::<M>(&e))?;
            self.out = d.outputs().map_err(|e| field_error::<M>(&e))?;
        }
        Ok(())
    }

    fn do_step<M: FmuModel>(&mut self, h: f64, diag: &mut Diagnostics) -> Result<(), StepError> {
        let Some(d) = &mut self.damper else {
            return Err(not_initialised());
        };
        // The physics' step is atomic (it steps a copy and commits on success only).
        let out = d.step(h, &self.inputs).map_err(|e| step_error::<M>(&e))?;
        self.out = out;
        self.report_clamp(diag);
        self.report_overspeed(diag);
        Ok(())
    }

    fn report_overspeed(&mut self, diag: &mut Diagnostics) {
        let v = self.inputs.elongation_velocity_mps;
        let over = v.abs() > PLAUSIBLE_VELOCITY_MPS;
        if over && !self.overspeed_active {
            diag.warn(format!(
                "damper.elongation_velocity = {v} m/s is beyond the {PLAUSIBLE_VELOCITY_MPS} m/s \
                 a yaw damper plausibly sees (a velocity in mm/s?); the model goes on \
                 (further such steps are not reported until the velocity returns into range)"
            ));
        }
        self.overspeed_active = over;
    }

    /// A restored state's physics was built from the declared parameters.
    fn check_restored(&self) -> Result<(), String> {
        restored_physics(
            self.damper.as_ref().map(|d| d.is_built_from(&self.params)),
            "damper",
        )
    }

    fn report_clamp(&mut self, diag: &mut Diagnostics) {
        if self.out.command_clamped && !self.clamp_active {
            diag.warn(format!(
                "valve.command = {} V is outside [0, {}] V: clamped to an opening of {} \
                 (further out-of-range commands are not reported until the command returns \
                 into range)",
                self.inputs.valve_command_v,
                self.params.valve.full_scale_command_v,
                self.out.valve_opening_command
            ));
        }
        self.clamp_active = self.out.command_clamped;
    }
}

/// The FMI life cycle of both models: all of it is the shell's (field `s`).
macro_rules! delegate_to_shell {
    () => {
        fn exit_initialization(&mut self, diag: &mut Diagnostics) -> Result<(), ModelError> {
            self.s.exit_initialization::<Self>(diag)
        }

        fn update_outputs(&mut self, _diag: &mut Diagnostics) -> Result<(), ModelError> {
            self.s.update_outputs::<Self>()
        }

        fn check_restored(&self) -> Result<(), String> {
            self.s.check_restored()
        }

        fn do_step(
            &mut self,
            _time: f64,
            step: f64,
            diag: &mut Diagnostics,
        ) -> Result<(), StepError> {
            self.s.do_step::<Self>(step, diag)
        }

        /// The physics' step returns the outputs at its end with the held inputs, as
        /// `update_outputs` would compute them.
        fn step_computes_outputs(&self) -> bool {
            true
        }
    };
}

/// Parameters of (3.38)-(3.45) common to both shells (both hold the shell in field `s`).
macro_rules! declare_damper_parameters {
    ($v:ident) => {
        model_description::declare! { $v;
            /// A_eff of (3.38): piston (annulus) area, Table 3-1
            parameter "damper.effective_area" [unit = "m2", display_unit = "cm2", min = 0.0] => s.params.effective_area_m2;
            /// V0 of (3.41): chamber volume, Table 3-1 (must be > 0)
            parameter "damper.chamber_volume" [unit = "m3", display_unit = "l", min = 0.0] => s.params.chamber_volume_m3;
            /// K of (3.43): effective bulk modulus (oil + entrained air + hoses), calibrated to R1-R2
            parameter "damper.bulk_modulus" [unit = "Pa", display_unit = "bar", min = 0.0] => s.params.bulk_modulus_pa;
            /// C_f of (3.42): flow through the piston's internal valves, calibrated (R1 at 0 %)
            parameter "damper.piston_flow_coefficient" [unit = "m3/(s.Pa^0.5)", min = 0.0] => s.params.piston_flow_coeff;
            /// f(v_ref): value of the cubic-root velocity function of (3.43) at v_ref, calibrated
            parameter "damper.velocity_flow_reference" [unit = "m3/s", display_unit = "l/min", min = 0.0] => s.params.velocity_flow_ref_m3ps;
            /// v_ref: reference velocity of the cubic-root velocity function (scale only)
            parameter "damper.velocity_reference" [unit = "m/s", min = 0.0] => s.params.velocity_ref_mps;
            /// v_lin: linear core of the cubic-root velocity function (regularisation)
            parameter "damper.velocity_linear" [unit = "m/s", display_unit = "mm/s", min = 0.0] => s.params.velocity_linear_mps;
            /// c_d of (3.44): by-pass orifice discharge coefficient
            parameter "valve.discharge_coefficient" [unit = "1", range = 0.0..=1.0] => s.params.valve_discharge_coeff;
            /// A_v of (3.44): by-pass passage area when fully open, calibrated (R1 at 100 %)
            parameter "valve.area" [unit = "m2", display_unit = "cm2", min = 0.0] => s.params.valve_area_m2;
            /// rho of (3.44): oil density, Table 3-2
            parameter "damper.oil_density" [unit = "kg/m3", min = 0.0] => s.params.oil_density_kgpm3;
            /// dP_t: laminar core of the regularised orifice laws (3.42), (3.44)
            parameter "damper.laminar_pressure" [unit = "Pa", display_unit = "bar", min = 0.0] => s.params.laminar_pressure_pa;
        }
    };
}

/// The motion inputs and the force outputs of both shells.
macro_rules! declare_motion_inputs {
    ($v:ident) => {
        model_description::declare! { $v;
            /// Damper elongation, positive = extension (not used by the simplified model)
            input "damper.elongation" [unit = "m", display_unit = "mm"] => s.inputs.elongation_m;
            /// Damper elongation velocity, positive = extension; its start value, 0.05 m/s, is
            /// the default experiment's constant extension: left unconnected, the damper keeps
            /// a steady force
            input "damper.elongation_velocity" [unit = "m/s", display_unit = "mm/s"] => s.inputs.elongation_velocity_mps;
        }
    };
}

macro_rules! declare_force_outputs {
    ($v:ident) => {
        model_description::declare! { $v;
            /// Damper force A_eff dP (3.38), positive in tension (opposing extension); from the
            /// pressure state, no direct feedthrough
            output "damper.force" [unit = "N", display_unit = "kN"] => s.out.force_n;
            /// dP = P_A - P_B (rebound minus compression chamber), state of (3.45)
            output "damper.pressure_difference" [unit = "Pa", display_unit = "bar"] => s.out.pressure_difference_pa;
        }
    };
}

/// Default inputs of the default experiment: a constant extension at 0.05 m/s.
fn demo_inputs() -> SemiActiveInputs {
    SemiActiveInputs {
        elongation_m: 0.0,
        elongation_velocity_mps: 0.05,
        valve_command_v: 0.0,
    }
}

/// Semi-active yaw damper FMU (by-pass proportional valve, seed 3.3.2-3.3.3).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SemiActiveDamper {
    s: SemiShell,
}

impl FmuModel for SemiActiveDamper {
    const INFO: ModelInfo = ModelInfo {
        name: "SemiActiveDamper",
        description: "Semi-active hydraulic yaw damper with a by-pass proportional valve \
                      (simplified model, seed (3.38)-(3.45)), calibrated to R1/R2; force \
                      positive in tension",
        author: AUTHOR,
        version: "0.1.0",
        default_experiment: DefaultExperiment {
            start_time: 0.0,
            stop_time: 1.0,
            step_size: 1e-3,
        },
        documentation_html: SEMI_DOC,
        resources: &[],
    };

    fn variables() -> Vec<Variable<Self>> {
        let mut v: Vec<Variable<Self>> = Vec::new();
        declare_damper_parameters!(v);
        model_description::declare! { v;
            /// Command-to-opening dynamics: ideal (opening follows the command at once) or real
            /// (first-order lag + rate limit)
            parameter "valve.model" => s.params.valve.model;
            /// Lag time constant of the real valve (seed HIL valve: 0.1-0.2 s, R12)
            parameter "valve.time_constant" [unit = "s", display_unit = "ms", min = 0.0] => s.params.valve.time_constant_s;
            /// Maximum opening rate of the real valve (full travel needs at least 50 ms)
            parameter "valve.rate_limit" [unit = "1/s", min = 0.0] => s.params.valve.max_rate_per_s;
            /// Command giving full opening (0 V = closed)
            parameter "valve.full_scale_command" [unit = "V", min = 0.0] => s.params.valve.full_scale_command_v;
        }
        declare_motion_inputs!(v);
        model_description::declare! { v;
            // No min/max: an out-of-range command is clamped and reported (see documentation).
            /// Valve command, 0 V = closed (maximum damping) .. 10 V = fully open; values
            /// outside are clamped, with a warning on entry into the clamped state
            input "valve.command" [unit = "V"] => s.inputs.valve_command_v;
        }
        declare_force_outputs!(v);
        model_description::declare! { v;
            /// Actual valve opening x_v (ideal valve: the clamped command at once; real valve:
            /// lagged state)
            output "valve.opening" [unit = "1", display_unit = "%", depends_on = &["valve.command"]] => s.out.valve_opening;
            /// Commanded opening after clamping, command / full scale in [0, 1]
            output "valve.opening_command" [unit = "1", display_unit = "%", depends_on = &["valve.command"]] => s.out.valve_opening_command;
            /// True while valve.command is outside [0, full scale] and clamped
            output "valve.command_clamped" [depends_on = &["valve.command"]] => s.out.command_clamped;
            /// Orifice loss power dP (Q_f + Q_v) >= 0; the simplified pressure model is no energy
            /// balance, so this is not the heat of damper.power (see the documentation)
            output "damper.dissipated_power" [unit = "W", display_unit = "kW", depends_on = &["valve.command"]] => s.out.dissipated_power_w;
            /// Mechanical power taken from the vehicle, damper.force x damper.elongation_velocity
            output "damper.power" [unit = "W", display_unit = "kW", depends_on = &["damper.elongation_velocity"]] => s.out.mechanical_power_w;
        }
        super::declare_appended_parameters!(v, s.params);
        v
    }

    fn instantiate(_ctx: &InstanceContext) -> Result<Self, ModelError> {
        Ok(Self {
            s: SemiShell::new(SemiActiveParams::default(), demo_inputs()),
        })
    }

    delegate_to_shell!();
}

/// Passive reference yaw damper FMU: the semi-active damper at a fixed opening (seed 4.3).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct PassiveYawDamper {
    s: SemiShell,
}

impl FmuModel for PassiveYawDamper {
    const INFO: ModelInfo = ModelInfo {
        name: "PassiveYawDamper",
        description: "Passive reference yaw damper: the semi-active damper (3.38)-(3.45) with the \
                      by-pass valve fixed at 30 % (seed section 4.3); force positive in tension",
        author: AUTHOR,
        version: "0.1.0",
        default_experiment: DefaultExperiment {
            start_time: 0.0,
            stop_time: 1.0,
            step_size: 1e-3,
        },
        documentation_html: PASSIVE_DOC,
        resources: &[],
    };

    fn variables() -> Vec<Variable<Self>> {
        let mut v: Vec<Variable<Self>> = Vec::new();
        declare_damper_parameters!(v);
        model_description::declare! { v;
            /// Fixed by-pass valve opening (seed 4.3 passive reference: 30 %)
            parameter "valve.opening" [unit = "1", display_unit = "%", range = 0.0..=1.0] => s.params.fixed_opening as AlwaysSome;
        }
        declare_motion_inputs!(v);
        declare_force_outputs!(v);
        model_description::declare! { v;
            /// Orifice loss power dP (Q_f + Q_v) >= 0 (from the state: no feedthrough); the simplified
            /// pressure model is no energy balance, so this is not the heat of damper.power
            output "damper.dissipated_power" [unit = "W", display_unit = "kW"] => s.out.dissipated_power_w;
            /// Mechanical power taken from the vehicle, damper.force x damper.elongation_velocity
            output "damper.power" [unit = "W", display_unit = "kW", depends_on = &["damper.elongation_velocity"]] => s.out.mechanical_power_w;
        }
        super::declare_appended_parameters!(v, s.params);
        v
    }

    fn instantiate(_ctx: &InstanceContext) -> Result<Self, ModelError> {
        Ok(Self {
            s: SemiShell::new(SemiActiveParams::passive_reference(), demo_inputs()),
        })
    }

    delegate_to_shell!();
}

/// Equations, interpretations, calibration and numerics shared by both documentations.
macro_rules! semi_common_doc {
    () => {
        concat!(
            r#"
<h2>Equations (seed 3.3.2-3.3.3)</h2>
<p>One hydraulic state, the pressure difference dP = P_A - P_B (rebound minus compression
chamber), plus the valve opening x_v when the valve is not ideal:</p>
<pre>
F     = A_eff dP                                                        (3.38)
Q_f   = C_f g(dP)                      piston (internal valve) flow     (3.42)
Q_v   = c_d A_v x_v sqrt(2/rho) g(dP)  by-pass valve flow               (3.44)
dP'   = K/V0 ( f(v) - Q_f - Q_v )                                        (3.43), (3.45)
g(dP) = dP / (dP^2 + dP_t^2)^(1/4)     ~ sqrt(|dP|) sign(dP) for |dP| &gt;&gt; dP_t
f(v)  = Q_ref v / ( v_ref^(1/3) (v^2 + v_lin^2)^(1/3) )  ~ Q_ref (v / v_ref)^(1/3)   (Fig. 3.8)
</pre>
<p>v = <code>damper.elongation_velocity</code>. (3.39)-(3.41) with V_A = V_B = V0 reduce the two
chamber equations to the single state equation above.</p>

<h2>Interpretations (where the seed is wrong or silent)</h2>
<ul>
<li><b>(3.45) applies the square root twice</b> to the by-pass flow
(c_d A_v x_v sqrt(2 dP/rho) sqrt(dP)), which is dimensionally wrong; the model uses the by-pass
flow exactly as in (3.44): the root is applied once.</li>
<li><b>Regularisation.</b> The orifice law sqrt(|dP|) sign(dP) of (3.42)/(3.44) has an infinite
slope at dP = 0; g replaces it by a laminar (linear) law for |dP| &lt;&lt; dP_t
(<code>damper.laminar_pressure</code>, 3 bar) and is smooth everywhere. The cubic-root velocity
function f (the seed only plots it, Fig. 3.8) gets a linear core below v_lin.</li>
<li><b>Constants.</b> C_f, K, f and c_d A_v are not in the seed; they are calibrated against R1-R2
with Table 3-1's area and a 1 l chamber. The effective bulk modulus (3e8 Pa) is a fifth of pure
oil: entrained air and hose compliance. Only the products K Q_ref, K C_f, K c_d A_v matter for dP.</li>
<li><b>Elongation.</b> <code>damper.elongation</code> is accepted for interface uniformity but not used:
the simplified model's force depends on the velocity history only.</li>
<li><b>Powers.</b> <code>damper.dissipated_power</code> = dP (Q_f + Q_v) &gt;= 0 (orifice losses);
<code>damper.power</code> = F v (power taken from the vehicle, momentarily negative when the oil
compliance gives energy back). The simplified model is not energy-consistent (f is not A v), so
their cycle means differ.</li>
</ul>

<h2>Sign conventions</h2>
<p>Elongation and its velocity are positive in extension. Extension compresses the rebound
chamber A, so f(v) &gt; 0 raises dP and <code>damper.force</code> = A_eff dP is positive in
<b>tension</b>, i.e. it opposes extension (F ~ +c v for a passive damper). The full-active
actuator FMU uses the same convention, so both plug into the vehicle the same way.</p>

<h2>Calibration (defaults = the physics crate's <code>SemiActiveParams::default()</code>)</h2>
<table border="1">
<tr><th>quantity</th><th>value</th><th>source</th></tr>
<tr><td>A_eff</td><td>25.16 cm^2</td><td>Table 3-1 piston (annulus) area</td></tr>
<tr><td>V0</td><td>1 l</td><td>Table 3-1 chamber volume</td></tr>
<tr><td>K</td><td>3e8 Pa</td><td>chosen, about K_oil/5 (air, hoses)</td></tr>
<tr><td>C_f</td><td>1.6e-7 m^3/(s Pa^0.5)</td><td>calibrated, R1 at 0 %</td></tr>
<tr><td>Q_ref = f(v_ref), v_ref</td><td>7.9e-4 m^3/s at 0.1 m/s</td><td>calibrated, R1 at 0 % and k_eq peak</td></tr>
<tr><td>v_lin</td><td>1e-4 m/s</td><td>regularisation</td></tr>
<tr><td>c_d, A_v</td><td>0.7, 3.7e-5 m^2 (about 6.9 mm bore)</td><td>typical sharp-edged orifice; calibrated, R1 at 100 %</td></tr>
<tr><td>rho</td><td>844.4 kg/m^3</td><td>Table 3-2</td></tr>
<tr><td>dP_t</td><td>3 bar</td><td>laminar core; brings both 100 % peaks into R1</td></tr>
</table>
<p>Measured with these values (sinusoidal stroke at 4 Hz, steady state):</p>
<table border="1">
<tr><th></th><th>seed (R1/R2)</th><th>this model</th></tr>
<tr><td>peak force, 0 % opening, +-1 / +-3 mm</td><td>12-20 kN</td><td>12.2 / 19.9 kN</td></tr>
<tr><td>peak force, 100 % opening, +-1 / +-3 mm</td><td>0.5-1 kN</td><td>0.54 / 0.86 kN</td></tr>
<tr><td>phase of F/x at 0, 20, 50, 100 % (1 mm)</td><td>rises toward 90 deg</td><td>42, 75, 85, 88 deg</td></tr>
<tr><td>30 % opening, 1 mm, 4 Hz: k_eq, c_eq</td><td>(passive reference, R5)</td><td>386 kN/m, 95.6 kN s/m</td></tr>
</table>
<p>At 0 % opening only K Q_ref/V0 and K C_f/V0 matter, and across that plane the 1 mm k_eq peak
frequency is tied one-to-one to the force ratio F(3 mm)/F(1 mm) at 4 Hz (4.76 Hz at 1.632,
5.66 Hz at 1.670, 6.73 Hz at 1.711; <code>examples/r2_peak.rs</code>). R1's 20/12 = 1.667 caps the
peak at about 5.6 Hz with both forces on R1's edges; these defaults (12.2 / 19.9 kN) put it at
4.76 Hz, so "k_eq rises with frequency" (R2) holds up to 4.5 Hz at 0 % and beyond 8 Hz at the
other openings. A 6 Hz peak inside R1 needs nearly laminar orifices (a laminar core of 20-300 bar,
departing from (3.42)/(3.44)) and would cut the 30 % k_eq by about 40 %
(<code>examples/r2_candidate.rs</code>).</p>

<h2>Mounting stiffness</h2>
<p><code>damper.mounting_stiffness</code> k_m (default 0 = rigid) puts a spring in series with
the damper, as the installation's brackets and rubber bushes are: the seed names this series
stiffness as what limits a closed valve, MPE 2019 gives about 10 MN/m for a yaw damper. The
spring carries the damper force, so the damper's own elongation is the imposed one less F/k_m:
its own velocity w solves k_m (v - w) = A_eff dP' with (3.43) (a monotone scalar equation,
solved in every evaluation of the state equation; the massless spring adds no independent
state). Measured at 4 Hz and 1 mm with 10 MN/m:</p>
<table border="1">
<tr><th>opening</th><th>rigid k_eq, c_eq</th><th>c_eq with 10 MN/m</th><th>series formula Z_d k_m/(Z_d + k_m)</th></tr>
<tr><td>30 %</td><td>386 kN/m, 95.6 kN.s/m</td><td>84.2 kN.s/m</td><td>84.1 kN.s/m</td></tr>
<tr><td>0 %</td><td>9.0 MN/m, 325.7 kN.s/m</td><td>72.7 kN.s/m</td><td>76.1 kN.s/m</td></tr>
</table>
<p>A closed valve is mostly a 9 MN/m spring at this stroke, so a 10 MN/m mounting takes away
three quarters of its damping.</p>

<h2>Integrator</h2>
<p>The pressure state is stiff: its own eigenvalue (K/V0) dQ/ddP reaches 1e5-1e7 1/s near dP = 0
(laminar core), so an explicit scheme would need microsecond sub-steps. Each communication step
is integrated with the linearly implicit Rosenbrock pair of Shampine and Reichelt (1997, MATLAB's
ode23s): L-stable, second order with a third-order error estimate (relative tolerance 1e-6,
absolute 1 Pa on dP), no Newton iteration, allocation-free; the internal step is set by error
control and grows to the communication step when the solution is smooth. Inputs are held
constant over a communication step (zero-order hold). Step-size study (4 Hz, +-3 mm, 0 %): with
communication steps of 1e-4, 1e-3 and 5e-3 s the force agrees within 0.5 % of its peak when the
host samples the input at mid-step, and the steady peak force agrees within 0.5 % with a plain
zero-order hold (which delays the input by h/2).</p>

"#,
            $crate::fmu::failed_steps_doc!(),
            r#"
<h2>Initialisation</h2>
<p>dP = 0 at the start time (damper at rest). Outputs at the start time are consistent with the
inputs set during initialisation.</p>
"#
        )
    };
}

const SEMI_DOC: &str = concat!(
    r#"
<h1>SemiActiveDamper</h1>
<p>Semi-active hydraulic yaw damper of a high-speed bogie: the simplified Ferdek-Luczko model with
a by-pass proportional valve (seed sections 3.3.2-3.3.3, equations (3.38)-(3.45)). Inputs: the
damper's elongation velocity and the valve command; output: the damper force (tension
positive). The default experiment extends the damper at a constant 0.05 m/s with the valve
closed (0 V): the force rises towards its steady value of about 39 kN (21 kN at 0.1 s,
38.6 kN at 1 s; the closed damper's pressure time constant near 15 MPa is about 0.16 s).</p>

<h2>Valve</h2>
<pre>
x_cmd = clamp(valve.command / full_scale, 0, 1)         0 V closed (maximum damping), 10 V open
ideal (valve.model = ideal): x_v = x_cmd                   (the seed's simulations, R11)
real  (valve.model = real):  x_v' = clamp((x_cmd - x_v)/tau, -r_max, r_max)
</pre>
<p>tau = <code>valve.time_constant</code> (default 0.15 s: the seed's HIL valve shows a 0.1-0.2 s
command-to-opening lag, R12), r_max = <code>valve.rate_limit</code> (default 20 /s: the coil current
needs at least 50 ms for full travel). A real valve starts at rest at the opening commanded at
the start time.</p>
<p><b>Out-of-range command: clamped and logged, not rejected.</b> <code>valve.command</code> declares
no min/max (a controller or a noisy signal may overshoot 0..10 V, and rejecting the value would
stop the co-simulation). A command outside [0, full scale] is clamped; the step that
<em>enters</em> the clamped state returns fmi2Warning with a logged message, later steps in the
clamped state are silent (no log flood) and <code>valve.command_clamped</code> stays true until the
command returns into range. NaN/inf is rejected by fmi2SetReal.</p>

<h2>Direct feedthrough</h2>
<p><code>damper.force</code> and <code>damper.pressure_difference</code> come from the pressure state:
no direct feedthrough (no algebraic loop with the vehicle). <code>damper.power</code> = F v depends on
<code>damper.elongation_velocity</code> at the same instant. <code>valve.opening</code>,
<code>valve.opening_command</code>, <code>valve.command_clamped</code> and <code>damper.dissipated_power</code>
depend on <code>valve.command</code> at once with the ideal valve (with the real valve the opening is
a state; the declaration covers both).</p>
"#,
    semi_common_doc!()
);

const PASSIVE_DOC: &str = concat!(
    r#"
<h1>PassiveYawDamper</h1>
<p>Passive reference yaw damper of the seed (section 4.3): the semi-active damper of sections
3.3.2-3.3.3 with the by-pass valve fixed at <code>valve.opening</code> = 30 % (ideal valve, no
command input). Same physics and calibration as the SemiActiveDamper FMU. The default experiment
extends the damper at a constant 0.05 m/s: the force settles at about 3.5 kN within 0.1 s.</p>
<p>Every output except <code>damper.power</code> (= F v, feedthrough from
<code>damper.elongation_velocity</code>) comes from the pressure state: no direct feedthrough.</p>
"#,
    semi_common_doc!()
);
