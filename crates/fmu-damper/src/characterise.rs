//! Characterisation of the models (seed sections 3.3.4 and 3.4.4): hysteresis loops,
//! force/displacement FRFs with equivalent stiffness and damping, and actuator FRFs.
//! Functions return data only (no files).
//!
//! Method: the model is driven by a sinusoid until the first harmonic of the response
//! changes by less than 1e-6 (relative) from one period to the next (at least 3,
//! at most 60 periods); the first harmonic is taken over the last period. The input is
//! sampled at the middle of each communication step (second-order accurate hold), so
//! the measured phase is not biased by the zero-order hold.
//!
//! Conventions: displacement `x = X sin(wt)`; `H = F1 / X1` with complex first
//! harmonics, so a spring gives `H = k` (0 deg), a viscous damper `H = i c w` (90 deg);
//! `k_eq = Re H`, `c_eq = Im H / w`.

use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

use crate::error::{check_opening_input, positive_input, StepError};
use crate::full_active::{
    dead_zone_describing_gain, Actuator, ActuatorInputs, ActuatorModel, ActuatorParams, RodMode,
};
use crate::semi_active::{SemiActiveDamper, SemiActiveInputs, SemiActiveParams};
use num_complex::Complex64;

/// Samples per period of the sinusoidal tests (communication steps), at least.
pub const STEPS_PER_PERIOD: usize = 400;
/// The longest communication step of the damper's sinusoidal tests \[s\]: 400 steps per period
/// at 4 Hz. The stroke is held over each step at its mid-step value and the force taken at the
/// step's end, which is right while the oil column responds slower than a step (400 and 4000
/// steps per period agree at 4 Hz); a slow stroke at 400 steps per period would take steps of
/// seconds, over which the force settles to the held stroke's and reads half a step late
/// (89.55 deg instead of 90 at 0.001 Hz, and a k_eq that is that lag's).
const MAX_DAMPER_STEP_S: f64 = 1.0 / (4.0 * 400.0);
/// At most this many steps per period (below 0.004 Hz the step grows again; there the lag of
/// half a step is below 0.001 deg).
const MAX_DAMPER_STEPS_PER_PERIOD: usize = 400_000;
const MIN_PERIODS: usize = 3;
const MAX_PERIODS: usize = 60;
const CONVERGENCE: f64 = 1e-6;

/// One steady-state period of a sinusoidal stroke.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct HysteresisLoop {
    /// Valve opening, 0..1.
    pub opening: f64,
    /// Stroke frequency, Hz.
    pub freq_hz: f64,
    /// Displacement amplitude, m.
    pub amplitude_m: f64,
    /// Time since the start of the analysed period, s.
    pub time_s: Vec<f64>,
    /// Displacement (elongation), m.
    pub displacement_m: Vec<f64>,
    /// Velocity, m/s.
    pub velocity_mps: Vec<f64>,
    /// Force, N (tension positive).
    pub force_n: Vec<f64>,
    /// Largest |force| over the period, N.
    pub peak_force_n: f64,
    /// First-harmonic force/displacement ratio, N/m.
    pub transfer: Complex64,
}

/// One point of the damper force/displacement FRF.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct DamperFrfPoint {
    /// Frequency, Hz.
    pub freq_hz: f64,
    /// |F1/X1|, N/m.
    pub modulus_n_per_m: f64,
    /// arg(F1/X1), degrees.
    pub phase_deg: f64,
    /// Equivalent stiffness Re(F1/X1), N/m.
    pub k_eq_n_per_m: f64,
    /// Equivalent damping Im(F1/X1)/w, N s/m.
    pub c_eq_ns_per_m: f64,
}

fn first_harmonic(samples: &[f64], times: &[f64], omega: f64) -> Complex64 {
    let n = samples.len() as f64;
    let mut acc = Complex64::default();
    for (s, t) in samples.iter().zip(times) {
        acc += Complex64::new((omega * t).cos(), -(omega * t).sin()).scale(*s);
    }
    acc.scale(2.0 / n)
}

/// The last period of a harmonic measurement.
struct HarmonicResponse {
    /// End time of each communication step, from the start of the period, s.
    time_s: Vec<f64>,
    /// Response at the end of each step.
    response: Vec<f64>,
    /// First harmonic of the response over that of the input `A sin(wt)`.
    transfer: Complex64,
}

