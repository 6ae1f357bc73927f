//! FMI-facing choices of the track input: the source of the lateral alignment and the ERRI
//! B176 level of the internal generator, as Enumeration parameters, and their mapping onto the
//! physics' [`TrackSource`].

use model_description::fmi_enum;
use serde::{Deserialize, Serialize};
use wheel_rail::track::PsdLevel;
pub use wheel_rail::track::TrackSource;

#[doc(hidden)]
pub use model_description::fmi_enum as __fmi_enum;

/// ERRI B176 spectrum level of the internal generator (the FMI choice behind
/// [`PsdLevel`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum TrackLevel {
    /// A = 2.119e-7 m rad.
    Low,
    /// A = 6.125e-7 m rad.
    High,
}

fmi_enum! {
    TrackLevel as "TrackLevel", "ERRI B176 spectrum level of the internal track generator" {
        Low = 0, "low", "A = 2.119e-7 m rad";
        High = 1, "high", "A = 6.125e-7 m rad";
    }
}

impl From<TrackLevel> for PsdLevel {
    fn from(level: TrackLevel) -> Self {
        match level {
            TrackLevel::Low => PsdLevel::Low,
            TrackLevel::High => PsdLevel::High,
        }
    }
}

/// Declares, in the model crate that uses it, `TrackChoice`: where the lateral track alignment
/// comes from, the FMI Enumeration `TrackSource` behind the physics' [`TrackSource`] (whose
/// internal generator also takes the FMI parameters level and seed). `$external` describes
/// where that model applies the external input, which depends on its wheelsets; the rest is
/// the same for every model:
///
/// ```ignore
/// vehicle_elements::track_choice_enum!(
///     "The input track.lateral_alignment under the leading wheelset"
/// );
/// ```
#[macro_export]
macro_rules! track_choice_enum {
    ($external:literal) => {
        /// Where the lateral track alignment comes from (the FMI choice behind the physics'
        /// `TrackSource`, whose internal generator also carries level and seed).
        #[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
        pub enum TrackChoice {
            /// Ideal straight track.
            None,
            /// The model's track input.
            External,
            /// The built-in generator.
            Internal,
        }

        $crate::track::__fmi_enum! {
            TrackChoice as "TrackSource", "Source of the lateral track alignment" {
                None = 0, "none", "Ideal straight track";
                External = 1, "external", $external;
                Internal = 2, "internal", "The built-in ERRI B176 generator (track.level, track.seed)";
            }
        }

        impl $crate::track::TrackChoiceSource for TrackChoice {
            const EXTERNAL: Self = TrackChoice::External;

            fn track_source(
                self,
                level: $crate::TrackLevel,
                seed: i32,
            ) -> $crate::track::TrackSource {
                match self {
                    TrackChoice::None => $crate::track::TrackSource::None,
                    TrackChoice::External => $crate::track::TrackSource::External,
                    TrackChoice::Internal => $crate::track::internal_source(level, seed),
                }
            }
        }
    };
}

/// Declares, in the model crate that uses it, `ModelKind`: which wheel/rail force law the
/// time-domain model uses (default: the non-linear one), with the FMI Enumeration
/// `WheelRailForceLaw` behind the parameter `contact.model`. `$linear` and `$nonlinear`
/// describe the two laws as that model implements them (docs and enumeration items):
///
/// ```ignore
/// vehicle_elements::force_law_enum!(
///     "Kalker linear creep, constant conicity and gravitational stiffness",
///     "Contact table, Vermeulen-Johnson saturation, wheelset spin dofs"
/// );
/// ```
#[macro_export]
macro_rules! force_law_enum {
    ($linear:literal, $nonlinear:literal) => {
        /// Which wheel/rail force law the time-domain model uses.
        #[derive(
            Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize, Default,
        )]
        pub enum ModelKind {
            #[doc = $linear]
            Linear,
            #[doc = $nonlinear]
            #[default]
            NonLinear,
        }

        $crate::track::__fmi_enum! {
            ModelKind as "WheelRailForceLaw", "Wheel/rail force law of the time-domain model" {
                Linear = 0, "linear", $linear;
                NonLinear = 1, "nonlinear", $nonlinear;
            }
        }
    };
}

/// A model's FMI choice of track source (declared by [`track_choice_enum!`]).
pub trait TrackChoiceSource: Copy {
    /// The choice of the model's track input.
    const EXTERNAL: Self;

    /// The physics' track source of this choice with the generator's `level` and `seed` (an
    /// FMI Integer, taken by magnitude).
    fn track_source(self, level: TrackLevel, seed: i32) -> TrackSource;
}

/// The track parameters of a model's FMU: the source `C` (its `TrackChoice`), and the level
/// and seed of the internal generator.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct TrackSetting<C> {
    /// Where the lateral alignment comes from.
    pub source: C,
    /// ERRI B176 level of the internal generator.
    pub level: TrackLevel,
    /// Seed of the internal generator's phases.
    pub seed: i32,
}

impl<C: TrackChoiceSource> TrackSetting<C> {
    /// The FMU's start values: the external input (level low, seed 1 for the generator).
    pub fn external() -> Self {
        Self {
            source: C::EXTERNAL,
            level: TrackLevel::Low,
            seed: 1,
        }
    }

    /// The physics' track source of these parameters.
    pub fn source(&self) -> TrackSource {
        self.source.track_source(self.level, self.seed)
    }
}

/// The internal generator at `level` with `seed` (an FMI Integer, taken by magnitude).
pub fn internal_source(level: TrackLevel, seed: i32) -> TrackSource {
    TrackSource::Internal {
        level: level.into(),
        seed: u64::from(seed.unsigned_abs()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use model_description::FmiEnum;

    #[test]
    fn internal_source_takes_the_seed_by_magnitude() {
        assert_eq!(
            internal_source(TrackLevel::High, -7),
            TrackSource::Internal {
                level: PsdLevel::High,
                seed: 7
            }
        );
        assert_eq!(TrackLevel::from_value(1), Some(TrackLevel::High));
        assert_eq!(TrackLevel::Low.to_value(), 0);
        assert_eq!(TrackLevel::from_value(2), None);
    }
}
