//! End-to-end tests of the default stability study on the coach (`master study --quick`: four
//! yaw dampers and four controllers on RailVehicle; 260-420 km/h in 40 km/h steps, one track
//! seed, 12 s runs, bisection to 5 km/h), checked against the seed's full-vehicle targets
//! (REFERENCE.md R8-R17).
//!
//! The study runs once per test process (shared by all tests). Needs `dist/` (built by
//! `cargo run --release -p model-description --bin package-fmus`); run in release.
//! Where the coach does not reach the seed's number the measured value is asserted with a
//! stated tolerance and the reason is given (REPORT.md "Where we differ").

// test helpers outside #[test] fns: allowed like the other end-to-end test files
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use rail_study::study::report::ActuatorBound;
use rail_study::study::run::scenario;
use rail_study::study::{Critical, VehicleModel};
use tests::study::SharedStudy;

static STUDY: SharedStudy = SharedStudy::new(
    VehicleModel::Coach,
    &[
        "rms_vs_speed.svg",
        "carbody_vs_speed.svg",
        "comfort_vs_speed.svg",
    ],
    "## Car body",
);

#[test]
fn no_run_failed_and_every_run_has_car_body_numbers() {
    let r = STUDY.results();
    assert!(r.failures.is_empty(), "failed runs: {:?}", r.failures);
    for c in &r.configs {
        for p in &c.sweep {
            let (cb, ny) = (p.carbody_rms().unwrap(), p.comfort().unwrap());
            assert!(
                cb > 0.0 && cb < 3.0,
                "{} {}: car-body rms {cb}",
                c.id,
                p.speed_kmh
            );
            assert!(ny > 0.1 && ny < 6.0, "{} {}: N_y {ny}", c.id, p.speed_kmh);
        }
    }
}

/// R8/R17: passive limit exceeded at about 280-300 km/h. Measured on the quick grid (seed 1,
/// 12 s runs, max over the four axle-box pairs): met at 300 km/h, exceeded at 305 km/h. The
/// test accepts 280-310 km/h: the seed's range plus two 5 km/h bisection steps (seed 2 or
/// longer runs move the first exceedance by one step, tests/tests/vehicle_en14363.rs).
#[test]
fn passive_critical_speed_280_to_310() {
    let k = STUDY.critical("passive");
    match k {
        Critical::Between {
            stable_kmh,
            unstable_kmh,
        } => assert!(
            stable_kmh >= 280.0 && unstable_kmh <= 310.0,
            "passive {}",
            k.describe()
        ),
        other => panic!("passive: no bracket, {}", other.describe()),
    }
}

/// R9: MPPT raises the critical speed by about +70 km/h (accepted +40..+100). NOT MET on the
/// high side (docs/VALIDATION.md R9, full study +105..+140): the lower bound is asserted for
/// both weightings, and the measured gain is pinned (stable to the end of the quick grid,
/// 420 km/h, so at least 420 - passive, more than +100); nothing here asserts +100. A
/// nearly closed valve gives about 330 kNs/m at 4 Hz against 100 for the 30 % passive damper,
/// and our coach's critical speed rises more steeply with yaw damping than the seed's (the
/// ideal 210 kNs/m damper keeps it within the limit at 380 km/h, the seed's exceeds it, Table
/// 4-3); a 10 MN/m damper mounting (MPE 2019) leaves MPPT stable through 420 km/h too
/// (docs/VALIDATION.md).
#[test]
fn mppt_raises_the_critical_speed() {
    let p = STUDY.vcr("passive");
    for id in ["mppt1", "mppt2"] {
        let gain = STUDY.vcr(id) - p;
        assert!(
            gain >= 40.0,
            "{id}: gain {gain} km/h ({})",
            STUDY.critical(id).describe()
        );
        // pinned: stable through the quick grid
        assert!(
            matches!(STUDY.critical(id), Critical::Above { .. }),
            "{id}: {} (was stable to 420 km/h): update REPORT/tests",
            STUDY.critical(id).describe()
        );
    }
}

/// R9, why the gain is large: with MPPT the yaw dampers' stroke amplitude (sqrt(2) x std of
/// the elongation, largest of the four) stays within 2 mm up to 380 km/h, where the closed
/// valve linearised by its first harmonic leaves the linear coach without any stability
/// boundary below 716 km/h (`crates/rail-study/tests/analysis_commands.rs`); the passive coach
/// hunts with strokes above 3.5 mm. Measured on the quick study at 380 km/h: passive 4.6 mm,
/// MPPT1 1.0 mm, MPPT2 1.6 mm.
#[test]
fn mppt_keeps_the_damper_strokes_where_a_closed_valve_has_no_stability_boundary() {
    let stroke = |id: &str, v: f64| {
        STUDY
            .results()
            .config(id)
            .and_then(|c| c.sweep.iter().find(|p| (p.speed_kmh - v).abs() < 1e-6))
            .and_then(|p| p.damper_stroke())
            .unwrap_or_else(|| panic!("{id} at {v} km/h: no damper stroke"))
    };
    for v in [300.0, 340.0, 380.0] {
        for id in ["mppt1", "mppt2"] {
            let s = stroke(id, v);
            assert!(s < 2e-3, "{id} at {v} km/h: stroke {:.2} mm", s * 1e3);
        }
    }
    let s = stroke("passive", 380.0);
    assert!(s > 3.5e-3, "passive at 380 km/h: stroke {:.2} mm", s * 1e3);
}

