//! Yaw damper physics and FMUs.
