//! `SkyHookController` FMU: the sky-hook board of [`crate::skyhook`], with the damper's
//! damping-vs-opening table as fixed-size array parameters `table.opening[i]`, `table.damping[i]`.

use model_description::{
    field_error, fmi_enum, DefaultExperiment, Diagnostics, FieldError, FmuModel, InstanceContext,
    ModelError, ModelInfo, Sign, StepError, Variable,
};
use serde::{Deserialize, Serialize};

use super::{report_input_fault, Board, AUTHOR};
use crate::skyhook::{
    DampingTable, SkyHook, SkyHookMode, SkyHookOutputs, SkyHookParams, VelocitySource,
    DAMPING_TABLE_4HZ,
};

/// Number of points of the damping table parameters (that of the measured default table).
pub const TABLE_LEN: usize = DAMPING_TABLE_4HZ.len();

fmi_enum! {
    SkyHookMode as "SkyHookLaw", "Sky-hook law" {
        OnOff = 0, "on_off", "On/off (3.13): c_max when the condition holds, c_min otherwise";
        Continuous = 1, "continuous", "Continuous (3.11): c_sky x' / (x' - x0') within [c_min, c_max]";
    }
}

fmi_enum! {
    VelocitySource as "SkyHookVelocitySource", "Where the sky-hook velocity x' comes from" {
        EstimatedFromAcceleration = 0, "estimated", "High-pass + leaky integrator of sensor.acceleration (seed 2.3.2)";
        Ideal = 1, "ideal", "The input sensor.velocity";
    }
}

/// A damping-table point out of order, naming the array element (`table_opening[i]`), which
/// the glue reports as the FMI variable bound to it.
struct TableError {
    field: String,
    reason: String,
}

impl std::fmt::Display for TableError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.reason)
    }
}

impl FieldError for TableError {
    fn field(&self) -> Option<&str> {
        Some(&self.field)
    }
}

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
    board: Board<SkyHook, Reported>,
}

impl SkyHookController {
    /// Table from the array parameters, checked point by point so the error names the element.
    fn table(&self) -> Result<DampingTable, TableError> {
        let bad = |array: &str, i: usize, reason: String| TableError {
            field: format!("{array}[{i}]"),
            reason,
        };
        for i in 1..TABLE_LEN {
            let (o, o_prev) = (self.table_opening[i], self.table_opening[i - 1]);
            if o <= o_prev {
                return Err(bad(
                    "table_opening",
                    i,
                    format!(
                        "openings must increase strictly: {o} is not above table_opening[{}] = \
                         {o_prev}",
                        i - 1
                    ),
                ));
            }
            let (c, c_prev) = (self.table_damping[i], self.table_damping[i - 1]);
            if c >= c_prev {
                return Err(bad(
                    "table_damping",
                    i,
                    format!(
                        "damping must decrease strictly with the opening: {c} is not below \
                         table_damping[{}] = {c_prev}",
                        i - 1
                    ),
                ));
            }
        }
        for (i, &c) in self.table_damping.iter().enumerate() {
            if c <= 0.0 {
                return Err(bad("table_damping", i, format!("must be > 0, got {c}")));
            }
        }
        Ok(DampingTable {
            points: self
                .table_opening
                .iter()
                .copied()
                .zip(self.table_damping.iter().copied())
                .collect(),
        })
    }

    fn build(&mut self) -> Result<(), ModelError> {
        self.params.damping_table = self.table().map_err(|e| field_error::<Self>(&e))?;
        self.board.build::<Self>(&self.params)
    }

    /// The switching state at the start is not news.
    fn reported_after_init(&self) -> Reported {
        Reported {
            on_state: self.board.out.on_state,
            input_fault: false,
        }
    }

