//! `IdealDamperForceController` FMU: the IDF board of [`crate::idf`].

use model_description::{
    DefaultExperiment, Diagnostics, FmuModel, InstanceContext, ModelError, ModelInfo, StepError,
    Variable, VariableList,
};
use serde::{Deserialize, Serialize};

use super::{param_error, report_input_fault, sign_to_int, AUTHOR};
use crate::idf::{Idf, IdfInputs, IdfOutputs, IdfParams};

const NAMES: &[(&str, &str)] = &[
    ("sample_time_s", "sample_time"),
    ("c_v_nspm", "c_v"),
    ("k_p_m_per_n", "k_p"),
    ("command_sign", "command_sign"),
    ("u_max_m", "u_max"),
];

const INPUT_NAMES: &[(&str, &str)] = &[
    ("elongation_velocity_mps", "damper.elongation_velocity"),
    ("measured_force_n", "damper.force"),
];

#[derive(Clone, Debug, Default, Serialize, Deserialize)]
struct Reported {
    saturated: bool,
    input_fault: bool,
}

/// Ideal damper force controller FMU (plain data).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct IdealDamperForceController {
    params: IdfParams,
    inputs: IdfInputs,
    ctrl: Idf,
    out: IdfOutputs,
    initialized: bool,
    reported: Reported,
}

impl IdealDamperForceController {
    fn build(&mut self) -> Result<(), ModelError> {
        self.ctrl = Idf::new(self.params.clone()).map_err(|e| param_error(e, NAMES))?;
        self.out = self.ctrl.outputs();
        Ok(())
    }

    fn reported_after_init(&self) -> Reported {
        Reported::default()
    }

    fn report(&mut self, t_end: f64, o: &IdfOutputs, diag: &mut Diagnostics) {
        let r = &mut self.reported;
        if o.saturated != r.saturated {
            if o.saturated {
                diag.warn(format!(
                    "t = {t_end:.6} s: spool command clamped to +-u_max = {} m \
                     (force error {:.0} N)",
                    self.params.u_max_m, o.force_error_n
                ));
            } else {
                diag.event(format!(
                    "t = {t_end:.6} s: spool command back within +-u_max"
                ));
            }
            r.saturated = o.saturated;
        }
        report_input_fault(
            t_end,
            o.input_fault,
            o.dropped_samples,
            &mut r.input_fault,
            diag,
        );
    }
}

impl FmuModel for IdealDamperForceController {
    const INFO: ModelInfo = ModelInfo {
        name: "IdealDamperForceController",
        description: "Full-active yaw damper control: proportional force loop tracking an ideal \
                      viscous damper force (3.14)-(3.15)",
        author: AUTHOR,
        version: env!("CARGO_PKG_VERSION"),
        default_experiment: DefaultExperiment {
            start_time: 0.0,
            stop_time: 1.0,
            step_size: 1e-3,
        },
        documentation_html: DOC,
        resources: &[],
    };

    fn variables() -> Vec<Variable<Self>> {
        let mut v = VariableList::<Self>::new();
        v.parameter(
            "c_v",
            "Viscous gain of the reference force (3.14) (section 4.5, Table 4-3)",
            |m| m.params.c_v_nspm,
            |m, x| m.params.c_v_nspm = x,
        )
        .unit("N.s/m")
        .display_unit("kN.s/m")
        .min(0.0);
        // Unit m/N is not in the project's unit table: stated in the description instead.
        v.parameter(
            "k_p",
            "Proportional gain of (3.15), in m of spool per N of force error",
            |m| m.params.k_p_m_per_n,
            |m, x| m.params.k_p_m_per_n = x,
        )
        .min(0.0);
        v.parameter(
            "u_max",
            "Spool command saturation (Table 3-2: spool stroke alpha = 1 mm)",
            |m| m.params.u_max_m,
            |m, x| m.params.u_max_m = x,
        )
        .unit("m")
        .display_unit("mm")
        .min(0.0);
        v.integer_parameter(
            "command_sign",
            "+1: u = k_p (F_ref - F); -1: u = k_p (F - F_ref) (seed's printed (3.15)). \
             Must make a positive command increase the measured tension (see documentation)",
            |m| sign_to_int(m.params.command_sign),
            |m, x| m.params.command_sign = f64::from(x),
        )
        .range(-1.0, 1.0);
        v.parameter(
            "sample_time",
            "Board sample time (1 kHz board)",
            |m| m.params.sample_time_s,
            |m, x| m.params.sample_time_s = x,
        )
        .unit("s")
        .display_unit("ms")
        .min(0.0);

        v.input(
            "damper.elongation_velocity",
            "Damper (actuator rod) elongation velocity, positive = extension",
            |m| m.inputs.elongation_velocity_mps,
            |m, x| m.inputs.elongation_velocity_mps = x,
        )
        .unit("m/s");
        v.input(
            "damper.force",
            "Measured actuator force, tension positive",
            |m| m.inputs.measured_force_n,
            |m, x| m.inputs.measured_force_n = x,
        )
        .unit("N")
        .display_unit("kN");

        v.output(
            "spool.command",
            "Spool position command u (3.15), saturated to +-u_max",
            &[],
            |m| m.out.spool_command_m,
        )
        .unit("m")
        .display_unit("mm")
        .discrete();
        v.output(
            "force_reference",
            "Reference force F_ref = c_v v (3.14), tension positive",
            &[],
            |m| m.out.force_ref_n,
        )
        .unit("N")
        .display_unit("kN")
        .discrete();
        v.output("force_error", "Force error F_ref - F", &[], |m| {
            m.out.force_error_n
        })
        .unit("N")
        .display_unit("kN")
        .discrete();
        v.boolean_output(
            "saturated",
            "True if the spool command is clamped at +-u_max",
            &[],
            |m| m.out.saturated,
        );
        v.boolean_output(
            "input_fault",
            "True if an input of the last step was not finite (sample dropped, command held)",
            &[],
            |m| m.out.input_fault,
        );
        v.integer_output(
            "dropped_samples",
            "Board samples dropped because of non-finite inputs since the start",
            &[],
            |m| i32::try_from(m.out.dropped_samples).unwrap_or(i32::MAX),
        );
        v.into_vec()
    }

