//! A host that passes wrong counts, tampered FMU states or unusual files gets fmi2Error with a
//! message, never an abort, a hang or a poisoned instance: through the real C ABI of the
//! packaged FMUs (dist/*.fmu).

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::os::raw::c_char;
use std::sync::mpsc;
use std::time::Duration;

use tests::*;

fn mass_spring() -> TestFmu {
    TestFmu::open_dist("MassSpring").expect("dist/MassSpring.fmu")
}

#[test]
fn huge_value_counts_are_refused_without_allocating_or_reading_past_the_arrays() {
    let f = mass_spring();
    let inst = f.instantiate("n").unwrap();
    assert_eq!(inst.initialize(0.0), OK);
    let vr = [inst.vr("position")];
    for n in [i32::MAX as usize, usize::MAX, (1 << 20) + 1] {
        let mut r = [0.0f64];
        let mut i = [0i32];
        let mut b = [0i32];
        let mut s: [ffi::fmi2String; 1] = [std::ptr::null()];
        let set_r = [1.0f64];
        let set_s = [c"x".as_ptr()];
        let c = inst.component;
        let b_ = inst.b();
        // SAFETY: the arrays hold one element; a correct FMU must not read further when n is
        // refused.
        unsafe {
            assert_eq!(b_.fmi2GetReal(c, vr.as_ptr(), n, r.as_mut_ptr()), ERROR);
            assert_eq!(b_.fmi2GetInteger(c, vr.as_ptr(), n, i.as_mut_ptr()), ERROR);
            assert_eq!(b_.fmi2GetBoolean(c, vr.as_ptr(), n, b.as_mut_ptr()), ERROR);
            assert_eq!(b_.fmi2GetString(c, vr.as_ptr(), n, s.as_mut_ptr()), ERROR);
            assert_eq!(b_.fmi2SetReal(c, vr.as_ptr(), n, set_r.as_ptr()), ERROR);
            assert_eq!(b_.fmi2SetInteger(c, vr.as_ptr(), n, i.as_ptr()), ERROR);
            assert_eq!(b_.fmi2SetBoolean(c, vr.as_ptr(), n, b.as_ptr()), ERROR);
            assert_eq!(b_.fmi2SetString(c, vr.as_ptr(), n, set_s.as_ptr()), ERROR);
            assert_eq!(b_.fmi2SetDebugLogging(c, 1, n, set_s.as_ptr()), ERROR);
        }
        assert!(
            inst.messages()
                .iter()
                .any(|m| m.contains(&format!("{n} values in one call"))),
            "{:?}",
            inst.messages()
        );
    }
    // The instance is unharmed.
    assert_eq!(inst.do_step(0.0, 1e-3), OK);
    assert_eq!(inst.get_real("position").0, OK);
}

/// A serialised state of a MassSpring instance after 100 steps, and the instance.
fn serialised_state(f: &TestFmu) -> (Instance<'_>, Vec<c_char>) {
    let inst = f.instantiate("s").unwrap();
    assert_eq!(inst.initialize(0.0), OK);
    for k in 0..100 {
        assert_eq!(inst.do_step(k as f64 * 1e-3, 1e-3), OK);
    }
    let mut state: ffi::fmi2FMUstate = std::ptr::null_mut();
    let mut size = 0usize;
    let mut bytes;
    // SAFETY: plain FMI calls on a live instance with buffers of the announced size.
    unsafe {
        assert_eq!(inst.b().fmi2GetFMUstate(inst.component, &mut state), OK);
        assert_eq!(
            inst.b()
                .fmi2SerializedFMUstateSize(inst.component, state, &mut size),
            OK
        );
        bytes = vec![0 as c_char; size];
        assert_eq!(
            inst.b()
                .fmi2SerializeFMUstate(inst.component, state, bytes.as_mut_ptr(), size),
            OK
        );
        assert_eq!(inst.b().fmi2FreeFMUstate(inst.component, &mut state), OK);
    }
    (inst, bytes)
}

