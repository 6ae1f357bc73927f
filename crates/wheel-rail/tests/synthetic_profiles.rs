//! Contact geometry of synthetic profiles whose answers are known exactly: a cylindrical tread
//! with a flange (Δr = 0 and conicity 0 until the flange), a pure cone with unequal radii in
//! both radius conventions, a hollow-worn tread of two circular arcs with a two-point contact at
//! a y computed here from the rigid-body geometry, and left/right mirror images.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)] // test code

use wheel_rail::{
    compute_table, equivalent_conicity, harmonic_linearisation, linear_regression, solve_contact,
    ContactSetup, ContactTable, DeltaR, LateralReference, Profile, RadiusConvention, RailPlacement,
    WheelPlacement, WheelSide, CONTACT_ZONE_DEPTH_M,
};

const DATA: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/data");

fn wheel_a() -> Profile {
    Profile::from_file(format!("{DATA}/RUIC519A.dat")).unwrap()
}

fn rail_a() -> Profile {
    Profile::from_file(format!("{DATA}/SUIC519A.dat")).unwrap()
}

/// Lateral position where the cylindrical tread of [`cylinder_wheel`] meets the flange [m].
const CYLINDER_FROM_M: f64 = -15e-3;

/// Wheel A with its tread made cylindrical: z = 0 for s >= -15 mm, wheel A's flange (lowered to
/// meet the tread without a step) for s < -15 mm.
fn cylinder_wheel() -> Profile {
    let a = wheel_a();
    let z0 = a.vertical_at(CYLINDER_FROM_M).unwrap();
    let pts: Vec<(f64, f64)> = a
        .lateral_m
        .iter()
        .zip(&a.vertical_m)
        .map(|(&s, &z)| {
            if s < CYLINDER_FROM_M {
                (s, (z - z0).min(0.0))
            } else {
                (s, 0.0)
            }
        })
        .collect();
    Profile::from_points("cylinder tread with wheel A flange", &pts).unwrap()
}

/// A flat tread gives Δr = 0 exactly while both contacts stay on it, so the EN 15302 conicity is
/// 0 (not "no value") for every amplitude inside that stretch; beyond it the flange makes it
/// positive.
#[test]
fn cylinder_tread_has_zero_conicity_until_the_flange() {
    let setup = ContactSetup::symmetric(cylinder_wheel(), rail_a(), 0.46, 1.43516);
    let table = compute_table(&setup, -10e-3, 10e-3, 0.05e-3).unwrap();
    // last grid row from the centre with both contacts on the cylinder
    let y_flat = table
        .reachable_rows()
        .filter(|r| r.y_m >= 0.0)
        .take_while(|r| {
            r.left.wheel_lateral_m >= CYLINDER_FROM_M && r.right.wheel_lateral_m >= CYLINDER_FROM_M
        })
        .map(|r| r.y_m)
        .last()
        .unwrap();
    println!(
        "cylinder: Δr = 0 up to |y| = {:.2} mm, reachable to {:.2} mm",
        y_flat * 1e3,
        table.y_reachable_max_m * 1e3
    );
    assert!(y_flat > 3e-3, "flat stretch {y_flat}");
    for r in table.reachable_rows().filter(|r| r.y_m.abs() <= y_flat) {
        assert_eq!(r.delta_r_m, 0.0, "y = {}", r.y_m);
        assert_eq!(r.right.delta_radius_m, 0.0);
    }
    let mut a = 0.5e-3;
    while a <= y_flat + 1e-12 {
        let c = equivalent_conicity(&table, a).unwrap();
        assert_eq!(c.tan_gamma_e, 0.0, "{a}: {c:?}");
        assert!(c.wavelength_m.is_infinite());
        assert_eq!(harmonic_linearisation(&table, a).unwrap(), 0.0);
        assert_eq!(linear_regression(&table, a).unwrap().tan_gamma_e, 0.0);
        a += 0.5e-3;
    }
    // past the flat stretch the flange restores the wheelset: a finite wavelength
    for a in [y_flat + 0.5e-3, 7e-3] {
        let c = equivalent_conicity(&table, a).unwrap();
        println!("cylinder {:.2} mm: {:.4}", a * 1e3, c.tan_gamma_e);
        assert!(c.tan_gamma_e > 0.0 && c.wavelength_m.is_finite(), "{c:?}");
    }
}

