//! Cost of the FMI glue per communication step: fmi2SetReal + fmi2DoStep + fmi2GetReal (two
//! values) through the exported C functions, against calling the same model directly in Rust.
//! Run: cargo bench -p fmu-examples --features fmi-export --bench glue
#![allow(clippy::unwrap_used, clippy::expect_used)]

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use fmu_examples::{__fmi2_exports as fmi, MassSpring};
use model_description::capi::ffi;
use model_description::{Diagnostics, FmuModel, InstanceContext};

fn bench(c: &mut Criterion) {
    let h = 1.0e-3;
    let mut group = c.benchmark_group("communication step (MassSpring, h = 1 ms)");
    group.bench_function("direct Rust", |b| {
        let mut m = MassSpring::instantiate(&InstanceContext::default()).unwrap();
        let mut diag = Diagnostics::default();
        m.exit_initialization(&mut diag).unwrap();
        let mut t = 0.0;
        b.iter(|| {
            m.force_n = black_box(0.5);
            m.do_step(t, h, &mut diag).unwrap();
            t += h;
            black_box((m.position_m, m.velocity_mps))
        })
    });
    group.bench_function("through the FMI C ABI", |b| unsafe {
        let guid = model_description::xml::model_description::<MassSpring>()
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
        let fvr = [model_description::value_reference::<MassSpring>("force").unwrap()];
        let ovr = [
            model_description::value_reference::<MassSpring>("position").unwrap(),
            model_description::value_reference::<MassSpring>("velocity").unwrap(),
        ];
        let mut out = [0.0; 2];
        let mut k = 0u64;
        b.iter(|| {
            let t = k as f64 * h;
            fmi::fmi2SetReal(comp, fvr.as_ptr(), 1, [black_box(0.5)].as_ptr());
            fmi::fmi2DoStep(comp, t, h, 1);
            fmi::fmi2GetReal(comp, ovr.as_ptr(), 2, out.as_mut_ptr());
            k += 1;
            black_box(out)
        });
        fmi::fmi2FreeInstance(comp);
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
