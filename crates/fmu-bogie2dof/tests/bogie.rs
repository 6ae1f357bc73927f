//! Reference results R5-R7 of REFERENCE.md and numerical checks of the time-domain model.
//! The passive damper is the Maxwell fit of the fmu-damper characterisation (30 % opening,
//! 1 mm, 3-4 Hz): k_s = 16.9 MN/m in series with c_s = 104 kNs/m per damper
//! (`calibration::passive_damper`); in the time domain the same element is fed back through
//! the damper-force inputs. Contact: the default worn-profile surrogate table.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use fmu_bogie2dof::calibration::*;
use fmu_bogie2dof::eigen::*;
use fmu_bogie2dof::sim::{run_closed_loop, LinearDamper};
use fmu_bogie2dof::*;
use wheel_rail::GeometryTable;

fn passive_loop() -> LinearDamper {
    LinearDamper::Maxwell {
        k: PASSIVE_MAXWELL_K_N_PER_M,
        c: PASSIVE_MAXWELL_C_NS_PER_M,
    }
}

/// Synthetic cone + steep flange at 7 mm (no gravitational stiffness): integrator checks.
fn synthetic_table() -> GeometryTable {
    GeometryTable::synthetic(CALIBRATED_CONICITY, 7e-3, 5e-4, 2.7).unwrap()
}

fn default_table() -> GeometryTable {
    fmu_bogie2dof::model::default_contact_table().unwrap()
}

/// Runs the closed loop; returns (time, front wheelset displacement) samples.
fn run(
    kmh: f64,
    model: ModelKind,
    y0: f64,
    h: f64,
    t_end: f64,
    damper: LinearDamper,
) -> Vec<(f64, f64, f64)> {
    run_with(kmh, model, y0, h, t_end, damper, default_table())
}

fn run_with(
    kmh: f64,
    model: ModelKind,
    y0: f64,
    h: f64,
    t_end: f64,
    damper: LinearDamper,
    table: GeometryTable,
) -> Vec<(f64, f64, f64)> {
    let p = Params {
        speed_mps: kmh / 3.6,
        model,
        initial_lateral_m: y0,
        ..Params::default()
    };
    let mut b = Bogie::with_table(p, table).unwrap();
    let mut v = Vec::new();
    run_closed_loop(&mut b, damper, h, t_end, &|_| 0.0, &mut |o| {
        v.push((
            o.time_s,
            o.wheelset_front_lateral_m,
            o.wheelset_rear_lateral_m,
        ))
    })
    .unwrap();
    v
}

fn peak_between(tr: &[(f64, f64, f64)], t0: f64, t1: f64) -> f64 {
    tr.iter()
        .filter(|s| s.0 >= t0 && s.0 <= t1)
        .map(|s| s.1.abs().max(s.2.abs()))
        .fold(0.0, f64::max)
}

#[test]
fn maxwell_fit_of_passive_damper() {
    // least-squares fit to the 1 mm data at 3, 3.5, 4 Hz reproduces the constants
    let (k, c) = fit_maxwell(&PASSIVE_DAMPER_1MM[1..4]).unwrap();
    assert!((k - PASSIVE_MAXWELL_K_N_PER_M).abs() / k < 0.01, "{k}");
    assert!((c - PASSIVE_MAXWELL_C_NS_PER_M).abs() / c < 0.01, "{c}");
    // quality of the fit around the hunting frequency: k_eq within 3 %, c_eq within 8 %
    for m in &PASSIVE_DAMPER_1MM[1..4] {
        let (ke, ce) = maxwell_equivalent(k, c, m.freq_hz);
        println!(
            "{} Hz: k_eq {:.0} vs {:.0} kN/m, c_eq {:.1} vs {:.1} kNs/m",
            m.freq_hz,
            ke / 1e3,
            m.k_eq_n_per_m / 1e3,
            ce / 1e3,
            m.c_eq_ns_per_m / 1e3
        );
        assert!((ke - m.k_eq_n_per_m).abs() / m.k_eq_n_per_m < 0.03);
        assert!((ce - m.c_eq_ns_per_m).abs() / m.c_eq_ns_per_m < 0.08);
    }
    // the damper is Maxwell-like: k_eq rises and c_eq falls with frequency (R2)
    for w in PASSIVE_DAMPER_1MM.windows(2) {
        assert!(w[1].k_eq_n_per_m > w[0].k_eq_n_per_m && w[1].c_eq_ns_per_m < w[0].c_eq_ns_per_m);
    }
}

/// The shipped A/A table against today's profile contact search (EN 15302 E1, the settings of
/// `wheel-rail/examples/bogie_table.rs`): the same rows, and numbers within the change the
/// example documents (measured: 0.24 mm in delta r, 0.046 in tan gamma, near the flange root).
#[test]
fn contact_search_reproduces_the_shipped_table_within_its_known_change() {
    use wheel_rail::{compute_table, ContactSetup, Profile, RadiusConvention};
    let data = concat!(env!("CARGO_MANIFEST_DIR"), "/../wheel-rail/data");
    let wheel = Profile::from_file(format!("{data}/RUIC519A.dat")).unwrap();
    let rail = Profile::from_file(format!("{data}/SUIC519A.dat")).unwrap();
    let setup = ContactSetup {
        radius_convention: RadiusConvention::RigidRoll,
        ..ContactSetup::symmetric(wheel, rail, 0.920 / 2.0, 1.43516)
    };
    let today = compute_table(&setup, -10e-3, 10e-3, 0.05e-3).unwrap();
    let today = GeometryTable::parse_csv(&today.to_bogie_csv(), "today's search").unwrap();
    let shipped = model::default_aa_table().unwrap();
    assert_eq!(today.rows().len(), shipped.rows().len());
    let (mut dr, mut tg) = (0.0f64, 0.0f64);
    for (a, b) in today.rows().zip(shipped.rows()) {
        assert!((a[0] - b[0]).abs() < 1e-9, "y {} vs {}", a[0], b[0]);
        dr = dr.max((a[1] - b[1]).abs()).max((a[2] - b[2]).abs());
        tg = tg.max((a[3] - b[3]).abs()).max((a[4] - b[4]).abs());
    }
    assert!(
        dr <= 0.25e-3 && tg <= 0.05,
        "delta r {:.3} mm, tan gamma {tg:.3}",
        dr * 1e3
    );
    // and the change is real: the table is a calibration input, not today's output (when the
    // table is regenerated with the recalibration, this and the docs that say so go with it)
    assert!(
        dr > 0.1e-3,
        "delta r differs by only {:.3} mm: was the shipped table regenerated? update the docs",
        dr * 1e3
    );
}

