//! FMI 2.0 co-simulation master for the bogie / yaw damper FMUs.
pub mod coupling;
pub mod en14363;
pub mod fmu;
pub mod model_description;
pub mod output;
pub mod signal;
pub mod slave;
pub mod system;
