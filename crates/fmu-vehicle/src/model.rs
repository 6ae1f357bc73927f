//! Time-domain coach for co-simulation: [`Vehicle`] with [`Inputs`] and [`Outputs`].
//!
//! Integration: classical RK4 with a fixed internal sub-step (at most
//! [`VehicleParams::solver_substep_s`], chosen by the convergence study in
//! [`crate::calibration`]); the communication step is split into n = ceil(h / h_sub) equal
//! sub-steps. Fixed cost per communication step, no allocation, deterministic. Damper forces
//! and the external track input are held over a communication step; the trailing wheelsets'
//! external alignment is interpolated linearly between its values at the step ends, the
//! internal generator (wheel-rail's ERRI B176 realisation) is evaluated at every RK4 stage.
//! Every wheelset sees the same track, delayed by its distance behind the leading wheelset
//! over the speed (external input: through a spatial delay line).
//!
//! Direct feedthrough: the yaw-damper forces act on frame and car-body yaw, so the
//! accelerations of frame and car-body points away from their centres (frame over the axle
//! boxes, car body over the bogies, damper ends) depend on them at the same instant; the track
//! input reaches the leading wheelset's relative displacement, guiding force, Y/Q and
//! acceleration at once. [`Vehicle::outputs`] evaluates them without stepping.

use serde::{Deserialize, Serialize};
use vehicle_elements::{blame, check_inputs, check_step, stable_substep, substep_count, TooStiff};

pub use vehicle_elements::InputError;
use wheel_rail::{FlangeNotCovered, GeometryTable, SegmentHint, TableError};

use crate::dynamics::{rhs, Consts, Eval, N_STATES, RATES};
use crate::layout::{
    damper_bogie, damper_side, frame_roll, frame_y, frame_yaw, wheelset_y, wheelset_yaw, Positions,
    Suspension, CARBODY_ROLL, CARBODY_Y, CARBODY_YAW, N_BOGIES, N_DAMPERS, N_WHEELSETS,
};
use crate::params::{ContactSource, ParamError, TrackSource, VehicleParams};
use wheel_rail::track::{DelayLine, TrackGenerator};

/// The worn-profile surrogate table shipped with the crate (the 2-dof bogie's default table:
/// EN 15302 A/A with a 0.25 cone on the central +-3.5 mm of the tread, A/A flange).
pub const WORN_SURROGATE_CSV: &str = include_str!("../resources/wheel_rail_worn_surrogate.csv");

/// The shipped default table.
pub fn worn_surrogate_table() -> Result<GeometryTable, TableError> {
    GeometryTable::parse_csv(WORN_SURROGATE_CSV, "built-in wheel_rail_worn_surrogate.csv")
}

/// Errors when building the model.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ModelError {
    /// Invalid parameter.
    #[error(transparent)]
    Param(#[from] ParamError),
    /// The contact table could not be read.
    #[error(transparent)]
    Table(#[from] TableError),
    /// The parameters need an internal step too short to compute.
    #[error(transparent)]
    TooStiff(#[from] TooStiff),
    /// The contact table does not reach flange contact on one side.
    #[error(transparent)]
    FlangeNotCovered(#[from] FlangeNotCovered),
    /// The suspension cannot hold the car body and frames upright on wheelsets held still:
    /// gravity's overturning moment (heights of the centres of gravity above the springs)
    /// exceeds the roll stiffness, and the small-angle model would let the body tip over.
    #[error(
        "the suspension cannot hold the car body and bogie frames upright: the stiffness of \
         car body and frames on fixed wheelsets is not positive definite (smallest eigenvalue \
         {smallest:.3e}, a {body} roll or sway); raise the vertical or anti-roll stiffness \
         (secondary.*, primary.*) or their lateral spacing, or lower carbody.cg_height / \
         frame.cg_height"
    )]
    StaticallyUnstable {
        /// Smallest eigenvalue of that stiffness matrix (scaled to a unit diagonal).
        smallest: f64,
        /// The body with the largest share of that eigenvector.
        body: &'static str,
        /// The changed parameter whose default alone steadies the bodies most (its path in
        /// [`VehicleParams`]), if one does.
        parameter: Option<String>,
    },
    /// A wheelset starts beyond the contact table's range (derailed before the first step).
    #[error(
        "the initial displacement puts wheelset {wheelset} {y_mm:.2} mm from the track centre, \
         beyond the contact table's range ({lo_mm:.2} to {hi_mm:.2} mm): lower \
         initial.lateral_displacement or initial.yaw_angle"
    )]
    StartsDerailed {
        /// Wheelset number, 1 = leading.
        wheelset: usize,
        /// Its initial lateral displacement \[mm\].
        y_mm: f64,
        /// The table's range \[mm\].
        lo_mm: f64,
        hi_mm: f64,
    },
}

