//! The coach's linear critical speed with the hydraulic semi-active damper itself, linearised by
//! its first harmonic (`master root-locus --damper semi-active:OPENING:STROKE`), over valve
//! openings and stroke amplitudes: each linearisation at the frequency of the mode that crosses
//! with it, or of the hunting mode at 716 km/h when nothing crosses ([`linearise_at_crossing`],
//! as the command does without FREQ), so each row is self-consistent (docs/VALIDATION.md, R9).
//!
//! `cargo run --release -p rail-study --example linearised_damper_scan`
use fmu_vehicle::eigen::critical_speed;
use fmu_vehicle::VehicleParams;
use rail_study::analysis::locus::{
    linearise_at_crossing, DamperSpec, LinearisedDamper, DEFAULT_LINEARISATION_FREQ_HZ,
};
use rail_study::analysis::vehicle_locus::{damper_model, vehicle_onset, CRITICAL_SEARCH_MPS};

fn main() {
    let p = VehicleParams::default();
    let (lo, hi) = CRITICAL_SEARCH_MPS;
    let v_cr = |spec: DamperSpec| critical_speed(&p, &damper_model(spec, None), lo, hi);
    println!("opening  stroke [mm]   k' [MN/m]  c' [kNs/m]  f [Hz]  V_cr [km/h]");
    for opening in [0.0, 0.05, 0.1, 0.3] {
        for stroke_mm in [0.25, 0.5, 1.0, 2.0, 3.0, 5.0] {
            let found =
                LinearisedDamper::measure(opening, stroke_mm * 1e-3, DEFAULT_LINEARISATION_FREQ_HZ)
                    .and_then(|d| linearise_at_crossing(d, |spec| vehicle_onset(&p, spec, None)));
            let row = match found {
                Ok(f) => {
                    let d = f.damper;
                    let head = format!(
                        "{:9.2}  {:10.2}  {:6.2}",
                        d.k_n_per_m * 1e-6,
                        d.c_ns_per_m * 1e-3,
                        d.freq_hz
                    );
                    match v_cr(DamperSpec::Linearised(d)) {
                        Ok(c) => format!("{head}  {:8.1}", c.speed_kmh),
                        Err(_) => format!("{head}  > {:.0}", hi * 3.6),
                    }
                }
                Err(e) => format!("not linearised: {e}"),
            };
            println!("{:6.0} %  {stroke_mm:10.2}  {row}", opening * 100.0);
        }
    }
}