/// Cone z = tanα s on [-40, 40] mm.
fn cone(tan_alpha: f64) -> Profile {
    let pts: Vec<(f64, f64)> = (-400..=400)
        .map(|i| {
            let s = i as f64 * 0.1e-3;
            (s, tan_alpha * s)
        })
        .collect();
    Profile::from_points("cone", &pts).unwrap()
}

/// Rail with a circular crown of radius `r` over ±`half_width`, vertices every 0.01 mm.
fn crowned_rail(r: f64, half_width: f64) -> Profile {
    let n = (half_width / 0.01e-3).round() as i64;
    let pts: Vec<(f64, f64)> = (-n..=n)
        .map(|i| {
            let s = i as f64 * 0.01e-3;
            (s, (r * r - s * s).sqrt() - r)
        })
        .collect();
    Profile::from_points("crown", &pts).unwrap()
}

fn setup(
    wheel_left: Profile,
    wheel_right: Profile,
    rail: Profile,
    r_left: f64,
    r_right: f64,
    convention: RadiusConvention,
) -> ContactSetup {
    ContactSetup {
        wheel_left,
        wheel_right,
        rail_left: rail.clone(),
        rail_right: rail,
        nominal_radius_left_m: r_left,
        nominal_radius_right_m: r_right,
        wheel_placement: WheelPlacement::RollingCircleDistance { distance_m: 1.5 },
        rail_placement: RailPlacement::OriginDistance { distance_m: 1.5 },
        rail_inclination: 0.0,
        lateral_reference: LateralReference::RailLevel,
        contact_zone_depth_m: CONTACT_ZONE_DEPTH_M,
        radius_convention: convention,
    }
}

/// Pure cone with unequal radii on a nearly pointed rail (crown radius 2 mm, so the roll moves
/// the contact by a few tenths of a micrometre only): in the EN 15302 convention
/// Δr = 2 tanα y + (r_R - r_L) and tanγe = tanα by every method, the oscillation centred on
/// Δr = 0.
#[test]
fn cone_with_unequal_radii_in_the_en15302_convention() {
    let tan_alpha = 0.1;
    let (r_left, r_right) = (0.4595, 0.4605);
    let dr0 = r_right - r_left;
    let s = setup(
        cone(tan_alpha),
        cone(tan_alpha),
        crowned_rail(2e-3, 1.5e-3),
        r_left,
        r_right,
        RadiusConvention::En15302Offset,
    );
    let table = compute_table(&s, -10e-3, 10e-3, 0.1e-3).unwrap();
    assert!(table.rows.iter().all(|r| !r.beyond_flange_limit));
    assert!(table.jumps.is_empty(), "{:?}", table.jumps);
    for r in &table.rows {
        let exact = 2.0 * tan_alpha * r.y_m + dr0;
        assert!(
            (r.delta_r_m - exact).abs() < 1e-3 * (2.0 * tan_alpha * r.y_m).abs() + 1e-9,
            "y {} Δr {} exact {exact}",
            r.y_m,
            r.delta_r_m
        );
        assert!((r.left.rolling_radius_m - (r_left + r.left.delta_radius_m)).abs() < 1e-15);
    }
    let y_eq = -dr0 / (2.0 * tan_alpha);
    for a_mm in [1.0, 3.0, 5.0] {
        let a = a_mm * 1e-3;
        let c = equivalent_conicity(&table, a).unwrap();
        let l = linear_regression(&table, a).unwrap();
        let h = harmonic_linearisation(&table, a).unwrap();
        for v in [c.tan_gamma_e, l.tan_gamma_e, h] {
            assert!((v / tan_alpha - 1.0).abs() < 2e-3, "{a_mm} mm: {v}");
        }
        assert!((0.5 * (c.y1_m + c.y2_m) - y_eq).abs() < 2e-6, "{c:?}");
        assert!((l.centre_m - y_eq).abs() < 2e-6);
    }
}