/// Drives a model with `A sin(2 pi f t)`, `steps_per_period` communication steps per period,
/// until the transfer of one period differs from the previous one's by at most
/// `relative |H| + absolute` (at least `MIN_PERIODS`, at most `MAX_PERIODS` periods).
/// `step(h, t_mid)` advances the model over a step of length `h` whose middle is `t_mid`
/// (where the input is sampled) and returns the response at its end.
fn harmonic_response(
    freq_hz: f64,
    amplitude: f64,
    steps_per_period: usize,
    relative: f64,
    absolute: f64,
    mut step: impl FnMut(f64, f64) -> Result<f64, StepError>,
) -> Result<HarmonicResponse, StepError> {
    let omega = 2.0 * PI * freq_hz;
    let n = steps_per_period;
    let h = 1.0 / (freq_hz * n as f64);
    let mut time = vec![0.0; n];
    let mut response = vec![0.0; n];
    let mut prev: Option<Complex64> = None;
    let mut transfer = Complex64::default();
    let input1 = Complex64::new(0.0, -amplitude); // phasor of A sin(wt)
    for period in 0..MAX_PERIODS {
        let t0 = period as f64 / freq_hz;
        for k in 0..n {
            let tm = t0 + (k as f64 + 0.5) * h;
            response[k] = step(h, tm)?;
            time[k] = (k as f64 + 1.0) * h;
        }
        transfer = first_harmonic(&response, &time, omega) / input1;
        if let Some(p) = prev {
            if period + 1 >= MIN_PERIODS
                && (transfer - p).norm() <= relative * transfer.norm() + absolute
            {
                break;
            }
        }
        prev = Some(transfer);
    }
    Ok(HarmonicResponse {
        time_s: time,
        response,
        transfer,
    })
}

/// Runs the damper with the valve fixed at `opening` under `x = X sin(2 pi f t)` to a
/// periodic steady state and returns the last period.
pub fn hysteresis_loop(
    params: &SemiActiveParams,
    opening: f64,
    freq_hz: f64,
    amplitude_m: f64,
) -> Result<HysteresisLoop, StepError> {
    check_opening_input("opening", opening)?;
    positive_input("freq_hz", freq_hz)?;
    positive_input("amplitude_m", amplitude_m)?;
    hysteresis_loop_in(params, opening, freq_hz, amplitude_m, damper_steps(freq_hz))
}

/// Steps per period of the damper's sinusoidal tests at `freq_hz`: [`STEPS_PER_PERIOD`], more
/// where that would make a step longer than [`MAX_DAMPER_STEP_S`].
fn damper_steps(freq_hz: f64) -> usize {
    let bounded = (1.0 / (freq_hz * MAX_DAMPER_STEP_S)).ceil();
    if bounded.is_finite() {
        (bounded as usize).clamp(STEPS_PER_PERIOD, MAX_DAMPER_STEPS_PER_PERIOD)
    } else {
        STEPS_PER_PERIOD
    }
}

/// [`hysteresis_loop`] with `steps` communication steps per period.
fn hysteresis_loop_in(
    params: &SemiActiveParams,
    opening: f64,
    freq_hz: f64,
    amplitude_m: f64,
    steps: usize,
) -> Result<HysteresisLoop, StepError> {
    let mut damper = SemiActiveDamper::new(params.with_fixed_opening(opening))?;
    let omega = 2.0 * PI * freq_hz;
    let r = harmonic_response(freq_hz, amplitude_m, steps, CONVERGENCE, 0.0, |h, tm| {
        let inputs = SemiActiveInputs {
            elongation_m: amplitude_m * (omega * tm).sin(),
            elongation_velocity_mps: amplitude_m * omega * (omega * tm).cos(),
            valve_command_v: 0.0,
        };
        Ok(damper.step(h, &inputs)?.force_n)
    })?;
    let (time, fs, transfer) = (r.time_s, r.response, r.transfer);
    let xs = time
        .iter()
        .map(|t| amplitude_m * (omega * t).sin())
        .collect();
    let vs = time
        .iter()
        .map(|t| amplitude_m * omega * (omega * t).cos())
        .collect();
    let peak = fs.iter().fold(0.0f64, |m, f| m.max(f.abs()));
    Ok(HysteresisLoop {
        opening,
        freq_hz,
        amplitude_m,
        time_s: time,
        displacement_m: xs,
        velocity_mps: vs,
        force_n: fs,
        peak_force_n: peak,
        transfer,
    })
}

/// Hysteresis loops of the seed's Figures 3.10-3.13: strokes of 1 and 3 mm at 4 Hz
/// for openings 0, 20, 50 and 100 %.
pub fn seed_hysteresis_loops(params: &SemiActiveParams) -> Result<Vec<HysteresisLoop>, StepError> {
    let mut out = Vec::new();
    for opening in [0.0, 0.2, 0.5, 1.0] {
        for amp in [1e-3, 3e-3] {
            out.push(hysteresis_loop(params, opening, 4.0, amp)?);
        }
    }
    Ok(out)
}

