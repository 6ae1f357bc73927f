//! Closed-loop checks with tiny stand-in plants written here (the real damper/actuator crates are
//! only coupled through FMI). The host loop is a Jacobi co-simulation: at each communication
//! point the controller's current output drives the plant over `[t, t+h)` while the controller
//! steps with the plant outputs at `t`.

// Test-only helpers below are not #[test] fns, so the workspace lint allowance does not reach them.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use fmu_controller::skyhook::DAMPING_TABLE_4HZ;
use fmu_controller::{
    DampingTable, Idf, IdfInputs, IdfParams, Mppt, MpptInputs, MpptParams, SkyHook, SkyHookInputs,
    SkyHookMode, SkyHookParams, VelocitySource,
};
use std::f64::consts::PI;

// ---------------------------------------------------------------------------------------------
// IDF with a stand-in hydraulic actuator: 2nd-order valve (omega0 = 1200 rad/s, xi = 0.7, (3.46)),
// force rate dF/dt = plant_sign * K_f * v + K_h * v_e (linearised Table 3-2 actuator with fixed
// supply pressure: K_f = 7.1e8 N/(s m), hydraulic stiffness K_h = 2 A^2 E / V0 = 1.27e6 N/m),
// rod driven at 4 Hz, +-2 mm (hunting-like elongation velocity, 50 mm/s amplitude).

const KF: f64 = 7.1e8;
const KH: f64 = 1.27e6;
const W0: f64 = 1200.0;
const XI: f64 = 0.7;

fn rod_velocity(t: f64) -> f64 {
    let w = 2.0 * PI * 4.0;
    2e-3 * w * (w * t).cos()
}

/// Returns (rms tracking error / rms reference, max |u|) over the last second of a 3 s run.
fn run_idf(h: f64, plant_sign: f64, command_sign: f64) -> (f64, f64, Vec<f64>) {
    let mut ctrl = Idf::new(IdfParams {
        command_sign,
        ..Default::default()
    })
    .unwrap();
    // plant state: spool v, spool rate, force
    let (mut v, mut vd, mut f) = (0.0f64, 0.0f64, 0.0f64);
    let dt = 1e-5;
    let sub = (h / dt).round() as usize;
    let n = (3.0 / h).round() as usize;
    let (mut se, mut sr, mut umax) = (0.0, 0.0, 0.0f64);
    let mut trace = Vec::new();
    for k in 0..n {
        let t = k as f64 * h;
        let u = ctrl.outputs().spool_command_m;
        let ve = rod_velocity(t);
        ctrl.step(
            h,
            &IdfInputs {
                elongation_velocity_mps: ve,
                measured_force_n: f,
            },
        )
        .unwrap();
        for j in 0..sub {
            // semi-implicit Euler on the valve, explicit on the force (dt << 1/1200 s)
            let ts = t + j as f64 * dt;
            let acc = W0 * W0 * (u - v) - 2.0 * XI * W0 * vd;
            vd += dt * acc;
            v += dt * vd;
            f += dt * (plant_sign * KF * v + KH * rod_velocity(ts));
        }
        let tn = t + h;
        if tn > 2.0 - 1e-12 {
            let fr = 330e3 * rod_velocity(tn);
            se += (f - fr) * (f - fr);
            sr += fr * fr;
            umax = umax.max(u.abs());
        }
        if ((tn / 1e-3).round() - tn / 1e-3).abs() < 1e-6 {
            trace.push(f);
        }
        assert!(f.is_finite());
    }
    ((se / sr).sqrt(), umax, trace)
}

