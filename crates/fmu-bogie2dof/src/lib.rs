//! Bogie physics and FMU.
