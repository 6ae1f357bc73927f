//! Time-domain bogie model for co-simulation: [`Bogie`] with [`Inputs`] and [`Outputs`].
//!
//! Integration: classical RK4 with a FIXED internal sub-step h_sub <= 1e-4 s (smaller if the
//! creep damping of the spin dofs, ~2 f11 r0^2/(V J_w), or the flange contact stiffness
//! require it), the communication step being split into n = ceil(h / h_sub) equal sub-steps.
//! Why: fixed cost per step (real-time use in HIL), no allocation, deterministic results for
//! a given step, and the RHS is only piecewise smooth (table kinks, flange), where adaptive
//! error control would keep rejecting steps without gaining accuracy; with the flange
//! stiffness of the synthetic profile (~600 rad/s) omega*h_sub <= 0.06, far inside RK4's
//! stability and accuracy region. Damper forces and an external track input are held
//! constant over a communication step (zero-order hold); the internal track generator is
//! interpolated linearly between the step ends.
//!
//! Direct feedthrough: accelerations (bogie frame above each wheelset, wheelsets) and the
//! guiding forces depend on the damper forces and track input at the same instant; call
//! [`Bogie::outputs`] with the current inputs to get them without stepping.

use serde::{Deserialize, Serialize};

use crate::contact::{ContactError, ContactTable};
use crate::nonlinear::{rhs, Consts, N_STATES};
use crate::params::{ParamError, Params, TrackSource};
use crate::track::{DelayLine, TrackGenerator};

/// Default wheel/rail table (CSV, see [`crate::contact`]).
pub fn default_contact_table() -> Result<ContactTable, ContactError> {
    // Until resources/wheel_rail_A_A.csv (profiles A/A, EN 15302) exists, a synthetic
    // cone + flange profile of the calibrated conicity with flange contact at 7 mm.
    ContactTable::synthetic(crate::calibration::CALIBRATED_CONICITY, 7e-3, 5e-4, 2.7)
}

/// Errors when building the model.
#[derive(Debug, thiserror::Error)]
pub enum ModelError {
    /// Invalid parameter.
    #[error(transparent)]
    Param(#[from] ParamError),
    /// Contact table could not be loaded.
    #[error(transparent)]
    Contact(#[from] ContactError),
}

/// Errors of a step or an output evaluation.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum StepError {
    /// An input is NaN or infinite.
    #[error("input `{name}` is not finite ({value})")]
    NonFiniteInput {
        /// Input name.
        name: &'static str,
        /// Value.
        value: f64,
    },
    /// Step size not usable.
    #[error("invalid communication step {h} s (must be finite, > 0 and <= 1 s)")]
    InvalidStep {
        /// Step [s].
        h: f64,
    },
    /// The state became NaN/inf or left the physical range (derailment).
    #[error("state diverged at t = {time_s} s: {what}")]
    Diverged {
        /// Time [s].
        time_s: f64,
        /// Description.
        what: String,
    },
}

/// Inputs of one communication step.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Inputs {
    /// Left yaw damper force, tension positive [N].
    pub damper_left_force_n: f64,
    /// Right yaw damper force, tension positive [N].
    pub damper_right_force_n: f64,
    /// Track lateral alignment at the front wheelset, positive right [m] (used when the
    /// track source is External).
    pub track_lateral_m: f64,
}

impl Inputs {
    fn check(&self) -> Result<(), StepError> {
        for (name, value) in [
            ("damper_left_force_n", self.damper_left_force_n),
            ("damper_right_force_n", self.damper_right_force_n),
            ("track_lateral_m", self.track_lateral_m),
        ] {
            if !value.is_finite() {
                return Err(StepError::NonFiniteInput { name, value });
            }
        }
        Ok(())
    }
}

/// Outputs at one instant. Front = wheelset 1 at +p (leading), rear = wheelset 2.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Outputs {
    /// Time [s].
    pub time_s: f64,
    /// Left damper elongation e_L = +b sigma [m] (extension positive).
    pub damper_left_elongation_m: f64,
    /// Right damper elongation e_R = -b sigma [m].
    pub damper_right_elongation_m: f64,
    /// Left damper elongation velocity [m/s].
    pub damper_left_velocity_mps: f64,
    /// Right damper elongation velocity [m/s].
    pub damper_right_velocity_mps: f64,
    /// Bogie frame lateral acceleration above the front wheelset, y'' - p sigma'' [m/s^2]
    /// (EN 14363 stability quantity). Direct feedthrough.
    pub frame_acc_front_mps2: f64,
    /// Bogie frame lateral acceleration above the rear wheelset, y'' + p sigma'' [m/s^2].
    pub frame_acc_rear_mps2: f64,
    /// Front wheelset lateral displacement (absolute) [m].
    pub wheelset_front_lateral_m: f64,
    /// Rear wheelset lateral displacement (absolute) [m].
    pub wheelset_rear_lateral_m: f64,
    /// Front wheelset displacement relative to the track [m].
    pub wheelset_front_rel_track_m: f64,
    /// Rear wheelset displacement relative to the track [m].
    pub wheelset_rear_rel_track_m: f64,
    /// Front wheelset lateral acceleration [m/s^2] (rigid primary suspension: equals the
    /// frame acceleration above it).
    pub wheelset_front_acc_mps2: f64,
    /// Rear wheelset lateral acceleration [m/s^2].
    pub wheelset_rear_acc_mps2: f64,
    /// Sum of lateral wheel/rail forces on the front wheelset (Sum Y, force of the rails on
    /// the wheelset, positive right) [N].
    pub guiding_force_front_n: f64,
    /// Same for the rear wheelset [N].
    pub guiding_force_rear_n: f64,
    /// Yaw angle sigma, positive nose-left [rad].
    pub yaw_rad: f64,
    /// Yaw rate [rad/s].
    pub yaw_rate_radps: f64,
    /// Bogie centre lateral displacement [m].
    pub bogie_lateral_m: f64,
    /// Bogie centre lateral velocity [m/s].
    pub bogie_lateral_velocity_mps: f64,
    /// Track alignment under the front / rear wheelset [m].
    pub track_front_m: f64,
    /// See `track_front_m`.
    pub track_rear_m: f64,
}

