//! EN 15302 benchmark case E1 (wheel A / rail A both sides, 920 mm wheels, gauge 1435.16 mm).

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)] // test code

use wheel_rail::{
    compute_table, equivalent_conicity, harmonic_linearisation, solve_contact, ContactSetup,
    DeltaR, Profile,
};

const DATA: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/data");

fn e1_setup() -> ContactSetup {
    let wheel = Profile::from_file(format!("{DATA}/RUIC519A.dat")).unwrap();
    let rail = Profile::from_file(format!("{DATA}/SUIC519A.dat")).unwrap();
    ContactSetup::symmetric(wheel, rail, 0.920 / 2.0, 1.43516)
}

/// (y [m], Δr [m]) of the reference file.
fn reference() -> Vec<(f64, f64)> {
    let text = std::fs::read_to_string(format!("{DATA}/en15302_E1_delta_r.csv")).unwrap();
    text.lines()
        .skip(1)
        .map(|l| {
            let mut it = l.split(',');
            let y: f64 = it.next().unwrap().trim().parse().unwrap();
            let dr: f64 = it.next().unwrap().trim().parse().unwrap();
            (y * 1e-3, dr * 1e-3)
        })
        .collect()
}

/// Pointwise Δr error against the reference for |y| <= 6 mm: (y, error) for each reference point.
fn errors_up_to_6mm(setup: &ContactSetup) -> Vec<(f64, f64)> {
    reference()
        .into_iter()
        .filter(|(y, _)| y.abs() <= 6.0e-3 + 1e-12)
        .map(|(y, dr_ref)| {
            let row = solve_contact(setup, y).unwrap();
            assert!(!row.beyond_flange_limit, "y = {y}");
            (y, row.delta_r_m - dr_ref)
        })
        .collect()
}

fn worst(errs: &[(f64, f64)]) -> (f64, f64) {
    errs.iter().copied().fold((0.0_f64, 0.0_f64), |a, e| {
        if e.1.abs() > a.1.abs() {
            e
        } else {
            a
        }
    })
}

/// E1 target (docs/VALIDATION.md): every reference point with |y| <= 6 mm within 0.1 mm of the reference.
/// Measured: RMS 0.038 mm, max 0.076 mm at |y| = 5.6 mm.
#[test]
fn e1_delta_r_matches_reference() {
    let errs = errors_up_to_6mm(&e1_setup());
    assert_eq!(errs.len(), 121);
    let rms = (errs.iter().map(|e| e.1 * e.1).sum::<f64>() / errs.len() as f64).sqrt();
    let within = errs.iter().filter(|e| e.1.abs() <= 0.1e-3).count();
    let w = worst(&errs);
    println!(
        "E1 |y|<=6 mm: rms {:.4} mm, {within}/{} within 0.1 mm, max {:.4} mm at y = {:.1} mm",
        rms * 1e3,
        errs.len(),
        w.1 * 1e3,
        w.0 * 1e3
    );
    assert_eq!(within, errs.len(), "worst {w:?}");
    assert!(rms < 0.05e-3, "rms {rms}");
}

/// The criterion does not hinge on the exact contact-zone depth: it holds from 5 to 10 µm. The
/// bare minimum-distance point (depth 0) misses it, because the profile tables' curvature ripple
/// makes the minimum jump across the nearly conformal zones (crate docs).
#[test]
fn e1_contact_zone_depth_sensitivity() {
    for depth in [5e-6, 10e-6] {
        let mut setup = e1_setup();
        setup.contact_zone_depth_m = depth;
        let w = worst(&errors_up_to_6mm(&setup));
        println!(
            "depth {depth:e} m: max error {:.4} mm at {:.1} mm",
            w.1 * 1e3,
            w.0 * 1e3
        );
        assert!(w.1.abs() <= 0.1e-3, "depth {depth}: {w:?}");
    }
    let mut setup = e1_setup();
    setup.contact_zone_depth_m = 0.0;
    let errs = errors_up_to_6mm(&setup);
    let w = worst(&errs);
    let within = errs.iter().filter(|e| e.1.abs() <= 0.1e-3).count();
    println!(
        "depth 0: {within}/121 within 0.1 mm, max {:.4} mm at {:.1} mm",
        w.1 * 1e3,
        w.0 * 1e3
    );
    assert!(w.1.abs() > 0.15e-3 && within < 115, "{within} {w:?}");
}

