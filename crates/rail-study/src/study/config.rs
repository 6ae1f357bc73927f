//! The yaw-damper configurations of the study, each a system description shipped in
//! `systems/*.json` (embedded here so `master study` runs from any folder), and how a job is
//! derived from one (FMU folder, speed, track seed, run length, extra parameters).
//!
//! Instance and variable names the study relies on (see the JSON files):
//! * `bogie` (Bogie2Dof): `vehicle.speed` [m/s], `track.source` (0 none, 2 internal ERRI
//!   generator), `track.seed`, `initial.lateral_displacement` [m]; recorded
//!   `wheelset_{front,rear}.lateral_{displacement,acceleration}`.
//! * dampers `damper_left/right` (PassiveYawDamper, SemiActiveDamper) or
//!   `actuator_left/right` (FullActiveActuator); their `damper.force` is recorded.
//! * controllers `controller_left/right` (MpptController, SkyHookController; `valve.command`
//!   recorded) or `idf_left/right` (IdealDamperForceController, parameter `c_v`).
//!
//! System-level choices (the seed leaves them open):
//! * each controller takes the signals of its own side: the left MPPT board the frame
//!   acceleration over the front axle box, the right one over the rear axle box; sky-hook the
//!   same accelerations and the elongation velocity of its own damper; IDF the elongation
//!   velocity and force of its own actuator. IDF `force_loop.command_sign = -1` (a positive
//!   spool command pushes the rod out, i.e. compression in the tension-positive convention).
//! * MPPT band-pass 2-8 Hz instead of the controller's default 2-6 Hz: our bogie hunts at
//!   4.4 Hz at onset but its flange-contact limit cycles run at 5.5-6.5 Hz (EN 14363: f0 +- 2 Hz).
//! * MPPT instability threshold (3.5) = 2.7 m/s^2 = a_lim / 2 (the seed gives no number): the
//!   board's 1 s rms of a fully developed limit cycle is about a_lim in our bogie, so with
//!   threshold = a_lim the emergency closing stopped half way (4 V) and the limit cycle stayed.
//! * Sky-hook: x' of (3.6) is estimated from the frame lateral acceleration over the axle box
//!   of the controller's side (the signal the seed's co-simulation gives the controllers, 4.4),
//!   `sensor.sign` -1 left / +1 right so both dampers switch together; otherwise the
//!   controller's defaults (corner 0.3 Hz; c_sky = 330 kNs/m; damping table of our damper at
//!   4 Hz). See fmu-controller's skyhook module for why not the damper end's velocity.
//! * The bogie starts centred (initial displacement 0) on the irregular track; the
//!   perturbation and HIL-like runs set 3 mm on an ideal track.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde_json::Value;

use master::runset::{sanitize, Job, RunSet, RunSpec};
use master::system::{LoadedSystem, SystemDescription, SystemError};

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
    /// FullActiveActuator x2 + IdealDamperForceController x2 (3.14)-(3.15).
    FullActive,
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
        label: "passive (30 %)",
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
        id: "full_active",
        label: "full-active IDF, c_v = 330 kNs/m",
        family: Family::FullActive,
        valve: Valve::None,
        json: system_json!("full_active"),
        seed_value: "> 380 km/h (stable in the whole range)",
        reference: "R13",
    },
];

/// The configuration with this id.
pub fn configuration(id: &str) -> Option<&'static Configuration> {
    CONFIGURATIONS.iter().find(|c| c.id == id)
}

/// Variables the study sets and reads (instance.variable).
pub mod var {
    pub const SPEED: &str = "bogie.vehicle.speed";
    pub const TRACK_SOURCE: &str = "bogie.track.source";
    pub const TRACK_SEED: &str = "bogie.track.seed";
    pub const INITIAL_LATERAL: &str = "bogie.initial.lateral_displacement";
    pub const WS_FRONT_Y: &str = "bogie.wheelset_front.lateral_displacement_relative";
    pub const WS_REAR_Y: &str = "bogie.wheelset_rear.lateral_displacement_relative";
    pub const WS_FRONT_ACC: &str = "bogie.wheelset_front.lateral_acceleration";
    pub const WS_REAR_ACC: &str = "bogie.wheelset_rear.lateral_acceleration";
    pub const FORCE_LEFT_DAMPER: &str = "damper_left.damper.force";
    pub const FORCE_RIGHT_DAMPER: &str = "damper_right.damper.force";
    pub const FORCE_LEFT_ACTUATOR: &str = "actuator_left.damper.force";
    pub const FORCE_RIGHT_ACTUATOR: &str = "actuator_right.damper.force";
    pub const FORCE_REFERENCE_LEFT: &str = "idf_left.reference.force";
    /// Mechanical power taken from the vehicle, F v (the seed's "dissipated power").
    pub const POWER_LEFT: &str = "actuator_left.damper.power";
    pub const POWER_RIGHT: &str = "actuator_right.damper.power";
    /// Hydraulic power drawn from the supply.
    pub const HYDRAULIC_POWER_LEFT: &str = "actuator_left.damper.hydraulic_power";
    pub const HYDRAULIC_POWER_RIGHT: &str = "actuator_right.damper.hydraulic_power";
    pub const COMMAND_LEFT: &str = "controller_left.valve.command";
    pub const COMMAND_RIGHT: &str = "controller_right.valve.command";
    pub const OPENING_LEFT: &str = "damper_left.valve.opening";
    pub const MPPT_INITIAL_LEFT: &str = "controller_left.valve.initial_command";
    pub const MPPT_INITIAL_RIGHT: &str = "controller_right.valve.initial_command";
    pub const CV_LEFT: &str = "idf_left.reference.damping";
    pub const CV_RIGHT: &str = "idf_right.reference.damping";
}

