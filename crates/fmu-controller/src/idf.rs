//! Ideal damper force (IDF) controller of the full-active actuator, seed section 3.2.2:
//!
//! `F_ref = c_v v_rel`                                                   (3.14)
//! `u = command_sign k_p (F_ref - F_measured)`, `|u| <= u_max`          (3.15)
//!
//! * `v_rel` = damper elongation velocity (positive = extension), `F` tension positive, so
//!   `F_ref = +c_v v_rel` is the force of an ideal viscous damper in our convention.
//! * `u` is the spool position command (m); it saturates at `u_max = alpha = 1e-3 m`, the spool
//!   stroke of Table 3-2 (beyond it the orifice saturates anyway, (3.47)).
//!
//! # Sign (`command_sign`)
//! The loop is stable only if a positive `command_sign * u` INCREASES the measured tension
//! (with the rod at rest, d F_measured/dt has the sign of `command_sign * u`). With
//! `command_sign = +1` this requires that a positive spool command pressurises the chamber whose
//! pressure pulls the damper ends together. In the seed's full-order model (3.50)-(3.58) a
//! positive `z` feeds chamber A and `P_A A_A` pushes the rod in `+x`; if `x` is the elongation,
//! chamber A pressure is a compression, the tension is `-(P_A - P_B) A` and the right value is
//! `command_sign = -1`, which is exactly the seed's printed form `u = k_p (F_YD - F_ref)` (3.15).
//! The default is -1: our `FullActiveActuator` FMU confirms it (a positive `spool.command` fills
//! chamber A, pushes the rod out and lowers `damper.force`; its test closes this loop with -1).
//!
//! # Gain
//! The seed tunes `k_p` "by trial and error". Around zero load the actuator of Table 3-2 turns
//! spool travel into force rate at about `K_f = 2 A E/V0 K sqrt(P_S/2) = 7.1e8 N/(s m)` (A =
//! 25.16 cm^2, E = 1e8 Pa, V0 = 1 l, K = C_d w sqrt(2/rho) = 6.3e-4, P_S = 100 bar), so the force
//! loop is an integrator with crossover `K_f k_p`. Default `k_p = 3e-7 m/N`: crossover about
//! 210 rad/s, 10x the hunting frequency (21 rad/s, R6), while the 1 kHz board delay (1.5 ms on
//! average) and the 1200 rad/s valve (3.46) cost about 32 deg, leaving ~58 deg of phase margin.
//! `u_max` is reached for force errors above 3.3 kN. The valve dead zone (beta = 0.3 alpha) maps
//! to a force error band of +-1 kN that a pure P law does not remove (open point).

use serde::{Deserialize, Serialize};

use crate::{
    board_outputs, check_finite_nonneg, check_finite_pos, check_sample_time, check_sign,
    finish_step, screen_step, NanPolicy, ParamError, SampleClock, StepError,
};

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct IdfParams {
    /// Board sample time (s). Default 1 ms.
    pub sample_time_s: f64,
    /// Viscous gain c_v (N s/m), (3.14). Default 330 kNs/m (section 4.5, Table 4-3).
    pub c_v_nspm: f64,
    /// Proportional gain k_p (m of spool per N), (3.15). Default 3e-7 (see module docs).
    pub k_p_m_per_n: f64,
    /// +1 or -1, see module docs. Default +1.
    pub command_sign: f64,
    /// Spool command saturation (m). Default alpha = 1e-3 m (Table 3-2).
    pub u_max_m: f64,
    pub nan_policy: NanPolicy,
}

impl Default for IdfParams {
    fn default() -> Self {
        Self {
            sample_time_s: 1e-3,
            c_v_nspm: 330e3,
            k_p_m_per_n: 3e-7,
            command_sign: -1.0,
            u_max_m: 1e-3,
            nan_policy: NanPolicy::HoldAndWarn,
        }
    }
}

