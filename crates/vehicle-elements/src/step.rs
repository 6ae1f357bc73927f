//! Checks of what a host hands a model's step: the communication step and the inputs, with
//! the error that names the offending input.

use serde::{de::DeserializeOwned, Serialize};

use model_description::FieldError;

/// The largest communication step a model accepts [s].
pub const MAX_STEP_S: f64 = 1.0;

/// A step refused before it starts; the model is unchanged.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum InputError {
    /// An input is NaN or infinite.
    #[error("input `{name}` is not finite ({value})")]
    NonFiniteInput {
        /// Input name (physics field).
        name: &'static str,
        /// Value.
        value: f64,
    },
    /// Step size not usable.
    #[error("invalid communication step {h} s (must be finite, > 0 and <= 1 s)")]
    InvalidStep {
        /// Step [s].
        h: f64,
    },
}

/// `h` [s] is finite, > 0 and <= [`MAX_STEP_S`].
pub fn check_step(h: f64) -> Result<(), InputError> {
    if h.is_finite() && h > 0.0 && h <= MAX_STEP_S {
        Ok(())
    } else {
        Err(InputError::InvalidStep { h })
    }
}

/// Every `(name, value)` is finite; the error names the first that is not.
pub fn check_inputs(
    inputs: impl IntoIterator<Item = (&'static str, f64)>,
) -> Result<(), InputError> {
    for (name, value) in inputs {
        if !value.is_finite() {
            return Err(InputError::NonFiniteInput { name, value });
        }
    }
    Ok(())
}

/// One host communication step of `step_s` on a model's physics, whatever its length: up to
/// [`MAX_STEP_S`] one physics step in place (the physics leaves itself unchanged when a step
/// fails), longer ones in equal sub-steps of at most that on a copy, committed only when every
/// sub-step succeeded. Returns the outputs at the end of the step.
pub fn host_step<P: Clone, O, E>(
    physics: &mut P,
    step_s: f64,
    mut step: impl FnMut(&mut P, f64) -> Result<O, E>,
) -> Result<O, E> {
    if step_s <= MAX_STEP_S {
        return step(physics, step_s);
    }
    let n = (step_s / MAX_STEP_S).ceil() as usize;
    let h = step_s / n as f64;
    let mut next = physics.clone();
    let mut out = step(&mut next, h)?;
    for _ in 1..n {
        out = step(&mut next, h)?;
    }
    *physics = next;
    Ok(out)
}

/// A bad input is reported under the FMI variable bound to the input it names.
impl FieldError for InputError {
    fn field(&self) -> Option<&str> {
        match self {
            InputError::NonFiniteInput { name, .. } => Some(name),
            InputError::InvalidStep { .. } => None,
        }
    }

    fn reason(&self) -> String {
        match self {
            InputError::NonFiniteInput { value, .. } => format!("not finite ({value})"),
            other => other.to_string(),
        }
    }
}

/// Shortest internal sub-step the vehicle models accept [s]. Their sub-step follows their
/// fastest dynamics (creep decay, contact and suspension frequencies); parameters that need a
/// shorter one are outside any vehicle's range (a mass of a few ulps, a stiffness of 1e300), and
/// would make a 1 ms step take longer than any host waits.
pub const MIN_SUBSTEP_S: f64 = 1e-7;

/// The parameters need a shorter internal step than [`MIN_SUBSTEP_S`].
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{}{}", .parameter.as_ref().map(|p| format!("`{p}`: ")).unwrap_or_default(), self.reason())]
pub struct TooStiff {
    /// The sub-step the dynamics need [s] (NaN when the parameters give no rate at all).
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

    #[test]
    fn a_long_host_step_is_split_and_committed_only_whole() {
        // the "physics": a clock that refuses to pass t = 2.5 s
        let step = |t: &mut f64, h: f64| {
            if *t + h > 2.5 {
                Err(*t + h)
            } else {
                *t += h;
                Ok(*t)
            }
        };
        let mut t = 0.0;
        assert_eq!(host_step(&mut t, 0.5, step), Ok(0.5));
        // 1.5 s: two sub-steps of 0.75 s
        assert_eq!(host_step(&mut t, 1.5, step), Ok(2.0));
        // 3 s fails in its first sub-step: nothing changes
        assert_eq!(host_step(&mut t, 3.0, step), Err(3.0));
        assert_eq!(t, 2.0);
    }

    #[test]
    fn step_and_inputs_are_checked_with_the_name() {
        assert_eq!(check_step(1.0), Ok(()));
        for h in [0.0, -1e-3, 1.5, f64::NAN] {
            assert!(
                matches!(check_step(h), Err(InputError::InvalidStep { .. })),
                "{h}"
            );
        }
        assert_eq!(check_inputs([("a", 1.0), ("b", 2.0)]), Ok(()));
        let e = check_inputs([("a", 1.0), ("b", f64::INFINITY), ("c", f64::NAN)]).unwrap_err();
        assert_eq!(e.field(), Some("b"));
        assert_eq!(e.reason(), "not finite (inf)");
        assert_eq!(e.to_string(), "input `b` is not finite (inf)");
        assert_eq!(check_step(2.0).unwrap_err().field(), None);
    }
}