#[test]
fn idf_tracks_reference_force_with_stand_in_actuator() {
    let (e4, u4, tr4) = run_idf(1e-4, 1.0, 1.0);
    let (e3, u3, tr3) = run_idf(1e-3, 1.0, 1.0);
    println!(
        "IDF rms error / rms F_ref: h=1e-4 {e4:.4}, h=1e-3 {e3:.4}; max |u| {u4:.2e} {u3:.2e}"
    );
    // P control of an integrating plant: error ~ omega / crossover = 25 / 213 plus the 1.5 ms board
    // delay; stated bound 20 % of the reference rms (F_ref amplitude 16.6 kN).
    assert!(e4 < 0.20, "rms error ratio {e4}");
    assert!(
        e4 > 0.02,
        "P law should leave a visible tracking error, got {e4}"
    );
    assert!(
        u4 < 1e-3,
        "spool should not saturate in tracking, max |u| = {u4}"
    );
    // Independent of the communication step: same force trace at every ms within 0.5 % of peak.
    let peak = tr4.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let max_diff = tr4
        .iter()
        .zip(&tr3)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    println!("max force difference 1e-4 vs 1e-3: {max_diff:.3} N of peak {peak:.0} N");
    assert!(max_diff < 5e-3 * peak);
    assert!((e4 - e3).abs() < 0.01);
}

#[test]
fn idf_wrong_command_sign_is_unstable() {
    // If the actuator's positive spool reduces tension, command_sign must be -1 ...
    let (e_ok, _, _) = run_idf(1e-3, -1.0, -1.0);
    assert!(e_ok < 0.20, "{e_ok}");
    // ... and a sign mismatch does not track at all (positive feedback, spool saturates).
    let (e_bad, u_bad, _) = run_idf(1e-3, -1.0, 1.0);
    println!("sign mismatch: error ratio {e_bad:.1}, max |u| {u_bad:.1e}");
    assert!(e_bad > 1.0);
    assert!((u_bad - 1e-3).abs() < 1e-12);
}

// ---------------------------------------------------------------------------------------------
// MPPT with a stand-in "hunting mode": m x'' + (c(opening) - c_neg) x' + c3 x'^3 + k x = F_track,
// f_n = 4 Hz, m = 6 t, self-excitation c_neg = 60 kNs/m (unstable for openings above ~ 50 %),
// cubic limiter c3 giving a limit cycle of about 0.5 m/s at full opening (flange-contact stand-in),
// track forcing: 12 sines 1-8 Hz plus 4 strong sines 0.5-1.2 Hz, fixed pseudo-random phases. The damper is a viscous
// c(opening) from the placeholder table (instant valve).

struct HuntingMode {
    x: f64,
    xd: f64,
    table: DampingTable,
    phases: Vec<f64>,
}

const M: f64 = 6000.0;
const C_NEG: f64 = 60e3;
const C3: f64 = 160e3;

impl HuntingMode {
    fn new() -> Self {
        let mut s: u64 = 12345;
        let phases = (0..16)
            .map(|_| {
                s = s
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                (s >> 11) as f64 / (1u64 << 53) as f64 * 2.0 * PI
            })
            .collect();
        Self {
            x: 0.0,
            xd: 0.0,
            table: DampingTable {
                points: DAMPING_TABLE_4HZ.to_vec(),
            },
            phases,
        }
    }
    fn track_force(&self, t: f64) -> f64 {
        let broadband: f64 = self.phases[..12]
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let f = 1.0 + 7.0 * i as f64 / 11.0;
                3.0e3 * (2.0 * PI * f * t + p).sin()
            })
            .sum();
        // Low-frequency (0.5-1.2 Hz, quasi-static) forcing: outside the band-pass, it costs
        // damper force (c x') but little filtered acceleration: the MPPT2 trade-off.
        let low: f64 = self.phases[12..]
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let f = 0.5 + 0.7 * i as f64 / 3.0;
                20.0e3 * (2.0 * PI * f * t + p).sin()
            })
            .sum();
        broadband + low
    }
    fn deriv(&self, x: f64, xd: f64, c: f64, t: f64) -> (f64, f64) {
        let k = M * (2.0 * PI * 4.0f64).powi(2);
        let a = (self.track_force(t) - (c - C_NEG) * xd - C3 * xd.powi(3) - k * x) / M;
        (xd, a)
    }
    /// RK4 over dt with the opening held; returns nothing, state updated.
    fn advance(&mut self, t: f64, dt: f64, opening: f64) {
        let c = self.table.damping_at(opening);
        let (x, v) = (self.x, self.xd);
        let k1 = self.deriv(x, v, c, t);
        let k2 = self.deriv(x + 0.5 * dt * k1.0, v + 0.5 * dt * k1.1, c, t + 0.5 * dt);
        let k3 = self.deriv(x + 0.5 * dt * k2.0, v + 0.5 * dt * k2.1, c, t + 0.5 * dt);
        let k4 = self.deriv(x + dt * k3.0, v + dt * k3.1, c, t + dt);
        self.x += dt / 6.0 * (k1.0 + 2.0 * k2.0 + 2.0 * k3.0 + k4.0);
        self.xd += dt / 6.0 * (k1.1 + 2.0 * k2.1 + 2.0 * k3.1 + k4.1);
    }
    fn outputs(&self, t: f64, opening: f64) -> (f64, f64) {
        let c = self.table.damping_at(opening);
        let (_, a) = self.deriv(self.x, self.xd, c, t);
        (a, c * self.xd)
    }
}