/// The smallest eigenvalue of the stiffness matrix over the car body's and frames' dofs
/// (lateral, yaw, roll each; gravitational roll terms included) on wheelsets held still,
/// scaled to a unit diagonal so that N/m and N m/rad compare, and the body that moves most in
/// its mode.
fn static_stability(params: &VehicleParams) -> (f64, &'static str) {
    let k = Suspension::new(params).k;
    let dofs = [
        CARBODY_Y,
        CARBODY_YAW,
        CARBODY_ROLL,
        frame_y(0),
        frame_yaw(0),
        frame_roll(0),
        frame_y(1),
        frame_yaw(1),
        frame_roll(1),
    ];
    let scale: Vec<f64> = dofs
        .iter()
        .map(|&i| k[(i, i)].abs().sqrt().max(1e-300))
        .collect();
    let sub = nalgebra::DMatrix::from_fn(dofs.len(), dofs.len(), |r, c| {
        0.5 * (k[(dofs[r], dofs[c])] + k[(dofs[c], dofs[r])]) / (scale[r] * scale[c])
    });
    let eigen = sub.symmetric_eigen();
    let Some((at, &smallest)) = eigen
        .eigenvalues
        .iter()
        .enumerate()
        .min_by(|a, b| a.1.total_cmp(b.1))
    else {
        return (f64::NAN, "car-body");
    };
    let v = eigen.eigenvectors.column(at);
    let share = |range: std::ops::Range<usize>| range.map(|i| v[i] * v[i]).sum::<f64>();
    let body = [
        ("car-body", share(0..3)),
        ("front frame", share(3..6)),
        ("rear frame", share(6..9)),
    ]
    .into_iter()
    .max_by(|a, b| a.1.total_cmp(&b.1))
    .map_or("car-body", |b| b.0);
    (smallest, body)
}

/// The car body and frames rest statically stable on wheelsets held still
/// ([`static_stability`] positive); else the error, with the parameter to blame.
fn check_static_stability(params: &VehicleParams) -> Result<(), ModelError> {
    let (smallest, body) = static_stability(params);
    if smallest > 1e-9 {
        return Ok(());
    }
    let parameter = blame(params, &VehicleParams::default(), |p| static_stability(p).0);
    Err(ModelError::StaticallyUnstable {
        smallest,
        body,
        parameter,
    })
}

/// Errors of a step or an output evaluation; the model is unchanged after any of them.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum StepError {
    /// A non-finite input or an unusable step size.
    #[error(transparent)]
    Input(#[from] InputError),
    /// The state became NaN or infinite.
    #[error("state diverged at t = {time_s} s")]
    Diverged {
        /// Time \[s\].
        time_s: f64,
    },
    /// A wheelset left the contact table's range: it has climbed the flange (derailment).
    #[error(
        "derailment at t = {time_s:.4} s: wheelset {wheelset} displaced {y_rel_mm:.2} mm \
         relative to the track, beyond the contact table's range ({limit_mm:.2} mm)"
    )]
    Derailed {
        /// Time \[s\].
        time_s: f64,
        /// Wheelset number, 1 = leading.
        wheelset: usize,
        /// Displacement relative to the track \[mm\].
        y_rel_mm: f64,
        /// Table range on that side \[mm\].
        limit_mm: f64,
    },
}

/// Inputs of one communication step.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Inputs {
    /// Yaw damper forces, tension positive \[N\]: front left, front right, rear left, rear right.
    pub damper_force_n: [f64; N_DAMPERS],
    /// Track lateral alignment under the leading wheelset, positive right \[m\] (used when the
    /// track source is External).
    pub track_lateral_m: f64,
}

