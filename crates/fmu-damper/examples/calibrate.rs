//! Prints the semi-active damper's R1/R2 numbers for the parameters given on the
//! command line: K C_f Q_ref A_v dP_t (SI). Used to calibrate the defaults.
use fmu_damper::characterise::{damper_frf_point, hysteresis_loop};
use fmu_damper::SemiActiveParams;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let a: Vec<f64> = std::env::args()
        .skip(1)
        .map(|s| s.parse().unwrap_or(f64::NAN))
        .collect();
    let mut p = SemiActiveParams::default();
    if a.len() >= 5 {
        p.bulk_modulus_pa = a[0];
        p.piston_flow_coeff = a[1];
        p.velocity_flow_ref_m3ps = a[2];
        p.valve_area_m2 = a[3];
        p.laminar_pressure_pa = a[4];
    }
    for op in [0.0, 0.2, 0.3, 0.5, 1.0] {
        let l1 = hysteresis_loop(&p, op, 4.0, 1e-3)?;
        let l3 = hysteresis_loop(&p, op, 4.0, 3e-3)?;
        println!(
            "open {op:.1}: peak 1mm {:8.0} N  3mm {:8.0} N  phase1 {:5.1} phase3 {:5.1}",
            l1.peak_force_n,
            l3.peak_force_n,
            l1.transfer.arg().to_degrees(),
            l3.transfer.arg().to_degrees()
        );
    }
    for op in [0.0, 0.3, 1.0] {
        print!("open {op:.1} k/c:");
        for f in [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 10.0, 15.0, 20.0] {
            let q = damper_frf_point(&p, op, f, 1e-3)?;
            print!(
                " {f}Hz {:.2}MN/m {:.0}kNs/m |",
                q.k_eq_n_per_m / 1e6,
                q.c_eq_ns_per_m / 1e3
            );
        }
        println!();
    }
    Ok(())
}
