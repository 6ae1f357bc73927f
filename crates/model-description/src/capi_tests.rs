//! The C boundary: a panic inside a call is caught, and the instance is then refused until
//! fmi2Reset instead of panicking again at every call.
#![allow(clippy::unwrap_used)]

use super::*;
use crate::model::{DefaultExperiment, ModelInfo, StepError};
use crate::{declare, rust_component, value_reference, CollectLog, Diagnostics, Variable};

/// x grows by u per step; a step with u < 0 panics (an invariant broken, as by a bad state).
#[derive(Clone, Debug, Serialize, Deserialize)]
struct Fragile {
    u: f64,
    x: f64,
    gain: f64,
}

impl FmuModel for Fragile {
    const INFO: ModelInfo = ModelInfo {
        name: "Fragile",
        description: "panics on a negative input",
        author: "test",
        version: "0",
        default_experiment: DefaultExperiment {
            start_time: 0.0,
            stop_time: 1.0,
            step_size: 0.1,
        },
        documentation_html: "",
        resources: &[],
    };

    fn variables() -> Vec<Variable<Self>> {
        let mut v: Vec<Variable<Self>> = Vec::new();
        declare! { v;
            /// Input
            input "u" => u;
            /// State
            output "x" => x;
            /// A parameter with a range
            parameter "gain" [range = 0.0..=10.0] => gain;
        }
        v
    }

    fn instantiate(_ctx: &InstanceContext) -> Result<Self, ModelError> {
        Ok(Fragile {
            u: 0.0,
            x: 0.0,
            gain: 1.0,
        })
    }

    fn exit_initialization(&mut self, _diag: &mut Diagnostics) -> Result<(), ModelError> {
        Ok(())
    }

    fn update_outputs(&mut self, _diag: &mut Diagnostics) -> Result<(), ModelError> {
        Ok(())
    }

    fn do_step(&mut self, _t: f64, _h: f64, _diag: &mut Diagnostics) -> Result<(), StepError> {
        let table = std::hint::black_box([1.0, 2.0]);
        // index out of bounds for u < 0: a panic in the middle of the physics
        let i = std::hint::black_box(if self.u < 0.0 { 7 } else { 0 });
        self.x += self.u * table[i];
        Ok(())
    }
}

/// A Fragile instance behind the C API, and its log.
fn fragile() -> (fmi2Component, CollectLog) {
    let (component, log) = rust_component::<Fragile>(InstanceContext::default()).unwrap();
    let c = Box::into_raw(Box::new(CComponent {
        component,
        serialized: None,
        booleans: Vec::new(),
    })) as fmi2Component;
    (c, log)
}

/// fmi2SetupExperiment from `start` and through initialisation.
unsafe fn start_at(c: fmi2Component, start: f64) {
    assert_eq!(setup_experiment(c, 0, 0.0, start, 0, 0.0), FMI2_OK);
    assert_eq!(enter_initialization_mode(c), FMI2_OK);
    assert_eq!(exit_initialization_mode(c), FMI2_OK);
}

#[test]
fn a_panic_is_an_error_and_leaves_the_instance_in_the_error_state_until_reset() {
    let (c, log) = fragile();
    let u = [value_reference::<Fragile>("u").unwrap()];
    let start = |c| unsafe { start_at(c, 0.0) };
    unsafe {
        start(c);
        assert_eq!(set_real(c, u.as_ptr(), 1, [1.0].as_ptr()), FMI2_OK);
        assert_eq!(do_step(c, 0.0, 0.1), FMI2_OK);
        assert_eq!(set_real(c, u.as_ptr(), 1, [-1.0].as_ptr()), FMI2_OK);
        assert_eq!(do_step(c, 0.1, 0.1), FMI2_ERROR);
        let first: Vec<String> = log.take().into_iter().map(|(_, _, m)| m).collect();
        assert!(
            first.iter().any(|m| m.contains("panic caught")),
            "{first:?}"
        );
        // refused without running the physics again, even with a sane input
        assert_eq!(set_real(c, u.as_ptr(), 1, [1.0].as_ptr()), FMI2_ERROR);
        assert_eq!(do_step(c, 0.1, 0.1), FMI2_ERROR);
        // the getters still answer in the Error state (for the host's diagnosis)
        let x = [value_reference::<Fragile>("x").unwrap()];
        let mut value = [f64::NAN];
        assert_eq!(get_real(c, x.as_ptr(), 1, value.as_mut_ptr()), FMI2_OK);
        assert_eq!(value, [1.0]);
        let later: Vec<String> = log.take().into_iter().map(|(_, _, m)| m).collect();
        assert!(!later.iter().any(|m| m.contains("panic")), "{later:?}");
        assert!(later.iter().any(|m| m.contains("Error")), "{later:?}");
        // fmi2Reset gives a fresh instance that steps again
        assert_eq!(reset(c), FMI2_OK);
        start(c);
        assert_eq!(set_real(c, u.as_ptr(), 1, [1.0].as_ptr()), FMI2_OK);
        assert_eq!(do_step(c, 0.0, 0.1), FMI2_OK);
        free_instance(c);
    }
}

