//! How a job is derived from a configuration of [`crate::study::configurations`] (vehicle
//! model, FMU folder, speed, track seed, run length, extra parameters). On the bogie each
//! configuration's system is the description shipped in `systems/*.json`; on the coach it is
//! generated from the damper positions ([`crate::study::vehicle::coach_system`]).
//!
//! Instance and variable names the study relies on on the bogie (see the JSON files):
//! * `bogie` (Bogie2Dof): `vehicle.speed` [m/s], `track.source` (0 none, 2 internal ERRI
//!   generator), `track.seed`, `initial.lateral_displacement` \[m\]; recorded
//!   `wheelset_{front,rear}.lateral_{displacement,acceleration}`.
//! * dampers `damper_left/right` (PassiveYawDamper, SemiActiveDamper) or
//!   `actuator_left/right` (FullActiveActuator); their `damper.force` is recorded.
//! * controllers `controller_left/right` (MpptController, SkyHookController; `valve.command`
//!   recorded) or `idf_left/right` (IdealDamperForceController, parameter `reference.damping`, the c_v of (3.14)).
//!
//! System-level choices on the bogie (the seed leaves them open):
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
//!   4 Hz). See fmu-controller's skyhook module for why not the damper end's velocity: with the
//!   car body fixed it would equal the elongation velocity. The coach uses the textbook signal
//!   (see [`crate::study::vehicle`]).
//! * The bogie starts centred (initial displacement 0) on the irregular track; the
//!   perturbation and HIL-like runs set 3 mm on an ideal track.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde_json::Value;

use master::runset::{sanitize, Job, RunSet, RunSpec};
use master::system::{LoadedSystem, SystemDescription, SystemError};

use crate::study::configurations::Configuration;
use crate::study::settings::TrackLevel;
use crate::study::vehicle::{coach_system, VehicleModel};

/// Where the study takes its system descriptions and FMUs from.
#[derive(Debug, Clone, PartialEq)]
pub struct Sources {
    /// Folder with the FMUs (`RailVehicle.fmu`, `Bogie2Dof.fmu`, ...); every instance's FMU is
    /// looked up here by its file name.
    pub fmus: PathBuf,
    /// Folder with `<id>.json` system descriptions to use instead of the built-in ones.
    pub systems: Option<PathBuf>,
}

/// The built-in system description of a configuration on a vehicle model: the shipped
/// `systems/<id>.json` for the bogie, the one generated from the damper positions for the coach.
pub fn builtin_system(vehicle: VehicleModel, c: &Configuration) -> SystemDescription {
    match vehicle {
        VehicleModel::Bogie2Dof => serde_json::from_str(c.json).unwrap_or_else(|_| empty_system()),
        VehicleModel::Coach => {
            serde_json::from_value(coach_system(c)).unwrap_or_else(|_| empty_system())
        }
    }
}

/// Only reached if a built-in description does not parse, which the unit tests rule out; an
/// empty system then fails with a clear message when prepared.
fn empty_system() -> SystemDescription {
    SystemDescription {
        instances: Vec::new(),
        connections: Vec::new(),
        start_time: 0.0,
        stop_time: 0.0,
        step: 1e-3,
        algorithm: master::coupling::Algorithm::GaussSeidel,
        order: None,
        record: None,
        init_sweeps: 3,
        max_step_halvings: 0,
    }
}

/// FMU file names the configurations use on a vehicle (for a clear "missing FMU" message up
/// front).
pub fn required_fmus(vehicle: VehicleModel, configs: &[&Configuration]) -> Vec<String> {
    let mut names: Vec<String> = Vec::new();
    for c in configs {
        for i in builtin_system(vehicle, c).instances {
            if let Some(n) = i.fmu.file_name().and_then(|n| n.to_str()) {
                if !names.iter().any(|x| x == n) {
                    names.push(n.to_string());
                }
            }
        }
    }
    names
}

