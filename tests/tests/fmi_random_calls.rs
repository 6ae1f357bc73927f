//! Property: whatever sequence of FMI calls a host makes, in any order and with any values
//! (unknown value references, NaN, infinities, huge numbers, several values per call with
//! repeats, empty calls with NULL arrays, steps from the wrong time, FMU states got, set, freed
//! and serialised at any point), every packaged FMU answers each call
//! with a defined status, never aborts or hangs, and whatever fmi2GetReal returns with
//! fmi2OK or fmi2Warning is finite. Through the real C ABI of dist/*.fmu, as a third-party
//! host would call it.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::ffi::{c_char, CString};

use proptest::prelude::*;
use proptest::test_runner::{Config, TestCaseError, TestRunner};
use tests::*;

/// The FMI base type of a variable, from its modelDescription element.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Kind {
    Real,
    Integer,
    Boolean,
    String,
}

#[derive(Debug, Clone)]
struct Variable {
    vr: u32,
    kind: Kind,
}

fn attribute(element: &str, key: &str) -> Option<String> {
    let start = element.find(&format!(" {key}=\""))? + key.len() + 3;
    let end = element[start..].find('"')? + start;
    Some(element[start..end].to_string())
}

/// Every ScalarVariable of a modelDescription.xml (value reference and base type).
fn variables(model_description: &str) -> Vec<Variable> {
    model_description
        .split("<ScalarVariable")
        .skip(1)
        .filter_map(|v| {
            let element = &v[..v.find("</ScalarVariable>").unwrap_or(v.len())];
            let vr = attribute(element, "valueReference")?.parse().ok()?;
            let kind = if element.contains("<Real") {
                Kind::Real
            } else if element.contains("<Integer") || element.contains("<Enumeration") {
                Kind::Integer
            } else if element.contains("<Boolean") {
                Kind::Boolean
            } else if element.contains("<String") {
                Kind::String
            } else {
                return None;
            };
            Some(Variable { vr, kind })
        })
        .collect()
}

/// One host call; `var` picks a variable of the call's type or an unknown value reference.
#[derive(Debug, Clone)]
enum Call {
    Setup {
        start: f64,
        stop: Option<f64>,
    },
    EnterInit,
    ExitInit,
    SetReal {
        var: usize,
        value: f64,
    },
    SetInteger {
        var: usize,
        value: i32,
    },
    SetBoolean {
        var: usize,
        value: i32,
    },
    SetString {
        var: usize,
        value: usize,
    },
    /// fmi2SetReal of several values at once (repeats and unknown references possible), the
    /// values drawn from the same set as [`Call::SetReal`]'s
    SetReals {
        vars: Vec<usize>,
        values: Vec<f64>,
    },
    /// fmi2GetReal of several values at once, with the same finiteness check as GetAll
    GetReals {
        vars: Vec<usize>,
    },
    /// every get and set with no values and NULL arrays (legal: nothing to read or write)
    Empty,
    GetAll,
    DoStep {
        from_own_time: bool,
        t: f64,
        h: f64,
    },
    Reset,
    Terminate,
    GetState,
    SetState {
        slot: usize,
    },
    FreeState {
        slot: usize,
    },
    SerialiseRoundTrip {
        slot: usize,
    },
}

const STRINGS: [&str; 4] = ["", "x", "../../../../etc/passwd", "%s%n%s%n"];

fn real() -> impl Strategy<Value = f64> {
    prop_oneof![
        Just(0.0),
        Just(1.0),
        Just(-1.0),
        Just(1e-3),
        Just(80.0),
        Just(1e300),
        Just(-1e300),
        Just(f64::NAN),
        Just(f64::INFINITY),
        Just(f64::NEG_INFINITY),
        Just(1e-310),
        -1e4..1e4f64,
    ]
}

