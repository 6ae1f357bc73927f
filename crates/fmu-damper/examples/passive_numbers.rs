//! Prints the numbers other crates need: passive (30 %) damper k_eq, c_eq at
//! 2-5 Hz (1 and 3 mm) and c_eq vs opening at 4 Hz, 1 mm.
use fmu_damper::{equivalent_stiffness_damping, SemiActiveParams};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let p = SemiActiveParams::default();
    println!("passive (30 %): freq_hz amp_mm k_eq_kn_per_m c_eq_kns_per_m");
    for amp in [1e-3, 3e-3] {
        for f in [2.0, 3.0, 3.5, 4.0, 5.0] {
            let (k, c) = equivalent_stiffness_damping(&p, 0.3, f, amp)?;
            println!("{f:4.1} {:.0} {:8.1} {:7.1}", amp * 1e3, k / 1e3, c / 1e3);
        }
    }
    println!("4 Hz, 1 mm: opening_pct k_eq_kn_per_m c_eq_kns_per_m");
    for i in 0..=10 {
        let o = i as f64 / 10.0;
        let (k, c) = equivalent_stiffness_damping(&p, o, 4.0, 1e-3)?;
        println!("{:3.0} {:8.1} {:7.1}", o * 100.0, k / 1e3, c / 1e3);
    }
    Ok(())
}