/// Runs MPPT on the stand-in; returns the (J, command) log of every update.
fn run_mppt(params: MpptParams, t_end: f64) -> Vec<(f64, f64, f64)> {
    let mut plant = HuntingMode::new();
    let mut ctrl = Mppt::new(params).unwrap();
    let h = 1e-3;
    let n = (t_end / h).round() as usize;
    let mut log = Vec::new();
    let mut updates = 0;
    for k in 0..n {
        let t = k as f64 * h;
        let opening = ctrl.outputs().opening;
        let (a, f) = plant.outputs(t, opening);
        let o = ctrl
            .step(
                h,
                &MpptInputs {
                    bogie_accel_mps2: a,
                    damper_force_n: f,
                },
            )
            .unwrap();
        // RK4 at the host step: c/m <= 67 1/s, omega = 25 rad/s, well inside RK4 stability.
        plant.advance(t, h, opening);
        if o.updates != updates {
            updates = o.updates;
            log.push((o.cost, o.command_v, o.rms_accel_mps2));
        }
    }
    log
}

/// Mean J over the last 10 updates of a run.
fn tail_cost(log: &[(f64, f64, f64)]) -> f64 {
    let tail = &log[log.len() - 10..];
    tail.iter().map(|l| l.0).sum::<f64>() / tail.len() as f64
}

#[test]
fn mppt_closes_unstable_valve_and_settles_with_lower_cost() {
    for (name, params, factor) in [
        ("MPPT1", MpptParams::mppt1(), 0.05),
        ("MPPT2", MpptParams::mppt2(), 0.6),
    ] {
        // J of the same cost function with the valve frozen (k_J = Delta_V = 0) at 0 V and 10 V.
        let frozen = |v: f64| {
            tail_cost(&run_mppt(
                MpptParams {
                    k_j_v: 0.0,
                    delta_v_v: 0.0,
                    initial_command_v: v,
                    ..params.clone()
                },
                20.0,
            ))
        };
        let (j_closed, j_open) = (frozen(0.0), frozen(10.0));
        let log = run_mppt(
            MpptParams {
                initial_command_v: 10.0,
                ..params
            },
            40.0,
        );
        for (i, l) in log.iter().take(8).enumerate() {
            println!(
                "  {name} update {}: J {:.3} command {:.2} V rms acc {:.2}",
                i + 1,
                l.0,
                l.1,
                l.2
            );
        }
        let first = *log[..3].iter().max_by(|a, b| a.0.total_cmp(&b.0)).unwrap();
        let tail = &log[log.len() - 10..];
        let j_tail = tail.iter().map(|l| l.0).sum::<f64>() / tail.len() as f64;
        let v_tail = tail.iter().map(|l| l.1).sum::<f64>() / tail.len() as f64;
        let v_spread = tail.iter().fold(0.0f64, |m, l| m.max((l.1 - v_tail).abs()));
        println!(
            "{name}: worst early update J = {:.3}, rms acc {:.2} m/s^2 at {:.1} V; last 10 updates: \
             mean J = {j_tail:.3}, mean command {v_tail:.2} V (+-{v_spread:.2}), rms acc {:.2}",
            first.0, first.2, first.1, tail[9].2
        );
        // Started open and hunting above the EN 14363 limit ...
        assert!(first.2 > 5.39, "{name}: the stand-in should start unstable");
        println!("{name}: J with the valve frozen closed {j_closed:.3}, frozen open {j_open:.3}");
        // ... MPPT closes the valve into the stable range and J drops well below its early value
        // (MPPT2 keeps paying for the quasi-static damper force, hence the weaker factor) ...
        assert!(
            j_tail < factor * first.0,
            "{name}: J {j_tail} vs {}",
            first.0
        );
        // ... and ends within 25 % of the better of the two extreme fixed commands (
        // the hill climb keeps probing around its optimum).
        assert!(j_tail < 1.25 * j_closed.min(j_open), "{name}: J {j_tail}");
        assert!(j_tail < j_open, "{name}");
        assert!(tail.iter().all(|l| l.2 < 5.39), "{name}: stays below a_lim");
        assert!(
            v_tail < 5.0,
            "{name}: command {v_tail} V not in the stable range"
        );
    }
}

