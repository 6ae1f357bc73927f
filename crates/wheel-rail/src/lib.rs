//! Wheel/rail contact geometry.