/// The two conventions on a crowned rail (R 20 mm): the EN 15302 offset gives exactly the
/// equal-radius rows plus the radius difference (Δr(0) = r_R - r_L); the rigid wheelset rolls by
/// φ0 ≈ (r_R - r_L) / (2 e0) and both contacts move by R cosα φ0, so Δr(0) is larger by
/// 2 tanα R cosα φ0.
#[test]
fn radius_conventions_differ_by_the_roll_of_the_radius_difference() {
    let tan_alpha = 0.05;
    let crown = 20e-3;
    let (r_left, r_right) = (0.459, 0.461);
    let dr0 = r_right - r_left;
    let mk = |rl, rr, conv| {
        setup(
            cone(tan_alpha),
            cone(tan_alpha),
            crowned_rail(crown, 15e-3),
            rl,
            rr,
            conv,
        )
    };
    let equal = compute_table(
        &mk(0.46, 0.46, RadiusConvention::RigidRoll),
        -5e-3,
        5e-3,
        0.5e-3,
    )
    .unwrap();
    let offset = compute_table(
        &mk(r_left, r_right, RadiusConvention::En15302Offset),
        -5e-3,
        5e-3,
        0.5e-3,
    )
    .unwrap();
    let rigid = compute_table(
        &mk(r_left, r_right, RadiusConvention::RigidRoll),
        -5e-3,
        5e-3,
        0.5e-3,
    )
    .unwrap();
    assert_eq!(offset.radius_convention, RadiusConvention::En15302Offset);
    for ((e, o), g) in equal.rows.iter().zip(&offset.rows).zip(&rigid.rows) {
        assert!(
            (o.delta_r_m - (e.delta_r_m + dr0)).abs() < 1e-15,
            "y {}",
            e.y_m
        );
        assert_eq!(o.roll_rad, e.roll_rad);
        if e.y_m.abs() < 1e-12 {
            assert!((o.delta_r_m - dr0).abs() < 1e-15);
            let predicted = 2.0 * tan_alpha * crown * tan_alpha.atan().cos() * g.roll_rad;
            println!(
                "y = 0: rigid Δr - offset Δr = {:.3} µm, predicted {:.3} µm (roll {:.3e} rad)",
                (g.delta_r_m - o.delta_r_m) * 1e6,
                predicted * 1e6,
                g.roll_rad
            );
            assert!(g.roll_rad.abs() > 0.5 * dr0 / 1.5);
            assert!(((g.delta_r_m - o.delta_r_m) / predicted - 1.0).abs() < 0.05);
        }
    }
}

/// Lower arc of a circle: z = zc - sqrt(ρ² - (s - sc)²).
#[derive(Debug, Clone, Copy)]
struct Arc {
    centre_s: f64,
    centre_z: f64,
    radius: f64,
}

impl Arc {
    fn z(&self, s: f64) -> f64 {
        self.centre_z - (self.radius.powi(2) - (s - self.centre_s).powi(2)).sqrt()
    }
}

/// Hollow-worn tread: an inner arc A (bottom at s = -5 mm) and a field-side arc B ("false
/// flange", bottom at +10 mm, 0.05 mm higher), both of radius 50 mm, with the hollow between
/// them (0.57 mm deep).
fn hollow_arcs() -> [Arc; 2] {
    [
        Arc {
            centre_s: -5e-3,
            centre_z: 50e-3,
            radius: 50e-3,
        },
        Arc {
            centre_s: 10e-3,
            centre_z: 0.05e-3 + 50e-3,
            radius: 50e-3,
        },
    ]
}

fn hollow_wheel() -> Profile {
    let arcs = hollow_arcs();
    let pts: Vec<(f64, f64)> = (-500..=500)
        .map(|i| {
            let s = i as f64 * 0.05e-3;
            (s, arcs[0].z(s).min(arcs[1].z(s)))
        })
        .collect();
    Profile::from_points("hollow tread", &pts).unwrap()
}

const HOLLOW_RAIL_CROWN_M: f64 = 80e-3;