/// The shipped tables are in the exact form of the one CSV writer of `wheel-rail` (a format
/// check, not a check of their numbers): the A/A table in fixed decimals, the surrogate in
/// exponent form after its comment line (written by `examples/write_surrogate.rs`). The A/A
/// numbers are a calibration input, written by the profile contact search before its contact
/// point became the zone's centroid; `wheel-rail/examples/bogie_table.rs` says how far today's
/// search differs, and `contact_search_reproduces_the_shipped_table_within_its_known_change`
/// bounds that difference.
#[test]
fn shipped_tables_are_the_wheel_rail_writers_output() {
    let aa = include_str!("../resources/wheel_rail_A_A.csv");
    let table = model::default_aa_table().unwrap();
    assert_eq!(table.to_csv(wheel_rail::CsvNumbers::Fixed), aa);
    let worn = include_str!("../resources/wheel_rail_worn_surrogate.csv");
    let (comment, body) = worn.split_once('\n').unwrap();
    assert!(comment.starts_with("# Worn-profile surrogate"), "{comment}");
    let surrogate = model::worn_surrogate_table().unwrap();
    assert_eq!(surrogate.to_csv(wheel_rail::CsvNumbers::Scientific), body);
}

#[test]
fn linear_model_uses_the_default_tables_contact_at_1mm() {
    let (lam, g) = default_table().linearise(LINEARISATION_AMPLITUDE_M);
    let p = Params::default();
    assert!((lam - p.conicity).abs() < 1e-3, "{lam}");
    assert!(
        (g * p.wheel_load_n - p.gravity_stiffness_n_per_m).abs() < 0.01e6,
        "{}",
        g * p.wheel_load_n
    );
    // the shipped CSV equals the built-in surrogate
    let text = include_str!("../resources/wheel_rail_worn_surrogate.csv");
    let shipped = GeometryTable::parse_csv(text, "wheel_rail_worn_surrogate.csv").unwrap();
    for y in [-8e-3, -5e-3, -1e-3, 0.0, 2e-3, 4.2e-3, 6.7e-3] {
        let (a, b) = (shipped.lookup(y), default_table().lookup(y));
        // the CSV carries 7 significant digits
        assert!(
            (a.delta_r_right_m - b.delta_r_right_m).abs() <= 1e-6 * b.delta_r_right_m.abs() + 1e-12,
            "{y}: {} vs {}",
            a.delta_r_right_m,
            b.delta_r_right_m
        );
        assert!((a.tan_gamma_left - b.tan_gamma_left).abs() < 1e-6);
    }
    // worn surrogate: 0.25 on the tread, rising towards the worn range at large amplitude
    let (l6, _) = default_table().linearise(6e-3);
    assert!(l6 > 0.3 && l6 < 0.4, "{l6}");
}

#[test]
fn r5_r6_linear_critical_speed_and_hunting_frequency_passive_damper() {
    let p = Params::default();
    let c = critical_speed(&p, &passive_damper(), 5.0, 200.0).unwrap();
    println!(
        "V_cr = {:.1} km/h, hunting {:.2} Hz, Im {:.2} rad/s",
        c.speed_kmh, c.hunting.freq_hz, c.hunting.im
    );
    // R5: 270 km/h (+-10)
    assert!((c.speed_kmh - 270.0).abs() <= 10.0, "{c:?}");
    // R6: 3-4.5 Hz at onset. KNOWN GAP: the seed's Im ~ 21 rad/s is not reached, ours is
    // 27.7 rad/s (4.41 Hz) because the gravitational stiffness lifts the lateral natural
    // frequency to 4.2 Hz (see calibration docs); pinned here.
    assert!(
        c.hunting.freq_hz >= 3.0 && c.hunting.freq_hz <= 4.5,
        "{c:?}"
    );
    assert!((c.hunting.im - 27.7).abs() < 0.5, "{c:?}");
    assert!(c.hunting.re.abs() < 1e-3);
    // stable below, unstable above
    let below = analyse(&p, 250.0 / 3.6, &passive_damper()).unwrap();
    let above = analyse(&p, 290.0 / 3.6, &passive_damper()).unwrap();
    assert!(below.max_re < 0.0 && above.max_re > 0.0);
    // the frequency-dependent table of the real damper (Kelvin-Voigt at the mode's own
    // frequency) gives nearly the same critical speed as the Maxwell fit
    let table: Vec<DamperPoint> = PASSIVE_DAMPER_1MM
        .iter()
        .map(|m| DamperPoint {
            freq_hz: m.freq_hz,
            k_n_per_m: m.k_eq_n_per_m,
            c_ns_per_m: m.c_eq_ns_per_m,
        })
        .collect();
    let t = critical_speed(
        &p,
        &DamperRepresentation::FrequencyDependent(table),
        5.0,
        200.0,
    )
    .unwrap();
    println!("frequency-dependent table: {:.1} km/h", t.speed_kmh);
    // 264.7 vs 270 km/h: at 4.4 Hz the table's c_eq (91 kNs/m, interpolated 4-5 Hz) is under
    // the Maxwell fit's (101); within the 10 km/h the coupled study allows.
    assert!((t.speed_kmh - c.speed_kmh).abs() < 10.0, "{t:?}");
}

