//! `MpptController` FMU: the MPPT board of [`crate::mppt`].

use model_description::{
    fmi_enum, Codec, DefaultExperiment, Diagnostics, EnumItem, EnumType, FmuModel, InstanceContext,
    ModelError, ModelInfo, Native, Sign, StepError, Variable,
};
use serde::{Deserialize, Serialize};

use super::{report_input_fault, Board, AUTHOR};
use crate::mppt::{ForceNormaliser, Mppt, MpptOutputs, MpptParams};

fmi_enum! {
    ForceNormaliser as "ForceNormaliser", "Force normaliser of the MPPT cost (3.2)" {
        Fixed = 0, "fixed", "The fixed value F_norm (default: J depends on the current state only)";
        RunningMax = 1, "running_max", "The running maximum of the rms force, from F_norm (the seed literally)";
    }
}

/// `band_pass.order` as the Enumeration `BandPassOrder`: the design takes 2 or 4 (one or two
/// Butterworth prototype poles per edge), so the glue refuses any other order when it is set.
struct FilterOrder;

static BAND_PASS_ORDER: EnumType = EnumType {
    name: "BandPassOrder",
    description: "Order of the Butterworth band-pass",
    items: &[
        EnumItem {
            name: "second",
            value: 2,
            description: "Second order (a first-order prototype)",
        },
        EnumItem {
            name: "fourth",
            value: 4,
            description: "Fourth order (a second-order prototype)",
        },
    ],
};

impl Codec<u32> for FilterOrder {
    type Fmi = i32;
    const ENUMERATION: Option<&'static EnumType> = Some(&BAND_PASS_ORDER);
    // the field's own Integer form; the glue sets items only (2 or 4)
    fn get(field: &u32) -> i32 {
        <Native as Codec<u32>>::get(field)
    }
    fn set(field: &mut u32, value: i32) {
        <Native as Codec<u32>>::set(field, value);
    }
}

/// What was last reported, so that the log shows changes only.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
struct Reported {
    updates: u64,
    override_active: bool,
    input_fault: bool,
    at_limit: bool,
}

/// MPPT valve controller FMU (plain data: FMU state save/restore clones it).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct MpptController {
    params: MpptParams,
    board: Board<Mppt, Reported>,
}

impl MpptController {
    fn build(&mut self) -> Result<(), ModelError> {
        self.board.build::<Self>(&self.params)
    }

    fn at_limit(&self, o: &MpptOutputs) -> bool {
        o.command_v <= self.params.command_min_v || o.command_v >= self.params.command_max_v
    }

    /// A command starting at its limit is not news.
    fn reported_after_init(&self) -> Reported {
        Reported {
            at_limit: self.at_limit(&self.board.out),
            ..Reported::default()
        }
    }

    /// Log what changed in this step (never once per sample).
    fn report(&mut self, t_end: f64, o: &MpptOutputs, diag: &mut Diagnostics) {
        let r = &mut self.board.reported;
        if o.updates > r.updates {
            diag.event(format!(
                "t = {t_end:.6} s: valve update #{}: J = {:.6} (rms a = {:.4} m/s2, rms F = {:.1} N), \
                 command {:.4} V, direction {:+}",
                o.updates, o.cost, o.rms_accel_mps2, o.rms_force_n, o.command_v, o.direction
            ));
            r.updates = o.updates;
        }
        if o.override_active != r.override_active {
            if o.override_active {
                diag.warn(format!(
                    "t = {t_end:.6} s: rms acceleration {:.3} m/s2 above the threshold {:.3} m/s2: \
                     instability override (3.5), closing the valve by Delta_V = {} V per update",
                    o.rms_accel_mps2, self.params.acc_threshold_mps2, self.params.delta_v_v
                ));
            } else {
                diag.event(format!(
                    "t = {t_end:.6} s: rms acceleration back below the threshold, hill climb resumed"
                ));
            }
            r.override_active = o.override_active;
        }
        report_input_fault(
            t_end,
            o.input_fault,
            o.dropped_samples,
            &mut r.input_fault,
            diag,
        );
        let at_limit = self.at_limit(o);
        if at_limit != self.board.reported.at_limit {
            diag.event(if at_limit {
                format!(
                    "t = {t_end:.6} s: valve command saturated at {} V",
                    o.command_v
                )
            } else {
                format!("t = {t_end:.6} s: valve command left its limit")
            });
            self.board.reported.at_limit = at_limit;
        }
    }
}

impl FmuModel for MpptController {
    const INFO: ModelInfo = ModelInfo {
        name: "MpptController",
        description: "Semi-active yaw damper valve control by maximum power point tracking \
                      (hill climbing on an acceleration/force cost, seed 3.2.1.1)",
        author: AUTHOR,
        version: env!("CARGO_PKG_VERSION"),
        default_experiment: DefaultExperiment {
            start_time: 0.0,
            stop_time: 10.0,
            step_size: 1e-3,
        },
        documentation_html: DOC,
        resources: &[],
    };

