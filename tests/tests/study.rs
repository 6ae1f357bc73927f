//! End-to-end tests of the stability study (`master study --quick`) with the packaged FMUs:
//! the reduced sweep (240-400 km/h in 40 km/h steps, one track seed, bisection to 10 km/h),
//! the perturbation runs, the c_v sensitivity and the MPPT / slow-valve scenarios, checked
//! against REFERENCE.md R7-R14.
//!
//! The study runs once per test process (shared by all tests). Needs `dist/` (built by
//! `cargo run --release -p model-description --bin package-fmus`); run in release.
//! Where our physics cannot reach the seed's number the measured value is pinned with a
//! comment and the qualitative ordering is asserted instead (see REPORT.md).

use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::sync::OnceLock;

use master::study::run::scenario;
use master::study::{run_study, Critical, Sources, StudyOptions, StudyResults, StudySettings};

static CANCEL: AtomicBool = AtomicBool::new(false);
static RESULTS: OnceLock<Result<StudyResults, String>> = OnceLock::new();

fn dist() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../dist")
}

fn results() -> &'static StudyResults {
    let r = RESULTS.get_or_init(|| {
        let fmus = std::env::var_os("STUDY_FMUS").map_or_else(dist, PathBuf::from);
        if !fmus.join("Bogie2Dof.fmu").is_file() {
            return Err(format!(
                "{} has no Bogie2Dof.fmu: build the FMUs first with \
                 `cargo run --release -p model-description --bin package-fmus`",
                fmus.display()
            ));
        }
        let out = tempfile::tempdir().map_err(|e| e.to_string())?;
        let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
        let opts = StudyOptions {
            sources: Sources {
                fmus,
                systems: None,
            },
            out: out.path().to_path_buf(),
            threads,
            progress: false,
            cancel: &CANCEL,
        };
        let start = std::time::Instant::now();
        let r = run_study(&StudySettings::quick(), &opts).map_err(|e| e.to_string())?;
        // the report must be writable from these results (plots need the kept runs)
        let timing = master::study::Timing {
            wall_s: start.elapsed().as_secs_f64(),
            threads,
        };
        let md =
            master::study::write_outputs(&r, out.path(), &timing).map_err(|e| e.to_string())?;
        if !md.contains("Critical speeds") || !out.path().join("rms_vs_speed.svg").is_file() {
            return Err("report or rms plot missing".into());
        }
        eprintln!("{md}");
        Ok(r)
    });
    match r {
        Ok(r) => r,
        Err(e) => panic!("the quick study did not run: {e}"),
    }
}

fn critical(id: &str) -> Critical {
    let c = results()
        .config(id)
        .unwrap_or_else(|| panic!("configuration {id} missing"));
    c.critical
        .unwrap_or_else(|| panic!("{id}: no critical speed (empty curve)"))
}

/// The critical speed, or the end of the range (400) when stable throughout.
fn vcr(id: &str) -> f64 {
    critical(id).at_least_kmh()
}

fn scenario_metrics(name: &str) -> &'static master::study::metrics::RunMetrics {
    let r = results()
        .scenario(name)
        .unwrap_or_else(|| panic!("scenario {name} missing"));
    r.metrics
        .as_ref()
        .unwrap_or_else(|| panic!("scenario {name} failed: {:?}", r.error))
}

#[test]
fn no_run_failed() {
    let r = results();
    assert!(r.failures.is_empty(), "failed runs: {:?}", r.failures);
    assert!(r.simulated_s > 0.0);
}

/// R8: passive limit exceeded at about 280-300 km/h; accepted 260-320 km/h. The quick grid
/// brackets to 10 km/h: the first unstable speed must lie in (260, 320].
#[test]
fn r8_passive_critical_speed() {
    let k = critical("passive");
    let v = k.speed_kmh().unwrap_or(f64::INFINITY);
    assert!(
        (260.0..=320.0).contains(&v),
        "passive critical speed {} not in 260-320 km/h",
        k.describe()
    );
    if let Critical::Between { stable_kmh, .. } = k {
        assert!(stable_kmh >= 250.0, "{}", k.describe());
    }
}

/// R9: MPPT (both weightings) raises the critical speed by about 70 km/h; accepted 50-90
/// (+-10 km/h bracket of the quick study on each side).
#[test]
fn r9_mppt_raises_critical_speed() {
    let p = vcr("passive");
    for id in ["mppt1", "mppt2"] {
        let gain = vcr(id) - p;
        assert!(
            (40.0..=100.0).contains(&gain),
            "{id}: gain over passive {gain} km/h ({} vs {}) not about 50-90 km/h",
            critical(id).describe(),
            critical("passive").describe()
        );
    }
}

/// R10: MPPT1 keeps the valve nearly closed once stable, MPPT2 re-opens it part way, from a
/// closed start at a stable speed (Fig. 4.16) and from an open start at 260 km/h (Fig. 5.22).
#[test]
fn r10_mppt1_stays_closed_mppt2_reopens() {
    for (m1, m2) in [
        (scenario::mppt_low("mppt1"), scenario::mppt_low("mppt2")),
        (scenario::hil("mppt1_slow"), scenario::hil("mppt2_slow")),
    ] {
        let c1 = scenario_metrics(&m1).tail_command_v.unwrap_or(f64::NAN);
        let c2 = scenario_metrics(&m2).tail_command_v.unwrap_or(f64::NAN);
        assert!(
            c1 <= 2.0,
            "{m1}: MPPT1 final command {c1} V, expected nearly closed (<= 2 V)"
        );
        assert!(
            c2 >= c1 + 1.0 && c2 < 10.0,
            "{m2}: MPPT2 final command {c2} V should re-open part way above MPPT1's {c1} V"
        );
    }
}

