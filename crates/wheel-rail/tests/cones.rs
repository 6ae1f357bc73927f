//! Synthetic pure cones on crowned rails: Δr = (r_R0 - r_L0) + 2 tanα y and tanγe = tanα.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)] // test code

use wheel_rail::{
    compute_table, equivalent_conicity, harmonic_linearisation, ContactSetup, LateralReference,
    Profile, RadiusConvention, RailPlacement, WheelPlacement, CONTACT_ZONE_DEPTH_M,
};

/// Cone: radius r0 - tanα s, i.e. vertical coordinate z = tanα s, s in [-40, 40] mm.
fn cone(tan_alpha: f64) -> Profile {
    let pts: Vec<(f64, f64)> = (-400..=400)
        .map(|i| {
            let s = i as f64 * 0.1e-3;
            (s, tan_alpha * s)
        })
        .collect();
    Profile::from_points("cone", &pts).unwrap()
}

/// Crown radius of the synthetic rail [m].
const CROWN_R: f64 = 0.02;

/// Rail vertex spacing [m]: a polygonal crown moves the contact in steps of one vertex, i.e. the
/// rolling radius in steps of up to RAIL_STEP * tanα per wheel.
const RAIL_STEP: f64 = 0.01e-3;

/// Rail with a circular crown of radius `r`, s in [-15, 15] mm. A small crown radius keeps the
/// roll coupling (contact shift R cosα φ, about +0.3 % on Δr here) below the 1 % tolerances.
fn crowned_rail(r: f64) -> Profile {
    let pts: Vec<(f64, f64)> = (-1500..=1500)
        .map(|i| {
            let s = i as f64 * RAIL_STEP;
            (s, (r * r - s * s).sqrt() - r)
        })
        .collect();
    Profile::from_points("crown", &pts).unwrap()
}

fn setup(tan_alpha: f64, r_left: f64, r_right: f64) -> ContactSetup {
    ContactSetup {
        wheel_left: cone(tan_alpha),
        wheel_right: cone(tan_alpha),
        rail_left: crowned_rail(CROWN_R),
        rail_right: crowned_rail(CROWN_R),
        nominal_radius_left_m: r_left,
        nominal_radius_right_m: r_right,
        wheel_placement: WheelPlacement::RollingCircleDistance { distance_m: 1.5 },
        rail_placement: RailPlacement::OriginDistance { distance_m: 1.5 },
        rail_inclination: 0.0,
        lateral_reference: LateralReference::RailLevel,
        contact_zone_depth_m: CONTACT_ZONE_DEPTH_M,
        radius_convention: RadiusConvention::RigidRoll,
    }
}

#[test]
fn cones_delta_r_and_conicity() {
    for (tan_alpha, r_left, r_right) in [
        (0.05, 0.46, 0.46),
        (0.1, 0.46, 0.4602),
        (0.025, 0.45, 0.4499),
    ] {
        let s = setup(tan_alpha, r_left, r_right);
        let table = compute_table(&s, -10e-3, 10e-3, 0.05e-3).unwrap();
        assert!(table.rows.iter().all(|r| !r.beyond_flange_limit));
        let dr0 = r_right - r_left;
        for r in &table.rows {
            // Roll φ turns the cones by ±φ in the track frame, so on both crowned rails the tangent
            // point moves by R cosα φ in the same lateral direction as y (pivot at rail level):
            // first order, Δr = Δr0 + 2 tanα (y + R cosα φ).
            let cos_a = tan_alpha.atan().cos();
            let expected = dr0 + 2.0 * tan_alpha * (r.y_m + CROWN_R * cos_a * r.roll_rad);
            let naive = dr0 + 2.0 * tan_alpha * r.y_m;
            assert!(
                (r.delta_r_m - naive).abs() < 0.015 * (naive - dr0).abs() + 5e-6,
                "tanα {tan_alpha}: y {} Δr {} naive {naive} roll {}",
                r.y_m,
                r.delta_r_m,
                r.roll_rad
            );
            assert!(
                (r.delta_r_m - expected).abs()
                    < 0.002 * (2.0 * tan_alpha * r.y_m).abs() + 2.0 * RAIL_STEP * tan_alpha + 1e-8,
                "tanα {tan_alpha}: y {} Δr {} expected {expected}",
                r.y_m,
                r.delta_r_m
            );
            // contact angle = cone angle (roll changes it by < 1e-3)
            assert!((r.left.tan_gamma - tan_alpha).abs() < 2e-3);
            assert!((r.right.tan_gamma - tan_alpha).abs() < 2e-3);
            assert!((r.right.delta_radius_m - (r.right.rolling_radius_m - r_right)).abs() < 1e-15);
        }
        let y_eq = -dr0 / (2.0 * tan_alpha);
        for a_mm in [1.0, 3.0, 5.0, 7.0] {
            let a = a_mm * 1e-3;
            if (y_eq - a) < -10e-3 || (y_eq + a) > 10e-3 {
                continue;
            }
            let c = equivalent_conicity(&table, a).unwrap();
            let h = harmonic_linearisation(&table, a).unwrap();
            assert!((c.tan_gamma_e / tan_alpha - 1.0).abs() < 0.01, "{c:?}");
            assert!((h / tan_alpha - 1.0).abs() < 0.01, "{h}");
            // oscillation centred on the equilibrium Δr = 0
            assert!((0.5 * (c.y1_m + c.y2_m) - y_eq).abs() < 0.02e-3, "{c:?}");
            // Klingel wavelength 2π sqrt(r0 e0 / tanα)
            let lk = 2.0 * std::f64::consts::PI * (c.r0_m * c.e0_m / tan_alpha).sqrt();
            assert!((c.wavelength_m / lk - 1.0).abs() < 0.01);
        }
    }
}