#[test]
fn mppt2_reopens_more_than_mppt1_when_stable() {
    // R10 (qualitative): started from a closed valve on a stable vehicle, MPPT1 keeps the valve
    // nearly closed, MPPT2 opens it part way to lower the damper force.
    let tail_mean = |log: &[(f64, f64, f64)]| {
        let t = &log[log.len() - 20..];
        t.iter().map(|l| l.1).sum::<f64>() / t.len() as f64
    };
    let l1 = run_mppt(MpptParams::mppt1(), 60.0);
    let l2 = run_mppt(MpptParams::mppt2(), 60.0);
    let (v1, v2) = (tail_mean(&l1), tail_mean(&l2));
    println!("mean command over the last 20 updates: MPPT1 {v1:.2} V, MPPT2 {v2:.2} V");
    assert!(
        v2 > v1 + 0.5,
        "MPPT2 {v2} V should open more than MPPT1 {v1} V"
    );
    assert!(l2.iter().all(|l| l.2 < 5.39));
}

// ---------------------------------------------------------------------------------------------
// Sky-hook on the same stand-in, ideal (instant) valve: both modes must stabilise the unstable
// mode (R11: about as good as MPPT with an ideal valve).

#[test]
fn skyhook_stabilises_stand_in_with_ideal_valve() {
    for mode in [SkyHookMode::OnOff, SkyHookMode::Continuous] {
        for source in [
            VelocitySource::Ideal,
            VelocitySource::EstimatedFromAcceleration,
        ] {
            let mut plant = HuntingMode::new();
            let mut ctrl = SkyHook::new(SkyHookParams {
                mode,
                velocity_source: source,
                initial_command_v: 10.0,
                ..Default::default()
            })
            .unwrap();
            // The stand-in's "car body" is fixed: x0' = 0, the damper elongation velocity is x'.
            let h = 1e-3;
            let mut accel_est = 0.0;
            let (mut s2, mut cnt) = (0.0, 0);
            for k in 0..20_000 {
                let t = k as f64 * h;
                let opening = ctrl.outputs().opening;
                let (a, _) = plant.outputs(t, opening);
                accel_est = a;
                ctrl.step(
                    h,
                    &SkyHookInputs {
                        sensor_accel_mps2: a,
                        abs_velocity_mps: plant.xd,
                        elongation_velocity_mps: plant.xd,
                    },
                )
                .unwrap();
                plant.advance(t, h, opening);
                if t > 10.0 {
                    s2 += a * a;
                    cnt += 1;
                }
            }
            let rms = (s2 / cnt as f64).sqrt();
            println!("sky-hook {mode:?} {source:?}: rms acceleration {rms:.2} m/s^2 (last 10 s)");
            assert!(accel_est.is_finite());
            assert!(rms < 5.39 * 0.5, "{mode:?} {source:?}: rms {rms}");
        }
    }
}
