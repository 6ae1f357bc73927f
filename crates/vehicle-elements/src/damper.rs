//! The linear yaw damper law of both models, and the closed loop that evaluates it beside a
//! vehicle model, co-simulation style (each damper's force from the outputs of the previous
//! step, held over the step). The coupled runs with the hydraulic damper FMUs happen in the
//! master; this loop serves the models' calibration and convergence tests.

use serde::{Deserialize, Serialize};

/// A linear yaw damper law, values per damper, the same for every damper of the model: what
/// the closed loop evaluates beside a model, and how the coach's eigen-analysis takes its
/// dampers.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum LinearDamper {
    /// No damper.
    None,
    /// Dashpot c: F = c e'.
    Viscous {
        /// Damping [N s/m].
        c: f64,
    },
    /// Spring k parallel to dashpot c: F = k e + c e'.
    KelvinVoigt {
        /// Stiffness [N/m].
        k: f64,
        /// Damping [N s/m].
        c: f64,
    },
    /// Spring k in series with dashpot c: F' = k (e' - F / c); in the closed loop advanced
    /// exactly over a step for a constant elongation velocity, the force held over the step
    /// the mean of its values at the step ends.
    Maxwell {
        /// Series stiffness [N/m].
        k: f64,
        /// Damping [N s/m].
        c: f64,
    },
}

/// Stiffness a linear damper (its spring, or the mounting it sits on) may have, when it has
/// one [N/m]: 1 kN/m is nothing beside the coach's suspension, 10 GN/m is a thousand times a
/// published damper mounting (10 MN/m) and stiffer than the steel around it. Beyond these
/// bounds the eigen-analysis' state matrix spans too many orders of magnitude for its
/// eigenvalues to be trusted (a dashpot of 1e20 N s/m made the coach unstable at 18 km/h).
pub const STIFFNESS_RANGE_N_PER_M: std::ops::RangeInclusive<f64> = 1e3..=1e10;
/// Damping a linear damper may have, when it has any [N s/m]: 1 N s/m is nothing, 100 MN s/m
/// three hundred times a closed semi-active valve (about 330 kN s/m).
pub const DAMPING_RANGE_NS_PER_M: std::ops::RangeInclusive<f64> = 1.0..=1e8;

/// Checks a stiffness \[N/m\]: zero where `zero_allowed`, else within
/// [`STIFFNESS_RANGE_N_PER_M`]; the message names `what`.
pub fn check_stiffness(what: &str, k: f64, zero_allowed: bool) -> Result<(), String> {
    check_in(what, k, zero_allowed, &STIFFNESS_RANGE_N_PER_M, "N/m")
}

/// Checks a damping \[N s/m\]: zero where `zero_allowed`, else within
/// [`DAMPING_RANGE_NS_PER_M`]; the message names `what`.
pub fn check_damping(what: &str, c: f64, zero_allowed: bool) -> Result<(), String> {
    check_in(what, c, zero_allowed, &DAMPING_RANGE_NS_PER_M, "N s/m")
}

fn check_in(
    what: &str,
    v: f64,
    zero_allowed: bool,
    range: &std::ops::RangeInclusive<f64>,
    unit: &str,
) -> Result<(), String> {
    if (zero_allowed && v == 0.0) || range.contains(&v) {
        return Ok(());
    }
    let short = |x: f64| {
        if (1e-3..1e4).contains(&x.abs()) {
            format!("{x}")
        } else {
            format!("{x:e}")
        }
    };
    Err(format!(
        "{what} {} {unit} is outside {} .. {} {unit}{}",
        short(v),
        short(*range.start()),
        short(*range.end()),
        if zero_allowed { " (or 0)" } else { "" }
    ))
}

impl LinearDamper {
    /// Checks the law's values against [`STIFFNESS_RANGE_N_PER_M`] and
    /// [`DAMPING_RANGE_NS_PER_M`] (a viscous or Kelvin-Voigt damper may have zero of either,
    /// a Maxwell element needs both).
    pub fn check(&self) -> Result<(), String> {
        match *self {
            LinearDamper::None => Ok(()),
            LinearDamper::Viscous { c } => check_damping("damping", c, true),
            LinearDamper::KelvinVoigt { k, c } => {
                check_stiffness("stiffness", k, true)?;
                check_damping("damping", c, true)
            }
            LinearDamper::Maxwell { k, c } => {
                check_stiffness("series stiffness", k, false)?;
                check_damping("damping", c, false)
            }
        }
    }

    /// Force of one damper held over the next step of length `h_s`, from its elongation
    /// \[m\] and elongation velocity [m/s] at the start of the step; `state_n` is the
    /// Maxwell element's force \[N\], advanced to the end of the step.
    pub fn held_force_n(
        &self,
        elongation_m: f64,
        velocity_mps: f64,
        state_n: &mut f64,
        h_s: f64,
    ) -> f64 {
        match *self {
            LinearDamper::None => 0.0,
            LinearDamper::Viscous { c } => c * velocity_mps,
            LinearDamper::KelvinVoigt { k, c } => k * elongation_m + c * velocity_mps,
            LinearDamper::Maxwell { k, c } => {
                let old = *state_n;
                let a = (-k * h_s / c).exp();
                *state_n = old * a + c * velocity_mps * (1.0 - a);
                0.5 * (old + *state_n)
            }
        }
    }
}