/// Exact rigid-body geometry of the hollow wheelset (pivot at rail level, profile origins and
/// rail origins both 2d = 1.5 m apart, equal radii): the minimum vertical gap between the lower
/// arc of a wheel circle (centre Cw, radius ρ) and the rail crown (centre Cr, radius R) is
/// (Cw_Z - Cr_Z) - sqrt((ρ + R)² - (Cw_Y - Cr_Y)²), where both surfaces have the same slope. A
/// wheel circle of profile centre (sc, zc) on side ±1 has its centre at (±(d + sc), zc)
/// relative to the pivot, rotated by the roll φ and moved by y.
fn hollow_gap(side: f64, arc: &Arc, y: f64, phi: f64) -> f64 {
    let d = 0.75;
    let (sn, cs) = phi.sin_cos();
    let yh = side * (d + arc.centre_s);
    let cw_y = y + yh * cs - arc.centre_z * sn;
    let cw_z = yh * sn + arc.centre_z * cs;
    let (cr_y, cr_z) = (side * d, -HOLLOW_RAIL_CROWN_M);
    let rr = arc.radius + HOLLOW_RAIL_CROWN_M;
    (cw_z - cr_z) - (rr * rr - (cw_y - cr_y).powi(2)).sqrt()
}

/// The y > 0 where the left wheel touches with both arcs while the right wheel rests on its arc
/// A: gap_L,A = gap_L,B (two-point contact) and gap_R,A = gap_L,A (roll equilibrium), solved by
/// Newton's method in (y, φ).
fn exact_two_point_y() -> (f64, f64) {
    let [a, b] = hollow_arcs();
    let f = |y: f64, phi: f64| {
        [
            hollow_gap(-1.0, &a, y, phi) - hollow_gap(-1.0, &b, y, phi),
            hollow_gap(1.0, &a, y, phi) - hollow_gap(-1.0, &a, y, phi),
        ]
    };
    let (mut y, mut phi) = (3e-3, 0.0);
    for _ in 0..50 {
        let f0 = f(y, phi);
        let (hy, hp) = (1e-9, 1e-9);
        let fy = f(y + hy, phi);
        let fp = f(y, phi + hp);
        let j = [
            [(fy[0] - f0[0]) / hy, (fp[0] - f0[0]) / hp],
            [(fy[1] - f0[1]) / hy, (fp[1] - f0[1]) / hp],
        ];
        let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
        let dy = (f0[0] * j[1][1] - f0[1] * j[0][1]) / det;
        let dp = (j[0][0] * f0[1] - j[1][0] * f0[0]) / det;
        y -= dy;
        phi -= dp;
        if dy.abs() < 1e-13 && dp.abs() < 1e-15 {
            break;
        }
    }
    // the right wheel is on A and B is clear there
    assert!(hollow_gap(1.0, &b, y, phi) > hollow_gap(1.0, &a, y, phi));
    (y, phi)
}

fn hollow_table(step_m: f64) -> ContactTable {
    let s = setup(
        hollow_wheel(),
        hollow_wheel(),
        crowned_rail(HOLLOW_RAIL_CROWN_M, 30e-3),
        0.46,
        0.46,
        RadiusConvention::En15302Offset,
    );
    compute_table(&s, -6e-3 - step_m / 3.0, 6e-3, step_m).unwrap()
}

