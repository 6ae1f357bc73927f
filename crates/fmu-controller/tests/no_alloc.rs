//! The step path of each control board (3000 steps of 1 ms of every reference case, three MPPT updates) allocates nothing: counted with a global allocator (one test in this
//! binary; only the test's own thread is counted, not the test harness's).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

use fmu_controller::perf::{ControllerCase, ControllerWorkload};

struct Counting;
static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

thread_local! {
    /// Set on the test's thread: the harness's other threads may allocate meanwhile.
    static COUNTED: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if COUNTED.try_with(std::cell::Cell::get).unwrap_or(false) {
            ALLOCATIONS.fetch_add(1, Ordering::SeqCst);
        }
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
    COUNTED.with(|c| c.set(true));
    for case in ControllerCase::ALL {
        let mut board = ControllerWorkload::new(case).unwrap();
        board.run_steps(0, 10).unwrap();
        let before = ALLOCATIONS.load(Ordering::SeqCst);
        board.run_steps(10, 3000).unwrap();
        assert_eq!(
            ALLOCATIONS.load(Ordering::SeqCst),
            before,
            "{}",
            case.name()
        );
    }
}
