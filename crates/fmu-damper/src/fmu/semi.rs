//! FMU shells of the semi-active damper ([`SemiActiveDamper`]) and of the passive reference
//! damper ([`PassiveYawDamper`], the same physics at a fixed opening).

use model_description::{
    DefaultExperiment, Diagnostics, FmuModel, InstanceContext, ModelError, ModelInfo, StepError,
    Variable, VariableList,
};
use serde::{Deserialize, Serialize};

use super::{
    model_error, not_initialised, param_error, step_error, steps_from_fmi, steps_to_fmi, AUTHOR,
    MAX_STEPS_DESCRIPTION, MAX_STEPS_NAME, MAX_STEPS_RANGE,
};
use crate::semi_active::{
    SemiActiveDamper as Physics, SemiActiveInputs, SemiActiveOutputs, SemiActiveParams,
};
use crate::valve::ValveModel;

/// Physics field -> FMI variable, for error messages.
const NAMES: &[(&str, &str)] = &[
    ("effective_area_m2", "damper.effective_area"),
    ("chamber_volume_m3", "damper.chamber_volume"),
    ("bulk_modulus_pa", "damper.bulk_modulus"),
    ("piston_flow_coeff", "damper.piston_flow_coefficient"),
    ("velocity_flow_ref_m3ps", "damper.velocity_flow_reference"),
    ("velocity_ref_mps", "damper.velocity_reference"),
    ("velocity_linear_mps", "damper.velocity_linear"),
    ("valve_discharge_coeff", "valve.discharge_coefficient"),
    ("valve_area_m2", "valve.area"),
    ("oil_density_kgpm3", "damper.oil_density"),
    ("laminar_pressure_pa", "damper.laminar_pressure"),
    ("fixed_opening", "valve.opening"),
    ("valve.time_constant_s", "valve.time_constant"),
    ("valve.max_rate_per_s", "valve.rate_limit"),
    ("valve.full_scale_command_v", "valve.full_scale_command"),
    ("elongation_m", "damper.elongation"),
    ("elongation_velocity_mps", "damper.elongation_velocity"),
    ("valve_command_v", "valve.command"),
];

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
}

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
        }
    }

    fn exit_initialization(&mut self, diag: &mut Diagnostics) -> Result<(), ModelError> {
        let mut d = Physics::new(self.params).map_err(|e| param_error(&e, NAMES))?;
        if self.params.fixed_opening.is_none() && self.params.valve.model == ValveModel::Real {
            // A real valve starts at rest at the opening commanded at the start time, so a run
            // does not begin with an opening transient the vehicle never asked for.
            let c = self
                .params
                .valve
                .command(self.inputs.valve_command_v)
                .map_err(|e| model_error(&e, NAMES))?;
            d.set_opening(c.opening)
                .map_err(|e| param_error(&e, NAMES))?;
        }
        d.set_inputs(&self.inputs)
            .map_err(|e| model_error(&e, NAMES))?;
        self.out = d.outputs().map_err(|e| model_error(&e, NAMES))?;
        self.damper = Some(d);
        self.report_clamp(diag);
        Ok(())
    }

    /// Outputs at the current instant with the current inputs (ideal valve opening, power).
    fn update_outputs(&mut self) -> Result<(), ModelError> {
        if let Some(d) = &mut self.damper {
            d.set_inputs(&self.inputs)
                .map_err(|e| model_error(&e, NAMES))?;
            self.out = d.outputs().map_err(|e| model_error(&e, NAMES))?;
        }
        Ok(())
    }

    fn do_step(&mut self, h: f64, diag: &mut Diagnostics) -> Result<(), StepError> {
        let Some(d) = &mut self.damper else {
            return Err(not_initialised());
        };
        // Step a copy (plain data, no allocation) and commit on success only.
        let mut next = d.clone();
        let out = next
            .step(h, &self.inputs)
            .map_err(|e| step_error(&e, NAMES))?;
        *d = next;
        self.out = out;
        self.report_clamp(diag);
        Ok(())
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

/// Access to the shared state, so both shells declare the damper parameters once.
trait HasShell {
    fn shell(&self) -> &SemiShell;
    fn shell_mut(&mut self) -> &mut SemiShell;
}

/// `HasShell` for a model whose shell is its field `s`.
macro_rules! impl_has_shell {
    ($model:ty) => {
        impl HasShell for $model {
            fn shell(&self) -> &SemiShell {
                &self.s
            }
            fn shell_mut(&mut self) -> &mut SemiShell {
                &mut self.s
            }
        }
    };
}

/// The FMI life cycle of both models: all of it is the shell's.
macro_rules! delegate_to_shell {
    () => {
        fn exit_initialization(&mut self, diag: &mut Diagnostics) -> Result<(), ModelError> {
            self.s.exit_initialization(diag)
        }

        fn update_outputs(&mut self, _diag: &mut Diagnostics) -> Result<(), ModelError> {
            self.s.update_outputs()
        }

        fn do_step(
            &mut self,
            _time: f64,
            step: f64,
            diag: &mut Diagnostics,
        ) -> Result<(), StepError> {
            self.s.do_step(step, diag)
        }
    };
}

/// Parameters of (3.38)-(3.45) common to both shells.
fn declare_damper_parameters<M: HasShell>(v: &mut VariableList<M>) {
    v.parameter(
        "damper.effective_area",
        "A_eff of (3.38): piston (annulus) area, Table 3-1",
        |m| m.shell().params.effective_area_m2,
        |m, x| m.shell_mut().params.effective_area_m2 = x,
    )
    .unit("m2")
    .display_unit("cm2")
    .min(0.0);
    v.parameter(
        "damper.chamber_volume",
        "V0 of (3.41): chamber volume, Table 3-1 (must be > 0)",
        |m| m.shell().params.chamber_volume_m3,
        |m, x| m.shell_mut().params.chamber_volume_m3 = x,
    )
    .unit("m3")
    .display_unit("l")
    .min(0.0);
    v.parameter(
        "damper.bulk_modulus",
        "K of (3.43): effective bulk modulus (oil + entrained air + hoses), calibrated to R1-R2",
        |m| m.shell().params.bulk_modulus_pa,
        |m, x| m.shell_mut().params.bulk_modulus_pa = x,
    )
    .unit("Pa")
    .display_unit("bar")
    .min(0.0);
    // Unit m3/(s.Pa^0.5) is not in the glue's unit table: none declared (see the documentation).
    v.parameter(
        "damper.piston_flow_coefficient",
        "C_f of (3.42), m3/(s Pa^0.5): flow through the piston's internal valves, calibrated (R1 at 0 %)",
        |m| m.shell().params.piston_flow_coeff,
        |m, x| m.shell_mut().params.piston_flow_coeff = x,
    )
    .min(0.0);
    v.parameter(
        "damper.velocity_flow_reference",
        "f(v_ref): value of the cubic-root velocity function of (3.43) at v_ref, calibrated",
        |m| m.shell().params.velocity_flow_ref_m3ps,
        |m, x| m.shell_mut().params.velocity_flow_ref_m3ps = x,
    )
    .unit("m3/s")
    .display_unit("l/min")
    .min(0.0);
    v.parameter(
        "damper.velocity_reference",
        "v_ref: reference velocity of the cubic-root velocity function (scale only)",
        |m| m.shell().params.velocity_ref_mps,
        |m, x| m.shell_mut().params.velocity_ref_mps = x,
    )
    .unit("m/s")
    .min(0.0);
    v.parameter(
        "damper.velocity_linear",
        "v_lin: linear core of the cubic-root velocity function (regularisation)",
        |m| m.shell().params.velocity_linear_mps,
        |m, x| m.shell_mut().params.velocity_linear_mps = x,
    )
    .unit("m/s")
    .display_unit("mm/s")
    .min(0.0);
    v.parameter(
        "valve.discharge_coefficient",
        "c_d of (3.44): by-pass orifice discharge coefficient",
        |m| m.shell().params.valve_discharge_coeff,
        |m, x| m.shell_mut().params.valve_discharge_coeff = x,
    )
    .unit("1")
    .range(0.0, 1.0);
    v.parameter(
        "valve.area",
        "A_v of (3.44): by-pass passage area when fully open, calibrated (R1 at 100 %)",
        |m| m.shell().params.valve_area_m2,
        |m, x| m.shell_mut().params.valve_area_m2 = x,
    )
    .unit("m2")
    .display_unit("cm2")
    .min(0.0);
    v.parameter(
        "damper.oil_density",
        "rho of (3.44): oil density, Table 3-2",
        |m| m.shell().params.oil_density_kgpm3,
        |m, x| m.shell_mut().params.oil_density_kgpm3 = x,
    )
    .unit("kg/m3")
    .min(0.0);
    v.parameter(
        "damper.laminar_pressure",
        "dP_t: laminar core of the regularised orifice laws (3.42), (3.44)",
        |m| m.shell().params.laminar_pressure_pa,
        |m, x| m.shell_mut().params.laminar_pressure_pa = x,
    )
    .unit("Pa")
    .display_unit("bar")
    .min(0.0);
}

/// The integrator's work bound, declared last so the other value references stay put.
fn declare_solver_parameter<M: HasShell>(v: &mut VariableList<M>) {
    v.integer_parameter(
        MAX_STEPS_NAME,
        MAX_STEPS_DESCRIPTION,
        |m| steps_to_fmi(m.shell().params.solver.max_internal_steps),
        |m, x| m.shell_mut().params.solver.max_internal_steps = steps_from_fmi(x),
    )
    .range(MAX_STEPS_RANGE.0, MAX_STEPS_RANGE.1);
}

fn declare_motion_inputs<M: HasShell>(v: &mut VariableList<M>) {
    v.input(
        "damper.elongation",
        "Damper elongation, positive = extension (not used by the simplified model)",
        |m| m.shell().inputs.elongation_m,
        |m, x| m.shell_mut().inputs.elongation_m = x,
    )
    .unit("m")
    .display_unit("mm");
    v.input(
        "damper.elongation_velocity",
        "Damper elongation velocity, positive = extension",
        |m| m.shell().inputs.elongation_velocity_mps,
        |m, x| m.shell_mut().inputs.elongation_velocity_mps = x,
    )
    .unit("m/s")
    .display_unit("mm/s");
}

fn declare_force_outputs<M: HasShell>(v: &mut VariableList<M>) {
    v.output(
        "damper.force",
        "Damper force A_eff dP (3.38), positive in tension (opposing extension); from the \
         pressure state, no direct feedthrough",
        &[],
        |m| m.shell().out.force_n,
    )
    .unit("N")
    .display_unit("kN");
    v.output(
        "damper.pressure_difference",
        "dP = P_A - P_B (rebound minus compression chamber), state of (3.45)",
        &[],
        |m| m.shell().out.pressure_difference_pa,
    )
    .unit("Pa")
    .display_unit("bar");
}

/// The two powers, declared after the valve outputs; only the loss power's description and
/// feedthrough (the valve command moves the opening at once, or not at all) differ per model.
fn declare_power_outputs<M: HasShell>(
    v: &mut VariableList<M>,
    dissipated_description: &str,
    dissipated_feedthrough: &[&'static str],
) {
    v.output(
        "damper.dissipated_power",
        dissipated_description,
        dissipated_feedthrough,
        |m| m.shell().out.dissipated_power_w,
    )
    .unit("W")
    .display_unit("kW");
    v.output(
        "damper.power",
        "Mechanical power taken from the vehicle, damper.force x damper.elongation_velocity",
        &["damper.elongation_velocity"],
        |m| m.shell().out.mechanical_power_w,
    )
    .unit("W")
    .display_unit("kW");
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

impl_has_shell!(SemiActiveDamper);

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
        let mut v = VariableList::<Self>::new();
        declare_damper_parameters(&mut v);
        v.integer_parameter(
            "valve.model",
            "Command-to-opening dynamics: 0 = ideal (opening follows the command at once), \
             1 = real (first-order lag + rate limit)",
            |m| match m.s.params.valve.model {
                ValveModel::Ideal => 0,
                ValveModel::Real => 1,
            },
            |m, x| {
                m.s.params.valve.model = if x == 1 {
                    ValveModel::Real
                } else {
                    ValveModel::Ideal
                }
            },
        )
        .range(0.0, 1.0);
        v.parameter(
            "valve.time_constant",
            "Lag time constant of the real valve (seed HIL valve: 0.1-0.2 s, R12)",
            |m| m.s.params.valve.time_constant_s,
            |m, x| m.s.params.valve.time_constant_s = x,
        )
        .unit("s")
        .display_unit("ms")
        .min(0.0);
        v.parameter(
            "valve.rate_limit",
            "Maximum opening rate of the real valve (full travel needs at least 50 ms)",
            |m| m.s.params.valve.max_rate_per_s,
            |m, x| m.s.params.valve.max_rate_per_s = x,
        )
        .unit("1/s")
        .min(0.0);
        v.parameter(
            "valve.full_scale_command",
            "Command giving full opening (0 V = closed)",
            |m| m.s.params.valve.full_scale_command_v,
            |m, x| m.s.params.valve.full_scale_command_v = x,
        )
        .unit("V")
        .min(0.0);

        declare_motion_inputs(&mut v);
        // No min/max: an out-of-range command is clamped and reported (see documentation).
        v.input(
            "valve.command",
            "Valve command, 0 V = closed (maximum damping) .. 10 V = fully open; values \
             outside are clamped, with a warning on entry into the clamped state",
            |m| m.s.inputs.valve_command_v,
            |m, x| m.s.inputs.valve_command_v = x,
        )
        .unit("V");

        declare_force_outputs(&mut v);
        v.output(
            "valve.opening",
            "Actual valve opening x_v (ideal valve: the clamped command at once; real valve: \
             lagged state)",
            &["valve.command"],
            |m| m.s.out.valve_opening,
        )
        .unit("1")
        .display_unit("%");
        v.output(
            "valve.opening_command",
            "Commanded opening after clamping, command / full scale in [0, 1]",
            &["valve.command"],
            |m| m.s.out.valve_opening_command,
        )
        .unit("1")
        .display_unit("%");
        v.boolean_output(
            "valve.command_clamped",
            "True while valve.command is outside [0, full scale] and clamped",
            &["valve.command"],
            |m| m.s.out.command_clamped,
        );
        declare_power_outputs(
            &mut v,
            "Orifice loss power dP (Q_f + Q_v) >= 0",
            &["valve.command"],
        );
        declare_solver_parameter(&mut v);
        v.into_vec()
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

impl_has_shell!(PassiveYawDamper);

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
        let mut v = VariableList::<Self>::new();
        declare_damper_parameters(&mut v);
        v.parameter(
            "valve.opening",
            "Fixed by-pass valve opening (seed 4.3 passive reference: 30 %)",
            // Always Some: set by instantiate and by this setter.
            |m| m.s.params.fixed_opening.unwrap_or(0.0),
            |m, x| m.s.params.fixed_opening = Some(x),
        )
        .unit("1")
        .display_unit("%")
        .range(0.0, 1.0);
        declare_motion_inputs(&mut v);
        declare_force_outputs(&mut v);
        declare_power_outputs(
            &mut v,
            "Orifice loss power dP (Q_f + Q_v) >= 0 (from the state: no feedthrough)",
            &[],
        );
        declare_solver_parameter(&mut v);
        v.into_vec()
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
ideal (valve.model = 0):  x_v = x_cmd                    (the seed's simulations, R11)
real  (valve.model = 1):  x_v' = clamp((x_cmd - x_v)/tau, -r_max, r_max)
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
