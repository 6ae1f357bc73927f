//! The yaw-damper configurations of the study: control family, valve dynamics, the bogie's
//! system description (`systems/<id>.json`, embedded so `master study` runs from any folder),
//! and the seed's value each is compared with. How a configuration becomes a system and a job
//! on a vehicle model is in [`crate::study::config`] and [`crate::study::vehicle`].

/// Control family of a configuration.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum Family {
    /// PassiveYawDamper x2 (semi-active damper model, valve fixed at 30 %, seed 4.3).
    Passive,
    /// SemiActiveDamper x2 + MpptController x2, k_F = 0 (Table 4-2).
    Mppt1,
    /// SemiActiveDamper x2 + MpptController x2, k_F = 4 (Table 4-2).
    Mppt2,
    /// SemiActiveDamper x2 + SkyHookController x2, on/off (3.13).
    SkyHookOnOff,
    /// SemiActiveDamper x2 + SkyHookController x2, continuous (3.11).
    SkyHookContinuous,
    /// The seed's accelerometer-based on/off sky-hook (3.13) on the coach: x' estimated from the
    /// frame lateral acceleration over the controller's axle box, as on the bogie, beside the
    /// textbook sky-hook of [`Family::SkyHookOnOff`]. On the bogie it is `SkyHookOnOff` itself,
    /// so the bogie study does not run it (see [`Configuration::on_bogie`]).
    SkyHookAccelerometerOnOff,
    /// FullActiveActuator x2 + IdealDamperForceController x2 (3.14)-(3.15).
    FullActive,
}

impl Family {
    /// The panel of the study's figures over speed that draws this family, beside the passive
    /// damper drawn in grey in each (`None`: the passive damper itself).
    pub fn panel(self) -> Option<&'static str> {
        match self {
            Family::Passive => None,
            Family::Mppt1 | Family::Mppt2 => Some("MPPT"),
            Family::SkyHookOnOff | Family::SkyHookContinuous => Some("sky-hook"),
            Family::SkyHookAccelerometerOnOff => Some("sky-hook on the frame accelerometer"),
            Family::FullActive => Some("full-active"),
        }
    }
}

/// Valve dynamics of the semi-active damper.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum Valve {
    /// No controllable valve (passive, full-active).
    None,
    /// Opening follows the command at once (seed chapter 4).
    Ideal,
    /// First-order lag 0.15 s + rate limit (the HIL valve of seed 5.4.2, R12).
    Slow,
}

impl Valve {
    /// The semi-active damper's `valve.model` item for this valve (0 ideal, 1 slow), `None`
    /// where the configuration has no valve.
    pub fn model(self) -> Option<i64> {
        match self {
            Valve::None => None,
            Valve::Ideal => Some(0),
            Valve::Slow => Some(1),
        }
    }
}

/// One configuration of the study.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Configuration {
    /// Short id, also the file stem in `systems/`.
    pub id: &'static str,
    /// Label in plots and the report.
    pub label: &'static str,
    pub family: Family,
    pub valve: Valve,
    /// The system description (JSON text of `systems/<id>.json`).
    pub json: &'static str,
    /// The seed's critical speed / statement for this configuration (report column).
    pub seed_value: &'static str,
    /// REFERENCE.md ids the configuration is compared with.
    pub reference: &'static str,
}

macro_rules! system_json {
    ($id:literal) => {
        include_str!(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../systems/",
            $id,
            ".json"
        ))
    };
}