/// Deserialises `size` bytes into a state and, as a host restoring a checkpoint would, sets the
/// instance to any state it gets: a refused state must come back NULL, so a tampered one that
/// were accepted would change the instance (compared with a twin below).
fn deserialise(inst: &Instance, bytes: &[c_char], size: usize) -> ffi::fmi2Status {
    let mut state: ffi::fmi2FMUstate = std::ptr::null_mut();
    // SAFETY: `bytes` holds at least `size` bytes in every call below.
    let s = unsafe {
        inst.b()
            .fmi2DeSerializeFMUstate(inst.component, bytes.as_ptr(), size, &mut state)
    };
    if s != OK {
        assert!(state.is_null(), "a refused state came back non-NULL");
    }
    if !state.is_null() {
        unsafe {
            assert_eq!(inst.b().fmi2SetFMUstate(inst.component, state), OK);
            inst.b().fmi2FreeFMUstate(inst.component, &mut state);
        }
    }
    s
}

/// `bytes` with the f64 at `at` replaced, sealed again with a matching checksum (a forged
/// state: the state's own checks decide, not the checksum).
fn with_f64_at(bytes: &[c_char], at: usize, x: f64) -> Vec<c_char> {
    let mut b: Vec<u8> = bytes.iter().map(|&c| c as u8).collect();
    b[at..at + 8].copy_from_slice(&x.to_le_bytes());
    model_description::testing::reseal_state(&mut b);
    b.into_iter().map(|c| c as c_char).collect()
}

#[test]
fn tampered_fmu_states_are_refused() {
    let f = mass_spring();
    let (inst, bytes) = serialised_state(&f);
    let n = bytes.len();
    assert_eq!(deserialise(&inst, &bytes, n), OK, "the untampered state");
    // Trailing bytes, or the right bytes with a wrong (larger) size.
    let mut longer = bytes.clone();
    longer.extend([0, 0, 0, 0]);
    assert_eq!(deserialise(&inst, &longer, n + 4), ERROR);
    assert_eq!(deserialise(&inst, &longer, n + 1), ERROR);
    assert!(inst
        .messages()
        .iter()
        .any(|m| m.contains("are not exactly one serialised state")));
    // Too short.
    assert_eq!(deserialise(&inst, &bytes, n - 1), ERROR);
    // One byte of the model altered (the last 4 bytes are the checksum): refused as a whole.
    let mut flipped = bytes.clone();
    flipped[n - 12] ^= 1;
    assert_eq!(deserialise(&inst, &flipped, n), ERROR);
    assert!(inst
        .messages()
        .iter()
        .any(|m| m.contains("their checksum does not match")));
    // A non-finite time (the header's time follows the 4-byte magic).
    for bad in [f64::NAN, f64::INFINITY] {
        assert_eq!(deserialise(&inst, &with_f64_at(&bytes, 4, bad), n), ERROR);
    }
    assert!(inst.messages().iter().any(|m| m.contains("invalid time")));
    // A non-finite value in the model: the 8 bytes before the checksum are MassSpring's
    // velocity.
    for bad in [f64::NAN, f64::NEG_INFINITY] {
        assert_eq!(
            deserialise(&inst, &with_f64_at(&bytes, n - 12, bad), n),
            ERROR
        );
    }
    assert!(inst
        .messages()
        .iter()
        .any(|m| m.contains("non-finite number")));
    // An absurd size is refused before the buffer is touched.
    assert_eq!(deserialise(&inst, &bytes, usize::MAX), ERROR);
    // Nothing was restored: the instance continues from its own state, as a twin that never
    // saw the tampered bytes does.
    assert_eq!(inst.do_step(0.1, 1e-3), OK);
    let (s, x) = inst.get_real("position");
    assert_eq!(s, OK);
    let twin = f.instantiate("twin").unwrap();
    assert_eq!(twin.initialize(0.0), OK);
    for k in 0..101 {
        assert_eq!(twin.do_step(k as f64 * 1e-3, 1e-3), OK);
    }
    let (s, y) = twin.get_real("position");
    assert_eq!(s, OK);
    assert_eq!(x.to_bits(), y.to_bits(), "{x} vs the twin's {y}");
}

