//! Prints the calibration numbers: linear critical speed and hunting mode (R5, R6) with the
//! passive (Maxwell-fitted) damper, and the non-linear response to a 3 mm initial perturbation (R7) at
//! several speeds. Usage: `cargo run --release --example calibration_report [table.csv [k_ssx [conicity [k_grav]]]]`.
use fmu_bogie2dof::calibration::*;
use fmu_bogie2dof::eigen::critical_speed;
use fmu_bogie2dof::sim::{run_closed_loop, LinearDamper};
use fmu_bogie2dof::{Bogie, Params};
use wheel_rail::GeometryTable;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let table = match std::env::args().nth(1) {
        Some(path) => GeometryTable::load(&path)?,
        None => fmu_bogie2dof::model::default_contact_table()?,
    };
    let mut p = Params::default();
    if let Some(k) = std::env::args().nth(2) {
        p.k_ssx_n_per_m = k.parse()?;
    }
    if let Some(l) = std::env::args().nth(3) {
        p.conicity = l.parse()?;
    }
    if let Some(g) = std::env::args().nth(4) {
        p.gravity_stiffness_n_per_m = g.parse()?;
    }
    let c = critical_speed(&p, &passive_damper(), 5.0, 199.0)?;
    println!(
        "linear: V_cr {:.1} km/h, hunting {:.2} Hz (Im {:.2} rad/s)",
        c.speed_kmh, c.hunting.freq_hz, c.hunting.im
    );
    let (lam, grav) = table.linearise(LINEARISATION_AMPLITUDE_M);
    println!("table: equivalent conicity at 1 mm {lam:.3}, gravity stiffness/P {grav:.2} 1/m");
    let damper = LinearDamper::Maxwell {
        k: PASSIVE_MAXWELL_K_N_PER_M,
        c: PASSIVE_MAXWELL_C_NS_PER_M,
    };
    for kmh in [220.0, 250.0, 265.0, 275.0, 285.0, 300.0, 320.0] {
        let q = Params {
            speed_mps: kmh / 3.6,
            initial_lateral_m: 3e-3,
            ..p.clone()
        };
        let mut b = Bogie::with_table(q, table.clone())?;
        let mut peaks = [0.0_f64; 8];
        run_closed_loop(&mut b, damper, 1e-3, 16.0, &|_| 0.0, &mut |o| {
            let k = ((o.time_s / 2.0) as usize).min(7);
            let a = o
                .wheelset_front_lateral_m
                .abs()
                .max(o.wheelset_rear_lateral_m.abs());
            peaks[k] = peaks[k].max(a);
        })?;
        let mm: Vec<String> = peaks.iter().map(|v| format!("{:.2}", v * 1e3)).collect();
        println!(
            "{kmh} km/h: peak wheelset displacement per 2 s [mm]: {}",
            mm.join(" ")
        );
    }
    Ok(())
}
