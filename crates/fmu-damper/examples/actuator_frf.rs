//! Prints the actuator FRFs u -> rod velocity (full, reduced, linearised).
use fmu_damper::characterise::{actuator_frf, linearised_actuator_frf};
use fmu_damper::{ActuatorModel, ActuatorParams};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut p = ActuatorParams::default();
    if let Some(cl) = std::env::args().nth(1).and_then(|s| s.parse().ok()) {
        p.leakage_coeff_m3ps_per_pa = cl;
    }
    if std::env::var("NO_COULOMB").is_ok() {
        p.coulomb_friction_n = 0.0;
        p.stribeck_friction_n = 0.0;
    }
    println!(
        "omega_c = {:.2} rad/s, xi_c = {:.3}",
        p.cylinder_eigenfrequency_radps(),
        p.cylinder_damping_ratio()
    );
    let freqs: Vec<f64> = [
        1.0, 5.0, 20.0, 50.0, 80.0, 95.0, 130.0, 160.0, 191.0, 250.0, 320.0,
    ]
    .to_vec();
    for amp in [p.alpha_m, 0.3 * p.alpha_m] {
        let t = std::time::Instant::now();
        let full = actuator_frf(&p, ActuatorModel::FullOrder, amp, &freqs)?;
        let red = actuator_frf(&p, ActuatorModel::ReducedOrder, amp, &freqs)?;
        let lin = linearised_actuator_frf(&p, amp, 0.75 * p.supply_pressure_pa, &freqs)?;
        println!("|u| = {amp:e} ({:.2?})", t.elapsed());
        for i in 0..freqs.len() {
            println!(
                "  {:7.1} rad/s  full {:8.3} {:7.1}  red {:8.3} {:7.1}  lin {:8.3} {:7.1}",
                full[i].omega_radps,
                full[i].modulus_per_s,
                full[i].phase_deg,
                red[i].modulus_per_s,
                red[i].phase_deg,
                lin[i].modulus_per_s,
                lin[i].phase_deg
            );
        }
    }
    Ok(())
}
