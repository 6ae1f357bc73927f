//! Critical speed from an rms-versus-speed curve (pure logic, no simulation).
//!
//! The critical speed of a configuration is the first speed of the sweep at which the EN 14363
//! rms (the maximum over wheelsets and track seeds) exceeds the limit. It is then refined by
//! bisection between the last stable and the first unstable speed: each round runs the
//! midpoint (all seeds) and keeps the half that still brackets the change. A speed at which a
//! run failed (e.g. the bogie model left its contact table) counts as unstable: the study
//! cannot show it is stable there; the report lists such runs.

/// One point of a curve: speed [km/h] and rms over all seeds (`None`: a run failed).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct CurvePoint {
    pub speed_kmh: f64,
    pub rms: Option<f64>,
}

impl CurvePoint {
    pub fn unstable(&self, limit: f64) -> bool {
        !matches!(self.rms, Some(r) if r <= limit)
    }
}

/// Where the limit is crossed.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub enum Critical {
    /// Limit not exceeded at any speed up to `max_kmh`.
    Above { max_kmh: f64 },
    /// Limit already exceeded at the lowest speed `min_kmh`.
    Below { min_kmh: f64 },
    /// Stable at `stable_kmh`, unstable at `unstable_kmh` (adjacent speeds).
    Between { stable_kmh: f64, unstable_kmh: f64 },
}

impl Critical {
    /// From a curve (any order): the first exceedance by speed.
    pub fn from_curve(points: &[CurvePoint], limit: f64) -> Option<Critical> {
        let mut p: Vec<CurvePoint> = points.to_vec();
        p.sort_by(|a, b| a.speed_kmh.total_cmp(&b.speed_kmh));
        let first = p.first()?;
        match p.iter().position(|x| x.unstable(limit)) {
            None => Some(Critical::Above {
                max_kmh: p[p.len() - 1].speed_kmh,
            }),
            Some(0) => Some(Critical::Below {
                min_kmh: first.speed_kmh,
            }),
            Some(i) => Some(Critical::Between {
                stable_kmh: p[i - 1].speed_kmh,
                unstable_kmh: p[i].speed_kmh,
            }),
        }
    }

    /// Next speed to evaluate if the bracket is still wider than `tol_kmh` (rounded to 0.1).
    pub fn midpoint(&self, tol_kmh: f64) -> Option<f64> {
        match *self {
            Critical::Between {
                stable_kmh,
                unstable_kmh,
            } if unstable_kmh - stable_kmh > tol_kmh => {
                let m = ((stable_kmh + unstable_kmh) / 2.0 * 10.0).round() / 10.0;
                (m > stable_kmh && m < unstable_kmh).then_some(m)
            }
            _ => None,
        }
    }

    /// The bracket after evaluating `speed_kmh` (`unstable` = limit exceeded there).
    pub fn refine(self, speed_kmh: f64, unstable: bool) -> Critical {
        match self {
            Critical::Between {
                stable_kmh,
                unstable_kmh,
            } if speed_kmh > stable_kmh && speed_kmh < unstable_kmh => {
                if unstable {
                    Critical::Between {
                        stable_kmh,
                        unstable_kmh: speed_kmh,
                    }
                } else {
                    Critical::Between {
                        stable_kmh: speed_kmh,
                        unstable_kmh,
                    }
                }
            }
            other => other,
        }
    }

    /// The critical speed as a number: the first unstable speed; `None` above the range.
    pub fn speed_kmh(&self) -> Option<f64> {
        match *self {
            Critical::Above { .. } => None,
            Critical::Below { min_kmh } => Some(min_kmh),
            Critical::Between { unstable_kmh, .. } => Some(unstable_kmh),
        }
    }

    /// A lower bound that is always defined (the range end when stable throughout).
    pub fn at_least_kmh(&self) -> f64 {
        match *self {
            Critical::Above { max_kmh } => max_kmh,
            Critical::Below { min_kmh } => min_kmh,
            Critical::Between { unstable_kmh, .. } => unstable_kmh,
        }
    }

    /// Text for the report, e.g. "287.5 (stable at 285.0)", "> 400", "<= 200".
    pub fn describe(&self) -> String {
        match *self {
            Critical::Above { max_kmh } => format!("> {max_kmh:.0}"),
            Critical::Below { min_kmh } => format!("<= {min_kmh:.0}"),
            Critical::Between {
                stable_kmh,
                unstable_kmh,
            } => format!("{unstable_kmh:.1} (stable at {stable_kmh:.1})"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn curve(v: &[(f64, f64)]) -> Vec<CurvePoint> {
        v.iter()
            .map(|&(s, r)| CurvePoint {
                speed_kmh: s,
                rms: Some(r),
            })
            .collect()
    }

    #[test]
    fn first_exceedance_brackets_and_bisection_converges() {
        let lim = 5.39;
        // unsorted input, a dip after the first exceedance is ignored
        let c = curve(&[(300.0, 7.0), (280.0, 2.0), (290.0, 6.0), (310.0, 4.0)]);
        let k = Critical::from_curve(&c, lim).unwrap();
        assert_eq!(
            k,
            Critical::Between {
                stable_kmh: 280.0,
                unstable_kmh: 290.0
            }
        );
        // bisection against a "true" critical speed of 283.3
        let truth = 283.3;
        let mut k = k;
        let mut rounds = 0;
        while let Some(m) = k.midpoint(2.0) {
            k = k.refine(m, m >= truth);
            rounds += 1;
        }
        assert_eq!(rounds, 3);
        let v = k.speed_kmh().unwrap();
        assert!(v >= truth && v - truth <= 2.0, "{k:?}");
        assert!(k.describe().starts_with("28"));
    }

    #[test]
    fn ends_of_the_range_and_failed_runs() {
        let lim = 5.39;
        let k = Critical::from_curve(&curve(&[(200.0, 1.0), (400.0, 5.0)]), lim).unwrap();
        assert_eq!(k, Critical::Above { max_kmh: 400.0 });
        assert_eq!(k.speed_kmh(), None);
        assert_eq!(k.describe(), "> 400");
        assert_eq!(k.midpoint(2.0), None);
        let k = Critical::from_curve(&curve(&[(200.0, 6.0), (210.0, 7.0)]), lim).unwrap();
        assert_eq!(k.speed_kmh(), Some(200.0));
        let mut c = curve(&[(200.0, 1.0), (210.0, 1.0), (220.0, 1.0)]);
        c[1].rms = None;
        let k = Critical::from_curve(&c, lim).unwrap();
        assert_eq!(k.speed_kmh(), Some(210.0));
        assert!(Critical::from_curve(&[], lim).is_none());
        // refine outside the bracket changes nothing
        let b = Critical::Between {
            stable_kmh: 1.0,
            unstable_kmh: 2.0,
        };
        assert_eq!(b.refine(5.0, true), b);
    }
}
