//! `SkyHookController` FMU: the sky-hook board of [`crate::skyhook`], with the damper's
//! damping-vs-opening table as fixed-size array parameters `table.opening[i]`, `table.damping[i]`.

use model_description::{
    DefaultExperiment, Diagnostics, FmuModel, InstanceContext, ModelError, ModelInfo, StepError,
    Variable, VariableList,
};
use serde::{Deserialize, Serialize};

use super::{invalid, param_error, report_input_fault, sign_to_int, AUTHOR};
use crate::skyhook::{
    DampingTable, SkyHook, SkyHookInputs, SkyHookMode, SkyHookOutputs, SkyHookParams,
    VelocitySource, DAMPING_TABLE_4HZ,
};

/// Number of points of the damping table parameters (that of the measured default table).
pub const TABLE_LEN: usize = DAMPING_TABLE_4HZ.len();

const NAMES: &[(&str, &str)] = &[
    ("sample_time_s", "sample_time"),
    ("velocity_filter_corner_hz", "filter_corner"),
    ("absolute_sign", "absolute_sign"),
    ("c_sky_nspm", "c_sky"),
    ("c_min_nspm", "c_min"),
    ("c_max_nspm", "c_max"),
    ("damping_table", "table"),
    ("initial_command_v", "initial_command"),
];

const INPUT_NAMES: &[(&str, &str)] = &[
    ("sensor_accel_mps2", "sensor.acceleration"),
    ("abs_velocity_mps", "sensor.velocity"),
    ("elongation_velocity_mps", "damper.elongation_velocity"),
];

#[derive(Clone, Debug, Default, Serialize, Deserialize)]
struct Reported {
    on_state: bool,
    input_fault: bool,
}

/// Sky-hook valve controller FMU (plain data).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SkyHookController {
    /// Parameters except the table, which lives in the two arrays below until initialisation.
    params: SkyHookParams,
    table_opening: [f64; TABLE_LEN],
    table_damping: [f64; TABLE_LEN],
    inputs: SkyHookInputs,
    ctrl: SkyHook,
    out: SkyHookOutputs,
    initialized: bool,
    reported: Reported,
}

type Get = fn(&SkyHookController) -> f64;
type Set = fn(&mut SkyHookController, f64);

fn get_opening<const I: usize>(m: &SkyHookController) -> f64 {
    m.table_opening[I]
}
fn set_opening<const I: usize>(m: &mut SkyHookController, x: f64) {
    m.table_opening[I] = x;
}
fn get_damping<const I: usize>(m: &SkyHookController) -> f64 {
    m.table_damping[I]
}
fn set_damping<const I: usize>(m: &mut SkyHookController, x: f64) {
    m.table_damping[I] = x;
}

macro_rules! table_access {
    ($($i:literal),*) => {
        [$((
            get_opening::<$i> as Get,
            set_opening::<$i> as Set,
            get_damping::<$i> as Get,
            set_damping::<$i> as Set,
        )),*]
    };
}

/// Accessors of `table.opening[i+1]`, `table.damping[i+1]` (fails to compile if the default
/// table changes length: add or remove entries here).
const TABLE_ACCESS: [(Get, Set, Get, Set); TABLE_LEN] = table_access!(0, 1, 2, 3, 4, 5, 6, 7, 8);

impl SkyHookController {
    /// Table from the array parameters, checked point by point so the error names the variable.
    fn table(&self) -> Result<DampingTable, ModelError> {
        for i in 1..TABLE_LEN {
            if self.table_opening[i] <= self.table_opening[i - 1] {
                return Err(invalid(
                    format!("table.opening[{}]", i + 1),
                    format!(
                        "openings must be strictly increasing: {} after {}",
                        self.table_opening[i],
                        self.table_opening[i - 1]
                    ),
                ));
            }
            if self.table_damping[i] >= self.table_damping[i - 1] {
                return Err(invalid(
                    format!("table.damping[{}]", i + 1),
                    format!(
                        "damping must decrease strictly with the opening: {} after {}",
                        self.table_damping[i],
                        self.table_damping[i - 1]
                    ),
                ));
            }
        }
        for i in 0..TABLE_LEN {
            if self.table_damping[i] <= 0.0 {
                return Err(invalid(
                    format!("table.damping[{}]", i + 1),
                    format!("must be > 0, got {}", self.table_damping[i]),
                ));
            }
        }
        let table = DampingTable {
            points: self
                .table_opening
                .iter()
                .copied()
                .zip(self.table_damping.iter().copied())
                .collect(),
        };
        table.validate().map_err(|e| param_error(e, NAMES))?;
        Ok(table)
    }