/// The bytes fmi2SerializeFMUstate gives for `state` (size asked first).
unsafe fn serialise(c: fmi2Component, state: fmi2FMUstate) -> Vec<u8> {
    let mut size = 0usize;
    assert_eq!(serialized_fmu_state_size(c, state, &mut size), FMI2_OK);
    let mut bytes = vec![0u8; size];
    assert_eq!(
        serialize_fmu_state(c, state, bytes.as_mut_ptr().cast(), size),
        FMI2_OK
    );
    bytes
}

#[test]
fn a_state_updated_in_place_serialises_its_new_content_and_an_overflowing_step_is_refused() {
    let (c, _log) = fragile();
    let u = [value_reference::<Fragile>("u").unwrap()];
    unsafe {
        start_at(c, 0.0);
        let mut state: fmi2FMUstate = std::ptr::null_mut();
        assert_eq!(get_fmu_state(c, &mut state), FMI2_OK);
        let mut size = 0usize;
        // the size is asked first (the bytes are computed then), the state updated after
        assert_eq!(serialized_fmu_state_size(c, state, &mut size), FMI2_OK);
        let at_start = serialise(c, state);
        assert_eq!(set_real(c, u.as_ptr(), 1, [1.0].as_ptr()), FMI2_OK);
        assert_eq!(do_step(c, 0.0, 0.1), FMI2_OK);
        // size asked (bytes computed from the old content), state updated, then serialised
        // without asking the size again: the host's usual order
        assert_eq!(serialized_fmu_state_size(c, state, &mut size), FMI2_OK);
        assert_eq!(get_fmu_state(c, &mut state), FMI2_OK);
        let mut bytes = vec![0u8; size];
        assert_eq!(
            serialize_fmu_state(c, state, bytes.as_mut_ptr().cast(), size),
            FMI2_OK
        );
        assert_ne!(
            bytes, at_start,
            "the serialised bytes are those of the old state"
        );
        assert_eq!(bytes, serialise(c, state));
        assert_eq!(free_fmu_state(c, &mut state), FMI2_OK);
        free_instance(c);
    }
    // a step whose end overflows is refused as an argument, and the instance steps on
    let (c, _log) = fragile();
    unsafe {
        start_at(c, 1.7e308);
        assert_eq!(do_step(c, 1.7e308, 1e308), FMI2_ERROR);
        assert_eq!(do_step(c, 1.7e308, 1e300), FMI2_OK);
        free_instance(c);
    }
}