#[test]
fn calibration_function_reproduces_constant() {
    let p = Params::default();
    let (k, c) = calibrate_k_ssx(&p, &passive_damper(), TARGET_CRITICAL_SPEED_KMH).unwrap();
    assert!((c.speed_kmh - 270.0).abs() < 0.01);
    assert!((k - CALIBRATED_K_SSX_N_PER_M).abs() / k < 0.01, "k_ssx {k}");
    // effective yaw stiffness per side: k_ssx + damper k_eq + gravitational share.
    // KNOWN GAP: about 2.6 MN/m, under REFERENCE's 3-5 MN/m (derived without gravity).
    let (ke, _) = maxwell_equivalent(
        PASSIVE_MAXWELL_K_N_PER_M,
        PASSIVE_MAXWELL_C_NS_PER_M,
        c.hunting.freq_hz,
    );
    let grav = p.gravity_stiffness_n_per_m * p.half_wheelbase_m.powi(2) / p.damper_arm_m.powi(2);
    let total = k + ke + grav;
    println!("effective yaw stiffness per side {:.2} MN/m", total / 1e6);
    assert!(total > 2.2e6 && total < 3e6);
}

#[test]
fn stiffness_not_damping_sets_critical_speed() {
    // REFERENCE (the seed's model: no gravitational stiffness, Kalker without reduction):
    // with air-spring stiffness alone the onset is far below 270 km/h, whatever the damping.
    let p = Params {
        k_ssx_n_per_m: 160e3,
        gravity_stiffness_n_per_m: 0.0,
        creep_reduction: 1.0,
        conicity: 0.15,
        ..Params::default()
    };
    for c0 in [60e3, 120e3, 300e3] {
        let c = critical_speed(
            &p,
            &DamperRepresentation::Linear(LinearDamper::Viscous { c: c0 }),
            5.0,
            200.0,
        )
        .unwrap();
        assert!(c.speed_kmh < 230.0, "c0 {c0}: {c:?}");
        assert!(c.hunting.freq_hz < 2.5, "c0 {c0}: {c:?}");
    }
}

#[test]
fn maxwell_and_frequency_dependent_representations_work() {
    let p = Params::default();
    // A stiff Maxwell damper (series stiffness ~10 MN/m, MPE 2019) gives a critical speed.
    let m = critical_speed(
        &p,
        &DamperRepresentation::Linear(LinearDamper::Maxwell { k: 10e6, c: 300e3 }),
        5.0,
        200.0,
    )
    .unwrap();
    assert!(m.speed_kmh > 150.0 && m.speed_kmh < 500.0, "{m:?}");
    // Kelvin-Voigt equivalent of that Maxwell element at the mode frequency, as a table:
    // same critical speed.
    let (k, c) = (10e6, 300e3);
    let table: Vec<DamperPoint> = (1..=80)
        .map(|i| {
            let f = 0.1 * i as f64;
            let (ke, ce) = maxwell_equivalent(k, c, f);
            DamperPoint {
                freq_hz: f,
                k_n_per_m: ke,
                c_ns_per_m: ce,
            }
        })
        .collect();
    let fd = critical_speed(
        &p,
        &DamperRepresentation::FrequencyDependent(table),
        5.0,
        200.0,
    )
    .unwrap();
    assert!((fd.speed_kmh - m.speed_kmh).abs() < 1.0, "{fd:?} vs {m:?}");
}

/// The linear time-domain model with the Maxwell damper fed back through the inputs decays
/// at the rate of the eigen-analysis: checks the damper sign convention end to end.
#[test]
fn time_domain_linear_decay_matches_eigenvalue() {
    let kmh = 240.0;
    let p = Params::default();
    let e = analyse(&p, kmh / 3.6, &passive_damper()).unwrap();
    let h = e.hunting.unwrap();
    let tr = run(kmh, ModelKind::Linear, 2e-3, 1e-4, 6.0, passive_loop());
    // decay of the envelope between 2 s and 5 s (hunting dominates by then)
    let a1 = peak_between(&tr, 2.0, 2.0 + 1.0 / h.freq_hz);
    let a2 = peak_between(&tr, 5.0, 5.0 + 1.0 / h.freq_hz);
    let rate = (a2 / a1).ln() / 3.0;
    println!("decay rate {rate:.4} vs eigen {:.4}", h.re);
    assert!((rate - h.re).abs() < 0.1 * h.re.abs(), "{rate} vs {}", h.re);
}

/// Peak |relative wheelset displacement| and peak contact angle in [t0, t1].
fn peak_and_contact_angle(kmh: f64, y0: f64, t_end: f64, t0: f64) -> (f64, f64, f64) {
    let p = Params {
        speed_mps: kmh / 3.6,
        initial_lateral_m: y0,
        ..Params::default()
    };
    let mut b = Bogie::new(p).unwrap();
    let table = default_table();
    let (mut early, mut peak, mut tg): (f64, f64, f64) = (0.0, 0.0, 0.0);
    run_closed_loop(&mut b, passive_loop(), 1e-3, t_end, &|_| 0.0, &mut |o| {
        let a = o
            .wheelset_front_rel_track_m
            .abs()
            .max(o.wheelset_rear_rel_track_m.abs());
        if o.time_s <= 0.5 {
            early = early.max(a);
        }
        if o.time_s >= t0 {
            peak = peak.max(a);
            for y in [o.wheelset_front_rel_track_m, o.wheelset_rear_rel_track_m] {
                let c = table.lookup(y);
                tg = tg.max(c.tan_gamma_left.max(c.tan_gamma_right));
            }
        }
    })
    .unwrap();
    (early, peak, tg)
}

