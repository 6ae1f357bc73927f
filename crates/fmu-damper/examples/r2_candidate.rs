//! R2 exploration, companion of `r2_peak`: for a given laminar core dP_t, find the
//! (Q_ref, C_f) whose 0 % k_eq peak (1 mm) sits at a target frequency while the 0 % peak forces
//! at 4 Hz are centred in R1 (sqrt(F1 F3) = sqrt(12 kN 20 kN)), then A_v centring the 100 %
//! peaks in 0.5-1 kN; prints R1, the phases, the c_eq table the sky-hook controller uses
//! (4 Hz, 1 mm) and k_eq, c_eq at 30 %, 3.5 Hz, 1 mm (bogie passive-damper fit).
//! Does NOT change the defaults. With no argument, prints the same numbers for the defaults.
//!
//! Usage: cargo run --release -p fmu-damper --example r2_candidate -- [dP_t_Pa target_Hz]
use fmu_damper::characterise::{damper_frf_point, hysteresis_loop};
use fmu_damper::SemiActiveParams;

type R<T> = Result<T, Box<dyn std::error::Error>>;

fn k_peak(p: &SemiActiveParams) -> R<f64> {
    k_peak_at(p, 1e-3)
}

fn k_peak_at(p: &SemiActiveParams, amp: f64) -> R<f64> {
    let (mut a, mut b) = (1.0f64, 20.0f64);
    let k = |f: f64| damper_frf_point(p, 0.0, f, amp).map(|q| q.k_eq_n_per_m);
    for _ in 0..25 {
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

fn peaks(p: &SemiActiveParams, opening: f64) -> R<(f64, f64)> {
    Ok((
        hysteresis_loop(p, opening, 4.0, 1e-3)?.peak_force_n,
        hysteresis_loop(p, opening, 4.0, 3e-3)?.peak_force_n,
    ))
}

/// Log-bisection of an increasing `g` for `g(x) = target` in [lo, hi].
fn solve(mut lo: f64, mut hi: f64, target: f64, mut g: impl FnMut(f64) -> R<f64>) -> R<f64> {
    for _ in 0..40 {
        let mid = (lo * hi).sqrt();
        if g(mid)? < target {
            lo = mid
        } else {
            hi = mid
        }
    }
    Ok((lo * hi).sqrt())
}

/// Q_ref centring the 0 % forces in R1 for the given C_f.
fn centred_q(base: &SemiActiveParams, cf: f64) -> R<f64> {
    solve(1e-5, 1e-1, (12e3f64 * 20e3).sqrt(), |q| {
        let p = SemiActiveParams {
            velocity_flow_ref_m3ps: q,
            piston_flow_coeff: cf,
            ..*base
        };
        let (f1, f3) = peaks(&p, 0.0)?;
        Ok((f1 * f3).sqrt())
    })
}

fn report(p: &SemiActiveParams) -> R<()> {
    println!(
        "K {:.3e} Pa, V0 {:.3e} m3, C_f {:.4e}, Q_ref {:.4e} m3/s at {} m/s, c_d {} A_v {:.4e} m2, \
         dP_t {:.3e} Pa, v_lin {:.1e} m/s",
        p.bulk_modulus_pa,
        p.chamber_volume_m3,
        p.piston_flow_coeff,
        p.velocity_flow_ref_m3ps,
        p.velocity_ref_mps,
        p.valve_discharge_coeff,
        p.valve_area_m2,
        p.laminar_pressure_pa,
        p.velocity_linear_mps
    );
    for op in [0.0, 1.0] {
        let (f1, f3) = peaks(p, op)?;
        println!(
            "R1 {:3.0} %: peak force 1 mm {f1:7.0} N, 3 mm {f3:7.0} N",
            op * 100.0
        );
    }
    print!("R2 phase of F/x at 4 Hz, 1 mm:");
    for op in [0.0, 0.2, 0.5, 1.0] {
        let q = damper_frf_point(p, op, 4.0, 1e-3)?;
        print!(" {:.0} % {:.1} deg,", op * 100.0, q.phase_deg);
    }
    println!();
    println!(
        "k_eq peak at 0 %: {:.2} Hz at 1 mm, {:.2} Hz at 3 mm",
        k_peak(p)?,
        k_peak_at(p, 3e-3)?
    );
    print!("0 % k_eq (MN/m) at 1 mm:");
    for f in [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 10.0] {
        let q = damper_frf_point(p, 0.0, f, 1e-3)?;
        print!(" {f} Hz {:.2},", q.k_eq_n_per_m / 1e6);
    }
    println!();
    print!("c_eq at 4 Hz, 1 mm (kN s/m):");
    for op in [0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.8, 1.0] {
        let q = damper_frf_point(p, op, 4.0, 1e-3)?;
        print!(" {:.0} % {:.1},", op * 100.0, q.c_eq_ns_per_m / 1e3);
    }
    println!();
    let q = damper_frf_point(p, 0.3, 3.5, 1e-3)?;
    println!(
        "30 %, 3.5 Hz, 1 mm: k_eq {:.1} kN/m, c_eq {:.1} kN s/m",
        q.k_eq_n_per_m / 1e3,
        q.c_eq_ns_per_m / 1e3
    );
    Ok(())
}

fn main() -> R<()> {
    let args: Vec<f64> = std::env::args()
        .skip(1)
        .map(|s| s.parse().unwrap_or(f64::NAN))
        .collect();
    let d = SemiActiveParams::default();
    let (Some(&dpt), Some(&target)) = (args.first(), args.get(1)) else {
        return report(&d);
    };
    let base = SemiActiveParams {
        laminar_pressure_pa: dpt,
        ..d
    };
    // The centred k_eq peak rises with C_f: bisect C_f for the target.
    let cf = solve(1e-8, 1e-5, target, |cf| {
        let q = centred_q(&base, cf)?;
        k_peak(&SemiActiveParams {
            velocity_flow_ref_m3ps: q,
            piston_flow_coeff: cf,
            ..base
        })
    })?;
    let q = centred_q(&base, cf)?;
    let p0 = SemiActiveParams {
        velocity_flow_ref_m3ps: q,
        piston_flow_coeff: cf,
        ..base
    };
    // The 100 % force falls as the area grows: solve 1/sqrt(F1 F3) = 1/sqrt(0.5 kN 1 kN).
    let av = solve(1e-7, 1e-2, 1.0 / (500.0f64 * 1000.0).sqrt(), |av| {
        let (f1, f3) = peaks(
            &SemiActiveParams {
                valve_area_m2: av,
                ..p0
            },
            1.0,
        )?;
        Ok(1.0 / (f1 * f3).sqrt())
    })?;
    report(&SemiActiveParams {
        valve_area_m2: av,
        ..p0
    })
}