#[test]
fn a_deserialised_state_with_a_parameter_out_of_its_range_is_refused() {
    let (c, log) = fragile();
    let gain = [value_reference::<Fragile>("gain").unwrap()];
    let marker = 0.123_456_789_f64;
    unsafe {
        assert_eq!(setup_experiment(c, 0, 0.0, 0.0, 0, 0.0), FMI2_OK);
        assert_eq!(enter_initialization_mode(c), FMI2_OK);
        assert_eq!(set_real(c, gain.as_ptr(), 1, [marker].as_ptr()), FMI2_OK);
        assert_eq!(exit_initialization_mode(c), FMI2_OK);
        let mut state: fmi2FMUstate = std::ptr::null_mut();
        assert_eq!(get_fmu_state(c, &mut state), FMI2_OK);
        let bytes = serialise(c, state);
        let deserialise = |bytes: &[u8]| {
            let mut restored: fmi2FMUstate = std::ptr::null_mut();
            let status =
                deserialize_fmu_state(c, bytes.as_ptr().cast(), bytes.len(), &mut restored);
            if !restored.is_null() {
                assert_eq!(free_fmu_state(c, &mut restored), FMI2_OK);
            }
            status
        };
        assert_eq!(deserialise(&bytes), FMI2_OK);
        // the same bytes with the parameter's value altered
        let at = bytes
            .windows(8)
            .position(|w| w == marker.to_le_bytes())
            .unwrap();
        for (bad, shown) in [(-5.0_f64, "-5.0"), (1e300, "1e300")] {
            let mut altered = bytes.clone();
            altered[at..at + 8].copy_from_slice(&bad.to_le_bytes());
            // as altered: its checksum no longer matches
            assert_eq!(deserialise(&altered), FMI2_ERROR);
            assert!(log
                .take()
                .iter()
                .any(|(_, _, m)| m.contains("their checksum does not match")));
            // forged with a matching checksum: the value's own check names it
            let n = altered.len() - 4;
            altered.truncate(n);
            crate::state_bytes::seal(&mut altered);
            assert_eq!(deserialise(&altered), FMI2_ERROR);
            let expected = format!("'gain' = {shown} is outside its range");
            assert!(
                log.take().iter().any(|(_, _, m)| m.contains(&expected)),
                "{expected}"
            );
        }
        // refused, nothing changed: the instance steps on
        assert_eq!(do_step(c, 0.0, 0.1), FMI2_OK);
        assert_eq!(free_fmu_state(c, &mut state), FMI2_OK);
        free_instance(c);
    }
}

#[test]
fn a_panic_is_reported_with_its_message() {
    let (c, log) = fragile();
    let u = [value_reference::<Fragile>("u").unwrap()];
    unsafe {
        start_at(c, 0.0);
        assert_eq!(set_real(c, u.as_ptr(), 1, [-1.0].as_ptr()), FMI2_OK);
        assert_eq!(do_step(c, 0.0, 0.1), FMI2_ERROR);
        free_instance(c);
    }
    let messages: Vec<String> = log.take().into_iter().map(|(_, _, m)| m).collect();
    assert!(
        messages
            .iter()
            .any(|m| m.contains("panic caught at the C boundary: index out of bounds")),
        "{messages:?}"
    );
}

#[test]
fn a_step_below_the_time_resolution_is_refused_not_taken_as_done() {
    let (c, log) = fragile();
    let u = [value_reference::<Fragile>("u").unwrap()];
    let x = [value_reference::<Fragile>("x").unwrap()];
    unsafe {
        start_at(c, 1e15);
        assert_eq!(set_real(c, u.as_ptr(), 1, [1.0].as_ptr()), FMI2_OK);
        // 1e15 + 1e-3 == 1e15: the step would not advance time
        assert_eq!(do_step(c, 1e15, 1e-3), FMI2_ERROR);
        let messages: Vec<String> = log.take().into_iter().map(|(_, _, m)| m).collect();
        assert!(
            messages
                .iter()
                .any(|m| m.contains("is below the time resolution at t = 1000000000000000.0 s")),
            "{messages:?}"
        );
        let mut t = f64::NAN;
        assert_eq!(
            get_real_status(c, ffi::fmi2StatusKind_fmi2LastSuccessfulTime, &mut t),
            FMI2_OK
        );
        assert_eq!(t, 1e15);
        free_instance(c);
    }
    // a step that advances time at that point is taken (an ulp of 1e15 is 0.125)
    let (c, _log) = fragile();
    unsafe {
        start_at(c, 1e15);
        assert_eq!(set_real(c, u.as_ptr(), 1, [1.0].as_ptr()), FMI2_OK);
        assert_eq!(do_step(c, 1e15, 0.125), FMI2_OK);
        let mut value = [f64::NAN];
        assert_eq!(get_real(c, x.as_ptr(), 1, value.as_mut_ptr()), FMI2_OK);
        assert_eq!(value, [1.0]);
        // a zero step stays allowed
        assert_eq!(do_step(c, 1e15 + 0.125, 0.0), FMI2_OK);
        free_instance(c);
    }
}