#[test]
fn r7_nonlinear_decays_at_220_kmh() {
    let (early, late, _) = peak_and_contact_angle(220.0, 3e-3, 6.0, 5.0);
    println!("220 km/h: peak {early:e} -> {late:e}");
    assert!(early > 2e-3 && late < 0.05 * early, "{early} -> {late}");
}

#[test]
fn r7_nonlinear_flange_limit_cycle_at_320_kmh() {
    let (_, a, tg) = peak_and_contact_angle(320.0, 3e-3, 8.0, 5.0);
    let (_, b, _) = peak_and_contact_angle(320.0, 3e-3, 5.0, 3.0);
    println!(
        "320 km/h: limit cycle peak wheelset displacement {:.4} mm, max tan gamma {tg:.2}",
        a * 1e3
    );
    // seed: +-6 mm with flange contact; accepted 5-8 mm, and a steady cycle (not growing)
    assert!(a > 5e-3 && a < 8e-3, "{a}");
    assert!((a - b).abs() < 0.05 * a);
    // beyond the tread (tan gamma <= 0.28 up to 6 mm): on the flange root. KNOWN GAP: the
    // wheel-rail crate puts full flange contact from 6.6 mm; the cycle stops at ~6.5 mm.
    assert!(tg > 0.4, "{tg}");
}

/// R7 at 285 km/h: the seed has a small limit cycle without flange contact. Ours: a limit
/// cycle of about 3.5 mm on the tread (pinned).
#[test]
fn r7_nonlinear_285_kmh_limit_cycle_without_flange_contact() {
    let (_, a, tg) = peak_and_contact_angle(285.0, 3e-3, 8.0, 5.0);
    let (_, b, _) = peak_and_contact_angle(285.0, 3e-3, 5.0, 3.0);
    println!(
        "285 km/h: limit cycle {:.4} mm, max tan gamma {tg:.2}",
        a * 1e3
    );
    assert!(a > 2.5e-3 && a < 4.5e-3, "{a}");
    assert!((a - b).abs() < 0.05 * a);
    assert!(tg < 0.28, "{tg}");
}

/// Below the critical speed at small amplitude both models see the same contact (conicity
/// and gravitational stiffness of the table at 1 mm): the non-linear trajectory stays close to
/// the linear one. Remaining differences: tan gamma(y) is not linear below 1 mm (1.76 MN/m at
/// 0.5 mm) and the non-linear model has the spin dofs.
#[test]
fn linear_and_nonlinear_agree_at_small_amplitude_below_critical_speed() {
    let y0 = 1e-3;
    let a = run(220.0, ModelKind::Linear, y0, 1e-3, 3.0, passive_loop());
    let b = run(220.0, ModelKind::NonLinear, y0, 1e-3, 3.0, passive_loop());
    let max_diff = a
        .iter()
        .zip(&b)
        .filter(|(x, _)| x.0 <= 1.0)
        .map(|(x, y)| (x.1 - y.1).abs())
        .fold(0.0, f64::max);
    let (pa, pb) = (peak_between(&a, 1.0, 2.0), peak_between(&b, 1.0, 2.0));
    println!("max |lin - nonlin| (0-1 s) = {max_diff:e} m of {y0:e} m; peaks 1-2 s {pa:e} {pb:e}");
    assert!(max_diff < 0.2 * y0, "{max_diff}");
    // both decay
    assert!(pa < 0.5 * y0 && pb < 0.5 * y0);
}

