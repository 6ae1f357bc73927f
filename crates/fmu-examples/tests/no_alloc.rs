//! The glue allocates nothing on the communication-step path (fmi2SetReal, fmi2DoStep,
//! fmi2GetReal): counted with a global allocator (on this thread) around calls into the exported C
//! functions.
#![cfg(feature = "fmi-export")]

use fmu_examples::__fmi2_exports as fmi;
use model_description::capi::ffi;
use model_description::testing::{allocations_during, CountingAllocator};

#[global_allocator]
static GLOBAL: CountingAllocator = CountingAllocator;

#[test]
fn communication_step_path_does_not_allocate() {
    let guid = model_description::xml::model_description::<fmu_examples::MassSpring>()
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
    unsafe {
        let c = fmi::fmi2Instantiate(
            c"alloc".as_ptr(),
            ffi::fmi2Type_fmi2CoSimulation,
            guid.as_ptr(),
            std::ptr::null(),
            &callbacks,
            0,
            0,
        );
        assert!(!c.is_null());
        assert_eq!(fmi::fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0), 0);
        assert_eq!(fmi::fmi2EnterInitializationMode(c), 0);
        assert_eq!(fmi::fmi2ExitInitializationMode(c), 0);
        let force_vr =
            [model_description::value_reference::<fmu_examples::MassSpring>("force").unwrap()];
        let out_vr = [
            model_description::value_reference::<fmu_examples::MassSpring>("position").unwrap(),
            model_description::value_reference::<fmu_examples::MassSpring>("velocity").unwrap(),
        ];
        let mut out = [0.0; 2];
        let h = 1.0e-3;
        let (allocations, ()) = allocations_during(|| {
            for k in 0..1000 {
                let t = k as f64 * h;
                let f = [t.sin()];
                assert_eq!(fmi::fmi2SetReal(c, force_vr.as_ptr(), 1, f.as_ptr()), 0);
                assert_eq!(fmi::fmi2DoStep(c, t, h, 1), 0);
                assert_eq!(fmi::fmi2GetReal(c, out_vr.as_ptr(), 2, out.as_mut_ptr()), 0);
            }
        });
        assert_eq!(allocations, 0, "allocations on the step path");
        assert!(out[0].is_finite());
        fmi::fmi2FreeInstance(c);
    }
}