fn call() -> impl Strategy<Value = Call> {
    let var = any::<usize>();
    // weighted towards what keeps an instance running (steps from its own time, reads, Real
    // inputs), so that long runs in step mode are common; Reset and Terminate end them
    prop_oneof![
        1 => (prop_oneof![Just(0.0), Just(-1.0), Just(f64::NAN), 0.0..10.0f64],
         proptest::option::of(prop_oneof![Just(0.0), Just(0.05), Just(1e9), Just(f64::NAN)]))
            .prop_map(|(start, stop)| Call::Setup { start, stop }),
        1 => Just(Call::EnterInit),
        1 => Just(Call::ExitInit),
        4 => (var, real()).prop_map(|(var, value)| Call::SetReal { var, value }),
        1 => (var, prop_oneof![Just(0), Just(1), Just(-1), Just(2), Just(i32::MAX), Just(i32::MIN), any::<i32>()])
            .prop_map(|(var, value)| Call::SetInteger { var, value }),
        1 => (var, prop_oneof![Just(0), Just(1), Just(2), Just(-1)])
            .prop_map(|(var, value)| Call::SetBoolean { var, value }),
        1 => (var, 0..STRINGS.len() + 1).prop_map(|(var, value)| Call::SetString { var, value }),
        3 => Just(Call::GetAll),
        2 => (proptest::collection::vec(any::<usize>(), 1..8), proptest::collection::vec(real(), 8))
            .prop_map(|(vars, values)| Call::SetReals { vars, values }),
        2 => proptest::collection::vec(any::<usize>(), 1..8).prop_map(|vars| Call::GetReals { vars }),
        1 => Just(Call::Empty),
        2 => (any::<bool>(),
         prop_oneof![Just(0.0), Just(-1.0), Just(f64::NAN), 0.0..1.0f64],
         prop_oneof![Just(1e-3), Just(0.0), Just(-1e-3), Just(f64::NAN), Just(f64::INFINITY), Just(1e-12), Just(0.02)])
            .prop_map(|(from_own_time, t, h)| Call::DoStep { from_own_time, t, h }),
        6 => Just(Call::DoStep { from_own_time: true, t: 0.0, h: 1e-3 }),
        1 => Just(Call::Reset),
        1 => Just(Call::Terminate),
        1 => Just(Call::GetState),
        1 => (0usize..3).prop_map(|slot| Call::SetState { slot }),
        1 => (0usize..3).prop_map(|slot| Call::FreeState { slot }),
        1 => (0usize..3).prop_map(|slot| Call::SerialiseRoundTrip { slot }),
    ]
}

const STATUSES: [ffi::fmi2Status; 5] = [OK, WARNING, DISCARD, ERROR, ffi::fmi2Status_fmi2Fatal];

/// The worst of several calls' statuses, or the first that is not a defined fmi2Status (which
/// the caller then reports).
fn defined_or_first_undefined(statuses: &[ffi::fmi2Status]) -> ffi::fmi2Status {
    match statuses.iter().find(|s| !STATUSES.contains(s)) {
        Some(&undefined) => undefined,
        None => statuses.iter().copied().max().unwrap_or(OK),
    }
}

