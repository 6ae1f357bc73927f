//! Real-time factor of the non-linear model: one simulated second (1000 communication
//! steps of 1 ms, internal RK4 sub-step 1e-4 s) with the passive Maxwell damper in the
//! loop, at 320 km/h (default table, flange-root limit cycle). Simulated seconds per wall second = 1 / (time per iter).
#![allow(clippy::unwrap_used, clippy::expect_used)]
use criterion::{criterion_group, criterion_main, Criterion};
use fmu_bogie2dof::calibration::*;
use fmu_bogie2dof::sim::{run_closed_loop, LoopDamper};
use fmu_bogie2dof::{Bogie, Params, PsdLevel, TrackSource};

fn bench(c: &mut Criterion) {
    let table = fmu_bogie2dof::model::default_contact_table().unwrap();
    let damper = LoopDamper::Maxwell {
        k: PASSIVE_MAXWELL_K_N_PER_M,
        c: PASSIVE_MAXWELL_C_NS_PER_M,
    };
    for (name, track) in [
        ("nonlinear_1s_sim_h1ms", TrackSource::None),
        (
            "nonlinear_1s_sim_h1ms_internal_track",
            TrackSource::Internal {
                level: PsdLevel::High,
                seed: 1,
            },
        ),
    ] {
        let p = Params {
            speed_mps: 320.0 / 3.6,
            initial_lateral_m: 3e-3,
            track,
            ..Params::default()
        };
        c.bench_function(name, |b| {
            b.iter(|| {
                let mut m = Bogie::with_table(p.clone(), table.clone()).unwrap();
                run_closed_loop(&mut m, damper, 1e-3, 1.0, &|_| 0.0, &mut |_| {}).unwrap();
                m.state()[0]
            })
        });
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