impl IdfParams {
    pub fn validate(&self) -> Result<(), ParamError> {
        check_sample_time(self.sample_time_s)?;
        check_finite_nonneg("c_v_nspm", self.c_v_nspm)?;
        check_finite_nonneg("k_p_m_per_n", self.k_p_m_per_n)?;
        check_sign("command_sign", self.command_sign)?;
        check_finite_pos("u_max_m", self.u_max_m)?;
        Ok(())
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct IdfInputs {
    /// Damper elongation velocity (m/s), positive = extension.
    pub elongation_velocity_mps: f64,
    /// Measured actuator force (N), tension positive.
    pub measured_force_n: f64,
}

#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct IdfOutputs {
    /// Spool position command u (m), saturated.
    pub spool_command_m: f64,
    /// Reference force F_ref (N), tension positive.
    pub force_ref_n: f64,
    /// F_ref - F_measured (N).
    pub force_error_n: f64,
    /// True if |u| hit u_max.
    pub saturated: bool,
    pub input_fault: bool,
    pub dropped_samples: u64,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Idf {
    params: IdfParams,
    clock: SampleClock,
    dropped_samples: u64,
    pending: IdfOutputs,
    out: IdfOutputs,
}

impl Idf {
    pub fn new(params: IdfParams) -> Result<Self, ParamError> {
        params.validate()?;
        Ok(Self {
            clock: SampleClock::new(params.sample_time_s),
            params,
            dropped_samples: 0,
            pending: IdfOutputs::default(),
            out: IdfOutputs::default(),
        })
    }

    pub fn params(&self) -> &IdfParams {
        &self.params
    }

    pub fn outputs(&self) -> IdfOutputs {
        self.out
    }

    pub fn time_s(&self) -> f64 {
        self.clock.time_s
    }

    /// The static law (3.14)-(3.15) for one sample.
    pub fn law(&self, elongation_velocity_mps: f64, measured_force_n: f64) -> IdfOutputs {
        let p = &self.params;
        let f_ref = p.c_v_nspm * elongation_velocity_mps; // (3.14)
        let err = f_ref - measured_force_n;
        let u = p.command_sign * p.k_p_m_per_n * err; // (3.15)
        let us = u.clamp(-p.u_max_m, p.u_max_m);
        IdfOutputs {
            spool_command_m: us,
            force_ref_n: f_ref,
            force_error_n: err,
            saturated: u.abs() >= p.u_max_m,
            input_fault: false,
            dropped_samples: self.dropped_samples,
        }
    }

    pub fn step(&mut self, h: f64, inputs: &IdfInputs) -> Result<IdfOutputs, StepError> {
        let valid = screen_step(
            h,
            &[
                ("elongation_velocity_mps", inputs.elongation_velocity_mps),
                ("measured_force_n", inputs.measured_force_n),
            ],
            self.params.nan_policy,
        )?;
        let n = self.clock.advance(h)?;
        for _ in 0..n {
            self.out = self.pending;
            if valid {
                self.pending = self.law(inputs.elongation_velocity_mps, inputs.measured_force_n);
            } else {
                self.dropped_samples += 1;
            }
        }
        finish_step(
            &self.clock,
            &self.pending,
            &mut self.out,
            valid,
            self.dropped_samples,
        )
    }
}

board_outputs!(IdfOutputs: spool_command_m, force_ref_n, force_error_n);

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn proportional_law_hand_cases() {
        let mut c = Idf::new(IdfParams::default()).unwrap();
        // F_ref = 330e3 * 0.02 = 6600 N, F = 5000 N -> u = -3e-7 * 1600 = -4.8e-4 m (sign -1)
        let o = c
            .step(
                1e-3,
                &IdfInputs {
                    elongation_velocity_mps: 0.02,
                    measured_force_n: 5000.0,
                },
            )
            .unwrap();
        assert_relative_eq!(o.force_ref_n, 6600.0, max_relative = 1e-12);
        assert_relative_eq!(o.force_error_n, 1600.0, max_relative = 1e-12);
        assert_relative_eq!(o.spool_command_m, -4.8e-4, max_relative = 1e-12);
        assert!(!o.saturated);
        // large error saturates at alpha
        let o = c
            .step(
                1e-3,
                &IdfInputs {
                    elongation_velocity_mps: 0.02,
                    measured_force_n: -10e3,
                },
            )
            .unwrap();
        assert_eq!(o.spool_command_m, -1e-3);
        assert!(o.saturated);
        // command_sign = +1 (an actuator whose positive spool raises tension)
        let neg = Idf::new(IdfParams {
            command_sign: 1.0,
            ..Default::default()
        })
        .unwrap();
        assert_relative_eq!(
            neg.law(0.02, 5000.0).spool_command_m,
            4.8e-4,
            max_relative = 1e-12
        );
        assert_eq!(neg.law(-0.1, 0.0).spool_command_m, -1e-3);
    }

    #[test]
    fn one_sample_delay_and_step_independence() {
        let drive = |t: f64| {
            (
                0.03 * (2.0 * std::f64::consts::PI * 3.8 * t).sin(),
                8e3 * (2.0 * std::f64::consts::PI * 3.8 * t + 0.3).sin(),
            )
        };
        let mut a = Idf::new(IdfParams::default()).unwrap();
        let mut b = Idf::new(IdfParams::default()).unwrap();
        let mut max_du: f64 = 0.0;
        for k in 0..3000 {
            let t = k as f64 * 1e-3;
            let (v, f) = drive(t);
            let ob = b
                .step(
                    1e-3,
                    &IdfInputs {
                        elongation_velocity_mps: v,
                        measured_force_n: f,
                    },
                )
                .unwrap();
            let mut oa = a.outputs();
            for j in 0..10 {
                let (v, f) = drive(t + j as f64 * 1e-4);
                oa = a
                    .step(
                        1e-4,
                        &IdfInputs {
                            elongation_velocity_mps: v,
                            measured_force_n: f,
                        },
                    )
                    .unwrap();
                if j < 9 {
                    // inside the interval the output is the command computed one sample earlier
                    let (vp, fp) = drive(t - 1e-3);
                    let expect = if k == 0 {
                        0.0
                    } else {
                        a.law(vp, fp).spool_command_m
                    };
                    assert_relative_eq!(oa.spool_command_m, expect, epsilon = 1e-15);
                }
            }
            max_du = max_du.max((oa.spool_command_m - ob.spool_command_m).abs());
        }
        assert!(max_du < 1e-15, "{max_du}");
    }

    #[test]
    fn nan_holds_and_validation() {
        let mut c = Idf::new(IdfParams::default()).unwrap();
        let o1 = c
            .step(
                1e-3,
                &IdfInputs {
                    elongation_velocity_mps: 0.01,
                    measured_force_n: 0.0,
                },
            )
            .unwrap();
        let o2 = c
            .step(
                1e-3,
                &IdfInputs {
                    elongation_velocity_mps: 0.01,
                    measured_force_n: f64::NAN,
                },
            )
            .unwrap();
        assert!(o2.input_fault);
        assert_eq!(o2.spool_command_m, o1.spool_command_m);
        assert_eq!(o2.dropped_samples, 1);
        let bad = |f: fn(&mut IdfParams)| {
            let mut p = IdfParams::default();
            f(&mut p);
            p.validate().unwrap_err().name
        };
        assert_eq!(bad(|p| p.command_sign = 0.0), "command_sign");
        assert_eq!(bad(|p| p.u_max_m = 0.0), "u_max_m");
        assert_eq!(bad(|p| p.k_p_m_per_n = -1.0), "k_p_m_per_n");
        assert_eq!(bad(|p| p.c_v_nspm = f64::NAN), "c_v_nspm");
        assert_eq!(bad(|p| p.sample_time_s = 0.0), "sample_time_s");
    }
}
