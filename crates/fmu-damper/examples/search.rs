//! Grid search used once to calibrate the defaults (0 % opening: C_f, Q_ref).
use fmu_damper::characterise::{damper_frf_point, hysteresis_loop};
use fmu_damper::SemiActiveParams;

fn peak(p: &SemiActiveParams) -> Result<f64, Box<dyn std::error::Error>> {
    let (mut a, mut b) = (3.0f64, 8.0f64);
    let k = |f: f64| damper_frf_point(p, 0.0, f, 1e-3).map(|q| q.k_eq_n_per_m);
    for _ in 0..30 {
        let m1 = a + 0.382 * (b - a);
        let m2 = a + 0.618 * (b - a);
        if k(m1)? > k(m2)? {
            b = m2
        } else {
            a = m1
        }
    }
    Ok(0.5 * (a + b))
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<f64> = std::env::args()
        .skip(1)
        .map(|s| s.parse().unwrap_or(f64::NAN))
        .collect();
    let dpt = args.first().copied().unwrap_or(1e4);
    for qi in 0..12 {
        let q = 7.6e-4 * 1.01f64.powi(qi);
        for ci in 0..16 {
            let cf = 1.55e-7 * 1.01f64.powi(ci);
            let p = SemiActiveParams {
                bulk_modulus_pa: 3e8,
                piston_flow_coeff: cf,
                velocity_flow_ref_m3ps: q,
                laminar_pressure_pa: dpt,
                ..SemiActiveParams::default()
            };
            let f1 = hysteresis_loop(&p, 0.0, 4.0, 1e-3)?.peak_force_n;
            let f3 = hysteresis_loop(&p, 0.0, 4.0, 3e-3)?.peak_force_n;
            if !(12.05e3..19.95e3).contains(&f1) || !(12.05e3..19.95e3).contains(&f3) {
                continue;
            }
            println!(
                "Q {q:.4e} Cf {cf:.4e}: F1 {f1:6.0} F3 {f3:6.0} kpeak {:.2} Hz",
                peak(&p)?
            );
        }
    }
    Ok(())
}