/// Sign convention: y > 0 moves the right wheel towards its flange, so Δr = r_R - r_L > 0, and
/// the symmetric case is antisymmetric.
#[test]
fn e1_sign_and_symmetry() {
    let setup = e1_setup();
    let p = solve_contact(&setup, 4e-3).unwrap();
    let m = solve_contact(&setup, -4e-3).unwrap();
    assert!(p.delta_r_m > 1.5e-3);
    assert!((p.delta_r_m + m.delta_r_m).abs() < 1e-9);
    assert!(p.roll_rad > 0.0 && (p.roll_rad + m.roll_rad).abs() < 1e-9);
    assert!((p.right.tan_gamma - m.left.tan_gamma).abs() < 1e-9);
    // at y = 0 both treads: small positive contact angle, equal on both sides
    let c = solve_contact(&setup, 0.0).unwrap();
    assert!(c.left.tan_gamma > 0.005 && c.left.tan_gamma < 0.06, "{c:?}");
    assert!((c.left.tan_gamma - c.right.tan_gamma).abs() < 1e-9);
    assert!(c.delta_r_m.abs() < 1e-9);
}

/// Flange contact: the jump of Δr (tread -> flange) lies between 6.3 and 6.8 mm, and the
/// contact angle there is that of the flange.
#[test]
fn e1_flange_jump_and_table() {
    let table = compute_table(&e1_setup(), -10e-3, 10e-3, 0.01e-3).unwrap();
    assert_eq!(table.rows.len(), 2001);
    // first y with flange contact (contact angle > 45 deg)
    let first_flange = table
        .rows
        .iter()
        .find(|r| r.y_m > 0.0 && r.right.tan_gamma > 1.0)
        .unwrap();
    // largest single-step increase of Δr for y in (0, 7.5) mm
    let jump = table
        .rows
        .windows(2)
        .filter(|w| w[0].y_m > 0.0 && !w[1].beyond_flange_limit)
        .max_by(|a, b| {
            (a[1].delta_r_m - a[0].delta_r_m).total_cmp(&(b[1].delta_r_m - b[0].delta_r_m))
        })
        .unwrap();
    println!(
        "flange contact from y = {:.2} mm; largest Δr jump {:.3} -> {:.3} mm between y = {:.2} and {:.2} mm; reachable up to {:.2} mm",
        first_flange.y_m * 1e3,
        jump[0].delta_r_m * 1e3,
        jump[1].delta_r_m * 1e3,
        jump[0].y_m * 1e3,
        jump[1].y_m * 1e3,
        table.y_reachable_max_m * 1e3
    );
    assert!(first_flange.y_m > 6.3e-3 && first_flange.y_m < 6.8e-3);
    assert!(jump[0].y_m > 6.3e-3 && jump[1].y_m < 6.8e-3);
    assert!(jump[1].delta_r_m - jump[0].delta_r_m > 1e-3);
    assert!(jump[1].right.tan_gamma > 1.5);
    // the flange limit is reached before 10 mm and the rows beyond repeat the last one
    assert!(table.y_reachable_max_m > 6.8e-3 && table.y_reachable_max_m < 10e-3);
    let last = table.rows.last().unwrap();
    assert!(last.beyond_flange_limit);
    let edge = table
        .rows
        .iter()
        .find(|r| (r.y_m - table.y_reachable_max_m).abs() < 1e-12)
        .unwrap();
    assert_eq!(last.delta_r_m, edge.delta_r_m);
    assert!((table.y_reachable_min_m + table.y_reachable_max_m).abs() < 1e-12);
}

