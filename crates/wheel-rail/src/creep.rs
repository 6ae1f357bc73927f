//! Creep forces of one wheel: Kalker's linear creep coefficients from a Hertz contact ellipse
//! (5.2)-(5.7), and the Vermeulen-Johnson saturation (5.21)-(5.25).
//!
//! Time-domain models compute the unsaturated Kalker forces F = -f eps per wheel and scale both
//! components by [`saturation_factor`] of their resultant; all functions are plain arithmetic
//! (no allocation) and safe to call on the step path.

/// Vermeulen-Johnson saturation (5.21)-(5.25) as a scale factor F'/F_res applied to both
/// creep force components. With u = F_res/(mu P): F' = mu P (1 - (1 - u/3)^3)
/// = mu P (u - u^2/3 + u^3/27) for u <= 3, else mu P; the ratio F'/F_res is computed in
/// closed form so that F_res -> 0 gives 1 (no 0/0).
#[inline]
pub fn saturation_factor(f_res: f64, mu_p: f64) -> f64 {
    let u = f_res / mu_p;
    if u <= 3.0 {
        1.0 - u / 3.0 + u * u / 27.0
    } else {
        1.0 / u
    }
}

/// Creep forces of the two wheels of a wheelset, each saturated on its own resultant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WheelsetCreepForces {
    /// Lateral creep force on the left wheel \[N\].
    pub lateral_left_n: f64,
    /// Lateral creep force on the right wheel \[N\].
    pub lateral_right_n: f64,
    /// Longitudinal creep force on the left wheel \[N\].
    pub longitudinal_left_n: f64,
    /// Longitudinal creep force on the right wheel \[N\].
    pub longitudinal_right_n: f64,
}

/// Kalker forces (5.2)-(5.3) F = -f eps of a wheelset from its lateral creepage (the same on
/// both wheels) and the longitudinal creepage of each wheel, each wheel's pair scaled by
/// [`saturation_factor`] (5.21)-(5.25) of its resultant; `mu_p_n` = mu P per wheel.
#[inline]
pub fn saturated_wheelset_creep(
    f11_n: f64,
    f22_n: f64,
    mu_p_n: f64,
    lateral_creepage: f64,
    longitudinal_creepage_left: f64,
    longitudinal_creepage_right: f64,
) -> WheelsetCreepForces {
    let ft = -f22_n * lateral_creepage;
    let (flr, fll) = (
        -f11_n * longitudinal_creepage_right,
        -f11_n * longitudinal_creepage_left,
    );
    // plain root of the sum of squares: forces stay far below the square's overflow (a
    // diverging state is caught as non-finite by the models), so no hypot is needed
    let kr = saturation_factor((ft * ft + flr * flr).sqrt(), mu_p_n);
    let kl = saturation_factor((ft * ft + fll * fll).sqrt(), mu_p_n);
    WheelsetCreepForces {
        lateral_left_n: kl * ft,
        lateral_right_n: kr * ft,
        longitudinal_left_n: kl * fll,
        longitudinal_right_n: kr * flr,
    }
}

/// Kalker longitudinal coefficient C11 for Poisson 0.25 as a function of g = b/a
/// (a: semi-axis in rolling direction). The seed's (5.6)-(5.7) swap the labels: the fit the
/// seed calls "C22" reproduces Kalker's C11 (4.25 vs 4.12 at a = b), so it is used here.
pub fn kalker_c11(b_over_a: f64) -> f64 {
    3.2893 + 0.975 / b_over_a - 0.012 / (b_over_a * b_over_a)
}

/// Kalker lateral coefficient C22 for Poisson 0.25 (the seed's "C11" fit, see [`kalker_c11`]).
pub fn kalker_c22(b_over_a: f64) -> f64 {
    2.4014 + 1.3179 / b_over_a - 0.02 / (b_over_a * b_over_a)
}

/// Complete elliptic integrals K(k), E(k) by the arithmetic-geometric mean (modulus k < 1).
pub fn elliptic_ke(k: f64) -> (f64, f64) {
    let mut a = 1.0;
    let mut b = (1.0 - k * k).sqrt();
    let mut c_sum = 0.5 * k * k;
    let mut pow2 = 0.5;
    for _ in 0..40 {
        let an = 0.5 * (a + b);
        let bn = (a * b).sqrt();
        let cn = 0.5 * (a - b);
        pow2 *= 2.0;
        c_sum += pow2 * cn * cn;
        a = an;
        b = bn;
        if cn.abs() < 1e-16 {
            break;
        }
    }
    let kk = std::f64::consts::PI / (2.0 * a);
    (kk, kk * (1.0 - c_sum))
}

/// Result of [`hertz_kalker`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HertzKalker {
    /// Semi-axis in rolling direction \[m\].
    pub a_m: f64,
    /// Lateral semi-axis \[m\].
    pub b_m: f64,
    /// f11 = G a b C11 \[N\].
    pub f11_n: f64,
    /// f22 = G a b C22 \[N\].
    pub f22_n: f64,
}

