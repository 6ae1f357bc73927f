//! The step path of the bogie (1000 steps of 1 ms, non-linear, ideal and internal irregular track) allocates nothing: counted with a global allocator on this thread.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use fmu_bogie2dof::perf::{reference_bogie, simulate_reference, ReferenceTrack};
use model_description::testing::{allocations_during, CountingAllocator};

#[global_allocator]
static GLOBAL: CountingAllocator = CountingAllocator;

#[test]
fn step_path_does_not_allocate() {
    // the model is built (table parsed, track synthesised) before counting
    for track in [ReferenceTrack::Ideal, ReferenceTrack::InternalIrregular] {
        let mut bogie = reference_bogie(track).unwrap();
        simulate_reference(&mut bogie, 0.1).unwrap();
        let (allocations, run) = allocations_during(|| simulate_reference(&mut bogie, 1.0));
        run.unwrap();
        assert_eq!(allocations, 0, "{track:?}");
    }
}