/// Initialise a Bogie2Dof instance with `contact.table` = `path` in a separate thread, so that
/// a host-blocking read shows up as a timeout instead of a hung test. Returns the status and
/// the messages.
fn init_bogie_with_table(path: &str) -> (ffi::fmi2Status, Vec<String>) {
    let path = path.to_string();
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        let f = TestFmu::open_dist("Bogie2Dof").unwrap();
        let inst = f.instantiate("b").unwrap();
        assert_eq!(inst.setup(0.0, None), OK);
        assert_eq!(inst.enter_init(), OK);
        let vr = [inst.vr("contact.table")];
        let value = std::ffi::CString::new(path).unwrap();
        let v = [value.as_ptr()];
        // SAFETY: one value reference, one string.
        let s = unsafe {
            inst.b()
                .fmi2SetString(inst.component, vr.as_ptr(), 1, v.as_ptr())
        };
        assert_eq!(s, OK);
        let status = inst.exit_init();
        let _ = tx.send((status, inst.messages()));
    });
    rx.recv_timeout(Duration::from_secs(20))
        .expect("initialisation blocked or crashed")
}

#[test]
fn contact_table_files_that_are_no_regular_files_are_refused_without_reading_them() {
    let dir = tempfile::tempdir().unwrap();
    // A FIFO nobody writes to: opening it for reading would block forever.
    let fifo = dir.path().join("table.fifo");
    let made = std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap();
    assert!(made.success());
    let big = dir.path().join("big.csv");
    // Sparse: 64 MiB + 1 byte without writing them.
    std::fs::File::create(&big)
        .unwrap()
        .set_len(64 * 1024 * 1024 + 1)
        .unwrap();
    let cases = [
        (
            fifo.to_str().unwrap().to_string(),
            "is not a regular file (a FIFO)",
        ),
        (
            dir.path().to_str().unwrap().to_string(),
            "is not a regular file (a directory)",
        ),
        (
            "/dev/zero".to_string(),
            "is not a regular file (a character device)",
        ),
        (
            big.to_str().unwrap().to_string(),
            "67108865 bytes, more than the 67108864 bytes",
        ),
    ];
    for (path, why) in cases {
        let (status, msgs) = init_bogie_with_table(&path);
        assert_eq!(status, ERROR, "{path}");
        assert!(
            msgs.iter()
                .any(|m| m.contains("invalid parameter 'contact.table'") && m.contains(why)),
            "{path}: {msgs:?}"
        );
    }
    // A regular, well-formed file is still read.
    let good = dir.path().join("good.csv");
    let shipped = workspace_root().join("crates/fmu-bogie2dof/resources/wheel_rail_A_A.csv");
    std::fs::copy(shipped, &good).unwrap();
    let (status, msgs) = init_bogie_with_table(good.to_str().unwrap());
    assert!(status == OK || status == WARNING, "{msgs:?}");
}