/// Equivalent conicity. Brief: 0.15-0.25 at 3 mm. EN 15302 Annex E reference values for E1
/// (as tabulated in criogenox/B_ECC-Equivalent-Conicity-Calculation, data/ben_E1.dat):
/// 0.125 / 0.188 / 0.254 / 0.505 at 1 / 3 / 5 / 7 mm, with the Annex F tolerance
/// ±min(0.05, 0.5 tanγe).
#[test]
fn e1_equivalent_conicity() {
    let table = compute_table(&e1_setup(), -8e-3, 8e-3, 0.02e-3).unwrap();
    let annex_e = [(1.0, 0.125), (3.0, 0.188), (5.0, 0.254), (7.0, 0.505)];
    for (a_mm, reference) in annex_e {
        let c = equivalent_conicity(&table, a_mm * 1e-3).unwrap();
        let h = harmonic_linearisation(&table, a_mm * 1e-3).unwrap();
        println!(
            "E1 amplitude {a_mm} mm: tan_gamma_e = {:.4} (Annex E {reference}), harmonic {:.4}, wavelength {:.2} m",
            c.tan_gamma_e, h, c.wavelength_m
        );
        let tol = f64::min(0.05, 0.5 * reference);
        assert!((c.tan_gamma_e - reference).abs() <= tol, "{a_mm} mm: {c:?}");
        assert!(
            (c.y1_m + a_mm * 1e-3).abs() < 1e-6,
            "symmetric: y1 = -amplitude"
        );
    }
    let c3 = equivalent_conicity(&table, 3e-3).unwrap().tan_gamma_e;
    assert!(c3 > 0.15 && c3 < 0.25);
}

/// The conicity integration applied to the reference Δr itself reproduces Annex E closely, which
/// separates integration errors from contact-geometry errors.
#[test]
fn conicity_of_reference_delta_r() {
    let (y, dr): (Vec<f64>, Vec<f64>) = reference().into_iter().unzip();
    let d = DeltaR::from_samples(&y, &dr, 0.75, 0.46).unwrap();
    for (a_mm, reference) in [(1.0, 0.125), (3.0, 0.188), (5.0, 0.254)] {
        let c = d.equivalent_conicity(a_mm * 1e-3).unwrap().tan_gamma_e;
        println!("reference Δr, {a_mm} mm: {c:.4} (Annex E {reference})");
        assert!((c - reference).abs() < 0.01, "{a_mm} mm: {c}");
    }
}

/// A negative or non-finite contact-zone depth is rejected, naming the parameter.
#[test]
fn bad_contact_zone_depth_is_rejected() {
    for bad in [-1e-6, f64::NAN, 1e-3] {
        let mut setup = e1_setup();
        setup.contact_zone_depth_m = bad;
        let err = solve_contact(&setup, 1e-3).unwrap_err().to_string();
        assert!(err.contains("contact_zone_depth_m"), "{err}");
    }
}

/// Why rail level is the convention: measuring y at the axle centre instead (shifted by
/// r0 sin(roll)) fits the E1 reference four times worse. Measured: RMS 0.038 mm at rail level,
/// 0.163 mm at the axle centre (|y| <= 6 mm).
#[test]
fn rail_level_is_the_convention_of_the_e1_reference() {
    let rms = |errs: &[(f64, f64)]| {
        (errs.iter().map(|e| e.1 * e.1).sum::<f64>() / errs.len() as f64).sqrt()
    };
    let rail = rms(&errors_up_to_6mm(&e1_setup()));
    let axle = rms(&errors_up_to_6mm(&ContactSetup {
        lateral_reference: wheel_rail::LateralReference::AxleCentre,
        ..e1_setup()
    }));
    eprintln!(
        "E1 RMS: rail level {:.3} mm, axle centre {:.3} mm",
        rail * 1e3,
        axle * 1e3
    );
    assert!(rail < 0.05e-3 && axle > 3.0 * rail, "{rail} vs {axle}");
}