    fn instantiate(_ctx: &InstanceContext) -> Result<Self, ModelError> {
        let params = IdfParams::default();
        let ctrl = Idf::new(params.clone()).map_err(|e| param_error(e, NAMES))?;
        let out = ctrl.outputs();
        Ok(Self {
            params,
            inputs: IdfInputs::default(),
            ctrl,
            out,
            initialized: false,
            reported: Reported::default(),
        })
    }

    board_life_cycle!(INPUT_NAMES);
}

const DOC: &str = r#"
<h2>Law</h2>
<p>Ideal damper force (IDF) control of the full-active actuator, seed section 3.2.2. Each board
sample (period <code>sample_time</code>, 1 ms):</p>
<pre>
F_ref = c_v v                                           (3.14)
u     = command_sign k_p (F_ref - F),  |u| &lt;= u_max      (3.15)
</pre>
<p>v = <code>damper.elongation_velocity</code> (positive = extension), F = <code>damper.force</code>
(tension positive, the project's damper convention, so a passive viscous damper gives F = +c v and
F_ref is the force of an ideal viscous damper). u = <code>spool.command</code> is the spool position
demand in metres, saturated at <code>u_max</code> = alpha = 1 mm (Table 3-2; beyond it the orifice
saturates anyway, (3.47)).</p>
<h2>Sign (<code>command_sign</code>)</h2>
<p>The loop is stable only if a positive <code>command_sign</code> x u <em>increases</em> the measured
tension. Default -1, which our FullActiveActuator needs (its test closes the loop with -1;
+1 runs away). The seed's printed form u = k_p (F_YD - F_ref) also corresponds to -1. The project's full-active actuator (fmu-damper, as documented at the time of
writing: a positive spool position feeds chamber A, whose pressure pushes the rod towards
extension, and its force output is tension positive = minus the push force) is of the kind that
needs <b>command_sign = -1</b>; check the actuator's documentation before coupling, a wrong sign
makes the loop run away to the saturation.</p>
<h2>Gain</h2>
<p>The seed tunes k_p by trial and error. Default 3e-7 m/N: with the Table 3-2 actuator's force
rate per spool travel of about 7.1e8 N/(s m) the force loop crosses over near 210 rad/s, ten
times the hunting frequency (R6), leaving about 58 deg of phase margin after the 1 ms board delay
and the 1200 rad/s valve (3.46). The spool saturates for force errors above u_max/k_p = 3.3 kN.
The valve dead zone (beta = 0.3 alpha) leaves a force error band that a pure P law does not
remove.</p>
<h2>Timing and co-simulation</h2>
<p>Samples at <code>start_time + k sample_time</code>; the command computed from the inputs sampled at
t_k is output from t_(k+1) on (one sample of computational delay), so no output depends on the
inputs at the same instant (no direct feedthrough, no algebraic loop with the actuator). With a
communication step dividing the sample time the results are independent of the step. NaN/inf
inputs are rejected when set (fmi2Error). Clamping of the spool command is a warning when it
starts, an event when it ends.</p>
"#;
