//! One communication step (1 ms) through the FMU's C functions against the same physics
//! called directly in Rust, for:
//! * the semi-active damper (fmi2SetReal of 2 inputs + fmi2DoStep + fmi2GetReal of the force),
//!   3 mm at 4 Hz, valve closed;
//! * the full-active actuator, full order and reduced order (`actuator.model` = 0 / 1)
//!   (fmi2SetReal of 3 inputs + fmi2DoStep + fmi2GetReal of the force), rod imposed at 3 mm and
//!   4 Hz, spool command 0.6 mm at 4 Hz in phase with the rod velocity (inside the valve's
//!   useful range beta..alpha + beta), the FMU's default parameters on both sides.
//!
//! One benchmark iteration is one whole 4 Hz period (250 steps), so both paths do exactly the
//! same work per iteration whatever the cost of the individual steps along the cycle; the models
//! are created once and first run for 1 s (four periods) to reach the periodic state.
//! Time per step = reported time / 250. After each model's two criterion benchmarks, a paired
//! measurement alternates one period direct / one period through the FMU and prints the median
//! ratio (robust to a change of machine load between the two criterion runs). Report the
//! ratios of each model from one run.
//! Run: cargo bench -p fmu-damper --features fmi-export --bench fmu_vs_direct
#![allow(clippy::unwrap_used, clippy::expect_used)]

use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};
use fmu_damper::fmu::{
    __fmi2_exports as fmi, FullActiveActuator as ActFmu, SemiActiveDamper as SemiFmu,
};
use fmu_damper::{
    Actuator, ActuatorInputs, ActuatorModel, SemiActiveDamper, SemiActiveInputs, SemiActiveParams,
};
use model_description::capi::ffi;
use model_description::FmuModel;

const H: f64 = 1.0e-3;
const W: f64 = 2.0 * std::f64::consts::PI * 4.0;

/// Rod stroke 3 mm at 4 Hz: (elongation, velocity) at step `k`.
fn stroke(k: u64) -> (f64, f64) {
    let t = k as f64 * H;
    (3e-3 * (W * t).sin(), 3e-3 * W * (W * t).cos())
}

/// Spool command of the actuator at step `k`: 0.6 mm in phase with the rod velocity.
fn spool(k: u64) -> f64 {
    0.6e-3 * (W * k as f64 * H).cos()
}

/// An FMU instance of `M` through the C ABI, initialised with the given integer parameters.
unsafe fn instantiate<M: FmuModel>(integers: &[(&str, i32)]) -> ffi::fmi2Component {
    let guid = model_description::xml::model_description::<M>()
        .unwrap()
        .guid;
    let guid = std::ffi::CString::new(guid).unwrap();
    let callbacks = ffi::fmi2CallbackFunctions {
        logger: None,
        allocateMemory: None,
        freeMemory: None,
        stepFinished: None,
        componentEnvironment: std::ptr::null_mut(),
    };
    let comp = fmi::fmi2Instantiate(
        c"bench".as_ptr(),
        ffi::fmi2Type_fmi2CoSimulation,
        guid.as_ptr(),
        std::ptr::null(),
        &callbacks,
        0,
        0,
    );
    assert!(!comp.is_null());
    assert_eq!(fmi::fmi2SetupExperiment(comp, 0, 0.0, 0.0, 0, 0.0), 0);
    assert_eq!(fmi::fmi2EnterInitializationMode(comp), 0);
    for (name, x) in integers {
        let vr = [model_description::value_reference::<M>(name).unwrap()];
        assert_eq!(fmi::fmi2SetInteger(comp, vr.as_ptr(), 1, [*x].as_ptr()), 0);
    }
    assert_eq!(fmi::fmi2ExitInitializationMode(comp), 0);
    comp
}

/// Steps per 4 Hz period (one benchmark iteration).
const PERIOD: u64 = 250;
/// Warm-up periods before timing (1 s: the periodic state is reached).
const WARM_PERIODS: u64 = 4;

/// Runs `step(k)` for one period starting at `*k`; returns the last force.
fn period(k: &mut u64, mut step: impl FnMut(u64) -> f64) -> f64 {
    let mut f = 0.0;
    for _ in 0..PERIOD {
        f = step(*k);
        *k += 1;
    }
    f
}

/// Load-robust ratio: alternate one period direct / one period through the FMU (order
/// swapped every round) and print the medians. Criterion measures the two paths one after
/// the other, so a change of machine load between them biases its ratio; paired rounds see
/// the same load.
fn paired(
    name: &str,
    kd: &mut u64,
    direct: &mut impl FnMut(u64) -> f64,
    kf: &mut u64,
    fmu: &mut impl FnMut(u64) -> f64,
) {
    const ROUNDS: usize = 201;
    let mut ratios = Vec::with_capacity(ROUNDS);
    let (mut td, mut tf) = (Vec::with_capacity(ROUNDS), Vec::with_capacity(ROUNDS));
    for r in 0..ROUNDS {
        let time = |k: &mut u64, f: &mut dyn FnMut(u64) -> f64| {
            let t0 = std::time::Instant::now();
            black_box(period(k, f));
            t0.elapsed().as_secs_f64()
        };
        let (d, f) = if r % 2 == 0 {
            let d = time(kd, direct);
            (d, time(kf, fmu))
        } else {
            let f = time(kf, fmu);
            (time(kd, direct), f)
        };
        ratios.push(f / d);
        td.push(d);
        tf.push(f);
    }
    let median = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let per_step = 1e6 / PERIOD as f64;
    println!(
        "{name}: paired medians over {ROUNDS} periods: direct {:.3} us/step, FMU {:.3} us/step, \
         ratio FMU/direct {:.3}",
        median(&mut td) * per_step,
        median(&mut tf) * per_step,
        median(&mut ratios)
    );
}

