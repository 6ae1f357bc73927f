//! What an FMU's binaries need and provide, read from the files themselves (no loading).
//!
//! [`inspect`] reads one shared library (ELF, PE or Mach-O, also a universal Mach-O) with the
//! `object` crate: its format and architecture, the symbols it exports, the libraries it needs,
//! its RPATH/RUNPATH and, for ELF, the symbol versions it needs (e.g. `GLIBC_2.14`), hence the
//! oldest glibc it loads on ([`BinaryInfo::newest_glibc`]). [`check_binary`] compares that with a
//! [`Platform`] folder of an FMU and a [`Policy`]; [`check_fmu`] does it for every binary of an
//! `.fmu` file against the model identifiers of its `modelDescription.xml`.
//!
//! The default policy is the manylinux2014 baseline: glibc 2.17, so a Linux binary loads on
//! every distribution released since 2014 (RHEL/CentOS 7 and later, SLES 12 and later, Ubuntu
//! 14.04 and later).

mod fmu;
mod inspect;
mod platform;
mod policy;
mod version;
mod xml_text;

pub use fmu::{check_fmu, required_functions, FmuBinaryReport, FmuError, FmuReport};
pub use inspect::{
    inspect, Architecture, BinaryError, BinaryFormat, BinaryInfo, Image, VersionNeed,
};
pub use platform::Platform;
pub use policy::{
    check_binary, LinuxPolicy, Policy, Problem, ALLOWED_LINUX_LIBRARIES, GCC_BASELINE,
    GLIBC_BASELINE,
};
pub use version::{ParseVersionError, SymbolVersion};
pub use xml_text::{escape_attribute, forbidden_in_xml};

/// The functions every FMI 2.0 binary exports, whatever its interface type (FMI 2.0.4, 2.1.9).
pub const FMI2_COMMON_FUNCTIONS: [&str; 25] = [
    "fmi2GetTypesPlatform",
    "fmi2GetVersion",
    "fmi2SetDebugLogging",
    "fmi2Instantiate",
    "fmi2FreeInstance",
    "fmi2SetupExperiment",
    "fmi2EnterInitializationMode",
    "fmi2ExitInitializationMode",
    "fmi2Terminate",
    "fmi2Reset",
    "fmi2GetReal",
    "fmi2GetInteger",
    "fmi2GetBoolean",
    "fmi2GetString",
    "fmi2SetReal",
    "fmi2SetInteger",
    "fmi2SetBoolean",
    "fmi2SetString",
    "fmi2GetFMUstate",
    "fmi2SetFMUstate",
    "fmi2FreeFMUstate",
    "fmi2SerializedFMUstateSize",
    "fmi2SerializeFMUstate",
    "fmi2DeSerializeFMUstate",
    "fmi2GetDirectionalDerivative",
];

/// The functions of the FMI 2.0 co-simulation interface (FMI 2.0.4, 4.2).
pub const FMI2_COSIMULATION_FUNCTIONS: [&str; 9] = [
    "fmi2SetRealInputDerivatives",
    "fmi2GetRealOutputDerivatives",
    "fmi2DoStep",
    "fmi2CancelStep",
    "fmi2GetStatus",
    "fmi2GetRealStatus",
    "fmi2GetIntegerStatus",
    "fmi2GetBooleanStatus",
    "fmi2GetStringStatus",
];

/// The functions of the FMI 2.0 model-exchange interface (FMI 2.0.4, 3.2).
pub const FMI2_MODEL_EXCHANGE_FUNCTIONS: [&str; 10] = [
    "fmi2EnterEventMode",
    "fmi2NewDiscreteStates",
    "fmi2EnterContinuousTimeMode",
    "fmi2CompletedIntegratorStep",
    "fmi2SetTime",
    "fmi2SetContinuousStates",
    "fmi2GetDerivatives",
    "fmi2GetEventIndicators",
    "fmi2GetContinuousStates",
    "fmi2GetNominalsOfContinuousStates",
];

/// Common plus co-simulation functions: what a co-simulation FMU's binary must export.
pub fn fmi2_cosimulation_api() -> Vec<&'static str> {
    FMI2_COMMON_FUNCTIONS
        .iter()
        .chain(FMI2_COSIMULATION_FUNCTIONS.iter())
        .copied()
        .collect()
}