/// Force/displacement FRF point at one frequency.
pub fn damper_frf_point(
    params: &SemiActiveParams,
    opening: f64,
    freq_hz: f64,
    amplitude_m: f64,
) -> Result<DamperFrfPoint, StepError> {
    let l = hysteresis_loop(params, opening, freq_hz, amplitude_m)?;
    let omega = 2.0 * PI * freq_hz;
    Ok(DamperFrfPoint {
        freq_hz,
        modulus_n_per_m: l.transfer.norm(),
        phase_deg: l.transfer.arg().to_degrees(),
        k_eq_n_per_m: l.transfer.re,
        c_eq_ns_per_m: l.transfer.im / omega,
    })
}

/// Force/displacement FRF over `freqs_hz` (seed Fig. 3.14-3.15 use 1 mm).
pub fn damper_frf(
    params: &SemiActiveParams,
    opening: f64,
    freqs_hz: &[f64],
    amplitude_m: f64,
) -> Result<Vec<DamperFrfPoint>, StepError> {
    freqs_hz
        .iter()
        .map(|&f| damper_frf_point(params, opening, f, amplitude_m))
        .collect()
}

/// Frequencies of the seed's damper FRF: 0.5 to 20 Hz, `n` log-spaced points.
pub fn log_space(f_lo: f64, f_hi: f64, n: usize) -> Vec<f64> {
    if n < 2 {
        return vec![f_lo];
    }
    (0..n)
        .map(|i| f_lo * (f_hi / f_lo).powf(i as f64 / (n - 1) as f64))
        .collect()
}

/// Equivalent stiffness (N/m) and damping (N s/m) of the damper at a fixed opening,
/// from the first harmonic of the steady-state response to `X sin(2 pi f t)`.
/// Used by the bogie calibration and the sky-hook controller table.
pub fn equivalent_stiffness_damping(
    params: &SemiActiveParams,
    opening: f64,
    freq_hz: f64,
    amplitude_m: f64,
) -> Result<(f64, f64), StepError> {
    let p = damper_frf_point(params, opening, freq_hz, amplitude_m)?;
    Ok((p.k_eq_n_per_m, p.c_eq_ns_per_m))
}

/// One point of an actuator FRF `u -> rod velocity`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ActuatorFrfPoint {
    /// Frequency, Hz.
    pub freq_hz: f64,
    /// Angular frequency, rad/s.
    pub omega_radps: f64,
    /// |xdot1 / u1|, (m/s)/m = 1/s.
    pub modulus_per_s: f64,
    /// arg(xdot1 / u1), degrees.
    pub phase_deg: f64,
}

/// FRF `u -> rod velocity` of the full- or reduced-order actuator (rod free, F_L = 0)
/// from the first harmonic of the steady-state response to `u = U sin(wt)`.
pub fn actuator_frf(
    params: &ActuatorParams,
    model: ActuatorModel,
    amplitude_m: f64,
    freqs_hz: &[f64],
) -> Result<Vec<ActuatorFrfPoint>, StepError> {
    positive_input("amplitude_m", amplitude_m)?;
    let p = ActuatorParams {
        model,
        rod: RodMode::Free,
        ..*params
    };
    let mut out = Vec::with_capacity(freqs_hz.len());
    for &f in freqs_hz {
        positive_input("freq_hz", f)?;
        let mut act = Actuator::new(p)?;
        let omega = 2.0 * PI * f;
        // Keep the communication step inside 1e-4..5e-3 s.
        let n = ((1.0 / (f * 5e-3)).ceil() as usize).clamp(64, 400);
        // Absolute floor: inside the dead zone the response is ~0.
        let g = harmonic_response(f, amplitude_m, n, 1e-4, 1e-9, |h, tm| {
            let inputs = ActuatorInputs {
                spool_command_m: amplitude_m * (omega * tm).sin(),
                ..ActuatorInputs::default()
            };
            Ok(act.step(h, &inputs)?.rod_velocity_mps)
        })?
        .transfer;
        out.push(ActuatorFrfPoint {
            freq_hz: f,
            omega_radps: omega,
            modulus_per_s: g.norm(),
            phase_deg: g.arg().to_degrees(),
        });
    }
    Ok(out)
}

