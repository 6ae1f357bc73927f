//! Benchmarks (speed is never asserted in tests): EN 14363 assessment of a 60 s signal, and
//! a run of the example FMUs if dist/ exists.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)] // test code

use criterion::{criterion_group, criterion_main, Criterion};
use master::en14363::{assess_lateral_acceleration, StabilitySettings};

fn assessment(c: &mut Criterion) {
    let fs = 500.0;
    let x: Vec<f64> = (0..(60.0 * fs) as usize)
        .map(|i| {
            let t = i as f64 / fs;
            4.0 * (2.0 * std::f64::consts::PI * 3.5 * t).sin()
                + (2.0 * std::f64::consts::PI * 17.0 * t).sin()
        })
        .collect();
    c.bench_function("en14363 assess 60 s @ 500 Hz", |b| {
        b.iter(|| assess_lateral_acceleration(&x, fs, 80.0, 6.1, &StabilitySettings::default()))
    });
}

fn fmu_run(c: &mut Criterion) {
    let dist = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../dist");
    if !dist.join("MassSpring.fmu").exists() {
        eprintln!("dist/ not built: skipping the FMU benchmark");
        return;
    }
    let json = format!(
        r#"{{"instances": [{{"name": "ms", "fmu": "{}"}}, {{"name": "sdm", "fmu": "{}"}}],
            "connections": [{{"from": "ms.position", "to": "sdm.input_position"}},
                            {{"from": "ms.velocity", "to": "sdm.input_velocity"}},
                            {{"from": "sdm.coupling_force", "to": "ms.force"}}],
            "stop_time": 1.0, "step": 0.001}}"#,
        dist.join("MassSpring.fmu").display(),
        dist.join("SpringDamperMass.fmu").display()
    );
    let Ok(sys) = master::system::LoadedSystem::from_json_str(&json, &dist, "bench") else {
        return;
    };
    c.bench_function("two-mass co-simulation, 1000 steps", |b| {
        b.iter(|| sys.run(&master::coupling::RunOptions::default()))
    });
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10);
    targets = assessment, fmu_run
}
criterion_main!(benches);