/// All configurations, in report order.
pub const CONFIGURATIONS: &[Configuration] = &[
    Configuration {
        id: "passive",
        label: "passive (valve 30 % open)",
        family: Family::Passive,
        valve: Valve::None,
        json: system_json!("passive"),
        seed_value: "280-300 km/h",
        reference: "R8",
    },
    Configuration {
        id: "mppt1",
        label: "MPPT1, ideal valve",
        family: Family::Mppt1,
        valve: Valve::Ideal,
        json: system_json!("mppt1"),
        seed_value: "about passive + 70 km/h (350-370 km/h)",
        reference: "R9",
    },
    Configuration {
        id: "mppt2",
        label: "MPPT2, ideal valve",
        family: Family::Mppt2,
        valve: Valve::Ideal,
        json: system_json!("mppt2"),
        seed_value: "about passive + 70 km/h (350-370 km/h)",
        reference: "R9",
    },
    Configuration {
        id: "skyhook_onoff",
        label: "sky-hook on/off, ideal valve",
        family: Family::SkyHookOnOff,
        valve: Valve::Ideal,
        json: system_json!("skyhook_onoff"),
        seed_value: "about the same as MPPT",
        reference: "R11",
    },
    Configuration {
        id: "skyhook_continuous",
        label: "sky-hook continuous, ideal valve",
        family: Family::SkyHookContinuous,
        valve: Valve::Ideal,
        json: system_json!("skyhook_continuous"),
        seed_value: "not given (on/off only in Fig. 4.23)",
        reference: "R11",
    },
    Configuration {
        id: "mppt1_slow",
        label: "MPPT1, slow valve",
        family: Family::Mppt1,
        valve: Valve::Slow,
        json: system_json!("mppt1_slow"),
        seed_value: "stabilises at 260-380 km/h (HIL)",
        reference: "R12",
    },
    Configuration {
        id: "mppt2_slow",
        label: "MPPT2, slow valve",
        family: Family::Mppt2,
        valve: Valve::Slow,
        json: system_json!("mppt2_slow"),
        seed_value: "stabilises at 260-380 km/h (HIL)",
        reference: "R12",
    },
    Configuration {
        id: "skyhook_onoff_slow",
        label: "sky-hook on/off, slow valve",
        family: Family::SkyHookOnOff,
        valve: Valve::Slow,
        json: system_json!("skyhook_onoff_slow"),
        seed_value: "fails at 260 km/h (+-6 mm, HIL)",
        reference: "R12",
    },
    Configuration {
        id: "skyhook_continuous_slow",
        label: "sky-hook continuous, slow valve",
        family: Family::SkyHookContinuous,
        valve: Valve::Slow,
        json: system_json!("skyhook_continuous_slow"),
        seed_value: "fails at 260 km/h (+-6 mm, HIL)",
        reference: "R12",
    },
    Configuration {
        id: "skyhook_accel_onoff",
        label: "sky-hook on/off (frame accelerometer), ideal valve",
        family: Family::SkyHookAccelerometerOnOff,
        valve: Valve::Ideal,
        json: system_json!("skyhook_onoff"),
        seed_value: "about the same as MPPT",
        reference: "R11",
    },
    Configuration {
        id: "skyhook_accel_onoff_slow",
        label: "sky-hook on/off (frame accelerometer), slow valve",
        family: Family::SkyHookAccelerometerOnOff,
        valve: Valve::Slow,
        json: system_json!("skyhook_onoff_slow"),
        seed_value: "fails at 260 km/h (+-6 mm, HIL)",
        reference: "R12",
    },
    Configuration {
        id: "full_active",
        label: "full-active IDF, c_v = 330 kNs/m",
        family: Family::FullActive,
        valve: Valve::None,
        json: system_json!("full_active"),
        seed_value: "> 380 km/h (stable in the whole range)",
        reference: "R13",
    },
];

impl Configuration {
    /// Whether the bogie study runs this configuration (the accelerometer-based sky-hook is the
    /// bogie's `skyhook_onoff` already).
    pub fn on_bogie(&self) -> bool {
        self.family != Family::SkyHookAccelerometerOnOff
    }
}

/// The configuration with this id.
pub fn configuration(id: &str) -> Option<&'static Configuration> {
    CONFIGURATIONS.iter().find(|c| c.id == id)
}

#[cfg(test)]
use master::system::SystemDescription;
#[cfg(test)]
use serde_json::Value;

/// Asserts that the damper instance of a system takes the configuration's valve model (and none
/// where the configuration has no valve).
#[cfg(test)]
pub(crate) fn assert_valve_model(d: &SystemDescription, damper: &str, c: &Configuration) {
    let model = d
        .instances
        .iter()
        .find(|i| i.name == damper)
        .and_then(|i| i.parameters.get("valve.model"))
        .and_then(Value::as_i64);
    assert_eq!(model, c.valve.model(), "{}: {damper}", c.id);
}