impl Inputs {
    fn check(&self) -> Result<(), InputError> {
        const NAMES: [&str; N_DAMPERS] = [
            "damper_force_n[0]",
            "damper_force_n[1]",
            "damper_force_n[2]",
            "damper_force_n[3]",
        ];
        check_inputs(NAMES.into_iter().zip(self.damper_force_n))?;
        check_inputs([("track_lateral_m", self.track_lateral_m)])
    }
}

/// Outputs of one wheelset.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct WheelsetOutputs {
    /// Lateral displacement (absolute) \[m\].
    pub lateral_m: f64,
    /// Lateral displacement relative to the track \[m\].
    pub lateral_rel_track_m: f64,
    /// Lateral velocity [m/s].
    pub lateral_velocity_mps: f64,
    /// Lateral acceleration [m/s^2].
    pub lateral_acc_mps2: f64,
    /// Yaw angle, nose-left \[rad\].
    pub yaw_rad: f64,
    /// Guiding force: sum of the lateral forces of the rails on the wheelset, positive right \[N\].
    pub guiding_force_n: f64,
    /// Y/Q of the wheel with the larger lateral force: max(|Y_L|, |Y_R|) / P [-].
    pub y_over_q: f64,
    /// Track alignment under the wheelset \[m\].
    pub track_m: f64,
}

/// Outputs of one bogie frame.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct FrameOutputs {
    /// Lateral displacement of the centre \[m\].
    pub lateral_m: f64,
    /// Yaw angle, nose-left \[rad\].
    pub yaw_rad: f64,
    /// Roll angle \[rad\].
    pub roll_rad: f64,
    /// Lateral acceleration of the frame over its leading axle box, at the frame's centre
    /// height (EN 14363 stability quantity) [m/s^2].
    pub lateral_acc_leading_axle_mps2: f64,
    /// Same over the trailing axle box [m/s^2].
    pub lateral_acc_trailing_axle_mps2: f64,
}

/// Outputs of the car body (accelerations at floor height, kinematic, without the gravity
/// component g phi an accelerometer tilting with the body would add).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct CarBodyOutputs {
    /// Lateral displacement of the centre of gravity \[m\].
    pub lateral_m: f64,
    /// Yaw angle, nose-left \[rad\].
    pub yaw_rad: f64,
    /// Roll angle \[rad\].
    pub roll_rad: f64,
    /// Lateral acceleration at floor height above the front bogie centre [m/s^2].
    pub lateral_acc_front_mps2: f64,
    /// Same at mid-length [m/s^2].
    pub lateral_acc_mid_mps2: f64,
    /// Same above the rear bogie centre [m/s^2].
    pub lateral_acc_rear_mps2: f64,
}

/// Outputs of one yaw damper. Velocities and accelerations of the attachment points are
/// absolute, along the damper axis (longitudinal), positive forward (from the frame end
/// towards the car-body end); elongation velocity = car-body end - frame end.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct DamperOutputs {
    /// Elongation, extension positive \[m\].
    pub elongation_m: f64,
    /// Elongation velocity [m/s].
    pub elongation_velocity_mps: f64,
    /// Velocity of the car-body end [m/s].
    pub carbody_end_velocity_mps: f64,
    /// Acceleration of the car-body end [m/s^2].
    pub carbody_end_acc_mps2: f64,
    /// Velocity of the frame end [m/s].
    pub frame_end_velocity_mps: f64,
    /// Acceleration of the frame end [m/s^2].
    pub frame_end_acc_mps2: f64,
}

/// All outputs at one instant.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Outputs {
    /// Time \[s\].
    pub time_s: f64,
    /// Wheelsets, leading first.
    pub wheelset: [WheelsetOutputs; N_WHEELSETS],
    /// Frames, front first.
    pub frame: [FrameOutputs; N_BOGIES],
    /// Car body.
    pub carbody: CarBodyOutputs,
    /// Yaw dampers: front left, front right, rear left, rear right.
    pub damper: [DamperOutputs; N_DAMPERS],
}

/// The coach: plain data, clonable and serialisable (FMU state).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Vehicle {
    params: VehicleParams,
    consts: Consts,
    table: GeometryTable,
    table_range_m: (f64, f64),
    hints: [SegmentHint; N_WHEELSETS],
    positions: Positions,
    #[serde(with = "state_serde")]
    state: [f64; N_STATES],
    time_s: f64,
    /// Distance travelled [m].
    position_m: f64,
    track: Track,
    /// Largest sub-step used [s]: the parameter, or less where stability needs it.
    substep_s: f64,
}

