//! The quick stability study as the end-to-end study tests share it: run once per test binary
//! on the packaged FMUs, its outputs written and checked, its results looked up by
//! configuration and scenario.

use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::sync::OnceLock;

use rail_study::study::metrics::RunMetrics;
use rail_study::study::{
    run_study, write_outputs, Critical, Sources, StudyOptions, StudyResults, StudySettings, Timing,
    VehicleModel,
};

/// The FMU folder the study tests run on: `STUDY_FMUS` if set, else the workspace's `dist/`.
pub fn study_fmus() -> PathBuf {
    std::env::var_os("STUDY_FMUS").map_or_else(
        || PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../dist"),
        PathBuf::from,
    )
}

/// A quick study's results and what its run cost.
#[derive(Debug)]
pub struct QuickStudy {
    pub results: StudyResults,
    /// FMU archives unpacked while the study ran.
    pub unpacked: u64,
}

/// The quick study of one vehicle model, run the first time a test asks for it.
pub struct SharedStudy {
    vehicle: VehicleModel,
    /// Figures the written outputs must hold.
    figures: &'static [&'static str],
    /// Text the written report must hold.
    report_section: &'static str,
    cancel: AtomicBool,
    cell: OnceLock<Result<QuickStudy, String>>,
}

impl SharedStudy {
    pub const fn new(
        vehicle: VehicleModel,
        figures: &'static [&'static str],
        report_section: &'static str,
    ) -> Self {
        SharedStudy {
            vehicle,
            figures,
            report_section,
            cancel: AtomicBool::new(false),
            cell: OnceLock::new(),
        }
    }

    /// The study, run now if no test has run it yet.
    #[allow(clippy::panic)] // the tests that need the study cannot go on without it
    pub fn get(&self) -> &QuickStudy {
        match self.cell.get_or_init(|| self.run()) {
            Ok(s) => s,
            Err(e) => panic!("the quick {:?} study did not run: {e}", self.vehicle),
        }
    }

    pub fn results(&self) -> &StudyResults {
        &self.get().results
    }

    /// A configuration's critical speed.
    #[allow(clippy::panic)]
    pub fn critical(&self, id: &str) -> Critical {
        let c = self
            .results()
            .config(id)
            .unwrap_or_else(|| panic!("configuration {id} missing"));
        c.critical
            .unwrap_or_else(|| panic!("{id}: no critical speed (empty curve)"))
    }

    /// The critical speed, or the end of the range when stable throughout.
    pub fn vcr(&self, id: &str) -> f64 {
        self.critical(id).at_least_kmh()
    }

    /// The first speed over the limit, infinite when stable throughout: for orderings, where
    /// a configuration stable to the end of the range must rank above one that exceeds the
    /// limit at that end ([`Self::vcr`] gives both the last speed).
    pub fn exceedance_kmh(&self, id: &str) -> f64 {
        match self.critical(id) {
            Critical::Above { .. } => f64::INFINITY,
            c => c.at_least_kmh(),
        }
    }

    /// The metrics of a scenario run.
    #[allow(clippy::panic)]
    pub fn scenario_metrics(&self, name: &str) -> &RunMetrics {
        let r = self
            .results()
            .scenario(name)
            .unwrap_or_else(|| panic!("scenario {name} missing"));
        r.metrics
            .as_ref()
            .unwrap_or_else(|| panic!("scenario {name} failed: {:?}", r.error))
    }

    fn run(&self) -> Result<QuickStudy, String> {
        let fmus = study_fmus();
        let model_fmu = self.vehicle.fmu();
        if !fmus.join(model_fmu).is_file() {
            return Err(format!(
                "{} has no {model_fmu}: build the FMUs first with \
                 `cargo run --release -p model-description --bin package-fmus`",
                fmus.display()
            ));
        }
        let out = tempfile::tempdir().map_err(|e| e.to_string())?;
        let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
        let opts = StudyOptions {
            sources: Sources {
                fmus,
                systems: None,
            },
            out: out.path().to_path_buf(),
            threads,
            progress: false,
            cancel: &self.cancel,
        };
        let start = std::time::Instant::now();
        let unpacked_before = master::fmu::extraction_count();
        let results =
            run_study(&StudySettings::quick(self.vehicle), &opts).map_err(|e| e.to_string())?;
        let unpacked = master::fmu::extraction_count() - unpacked_before;
        // the report must be writable from these results (plots need the kept runs)
        let timing = Timing {
            wall_s: start.elapsed().as_secs_f64(),
            threads,
        };
        let md = write_outputs(&results, out.path(), &timing).map_err(|e| e.to_string())?;
        for f in self.figures {
            if !out.path().join(f).is_file() {
                return Err(format!("{f} missing"));
            }
        }
        if !md.contains(self.report_section) {
            return Err(format!("'{}' missing from the report", self.report_section));
        }
        eprintln!("{md}");
        Ok(QuickStudy { results, unpacked })
    }
}