/// Runs one call sequence on a fresh instance; fails on an undefined status or a non-finite
/// Real read with fmi2OK or fmi2Warning.
fn run_sequence(fmu: &TestFmu, vars: &[Variable], calls: &[Call]) -> Result<(), TestCaseError> {
    let inst = fmu.instantiate("random").map_err(TestCaseError::fail)?;
    let (c, b) = (inst.component, inst.b());
    let of = |kind: Kind| -> Vec<u32> {
        vars.iter()
            .filter(|v| v.kind == kind)
            .map(|v| v.vr)
            .collect()
    };
    let (reals, integers, booleans, strings) = (
        of(Kind::Real),
        of(Kind::Integer),
        of(Kind::Boolean),
        of(Kind::String),
    );
    // one of the variables of a type, or one of two value references no variable has
    let pick = |vrs: &[u32], var: usize| -> u32 {
        let i = var % (vrs.len() + 2);
        vrs.get(i).copied().unwrap_or(u32::MAX - i as u32)
    };
    let long = "y".repeat(100_000);
    let mut time = 0.0f64;
    let mut states: Vec<ffi::fmi2FMUstate> = Vec::new();
    for (k, call) in calls.iter().enumerate() {
        let status;
        // SAFETY: every pointer passed below points to a live array of the count passed with it.
        unsafe {
            status = match *call {
                Call::Setup { start, stop } => {
                    let s = b.fmi2SetupExperiment(
                        c,
                        0,
                        0.0,
                        start,
                        i32::from(stop.is_some()),
                        stop.unwrap_or(0.0),
                    );
                    if s == OK {
                        time = start;
                    }
                    s
                }
                Call::EnterInit => b.fmi2EnterInitializationMode(c),
                Call::ExitInit => b.fmi2ExitInitializationMode(c),
                Call::SetReal { var, value } => b.fmi2SetReal(c, &pick(&reals, var), 1, &value),
                Call::SetInteger { var, value } => {
                    b.fmi2SetInteger(c, &pick(&integers, var), 1, &value)
                }
                Call::SetBoolean { var, value } => {
                    b.fmi2SetBoolean(c, &pick(&booleans, var), 1, &value)
                }
                Call::SetString { var, value } => {
                    let text = CString::new(STRINGS.get(value).copied().unwrap_or(&long)).unwrap();
                    let p: *const c_char = text.as_ptr();
                    b.fmi2SetString(c, &pick(&strings, var), 1, &p)
                }
                Call::SetReals {
                    ref vars,
                    ref values,
                } => {
                    let vrs: Vec<u32> = vars.iter().map(|&v| pick(&reals, v)).collect();
                    b.fmi2SetReal(c, vrs.as_ptr(), vrs.len(), values.as_ptr())
                }
                Call::GetReals { ref vars } => {
                    let vrs: Vec<u32> = vars.iter().map(|&v| pick(&reals, v)).collect();
                    let mut values = vec![f64::NAN; vrs.len()];
                    let s = b.fmi2GetReal(c, vrs.as_ptr(), vrs.len(), values.as_mut_ptr());
                    if (s == OK || s == WARNING) && values.iter().any(|x| !x.is_finite()) {
                        return Err(TestCaseError::fail(format!(
                            "call {k}: fmi2GetReal of {vrs:?} gave {values:?} with status {s}"
                        )));
                    }
                    s
                }
                Call::Empty => {
                    let (vr, null) = (std::ptr::null(), std::ptr::null_mut());
                    let statuses = [
                        b.fmi2GetReal(c, vr, 0, null),
                        b.fmi2GetInteger(c, vr, 0, null.cast()),
                        b.fmi2GetBoolean(c, vr, 0, null.cast()),
                        b.fmi2GetString(c, vr, 0, null.cast()),
                        b.fmi2SetReal(c, vr, 0, null),
                        b.fmi2SetInteger(c, vr, 0, null.cast()),
                        b.fmi2SetBoolean(c, vr, 0, null.cast()),
                        b.fmi2SetString(c, vr, 0, null.cast()),
                    ];
                    defined_or_first_undefined(&statuses)
                }
                Call::GetAll => {
                    let mut values = vec![f64::NAN; reals.len()];
                    let s = b.fmi2GetReal(c, reals.as_ptr(), reals.len(), values.as_mut_ptr());
                    if s == OK || s == WARNING {
                        if let Some(i) = values.iter().position(|x| !x.is_finite()) {
                            return Err(TestCaseError::fail(format!(
                                "call {k}: fmi2GetReal gave {} for value reference {} with status {s}",
                                values[i], reals[i]
                            )));
                        }
                    }
                    let mut ints = vec![0; integers.len()];
                    let si =
                        b.fmi2GetInteger(c, integers.as_ptr(), integers.len(), ints.as_mut_ptr());
                    let mut bools = vec![0; booleans.len()];
                    let sb =
                        b.fmi2GetBoolean(c, booleans.as_ptr(), booleans.len(), bools.as_mut_ptr());
                    let mut texts: Vec<ffi::fmi2String> = vec![std::ptr::null(); strings.len()];
                    let s2 =
                        b.fmi2GetString(c, strings.as_ptr(), strings.len(), texts.as_mut_ptr());
                    if s2 == OK && texts.iter().any(|t| t.is_null()) {
                        return Err(TestCaseError::fail(format!(
                            "call {k}: fmi2GetString gave NULL with fmi2OK"
                        )));
                    }
                    defined_or_first_undefined(&[s, si, sb, s2])
                }
                Call::DoStep {
                    from_own_time,
                    t,
                    h,
                } => {
                    let t = if from_own_time { time } else { t };
                    let s = b.fmi2DoStep(c, t, h, 1);
                    if s == OK || s == WARNING {
                        time = t + h;
                    }
                    s
                }
                Call::Reset => {
                    let s = b.fmi2Reset(c);
                    if s == OK {
                        time = 0.0;
                    }
                    s
                }
                Call::Terminate => b.fmi2Terminate(c),
                Call::GetState => {
                    let mut state: ffi::fmi2FMUstate = std::ptr::null_mut();
                    let s = b.fmi2GetFMUstate(c, &mut state);
                    if !state.is_null() {
                        states.push(state);
                    }
                    s
                }
                Call::SetState { slot } => match states.get(slot) {
                    // the time it restores is not tracked: later steps from "own time" may be
                    // refused, which is itself a sequence worth calling
                    Some(&state) => b.fmi2SetFMUstate(c, state),
                    None => b.fmi2SetFMUstate(c, std::ptr::null_mut()),
                },
                Call::FreeState { slot } => {
                    if slot < states.len() {
                        let mut state = states.remove(slot);
                        b.fmi2FreeFMUstate(c, &mut state)
                    } else {
                        let mut none: ffi::fmi2FMUstate = std::ptr::null_mut();
                        b.fmi2FreeFMUstate(c, &mut none)
                    }
                }
                Call::SerialiseRoundTrip { slot } => match states.get(slot) {
                    Some(&state) => {
                        let mut size = 0usize;
                        let s = b.fmi2SerializedFMUstateSize(c, state, &mut size);
                        if s != OK {
                            s
                        } else {
                            let mut bytes = vec![0 as c_char; size];
                            let s = b.fmi2SerializeFMUstate(c, state, bytes.as_mut_ptr(), size);
                            if s != OK {
                                s
                            } else {
                                let mut copy: ffi::fmi2FMUstate = std::ptr::null_mut();
                                let s =
                                    b.fmi2DeSerializeFMUstate(c, bytes.as_ptr(), size, &mut copy);
                                if !copy.is_null() {
                                    states.push(copy);
                                }
                                s
                            }
                        }
                    }
                    None => {
                        let mut size = 0usize;
                        b.fmi2SerializedFMUstateSize(c, std::ptr::null_mut(), &mut size)
                    }
                },
            };
        }
        if !STATUSES.contains(&status) {
            return Err(TestCaseError::fail(format!(
                "call {k} ({call:?}): undefined status {status}"
            )));
        }
    }
    for mut state in states {
        // SAFETY: states got from this instance and not freed yet.
        unsafe {
            b.fmi2FreeFMUstate(c, &mut state);
        }
    }
    Ok(())
}

