//! The conicity methods on Δr functions with closed-form answers: a relay (a pure two-point
//! contact jump), a flat tread between flanges, a cone with an offset, and the cases where no
//! value exists (no equilibrium, a double well between its wells, an oscillation leaving the
//! known range), which must be errors saying why.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)] // test code

use std::f64::consts::PI;

use wheel_rail::{ConicityError, DeltaR};

const E0: f64 = 0.75;
const R0: f64 = 0.46;

fn sampled(f: impl Fn(f64) -> f64, y_max: f64, n: usize) -> (Vec<f64>, Vec<f64>) {
    (0..=n)
        .map(|i| {
            let y = -y_max + 2.0 * y_max * i as f64 / n as f64;
            (y, f(y))
        })
        .unzip()
}

/// Δr = J sign(y) (two-point contact at y = 0 and nothing else): S = J |y|, the half period
/// integral is I = 4 sqrt(ŷ / J), so tanγe = π² J / (16 ŷ).
#[test]
fn relay_delta_r_gives_the_closed_form() {
    let j = 0.2e-3;
    let (mut y, mut dr): (Vec<f64>, Vec<f64>) = (vec![], vec![]);
    for i in -100..=100 {
        if i == 0 {
            // the jump as a step 1e-9 m wide
            y.extend([-0.5e-9, 0.5e-9]);
            dr.extend([-j, j]);
        } else {
            y.push(i as f64 * 0.1e-3);
            dr.push(j * f64::from(i).signum());
        }
    }
    let d = DeltaR::from_samples(&y, &dr, E0, R0).unwrap();
    for a in [0.5e-3, 1e-3, 3e-3, 7e-3] {
        let c = d.equivalent_conicity(a).unwrap();
        let exact = PI * PI * j / (16.0 * a);
        println!("relay {a}: {:.6} exact {exact:.6}", c.tan_gamma_e);
        assert!((c.tan_gamma_e / exact - 1.0).abs() < 1e-3, "{a}: {c:?}");
        assert!((c.y1_m + a).abs() < 1e-9);
        // harmonic linearisation of a relay: 4 J / (π ŷ) / 2
        let h = d.harmonic_linearisation(a).unwrap();
        assert!((h / (2.0 * j / (PI * a)) - 1.0).abs() < 1e-3, "{h}");
        // uniform regression of a relay over ±ŷ: slope 3 J / (2 ŷ)
        let l = d.linear_regression(a).unwrap();
        assert!((l.tan_gamma_e / (0.75 * j / a) - 1.0).abs() < 1e-6, "{l:?}");
    }
}

/// Flat tread (Δr = 0 for |y| <= w) between two flanges of slope k (Δr = ±k (|y| - w)): for
/// ŷ <= w the wheelset is not restored, λ is infinite and tanγe = 0 (a number, not an error);
/// for ŷ > w, I = 2 w / (sqrt(k/2) (ŷ - w)) + π sqrt(2 / k).
#[test]
fn flat_tread_between_flanges_gives_zero_then_the_closed_form() {
    let (w, k) = (4e-3, 2.0);
    let f = |y: f64| {
        if y.abs() <= w {
            0.0
        } else {
            k * (y.abs() - w) * y.signum()
        }
    };
    let (y, dr) = sampled(f, 10e-3, 2000);
    let d = DeltaR::from_samples(&y, &dr, E0, R0).unwrap();
    assert_eq!(d.equilibrium_m().unwrap(), 0.0);
    for a in [0.5e-3, 2e-3, 4e-3] {
        let c = d.equivalent_conicity(a).unwrap();
        assert_eq!(c.tan_gamma_e, 0.0, "{a}");
        assert!(c.wavelength_m.is_infinite());
        assert!(
            (c.y1_m + a).abs() < 1e-12,
            "centred on the flat stretch: {c:?}"
        );
        assert_eq!(d.harmonic_linearisation(a).unwrap(), 0.0);
        assert_eq!(d.linear_regression(a).unwrap().tan_gamma_e, 0.0);
    }
    for a in [4.5e-3, 5e-3, 7e-3, 9e-3] {
        let c = d.equivalent_conicity(a).unwrap();
        let i = 2.0 * w / ((k / 2.0).sqrt() * (a - w)) + PI * (2.0 / k).sqrt();
        let exact = (PI / i).powi(2);
        println!("flat tread {a}: {:.6} exact {exact:.6}", c.tan_gamma_e);
        assert!(
            (c.tan_gamma_e / exact - 1.0).abs() < 2e-3,
            "{a}: {c:?} vs {exact}"
        );
        let lk = 2.0 * (E0 * R0).sqrt() * i;
        assert!((c.wavelength_m / lk - 1.0).abs() < 2e-3);
    }
}