#[test]
fn a_state_of_another_model_in_the_same_binary_is_not_freed_as_ours() {
    let f = mass_spring();
    // the binary carries both example models: one instance of each from the same library
    let guid = TestFmu::open_dist("SpringDamperMass").unwrap().guid;
    let mass = f.instantiate("mass").unwrap();
    let other = f.instantiate_with_guid("other", &guid).unwrap();
    assert_eq!(mass.initialize(0.0), OK);
    assert_eq!(other.initialize(0.0), OK);
    let mut state: ffi::fmi2FMUstate = std::ptr::null_mut();
    // SAFETY: plain FMI calls on live instances; the state stays owned by `other`.
    unsafe {
        assert_eq!(other.b().fmi2GetFMUstate(other.component, &mut state), OK);
        assert_eq!(mass.b().fmi2FreeFMUstate(mass.component, &mut state), ERROR);
        assert!(!state.is_null(), "the refused state was released");
        assert!(mass
            .messages()
            .iter()
            .any(|m| m.contains("belongs to another model")));
        // still whole: its own model restores and frees it
        assert_eq!(other.b().fmi2SetFMUstate(other.component, state), OK);
        assert_eq!(other.b().fmi2FreeFMUstate(other.component, &mut state), OK);
    }
    assert!(state.is_null());
}

/// `fmi2DeSerializeFMUstate`'s state argument is an output: a host that reuses a variable
/// holding a state it still uses, or passes one never initialised, keeps its state whole and
/// gets the new one (the argument's value on entry was once freed: a double free, or a crash
/// on a stale pointer).
#[test]
fn deserialising_into_a_variable_that_holds_a_pointer_frees_nothing() {
    let f = mass_spring();
    let (inst, bytes) = serialised_state(&f);
    // SAFETY: plain FMI calls on a live instance; `kept` stays owned by the host throughout,
    // and the dangling pointer below is only ever written over.
    unsafe {
        let mut kept: ffi::fmi2FMUstate = std::ptr::null_mut();
        assert_eq!(inst.b().fmi2GetFMUstate(inst.component, &mut kept), OK);
        let mut reused = kept;
        assert_eq!(
            inst.b().fmi2DeSerializeFMUstate(
                inst.component,
                bytes.as_ptr(),
                bytes.len(),
                &mut reused
            ),
            OK
        );
        assert!(
            !reused.is_null() && reused != kept,
            "a new state is returned"
        );
        // the earlier state is still the host's to use and free, once
        assert_eq!(inst.b().fmi2SetFMUstate(inst.component, kept), OK);
        assert_eq!(inst.b().fmi2FreeFMUstate(inst.component, &mut kept), OK);
        assert_eq!(inst.b().fmi2SetFMUstate(inst.component, reused), OK);
        assert_eq!(inst.b().fmi2FreeFMUstate(inst.component, &mut reused), OK);
        // a variable never initialised: any pointer value, written over
        let mut stale = std::ptr::NonNull::<u8>::dangling().as_ptr() as ffi::fmi2FMUstate;
        assert_eq!(
            inst.b().fmi2DeSerializeFMUstate(
                inst.component,
                bytes.as_ptr(),
                bytes.len(),
                &mut stale
            ),
            OK
        );
        assert_eq!(inst.b().fmi2FreeFMUstate(inst.component, &mut stale), OK);
    }
}

/// After fmi2Terminate "the final values of all variables can be inquired": an output that
/// feeds through from an input set after the last step reads the same whether the host read
/// it before terminating or not.
#[test]
fn outputs_read_after_terminate_follow_the_inputs_set_before_it() {
    let f = TestFmu::open_dist("SpringDamperMass").expect("dist/SpringDamperMass.fmu");
    let run = |read_before: bool| {
        let inst = f.instantiate("s").unwrap();
        assert_eq!(inst.initialize(0.0), OK);
        assert_eq!(inst.do_step(0.0, 1e-3), OK);
        assert_eq!(inst.set_real("input_position", 0.02), OK);
        assert_eq!(inst.set_real("input_velocity", 0.3), OK);
        if read_before {
            assert_eq!(inst.get_real("coupling_force").0, OK);
        }
        assert_eq!(inst.terminate(), OK);
        let (status, force) = inst.get_real("coupling_force");
        assert_eq!(status, OK);
        force
    };
    let (unread, read) = (run(false), run(true));
    assert_eq!(unread.to_bits(), read.to_bits(), "{unread} vs {read}");
    assert!(unread != 0.0, "the inputs move the coupling force");
}
