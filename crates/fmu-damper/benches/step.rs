//! One communication step (h = 1 ms) of each model, driven by a 4 Hz, 3 mm stroke
//! (cycled over one period so every iteration sees a realistic state).

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use fmu_damper::{
    Actuator, ActuatorInputs, ActuatorModel, ActuatorParams, RodMode, SemiActiveDamper,
    SemiActiveInputs, SemiActiveParams, ValveParams,
};
use std::f64::consts::PI;

const H: f64 = 1e-3;
const N: usize = 250; // one 4 Hz period

fn stroke(k: usize) -> (f64, f64) {
    let w = 2.0 * PI * 4.0;
    let t = (k % N) as f64 * H;
    (3e-3 * (w * t).sin(), 3e-3 * w * (w * t).cos())
}

fn bench_semi(c: &mut Criterion, name: &str, params: SemiActiveParams, volts: f64) {
    let Ok(mut d) = SemiActiveDamper::new(params) else {
        return;
    };
    let mut k = 0usize;
    c.bench_function(name, |b| {
        b.iter(|| {
            let (x, v) = stroke(k);
            k += 1;
            let i = SemiActiveInputs {
                elongation_m: x,
                elongation_velocity_mps: v,
                valve_command_v: volts,
            };
            black_box(d.step(black_box(H), &i).ok())
        })
    });
}

fn bench_act(c: &mut Criterion, name: &str, params: ActuatorParams) {
    let Ok(mut a) = Actuator::new(params) else {
        return;
    };
    let mut k = 0usize;
    c.bench_function(name, |b| {
        b.iter(|| {
            let (x, v) = stroke(k);
            k += 1;
            let i = ActuatorInputs {
                spool_command_m: 0.6e-3 * (v / 0.075),
                load_force_n: 0.0,
                elongation_m: x,
                elongation_velocity_mps: v,
            };
            black_box(a.step(black_box(H), &i).ok())
        })
    });
}

fn benches(c: &mut Criterion) {
    bench_semi(
        c,
        "semi_active_ideal_valve_step_1ms",
        SemiActiveParams::default(),
        3.0,
    );
    bench_semi(
        c,
        "semi_active_real_valve_step_1ms",
        SemiActiveParams {
            valve: ValveParams::real(),
            ..SemiActiveParams::default()
        },
        3.0,
    );
    bench_semi(
        c,
        "passive_step_1ms",
        SemiActiveParams::passive_reference(),
        0.0,
    );
    for (name, model, rod) in [
        (
            "actuator_full_imposed_step_1ms",
            ActuatorModel::FullOrder,
            RodMode::Imposed,
        ),
        (
            "actuator_reduced_imposed_step_1ms",
            ActuatorModel::ReducedOrder,
            RodMode::Imposed,
        ),
        (
            "actuator_full_free_step_1ms",
            ActuatorModel::FullOrder,
            RodMode::Free,
        ),
    ] {
        bench_act(
            c,
            name,
            ActuatorParams {
                model,
                rod,
                ..ActuatorParams::default()
            },
        );
    }
}

criterion_group!(step, benches);
criterion_main!(step);
