//! Control laws and their FMUs.