    fn report(&mut self, t_end: f64, o: &SkyHookOutputs, diag: &mut Diagnostics) {
        let r = &mut self.board.reported;
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
        let mut v: Vec<Variable<Self>> = Vec::new();
        model_description::declare! { v;
            /// On/off (3.13) or continuous (3.11)
            parameter "control.mode" => params.mode;
            /// Absolute velocity x': estimated from sensor.acceleration (high-pass + leaky
            /// integrator, seed 2.3.2) or the ideal input sensor.velocity
            parameter "sensor.velocity_source" => params.velocity_source;
            /// Sign applied to sensor.acceleration / sensor.velocity to give x' of (3.6): a mounting
            /// convention (the study uses -1 left, +1 right with the lateral frame acceleration)
            parameter "sensor.sign" => params.absolute_sign as Sign;
            /// Sky-hook damping c_sky (3.6), (3.11) (not in the seed: same as c_v of (3.14))
            parameter "damping.sky_hook" [unit = "N.s/m", display_unit = "kN.s/m", min = 0.0] => params.c_sky_nspm;
            /// Off-state / lower damping bound c_min (3.11), (3.13); default: open end of the table
            parameter "damping.min" [unit = "N.s/m", display_unit = "kN.s/m", min = 0.0] => params.c_min_nspm;
            /// On-state / upper damping bound c_max (3.11), (3.13); default: closed end of the table
            parameter "damping.max" [unit = "N.s/m", display_unit = "kN.s/m", min = 0.0] => params.c_max_nspm;
            /// Corner of the high-pass and of the leaky integrator of the velocity estimate
            parameter "sensor.filter_corner" [unit = "Hz", min = 0.0] => params.velocity_filter_corner_hz;
            /// Board sample time (1 kHz board)
            parameter "board.sample_time" [unit = "s", display_unit = "ms", min = crate::MIN_SAMPLE_TIME_S] => params.sample_time_s;
            /// Valve command before the first sample (0 V = closed)
            parameter "valve.initial_command" [unit = "V", range = 0.0..=10.0] => params.initial_command_v;
            /// Damper valve opening of table point (strictly increasing)
            parameter "table.opening[1]" [unit = "1", range = 0.0..=1.0] => table_opening[0];
            /// Damper valve opening of table point (strictly increasing)
            parameter "table.opening[2]" [unit = "1", range = 0.0..=1.0] => table_opening[1];
            /// Damper valve opening of table point (strictly increasing)
            parameter "table.opening[3]" [unit = "1", range = 0.0..=1.0] => table_opening[2];
            /// Damper valve opening of table point (strictly increasing)
            parameter "table.opening[4]" [unit = "1", range = 0.0..=1.0] => table_opening[3];
            /// Damper valve opening of table point (strictly increasing)
            parameter "table.opening[5]" [unit = "1", range = 0.0..=1.0] => table_opening[4];
            /// Damper valve opening of table point (strictly increasing)
            parameter "table.opening[6]" [unit = "1", range = 0.0..=1.0] => table_opening[5];
            /// Damper valve opening of table point (strictly increasing)
            parameter "table.opening[7]" [unit = "1", range = 0.0..=1.0] => table_opening[6];
            /// Damper valve opening of table point (strictly increasing)
            parameter "table.opening[8]" [unit = "1", range = 0.0..=1.0] => table_opening[7];
            /// Damper valve opening of table point (strictly increasing)
            parameter "table.opening[9]" [unit = "1", range = 0.0..=1.0] => table_opening[8];
            /// Equivalent damping of the damper at table.opening[i] (strictly decreasing;
            /// default: measured on SemiActiveDamper at 4 Hz, 1 mm)
            parameter "table.damping[1]" [unit = "N.s/m", display_unit = "kN.s/m", min = 0.0] => table_damping[0];
            /// Equivalent damping of the damper at table.opening[i] (strictly decreasing;
            /// default: measured on SemiActiveDamper at 4 Hz, 1 mm)
            parameter "table.damping[2]" [unit = "N.s/m", display_unit = "kN.s/m", min = 0.0] => table_damping[1];
            /// Equivalent damping of the damper at table.opening[i] (strictly decreasing;
            /// default: measured on SemiActiveDamper at 4 Hz, 1 mm)
            parameter "table.damping[3]" [unit = "N.s/m", display_unit = "kN.s/m", min = 0.0] => table_damping[2];
            /// Equivalent damping of the damper at table.opening[i] (strictly decreasing;
            /// default: measured on SemiActiveDamper at 4 Hz, 1 mm)
            parameter "table.damping[4]" [unit = "N.s/m", display_unit = "kN.s/m", min = 0.0] => table_damping[3];
            /// Equivalent damping of the damper at table.opening[i] (strictly decreasing;
            /// default: measured on SemiActiveDamper at 4 Hz, 1 mm)
            parameter "table.damping[5]" [unit = "N.s/m", display_unit = "kN.s/m", min = 0.0] => table_damping[4];
            /// Equivalent damping of the damper at table.opening[i] (strictly decreasing;
            /// default: measured on SemiActiveDamper at 4 Hz, 1 mm)
            parameter "table.damping[6]" [unit = "N.s/m", display_unit = "kN.s/m", min = 0.0] => table_damping[5];
            /// Equivalent damping of the damper at table.opening[i] (strictly decreasing;
            /// default: measured on SemiActiveDamper at 4 Hz, 1 mm)
            parameter "table.damping[7]" [unit = "N.s/m", display_unit = "kN.s/m", min = 0.0] => table_damping[6];
            /// Equivalent damping of the damper at table.opening[i] (strictly decreasing;
            /// default: measured on SemiActiveDamper at 4 Hz, 1 mm)
            parameter "table.damping[8]" [unit = "N.s/m", display_unit = "kN.s/m", min = 0.0] => table_damping[7];
            /// Equivalent damping of the damper at table.opening[i] (strictly decreasing;
            /// default: measured on SemiActiveDamper at 4 Hz, 1 mm)
            parameter "table.damping[9]" [unit = "N.s/m", display_unit = "kN.s/m", min = 0.0] => table_damping[8];

            /// Accelerometer whose integral (x sensor.sign) is the sky-hook velocity x' of (3.6):
            /// the bogie's lateral acceleration as in the seed's co-simulation (4.4), or the
            /// damper end's along its axis; used with sensor.velocity_source = estimated
            input "sensor.acceleration" [unit = "m/s2"] => board.inputs.sensor_accel_mps2;
            /// Velocity of the same sensor (ideal x'); used with sensor.velocity_source = ideal
            input "sensor.velocity" [unit = "m/s"] => board.inputs.abs_velocity_mps;
            /// Damper elongation velocity x' - x0', positive = extension
            input "damper.elongation_velocity" [unit = "m/s"] => board.inputs.elongation_velocity_mps;

            /// By-pass valve command, 0 V = closed (maximum damping) .. 10 V = open
            output "valve.command" [unit = "V", discrete = true] => board.out.command_v;
            /// Valve opening = command / 10 V (table inverse of damping.desired)
            output "valve.opening" [unit = "1", display_unit = "%", discrete = true] => board.out.opening;
            /// Desired damping from (3.11) or (3.13)
            output "damping.desired" [unit = "N.s/m", display_unit = "kN.s/m", discrete = true] => board.out.c_desired_nspm;
            /// Condition function x' (x' - x0') = x' v_e (3.11), (3.13)
            output "control.condition" [unit = "m2/s2", discrete = true] => board.out.condition;
            /// Sky-hook velocity x' used by the law (estimated or ideal, times sensor.sign)
            output "sensor.absolute_velocity" [unit = "m/s", discrete = true] => board.out.abs_velocity_mps;
            /// True when the condition function is >= 0 (damping demanded)
            output "control.on_state" => board.out.on_state;
        }
        declare_board_status!(
            v,
            " True if a used input of the last step was not finite (sample dropped, command held)"
        );
        v
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
        Ok(Self {
            board: Board::new::<Self>(&params)?,
            params,
            table_opening,
            table_damping,
        })
    }