fn bench_semi(c: &mut Criterion) {
    let name = "semi-active damper, 250 steps of 1 ms (3 mm at 4 Hz)".to_string();
    let mut group = c.benchmark_group(&name);
    group.throughput(Throughput::Elements(PERIOD));
    let mut d = SemiActiveDamper::new(SemiActiveParams::default()).unwrap();
    let mut direct = |k: u64| {
        let (x, v) = stroke(k);
        let inputs = SemiActiveInputs {
            elongation_m: x,
            elongation_velocity_mps: v,
            valve_command_v: 0.0,
        };
        d.step(H, &inputs).unwrap().force_n
    };
    let mut kd = 0u64;
    for _ in 0..WARM_PERIODS {
        period(&mut kd, &mut direct);
    }
    group.bench_function("direct Rust", |b| {
        b.iter(|| black_box(period(&mut kd, &mut direct)))
    });
    unsafe {
        let comp = instantiate::<SemiFmu>(&[]);
        let ivr = [
            model_description::value_reference::<SemiFmu>("damper.elongation").unwrap(),
            model_description::value_reference::<SemiFmu>("damper.elongation_velocity").unwrap(),
        ];
        let ovr = [model_description::value_reference::<SemiFmu>("damper.force").unwrap()];
        let mut out = [0.0];
        let mut fmu = |k: u64| {
            let (x, v) = stroke(k);
            let u = [x, v];
            fmi::fmi2SetReal(comp, ivr.as_ptr(), 2, u.as_ptr());
            fmi::fmi2DoStep(comp, k as f64 * H, H, 1);
            fmi::fmi2GetReal(comp, ovr.as_ptr(), 1, out.as_mut_ptr());
            out[0]
        };
        let mut k = 0u64;
        for _ in 0..WARM_PERIODS {
            period(&mut k, &mut fmu);
        }
        group.bench_function("through the FMI C ABI", |b| {
            b.iter(|| black_box(period(&mut k, &mut fmu)))
        });
        paired(&name, &mut kd, &mut direct, &mut k, &mut fmu);
        fmi::fmi2FreeInstance(comp);
    }
    group.finish();
}

fn bench_actuator(c: &mut Criterion, model: ActuatorModel, fmi_model: i32, label: &str) {
    let name = format!("actuator {label}, 250 steps of 1 ms (3 mm at 4 Hz, spool 0.6 mm)");
    let mut group = c.benchmark_group(&name);
    group.throughput(Throughput::Elements(PERIOD));
    let mut a = Actuator::new(fmu_damper::ActuatorParams {
        model,
        ..ActFmu::default_params()
    })
    .unwrap();
    let mut direct = |k: u64| {
        let (x, v) = stroke(k);
        let inputs = ActuatorInputs {
            spool_command_m: spool(k),
            load_force_n: 0.0,
            elongation_m: x,
            elongation_velocity_mps: v,
        };
        a.step(H, &inputs).unwrap().force_n
    };
    let mut kd = 0u64;
    for _ in 0..WARM_PERIODS {
        period(&mut kd, &mut direct);
    }
    group.bench_function("direct Rust", |b| {
        b.iter(|| black_box(period(&mut kd, &mut direct)))
    });
    unsafe {
        let comp = instantiate::<ActFmu>(&[("actuator.model", fmi_model)]);
        let ivr = [
            model_description::value_reference::<ActFmu>("spool.command").unwrap(),
            model_description::value_reference::<ActFmu>("damper.elongation").unwrap(),
            model_description::value_reference::<ActFmu>("damper.elongation_velocity").unwrap(),
        ];
        let ovr = [model_description::value_reference::<ActFmu>("damper.force").unwrap()];
        let mut out = [0.0];
        let mut fmu = |k: u64| {
            let (x, v) = stroke(k);
            let u = [spool(k), x, v];
            fmi::fmi2SetReal(comp, ivr.as_ptr(), 3, u.as_ptr());
            fmi::fmi2DoStep(comp, k as f64 * H, H, 1);
            fmi::fmi2GetReal(comp, ovr.as_ptr(), 1, out.as_mut_ptr());
            out[0]
        };
        let mut k = 0u64;
        for _ in 0..WARM_PERIODS {
            period(&mut k, &mut fmu);
        }
        group.bench_function("through the FMI C ABI", |b| {
            b.iter(|| black_box(period(&mut k, &mut fmu)))
        });
        paired(&name, &mut kd, &mut direct, &mut k, &mut fmu);
        fmi::fmi2FreeInstance(comp);
    }
    group.finish();
}

fn bench(c: &mut Criterion) {
    bench_semi(c);
    bench_actuator(c, ActuatorModel::FullOrder, 0, "full order");
    bench_actuator(c, ActuatorModel::ReducedOrder, 1, "reduced order");
}

criterion_group!(benches, bench);
criterion_main!(benches);