/// Every FMU of dist/ against random call sequences; a case that hangs fails the test after
/// [`WATCHDOG`] instead of holding the test run (the stuck thread ends with the process).
#[test]
fn random_call_sequences_get_defined_answers_and_finite_reals_from_every_fmu() {
    let (done, finished) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let _ = done.send(std::panic::catch_unwind(every_fmu_against_random_calls));
    });
    match finished.recv_timeout(WATCHDOG) {
        Ok(Ok(())) => {}
        Ok(Err(panic)) => std::panic::resume_unwind(panic),
        Err(_) => panic!("a call sequence did not finish within {WATCHDOG:?}: an FMU hangs"),
    }
}

/// Far above the test's own time (a few seconds).
const WATCHDOG: std::time::Duration = std::time::Duration::from_secs(300);

fn every_fmu_against_random_calls() {
    let mut fmus: Vec<_> = std::fs::read_dir(workspace_root().join("dist"))
        .expect("dist/ (package the FMUs first)")
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "fmu"))
        .collect();
    fmus.sort();
    assert!(fmus.len() >= 9, "{fmus:?}");
    for path in fmus {
        let fmu = TestFmu::open(&path).unwrap();
        let vars = variables(&fmu.model_description);
        assert!(
            vars.iter().any(|v| v.kind == Kind::Real),
            "{}",
            path.display()
        );
        let mut runner = TestRunner::new(Config {
            cases: 300,
            failure_persistence: None,
            ..Config::default()
        });
        // half the sequences start initialised, so that stepping and states are reached often
        let sequence = (any::<bool>(), proptest::collection::vec(call(), 1..40)).prop_map(
            |(initialised, calls)| {
                let prefix = [
                    Call::Setup {
                        start: 0.0,
                        stop: None,
                    },
                    Call::EnterInit,
                    Call::ExitInit,
                ];
                let n = if initialised { prefix.len() } else { 0 };
                prefix[..n].iter().cloned().chain(calls).collect::<Vec<_>>()
            },
        );
        if let Err(e) = runner.run(&sequence, |calls| run_sequence(&fmu, &vars, &calls)) {
            panic!("{}: {e}", path.display());
        }
    }
}