/// The 2-dof bogie (plus two spin dofs in the non-linear model); plain data, clonable and
/// serialisable for FMU state save/restore.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Bogie {
    params: Params,
    consts: Consts,
    table: ContactTable,
    generator: Option<TrackGenerator>,
    delay: DelayLine,
    /// y, sigma, y', sigma', beta1', beta2'.
    state: [f64; N_STATES],
    time_s: f64,
    position_m: f64,
    h_sub_max: f64,
    /// Track alignment (front, rear) at the current time (internal generator).
    track_now: [f64; 2],
}

impl Bogie {
    /// Validates the parameters, loads the contact table (file if given, else default).
    pub fn new(params: Params) -> Result<Self, ModelError> {
        let table = match &params.contact_table_path {
            Some(path) => ContactTable::load(path)?,
            None => default_contact_table()?,
        };
        Self::with_table(params, table)
    }

    /// As [`Self::new`] with an explicit contact table (ignores `contact_table_path`).
    pub fn with_table(params: Params, table: ContactTable) -> Result<Self, ModelError> {
        params.validate()?;
        let consts = Consts::new(&params);
        let generator = match params.track {
            TrackSource::Internal { level, seed } => Some(TrackGenerator::new(level, seed)),
            _ => None,
        };
        // Sub-step bound from the fastest dynamics (see module docs).
        let c = &consts;
        let mut rate = (4.0 * c.f22 / (c.v * c.m))
            .max((4.0 * c.f11 * c.s * c.s + 4.0 * c.f22 * c.p * c.p) / (c.v * c.j));
        if c.nonlinear {
            rate = rate.max(2.0 * c.f11 * c.r0 * c.r0 / (c.v * c.jw));
        }
        let k_flange = if c.nonlinear {
            c.load * table.max_tan_gamma_slope()
        } else {
            c.kg
        };
        let w_flange = (2.0 * k_flange * (1.0 / c.m + c.p * c.p / c.j)).sqrt();
        let h_sub_max = 1e-4_f64.min(1.0 / rate).min(0.2 / w_flange.max(1e-9));
        let mut state = [0.0; N_STATES];
        state[0] = params.initial_lateral_m;
        state[1] = params.initial_yaw_rad;
        let delay = DelayLine::new(2.0 * params.half_wheelbase_m);
        let mut me = Self {
            params,
            consts,
            table,
            generator,
            delay,
            state,
            time_s: 0.0,
            position_m: 0.0,
            h_sub_max,
            track_now: [0.0; 2],
        };
        me.track_now = me.generated_track(0.0);
        Ok(me)
    }

    /// Parameters in use.
    pub fn params(&self) -> &Params {
        &self.params
    }

    /// Contact table in use.
    pub fn contact_table(&self) -> &ContactTable {
        &self.table
    }

    /// Current time [s].
    pub fn time_s(&self) -> f64 {
        self.time_s
    }

    /// Internal sub-step used for the integration [s].
    pub fn substep_s(&self) -> f64 {
        self.h_sub_max
    }

    /// State (y, sigma, y', sigma', beta1', beta2').
    pub fn state(&self) -> [f64; N_STATES] {
        self.state
    }

    /// Overwrites the state (e.g. to impose an initial perturbation); must be finite.
    pub fn set_state(&mut self, state: [f64; N_STATES]) -> Result<(), StepError> {
        if state.iter().any(|v| !v.is_finite()) {
            return Err(StepError::Diverged {
                time_s: self.time_s,
                what: "non-finite state given".into(),
            });
        }
        self.state = state;
        Ok(())
    }

    fn generated_track(&self, x: f64) -> [f64; 2] {
        match &self.generator {
            Some(g) => [g.eval(x), g.eval(x - 2.0 * self.consts.p)],
            None => [0.0, 0.0],
        }
    }