/// Where the study takes its system descriptions and FMUs from.
#[derive(Debug, Clone, PartialEq)]
pub struct Sources {
    /// Folder with the FMUs (`Bogie2Dof.fmu`, ...); every instance's FMU is looked up here by
    /// its file name.
    pub fmus: PathBuf,
    /// Folder with `<id>.json` system descriptions to use instead of the embedded copies.
    pub systems: Option<PathBuf>,
}

/// FMU file names the configurations use (for a clear "missing FMU" message up front).
pub fn required_fmus(configs: &[&Configuration]) -> Vec<String> {
    let mut names: Vec<String> = Vec::new();
    for c in configs {
        if let Ok(d) = serde_json::from_str::<SystemDescription>(c.json) {
            for i in d.instances {
                if let Some(n) = i.fmu.file_name().and_then(|n| n.to_str()) {
                    if !names.iter().any(|x| x == n) {
                        names.push(n.to_string());
                    }
                }
            }
        }
    }
    names
}

impl Sources {
    /// The configuration's system description with FMU paths pointing into `self.fmus`.
    pub fn system(&self, c: &Configuration) -> Result<LoadedSystem, SystemError> {
        let mut sys = match &self.systems {
            Some(dir) => LoadedSystem::load(&dir.join(format!("{}.json", c.id)))?,
            None => LoadedSystem::from_json_str(
                c.json,
                Path::new("systems"),
                &format!("systems/{}.json (embedded)", c.id),
            )?,
        };
        let fmus = std::path::absolute(&self.fmus).unwrap_or_else(|_| self.fmus.clone());
        for inst in &mut sys.desc.instances {
            if let Some(name) = inst.fmu.file_name() {
                inst.fmu = fmus.join(name);
            }
        }
        Ok(sys)
    }
}

/// One run the study asks for: configuration, speed, seed, length, extra start values.
#[derive(Debug, Clone, PartialEq)]
pub struct RunRequest {
    /// Unique run name (folder name).
    pub name: String,
    pub config: &'static Configuration,
    pub speed_kmh: f64,
    /// Track seed; `None` = ideal track (track.source = 0).
    pub seed: Option<u32>,
    pub stop_time_s: f64,
    /// Further start values (`instance.variable` -> value).
    pub extra: BTreeMap<String, Value>,
}

impl RunRequest {
    pub fn new(
        prefix: &str,
        config: &'static Configuration,
        speed_kmh: f64,
        seed: Option<u32>,
        stop_time_s: f64,
    ) -> Self {
        let seed_part = seed.map_or_else(|| "ideal".to_string(), |s| format!("s{s}"));
        RunRequest {
            name: sanitize(&format!(
                "{prefix}{}_v{}_{seed_part}",
                config.id,
                fmt_speed(speed_kmh)
            )),
            config,
            speed_kmh,
            seed,
            stop_time_s,
            extra: BTreeMap::new(),
        }
    }

    pub fn with(mut self, key: &str, value: Value) -> Self {
        self.extra.insert(key.to_string(), value);
        self
    }

    pub fn named(mut self, name: &str) -> Self {
        self.name = sanitize(name);
        self
    }

    /// Start values of this run (speed, track, extras).
    pub fn parameters(&self) -> BTreeMap<String, Value> {
        let mut p = BTreeMap::new();
        p.insert(var::SPEED.to_string(), Value::from(self.speed_kmh / 3.6));
        match self.seed {
            Some(s) => {
                p.insert(var::TRACK_SOURCE.to_string(), Value::from(2));
                p.insert(var::TRACK_SEED.to_string(), Value::from(s));
            }
            None => {
                p.insert(var::TRACK_SOURCE.to_string(), Value::from(0));
            }
        }
        for (k, v) in &self.extra {
            p.insert(k.clone(), v.clone());
        }
        p
    }