#[test]
fn status_queries_are_refused_before_the_first_step_as_the_state_machine_says() {
    let (c, _log) = fragile();
    unsafe {
        let query = |c| {
            let mut t = f64::NAN;
            let mut b: fmi2Boolean = 7;
            (
                get_real_status(c, ffi::fmi2StatusKind_fmi2LastSuccessfulTime, &mut t),
                get_boolean_status(c, ffi::fmi2StatusKind_fmi2Terminated, &mut b),
            )
        };
        // instantiated, initialisation mode: refused
        assert_eq!(query(c), (FMI2_ERROR, FMI2_ERROR));
        assert_eq!(setup_experiment(c, 0, 0.0, 0.0, 0, 0.0), FMI2_OK);
        assert_eq!(enter_initialization_mode(c), FMI2_OK);
        assert_eq!(query(c), (FMI2_ERROR, FMI2_ERROR));
        assert_eq!(exit_initialization_mode(c), FMI2_OK);
        // step mode and terminated: answered
        assert_eq!(query(c), (FMI2_OK, FMI2_OK));
        assert_eq!(terminate(c), FMI2_OK);
        assert_eq!(query(c), (FMI2_OK, FMI2_OK));
        free_instance(c);
    }
}

#[test]
fn a_read_with_an_unknown_value_reference_leaves_the_hosts_array_untouched() {
    let (c, _log) = fragile();
    let x = value_reference::<Fragile>("x").unwrap();
    unsafe {
        start_at(c, 0.0);
        let vrs = [x, 99];
        let mut values = [-7.0, -7.0];
        assert_eq!(
            get_real(c, vrs.as_ptr(), 2, values.as_mut_ptr()),
            FMI2_ERROR
        );
        assert_eq!(values, [-7.0, -7.0]);
        free_instance(c);
    }
}

#[test]
fn serialised_bytes_are_those_of_the_state_asked_for_even_at_a_freed_states_address() {
    let (c, _log) = fragile();
    let (other, _other_log) = fragile();
    let u = [value_reference::<Fragile>("u").unwrap()];
    unsafe {
        start_at(c, 0.0);
        start_at(other, 0.0);
        let mut first: fmi2FMUstate = std::ptr::null_mut();
        assert_eq!(get_fmu_state(c, &mut first), FMI2_OK);
        let mut size = 0usize;
        // c keeps the bytes of `first` for the serialisation that usually follows
        assert_eq!(serialized_fmu_state_size(c, first, &mut size), FMI2_OK);
        let at_start = serialise(other, first);
        // freed through the other instance: c does not see it
        assert_eq!(free_fmu_state(other, &mut first), FMI2_OK);
        assert_eq!(set_real(c, u.as_ptr(), 1, [1.0].as_ptr()), FMI2_OK);
        assert_eq!(do_step(c, 0.0, 0.1), FMI2_OK);
        // a new state of the same size, most likely at the freed one's address
        let mut second: fmi2FMUstate = std::ptr::null_mut();
        assert_eq!(get_fmu_state(c, &mut second), FMI2_OK);
        let mut bytes = vec![0u8; size];
        assert_eq!(
            serialize_fmu_state(c, second, bytes.as_mut_ptr().cast(), size),
            FMI2_OK
        );
        assert_ne!(bytes, at_start, "the bytes of the freed state");
        assert_eq!(bytes, serialise(other, second));
        assert_eq!(free_fmu_state(c, &mut second), FMI2_OK);
        free_instance(c);
        free_instance(other);
    }
}

#[test]
fn an_instance_freed_twice_or_a_pointer_not_ours_is_not_freed_again() {
    unsafe {
        let (c, _log) = fragile();
        let (other, _other_log) = fragile();
        free_instance(c);
        // without the list of live instances the second free corrupts the heap (glibc aborts)
        free_instance(c);
        let mut not_ours = [0u64; 8];
        free_instance(not_ours.as_mut_ptr().cast());
        assert_eq!(not_ours, [0u64; 8]);
        // the other instance lives on
        start_at(other, 0.0);
        let u = [value_reference::<Fragile>("u").unwrap()];
        assert_eq!(set_real(other, u.as_ptr(), 1, [1.0].as_ptr()), FMI2_OK);
        assert_eq!(do_step(other, 0.0, 0.1), FMI2_OK);
        free_instance(other);
        free_instance(other);
        assert!(!live_instances().contains(&(other as usize)));
    }
}

