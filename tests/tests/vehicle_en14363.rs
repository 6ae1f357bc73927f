//! R17 for the passive coach: on ERRI B176 low-level track (seeds 1 and 2), with four
//! hydraulic passive dampers (fmu-damper at 30 % opening, coupled co-simulation style at
//! 1 ms), the EN 14363 rms of the frame lateral acceleration over the leading axle boxes of
//! both bogies (band-pass +-2 Hz around the dominant frequency, 100 m windows in 10 m steps,
//! a_lim = 5.39 m/s^2 for the 6.1 t bogie; the master's assessment) stays below the limit at
//! 290 km/h on both seeds, exceeds it at 300 km/h on one of them (the first crossing over
//! both seeds lies in the seed's 280-300 km/h) and at 320 km/h on both. Seed R8/R17: the
//! limit is exceeded at about 280-300 km/h (measured here on the 10 km/h grid: met up to
//! 290 km/h, first exceeded at 300 km/h on seed 2, 5.65 m/s^2, and at 310 km/h on seed 1).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use fmu_vehicle::{PsdLevel, TrackSource, VehicleParams};
use rail_study::en14363::{acceleration_limit, assess_lateral_acceleration, StabilitySettings};
use tests::coach::run_with_passive_dampers;

/// Largest EN 14363 rms over the two frames [m/s^2] for a 20 s run (the first 5 s skipped).
fn max_rms(kmh: f64, seed: u64) -> f64 {
    let p = VehicleParams {
        speed_mps: kmh / 3.6,
        track: TrackSource::Internal {
            level: PsdLevel::Low,
            seed,
        },
        ..VehicleParams::default()
    };
    let bogie_t = p.bogie_mass_kg() / 1000.0;
    let (mut front, mut rear) = (Vec::new(), Vec::new());
    let h = 1e-3;
    run_with_passive_dampers(p, h, 20_000, |out| {
        front.push(out.frame[0].lateral_acc_leading_axle_mps2);
        rear.push(out.frame[1].lateral_acc_leading_axle_mps2);
    })
    .unwrap();
    let s = StabilitySettings {
        skip_s: 5.0,
        ..StabilitySettings::default()
    };
    let a = |x: &[f64]| {
        assess_lateral_acceleration(x, 1.0 / h, kmh / 3.6, bogie_t, &s)
            .unwrap()
            .max_rms
    };
    let m = a(&front).max(a(&rear));
    eprintln!("{kmh} km/h, seed {seed}: max rms {m:.2} m/s^2");
    m
}

#[test]
fn r17_passive_coach_meets_en14363_at_290_and_first_exceeds_it_at_300_kmh() {
    let limit = acceleration_limit(VehicleParams::default().bogie_mass_kg() / 1000.0);
    assert!((limit - 5.39).abs() < 0.01);
    let mut at_300 = Vec::new();
    for seed in [1, 2] {
        let below = max_rms(290.0, seed);
        assert!(below < limit, "seed {seed}: {below} at 290 km/h");
        at_300.push(max_rms(300.0, seed));
        let above = max_rms(320.0, seed);
        assert!(above > limit, "seed {seed}: {above} at 320 km/h");
    }
    // the first crossing over both seeds, on the 10 km/h grid: 300 km/h
    assert!(
        at_300.iter().any(|&r| r > limit),
        "neither seed exceeds {limit} at 300 km/h: {at_300:?}"
    );
}