/// A vehicle model with `N` yaw-damper ports as the closed loop drives it.
pub trait ClosedLoopModel<const N: usize> {
    /// The model's inputs.
    type Inputs: Default;
    /// The model's outputs.
    type Outputs;
    /// Error of a step or an output evaluation.
    type Error;

    /// Model time \[s\].
    fn time_s(&self) -> f64;
    /// Outputs at the current state for `inputs`.
    fn outputs(&self, inputs: &Self::Inputs) -> Result<Self::Outputs, Self::Error>;
    /// One communication step of length `h_s`.
    fn step(&mut self, h_s: f64, inputs: &Self::Inputs) -> Result<Self::Outputs, Self::Error>;
    /// Sets the track alignment input \[m\].
    fn set_track_lateral_m(inputs: &mut Self::Inputs, track_lateral_m: f64);
    /// Elongation \[m\] and elongation velocity [m/s] of each damper.
    fn damper_motion(outputs: &Self::Outputs) -> [(f64, f64); N];
    /// Sets the force input \[N\] of each damper.
    fn set_damper_force_n(inputs: &mut Self::Inputs, force_n: [f64; N]);
}

/// The stepping items of a [`ClosedLoopModel`] impl, forwarded to the model's own `time_s`,
/// `outputs` and `step`: `forward_stepping!(Model, Inputs, Outputs, Error);` inside the impl.
#[macro_export]
macro_rules! forward_stepping {
    ($model:ty, $inputs:ty, $outputs:ty, $error:ty) => {
        type Inputs = $inputs;
        type Outputs = $outputs;
        type Error = $error;

        fn time_s(&self) -> f64 {
            <$model>::time_s(self)
        }

        fn outputs(&self, inputs: &$inputs) -> Result<$outputs, $error> {
            <$model>::outputs(self, inputs)
        }

        fn step(&mut self, h_s: f64, inputs: &$inputs) -> Result<$outputs, $error> {
            <$model>::step(self, h_s, inputs)
        }
    };
}

/// Runs `t_end_s` seconds with communication step `h_s`, the track input from
/// `track_lateral_m` (time -> alignment), `damper` on every port; calls `record` with every
/// output, the initial one included.
pub fn run_closed_loop<M: ClosedLoopModel<N>, const N: usize>(
    model: &mut M,
    damper: LinearDamper,
    h_s: f64,
    t_end_s: f64,
    track_lateral_m: &dyn Fn(f64) -> f64,
    record: &mut dyn FnMut(&M::Outputs),
) -> Result<(), M::Error> {
    let mut state_n = [0.0; N];
    let mut inputs = M::Inputs::default();
    M::set_track_lateral_m(&mut inputs, track_lateral_m(model.time_s()));
    let mut out = model.outputs(&inputs)?;
    record(&out);
    let n = (t_end_s / h_s).round() as usize;
    for _ in 0..n {
        let motion = M::damper_motion(&out);
        let mut force_n = [0.0; N];
        for (d, (e, v)) in motion.into_iter().enumerate() {
            force_n[d] = damper.held_force_n(e, v, &mut state_n[d], h_s);
        }
        M::set_damper_force_n(&mut inputs, force_n);
        M::set_track_lateral_m(&mut inputs, track_lateral_m(model.time_s()));
        out = model.step(h_s, &inputs)?;
        record(&out);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn maxwell_reaches_the_dashpot_force_and_holds_the_step_mean() {
        let d = LinearDamper::Maxwell { k: 1e6, c: 1e5 };
        let mut f = 0.0;
        // k h / c = 1: F(h) = c v (1 - e^-1), held force its half.
        let held = d.held_force_n(0.0, 0.1, &mut f, 0.1);
        let end = 1e4 * (1.0 - (-1.0f64).exp());
        assert!((f - end).abs() < 1e-9 * end);
        assert!((held - 0.5 * end).abs() < 1e-9 * end);
        for _ in 0..100 {
            d.held_force_n(0.0, 0.1, &mut f, 0.1);
        }
        assert!((f - 1e4).abs() < 1e-6);
        let kv = LinearDamper::KelvinVoigt { k: 2.0, c: 3.0 };
        assert_eq!(kv.held_force_n(5.0, 7.0, &mut f, 0.1), 31.0);
        let viscous = LinearDamper::Viscous { c: 3.0 };
        assert_eq!(viscous.held_force_n(5.0, 7.0, &mut f, 0.1), 21.0);
        assert_eq!(LinearDamper::None.held_force_n(5.0, 7.0, &mut f, 0.1), 0.0);
    }
}