    fn build(&mut self) -> Result<(), ModelError> {
        self.params.damping_table = self.table()?;
        self.ctrl = SkyHook::new(self.params.clone()).map_err(|e| param_error(e, NAMES))?;
        self.out = self.ctrl.outputs();
        Ok(())
    }

    /// The switching state at the start is not news.
    fn reported_after_init(&self) -> Reported {
        Reported {
            on_state: self.out.on_state,
            input_fault: false,
        }
    }

    fn report(&mut self, t_end: f64, o: &SkyHookOutputs, diag: &mut Diagnostics) {
        let r = &mut self.reported;
        if o.on_state != r.on_state {
            diag.event(format!(
                "t = {t_end:.6} s: sky-hook {} (condition {:.3e} m2/s2, desired damping {:.0} N.s/m, \
                 command {:.3} V)",
                if o.on_state { "on" } else { "off" },
                o.condition,
                o.c_desired_nspm,
                o.command_v
            ));
            r.on_state = o.on_state;
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

impl FmuModel for SkyHookController {
    const INFO: ModelInfo = ModelInfo {
        name: "SkyHookController",
        description:
            "Semi-active yaw damper valve control by sky-hook, on/off (3.13) or \
                      continuous (3.11), with the practical absolute-velocity estimate (seed 2.3.2)",
        author: AUTHOR,
        version: env!("CARGO_PKG_VERSION"),
        default_experiment: DefaultExperiment {
            start_time: 0.0,
            stop_time: 2.0,
            step_size: 1e-3,
        },
        documentation_html: DOC,
        resources: &[],
    };

    fn variables() -> Vec<Variable<Self>> {
        let mut v = VariableList::<Self>::new();
        v.integer_parameter(
            "mode",
            "0 = on/off (3.13), 1 = continuous (3.11)",
            |m| match m.params.mode {
                SkyHookMode::OnOff => 0,
                SkyHookMode::Continuous => 1,
            },
            |m, x| {
                m.params.mode = if x == 1 {
                    SkyHookMode::Continuous
                } else {
                    SkyHookMode::OnOff
                }
            },
        )
        .range(0.0, 1.0);
        v.integer_parameter(
            "velocity_source",
            "Absolute velocity x': 0 = estimated from sensor.acceleration \
             (high-pass + leaky integrator, seed 2.3.2), 1 = ideal input sensor.velocity",
            |m| match m.params.velocity_source {
                VelocitySource::EstimatedFromAcceleration => 0,
                VelocitySource::Ideal => 1,
            },
            |m, x| {
                m.params.velocity_source = if x == 1 {
                    VelocitySource::Ideal
                } else {
                    VelocitySource::EstimatedFromAcceleration
                }
            },
        )
        .range(0.0, 1.0);
        v.integer_parameter(
            "absolute_sign",
            "Sign applied to sensor.acceleration / sensor.velocity to give x' of (3.6): a mounting \
             convention (the study uses -1 left, +1 right with the lateral frame acceleration)",
            |m| sign_to_int(m.params.absolute_sign),
            |m, x| m.params.absolute_sign = f64::from(x),
        )
        .range(-1.0, 1.0);
        v.parameter(
            "c_sky",
            "Sky-hook damping c_sky (3.6), (3.11) (not in the seed: same as c_v of (3.14))",
            |m| m.params.c_sky_nspm,
            |m, x| m.params.c_sky_nspm = x,
        )
        .unit("N.s/m")
        .display_unit("kN.s/m")
        .min(0.0);
        v.parameter(
            "c_min",
            "Off-state / lower damping bound c_min (3.11), (3.13); default: open end of the table",
            |m| m.params.c_min_nspm,
            |m, x| m.params.c_min_nspm = x,
        )
        .unit("N.s/m")
        .display_unit("kN.s/m")
        .min(0.0);
        v.parameter(
            "c_max",
            "On-state / upper damping bound c_max (3.11), (3.13); default: closed end of the table",
            |m| m.params.c_max_nspm,
            |m, x| m.params.c_max_nspm = x,
        )
        .unit("N.s/m")
        .display_unit("kN.s/m")
        .min(0.0);
        v.parameter(
            "filter_corner",
            "Corner of the high-pass and of the leaky integrator of the velocity estimate",
            |m| m.params.velocity_filter_corner_hz,
            |m, x| m.params.velocity_filter_corner_hz = x,
        )
        .unit("Hz")
        .min(0.0);
        v.parameter(
            "sample_time",
            "Board sample time (1 kHz board)",
            |m| m.params.sample_time_s,
            |m, x| m.params.sample_time_s = x,
        )
        .unit("s")
        .display_unit("ms")
        .min(0.0);
        v.parameter(
            "initial_command",
            "Valve command before the first sample (0 V = closed)",
            |m| m.params.initial_command_v,
            |m, x| m.params.initial_command_v = x,
        )
        .unit("V")
        .range(0.0, 10.0);
        for (i, (go, so, _, _)) in TABLE_ACCESS.iter().enumerate() {
            v.parameter(
                &format!("table.opening[{}]", i + 1),
                "Damper valve opening of table point (strictly increasing)",
                *go,
                *so,
            )
            .unit("1")
            .range(0.0, 1.0);
        }
        for (i, (_, _, gd, sd)) in TABLE_ACCESS.iter().enumerate() {
            v.parameter(
                &format!("table.damping[{}]", i + 1),
                "Equivalent damping of the damper at table.opening[i] (strictly decreasing; \
                 default: measured on SemiActiveDamper at 4 Hz, 1 mm)",
                *gd,
                *sd,
            )
            .unit("N.s/m")
            .display_unit("kN.s/m")
            .min(0.0);
        }

        v.input(
            "sensor.acceleration",
            "Accelerometer whose integral (x absolute_sign) is the sky-hook velocity x' of (3.6): \
             the bogie's lateral acceleration as in the seed's co-simulation (4.4), or the \
             damper end's along its axis; used with velocity_source = 0",
            |m| m.inputs.sensor_accel_mps2,
            |m, x| m.inputs.sensor_accel_mps2 = x,
        )
        .unit("m/s2");
        v.input(
            "sensor.velocity",
            "Velocity of the same sensor (ideal x'); used with velocity_source = 1",
            |m| m.inputs.abs_velocity_mps,
            |m, x| m.inputs.abs_velocity_mps = x,
        )
        .unit("m/s");
        v.input(
            "damper.elongation_velocity",
            "Damper elongation velocity x' - x0', positive = extension",
            |m| m.inputs.elongation_velocity_mps,
            |m, x| m.inputs.elongation_velocity_mps = x,
        )
        .unit("m/s");

        v.output(
            "valve.command",
            "By-pass valve command, 0 V = closed (maximum damping) .. 10 V = open",
            &[],
            |m| m.out.command_v,
        )
        .unit("V")
        .discrete();
        v.output(
            "valve.opening",
            "Valve opening = command / 10 V (table inverse of damping_desired)",
            &[],
            |m| m.out.opening,
        )
        .unit("1")
        .display_unit("%")
        .discrete();
        v.output(
            "damping_desired",
            "Desired damping from (3.11) or (3.13)",
            &[],
            |m| m.out.c_desired_nspm,
        )
        .unit("N.s/m")
        .display_unit("kN.s/m")
        .discrete();
        // Unit m2/s2 is not in the project's unit table: stated in the description instead.
        v.output(
            "condition",
            "Condition function x' (x' - x0') = x' v_e, in m2/s2 (3.11), (3.13)",
            &[],
            |m| m.out.condition,
        )
        .discrete();
        v.output(
            "absolute_velocity",
            "Sky-hook velocity x' used by the law (estimated or ideal, times absolute_sign)",
            &[],
            |m| m.out.abs_velocity_mps,
        )
        .unit("m/s")
        .discrete();
        v.boolean_output(
            "on_state",
            "True when the condition function is >= 0 (damping demanded)",
            &[],
            |m| m.out.on_state,
        );
        v.boolean_output(
            "input_fault",
            "True if a used input of the last step was not finite (sample dropped, command held)",
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
        let params = SkyHookParams::default();
        let mut table_opening = [0.0; TABLE_LEN];
        let mut table_damping = [0.0; TABLE_LEN];
        for (i, &(o, c)) in params.damping_table.points.iter().enumerate() {
            if i < TABLE_LEN {
                table_opening[i] = o;
                table_damping[i] = c;
            }
        }
        let ctrl = SkyHook::new(params.clone()).map_err(|e| param_error(e, NAMES))?;
        let out = ctrl.outputs();
        Ok(Self {
            params,
            table_opening,
            table_damping,
            inputs: SkyHookInputs::default(),
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
<p>Sky-hook control of the semi-active yaw damper, seed section 3.2.1.2. The ideal sky-hook force
is F_sky = c_sky x' (3.6) with x' the absolute velocity of the bogie-side damper end; the damper
can only give F = c (x' - x0'), so each board sample (period <code>sample_time</code>, 1 ms)
chooses the damping</p>
<pre>
mode = 1, continuous (3.11):  c = clamp(c_sky x' / (x' - x0'), c_min, c_max)  if x' (x' - x0') &gt;= 0
                              c = c_min                                        otherwise
mode = 0, on/off (3.13):      c = c_max  if x' (x' - x0') &gt;= 0,  c_min otherwise
</pre>
<p>and turns c into a valve opening by inverting the damper's equivalent damping-vs-opening table
(piecewise linear, clamped: damping above the closed value gives 0 V, below the open value 10 V);
<code>valve.command</code> = 10 V x opening, 0 V = closed = maximum damping.</p>
<h2>Sign conventions</h2>
<p>Damper elongation positive = extension, x' - x0' = <code>damper.elongation_velocity</code>,
damper force tension positive (F = +c v_e). x' = <code>absolute_sign</code> times the integrated
<code>sensor.acceleration</code> (or <code>sensor.velocity</code>).</p>
<h2>Which velocity is x' (interpretation)</h2>
<p>The seed's co-simulation (section 4.4) gives the controller only the damper's piston velocity
and the lateral acceleration of the bogie, so its sky-hook integrates the <b>lateral</b>
acceleration: lateral and yaw motion of a hunting bogie are roughly in quadrature, the condition
x' (x' - x0') changes sign twice per cycle, and the valve switches frequently between open and
closed as in the seed's Figs. 4.19-4.20. Connect the bogie's lateral frame acceleration to
<code>sensor.acceleration</code> for that behaviour (the project's study does, with
<code>absolute_sign</code> = -1 on the left damper and +1 on the right so both switch together).
The textbook alternative, the absolute acceleration of the bogie-side damper end along the damper
axis, gives x' = x' - x0' when the car body does not move: the condition is then always &gt;= 0 and
the damper stays closed except for the phase lead of the estimate.</p>
<h2>Velocity estimate (seed 2.3.2)</h2>
<p><code>velocity_source = 0</code> (default): x' is estimated from
<code>sensor.acceleration</code> by a first-order high-pass and a leaky integrator with
the same corner <code>filter_corner</code> (0.3 Hz), G(s) = s/(s + w_c)^2: at 4 Hz the gain is
within 1 % of an integrator and the phase lead 8.6 deg; an accelerometer offset gives no velocity.
<code>velocity_source = 1</code> uses <code>sensor.velocity</code>.</p>
<h2>Damping table</h2>
<p><code>table.opening[i]</code> / <code>table.damping[i]</code>, i = 1..9: openings strictly
increasing in [0, 1], damping strictly decreasing; checked at fmi2ExitInitializationMode (the
offending element is named). The defaults are the equivalent damping c_eq = Im(F/x)/omega of the
project's SemiActiveDamper at 4 Hz and 1 mm amplitude, measured on its calibrated model
(325.7 kN.s/m closed ... 24.3 kN.s/m open; an end-to-end test re-measures them). Replace them by
your damper's table when you use another damper. <code>c_min</code> and <code>c_max</code> default
to the table's ends but do not follow a changed table. <code>c_sky</code> = 330 kN.s/m is not in
the seed (same magnitude as c_v of (3.14)).</p>
<h2>Timing and co-simulation</h2>
<p>Samples at <code>start_time + k sample_time</code>; the command computed from the inputs sampled at
t_k is output from t_(k+1) on (one sample of computational delay), so no output depends on the
inputs at the same instant (no direct feedthrough, no algebraic loop with the damper). With a
communication step dividing the sample time the results are independent of the step. NaN/inf inputs
are rejected when set (fmi2Error); the unused absolute input may be anything finite. Switching of
<code>on_state</code> is logged as an event (logEvents) when it changes.</p>
"#;