#[test]
fn a_communication_point_off_by_more_than_rounding_is_refused_at_any_time_and_time_never_goes_back()
{
    let (c, log) = fragile();
    let u = [value_reference::<Fragile>("u").unwrap()];
    let last = |c| unsafe {
        let mut t = f64::NAN;
        assert_eq!(
            get_real_status(c, ffi::fmi2StatusKind_fmi2LastSuccessfulTime, &mut t),
            FMI2_OK
        );
        t
    };
    unsafe {
        // an epoch start time: a point 1 ms or 0.5 s off is refused, not stepped over
        let t0 = 1.7e9;
        start_at(c, t0);
        assert_eq!(set_real(c, u.as_ptr(), 1, [1.0].as_ptr()), FMI2_OK);
        assert_eq!(do_step(c, t0, 1e-3), FMI2_OK);
        let t1 = t0 + 1e-3;
        for off in [-0.5, -1e-3, 1e-3, 0.5] {
            assert_eq!(do_step(c, t1 + off, 1e-3), FMI2_ERROR, "{off}");
        }
        assert!(log
            .take()
            .iter()
            .any(|(_, _, m)| m.contains("does not match the instance time")));
        assert_eq!(last(c), t1);
        // the host's t0 + 2 h against our (t0 + h) + h: a few ulps apart, accepted
        assert_eq!(do_step(c, t1, 1e-3), FMI2_OK);
        let host = t0 + 2.0 * 1e-3;
        assert_eq!(do_step(c, host, 1e-3), FMI2_OK);
        free_instance(c);
    }
    let (c, _log) = fragile();
    unsafe {
        start_at(c, 1.0);
        assert_eq!(do_step(c, 1.0, 0.25), FMI2_OK);
        // points within the tolerance before our time with zero or shorter steps: time stays
        for _ in 0..1000 {
            assert_eq!(do_step(c, 1.25 - 1e-10, 0.0), FMI2_OK);
            assert_eq!(do_step(c, 1.25 - 1e-10, 5e-11), FMI2_OK);
        }
        assert_eq!(last(c), 1.25);
        free_instance(c);
    }
}

#[test]
fn status_kinds_the_fmu_does_not_provide_are_discarded_not_errors() {
    let (c, log) = fragile();
    unsafe {
        start_at(c, 0.0);
        assert_eq!(do_step(c, 0.0, 0.1), FMI2_OK);
        let mut status = FMI2_OK;
        let mut real = f64::NAN;
        let mut integer = 0;
        let mut boolean: fmi2Boolean = 0;
        let mut text: fmi2String = std::ptr::null();
        let pending = ffi::fmi2StatusKind_fmi2PendingStatus;
        let answers = [
            get_status(c, ffi::fmi2StatusKind_fmi2DoStepStatus, &mut status),
            get_real_status(c, pending, &mut real),
            get_integer_status(c, pending, &mut integer),
            get_boolean_status(c, pending, &mut boolean),
            get_string_status(c, pending, &mut text),
        ];
        assert_eq!(answers, [FMI2_DISCARD; 5]);
        let messages = log.take();
        assert_eq!(messages.len(), 5, "{messages:?}");
        assert!(
            messages
                .iter()
                .all(|(s, cat, _)| *s == Status::Discard && cat == "logStatusDiscard"),
            "{messages:?}"
        );
        // the instance goes on; a NULL value pointer is still an error
        assert_eq!(do_step(c, 0.1, 0.1), FMI2_OK);
        assert_eq!(
            get_status(
                c,
                ffi::fmi2StatusKind_fmi2DoStepStatus,
                std::ptr::null_mut()
            ),
            FMI2_ERROR
        );
        free_instance(c);
    }
}

#[test]
fn an_fmu_state_can_be_taken_in_the_error_state_and_restores_it() {
    let (c, _log) = fragile();
    let u = [value_reference::<Fragile>("u").unwrap()];
    unsafe {
        start_at(c, 0.0);
        assert_eq!(set_real(c, u.as_ptr(), 1, [-1.0].as_ptr()), FMI2_OK);
        // the panic puts the instance in the Error state
        assert_eq!(do_step(c, 0.0, 0.1), FMI2_ERROR);
        let mut state: fmi2FMUstate = std::ptr::null_mut();
        assert_eq!(get_fmu_state(c, &mut state), FMI2_OK);
        assert!(!state.is_null());
        assert_eq!(reset(c), FMI2_OK);
        start_at(c, 0.0);
        assert_eq!(set_fmu_state(c, state), FMI2_OK);
        // restored to the Error state: the model does not step
        assert_eq!(do_step(c, 0.0, 0.1), FMI2_ERROR);
        assert_eq!(free_fmu_state(c, &mut state), FMI2_OK);
        free_instance(c);
    }
}
