//! Helpers for an FMU crate's own tests (feature `testing`, for dev-dependencies only): its
//! component driven through the glue's state machine by variable name, as the C API would
//! drive it. They panic on a name the model does not declare or a refused read, which is what
//! a test wants and what no code inside a host may do, hence the feature.

#![allow(clippy::panic, clippy::unwrap_used, clippy::expect_used)]

use crate::{
    rust_component, value_reference, Causality, CollectLog, Component, FmuModel, InstanceContext,
    Status, VarType,
};

/// The value reference of a declared variable.
pub fn vr<M: FmuModel>(name: &str) -> u32 {
    value_reference::<M>(name).unwrap_or_else(|| panic!("no variable {name}"))
}

/// A fresh component of `M` in initialisation mode (experiment from t = 0, no stop time).
pub fn initialising<M: FmuModel>() -> (Component, CollectLog) {
    let (mut c, log) = rust_component::<M>(InstanceContext::default())
        .unwrap_or_else(|e| panic!("instantiate: {e}"));
    assert_eq!(c.setup_experiment(0.0, None), Status::Ok);
    assert_eq!(c.enter_initialization_mode(), Status::Ok);
    (c, log)
}

/// Sets one Real variable by name.
pub fn set<M: FmuModel>(c: &mut Component, name: &str, x: f64) -> Status {
    c.set_real(&[vr::<M>(name)], &[x])
}

/// Reads one Real variable by name (a refused read fails the test).
pub fn get<M: FmuModel>(c: &mut Component, name: &str) -> f64 {
    let mut out = [f64::NAN];
    let s = c.get_real(&[vr::<M>(name)], &mut out);
    assert!(s <= Status::Warning, "get {name}: {s:?}");
    out[0]
}

/// Whether a logged message of `status` contains `needle`.
pub fn logged(log: &[(Status, String, String)], status: Status, needle: &str) -> bool {
    log.iter()
        .any(|(s, _, m)| *s == status && m.contains(needle))
}

/// The names of every Real output of `M`.
pub fn real_outputs<M: FmuModel>() -> Vec<String> {
    M::variables()
        .iter()
        .filter(|v| v.meta.causality == Causality::Output && v.meta.var_type == VarType::Real)
        .map(|v| v.meta.name.clone())
        .collect()
}

/// A global allocator that counts the allocations made on a thread while it counts there (the
/// test harness allocates on its own threads meanwhile). Install it in a test binary with
/// `#[global_allocator] static GLOBAL: CountingAllocator = CountingAllocator;` and measure
/// with [`allocations_during`].
pub struct CountingAllocator;

// Both the switch and the count are per thread: tests of one binary run on parallel threads,
// and a shared count would add another test's allocations to this one's.
thread_local! {
    static COUNTING: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
    static ALLOCATIONS: std::cell::Cell<usize> = const { std::cell::Cell::new(0) };
}

// SAFETY: every call is passed on to the system allocator unchanged; the count is a side
// effect that does not allocate (const-initialised thread-locals).
unsafe impl std::alloc::GlobalAlloc for CountingAllocator {
    unsafe fn alloc(&self, layout: std::alloc::Layout) -> *mut u8 {
        if COUNTING.with(std::cell::Cell::get) {
            ALLOCATIONS.with(|n| n.set(n.get() + 1));
        }
        std::alloc::System.alloc(layout)
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: std::alloc::Layout) {
        std::alloc::System.dealloc(ptr, layout)
    }
}

/// How many allocations `f` makes on this thread (with [`CountingAllocator`] installed as the
/// global allocator; without it, always 0), and what it returns.
pub fn allocations_during<T>(f: impl FnOnce() -> T) -> (usize, T) {
    let before = ALLOCATIONS.with(std::cell::Cell::get);
    COUNTING.with(|c| c.set(true));
    let out = f();
    COUNTING.with(|c| c.set(false));
    (ALLOCATIONS.with(std::cell::Cell::get) - before, out)
}

/// Seals serialised FMU-state bytes again after a test altered them (replaces the last 4
/// bytes, the checksum fmi2SerializeFMUstate appends), as a host forging a state would: the
/// state's own checks then decide.
pub fn reseal_state(bytes: &mut Vec<u8>) {
    let n = bytes.len().saturating_sub(4);
    bytes.truncate(n);
    crate::state_bytes::seal(bytes);
}
