//! Writes the wheel/rail table of the bogie model for EN 15302 case E1 (wheel A / rail A both
//! sides, 920 mm wheels, gauge 1435.16 mm): y from -10 to +10 mm in 0.05 mm steps.
//!
//! `cargo run -p wheel-rail --release --example bogie_table [output.csv]`
//! (default output: wheel_rail_A_A.csv in the current folder).
//!
//! The bogie FMU's shipped `resources/wheel_rail_A_A.csv` is a calibration input (its worn
//! surrogate and gravitational stiffness are built from it, and R5-R7 were fitted on them): it
//! was written by this example before the contact point became the centroid of the contact
//! zone, and differs from today's output by up to 0.24 mm in delta r and 0.046 in tan gamma near
//! the flange root (8 % less tread gravitational stiffness at 1 mm). Overwrite it only together
//! with a recalibration of fmu-bogie2dof.
//!
//! Bogie tables use the rigid wheelset's geometry for unequal radii
//! ([`RadiusConvention::RigidRoll`]); for this equal-radius case both conventions give the same
//! rows.

use wheel_rail::{compute_table, equivalent_conicity, ContactSetup, Profile, RadiusConvention};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let here = env!("CARGO_MANIFEST_DIR");
    let out = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "wheel_rail_A_A.csv".to_string());
    let wheel = Profile::from_file(format!("{here}/data/RUIC519A.dat"))?;
    let rail = Profile::from_file(format!("{here}/data/SUIC519A.dat"))?;
    let setup = ContactSetup {
        radius_convention: RadiusConvention::RigidRoll,
        ..ContactSetup::symmetric(wheel, rail, 0.920 / 2.0, 1.43516)
    };
    let table = compute_table(&setup, -10e-3, 10e-3, 0.05e-3)?;
    if let Some(dir) = std::path::Path::new(&out).parent() {
        std::fs::create_dir_all(dir)?;
    }
    std::fs::write(&out, table.to_bogie_csv())?;
    println!(
        "wrote {out}: {} rows, reachable y in [{:.2}, {:.2}] mm (flange limit), e0 = {:.2} mm",
        table.rows.len(),
        table.y_reachable_min_m * 1e3,
        table.y_reachable_max_m * 1e3,
        table.e0_m * 1e3
    );
    for a_mm in [1.0, 3.0, 5.0, 7.0] {
        let c = equivalent_conicity(&table, a_mm * 1e-3)?;
        println!(
            "equivalent conicity at {a_mm} mm: {:.4} (wavelength {:.2} m)",
            c.tan_gamma_e, c.wavelength_m
        );
    }
    Ok(())
}
