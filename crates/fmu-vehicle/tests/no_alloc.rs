//! The communication-step path of the physics allocates nothing: 1000 steps of the non-linear
//! model on the internal irregular track, counted with a global allocator (on this thread
//! only: the test harness may allocate on its own threads meanwhile).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use fmu_vehicle::{Inputs, PsdLevel, TrackSource, Vehicle, VehicleParams};
use model_description::testing::{allocations_during, CountingAllocator};

#[global_allocator]
static GLOBAL: CountingAllocator = CountingAllocator;

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
        let (allocations, ()) = allocations_during(|| {
            for k in 0..1000 {
                inputs.damper_force_n[0] = (k as f64).sin() * 1e3;
                inputs.track_lateral_m = 1e-3 * (k as f64 * 0.01).sin();
                let o = v.step(1e-3, &inputs).unwrap();
                assert!(o.wheelset[0].lateral_m.is_finite());
                let o = v.outputs(&inputs).unwrap();
                assert!(o.carbody.lateral_acc_mid_mps2.is_finite());
            }
        });
        assert_eq!(allocations, 0, "{track:?}");
    }
}

/// The counter sees an allocation (so the zero above is a measurement).
#[test]
fn the_counter_sees_an_allocation() {
    let (allocations, v) = allocations_during(|| vec![1u8; 16]);
    assert!(allocations >= 1);
    assert_eq!(v.len(), 16);
}

/// Another thread's allocations are not counted here: the tests of this binary run on
/// parallel threads, and each must see its own allocations only.
#[test]
fn another_threads_allocations_are_not_counted() {
    let started = std::sync::Barrier::new(2);
    let done = std::sync::Barrier::new(2);
    std::thread::scope(|s| {
        s.spawn(|| {
            let (own, ()) = allocations_during(|| {
                started.wait();
                for n in 0..100 {
                    std::hint::black_box(vec![0u8; n + 1]);
                }
                done.wait();
            });
            assert_eq!(own, 100);
        });
        let (here, ()) = allocations_during(|| {
            started.wait();
            done.wait();
        });
        assert_eq!(here, 0);
    });
}