/// R11: the sky-hook with an ideal valve is within 30 km/h of MPPT. The textbook sky-hook of
/// (3.6) hooks the bogie to the sky: x' is the frame attachment point's absolute velocity, x0'
/// the car body's. The car body barely moves at the 4 Hz hunting frequency, so the condition
/// x' (x' - x0') is mostly positive and the damper mostly closed, as MPPT1 keeps it (quick
/// study: both stable through 420 km/h, passive 305). Asserted: within 30 km/h of the lower
/// MPPT, at least +40 km/h over passive, and the valve mostly closed at 300 km/h (mean command
/// over the last 3 s: measured 0.87 V of 10 V).
#[test]
fn textbook_skyhook_about_like_mppt() {
    let p = STUDY.vcr("passive");
    let m = STUDY.vcr("mppt1").min(STUDY.vcr("mppt2"));
    for id in ["skyhook_onoff", "skyhook_continuous"] {
        let s = STUDY.vcr(id);
        assert!(
            (s - m).abs() <= 30.0,
            "{id}: {s} km/h vs MPPT {m} ({})",
            STUDY.critical(id).describe()
        );
        assert!(s - p >= 40.0, "{id}: {s} km/h vs passive {p}");
    }
    let h = STUDY.scenario_metrics(&scenario::history("skyhook_onoff"));
    let mean = h.tail_command_v.expect("sky-hook command recorded");
    assert!(mean < 3.0, "sky-hook at 300 km/h: mean command {mean:.2} V");
}

/// R11/R12, the seed's accelerometer-based on/off sky-hook (x' from the frame acceleration over
/// the axle box, as on the bogie): with the ideal valve it raises the critical speed above
/// passive (quick study: 330 vs 305 km/h) but stays well below MPPT (> 420); the slow valve
/// takes that gain away (285 km/h, at or below passive). Its x' is the frame's lateral motion,
/// in quadrature with the damper's elongation, so it switches twice per hunting cycle.
#[test]
fn accelerometer_skyhook_between_passive_and_mppt_and_broken_by_the_slow_valve() {
    let p = STUDY.vcr("passive");
    let m = STUDY.vcr("mppt1").min(STUDY.vcr("mppt2"));
    let ideal = STUDY.vcr("skyhook_accel_onoff");
    let slow = STUDY.vcr("skyhook_accel_onoff_slow");
    assert!(
        (10.0..=50.0).contains(&(ideal - p)),
        "ideal valve: {ideal} km/h vs passive {p} (measured +25)"
    );
    assert!(m - ideal > 50.0, "ideal valve: {ideal} vs MPPT {m}");
    assert!(
        slow <= p + 5.0 && ideal - slow >= 20.0,
        "slow valve: {slow} km/h vs passive {p}, ideal {ideal} (measured 285)"
    );
    // and the textbook sky-hook, mostly closed, stays above it
    assert!(STUDY.vcr("skyhook_onoff") > ideal + 20.0);
}

/// R12: the slow valve (lag 0.15 s) does not break MPPT: from an 8 V command and a 3 mm
/// perturbation at 260 km/h on ideal track the coach comes to rest, and in the sweep the
/// slow-valve MPPT keeps its gain over passive. The seed's accelerometer sky-hook loses its
/// gain with the slow valve (previous test). The textbook sky-hook is mostly closed on the
/// coach, so the valve lag does not matter to it: with the slow valve it keeps its gain and
/// damps the 260 km/h perturbation out (measured: > 420 km/h, 0.00 mm).
#[test]
fn slow_valve_keeps_mppt_and_the_mostly_closed_skyhook() {
    let p = STUDY.vcr("passive");
    for id in [
        "mppt1_slow",
        "mppt2_slow",
        "skyhook_onoff_slow",
        "skyhook_continuous_slow",
    ] {
        let m = STUDY.scenario_metrics(&scenario::hil(id));
        assert!(
            m.tail_amplitude_m < 1e-3,
            "{id}: final amplitude {:.2} mm",
            m.tail_amplitude_m * 1e3
        );
        assert!(
            STUDY.vcr(id) >= p + 40.0,
            "{id}: {}",
            STUDY.critical(id).describe()
        );
    }
}

/// R13: full-active IDF (c_v = 330 kNs/m) stable to at least 380 km/h (measured: through the
/// quick grid, 420 km/h), and within the limit in the c_v run at 380 km/h.
#[test]
fn full_active_stable_to_380() {
    let r = STUDY.results();
    assert!(
        STUDY.vcr("full_active") >= 380.0,
        "{}",
        STUDY.critical("full_active").describe()
    );
    let cv330 =
        r.cv.iter()
            .find(|c| c.c_v_nspm.is_some_and(|v| (v - 330e3).abs() < 1.0))
            .and_then(|c| c.metrics.as_ref())
            .expect("c_v = 330 kNs/m run");
    assert!(cv330.rms() < r.limit_mps2, "rms {}", cv330.rms());
}

