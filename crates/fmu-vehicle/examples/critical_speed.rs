//! Prints the linear critical speed of the default coach with the passive reference damper.
use fmu_vehicle::{calibration, eigen, VehicleParams};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let p = VehicleParams::default();
    let c = eigen::critical_speed(&p, &calibration::passive_damper(), 10.0, 150.0)?;
    println!(
        "V_cr = {:.1} km/h, f = {:.2} Hz, mode {} ({:?})",
        c.speed_kmh,
        c.mode.freq_hz,
        c.mode.kind.label(),
        c.mode.shares
    );
    for kmh in [100.0, 150.0, 200.0, 250.0, 280.0, 300.0, 350.0] {
        let r = eigen::analyse(&p, kmh / 3.6, &calibration::passive_damper())?;
        let m = r.least_damped.ok_or("no mode")?;
        println!(
            "{kmh} km/h: max re {:.3}, least damped {:.2} Hz zeta {:.4} {}",
            r.max_re,
            m.freq_hz,
            m.damping_ratio,
            m.kind.label()
        );
    }
    Ok(())
}