/// A cone with a radius offset: Δr = 2 t y + δ; every method gives t, centred on y = -δ / (2 t).
#[test]
fn cone_with_offset_is_centred_on_its_equilibrium() {
    let (t, delta) = (0.15, 1e-3);
    let (y, dr) = sampled(|y| 2.0 * t * y + delta, 10e-3, 200);
    let d = DeltaR::from_samples(&y, &dr, E0, R0).unwrap();
    let y_eq = -delta / (2.0 * t);
    assert!((d.equilibrium_m().unwrap() - y_eq).abs() < 1e-12);
    for a in [1e-3, 3e-3, 6e-3] {
        let c = d.equivalent_conicity(a).unwrap();
        assert!((c.tan_gamma_e / t - 1.0).abs() < 1e-4, "{c:?}");
        assert!((0.5 * (c.y1_m + c.y2_m) - y_eq).abs() < 1e-9);
        assert!((d.linear_regression(a).unwrap().tan_gamma_e / t - 1.0).abs() < 1e-9);
        assert!((d.harmonic_linearisation(a).unwrap() / t - 1.0).abs() < 1e-6);
        assert!(!c.beyond_flange_limit);
    }
    // 7 mm around -3.33 mm leaves the known range [-10, 10] mm
    let e = d.equivalent_conicity(7e-3).unwrap_err();
    let ConicityError::NoOscillation { reason, .. } = &e else {
        panic!("{e:?}")
    };
    assert!(reason.contains("-10.000 mm"), "{e}");
}

/// Δr > 0 everywhere: nothing centres the wheelset, no value at any amplitude.
#[test]
fn no_equilibrium_is_an_error() {
    let (y, dr) = sampled(|y| 2.0 * 0.1 * y + 3e-3, 10e-3, 200);
    let d = DeltaR::from_samples(&y, &dr, E0, R0).unwrap();
    let e = d.equivalent_conicity(1e-3).unwrap_err();
    assert!(matches!(e, ConicityError::NoEquilibrium { .. }), "{e:?}");
    assert!(e.to_string().contains("does not cross zero"), "{e}");
    assert!(d.linear_regression(1e-3).is_err());
    assert!(d.harmonic_linearisation(1e-3).is_err());
}

/// Double well Δr = c (y³ - b² y) (a hollow tread with negative conicity at the centre):
/// S = c (y⁴/4 - b² y²/2) has its minima at ±b and a barrier at 0. Small oscillations sit in one
/// well with tanγe → c b² (the local slope 2 c b² halved); an amplitude between half the width of
/// a well at the barrier level (b / sqrt 2 = 2.1 mm) and half the width of the merged well at
/// that level (sqrt 2 b = 4.2 mm) has no oscillation; above, the wheelset crosses the barrier.
#[test]
fn double_well_between_its_wells_has_no_value() {
    let (c, b) = (2.0e4, 3e-3);
    let (y, dr) = sampled(|y| c * (y.powi(3) - b * b * y), 10e-3, 4000);
    let d = DeltaR::from_samples(&y, &dr, E0, R0).unwrap();
    assert!((d.equilibrium_m().unwrap().abs() - b).abs() < 1e-6);
    let small = d.equivalent_conicity(0.05e-3).unwrap();
    println!("double well small: {small:?}");
    assert!(
        (small.tan_gamma_e / (c * b * b) - 1.0).abs() < 0.01,
        "{small:?}"
    );
    let e = d.equivalent_conicity(3e-3).unwrap_err();
    println!("double well 3 mm: {e}");
    let ConicityError::NoOscillation { reason, .. } = &e else {
        panic!("{e:?}")
    };
    assert!(reason.contains("does not restore"), "{e}");
    let wide = d.equivalent_conicity(5e-3).unwrap();
    assert!(
        wide.tan_gamma_e > 0.0 && (wide.y1_m + 5e-3).abs() < 1e-7,
        "{wide:?}"
    );
}

#[test]
fn bad_amplitude_is_rejected() {
    let (y, dr) = sampled(|y| 0.2 * y, 10e-3, 20);
    let d = DeltaR::from_samples(&y, &dr, E0, R0).unwrap();
    for a in [0.0, -1e-3, f64::NAN] {
        assert!(matches!(
            d.equivalent_conicity(a),
            Err(ConicityError::Amplitude(_))
        ));
    }
}
