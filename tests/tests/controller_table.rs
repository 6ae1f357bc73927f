//! The sky-hook controller's default damping-vs-opening table is the one our semi-active damper
//! actually has at 4 Hz, 1 mm (models meet only through FMI, so the numbers are copied; this test
//! keeps the copy honest).

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use fmu_controller::DAMPING_TABLE_4HZ;
use fmu_damper::characterise::equivalent_stiffness_damping;
use fmu_damper::SemiActiveParams;

#[test]
fn skyhook_default_table_matches_the_damper_characterisation() {
    let params = SemiActiveParams::default();
    for (opening, c_table) in DAMPING_TABLE_4HZ {
        let (_k, c) = equivalent_stiffness_damping(&params, opening, 4.0, 1.0e-3).unwrap();
        let rel = (c - c_table).abs() / c;
        assert!(
            rel < 0.01,
            "opening {opening}: damper c_eq {c:.0} vs controller table {c_table:.0}"
        );
    }
}