/// Integrator accuracy: the model alone (no damper in the loop; the damper's stiffness is put
/// into k_ssx so it is stable) must not depend on the communication step.
#[test]
fn communication_step_independence_model_alone() {
    let mk2 = |h: f64| {
        let p = Params {
            speed_mps: 320.0 / 3.6,
            initial_lateral_m: 6e-3,
            ..Params::default()
        };
        let mut b = Bogie::with_table(p, synthetic_table()).unwrap();
        let mut v = Vec::new();
        run_closed_loop(&mut b, LinearDamper::None, h, 1.55, &|_| 0.0, &mut |o| {
            v.push((o.time_s, o.wheelset_front_lateral_m))
        })
        .unwrap();
        v
    };
    let mk = |h: f64, t_end: f64| {
        let p = Params {
            speed_mps: 250.0 / 3.6,
            initial_lateral_m: 3e-3,
            // stable without damper: yaw stiffness in k_ssx
            k_ssx_n_per_m: 4e6,
            ..Params::default()
        };
        let mut b = Bogie::with_table(p, default_table()).unwrap();
        let mut v = Vec::new();
        run_closed_loop(&mut b, LinearDamper::None, h, t_end, &|_| 0.0, &mut |o| {
            v.push((o.time_s, o.wheelset_front_lateral_m))
        })
        .unwrap();
        v
    };
    // 1e-4 s (one sub-step of 1e-4) vs 1.55e-3 s (two sub-steps of 0.775e-3): different
    // internal grids, compared at the common instants (every 3.1 ms) over 1.55 s.
    let (a, b) = (mk(1e-4, 1.55), mk(1.55e-3, 1.55));
    let (ea, eb) = (a.last().unwrap(), b.last().unwrap());
    assert!((ea.0 - eb.0).abs() < 1e-9);
    let mut diff: f64 = 0.0;
    for (k, s) in b.iter().enumerate().step_by(2) {
        let sa = a[31 * k / 2];
        assert!((sa.0 - s.0).abs() < 1e-9);
        diff = diff.max((sa.1 - s.1).abs());
    }
    let env = |v: &[(f64, f64)]| {
        v.iter()
            .filter(|s| s.0 > 1.0)
            .map(|s| s.1.abs())
            .fold(0.0, f64::max)
    };
    println!(
        "model alone: max diff {diff:e} m, envelope after 1 s {:e} vs {:e}",
        env(&a),
        env(&b)
    );
    assert!(env(&a) > 1e-5, "still moving");
    // 1.5e-7 m with the 1.08 ms sub-step bound (1.6e-9 m when the sub-step was 0.1 ms)
    assert!(diff < 1e-4 * 3e-3, "{diff}");
    assert!((env(&a) - env(&b)).abs() < 1e-3 * env(&a));
    // and a flange-contact case (320 km/h, no damper): the amplitude of the flange-contact
    // cycle is resolved by the 1.55 ms sub-step (one RK4 step per communication step) as by
    // 0.1 ms. The instantaneous value at 1.55 s differs by 0.31 mm (4.5 % of the amplitude):
    // the timing of the flange impacts drifts by about 1.5 ms over 1.55 s, i.e. 0.1 % of the
    // cycle's period (3.5e-7 m when both steps were integrated with 0.1 ms sub-steps).
    let (a, b) = (mk2(1e-4), mk2(1.55e-3));
    let (pa, pb) = (env(&a), env(&b));
    let (ea, eb) = (a.last().unwrap(), b.last().unwrap());
    let diff = (ea.1 - eb.1).abs();
    println!(
        "flange contact: peak after 1 s {:.4} vs {:.4} mm, |y(1.55 s)| diff {diff:e} m",
        pa * 1e3,
        pb * 1e3
    );
    assert!(pa > 7e-3 && (pa - pb).abs() < 1e-3 * 7e-3, "{pa} {pb}");
    assert!(diff < 0.05 * 7e-3, "{diff}");
}

/// Closed loop with the zero-order-hold damper force: the coupling delay (h/2) shifts the
/// damper phase by about w h / 2, a few % of the decay rate at h = 2 ms. Bounded here.
#[test]
fn communication_step_independence_closed_loop() {
    let a = run(250.0, ModelKind::NonLinear, 3e-3, 1e-4, 3.0, passive_loop());
    let b = run(250.0, ModelKind::NonLinear, 3e-3, 2e-3, 3.0, passive_loop());
    let mut max_diff: f64 = 0.0;
    for s in &b {
        let k = (s.0 / 1e-4).round() as usize;
        max_diff = max_diff.max((a[k].1 - s.1).abs());
    }
    println!("closed loop: max |h=1e-4 - h=2e-3| = {max_diff:e} m (initial 3e-3)");
    assert!(max_diff < 0.08 * 3e-3, "{max_diff}");
}

#[test]
fn outputs_without_stepping_and_feedthrough() {
    let p = Params {
        initial_lateral_m: 2e-3,
        initial_yaw_rad: 1e-3,
        ..Params::default()
    };
    let b = Bogie::with_table(p.clone(), synthetic_table()).unwrap();
    let i0 = Inputs::default();
    let o0 = b.outputs(&i0).unwrap();
    assert_eq!(o0.time_s, 0.0);
    assert!((o0.damper_left_elongation_m - p.damper_arm_m * 1e-3).abs() < 1e-15);
    assert!((o0.damper_right_elongation_m + p.damper_arm_m * 1e-3).abs() < 1e-15);
    assert!((o0.wheelset_front_lateral_m - (2e-3 - 1.25e-3)).abs() < 1e-12);
    // left damper in tension -> yaw moment -b F_L -> nose-right acceleration: the front
    // end accelerates to the right, the rear to the left
    let i1 = Inputs {
        damper_left_force_n: 10e3,
        ..Inputs::default()
    };
    let o1 = b.outputs(&i1).unwrap();
    let dsdd = -p.damper_arm_m * 10e3 / p.bogie_yaw_inertia_kgm2;
    assert!(
        ((o1.frame_acc_front_mps2 - o0.frame_acc_front_mps2) - (-p.half_wheelbase_m * dsdd)).abs()
            < 1e-9
    );
    assert!(
        ((o1.frame_acc_rear_mps2 - o0.frame_acc_rear_mps2) - (p.half_wheelbase_m * dsdd)).abs()
            < 1e-9
    );
    assert!(o1.frame_acc_front_mps2 > o0.frame_acc_front_mps2);
}

#[test]
fn external_track_reaches_rear_wheelset_after_2p_over_v() {
    let p = Params {
        speed_mps: 50.0,
        model: ModelKind::NonLinear,
        ..Params::default()
    };
    let mut b = Bogie::with_table(p, synthetic_table()).unwrap();
    let step_in = |t: f64| if t >= 0.1 { 1e-3 } else { 0.0 };
    let mut rec = Vec::new();
    run_closed_loop(&mut b, passive_loop(), 1e-3, 0.3, &step_in, &mut |o| {
        rec.push((o.time_s, o.track_front_m, o.track_rear_m))
    })
    .unwrap();
    // rear sees the step 2p/V = 0.05 s later
    let rear_at = |t: f64| rec.iter().find(|r| (r.0 - t).abs() < 5e-4).unwrap().2;
    assert!(rear_at(0.14) < 1e-9);
    assert!((rear_at(0.16) - 1e-3).abs() < 1e-9);
    // the bogie follows the shifted track
    assert!(b.state()[0] > 0.3e-3);
}