    /// Track under (front, rear) now for the given external input, without recording it.
    fn track_at_start(&self, inputs: &Inputs) -> [f64; 2] {
        match self.params.track {
            TrackSource::None => [0.0, 0.0],
            TrackSource::Internal { .. } => self.track_now,
            TrackSource::External => {
                let front = inputs.track_lateral_m;
                let rear = self
                    .delay
                    .at(self.position_m - 2.0 * self.consts.p)
                    .unwrap_or(front);
                [front, rear]
            }
        }
    }

    /// Outputs at the current time for the given inputs (no stepping; direct feedthrough
    /// of damper forces and track input into accelerations and guiding forces).
    pub fn outputs(&self, inputs: &Inputs) -> Result<Outputs, StepError> {
        inputs.check()?;
        let yt = self.track_at_start(inputs);
        self.outputs_with(yt, inputs)
    }

    fn outputs_with(&self, yt: [f64; 2], inputs: &Inputs) -> Result<Outputs, StepError> {
        let c = &self.consts;
        let x = &self.state;
        let e = rhs(
            c,
            &self.table,
            x,
            yt,
            inputs.damper_left_force_n,
            inputs.damper_right_force_n,
        );
        let (ydd, sdd) = (e.dx[2], e.dx[3]);
        let (acc_f, acc_r) = (ydd - c.p * sdd, ydd + c.p * sdd);
        let (yf, yr) = (x[0] - c.p * x[1], x[0] + c.p * x[1]);
        let o = Outputs {
            time_s: self.time_s,
            damper_left_elongation_m: c.b * x[1],
            damper_right_elongation_m: -c.b * x[1],
            damper_left_velocity_mps: c.b * x[3],
            damper_right_velocity_mps: -c.b * x[3],
            frame_acc_front_mps2: acc_f,
            frame_acc_rear_mps2: acc_r,
            wheelset_front_lateral_m: yf,
            wheelset_rear_lateral_m: yr,
            wheelset_front_rel_track_m: yf - yt[0],
            wheelset_rear_rel_track_m: yr - yt[1],
            wheelset_front_acc_mps2: acc_f,
            wheelset_rear_acc_mps2: acc_r,
            guiding_force_front_n: e.guiding[0],
            guiding_force_rear_n: e.guiding[1],
            yaw_rad: x[1],
            yaw_rate_radps: x[3],
            bogie_lateral_m: x[0],
            bogie_lateral_velocity_mps: x[2],
            track_front_m: yt[0],
            track_rear_m: yt[1],
        };
        let all = [
            o.frame_acc_front_mps2,
            o.frame_acc_rear_mps2,
            o.guiding_force_front_n,
            o.guiding_force_rear_n,
        ];
        if all.iter().any(|v| !v.is_finite()) {
            return Err(StepError::Diverged {
                time_s: self.time_s,
                what: "non-finite output".into(),
            });
        }
        Ok(o)
    }

    /// Advances over one communication step h with the inputs held constant; returns the
    /// outputs at the end of the step (evaluated with the same held inputs).
    pub fn step(&mut self, h: f64, inputs: &Inputs) -> Result<Outputs, StepError> {
        if !(h.is_finite() && h > 0.0 && h <= 1.0) {
            return Err(StepError::InvalidStep { h });
        }
        inputs.check()?;
        if self.params.track == TrackSource::External {
            self.delay.push(self.position_m, inputs.track_lateral_m);
        }
        let c = self.consts;
        let yt0 = self.track_at_start(inputs);
        let x_end = self.position_m + c.v * h;
        let yt1 = match self.params.track {
            TrackSource::Internal { .. } => self.generated_track(x_end),
            _ => yt0,
        };
        let n = (h / self.h_sub_max - 1e-9).ceil().max(1.0) as usize;
        let hs = h / n as f64;
        let (fl, fr) = (inputs.damper_left_force_n, inputs.damper_right_force_n);
        let table = &self.table;
        let track = |tau: f64| -> [f64; 2] {
            let u = tau / h;
            [
                yt0[0] + u * (yt1[0] - yt0[0]),
                yt0[1] + u * (yt1[1] - yt0[1]),
            ]
        };
        let f = |x: &[f64; N_STATES], tau: f64| rhs(&c, table, x, track(tau), fl, fr).dx;
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
                time_s: self.time_s,
                what: "non-finite state".into(),
            });
        }
        // Beyond 50 mm the wheel has left the rail: the model has no meaning any more.
        let (yf, yr) = (x[0] - c.p * x[1], x[0] + c.p * x[1]);
        if (yf - yt1[0]).abs() > 0.05 || (yr - yt1[1]).abs() > 0.05 {
            return Err(StepError::Diverged {
                time_s: self.time_s + h,
                what: format!("wheelset displacement {yf:.4} / {yr:.4} m (derailment)"),
            });
        }
        self.state = x;
        self.time_s += h;
        self.position_m = x_end;
        self.track_now = yt1;
        self.outputs_with(yt1, inputs)
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
