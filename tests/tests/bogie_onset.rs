//! The linear bogie FMU coupled in our master to two passive damper FMUs (the real
//! pressure-state damper, not its linear fit) starts hunting at the speed the eigen-analysis
//! predicts when it represents that damper the way the coupled system sees it, within 10 km/h.
//!
//! Time domain: linear bogie model, no track irregularity, 1 mm initial lateral displacement;
//! the growth rate of the wheelset displacement envelope is measured over 3..9 s and its sign
//! change found by bisection on speed.
//!
//! The damper is non-linear (cube-root velocity law, (3.43)): its equivalent damping rises as
//! the stroke falls (at 3.5 Hz: 102 kNs/m at 1 mm, 65 kNs/m at 3 mm). So the eigen-analysis
//! takes the damper's k_eq(f), c_eq(f) measured on the damper model at the stroke amplitude the
//! coupled run shows at onset (frequency-dependent, evaluated at the hunting mode's own
//! frequency). With the 1 mm Maxwell fit (`calibration::passive_damper`, the root-locus default)
//! the eigen critical speed is the calibrated 270 km/h; both numbers are printed.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::path::PathBuf;

use fmu_bogie2dof::{calibration, eigen, Params};
use fmu_damper::characterise::equivalent_stiffness_damping;
use fmu_damper::SemiActiveParams;
use master::coupling::RunOptions;
use master::system::LoadedSystem;

fn dist() -> PathBuf {
    let d = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../dist");
    assert!(
        d.join("Bogie2Dof.fmu").exists(),
        "dist/Bogie2Dof.fmu missing: run scripts/test.sh (it packages the FMUs first)"
    );
    d
}

/// Envelope growth rate [1/s] of the front wheelset displacement at `speed_kmh`, and the
/// left damper's stroke amplitude over the measuring interval 3..9 s.
fn run(speed_kmh: f64, initial_m: f64) -> (f64, f64) {
    let d = dist();
    let json = format!(
        r#"{{
  "instances": [
    {{"name": "bogie", "fmu": "Bogie2Dof.fmu", "parameters": {{
        "vehicle.speed": {v}, "contact.model": 0, "track.source": 0,
        "initial.lateral_displacement": {y0}, "initial.yaw_angle": 0.0}}}},
    {{"name": "dl", "fmu": "PassiveYawDamper.fmu"}},
    {{"name": "dr", "fmu": "PassiveYawDamper.fmu"}}
  ],
  "connections": [
    {{"from": "bogie.damper_left.elongation", "to": "dl.damper.elongation"}},
    {{"from": "bogie.damper_left.elongation_velocity", "to": "dl.damper.elongation_velocity"}},
    {{"from": "dl.damper.force", "to": "bogie.damper_left.force"}},
    {{"from": "bogie.damper_right.elongation", "to": "dr.damper.elongation"}},
    {{"from": "bogie.damper_right.elongation_velocity", "to": "dr.damper.elongation_velocity"}},
    {{"from": "dr.damper.force", "to": "bogie.damper_right.force"}}
  ],
  "stop_time": 9.0, "step": 0.001,
  "record": ["bogie.wheelset_front.lateral_displacement", "bogie.damper_left.elongation"]
}}"#,
        v = speed_kmh / 3.6,
        y0 = initial_m
    );
    let sys = LoadedSystem::from_json_str(&json, &d, "onset.json").unwrap();
    let out = match sys.run(&RunOptions::default()) {
        Ok(out) => out,
        // Far above the critical speed the linear model grows until the bogie FMU stops the run
        // in a step (wheelset beyond the flange limit): that is growth, not a test failure. Any
        // other failure (loading, start values, the dampers) is.
        Err(e)
            if e.to_string()
                .contains("instance 'bogie': fmi2DoStep failed with fmi2Error") =>
        {
            eprintln!("{speed_kmh:.1} km/h: run stopped by the bogie ({e}): growing");
            return (f64::INFINITY, f64::NAN);
        }
        Err(e) => panic!("{speed_kmh} km/h: {e}"),
    };
    let t = out.column("time").unwrap();
    let y = out
        .column("bogie.wheelset_front.lateral_displacement")
        .unwrap();
    let e = out.column("bogie.damper_left.elongation").unwrap();
    let stroke = t
        .iter()
        .zip(&e)
        .filter(|(ti, _)| **ti >= 3.0)
        .map(|(_, ei)| ei.abs())
        .fold(0.0, f64::max);
    // Peak of |y| in 1 s windows; least-squares slope of ln(peak) over 3..9 s.
    let mut pts = Vec::new();
    for w in 3..9 {
        let peak = t
            .iter()
            .zip(&y)
            .filter(|(ti, _)| **ti >= w as f64 && **ti < (w + 1) as f64)
            .map(|(_, yi)| yi.abs())
            .fold(0.0, f64::max);
        pts.push((w as f64 + 0.5, peak.max(1e-15).ln()));
    }
    let n = pts.len() as f64;
    let (sx, sy) = pts.iter().fold((0.0, 0.0), |a, p| (a.0 + p.0, a.1 + p.1));
    let (mx, my) = (sx / n, sy / n);
    let num: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let den: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    (num / den, stroke)
}