#[test]
fn internal_track_generator_drives_the_bogie() {
    let p = Params {
        speed_mps: 200.0 / 3.6,
        track: TrackSource::Internal {
            level: PsdLevel::High,
            seed: 11,
        },
        ..Params::default()
    };
    let mut b = Bogie::with_table(p, synthetic_table()).unwrap();
    let mut max_t: f64 = 0.0;
    let mut max_acc: f64 = 0.0;
    run_closed_loop(&mut b, passive_loop(), 1e-3, 2.0, &|_| 0.0, &mut |o| {
        max_t = max_t.max(o.track_front_m.abs());
        max_acc = max_acc.max(o.frame_acc_front_mps2.abs());
    })
    .unwrap();
    assert!(max_t > 5e-4 && max_acc > 0.05, "{max_t} {max_acc}");
}

#[test]
fn bad_params_and_inputs_rejected() {
    let cases: Vec<(&str, Params)> = vec![
        (
            "bogie_mass_kg",
            Params {
                bogie_mass_kg: -1.0,
                ..Params::default()
            },
        ),
        (
            "k_ssy_n_per_m",
            Params {
                k_ssy_n_per_m: -5.0,
                ..Params::default()
            },
        ),
        (
            "k_ssx_n_per_m",
            Params {
                k_ssx_n_per_m: f64::NAN,
                ..Params::default()
            },
        ),
        (
            "speed_mps",
            Params {
                speed_mps: 0.0,
                ..Params::default()
            },
        ),
        (
            "friction_coefficient",
            Params {
                friction_coefficient: 1.5,
                ..Params::default()
            },
        ),
        (
            "friction_coefficient",
            Params {
                friction_coefficient: -0.1,
                ..Params::default()
            },
        ),
        (
            "wheel_load_n",
            Params {
                wheel_load_n: 0.0,
                ..Params::default()
            },
        ),
        // no rail wheel, no rail gauge (the coach's ranges)
        (
            "wheel_radius_m",
            Params {
                wheel_radius_m: 1e-300,
                ..Params::default()
            },
        ),
        (
            "half_contact_gauge_m",
            Params {
                half_contact_gauge_m: 10.0,
                ..Params::default()
            },
        ),
    ];
    for (name, p) in cases {
        let e = p.validate().unwrap_err();
        assert_eq!(e.name, name);
        assert!(e.to_string().contains(name));
        assert!(Bogie::new(p).is_err());
    }
    assert!(Params::default().validate().is_ok());
    let p = Params {
        contact: ContactSource::File("/nonexistent/x.csv".into()),
        ..Params::default()
    };
    assert!(Bogie::new(p).is_err());

    let mut b = Bogie::with_table(Params::default(), synthetic_table()).unwrap();
    let bad = Inputs {
        damper_left_force_n: f64::NAN,
        ..Inputs::default()
    };
    match b.step(1e-3, &bad) {
        Err(StepError::Input(model::InputError::NonFiniteInput { name, .. })) => {
            assert_eq!(name, "damper_left_force_n")
        }
        r => panic!("{r:?}"),
    }
    assert!(b.outputs(&bad).is_err());
    let bad = Inputs {
        track_lateral_m: f64::INFINITY,
        ..Inputs::default()
    };
    assert!(b.step(1e-3, &bad).is_err());
    assert!(b.step(0.0, &Inputs::default()).is_err());
    assert!(b.step(f64::NAN, &Inputs::default()).is_err());
    // huge forces: an error, never NaN
    let huge = Inputs {
        damper_left_force_n: 1e12,
        ..Inputs::default()
    };
    let mut res = Ok(b.outputs(&Inputs::default()).unwrap());
    for _ in 0..1000 {
        res = b.step(1e-3, &huge);
        if res.is_err() {
            break;
        }
    }
    assert!(
        matches!(
            res,
            Err(StepError::Diverged { .. }) | Err(StepError::Derailed { .. })
        ),
        "{res:?}"
    );
    // a failed step leaves the model unchanged
    let before = b.clone();
    assert!(b.step(1e-3, &huge).is_err());
    assert_eq!(b, before);
}

/// A failed step with an external track input leaves the delay line unchanged too.
#[test]
fn failed_step_is_transactional_with_external_track() {
    let p = Params {
        speed_mps: 50.0,
        ..Params::default()
    };
    let mut b = Bogie::new(p).unwrap();
    let i = Inputs {
        track_lateral_m: 1e-3,
        ..Inputs::default()
    };
    for _ in 0..20 {
        b.step(1e-3, &i).unwrap();
    }
    let huge = Inputs {
        damper_left_force_n: 1e13,
        track_lateral_m: 2e-3,
        ..Inputs::default()
    };
    let mut n = 0;
    loop {
        let before = b.clone();
        match b.step(1e-2, &huge) {
            Ok(_) => n += 1,
            Err(_) => {
                assert_eq!(b, before);
                break;
            }
        }
        assert!(n < 1000);
    }
}

#[test]
fn state_save_restore_by_clone_and_serde() {
    let p = Params {
        initial_lateral_m: 3e-3,
        ..Params::default()
    };
    let mut a = Bogie::with_table(p, synthetic_table()).unwrap();
    let i = Inputs::default();
    for _ in 0..100 {
        a.step(1e-3, &i).unwrap();
    }
    let mut b = a.clone();
    let oa = a.step(1e-3, &i).unwrap();
    let ob = b.step(1e-3, &i).unwrap();
    assert_eq!(oa, ob);
    let json = serde_json::to_string(&a).unwrap();
    let mut c: Bogie = serde_json::from_str(&json).unwrap();
    assert_eq!(a.step(1e-3, &i).unwrap(), c.step(1e-3, &i).unwrap());
}