    board_life_cycle!();
}

const DOC: &str = r#"
<h2>Law</h2>
<p>Sky-hook control of the semi-active yaw damper, seed section 3.2.1.2 (law chosen by
<code>control.mode</code>). The ideal sky-hook force
is F_sky = c_sky x' (3.6) with x' the absolute velocity of the bogie-side damper end; the damper
can only give F = c (x' - x0'), so each board sample (period <code>board.sample_time</code>, 1 ms)
chooses the damping</p>
<pre>
continuous (3.11):  c = clamp(c_sky x' / (x' - x0'), c_min, c_max)  if x' (x' - x0') &gt;= 0
                    c = c_min                                        otherwise
on/off (3.13):      c = c_max  if x' (x' - x0') &gt;= 0,  c_min otherwise
</pre>
<p>and turns c into a valve opening by inverting the damper's equivalent damping-vs-opening table
(piecewise linear, clamped: damping above the closed value gives 0 V, below the open value 10 V);
<code>valve.command</code> = 10 V x opening, 0 V = closed = maximum damping.</p>
<h2>Sign conventions</h2>
<p>Damper elongation positive = extension, x' - x0' = <code>damper.elongation_velocity</code>,
damper force tension positive (F = +c v_e). x' = <code>sensor.sign</code> times the integrated
<code>sensor.acceleration</code> (or <code>sensor.velocity</code>).</p>
<h2>Which velocity is x' (interpretation)</h2>
<p>The seed's co-simulation (section 4.4) gives the controller only the damper's piston velocity
and the lateral acceleration of the bogie, so its sky-hook integrates the <b>lateral</b>
acceleration: lateral and yaw motion of a hunting bogie are roughly in quadrature, the condition
x' (x' - x0') changes sign twice per cycle, and the valve switches frequently between open and
closed as in the seed's Figs. 4.19-4.20. Connect the bogie's lateral frame acceleration to
<code>sensor.acceleration</code> for that behaviour (the project's study does, with
<code>sensor.sign</code> = -1 on the left damper and +1 on the right so both switch together).
The textbook alternative, the absolute acceleration of the bogie-side damper end along the damper
axis, gives x' = x' - x0' when the car body does not move: the condition is then always &gt;= 0 and
the damper stays closed except for the phase lead of the estimate.</p>
<h2>Velocity estimate (seed 2.3.2)</h2>
<p><code>sensor.velocity_source</code> = estimated (default): x' is estimated from
<code>sensor.acceleration</code> by a first-order high-pass and a leaky integrator with
the same corner <code>sensor.filter_corner</code> (0.3 Hz), G(s) = s/(s + w_c)^2: at 4 Hz the gain is
within 1 % of an integrator and the phase lead 8.6 deg; an accelerometer offset gives no velocity.
<code>sensor.velocity_source</code> = ideal uses <code>sensor.velocity</code>.</p>
<h2>Damping table</h2>
<p><code>table.opening[i]</code> / <code>table.damping[i]</code>, i = 1..9: openings strictly
increasing in [0, 1], damping strictly decreasing; checked at fmi2ExitInitializationMode (the
offending element is named). The defaults are the equivalent damping c_eq = Im(F/x)/omega of the
project's SemiActiveDamper at 4 Hz and 1 mm amplitude, measured on its calibrated model
(325.7 kN.s/m closed ... 24.3 kN.s/m open; an end-to-end test re-measures them). Replace them by
your damper's table when you use another damper. c_min and c_max (<code>damping.min</code>,
<code>damping.max</code>) default to the table's ends but do not follow a changed table. c_sky
(<code>damping.sky_hook</code>) = 330 kN.s/m is not in
the seed (same magnitude as c_v of (3.14)).</p>
<h2>Timing and co-simulation</h2>
<p>Samples at <code>start_time + k board.sample_time</code>; the command computed from the inputs sampled at
t_k is output from t_(k+1) on (one sample of computational delay), so no output depends on the
inputs at the same instant (no direct feedthrough, no algebraic loop with the damper). With a
communication step dividing the sample time the results are independent of the step. NaN/inf inputs
are rejected when set (fmi2Error); the unused absolute input may be anything finite. Switching of
<code>control.on_state</code> is logged as an event (logEvents) when it changes.</p>
"#;