/// R11: sky-hook with an ideal valve gives about the same curve as MPPT: critical speeds
/// within 20 km/h.
#[test]
fn r11_ideal_skyhook_close_to_mppt() {
    let m = vcr("mppt2");
    for id in ["skyhook_onoff", "skyhook_continuous"] {
        let s = vcr(id);
        assert!(
            (s - m).abs() <= 20.0,
            "{id}: critical {} vs MPPT2 {}",
            critical(id).describe(),
            critical("mppt2").describe()
        );
    }
}

/// R12: with the slow valve at 260 km/h sky-hook leaves a wheelset oscillation of at least
/// 4 mm (seed: +-6 mm) while MPPT stabilises.
#[test]
fn r12_slow_valve_breaks_skyhook_not_mppt() {
    let lim = results().limit_mps2;
    for id in ["skyhook_onoff_slow", "skyhook_continuous_slow"] {
        let m = scenario_metrics(&scenario::hil(id));
        assert!(
            m.tail_amplitude_m >= 4e-3,
            "{id}: final wheelset amplitude {:.2} mm, expected >= 4 mm",
            m.tail_amplitude_m * 1e3
        );
    }
    for id in ["mppt1_slow", "mppt2_slow"] {
        let m = scenario_metrics(&scenario::hil(id));
        assert!(
            m.tail_amplitude_m < 2e-3,
            "{id}: final wheelset amplitude {:.2} mm, expected stabilised (< 2 mm)",
            m.tail_amplitude_m * 1e3
        );
        assert!(m.rms() < lim, "{id}: rms {} over the limit", m.rms());
    }
    // and in the sweep: the slow valve costs sky-hook more than MPPT
    let loss_sky = vcr("skyhook_onoff") - vcr("skyhook_onoff_slow");
    let loss_mppt = vcr("mppt2") - vcr("mppt2_slow");
    assert!(
        loss_sky > loss_mppt,
        "slow valve: sky-hook loses {loss_sky} km/h, MPPT2 {loss_mppt} km/h"
    );
}

/// R13: the full-active IDF damper (c_v = 330 kNs/m) is stable at 380 km/h and the ordering
/// passive < semi-active <= full-active holds for the critical speeds.
#[test]
fn r13_full_active_stable_at_380_and_ordering() {
    let r = results();
    let cv330 =
        r.cv.iter()
            .find(|c| c.c_v_nspm.is_some_and(|v| (v - 330e3).abs() < 1.0))
            .and_then(|c| c.metrics.as_ref())
            .expect("c_v = 330 kNs/m run at 380 km/h");
    assert!(
        cv330.rms() < r.limit_mps2,
        "full-active at 380 km/h: rms {} over the limit",
        cv330.rms()
    );
    assert!(
        vcr("full_active") > 380.0,
        "{}",
        critical("full_active").describe()
    );
    let p = vcr("passive");
    let f = vcr("full_active");
    for id in ["mppt1", "mppt2", "skyhook_onoff", "skyhook_continuous"] {
        let s = vcr(id);
        assert!(
            p < s && s <= f,
            "ordering: passive {p} < {id} {s} <= full-active {f}"
        );
    }
}

/// R14 (Table 4-3): at 380 km/h the rms acceleration falls and the peak force rises with c_v.
#[test]
fn r14_cv_trends() {
    let r = results();
    let rows: Vec<(f64, f64, f64)> =
        r.cv.iter()
            .map(|c| {
                let m = c.metrics.as_ref().expect("c_v run failed");
                (c.c_v_nspm.unwrap_or(0.0), m.rms(), m.peak_force_n)
            })
            .collect();
    assert_eq!(rows.len(), 4);
    let (first, last) = (rows[0], rows[3]);
    assert!(
        last.1 < first.1,
        "rms acceleration should fall with c_v: {rows:?}"
    );
    assert!(
        last.2 > first.2,
        "peak force should rise with c_v: {rows:?}"
    );
    // mostly monotone: at most one inversion between neighbours
    let inversions = rows.windows(2).filter(|w| w[1].1 > w[0].1).count();
    assert!(inversions <= 1, "rms vs c_v: {rows:?}");
}

/// R7: initial perturbation of the passive vehicle on ideal track: decays at 220 km/h, a
/// small limit cycle without flange contact at 285, a large one (flange, ~6 mm) at 320.
#[test]
fn r7_perturbation_runs() {
    let r = results();
    let amp = |v: f64| {
        r.perturbation
            .iter()
            .find(|p| (p.speed_kmh - v).abs() < 0.5)
            .and_then(|p| p.metrics.as_ref())
            .map(|m| m.tail_amplitude_m)
            .expect("perturbation run")
    };
    let (a220, a285, a320) = (amp(220.0), amp(285.0), amp(320.0));
    assert!(a220 < 0.5e-3, "220 km/h should decay: {a220}");
    assert!(a285 > a220 && a285 < 6e-3, "285 km/h: {a285}");
    assert!(a320 > 5e-3 && a320 > a285, "320 km/h: {a320}");
}