/// Where the alignment under the wheelsets comes from, with its memory.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
enum Track {
    /// Straight ideal track.
    None,
    /// External input under the leading wheelset, recorded for the trailing ones.
    External(DelayLine),
    /// Internal generator (synthesised once on a grid, interpolated).
    Internal(TrackGenerator),
}

impl Vehicle {
    /// Validates the parameters and loads the contact table.
    pub fn new(params: VehicleParams) -> Result<Self, ModelError> {
        let table = match &params.contact {
            ContactSource::WornSurrogate => worn_surrogate_table()?,
            ContactSource::File(path) => GeometryTable::load(path)?,
        };
        Self::with_table(params, table)
    }

    /// As [`Self::new`] with an explicit contact table (`params.contact` is ignored).
    pub fn with_table(params: VehicleParams, table: GeometryTable) -> Result<Self, ModelError> {
        params.validate()?;
        table.check_for_wheel(params.wheelset.wheel_radius_m)?;
        table.check_flange()?;
        let consts = Consts::new(&params, &table);
        let positions = Positions::new(&params);
        let mut state = [0.0; N_STATES];
        for i in 0..N_BOGIES {
            state[frame_y(i)] = params.initial.lateral_m;
            state[frame_yaw(i)] = params.initial.yaw_rad;
        }
        for j in 0..N_WHEELSETS {
            let arm = positions.wheelset_x_m[j] - positions.bogie_x_m[j / 2];
            state[wheelset_y(j)] = params.initial.lateral_m - arm * params.initial.yaw_rad;
            state[wheelset_yaw(j)] = params.initial.yaw_rad;
        }
        let (lo, hi) = table.y_range();
        for j in 0..N_WHEELSETS {
            let y = state[wheelset_y(j)];
            if !(lo..=hi).contains(&y) {
                return Err(ModelError::StartsDerailed {
                    wheelset: j + 1,
                    y_mm: y * 1e3,
                    lo_mm: lo * 1e3,
                    hi_mm: hi * 1e3,
                });
            }
        }
        let longest = positions.wheelset_delay_m[N_WHEELSETS - 1];
        let track = match params.track {
            TrackSource::None => Track::None,
            TrackSource::External => Track::External(DelayLine::new(longest)),
            TrackSource::Internal { level, seed } => {
                Track::Internal(TrackGenerator::new(level, seed))
            }
        };
        let stable_s = stable_substep(&params, consts.stable_substep_s(&params, &table), |p| {
            Consts::new(p, &table).stable_substep_s(p, &table)
        })?;
        let substep_s = params.solver_substep_s.min(stable_s);
        // after the step check, which refuses stiffnesses too far apart to compare
        check_static_stability(&params)?;
        Ok(Self {
            substep_s,
            table_range_m: table.y_range(),
            params,
            consts,
            table,
            hints: [SegmentHint::default(); N_WHEELSETS],
            positions,
            state,
            time_s: 0.0,
            position_m: 0.0,
            track,
        })
    }

    /// Parameters in use.
    pub fn params(&self) -> &VehicleParams {
        &self.params
    }

    /// Contact table in use.
    pub fn contact_table(&self) -> &GeometryTable {
        &self.table
    }

    /// Current time \[s\].
    pub fn time_s(&self) -> f64 {
        self.time_s
    }

    /// The state (q, q', spin rates).
    pub fn state(&self) -> &[f64; N_STATES] {
        &self.state
    }

    /// Overwrites the state (must be finite).
    pub fn set_state(&mut self, state: [f64; N_STATES]) -> Result<(), StepError> {
        if state.iter().any(|v| !v.is_finite()) {
            return Err(StepError::Diverged {
                time_s: self.time_s,
            });
        }
        self.state = state;
        Ok(())
    }

    /// Largest internal sub-step \[s\] (the parameter, lowered where stability needs it).
    pub fn substep_s(&self) -> f64 {
        self.substep_s
    }

    /// Number of internal sub-steps for a communication step h.
    pub fn substeps(&self, h: f64) -> Result<usize, InputError> {
        substep_count(h, self.substep_s)
    }