/// The built-in A/A table (EN 15302 profiles, from the wheel-rail crate, selectable with
/// `ContactSource::ProfilesAA`): conventions and the non-linear response. KNOWN DEVIATION:
/// its small-amplitude conicity (0.13 at 1 mm) with its gravitational stiffness (~2 MN/m per
/// wheelset) keeps the linear critical speed above 338 km/h for any knob setting in range,
/// hence the worn-profile surrogate default. Pinned: a 3 mm perturbation decays at 220 and
/// at 320 km/h (no hunting at all, against R7).
#[test]
fn profiles_aa_table_conventions_and_response() {
    let t = fmu_bogie2dof::model::default_aa_table().unwrap();
    let (a, b) = (t.lookup(3e-3), t.lookup(-3e-3));
    // right wheel radius grows and its contact angle steepens to the right
    assert!(a.delta_r_right_m > b.delta_r_right_m && a.delta_r_left_m < b.delta_r_left_m);
    assert!(a.tan_gamma_right > a.tan_gamma_left && b.tan_gamma_left > b.tan_gamma_right);
    assert!(t.lookup(7.5e-3).tan_gamma_right > 2.0);
    let (lam, g) = t.linearise(1e-3);
    println!(
        "A/A: equivalent conicity(1 mm) {lam:.3}, gravity stiffness {:.2} MN/m per wheelset",
        g * 70e3 / 1e6
    );
    assert!(lam > 0.1 && lam < 0.15);
    let p = Params {
        conicity: lam,
        gravity_stiffness_n_per_m: g * 70e3,
        ..Params::default()
    };
    match critical_speed(&p, &passive_damper(), 5.0, 199.0) {
        Ok(c) => {
            println!("A/A linear V_cr {:.0} km/h", c.speed_kmh);
            assert!(c.speed_kmh > 338.0);
        }
        Err(e) => println!("A/A linear: {e}"),
    }
    let mut peaks = vec![];
    for kmh in [220.0, 320.0] {
        let p = Params {
            speed_mps: kmh / 3.6,
            initial_lateral_m: 3e-3,
            contact: ContactSource::ProfilesAA,
            ..Params::default()
        };
        let mut m = Bogie::new(p).unwrap();
        let mut peak_late: f64 = 0.0;
        run_closed_loop(&mut m, passive_loop(), 1e-3, 4.0, &|_| 0.0, &mut |o| {
            if o.time_s > 3.0 {
                peak_late = peak_late.max(o.wheelset_front_lateral_m.abs());
            }
        })
        .unwrap();
        println!(
            "A/A table, {kmh} km/h: peak wheelset displacement after 3 s {:.4} mm",
            peak_late * 1e3
        );
        peaks.push(peak_late);
    }
    assert!(peaks[0] < 0.1e-3, "{peaks:?}");
    assert!(peaks[1] < 0.1e-3, "{peaks:?}");
}

/// The internal track is evaluated at every integrator stage's track position, so the model
/// alone on it does not depend on the communication step (the track under the wheelsets is the
/// same function of time for any step).
#[test]
fn internal_track_does_not_depend_on_the_communication_step() {
    let run = |h: f64| {
        let p = Params {
            speed_mps: 250.0 / 3.6,
            k_ssx_n_per_m: 4e6,
            track: TrackSource::Internal {
                level: PsdLevel::High,
                seed: 4,
            },
            ..Params::default()
        };
        let mut b = Bogie::with_table(p, default_table()).unwrap();
        let mut v = Vec::new();
        run_closed_loop(&mut b, LinearDamper::None, h, 1.55, &|_| 0.0, &mut |o| {
            v.push((o.time_s, o.track_front_m, o.wheelset_front_lateral_m))
        })
        .unwrap();
        v
    };
    let (a, b) = (run(1e-4), run(1.55e-3));
    let (mut track_diff, mut motion_diff, mut motion_peak): (f64, f64, f64) = (0.0, 0.0, 0.0);
    for (k, s) in b.iter().enumerate().step_by(2) {
        let sa = a[31 * k / 2];
        assert!((sa.0 - s.0).abs() < 1e-9);
        track_diff = track_diff.max((sa.1 - s.1).abs());
        motion_diff = motion_diff.max((sa.2 - s.2).abs());
        motion_peak = motion_peak.max(s.2.abs());
    }
    println!("internal track, h 1e-4 vs 1.55e-3: track {track_diff:e} m, wheelset {motion_diff:e} m of {motion_peak:e} m");
    assert!(motion_peak > 5e-4, "the track moves the bogie");
    assert!(track_diff < 1e-12, "{track_diff}");
    assert!(motion_diff < 1e-3 * motion_peak, "{motion_diff}");
}

/// After a step the outputs for new damper forces come from the kept contact evaluation: bit
/// for bit what a full evaluation gives (a model whose state is set afresh has none kept).
#[test]
fn outputs_for_new_damper_forces_equal_a_full_evaluation() {
    for track in [
        TrackSource::None,
        TrackSource::Internal {
            level: PsdLevel::High,
            seed: 3,
        },
        TrackSource::External,
    ] {
        let p = Params {
            speed_mps: 300.0 / 3.6,
            initial_lateral_m: 4e-3,
            track,
            ..Params::default()
        };
        let mut b = Bogie::new(p).unwrap();
        let mut i = Inputs {
            damper_left_force_n: 1e3,
            damper_right_force_n: -2e3,
            track_lateral_m: 1e-3,
        };
        for _ in 0..300 {
            b.step(1e-3, &i).unwrap();
        }
        i.damper_left_force_n = -7.5e3;
        i.damper_right_force_n = 6e3;
        let kept = b.outputs(&i).unwrap();
        let mut fresh = b.clone();
        fresh.set_state(b.state()).unwrap();
        let full = fresh.outputs(&i).unwrap();
        assert_eq!(kept, full, "{track:?}");
        assert_eq!(kept.yaw_acc_radps2.to_bits(), full.yaw_acc_radps2.to_bits());
        assert_eq!(b.step(1e-3, &i).unwrap(), fresh.step(1e-3, &i).unwrap());
    }
}

