//! The step path of each control board (3000 steps of 1 ms of every reference case, three MPPT
//! updates) allocates nothing: counted with a global allocator (on this thread only: the test
//! harness may allocate on its own threads meanwhile).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use fmu_controller::perf::{ControllerCase, ControllerWorkload};
use model_description::testing::{allocations_during, CountingAllocator};

#[global_allocator]
static GLOBAL: CountingAllocator = CountingAllocator;

#[test]
fn step_path_does_not_allocate() {
    for case in ControllerCase::ALL {
        let mut board = ControllerWorkload::new(case).unwrap();
        board.run_steps(0, 10).unwrap();
        let (allocations, sum) = allocations_during(|| board.run_steps(10, 3000).unwrap());
        assert!(sum.is_finite(), "{}", case.name());
        assert_eq!(allocations, 0, "{}", case.name());
    }
}