    /// Alignment under each wheelset when the leading one is at `x` and the external input
    /// is `input` (External: the trailing ones read the record, the leading one sees the input).
    fn track_at(&self, x: f64, input: f64) -> [f64; N_WHEELSETS] {
        let d = &self.positions.wheelset_delay_m;
        match &self.track {
            Track::None => [0.0; N_WHEELSETS],
            Track::External(line) => {
                let at = |k: usize| line.at(x - d[k]).unwrap_or(input);
                [input, at(1), at(2), at(3)]
            }
            Track::Internal(g) => g.eval_behind(x, *d),
        }
    }

    /// Outputs at the current time for the given inputs (no stepping).
    pub fn outputs(&self, inputs: &Inputs) -> Result<Outputs, StepError> {
        inputs.check()?;
        let yt = self.track_at(self.position_m, inputs.track_lateral_m);
        let mut hints = self.hints;
        Ok(self.outputs_with(&self.state, &mut hints, &yt, inputs))
    }

    fn outputs_with(
        &self,
        x: &[f64; N_STATES],
        hints: &mut [SegmentHint; N_WHEELSETS],
        yt: &[f64; N_WHEELSETS],
        inputs: &Inputs,
    ) -> Outputs {
        let c = &self.consts;
        let e: Eval = rhs(c, &self.table, hints, x, yt, &inputs.damper_force_n);
        let acc = |i: usize| e.dx[RATES + i];
        let p = &self.params;
        let pos = &self.positions;
        let mut o = Outputs {
            time_s: self.time_s,
            ..Outputs::default()
        };
        for (j, (w, &track_m)) in e.wheelsets.iter().zip(yt).enumerate() {
            let (iy, ip) = (wheelset_y(j), wheelset_yaw(j));
            o.wheelset[j] = WheelsetOutputs {
                lateral_m: x[iy],
                lateral_rel_track_m: x[iy] - track_m,
                lateral_velocity_mps: x[RATES + iy],
                lateral_acc_mps2: acc(iy),
                yaw_rad: x[ip],
                guiding_force_n: w.lateral_n,
                y_over_q: w.left_n.abs().max(w.right_n.abs()) / c.load,
                track_m,
            };
        }
        let arm = p.geometry.half_wheelbase_m;
        for i in 0..N_BOGIES {
            let (iy, ip) = (frame_y(i), frame_yaw(i));
            o.frame[i] = FrameOutputs {
                lateral_m: x[iy],
                yaw_rad: x[ip],
                roll_rad: x[frame_roll(i)],
                // point at +p (leading axle) moves laterally by -p psi
                lateral_acc_leading_axle_mps2: acc(iy) - arm * acc(ip),
                lateral_acc_trailing_axle_mps2: acc(iy) + arm * acc(ip),
            };
        }
        let dz = p.carbody.floor_height_m - p.carbody.cg_height_m;
        let cb = |xp: f64| acc(CARBODY_Y) - xp * acc(CARBODY_YAW) + dz * acc(CARBODY_ROLL);
        o.carbody = CarBodyOutputs {
            lateral_m: x[CARBODY_Y],
            yaw_rad: x[CARBODY_YAW],
            roll_rad: x[CARBODY_ROLL],
            lateral_acc_front_mps2: cb(pos.bogie_x_m[0]),
            lateral_acc_mid_mps2: cb(0.0),
            lateral_acc_rear_mps2: cb(pos.bogie_x_m[1]),
        };
        let b = p.geometry.damper_arm_m;
        for d in 0..N_DAMPERS {
            // attachment at lateral coordinate Y = side b: longitudinal u_x = psi Y
            let arm_y = damper_side(d) * b;
            let fy = frame_yaw(damper_bogie(d));
            let (cb_v, fr_v) = (arm_y * x[RATES + CARBODY_YAW], arm_y * x[RATES + fy]);
            let (cb_a, fr_a) = (arm_y * acc(CARBODY_YAW), arm_y * acc(fy));
            o.damper[d] = DamperOutputs {
                elongation_m: arm_y * (x[CARBODY_YAW] - x[fy]),
                elongation_velocity_mps: cb_v - fr_v,
                carbody_end_velocity_mps: cb_v,
                carbody_end_acc_mps2: cb_a,
                frame_end_velocity_mps: fr_v,
                frame_end_acc_mps2: fr_a,
            };
        }
        o
    }

