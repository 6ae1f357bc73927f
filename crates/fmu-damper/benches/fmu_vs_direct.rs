//! One communication step (1 ms) of the semi-active damper: through the FMU's C functions
//! (fmi2SetReal of 2 inputs + fmi2DoStep + fmi2GetReal of the force) against the same physics
//! called directly in Rust. Report the ratio of the two times from one run.
//! Run: cargo bench -p fmu-damper --features fmi-export --bench fmu_vs_direct
#![allow(clippy::unwrap_used, clippy::expect_used)]

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use fmu_damper::fmu::{__fmi2_exports as fmi, SemiActiveDamper as Fmu};
use fmu_damper::{SemiActiveDamper, SemiActiveInputs, SemiActiveParams};
use model_description::capi::ffi;

fn bench(c: &mut Criterion) {
    let h = 1.0e-3;
    let w = 2.0 * std::f64::consts::PI * 4.0;
    let mut group = c.benchmark_group("semi-active damper step (h = 1 ms, 3 mm at 4 Hz)");
    group.bench_function("direct Rust", |b| {
        let mut d = SemiActiveDamper::new(SemiActiveParams::default()).unwrap();
        let mut k = 0u64;
        b.iter(|| {
            let t = k as f64 * h;
            let inputs = SemiActiveInputs {
                elongation_m: 3e-3 * (w * t).sin(),
                elongation_velocity_mps: 3e-3 * w * (w * t).cos(),
                valve_command_v: 0.0,
            };
            k += 1;
            black_box(d.step(h, &inputs).unwrap().force_n)
        })
    });
    group.bench_function("through the FMI C ABI", |b| unsafe {
        let guid = model_description::xml::model_description::<Fmu>()
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
        fmi::fmi2SetupExperiment(comp, 0, 0.0, 0.0, 0, 0.0);
        fmi::fmi2EnterInitializationMode(comp);
        fmi::fmi2ExitInitializationMode(comp);
        let ivr = [
            model_description::value_reference::<Fmu>("damper.elongation").unwrap(),
            model_description::value_reference::<Fmu>("damper.elongation_velocity").unwrap(),
        ];
        let ovr = [model_description::value_reference::<Fmu>("damper.force").unwrap()];
        let mut out = [0.0];
        let mut k = 0u64;
        b.iter(|| {
            let t = k as f64 * h;
            let u = [3e-3 * (w * t).sin(), 3e-3 * w * (w * t).cos()];
            fmi::fmi2SetReal(comp, ivr.as_ptr(), 2, u.as_ptr());
            fmi::fmi2DoStep(comp, t, h, 1);
            fmi::fmi2GetReal(comp, ovr.as_ptr(), 1, out.as_mut_ptr());
            k += 1;
            black_box(out[0])
        });
        fmi::fmi2FreeInstance(comp);
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
