//! `IdealDamperForceController` FMU: the IDF board of [`crate::idf`].

use model_description::{
    DefaultExperiment, Diagnostics, FmuModel, InstanceContext, ModelError, ModelInfo, Sign,
    StepError, Variable,
};
use serde::{Deserialize, Serialize};

use super::{report_input_fault, Board, AUTHOR};
use crate::idf::{Idf, IdfOutputs, IdfParams};

#[derive(Clone, Debug, Default, Serialize, Deserialize)]
struct Reported {
    saturated: bool,
    input_fault: bool,
}

/// Ideal damper force controller FMU (plain data).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct IdealDamperForceController {
    params: IdfParams,
    board: Board<Idf, Reported>,
}

impl IdealDamperForceController {
    fn build(&mut self) -> Result<(), ModelError> {
        self.board.build::<Self>(&self.params)
    }

    fn reported_after_init(&self) -> Reported {
        Reported::default()
    }

    fn report(&mut self, t_end: f64, o: &IdfOutputs, diag: &mut Diagnostics) {
        let r = &mut self.board.reported;
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
        let mut v: Vec<Variable<Self>> = Vec::new();
        model_description::declare! { v;
            /// Viscous gain of the reference force (3.14) (section 4.5, Table 4-3)
            parameter "reference.damping" [unit = "N.s/m", display_unit = "kN.s/m", min = 0.0] => params.c_v_nspm;
            /// k_p: proportional gain of (3.15), m of spool per N of force error
            parameter "force_loop.gain" [unit = "m/N", min = 0.0] => params.k_p_m_per_n;
            /// Spool command saturation (Table 3-2: spool stroke alpha = 1 mm)
            parameter "spool.command_limit" [unit = "m", display_unit = "mm", min = 0.0] => params.u_max_m;
            /// +1: u = k_p (F_ref - F); -1: u = k_p (F - F_ref) (seed's printed (3.15)).
            /// Must make a positive command increase the measured tension (see documentation)
            parameter "force_loop.command_sign" => params.command_sign as Sign;
            /// Board sample time (1 kHz board)
            parameter "board.sample_time" [unit = "s", display_unit = "ms", min = crate::MIN_SAMPLE_TIME_S] => params.sample_time_s;

            /// Damper (actuator rod) elongation velocity, positive = extension
            input "damper.elongation_velocity" [unit = "m/s"] => board.inputs.elongation_velocity_mps;
            /// Measured actuator force, tension positive
            input "damper.force" [unit = "N", display_unit = "kN"] => board.inputs.measured_force_n;

            /// Spool position command u (3.15), saturated to +-u_max
            output "spool.command" [unit = "m", display_unit = "mm", discrete = true] => board.out.spool_command_m;
            /// Reference force F_ref = c_v v (3.14), tension positive
            output "reference.force" [unit = "N", display_unit = "kN", discrete = true] => board.out.force_ref_n;
            /// Force error F_ref - F
            output "force_loop.error" [unit = "N", display_unit = "kN", discrete = true] => board.out.force_error_n;
            /// True if the spool command is clamped at +-u_max
            output "spool.command_saturated" => board.out.saturated;
        }
        declare_board_status!(v);
        v
    }

    board_life_cycle!(instantiate);
}

const DOC: &str = r#"
<h2>Law</h2>
<p>Ideal damper force (IDF) control of the full-active actuator, seed section 3.2.2. Each board
sample (period <code>board.sample_time</code>, 1 ms):</p>
<pre>
F_ref = c_v v                                           (3.14), c_v = reference.damping
u     = command_sign k_p (F_ref - F),  |u| &lt;= u_max      (3.15)
</pre>
<p>v = <code>damper.elongation_velocity</code> (positive = extension), F = <code>damper.force</code>
(tension positive, the project's damper convention, so a passive viscous damper gives F = +c v and
F_ref is the force of an ideal viscous damper). u = <code>spool.command</code> is the spool position
demand in metres, saturated at u_max (<code>spool.command_limit</code>) = alpha = 1 mm (Table 3-2; beyond it the orifice
saturates anyway, (3.47)).</p>
<h2>Sign (<code>force_loop.command_sign</code>)</h2>
<p>The loop is stable only if a positive command_sign x u <em>increases</em> the measured
tension. Default -1, which our FullActiveActuator needs (its test closes the loop with -1;
+1 runs away). The seed's printed form u = k_p (F_YD - F_ref) also corresponds to -1. The project's full-active actuator (fmu-damper, as documented at the time of
writing: a positive spool position feeds chamber A, whose pressure pushes the rod towards
extension, and its force output is tension positive = minus the push force) is of the kind that
needs <b><code>force_loop.command_sign</code> = -1</b>; check the actuator's documentation before coupling, a wrong sign
makes the loop run away to the saturation.</p>
<h2>Gain</h2>
<p>The seed tunes k_p (<code>force_loop.gain</code>) by trial and error. Default 3e-7 m/N: with the Table 3-2 actuator's force
rate per spool travel of about 7.1e8 N/(s m) the force loop crosses over near 210 rad/s, ten
times the hunting frequency (R6), leaving about 58 deg of phase margin after the 1 ms board delay
and the 1200 rad/s valve (3.46). The spool saturates for force errors above u_max/k_p = 3.3 kN.
The valve dead zone (beta = 0.3 alpha) leaves a force error band that a pure P law does not
remove.</p>
<h2>Timing and co-simulation</h2>
<p>Samples at <code>start_time + k board.sample_time</code>; the command computed from the inputs sampled at
t_k is output from t_(k+1) on (one sample of computational delay), so no output depends on the
inputs at the same instant (no direct feedthrough, no algebraic loop with the actuator). With a
communication step dividing the sample time the results are independent of the step. NaN/inf
inputs are rejected when set (fmi2Error). Clamping of the spool command is a warning when it
starts, an event when it ends.</p>
"#;
