//! Benchmark (speed is never asserted in tests): EN 14363 assessment of a 60 s signal.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)] // test code

use criterion::{criterion_group, criterion_main, Criterion};
use rail_study::en14363::{assess_lateral_acceleration, StabilitySettings};

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

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10);
    targets = assessment
}
criterion_main!(benches);
