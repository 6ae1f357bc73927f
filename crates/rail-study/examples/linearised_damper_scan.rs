//! The coach's linear critical speed with the hydraulic semi-active damper itself, linearised by
//! its first harmonic (`master root-locus --damper semi-active:OPENING:STROKE:FREQ`), over valve
//! openings and stroke amplitudes: the frequency of each linearisation is iterated to that of the
//! crossing mode, so each row is self-consistent (docs/VALIDATION.md, R9).
//!
//! `cargo run --release -p rail-study --example linearised_damper_scan`
use fmu_vehicle::eigen::critical_speed;
use fmu_vehicle::VehicleParams;
use rail_study::analysis::locus::{DamperSpec, LinearisedDamper, DEFAULT_LINEARISATION_FREQ_HZ};
use rail_study::analysis::vehicle_locus::{damper_model, CRITICAL_SEARCH_MPS};

fn main() {
    let p = VehicleParams::default();
    let (lo, hi) = CRITICAL_SEARCH_MPS;
    println!("opening  stroke [mm]   k' [MN/m]  c' [kNs/m]  f [Hz]  V_cr [km/h]");
    for opening in [0.0, 0.05, 0.1, 0.3] {
        for stroke_mm in [0.25, 0.5, 1.0, 2.0, 3.0, 5.0] {
            let mut freq_hz = DEFAULT_LINEARISATION_FREQ_HZ;
            let mut row = String::new();
            // three rounds: the crossing frequency moves by less than 0.01 Hz after the second
            for _ in 0..3 {
                let d = match LinearisedDamper::measure(opening, stroke_mm * 1e-3, freq_hz) {
                    Ok(d) => d,
                    Err(e) => {
                        row = format!("not linearised: {e}");
                        break;
                    }
                };
                let head = format!("{:9.2}  {:10.2}", d.k_n_per_m * 1e-6, d.c_ns_per_m * 1e-3);
                match critical_speed(&p, &damper_model(DamperSpec::Linearised(d), None), lo, hi) {
                    Ok(c) => {
                        row = format!("{head}  {:6.2}  {:8.1}", freq_hz, c.speed_kmh);
                        freq_hz = c.mode.freq_hz;
                    }
                    Err(_) => {
                        row = format!("{head}  {freq_hz:6.2}  > {:.0}", hi * 3.6);
                        break;
                    }
                }
            }
            println!("{:6.0} %  {stroke_mm:10.2}  {row}", opening * 100.0);
        }
    }
}