    /// Advances over one communication step h with the inputs held; returns the outputs at the
    /// end of the step. On error the model is unchanged.
    pub fn step(&mut self, h: f64, inputs: &Inputs) -> Result<Outputs, StepError> {
        inputs.check()?;
        check_step(h)?;
        let x0 = self.position_m;
        let x1 = x0 + self.consts.v * h;
        let input = inputs.track_lateral_m;
        // Record the input before reading (a trailing wheelset less than a step's travel
        // behind reads it); taken back if the step fails.
        let undo = match &mut self.track {
            Track::External(line) => Some(line.push_undoable(x0, input)),
            Track::Internal(_) | Track::None => None,
        };
        let result = self.integrate(h, x0, x1, input, inputs);
        match result {
            Ok(o) => Ok(o),
            Err(e) => {
                if let (Some(u), Track::External(line)) = (undo, &mut self.track) {
                    line.undo(u);
                }
                Err(e)
            }
        }
    }

    fn integrate(
        &mut self,
        h: f64,
        x0: f64,
        x1: f64,
        input: f64,
        inputs: &Inputs,
    ) -> Result<Outputs, StepError> {
        let c = &self.consts;
        let yt0 = self.track_at(x0, input);
        let yt1 = self.track_at(x1, input);
        let n = self.substeps(h)?;
        let hs = h / n as f64;
        let forces = &inputs.damper_force_n;
        let table = &self.table;
        let mut hints = self.hints;
        let generator = match &self.track {
            Track::Internal(g) => Some(g),
            _ => None,
        };
        let delays = self.positions.wheelset_delay_m;
        let mut f = |x: &[f64; N_STATES], tau: f64| {
            // the generated track at each stage's position (independent of the step); the
            // external input's record between its values at the step ends
            let yt = match generator {
                Some(g) => g.eval_behind(x0 + c.v * tau, delays),
                None => {
                    let u = tau / h;
                    [0, 1, 2, 3].map(|j| yt0[j] + u * (yt1[j] - yt0[j]))
                }
            };
            rhs(c, table, &mut hints, x, &yt, forces).dx
        };
        let mut x = self.state;
        for k in 0..n {
            let t0 = k as f64 * hs;
            let k1 = f(&x, t0);
            let k2 = f(&axpy(&x, 0.5 * hs, &k1), t0 + 0.5 * hs);
            let k3 = f(&axpy(&x, 0.5 * hs, &k2), t0 + 0.5 * hs);
            let k4 = f(&axpy(&x, hs, &k3), t0 + hs);
            for i in 0..N_STATES {
                x[i] += hs / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
            }
        }
        if x.iter().any(|v| !v.is_finite()) {
            return Err(StepError::Diverged {
                time_s: self.time_s + h,
            });
        }
        let (lo, hi) = self.table_range_m;
        for j in 0..N_WHEELSETS {
            let y_rel = x[wheelset_y(j)] - yt1[j];
            if y_rel < lo || y_rel > hi {
                return Err(StepError::Derailed {
                    time_s: self.time_s + h,
                    wheelset: j + 1,
                    y_rel_mm: y_rel * 1e3,
                    limit_mm: if y_rel < lo { lo } else { hi } * 1e3,
                });
            }
        }
        self.state = x;
        self.hints = hints;
        self.time_s += h;
        self.position_m = x1;
        let mut hints = self.hints;
        Ok(self.outputs_with(&self.state, &mut hints, &yt1, inputs))
    }
}

#[inline]
fn axpy(x: &[f64; N_STATES], a: f64, d: &[f64; N_STATES]) -> [f64; N_STATES] {
    let mut r = *x;
    for i in 0..N_STATES {
        r[i] += a * d[i];
    }
    r
}

/// Serde for the state array (serde derives arrays up to 32 elements only).
mod state_serde {
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    use super::N_STATES;

    pub fn serialize<S: Serializer>(x: &[f64; N_STATES], s: S) -> Result<S::Ok, S::Error> {
        x.as_slice().serialize(s)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<[f64; N_STATES], D::Error> {
        let v = Vec::<f64>::deserialize(d)?;
        v.try_into().map_err(|v: Vec<f64>| {
            serde::de::Error::invalid_length(v.len(), &"the vehicle state length")
        })
    }
}