/// The non-linear model's derailment limit is its contact table's range, as the coach's: a
/// table that stops short of the flange is refused, a start beyond the table is refused before
/// the first step, and a wheelset pushed past the table's end is a derailment there (the table
/// used to be extrapolated to a fixed 50 mm, 40 mm off the track with fmi2OK).
#[test]
fn the_contact_table_bounds_the_non_linear_model() {
    let nonlinear = Params {
        model: ModelKind::NonLinear,
        track: TrackSource::None,
        ..Params::default()
    };
    // a +-3 mm cone of 0.2 without flange
    let tread = GeometryTable::parse_csv(
        "y_m,delta_r_left_m,delta_r_right_m,tan_gamma_left,tan_gamma_right\n\
         -0.003,-0.0006,0.0006,0.05,0.05\n0.003,0.0006,-0.0006,0.05,0.05\n",
        "tread.csv",
    )
    .unwrap();
    let e = Bogie::with_table(nonlinear.clone(), tread.clone()).unwrap_err();
    assert!(matches!(e, ModelError::FlangeNotCovered(_)), "{e}");
    assert!(e.to_string().contains("does not cover the flange"), "{e}");
    // a table reaching 1 m out, or with a rolling radius of -0.5 m, fits no wheelset
    for (text, why) in [
        (
            "-1.0,-0.0006,0.0006,0.05,0.05\n0.003,0.0006,-0.0006,0.05,0.05\n",
            "reaches 1000.0 mm",
        ),
        (
            "-0.003,-0.96,0.0006,0.05,0.05\n0.003,0.0006,-0.0006,0.05,0.05\n",
            "rolling radius of -0.5000 m",
        ),
    ] {
        let t = GeometryTable::parse_csv(
            &format!("y_m,delta_r_left_m,delta_r_right_m,tan_gamma_left,tan_gamma_right\n{text}"),
            "bad.csv",
        )
        .unwrap();
        let e = Bogie::with_table(nonlinear.clone(), t.clone()).unwrap_err();
        assert!(matches!(e, ModelError::Contact(_)), "{e}");
        assert!(e.to_string().contains(why), "{e}");
        // the linear model, which uses no table, runs
        let linear = Params {
            model: ModelKind::Linear,
            ..nonlinear.clone()
        };
        assert!(Bogie::with_table(linear, t).is_ok(), "{why}");
    }
    // the linear model does not use the table
    let linear = Params {
        model: ModelKind::Linear,
        ..nonlinear.clone()
    };
    assert!(Bogie::with_table(linear, tread).is_ok());

    let table = default_table();
    let (lo, hi) = table.y_range();
    let e = Bogie::with_table(
        Params {
            initial_lateral_m: hi + 1e-3,
            initial_yaw_rad: 0.0,
            ..nonlinear.clone()
        },
        table.clone(),
    )
    .unwrap_err();
    assert!(matches!(e, ModelError::StartsDerailed { .. }), "{e}");
    assert!(
        e.to_string().contains("initial.lateral_displacement"),
        "{e}"
    );

    let mut b = Bogie::with_table(nonlinear, table).unwrap();
    let push = Inputs {
        damper_left_force_n: 2e5,
        damper_right_force_n: -2e5,
        ..Inputs::default()
    };
    let mut last = None;
    for _ in 0..2000 {
        match b.step(1e-3, &push) {
            Ok(o) => {
                for y in [o.wheelset_front_rel_track_m, o.wheelset_rear_rel_track_m] {
                    assert!((lo..=hi).contains(&y), "{y} with fmi2OK");
                }
            }
            Err(e) => {
                last = Some(e);
                break;
            }
        }
    }
    let e = last.expect("pushed past the flange");
    assert!(matches!(e, StepError::Derailed { .. }), "{e}");
    assert!(e.to_string().contains("contact table's range"), "{e}");
}

/// A stiff secondary suspension shortens the internal step instead of diverging: 1e11 N/m
/// (laterally or longitudinally) gave a "derailment" at the first step, the sub-step following
/// only the contact and creep. Stiffer than any step can follow is refused, naming it.
#[test]
fn a_stiff_suspension_shortens_the_internal_step() {
    let base = Bogie::new(Params::default()).unwrap().substep_s();
    for stiff in [
        Params {
            k_ssy_n_per_m: 1e11,
            ..Params::default()
        },
        Params {
            k_ssx_n_per_m: 1e11,
            ..Params::default()
        },
    ] {
        let mut b = Bogie::new(Params {
            initial_lateral_m: 1e-3,
            ..stiff
        })
        .unwrap();
        assert!(b.substep_s() < base / 2.0, "{} s", b.substep_s());
        let mut peak = 0.0f64;
        for _ in 0..200 {
            let o = b.step(1e-3, &Inputs::default()).unwrap();
            peak = peak.max(o.wheelset_front_rel_track_m.abs());
        }
        assert!(peak < 0.02, "{peak} m");
    }
    let e = Bogie::new(Params {
        k_ssy_n_per_m: 1e25,
        ..Params::default()
    })
    .unwrap_err();
    assert!(matches!(e, ModelError::TooStiff(_)), "{e}");
    assert!(e.to_string().contains("k_ssy_n_per_m"), "{e}");
}