    /// The self-contained job (resolved FMU paths, stop time set) from the configuration's
    /// system (`Sources::system` of `self.config`).
    pub fn job(&self, base: &LoadedSystem) -> Result<Job, SystemError> {
        let set = RunSet {
            base: None,
            system: None,
            product: BTreeMap::new(),
            runs: vec![RunSpec {
                name: Some(self.name.clone()),
                parameters: self.parameters(),
            }],
        };
        let mut jobs = set.expand(base, &base.file)?;
        let mut job = jobs.pop().ok_or_else(|| SystemError::Invalid {
            file: base.file.clone(),
            line: None,
            field: "runs".into(),
            reason: "internal: run set expanded to no job".into(),
        })?;
        job.system.stop_time = job.system.start_time + self.stop_time_s;
        Ok(job)
    }
}

/// Speed in km/h as a folder-friendly string: 300 -> "300", 287.5 -> "287.5".
pub fn fmt_speed(v: f64) -> String {
    let r = (v * 10.0).round() / 10.0;
    if (r - r.round()).abs() < 1e-9 {
        format!("{}", r.round() as i64)
    } else {
        format!("{r:.1}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_embedded_system_parses_and_names_the_study_variables() {
        for c in CONFIGURATIONS {
            let d: SystemDescription = serde_json::from_str(c.json)
                .unwrap_or_else(|e| panic!("systems/{}.json: {e}", c.id));
            assert!(d.instances.iter().any(|i| i.name == "bogie"), "{}", c.id);
            let rec = d.record.clone().unwrap_or_default();
            for v in [
                var::WS_FRONT_Y,
                var::WS_REAR_Y,
                var::WS_FRONT_ACC,
                var::WS_REAR_ACC,
            ] {
                assert!(rec.iter().any(|r| r == v), "{}: {v} not recorded", c.id);
            }
            let has = |n: &str| d.instances.iter().any(|i| i.name == n);
            match c.family {
                Family::Passive => assert!(has("damper_left") && !has("controller_left")),
                Family::FullActive => assert!(has("actuator_left") && has("idf_right")),
                _ => assert!(has("damper_left") && has("controller_right")),
            }
            let slow = d
                .instances
                .iter()
                .find(|i| i.name == "damper_left")
                .and_then(|i| i.parameters.get("valve.model"))
                .and_then(Value::as_i64);
            match c.valve {
                Valve::Slow => assert_eq!(slow, Some(1), "{}", c.id),
                Valve::Ideal => assert_eq!(slow, Some(0), "{}", c.id),
                Valve::None => assert_eq!(slow, None, "{}", c.id),
            }
        }
        assert!(configuration("mppt2").is_some() && configuration("x").is_none());
        let f = required_fmus(&CONFIGURATIONS.iter().collect::<Vec<_>>());
        for n in [
            "Bogie2Dof.fmu",
            "PassiveYawDamper.fmu",
            "SemiActiveDamper.fmu",
            "MpptController.fmu",
            "SkyHookController.fmu",
            "FullActiveActuator.fmu",
            "IdealDamperForceController.fmu",
        ] {
            assert!(f.iter().any(|x| x == n), "{n}");
        }
    }

    #[test]
    fn request_builds_a_job_with_speed_seed_and_fmu_folder() {
        let c = configuration("mppt2").unwrap();
        let src = Sources {
            fmus: PathBuf::from("/opt/fmus"),
            systems: None,
        };
        let r = RunRequest::new("sweep-", c, 287.5, Some(3), 12.0)
            .with(var::MPPT_INITIAL_LEFT, Value::from(8.0));
        assert_eq!(r.name, "sweep-mppt2_v287.5_s3");
        let j = r.job(&src.system(c).unwrap()).unwrap();
        assert_eq!(j.name, "sweep-mppt2_v287.5_s3");
        assert!((j.system.stop_time - 12.0).abs() < 1e-12);
        let bogie = j
            .system
            .instances
            .iter()
            .find(|i| i.name == "bogie")
            .unwrap();
        assert_eq!(bogie.fmu, PathBuf::from("/opt/fmus/Bogie2Dof.fmu"));
        let v = bogie.parameters["vehicle.speed"].as_f64().unwrap();
        assert!((v - 287.5 / 3.6).abs() < 1e-12);
        assert_eq!(bogie.parameters["track.seed"], Value::from(3));
        assert_eq!(bogie.parameters["track.source"], Value::from(2));
        let ctl = j
            .system
            .instances
            .iter()
            .find(|i| i.name == "controller_left")
            .unwrap();
        assert_eq!(ctl.parameters["valve.initial_command"], Value::from(8.0));
        let ideal = RunRequest::new("p-", configuration("passive").unwrap(), 220.0, None, 5.0);
        assert_eq!(ideal.name, "p-passive_v220_ideal");
        assert_eq!(ideal.parameters()[var::TRACK_SOURCE], Value::from(0));
    }

    #[test]
    fn speed_format() {
        assert_eq!(fmt_speed(300.0), "300");
        assert_eq!(fmt_speed(287.5), "287.5");
        assert_eq!(fmt_speed(291.25), "291.3");
    }
}
