//! The communication-step path of the physics allocates nothing: 1000 steps of the non-linear
//! model on the internal irregular track, counted with a global allocator (on this thread
//! only: the test harness may allocate on its own threads meanwhile).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::sync::atomic::{AtomicUsize, Ordering};

use fmu_vehicle::{Inputs, PsdLevel, TrackSource, Vehicle, VehicleParams};

struct Counting;
static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

thread_local! {
    static COUNTING: Cell<bool> = const { Cell::new(false) };
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if COUNTING.with(Cell::get) {
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
fn steps_do_not_allocate() {
    for track in [
        TrackSource::Internal {
            level: PsdLevel::High,
            seed: 1,
        },
        TrackSource::External,
    ] {
        let mut v = Vehicle::new(VehicleParams {
            speed_mps: 300.0 / 3.6,
            track,
            ..VehicleParams::default()
        })
        .unwrap();
        let mut inputs = Inputs::default();
        let before = ALLOCATIONS.load(Ordering::SeqCst);
        COUNTING.with(|c| c.set(true));
        for k in 0..1000 {
            inputs.damper_force_n[0] = (k as f64).sin() * 1e3;
            inputs.track_lateral_m = 1e-3 * (k as f64 * 0.01).sin();
            let o = v.step(1e-3, &inputs).unwrap();
            assert!(o.wheelset[0].lateral_m.is_finite());
            let o = v.outputs(&inputs).unwrap();
            assert!(o.carbody.lateral_acc_mid_mps2.is_finite());
        }
        COUNTING.with(|c| c.set(false));
        assert_eq!(ALLOCATIONS.load(Ordering::SeqCst) - before, 0, "{track:?}");
    }
}