/// R14 (Table 4-3) at 380 km/h on the quick study's one track seed: the rms acceleration falls
/// with c_v (asserted, strictly). The seed's peak force does not fall (20.4 -> 24.6 kN). On seed
/// 1 alone the coach's peak rises from 210 to 270 kNs/m and falls above (full study: 22.3,
/// 24.4, 22.4, 19.0 kN), since a stiffer damper also shrinks the bogie's yaw relative to the car
/// body, the motion it reacts to. What sets each peak is the smaller of the controllers' peak
/// reference c_v v and the actuator's force bound (100 bar on 25.16 cm^2, 25.2 kN): on seed 1
/// the references peak at 32.3, 35.8, 30.9 and 21.4 kN, so the first three are bound-limited and
/// only the 390 one follows c_v v. Over the full study's two seeds the reference exceeds the
/// bound at every c_v and the peak does not fall (tests/tests/vehicle_cv_table.rs). Asserted
/// here: every peak in the seed's span 20-25 kN +-3 kN, seed 1's pinned shape (largest at 270
/// kNs/m, the 390 value at most the 210 one + 1 kN), and every peak at least 80 % of
/// min(peak reference, bound) and at most the bound.
#[test]
fn cv_sensitivity_of_the_full_active_damper() {
    let bound_n = ActuatorBound::of_default_actuator().force_n;
    let mut rows: Vec<(f64, f64, f64)> = Vec::new();
    for c in &STUDY.results().cv {
        let m = c.metrics.as_ref().expect("c_v run failed");
        let c_v = c.c_v_nspm.unwrap_or(0.0);
        let reference = m
            .peak_reference_force_n
            .expect("the full-active runs record the controllers' reference forces");
        let set_by = reference.min(bound_n);
        assert!(
            m.peak_force_n <= bound_n && m.peak_force_n >= 0.8 * set_by,
            "c_v {c_v}: F_max {} N against min(reference {reference} N, bound {bound_n} N)",
            m.peak_force_n
        );
        rows.push((c_v, m.rms(), m.peak_force_n));
    }
    assert_eq!(rows.len(), 4);
    assert!(
        rows.windows(2).all(|w| w[1].1 < w[0].1),
        "rms vs c_v: {rows:?}"
    );
    for (c_v, _, f) in &rows {
        assert!((17e3..=28e3).contains(f), "c_v {c_v}: F_max {f} N");
    }
    let fmax = |i: usize| rows[i].2;
    assert!(fmax(1) >= fmax(0) && fmax(1) >= fmax(3), "{rows:?}");
    assert!(fmax(3) <= fmax(0) + 1e3, "{rows:?}");
}

/// R16: from a 3 mm perturbation on ideal track the passive coach decays at 240 km/h, keeps a
/// small limit cycle at 280 km/h (measured 4.3 mm) and a 6-7 mm flange-contact one at 300
/// km/h (measured 6.6 mm).
#[test]
fn perturbation_runs_of_the_passive_coach() {
    let amp = |v: f64| {
        STUDY
            .results()
            .perturbation
            .iter()
            .find(|p| (p.speed_kmh - v).abs() < 0.5)
            .and_then(|p| p.metrics.as_ref())
            .map(|m| m.tail_amplitude_m)
            .expect("perturbation run")
    };
    let (a240, a280, a300) = (amp(240.0), amp(280.0), amp(300.0));
    assert!(a240 < 0.5e-3, "240 km/h should decay: {a240}");
    assert!((2e-3..6e-3).contains(&a280), "280 km/h: {a280}");
    assert!((6e-3..=7e-3).contains(&a300), "300 km/h: {a300}");
}

/// What the dampers transmit to the car body (the seed's future work): at 300 km/h, where the
/// passive coach is close to its limit, MPPT and the full-active damper keep the car body's
/// floor acceleration well below the passive one (measured 0.21-0.28 against 0.64 m/s^2),
/// and the comfort index follows (measured N_y 0.95-1.11 against 1.63).
#[test]
fn active_dampers_calm_the_car_body() {
    let at = |id: &str| {
        let p = STUDY
            .results()
            .config(id)
            .and_then(|c| c.sweep.iter().find(|p| (p.speed_kmh - 300.0).abs() < 1e-6))
            .unwrap_or_else(|| panic!("{id} at 300 km/h"));
        (p.carbody_rms().unwrap(), p.comfort().unwrap())
    };
    let (cb_p, ny_p) = at("passive");
    for id in ["mppt1", "mppt2", "full_active"] {
        let (cb, ny) = at(id);
        assert!(cb < 0.7 * cb_p, "{id}: car-body rms {cb} vs passive {cb_p}");
        assert!(ny < ny_p, "{id}: N_y {ny} vs passive {ny_p}");
    }
}