fn growth_rate(speed_kmh: f64, initial_m: f64) -> f64 {
    run(speed_kmh, initial_m).0
}

#[test]
fn eigenvalue_critical_speed_matches_coupled_onset_with_the_damper_fmu() {
    // Initial lateral displacements of 3 and 8 mm give damper strokes of about 1.3 and 3.2 mm
    // near onset. (From 1 mm the stroke is only 0.1 mm; there the damper's first-harmonic
    // characterisation, dominated by the laminar orifice region, predicts 387 km/h while the
    // coupled run starts hunting at 286 km/h: an open point, see docs/VALIDATION.md.)
    for initial_m in [0.003, 0.008] {
        check_onset(initial_m);
    }
}

fn check_onset(initial_m: f64) {
    let (mut lo, mut hi) = (200.0, 340.0);
    assert!(growth_rate(lo, initial_m) < 0.0, "must decay at {lo} km/h");
    assert!(growth_rate(hi, initial_m) > 0.0, "must grow at {hi} km/h");
    while hi - lo > 2.0 {
        let mid = 0.5 * (lo + hi);
        if growth_rate(mid, initial_m) > 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    let onset = 0.5 * (lo + hi);
    let (_, stroke) = run(lo, initial_m);
    assert!(stroke.is_finite() && stroke > 0.0, "{stroke}");
    // The damper as the coupled system sees it near onset: k_eq, c_eq of the passive damper
    // model (30 % opening) at that stroke, 2..6 Hz.
    let damper = SemiActiveParams::passive_reference();
    let table: Vec<eigen::DamperPoint> = [2.0, 2.5, 3.0, 3.5, 4.0, 4.5, 5.0, 5.5, 6.0]
        .iter()
        .map(|&f| {
            let (k, c) = equivalent_stiffness_damping(&damper, 0.30, f, stroke).unwrap();
            eigen::DamperPoint {
                freq_hz: f,
                k_n_per_m: k,
                c_ns_per_m: c,
            }
        })
        .collect();
    let rep = eigen::DamperRepresentation::FrequencyDependent(table);
    eprintln!("stroke at {lo:.1} km/h: {:.4} mm", stroke * 1e3);
    let eig = eigen::critical_speed(&Params::default(), &rep, 150.0 / 3.6, 500.0 / 3.6).unwrap();
    let eig_1mm = eigen::critical_speed(
        &Params::default(),
        &calibration::passive_damper(),
        150.0 / 3.6,
        400.0 / 3.6,
    )
    .unwrap();
    eprintln!(
        "coupled time-domain onset {onset:.1} km/h (damper stroke {:.3} mm); eigenvalue critical \
         speed with the damper at that stroke {:.1} km/h ({:.2} Hz); with the 1 mm Maxwell fit {:.1} km/h",
        stroke * 1e3,
        eig.speed_kmh,
        eig.hunting.freq_hz,
        eig_1mm.speed_kmh
    );
    assert!(
        (onset - eig.speed_kmh).abs() <= 10.0,
        "eigen {:.1} vs coupled onset {onset:.1} km/h",
        eig.speed_kmh
    );
}
