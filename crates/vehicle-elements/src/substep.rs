//! The shortest internal sub-step the vehicle models accept, and which parameter to blame when
//! a parameter set needs a shorter one.

use serde::{de::DeserializeOwned, Serialize};

/// Shortest internal sub-step the vehicle models accept \[s\]. Their sub-step follows their
/// fastest dynamics (creep decay, contact and suspension frequencies); parameters that need a
/// shorter one are outside any vehicle's range (a mass of a few ulps, a stiffness of 1e300), and
/// would make a 1 ms step take longer than any host waits.
pub const MIN_SUBSTEP_S: f64 = 1e-7;

/// The parameters need a shorter internal step than [`MIN_SUBSTEP_S`].
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{}{}", .parameter.as_ref().map(|p| format!("`{p}`: ")).unwrap_or_default(), self.reason())]
pub struct TooStiff {
    /// The sub-step the dynamics need \[s\] (NaN when the parameters give no rate at all).
    pub substep_s: f64,
    /// The parameter to blame (dotted field of the parameter struct, see [`blame_substep`]).
    pub parameter: Option<String>,
}

impl TooStiff {
    /// What is wrong, without the parameter's name.
    pub fn reason(&self) -> String {
        format!(
            "the parameters need internal steps of {:e} s to stay stable, shorter than {:e} s: \
             a mass, an inertia, a stiffness or a creep coefficient is outside any vehicle's \
             range",
            self.substep_s, MIN_SUBSTEP_S
        )
    }
}

/// The parameter that makes the sub-step too short: of the numbers in `params` that differ
/// from `defaults`, the one whose default value alone gives the longest sub-step (its path in
/// the parameter struct, `wheelset.mass_kg`). Only on the error path: it rebuilds the sub-step
/// once per changed number.
pub fn blame_substep<P: Serialize + DeserializeOwned>(
    params: &P,
    defaults: &P,
    substep_s: impl Fn(&P) -> f64,
) -> Option<String> {
    blame(params, defaults, substep_s)
}

/// The parameter to blame for a condition measured by `score` (larger is better): of the
/// numbers in `params` that differ from `defaults`, the one whose default value alone gives the
/// largest finite score (its path in the parameter struct). Only on an error path: it
/// evaluates `score` once per changed number.
pub fn blame<P: Serialize + DeserializeOwned>(
    params: &P,
    defaults: &P,
    score: impl Fn(&P) -> f64,
) -> Option<String> {
    let substep_s = score;
    let given = serde_json::to_value(params).ok()?;
    let default = serde_json::to_value(defaults).ok()?;
    let mut changed = Vec::new();
    changed_numbers(&given, &default, &mut Vec::new(), &mut changed);
    let mut best: Option<(f64, String)> = None;
    for path in changed {
        let mut candidate = given.clone();
        let (Some(slot), Some(value)) =
            (pointer_mut(&mut candidate, &path), pointer(&default, &path))
        else {
            continue;
        };
        *slot = value.clone();
        let Ok(p) = serde_json::from_value::<P>(candidate) else {
            continue;
        };
        let h = substep_s(&p);
        if h.is_finite() && best.as_ref().is_none_or(|(b, _)| h > *b) {
            best = Some((h, path.join(".")));
        }
    }
    best.map(|(_, path)| path)
}

/// Paths of the numbers of `given` that differ from `default` (same shape: both serialise the
/// same struct).
fn changed_numbers(
    given: &serde_json::Value,
    default: &serde_json::Value,
    path: &mut Vec<String>,
    out: &mut Vec<Vec<String>>,
) {
    use serde_json::Value;
    match (given, default) {
        (Value::Object(g), Value::Object(d)) => {
            for (k, gv) in g {
                if let Some(dv) = d.get(k) {
                    path.push(k.clone());
                    changed_numbers(gv, dv, path, out);
                    path.pop();
                }
            }
        }
        (Value::Number(g), Value::Number(d)) if g != d => out.push(path.clone()),
        _ => {}
    }
}

fn pointer<'a>(v: &'a serde_json::Value, path: &[String]) -> Option<&'a serde_json::Value> {
    path.iter().try_fold(v, |v, k| v.get(k))
}

fn pointer_mut<'a>(
    v: &'a mut serde_json::Value,
    path: &[String],
) -> Option<&'a mut serde_json::Value> {
    path.iter().try_fold(v, |v, k| v.get_mut(k))
}

/// `substep_s`, the sub-step the caller computed for `params`, if it is at least
/// [`MIN_SUBSTEP_S`]; otherwise the error, with the parameter to blame against `P::default()`
/// (see [`blame_substep`]; `substep_of` computes the sub-step of a parameter set, and runs only
/// on that error path).
pub fn stable_substep<P: Serialize + DeserializeOwned + Default>(
    params: &P,
    substep_s: f64,
    substep_of: impl Fn(&P) -> f64,
) -> Result<f64, TooStiff> {
    check_substep(substep_s).map_err(|mut e| {
        e.parameter = blame_substep(params, &P::default(), &substep_of);
        e
    })?;
    Ok(substep_s)
}

/// `substep_s` is at least [`MIN_SUBSTEP_S`] (and a number).
pub fn check_substep(substep_s: f64) -> Result<(), TooStiff> {
    if substep_s >= MIN_SUBSTEP_S {
        Ok(())
    } else {
        Err(TooStiff {
            substep_s,
            parameter: None,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde::Deserialize;

    #[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
    struct Body {
        mass_kg: f64,
        stiffness_n_per_m: f64,
    }

    #[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
    struct Toy {
        body: Body,
        speed_mps: f64,
        name: String,
    }

    fn toy() -> Toy {
        Toy {
            body: Body {
                mass_kg: 100.0,
                stiffness_n_per_m: 1e6,
            },
            speed_mps: 50.0,
            name: "toy".into(),
        }
    }

    /// Half a period of the toy's spring-mass.
    fn substep(t: &Toy) -> f64 {
        (t.body.mass_kg / t.body.stiffness_n_per_m).sqrt()
    }

    #[test]
    fn the_changed_value_whose_default_restores_the_step_is_blamed() {
        let mut t = toy();
        t.body.stiffness_n_per_m = 1e300;
        t.speed_mps = 80.0; // changed too, but not the cause
        t.name = "other".into();
        assert!(check_substep(substep(&t)).is_err());
        let blamed = blame_substep(&t, &toy(), substep);
        assert_eq!(blamed.as_deref(), Some("body.stiffness_n_per_m"));
        let e = TooStiff {
            substep_s: substep(&t),
            parameter: blamed,
        };
        assert!(
            e.to_string().starts_with(
                "`body.stiffness_n_per_m`: the parameters need internal steps of 1e-149 s"
            ),
            "{e}"
        );
    }

    #[test]
    fn nothing_is_blamed_when_nothing_numeric_changed() {
        let mut t = toy();
        t.name = "other".into();
        assert_eq!(blame_substep(&t, &toy(), substep), None);
        check_substep(substep(&toy())).unwrap();
        assert!(check_substep(f64::NAN).is_err());
    }
}
