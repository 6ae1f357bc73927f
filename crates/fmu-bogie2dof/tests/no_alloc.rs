//! The step path of the bogie (1000 steps of 1 ms, non-linear, ideal and internal irregular track) allocates nothing: counted with a global allocator (one test in this
//! binary, so no other test allocates meanwhile).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

use fmu_bogie2dof::perf::{reference_bogie, simulate_reference, ReferenceTrack};

struct Counting;
static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::SeqCst);
        System.alloc(layout)
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        System.dealloc(ptr, layout)
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn step_path_does_not_allocate() {
    // the model is built (table parsed, track synthesised) before counting
    for track in [ReferenceTrack::Ideal, ReferenceTrack::InternalIrregular] {
        let mut bogie = reference_bogie(track).unwrap();
        simulate_reference(&mut bogie, 0.1).unwrap();
        let before = ALLOCATIONS.load(Ordering::SeqCst);
        simulate_reference(&mut bogie, 1.0).unwrap();
        assert_eq!(ALLOCATIONS.load(Ordering::SeqCst), before, "{track:?}");
    }
}