    fn variables() -> Vec<Variable<Self>> {
        let mut v: Vec<Variable<Self>> = Vec::new();
        model_description::declare! { v;
            /// Weight k_x of the acceleration term of the cost (3.2); Table 4-2: 1
            parameter "cost.acceleration_weight" [unit = "1", min = 0.0] => params.k_acc;
            /// Weight k_F of the force term of the cost (3.2); Table 4-2: 0 = MPPT1, 4 = MPPT2
            parameter "cost.force_weight" [unit = "1", min = 0.0] => params.k_force;
            /// Cost gain k_J of the hill-climb step (3.3) (not in the seed)
            parameter "hill_climb.gain" [unit = "V", min = 0.0] => params.k_j_v;
            /// Valve update period (seed: every second); integer multiple of board.sample_time
            parameter "hill_climb.period" [unit = "s", min = 0.0] => params.update_period_s;
            /// Length of the moving rms windows of acceleration and force
            parameter "cost.rms_window" [unit = "s", min = 0.0] => params.rms_window_s;
            /// Emergency closing step of the instability override (3.5) (not in the seed)
            parameter "override.closing_step" [unit = "V", min = 0.0] => params.delta_v_v;
            /// Instability threshold on the rms band-passed acceleration (3.5); default
            /// cost.acceleration_limit. The study sets a_lim / 2 = 2.7 m/s2: the board's 1 s rms
            /// of a developed limit cycle is about a_lim, so the emergency closing stopped half way
            parameter "override.threshold" [unit = "m/s2", min = 0.0] => params.acc_threshold_mps2;
            /// EN 14363 lateral acceleration limit normalising (3.2), (12 - m/5)/2 (seed 4.2)
            parameter "cost.acceleration_limit" [unit = "m/s2", min = 0.0] => params.a_lim_mps2;
            /// Force normaliser of (3.2) (fixed value, or start of the running maximum)
            parameter "cost.force_norm" [unit = "N", display_unit = "kN", min = 0.0] => params.force_norm_n;
            /// Fixed F_norm (default) or the running maximum of the rms force (seed literal)
            parameter "cost.force_normaliser" => params.force_normaliser;
            /// Valve command before the first update (0 V = closed, maximum damping)
            parameter "valve.initial_command" [unit = "V", range = 0.0..=10.0] => params.initial_command_v;
            /// Initial hill-climb direction: +1 opening, -1 closing
            parameter "hill_climb.initial_direction" => params.initial_direction as Sign;
            /// Lower command saturation (seed 4.4.1: 0 V)
            parameter "valve.command_min" [unit = "V", range = 0.0..=10.0] => params.command_min_v;
            /// Upper command saturation (seed 4.4.1: 10 V)
            parameter "valve.command_max" [unit = "V", range = 0.0..=10.0] => params.command_max_v;
            /// Board sample time (1 kHz board)
            parameter "board.sample_time" [unit = "s", display_unit = "ms", min = crate::MIN_SAMPLE_TIME_S] => params.sample_time_s;
            /// Order of the Butterworth band-pass on the acceleration: 2 or 4
            parameter "band_pass.order" => params.filter_order as FilterOrder;
            /// Band-pass lower -3 dB edge, f0 - 2 Hz (EN 14363 via seed 4.2)
            parameter "band_pass.low" [unit = "Hz", min = 0.0] => params.band_low_hz;
            /// Band-pass upper -3 dB edge, f0 + 2 Hz. The study sets 8 Hz: the flange-contact limit
            /// cycles run at 5.5-6.5 Hz, at the 6 Hz default's edge
            parameter "band_pass.high" [unit = "Hz", min = 0.0] => params.band_high_hz;

            /// Bogie frame lateral acceleration (band-passed on the board)
            input "bogie.lateral_acceleration" [unit = "m/s2"] => board.inputs.bogie_accel_mps2;
            /// Yaw damper force, tension positive (only its rms is used)
            input "damper.force" [unit = "N", display_unit = "kN"] => board.inputs.damper_force_n;

            /// By-pass valve command, 0 V = closed (maximum damping) .. 10 V = open
            output "valve.command" [unit = "V", discrete = true] => board.out.command_v;
            /// Valve opening = command / 10 V
            output "valve.opening" [unit = "1", display_unit = "%", discrete = true] => board.out.opening;
            /// Cost J at the last update (3.2)
            output "cost.value" [unit = "1", discrete = true] => board.out.cost;
            /// rms of the band-passed bogie acceleration at the last update
            output "cost.rms_acceleration" [unit = "m/s2", discrete = true] => board.out.rms_accel_mps2;
            /// rms of the damper force at the last update
            output "cost.rms_force" [unit = "N", display_unit = "kN", discrete = true] => board.out.rms_force_n;
            /// Latest band-passed acceleration sample
            output "band_pass.acceleration" [unit = "m/s2", discrete = true] => board.out.filtered_accel_mps2;
            /// Hill-climb direction (3.4): +1 opening, -1 closing
            output "hill_climb.direction" => board.out.direction as Sign;
            /// True if the last update was the instability override (3.5)
            output "override.active" => board.out.override_active;
            /// Number of valve updates performed
            output "hill_climb.updates" => board.out.updates;
        }
        declare_board_status!(v);
        v
    }

