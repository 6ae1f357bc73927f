//! The FMI 2.0 co-simulation functions of one FMU binary, loaded once with libloading under
//! their fmi-sys types. Every function the master calls is looked up when the library is
//! loaded, so a missing one is an error naming it, never a failure in the middle of a run.

use std::ffi::c_void;
use std::path::Path;

use fmi_sys::fmi2 as ffi;

/// The function pointer inside one of fmi-sys's `Option<unsafe extern "C" fn ...>` typedefs.
pub(crate) trait FunctionType {
    type Function: Copy;
}

impl<F: Copy> FunctionType for Option<F> {
    type Function = F;
}

type Function<T> = <T as FunctionType>::Function;

/// A loaded FMU binary. The library stays loaded as long as this value lives (instances keep
/// it alive through their [`super::PreparedFmu`]).
pub(crate) struct Fmi2Library {
    pub instantiate: Function<ffi::fmi2InstantiateTYPE>,
    pub free_instance: Function<ffi::fmi2FreeInstanceTYPE>,
    pub setup_experiment: Function<ffi::fmi2SetupExperimentTYPE>,
    pub enter_initialization_mode: Function<ffi::fmi2EnterInitializationModeTYPE>,
    pub exit_initialization_mode: Function<ffi::fmi2ExitInitializationModeTYPE>,
    pub terminate: Function<ffi::fmi2TerminateTYPE>,
    pub get_real: Function<ffi::fmi2GetRealTYPE>,
    pub get_integer: Function<ffi::fmi2GetIntegerTYPE>,
    pub get_boolean: Function<ffi::fmi2GetBooleanTYPE>,
    pub set_real: Function<ffi::fmi2SetRealTYPE>,
    pub set_integer: Function<ffi::fmi2SetIntegerTYPE>,
    pub set_boolean: Function<ffi::fmi2SetBooleanTYPE>,
    pub do_step: Function<ffi::fmi2DoStepTYPE>,
    /// Required by FMI 2.0 but only used when a String variable is set or read, or a step is
    /// discarded: a binary that lacks one still runs everything else.
    pub get_string: Option<Function<ffi::fmi2GetStringTYPE>>,
    pub set_string: Option<Function<ffi::fmi2SetStringTYPE>>,
    pub get_boolean_status: Option<Function<ffi::fmi2GetBooleanStatusTYPE>>,
    pub get_real_status: Option<Function<ffi::fmi2GetRealStatusTYPE>>,
    /// Present when the FMU declares canGetAndSetFMUstate.
    pub fmu_state: Option<StateFunctions>,
    _library: libloading::Library,
}

/// fmi2GetFMUstate, fmi2SetFMUstate, fmi2FreeFMUstate.
#[derive(Clone, Copy)]
pub(crate) struct StateFunctions {
    pub get: Function<ffi::fmi2GetFMUstateTYPE>,
    pub set: Function<ffi::fmi2SetFMUstateTYPE>,
    pub free: Function<ffi::fmi2FreeFMUstateTYPE>,
}

/// Looks up `name` (NUL-terminated) as a function of type `T` (an fmi-sys `Option<fn>`).
fn symbol<T>(library: &libloading::Library, name: &[u8]) -> Result<Function<T>, String>
where
    T: FunctionType + Copy + Into<Option<Function<T>>>,
{
    let shown = || String::from_utf8_lossy(&name[..name.len().saturating_sub(1)]).into_owned();
    // SAFETY: the symbol is declared by FMI 2.0 with exactly the signature of fmi-sys's typedef.
    let found = unsafe { library.get::<T>(name) };
    match found.map(|s| (*s).into()) {
        Ok(Some(f)) => Ok(f),
        Ok(None) | Err(_) => Err(format!("the binary does not export {}", shown())),
    }
}

impl Fmi2Library {
    /// Loads the shared library at `path` and looks up the co-simulation functions (the FMU
    /// state functions only when `with_state`).
    pub fn load(path: &Path, with_state: bool) -> Result<Self, String> {
        // SAFETY: loading runs the library's initialisers; an FMU binary is loaded to be run.
        let library = unsafe { libloading::Library::new(path) }.map_err(|e| e.to_string())?;
        let l = &library;
        let fmu_state = if with_state {
            Some(StateFunctions {
                get: symbol::<ffi::fmi2GetFMUstateTYPE>(l, b"fmi2GetFMUstate\0")?,
                set: symbol::<ffi::fmi2SetFMUstateTYPE>(l, b"fmi2SetFMUstate\0")?,
                free: symbol::<ffi::fmi2FreeFMUstateTYPE>(l, b"fmi2FreeFMUstate\0")?,
            })
        } else {
            None
        };
        Ok(Fmi2Library {
            instantiate: symbol::<ffi::fmi2InstantiateTYPE>(l, b"fmi2Instantiate\0")?,
            free_instance: symbol::<ffi::fmi2FreeInstanceTYPE>(l, b"fmi2FreeInstance\0")?,
            setup_experiment: symbol::<ffi::fmi2SetupExperimentTYPE>(l, b"fmi2SetupExperiment\0")?,
            enter_initialization_mode: symbol::<ffi::fmi2EnterInitializationModeTYPE>(
                l,
                b"fmi2EnterInitializationMode\0",
            )?,
            exit_initialization_mode: symbol::<ffi::fmi2ExitInitializationModeTYPE>(
                l,
                b"fmi2ExitInitializationMode\0",
            )?,
            terminate: symbol::<ffi::fmi2TerminateTYPE>(l, b"fmi2Terminate\0")?,
            get_real: symbol::<ffi::fmi2GetRealTYPE>(l, b"fmi2GetReal\0")?,
            get_integer: symbol::<ffi::fmi2GetIntegerTYPE>(l, b"fmi2GetInteger\0")?,
            get_boolean: symbol::<ffi::fmi2GetBooleanTYPE>(l, b"fmi2GetBoolean\0")?,
            set_real: symbol::<ffi::fmi2SetRealTYPE>(l, b"fmi2SetReal\0")?,
            set_integer: symbol::<ffi::fmi2SetIntegerTYPE>(l, b"fmi2SetInteger\0")?,
            set_boolean: symbol::<ffi::fmi2SetBooleanTYPE>(l, b"fmi2SetBoolean\0")?,
            do_step: symbol::<ffi::fmi2DoStepTYPE>(l, b"fmi2DoStep\0")?,
            get_string: symbol::<ffi::fmi2GetStringTYPE>(l, b"fmi2GetString\0").ok(),
            set_string: symbol::<ffi::fmi2SetStringTYPE>(l, b"fmi2SetString\0").ok(),
            get_boolean_status: symbol::<ffi::fmi2GetBooleanStatusTYPE>(
                l,
                b"fmi2GetBooleanStatus\0",
            )
            .ok(),
            get_real_status: symbol::<ffi::fmi2GetRealStatusTYPE>(l, b"fmi2GetRealStatus\0").ok(),
            fmu_state,
            _library: library,
        })
    }
}

/// The callbacks handed to fmi2Instantiate: our logger (formats the variadic message in C,
/// defensively, and forwards it to the `log` facade, see [`super::logger`]) and the C
/// allocator.
pub(crate) fn callbacks() -> ffi::fmi2CallbackFunctions {
    ffi::fmi2CallbackFunctions {
        logger: super::logger::callback(),
        allocateMemory: Some(libc::calloc),
        freeMemory: Some(libc::free),
        stepFinished: None,
        componentEnvironment: std::ptr::null_mut::<c_void>(),
    }
}