/// The contact table locates the two-point contact of the hollow tread to well within a
/// micrometre, although its grid (0.1 mm, offset so that no row falls on the jump) is coarse, and
/// the equivalent conicity around that amplitude matches a 20 times finer table; Δr on the grid
/// alone (the jump smeared over one step) is visibly off.
#[test]
fn hollow_tread_two_point_contact_at_the_exact_y() {
    let (y_star, phi_star) = exact_two_point_y();
    println!(
        "exact two-point contact: y = {:.6} mm, roll {:.4e} rad",
        y_star * 1e3,
        phi_star
    );
    let table = hollow_table(0.1e-3);
    let left: Vec<_> = table
        .jumps
        .iter()
        .filter(|j| j.side == WheelSide::Left && j.y_m > 0.0)
        .collect();
    let right: Vec<_> = table
        .jumps
        .iter()
        .filter(|j| j.side == WheelSide::Right && j.y_m < 0.0)
        .collect();
    assert_eq!(left.len(), 1, "{:?}", table.jumps);
    assert_eq!(right.len(), 1, "{:?}", table.jumps);
    let j = left[0];
    println!(
        "table: jump of the left contact at y = {:.6} mm ({:.3} -> {:.3} mm on the wheel), Δr {:.4} -> {:.4} mm",
        j.y_m * 1e3,
        j.before.left.wheel_lateral_m * 1e3,
        j.after.left.wheel_lateral_m * 1e3,
        j.before.delta_r_m * 1e3,
        j.after.delta_r_m * 1e3
    );
    assert!((j.y_m - y_star).abs() < 1e-6, "{} vs {y_star}", j.y_m);
    assert!((j.before.roll_rad - phi_star).abs() < 1e-7);
    // from arc A (near its bottom, s ≈ -5 mm) to arc B (s ≈ +10 mm), Δr stepping up
    assert!(j.before.left.wheel_lateral_m < 0.0 && j.after.left.wheel_lateral_m > 5e-3);
    assert!(j.after.delta_r_m - j.before.delta_r_m > 0.02e-3);
    assert!(!j.involves_flange());
    assert!(j.wheel_distance_m() > 8e-3);
    // mirror image on the right wheel
    assert!((right[0].y_m + j.y_m).abs() < 1e-6);

    // conicity near the amplitude of the jump: coarse grid with the located jump vs fine grid
    let fine = hollow_table(0.005e-3);
    let grid_only = {
        let (y, dr): (Vec<f64>, Vec<f64>) =
            table.reachable_rows().map(|r| (r.y_m, r.delta_r_m)).unzip();
        DeltaR::from_samples(&y, &dr, table.e0_m, 0.46).unwrap()
    };
    let (mut worst_located, mut worst_grid) = (0.0_f64, 0.0_f64);
    for a_mm in [2.9, 3.0, 3.1, 3.2, 3.5, 4.0] {
        let a = a_mm * 1e-3;
        let reference = equivalent_conicity(&fine, a).unwrap().tan_gamma_e;
        let located = equivalent_conicity(&table, a).unwrap().tan_gamma_e;
        let smeared = grid_only.equivalent_conicity(a).unwrap().tan_gamma_e;
        println!(
            "hollow {a_mm} mm: fine {reference:.5}, 0.1 mm grid with the located jump {located:.5}, grid only {smeared:.5}"
        );
        worst_located = worst_located.max((located / reference - 1.0).abs());
        worst_grid = worst_grid.max((smeared / reference - 1.0).abs());
    }
    println!("largest relative error: located {worst_located:.2e}, grid only {worst_grid:.2e}");
    assert!(worst_located < 2e-3, "{worst_located}");
    assert!(worst_grid > 3.0 * worst_located, "{worst_grid}");
}

/// Left/right mirror images: swapping the left and right wheels, rails and radii turns Δr(y)
/// into -Δr(-y), in both conventions (wheel A on the left, the cylindrical tread on the right,
/// 920 / 918.8 mm).
#[test]
fn mirror_images_give_delta_r_of_opposite_sign() {
    for convention in [RadiusConvention::En15302Offset, RadiusConvention::RigidRoll] {
        let mut s = ContactSetup::symmetric(wheel_a(), rail_a(), 0.46, 1.43516);
        s.wheel_right = cylinder_wheel();
        s.nominal_radius_right_m = 0.4594;
        s.radius_convention = convention;
        let mut m = s.clone();
        std::mem::swap(&mut m.wheel_left, &mut m.wheel_right);
        std::mem::swap(&mut m.rail_left, &mut m.rail_right);
        std::mem::swap(&mut m.nominal_radius_left_m, &mut m.nominal_radius_right_m);
        let mut worst = 0.0_f64;
        for i in -60..=60 {
            let y = i as f64 * 0.1e-3;
            let a = solve_contact(&s, y).unwrap();
            let b = solve_contact(&m, -y).unwrap();
            worst = worst.max((a.delta_r_m + b.delta_r_m).abs());
            assert!(
                (a.roll_rad + b.roll_rad).abs() < 1e-9,
                "{convention:?} y {y}"
            );
            assert!((a.right.tan_gamma - b.left.tan_gamma).abs() < 1e-6);
        }
        println!("{convention:?}: max |Δr(y) + Δr_mirror(-y)| = {worst:.2e} m");
        assert!(worst < 1e-9, "{convention:?}: {worst}");
        // and the asymmetric pair is not trivially antisymmetric by itself
        let p = solve_contact(&s, 3e-3).unwrap();
        let q = solve_contact(&s, -3e-3).unwrap();
        assert!((p.delta_r_m + q.delta_r_m).abs() > 1e-5);
    }
}