/// Hertz contact ellipse of a wheel (rolling radius `wheel_radius_m`, flat across) on a
/// rail with crown radius `rail_crown_m`, both steel (`young_pa`, `poisson`), under normal
/// load `load_n`; then Kalker's f11, f22 (5.4)-(5.7) with the labels corrected.
/// Assumes the rail crown curvature exceeds the wheel curvature (a >= b).
pub fn hertz_kalker(
    load_n: f64,
    wheel_radius_m: f64,
    rail_crown_m: f64,
    young_pa: f64,
    poisson: f64,
) -> HertzKalker {
    let a_curv = 0.5 / wheel_radius_m; // rolling direction (rail straight)
    let b_curv = 0.5 / rail_crown_m; // lateral (wheel tread flat)
    let ratio = b_curv / a_curv;
    // ratio(e) = ((a/b)^2 E - K)/(K - E) grows with e: bisection on e.
    let ratio_of = |e: f64| {
        let (k, ee) = elliptic_ke(e);
        (ee / (1.0 - e * e) - k) / (k - ee)
    };
    let (mut lo, mut hi) = (1e-6, 1.0 - 1e-12);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if ratio_of(mid) < ratio {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let e = 0.5 * (lo + hi);
    let (k, ee) = elliptic_ke(e);
    let e_star = young_pa / (2.0 * (1.0 - poisson * poisson));
    // Johnson (1985) (4.39): A = p0 b (K - E)/(E* e^2 a^2), P = 2/3 pi a b p0
    let a3 = 3.0 * load_n * (k - ee) / (2.0 * std::f64::consts::PI * a_curv * e_star * e * e);
    let a = a3.cbrt();
    let b = a * (1.0 - e * e).sqrt();
    let g = young_pa / (2.0 * (1.0 + poisson));
    let g_ab = g * a * b;
    HertzKalker {
        a_m: a,
        b_m: b,
        f11_n: g_ab * kalker_c11(b / a),
        f22_n: g_ab * kalker_c22(b / a),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wheelset_creep_saturates_each_wheel_on_its_resultant() {
        // Unsaturated far below mu P: F = -f eps (factor 1 - u/3 + u^2/27 ~ 1).
        let small = saturated_wheelset_creep(1e7, 1e7, 1e12, 1e-6, 0.0, 0.0);
        assert!((small.lateral_left_n + 10.0).abs() < 1e-3);
        assert_eq!(small.lateral_left_n, small.lateral_right_n);
        assert_eq!(small.longitudinal_left_n, 0.0);
        // Left wheel far into saturation, right wheel free of longitudinal creep: the left
        // resultant is mu P, the right one is smaller and its lateral force larger.
        let f = saturated_wheelset_creep(1e7, 1e7, 2e4, 1e-3, 1e-1, 0.0);
        let left = f.lateral_left_n.hypot(f.longitudinal_left_n);
        assert!((left - 2e4).abs() < 1e-9 * 2e4, "{left}");
        assert!(f.lateral_right_n.abs() > f.lateral_left_n.abs());
        assert_eq!(f.longitudinal_right_n, 0.0);
        assert!(f.longitudinal_left_n < 0.0);
    }

    #[test]
    fn kalker_labels_match_kalker_table() {
        // Kalker (1967) Table, Poisson 0.25, a/b = 1: C11 = 4.12, C22 = 3.67
        assert!((kalker_c11(1.0) - 4.12).abs() / 4.12 < 0.04);
        assert!((kalker_c22(1.0) - 3.67).abs() / 3.67 < 0.02);
        // b/a = 0.5 (long ellipse): Kalker C11 = 5.10, C22 = 4.90
        assert!((kalker_c11(0.5) - 5.10).abs() / 5.10 < 0.05);
        assert!((kalker_c22(0.5) - 4.90).abs() / 4.90 < 0.05);
    }

    #[test]
    fn elliptic_integrals() {
        let (k, e) = elliptic_ke(0.0);
        assert!((k - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
        assert!((e - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
        // k = 0.5: K = 1.685750354812596, E = 1.467462209339427
        let (k, e) = elliptic_ke(0.5);
        assert!((k - 1.685_750_354_812_596).abs() < 1e-10);
        assert!((e - 1.467_462_209_339_427).abs() < 1e-10);
    }

    #[test]
    fn hertz_gives_creep_coefficients_of_order_10_mn() {
        let hk = hertz_kalker(70e3, 0.46, 0.3, 210e9, 0.28);
        // contact patch of a few mm, longer in rolling direction
        assert!(hk.a_m > hk.b_m && hk.a_m > 4e-3 && hk.a_m < 9e-3, "{hk:?}");
        assert!(hk.f11_n > 9e6 && hk.f11_n < 14e6, "{hk:?}");
        assert!(hk.f22_n > 8e6 && hk.f22_n < 13e6, "{hk:?}");
    }

    #[test]
    fn saturation_law() {
        // small force: unchanged; u = 3: fully saturated at mu P
        assert!((saturation_factor(1e-9, 1.0) - 1.0).abs() < 1e-8);
        assert!((saturation_factor(3.0, 1.0) * 3.0 - 1.0).abs() < 1e-12);
        assert!((saturation_factor(10.0, 1.0) * 10.0 - 1.0).abs() < 1e-12);
        // equals 1 - (1 - tau)^3 with tau = u/3 (5.24)
        for &u in &[0.3_f64, 1.0, 2.2] {
            let tau = u / 3.0;
            let f = 1.0 - (1.0 - tau).powi(3);
            assert!((saturation_factor(u, 1.0) * u - f).abs() < 1e-12);
        }
    }
}
