//! The search for a linear critical speed that both models' eigen-analyses run: a scan upwards
//! from a stable speed, then a bisection of the first interval whose upper end is unstable.

/// Where the search found the boundary.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Crossing {
    /// Unstable already at the lower end of the range.
    UnstableAtStart,
    /// Stable over the whole range.
    None,
    /// The lowest unstable speed found, within the bisection's tolerance of the boundary.
    At(f64),
}

/// Finds the first speed in `[lo, hi]` where `unstable` holds: scan in `scan_step` increments
/// from `lo` (the last one ends at `hi`), then bisect the first unstable interval until it is
/// narrower than `tolerance`. Returns the interval's upper (unstable) end. `unstable` is
/// evaluated at `lo` first, then in increasing order of the scan; its first error ends the
/// search. The range must satisfy `lo < hi`, both finite, and `scan_step`, `tolerance` > 0.
pub fn first_unstable_speed<E>(
    lo: f64,
    hi: f64,
    scan_step: f64,
    tolerance: f64,
    mut unstable: impl FnMut(f64) -> Result<bool, E>,
) -> Result<Crossing, E> {
    if unstable(lo)? {
        return Ok(Crossing::UnstableAtStart);
    }
    let mut a = lo;
    let n = ((hi - lo) / scan_step).ceil() as usize;
    let mut b = None;
    for i in 1..=n {
        let v = (lo + i as f64 * scan_step).min(hi);
        if unstable(v)? {
            b = Some(v);
            break;
        }
        a = v;
    }
    let Some(mut b) = b else {
        return Ok(Crossing::None);
    };
    while b - a > tolerance {
        let mid = 0.5 * (a + b);
        if unstable(mid)? {
            b = mid;
        } else {
            a = mid;
        }
    }
    Ok(Crossing::At(b))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn search(boundary: f64, lo: f64, hi: f64) -> Crossing {
        first_unstable_speed(lo, hi, 0.5, 1e-6, |v| Ok::<_, ()>(v >= boundary))
            .unwrap_or(Crossing::None)
    }

    #[test]
    fn finds_the_boundary_within_the_tolerance_from_above() {
        let Crossing::At(b) = search(73.123_456_7, 10.0, 200.0) else {
            panic!("no crossing")
        };
        assert!(b >= 73.123_456_7 && b - 73.123_456_7 <= 1e-6, "{b}");
    }

    #[test]
    fn reports_a_range_that_starts_unstable_or_never_becomes_unstable() {
        assert_eq!(search(5.0, 10.0, 200.0), Crossing::UnstableAtStart);
        assert_eq!(search(300.0, 10.0, 200.0), Crossing::None);
        // the last scan point is the range's end, even off the scan grid
        assert!(matches!(search(199.9, 10.0, 199.95), Crossing::At(b) if b > 199.9));
    }

    #[test]
    fn the_first_error_ends_the_search() {
        let mut calls = 0;
        let r = first_unstable_speed(10.0, 20.0, 1.0, 1e-6, |v| {
            calls += 1;
            if v > 12.5 {
                Err("failed")
            } else {
                Ok(false)
            }
        });
        assert_eq!(r, Err("failed"));
        assert_eq!(calls, 4); // the lower end 10, then 11, 12 and 13, which fails
    }
}