    // The start values are the physics crate's MPPT2 defaults.
    board_life_cycle!(instantiate);
}

const DOC: &str = r#"
<h2>Law</h2>
<p>Maximum power point tracking of the semi-active yaw damper's by-pass valve, seed section
3.2.1.1. A sampled board (period <code>board.sample_time</code>, default 1 ms) band-passes the
bogie lateral acceleration (Butterworth, order <code>band_pass.order</code>, edges
<code>band_pass.low</code> .. <code>band_pass.high</code> = f0 &plusmn; 2 Hz with f0 = 4 Hz, EN 14363
via seed 4.2), keeps moving rms values of the filtered acceleration and of the damper force over
<code>cost.rms_window</code>, and every <code>hill_climb.period</code> (default 1 s, "every one
second") updates the command:</p>
<pre>
J = k_acc (rms_a / a_lim)^2 + k_F (rms_F / F_norm)^2                      (3.2)
direction kept if J &lt; J_old, reversed if J &gt;= J_old                       (3.4)
V = V_old + direction * k_J |J - J_old| / max(J, J_old)                    (3.3)
V = V_old - Delta_V   if rms_a &gt; threshold  (then direction = closing)    (3.5)
V saturated to [command_min, command_max] = [0, 10] V                      (seed 4.4.1)
</pre>
<p>The first update only measures J (no J_old yet); the override (3.5) applies from the first
update. 0 V = valve closed = maximum damping (the safe power-up state, default initial command);
10 V = fully open; <code>valve.opening</code> = command / 10 V.</p>
<h2>Presets (Table 4-2)</h2>
<ul>
<li><b>MPPT1</b>: k_acc = 1, k_F = 0 (acceleration only).</li>
<li><b>MPPT2</b> (default): k_acc = 1, k_F = 4 (acceleration and force).</li>
</ul>
<h2>Symbols and variables</h2>
<table border="1">
<tr><th>symbol</th><th>variable</th></tr>
<tr><td>k_acc, k_F</td><td>cost.acceleration_weight, cost.force_weight</td></tr>
<tr><td>a_lim, F_norm</td><td>cost.acceleration_limit, cost.force_norm</td></tr>
<tr><td>k_J</td><td>hill_climb.gain</td></tr>
<tr><td>Delta_V, threshold</td><td>override.closing_step, override.threshold</td></tr>
<tr><td>command_min, command_max</td><td>valve.command_min, valve.command_max</td></tr>
</table>
<ul>
</ul>
<h2>Interpretations (seed silent or garbled)</h2>
<ul>
<li><code>max(RMS(F))</code> in (3.2) is a running maximum in the seed, which mixes normalisers
between J and J_old. Default: fixed F_norm = 10 kN (about the rms force of a closed valve at
hunting amplitude, R1); <code>cost.force_normaliser</code> = running_max gives the seed's running
maximum starting from F_norm.</li>
<li>k_J = 1 V and Delta_V = 2 V are not given in the seed (2 V per update
closes a fully open valve in 5 s, as in Fig. 4.18).</li>
<li>threshold = a_lim = 5.39 m/s2, the EN 14363 limit of the seed's bogie.</li>
<li>An update period containing a dropped sample is skipped (command held, J_old kept).</li>
</ul>
<h2>Timing and co-simulation</h2>
<p>Samples at <code>start_time + k board.sample_time</code>. The command computed from the inputs sampled at
t_k is output from t_(k+1) on (one sample of computational delay, as on a real board), so no output
depends on the inputs at the same instant: ModelStructure declares no direct feedthrough and a
controller-damper loop has no algebraic loop. With a communication step that divides the sample
time (1e-4 or 1e-3 s with the 1 ms board) the results do not depend on the step; coarser steps hold
the inputs over the step. Inputs are held constant over a communication step.</p>
<p>NaN/inf inputs are rejected when set (fmi2Error, variable named in the log). Logged: every valve
update (logEvents), the start of an override (3.5) (warning) and its end, command saturation
changes; the internal hold-and-warn path for non-finite samples (warning when it starts).</p>
"#;
