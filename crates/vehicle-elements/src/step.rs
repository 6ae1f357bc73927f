//! Checks of what a host hands a model's step: the communication step and the inputs, with
//! the error that names the offending input.

use model_description::FieldError;

/// The largest communication step a model's physics takes at once \[s\] (a longer host step is
/// split, see [`host_step`]).
pub const MAX_STEP_S: f64 = 1.0;

/// The longest communication step the rail-vehicle FMUs take in one call \[s\]
/// (`FmuModel::MAX_COMMUNICATION_STEP_S`): longer ones are discarded by the FMI glue rather
/// than computed for minutes while the host waits.
pub const MAX_HOST_STEP_S: f64 = 1000.0;

/// The most internal sub-steps one physics step of at most [`MAX_STEP_S`] takes: a 1 s step
/// at the smallest sub-step a model builds ([`crate::MIN_SUBSTEP_S`], 0.1 µs).
pub const MAX_SUBSTEPS: usize = 10_000_000;

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
        /// Step \[s\].
        h: f64,
    },
    /// The internal sub-step does not divide the step into at most [`MAX_SUBSTEPS`] parts (only
    /// a corrupted state has such a sub-step: a model refuses parameters that need a sub-step
    /// below [`crate::MIN_SUBSTEP_S`]).
    #[error(
        "internal sub-step {substep_s:?} s would split the step of {h:?} s into more than \
         {MAX_SUBSTEPS} parts"
    )]
    TooManySubsteps {
        /// Step \[s\].
        h: f64,
        /// Internal sub-step \[s\].
        substep_s: f64,
    },
}

/// `h` \[s\] is finite, > 0 and <= [`MAX_STEP_S`].
pub fn check_step(h: f64) -> Result<(), InputError> {
    if h.is_finite() && h > 0.0 && h <= MAX_STEP_S {
        Ok(())
    } else {
        Err(InputError::InvalidStep { h })
    }
}

/// The number of equal sub-steps of at most `substep_s` that make up `h` (at least one; a
/// sub-step within a billionth of dividing `h` counts as dividing it), at most [`MAX_SUBSTEPS`].
pub fn substep_count(h: f64, substep_s: f64) -> Result<usize, InputError> {
    let n = (h / substep_s - 1e-9).ceil().max(1.0);
    if substep_s > 0.0 && n <= MAX_SUBSTEPS as f64 {
        Ok(n as usize)
    } else {
        Err(InputError::TooManySubsteps { h, substep_s })
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
            InputError::InvalidStep { .. } | InputError::TooManySubsteps { .. } => None,
        }
    }

    fn reason(&self) -> String {
        match self {
            InputError::NonFiniteInput { value, .. } => format!("not finite ({value})"),
            other => other.to_string(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::MIN_SUBSTEP_S;

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
    fn the_substep_count_is_bounded_for_any_substep() {
        assert_eq!(substep_count(1e-3, 2.5e-4), Ok(4));
        // a sub-step dividing the step up to rounding gives no extra sliver
        assert_eq!(substep_count(1e-3, 1e-3 / 3.0), Ok(3));
        assert_eq!(substep_count(1e-3, 1.0), Ok(1));
        // the shortest sub-step a model builds fits a 1 s step, the bound is no tighter
        assert_eq!(substep_count(1.0, 1e-6), Ok(1_000_000));
        assert_eq!(substep_count(MAX_STEP_S, MIN_SUBSTEP_S), Ok(MAX_SUBSTEPS));
        assert!(substep_count(MAX_STEP_S, 0.99 * MIN_SUBSTEP_S).is_err());
        // what only a corrupted state holds: refused, never a loop of 1e297 sub-steps
        for substep_s in [1e-300, 0.0, -1e-3, f64::NAN] {
            assert!(
                matches!(
                    substep_count(1e-3, substep_s),
                    Err(InputError::TooManySubsteps { .. })
                ),
                "{substep_s}"
            );
        }
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