impl Sources {
    /// The configuration's system description on `vehicle` with FMU paths pointing into
    /// `self.fmus`.
    pub fn system(
        &self,
        vehicle: VehicleModel,
        c: &Configuration,
    ) -> Result<LoadedSystem, SystemError> {
        let mut sys = match &self.systems {
            Some(dir) => LoadedSystem::load(&dir.join(format!("{}.json", c.id)))?,
            None => match vehicle {
                VehicleModel::Bogie2Dof => LoadedSystem::from_json_str(
                    c.json,
                    Path::new("systems"),
                    &format!("systems/{}.json (embedded)", c.id),
                )?,
                VehicleModel::Coach => LoadedSystem::from_description(
                    builtin_system(vehicle, c),
                    Path::new("systems"),
                    &format!("coach system '{}' (built in)", c.id),
                ),
            },
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
    pub vehicle: VehicleModel,
    pub config: &'static Configuration,
    pub speed_kmh: f64,
    /// Track seed; `None` = ideal track (track.source = 0).
    pub seed: Option<u32>,
    /// Level of the irregular track (with a seed).
    pub track_level: TrackLevel,
    pub stop_time_s: f64,
    /// Further start values (`instance.variable` -> value).
    pub extra: BTreeMap<String, Value>,
}

impl RunRequest {
    pub fn new(
        prefix: &str,
        vehicle: VehicleModel,
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
            vehicle,
            config,
            speed_kmh,
            seed,
            track_level: TrackLevel::Low,
            stop_time_s,
            extra: BTreeMap::new(),
        }
    }

    pub fn with(mut self, key: &str, value: Value) -> Self {
        self.extra.insert(key.to_string(), value);
        self
    }

    /// The same run on a track of `level` (irregular-track runs only).
    pub fn on_track(mut self, level: TrackLevel) -> Self {
        self.track_level = level;
        self
    }

    pub fn named(mut self, name: &str) -> Self {
        self.name = sanitize(name);
        self
    }

    /// Start values of this run (speed, track, extras).
    pub fn parameters(&self) -> BTreeMap<String, Value> {
        let mut p = BTreeMap::new();
        let v = self.vehicle;
        p.insert(v.speed(), Value::from(self.speed_kmh / 3.6));
        match self.seed {
            Some(s) => {
                p.insert(v.track_source(), Value::from(2));
                p.insert(v.track_seed(), Value::from(s));
                p.insert(v.track_level(), Value::from(self.track_level.fmu_value()));
            }
            None => {
                p.insert(v.track_source(), Value::from(0));
            }
        }
        for (k, v) in &self.extra {
            p.insert(k.clone(), v.clone());
        }
        p
    }

    /// The self-contained job (resolved FMU paths, stop time set) from the configuration's
    /// system (`Sources::system` of `self.vehicle`, `self.config`).
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
    use crate::study::configurations::{assert_valve_model, configuration, Family, CONFIGURATIONS};

    #[test]
    fn every_embedded_system_parses_and_names_the_study_variables() {
        for c in CONFIGURATIONS {
            let d: SystemDescription = serde_json::from_str(c.json)
                .unwrap_or_else(|e| panic!("systems/{}.json: {e}", c.id));
            assert!(d.instances.iter().any(|i| i.name == "bogie"), "{}", c.id);
            let rec = d.record.clone().unwrap_or_default();
            let b = VehicleModel::Bogie2Dof;
            for v in b
                .wheelset_displacements()
                .iter()
                .chain(&b.stability_accelerations())
            {
                assert!(rec.iter().any(|r| r == v), "{}: {v} not recorded", c.id);
            }
            let has = |n: &str| d.instances.iter().any(|i| i.name == n);
            match c.family {
                Family::Passive => assert!(has("damper_left") && !has("controller_left")),
                Family::FullActive => assert!(has("actuator_left") && has("idf_right")),
                _ => assert!(has("damper_left") && has("controller_right")),
            }
            assert_valve_model(&d, "damper_left", c);
        }
        assert!(configuration("mppt2").is_some() && configuration("x").is_none());
        let all: Vec<&Configuration> = CONFIGURATIONS.iter().collect();
        let coach = required_fmus(VehicleModel::Coach, &all);
        assert!(coach.iter().any(|x| x == "RailVehicle.fmu"));
        assert!(!coach.iter().any(|x| x == "Bogie2Dof.fmu"));
        let f = required_fmus(VehicleModel::Bogie2Dof, &all);
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
        let b = VehicleModel::Bogie2Dof;
        let r = RunRequest::new("sweep-", b, c, 287.5, Some(3), 12.0)
            .with("controller_left.valve.initial_command", Value::from(8.0));
        assert_eq!(r.name, "sweep-mppt2_v287.5_s3");
        let j = r.job(&src.system(b, c).unwrap()).unwrap();
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
        let ideal = RunRequest::new("p-", b, configuration("passive").unwrap(), 220.0, None, 5.0);
        assert_eq!(ideal.name, "p-passive_v220_ideal");
        assert_eq!(ideal.parameters()[&b.track_source()], Value::from(0));
        // the coach: generated system, its own variable names, FMUs from the same folder
        let v = VehicleModel::Coach;
        let r = RunRequest::new("s-", v, c, 300.0, Some(2), 3.0);
        let j = r.job(&src.system(v, c).unwrap()).unwrap();
        let coach = j
            .system
            .instances
            .iter()
            .find(|i| i.name == "vehicle")
            .unwrap();
        assert_eq!(coach.fmu, PathBuf::from("/opt/fmus/RailVehicle.fmu"));
        let speed = coach.parameters["running.speed"].as_f64().unwrap();
        assert!((speed - 300.0 / 3.6).abs() < 1e-12);
        assert_eq!(coach.parameters["track.seed"], Value::from(2));
        assert_eq!(coach.parameters["track.level"], Value::from(0));
        assert_eq!(j.system.instances.len(), 9);
    }

    #[test]
    fn the_track_level_reaches_every_irregular_track_run_and_no_ideal_one() {
        let c = configuration("passive").unwrap();
        for v in [VehicleModel::Coach, VehicleModel::Bogie2Dof] {
            let r = RunRequest::new("s-", v, c, 300.0, Some(2), 3.0);
            assert_eq!(r.parameters()[&v.track_level()], Value::from(0));
            let high = r.on_track(TrackLevel::High).parameters();
            assert_eq!(high[&v.track_level()], Value::from(1));
            let ideal = RunRequest::new("p-", v, c, 220.0, None, 5.0).on_track(TrackLevel::High);
            assert!(!ideal.parameters().contains_key(&v.track_level()));
        }
    }

    #[test]
    fn speed_format() {
        assert_eq!(fmt_speed(300.0), "300");
        assert_eq!(fmt_speed(287.5), "287.5");
        assert_eq!(fmt_speed(291.25), "291.3");
    }
}
