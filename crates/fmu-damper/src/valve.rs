//! By-pass proportional valve of the semi-active damper: command mapping and
//! command-to-opening dynamics.
//!
//! * Command: 0..`full_scale_command_v` volts (10 V) maps linearly to an opening
//!   0..1 (0 V closed, 10 V fully open). Outside the range the command is clamped and
//!   [`ValveCommand::clamped`] is set so the shell can log a warning; NaN/inf is an error.
//! * Dynamics ([`ValveModel`]): `Ideal` = opening follows the command instantly (the
//!   seed's simulations, R11); `Real` = first-order lag with time constant
//!   `time_constant_s` (default 0.15 s: the seed's HIL valve shows a 0.1-0.2 s
//!   command-to-opening lag, R12) **plus** a rate limit `max_rate_per_s` (default
//!   1/0.05 s = 20 /s: the coil current needs at least 50 ms for full travel):
//!   `dx/dt = clamp((x_cmd - x)/tau, -r_max, r_max)`. The opening is a model state.

use serde::{Deserialize, Serialize};

use crate::error::{finite_input, in_range, positive, ParamError, StepError};

/// Command-to-opening model.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum ValveModel {
    /// Opening equals the (clamped) command at once.
    #[default]
    Ideal,
    /// First-order lag plus rate limit.
    Real,
}

/// Valve parameters.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ValveParams {
    /// Dynamics selector.
    pub model: ValveModel,
    /// Lag time constant, s (seed HIL: 0.1-0.2 s, section 5 / R12).
    pub time_constant_s: f64,
    /// Maximum opening rate, 1/s (full travel needs >= 50 ms: 1/0.05).
    pub max_rate_per_s: f64,
    /// Command giving full opening, V (seed: 0-10 V command).
    pub full_scale_command_v: f64,
}

impl Default for ValveParams {
    fn default() -> Self {
        Self {
            model: ValveModel::Ideal,
            time_constant_s: 0.15,
            max_rate_per_s: 1.0 / 0.05,
            full_scale_command_v: 10.0,
        }
    }
}

impl ValveParams {
    /// The seed's slow HIL valve (R12): lag 0.15 s and rate limit 20 /s.
    pub fn real() -> Self {
        Self {
            model: ValveModel::Real,
            ..Self::default()
        }
    }

    /// Checks every field.
    pub fn validate(&self) -> Result<(), ParamError> {
        positive("valve.time_constant_s", self.time_constant_s)?;
        positive("valve.max_rate_per_s", self.max_rate_per_s)?;
        positive("valve.full_scale_command_v", self.full_scale_command_v)?;
        Ok(())
    }

    /// Maps a voltage to a commanded opening in [0, 1].
    pub fn command(&self, volts: f64) -> Result<ValveCommand, StepError> {
        finite_input("valve_command_v", volts)?;
        let raw = volts / self.full_scale_command_v;
        let opening = raw.clamp(0.0, 1.0);
        Ok(ValveCommand {
            opening,
            clamped: opening != raw,
        })
    }

    /// Rate of change of the opening `x` towards the command `x_cmd` (Real model).
    pub fn opening_rate(&self, x: f64, x_cmd: f64) -> f64 {
        match self.model {
            ValveModel::Ideal => 0.0,
            ValveModel::Real => ((x_cmd - x) / self.time_constant_s)
                .clamp(-self.max_rate_per_s, self.max_rate_per_s),
        }
    }

    /// Exact solution of the opening dynamics over `h` s for a constant command
    /// (rate-limited ramp, then exponential). Used for checks and by callers that
    /// need the valve alone.
    pub fn advance(&self, x: f64, x_cmd: f64, h: f64) -> f64 {
        match self.model {
            ValveModel::Ideal => x_cmd,
            ValveModel::Real => {
                let tau = self.time_constant_s;
                let r = self.max_rate_per_s;
                let e = x_cmd - x;
                let band = r * tau; // |e| above this: rate-limited
                let mut x = x;
                let mut h_left = h;
                if e.abs() > band {
                    let t_ramp = (e.abs() - band) / r;
                    if t_ramp >= h_left {
                        return x + e.signum() * r * h_left;
                    }
                    x += e.signum() * r * t_ramp;
                    h_left -= t_ramp;
                }
                x_cmd - (x_cmd - x) * (-h_left / tau).exp()
            }
        }
    }
}

/// A commanded opening after range handling.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ValveCommand {
    /// Commanded opening in [0, 1].
    pub opening: f64,
    /// True if the raw command was outside 0..full scale and was clamped.
    pub clamped: bool,
}

/// Checks an opening value lies in [0, 1].
pub(crate) fn check_opening(name: &'static str, x: f64) -> Result<(), ParamError> {
    in_range(name, x, 0.0, 1.0, "opening must lie in [0, 1]")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn command_mapping_and_clamping() {
        let v = ValveParams::default();
        let c = v.command(5.0).unwrap();
        assert!((c.opening - 0.5).abs() < 1e-15 && !c.clamped);
        let c = v.command(12.0).unwrap();
        assert!(c.opening == 1.0 && c.clamped);
        let c = v.command(-1.0).unwrap();
        assert!(c.opening == 0.0 && c.clamped);
        assert!(v.command(f64::NAN).is_err());
    }

    #[test]
    fn real_valve_full_travel_is_rate_limited_then_lagged() {
        // With the default tau = 0.15 s the lag slope (1/tau = 6.7 /s) stays below the
        // 20 /s rate limit: a unit step is a pure first-order response.
        let v = ValveParams::real();
        let x = v.advance(0.0, 1.0, 0.15);
        assert!((x - (1.0 - (-1.0f64).exp())).abs() < 1e-12, "{x}");
        // A fast lag (tau = 10 ms) is rate-limited: 25 ms give at most 0.5 of travel.
        let fast = ValveParams {
            time_constant_s: 0.01,
            ..ValveParams::real()
        };
        let x = fast.advance(0.0, 1.0, 0.025);
        assert!((x - 0.5).abs() < 1e-12, "{x}");
        // Ramp ends at e = r tau = 0.2 (t = 40 ms), then exponential.
        let x = fast.advance(0.0, 1.0, 0.05);
        assert!((x - (1.0 - 0.2 * (-1.0f64).exp())).abs() < 1e-12, "{x}");
    }
}
