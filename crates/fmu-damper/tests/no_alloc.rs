//! The step path of each damper model (2000 steps of 1 ms of every reference case) allocates
//! nothing: counted with a global allocator (on this thread only: the test harness may
//! allocate on its own threads meanwhile).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use fmu_damper::perf::{DamperCase, DamperWorkload};
use model_description::testing::{allocations_during, CountingAllocator};

#[global_allocator]
static GLOBAL: CountingAllocator = CountingAllocator;

#[test]
fn step_path_does_not_allocate() {
    for case in DamperCase::ALL {
        let mut model = DamperWorkload::new(case).unwrap();
        model.run_steps(0, 10).unwrap();
        let (allocations, sum) = allocations_during(|| model.run_steps(10, 2000).unwrap());
        assert!(sum.is_finite(), "{}", case.name());
        assert_eq!(allocations, 0, "{}", case.name());
    }
}