/// A wheel profile with a near-vertical back face far from the rail (0.02 mm across, 14.5 mm
/// high) folds over when the wheelset rolls; only the part of the wheel over the rail can
/// touch it, so the table is E1's. It used to stop at 3.5 mm, taken for the flange limit.
#[test]
fn a_back_face_beyond_the_rail_does_not_cut_the_table_short() {
    let text = std::fs::read_to_string(format!("{DATA}/RUIC519A.dat")).unwrap();
    let wheel = Profile::parse_str(&format!("-70.02 5\n{text}"), "back_face.dat").unwrap();
    let rail = Profile::from_file(format!("{DATA}/SUIC519A.dat")).unwrap();
    let folded = ContactSetup::symmetric(wheel, rail, 0.920 / 2.0, 1.43516);
    let a = compute_table(&e1_setup(), -10e-3, 10e-3, 0.1e-3).unwrap();
    let b = compute_table(&folded, -10e-3, 10e-3, 0.1e-3).unwrap();
    assert_eq!(
        (b.y_reachable_min_m, b.y_reachable_max_m),
        (a.y_reachable_min_m, a.y_reachable_max_m)
    );
    assert!(b.y_reachable_max_m > 6e-3, "{}", b.y_reachable_max_m);
    for (ra, rb) in a.rows.iter().zip(&b.rows) {
        assert_eq!(ra.delta_r_m, rb.delta_r_m, "y = {}", ra.y_m);
    }
}

/// A wide gauge (1445 mm) puts both wheels on the flat of the tread over a few millimetres: Δr
/// of the contact search there is noise of 0.01-0.2 µm of either sign, taken as 0, so the
/// small oscillations have conicity 0 (no restoring force) and the larger ones a small one.
/// The noise put the equilibrium 1.1 mm off centre and no oscillation of 1 mm was found.
#[test]
fn a_wide_gauge_gives_a_conicity_curve_from_zero() {
    let wheel = Profile::from_file(format!("{DATA}/RUIC519A.dat")).unwrap();
    let rail = Profile::from_file(format!("{DATA}/SUIC519A.dat")).unwrap();
    let wide = ContactSetup::symmetric(wheel, rail, 0.920 / 2.0, 1.445);
    let table = compute_table(&wide, -10e-3, 10e-3, 0.05e-3).unwrap();
    let at = |a_mm: f64| {
        equivalent_conicity(&table, a_mm * 1e-3)
            .unwrap()
            .tan_gamma_e
    };
    // measured: 0 / 0.0015 / 0.0054 / 0.0278 at 1 / 3 / 5 / 7 mm
    assert_eq!(at(1.0), 0.0);
    let (c3, c5, c7) = (at(3.0), at(5.0), at(7.0));
    assert!(0.0 < c3 && c3 < c5 && c5 < c7 && c7 < 0.1, "{c3} {c5} {c7}");
}

/// The table computation asks its caller before each row and stops when told (Ctrl-C in the
/// command: a fine grid on a dense profile took minutes to notice it).
#[test]
fn the_table_computation_stops_when_asked() {
    let asked = std::cell::Cell::new(0usize);
    let stop = || {
        asked.set(asked.get() + 1);
        asked.get() > 10
    };
    let e =
        wheel_rail::compute_table_until(&e1_setup(), -10e-3, 10e-3, 0.01e-3, &stop).unwrap_err();
    assert_eq!(e, wheel_rail::ContactError::Stopped);
    assert_eq!(asked.get(), 11, "asked once per row until told to stop");
    let full = wheel_rail::compute_table_until(&e1_setup(), -10e-3, 10e-3, 0.1e-3, &|| false);
    assert_eq!(full.unwrap().rows.len(), 201);
}
