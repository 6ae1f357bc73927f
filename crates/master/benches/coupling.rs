//! Benchmark (speed is never asserted in tests): a run of the example FMUs if dist/ exists.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)] // test code

use criterion::{criterion_group, criterion_main, Criterion};

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
    targets = fmu_run
}
criterion_main!(benches);
