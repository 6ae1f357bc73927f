//! FMI 2.0 co-simulation master for the bogie / yaw damper FMUs.
pub mod coupling;
pub mod fmu;
pub mod model_description;
pub mod output;
pub mod slave;