/// FRF `u -> rod velocity` of the linearised reduced-order model (3.73), linearised at
/// `z_hat = h(U)` and `P_L_hat = load_pressure_hat_pa` (seed: 0.75 P_S). The dead zone
/// enters through its describing-function gain at amplitude `U` (a linear model has
/// no dead zone; this makes it comparable with the non-linear FRFs).
pub fn linearised_actuator_frf(
    params: &ActuatorParams,
    amplitude_m: f64,
    load_pressure_hat_pa: f64,
    freqs_hz: &[f64],
) -> Result<Vec<ActuatorFrfPoint>, StepError> {
    positive_input("amplitude_m", amplitude_m)?;
    params.validate()?;
    let z_hat = params.dead_zone(amplitude_m);
    let n_dz = dead_zone_describing_gain(params, amplitude_m);
    Ok(freqs_hz
        .iter()
        .map(|&f| {
            let omega = 2.0 * PI * f;
            let g = params
                .linearised_tf(Complex64::new(0.0, omega), z_hat, load_pressure_hat_pa)
                .scale(n_dz);
            ActuatorFrfPoint {
                freq_hz: f,
                omega_radps: omega,
                modulus_per_s: g.norm(),
                phase_deg: g.arg().to_degrees(),
            }
        })
        .collect())
}

/// The seed's actuator FRF set (Figures 3.18-3.22): 1..320 Hz, |u| = alpha and
/// 0.3 alpha, for the full-order, reduced-order and linearised (P_L_hat = 0.75 P_S)
/// models. Returns `(amplitude_m, full, reduced, linearised)` per amplitude.
#[allow(clippy::type_complexity)]
pub fn seed_actuator_frfs(
    params: &ActuatorParams,
    n_freqs: usize,
) -> Result<
    Vec<(
        f64,
        Vec<ActuatorFrfPoint>,
        Vec<ActuatorFrfPoint>,
        Vec<ActuatorFrfPoint>,
    )>,
    StepError,
> {
    let freqs = log_space(1.0, 320.0, n_freqs);
    let mut out = Vec::new();
    for amp in [params.alpha_m, 0.3 * params.alpha_m] {
        let full = actuator_frf(params, ActuatorModel::FullOrder, amp, &freqs)?;
        let red = actuator_frf(params, ActuatorModel::ReducedOrder, amp, &freqs)?;
        let lin = linearised_actuator_frf(params, amp, 0.75 * params.supply_pressure_pa, &freqs)?;
        out.push((amp, full, red, lin));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// At 4 Hz the default 400 steps per period give what ten times as many give (k_eq within
    /// 0.5 % where it is the damper's stiffness, the phase within 0.1 deg at every opening):
    /// the force taken at the end of a step whose stroke is held at its middle is the
    /// continuous response there. A slow stroke's steps are bounded so that the same holds.
    #[test]
    fn the_steps_per_period_are_converged() {
        let p = SemiActiveParams::default();
        for opening in [0.0, 0.3, 1.0] {
            let coarse = hysteresis_loop_in(&p, opening, 4.0, 1e-3, damper_steps(4.0))
                .unwrap()
                .transfer;
            let fine = hysteresis_loop_in(&p, opening, 4.0, 1e-3, 4000)
                .unwrap()
                .transfer;
            let phase = (coarse.arg() - fine.arg()).to_degrees().abs();
            assert!(phase < 0.1, "{opening}: phase differs by {phase} deg");
            if opening < 1.0 {
                let k = (coarse.re / fine.re - 1.0).abs();
                assert!(k < 5e-3, "{opening}: k_eq {} vs {}", coarse.re, fine.re);
            }
        }
        // a slow stroke: the bounded steps give what four times as many give, where 400 steps
        // per period (50 ms steps at 0.05 Hz) read the phase up to half a step late (0.45 deg;
        // 0.2 through the closed valve, which responds slower)
        for opening in [0.0, 0.3, 1.0] {
            let phase = |steps| {
                hysteresis_loop_in(&p, opening, 0.05, 1e-3, steps)
                    .unwrap()
                    .transfer
                    .arg()
                    .to_degrees()
            };
            let (bounded, fine, coarse) = (phase(damper_steps(0.05)), phase(128_000), phase(400));
            assert!(
                (bounded - fine).abs() < 0.01,
                "{opening}: {bounded} vs {fine}"
            );
            assert!(
                (coarse - fine).abs() > 0.15,
                "{opening}: {coarse} vs {fine}"
            );
        }
        assert_eq!(damper_steps(4.0), STEPS_PER_PERIOD);
        assert_eq!(damper_steps(20.0), STEPS_PER_PERIOD);
        assert_eq!(damper_steps(0.5), 3200);
        assert_eq!(damper_steps(1e-9), MAX_DAMPER_STEPS_PER_PERIOD);
    }
}
