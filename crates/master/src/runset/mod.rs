//! Run sets: a base system plus parameter variations, run in parallel.
//!
//! ```json
//! {
//!   "base": "system.json",                       // or "system": { ...inline... }
//!   "product": {"bogie.speed_mps": [60, 70, 80], "controller.mode": [0, 1]},
//!   "runs": [{"name": "special", "parameters": {"bogie.speed_mps": 90}}]
//! }
//! ```
//! Every combination of `product` (cartesian, keys in alphabetical order) and every entry of
//! `runs` is one job; with neither, the base alone is run. Keys are `instance.variable`.
//! Each job is self-contained (its resolved system description, FMU paths absolute) and is
//! written to `<outdir>/<run>/system.json`, with `summary.json` beside it and its results:
//! as CSV `<outdir>/<run>/results.csv` (metadata in `results.meta.json`), as Parquet
//! `<outdir>/results/<run>.parquet`, a folder of Parquet files alone that reads as one table
//! (`pandas.read_parquet("<outdir>/results")`: every run with its name and parameters as
//! columns; see [`crate::results`]).
//! The base system is prepared once ([`PreparedSystem`](crate::system::PreparedSystem): FMUs unpacked and loaded once, plan
//! built once); a job is then its start values and stop time ([`run_job`]). Jobs run on a
//! rayon pool; each job instantiates its own FMU instances (never shared across threads) and
//! frees them when done. A failed job is reported in its own summary and in
//! `<outdir>/sweep.json`; the other jobs go on.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde_json::Value;

use crate::coupling::Summary;
use crate::output::OutputError;
use crate::show::text;
use crate::system::{LoadedSystem, StartValueError, SystemDescription, SystemError};

#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunSet {
    /// Path of the base system JSON (relative to the run-set file).
    #[serde(default)]
    pub base: Option<PathBuf>,
    /// Inline base system (FMU paths relative to the run-set file).
    #[serde(default)]
    pub system: Option<SystemDescription>,
    #[serde(default, deserialize_with = "crate::input::unique_keys")]
    pub product: BTreeMap<String, Vec<Value>>,
    #[serde(default)]
    pub runs: Vec<RunSpec>,
}

#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunSpec {
    #[serde(default)]
    pub name: Option<String>,
    #[serde(deserialize_with = "crate::input::unique_keys")]
    pub parameters: BTreeMap<String, Value>,
}

/// One self-contained run (serialisable both ways: a job can be sent to another process).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Job {
    pub name: String,
    pub parameters: BTreeMap<String, Value>,
    pub system: SystemDescription,
}

/// Outcome of one job (also each run's `summary.json`, which reads back into it).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RunReport {
    pub name: String,
    pub parameters: BTreeMap<String, Value>,
    pub ok: bool,
    pub error: Option<String>,
    pub summary: Option<Summary>,
    pub results: Option<PathBuf>,
    /// A failed run's rows up to its failure (`history.csv` or `history.parquet` in its
    /// folder, never in the results table; its metadata's `summary.failed` says when and
    /// why); none when the run failed before its first row.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub history: Option<PathBuf>,
    /// The SHA-1 of each FMU file the run loaded, by its path: a resumed run set runs again a
    /// run whose FMU changed since (see [`completed`]).
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub fmu_digests: BTreeMap<String, String>,
}

#[derive(Debug, thiserror::Error)]
pub enum SweepError {
    #[error(transparent)]
    System(#[from] SystemError),
    #[error(transparent)]
    Output(#[from] OutputError),
    #[error("the output folder '{path}' is a file, not a folder")]
    NotAFolder { path: PathBuf },
    #[error("cannot create '{path}': {source}")]
    Dir {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("cannot start {jobs} worker threads: {reason}")]
    Pool { jobs: usize, reason: String },
    #[error(
        "'{path}', the folder of an earlier run '{run}', holds '{file}', which no run writes: \
         move it out of the folder (run '{run}' replaces the folder) or choose another output \
         folder"
    )]
    AddedToRunFolder {
        path: PathBuf,
        run: String,
        file: String,
    },
    #[error(
        "'{input}' lies in '{folder}', which this sweep replaces or removes: copy it out of \
         the output folder first"
    )]
    InputInRunFolder { input: PathBuf, folder: PathBuf },
    #[error(
        "'{path}' exists and is not a run folder of an earlier sweep, which run '{run}' would \
         replace; choose another output folder or rename the run"
    )]
    NotARunFolder { path: PathBuf, run: String },
    #[error(
        "'{path}' exists and is not the table of a run of an earlier sweep (no run set's \
         metadata in its footer), which run '{run}' would replace; choose another output folder \
         or move it"
    )]
    NotARunTable { path: PathBuf, run: String },
    #[error("the output folder is an empty path; name a folder (\".\" for the working folder)")]
    NoOutputFolder,
    #[error(
        "'{path}' is not a folder (a link or a file), and a run set writes its Parquet tables \
         there; choose another output folder or move it"
    )]
    NotATablesFolder { path: PathBuf },
    #[error(
        "another run set or study is writing into '{path}' (a `master sweep`, `master study` or a \
         Python run set): wait for it or choose another output folder"
    )]
    FolderInUse { path: PathBuf },
}

fn invalid(file: &str, field: String, reason: String) -> SystemError {
    SystemError::Invalid {
        file: file.to_string(),
        line: None,
        field,
        reason,
    }
}

/// Most runs a run set may expand to: a product beyond this is refused before any job is
/// built (a typo such as 1e6 values in one list should not fill the disk).
pub const MAX_RUNS: usize = 100_000;

/// The folder of a run set's Parquet results (`<outdir>/results/<run>.parquet`), a name no
/// run may have.
pub const PARQUET_FOLDER: &str = "results";

/// Longest run name (folder names are limited to 255 bytes on common file systems).
const MAX_RUN_NAME_LEN: usize = 200;

/// Folder-safe run name: characters other than ASCII letters, digits and `._-=` become `_`.
pub fn sanitize(name: &str) -> String {
    name.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || "._-=".contains(c) {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// The folder name of a run: [`sanitize`]d, and refused when it could not be a folder of its
/// own inside the output folder: empty, `.`/`..` or any name starting with `.` (hidden, and
/// the prefix of the sweep's temporary folders), `sweep.json` (the sweep's report) or longer
/// than 200 characters. `Err` is the reason.
pub fn run_folder_name(name: &str) -> Result<String, String> {
    let folder = sanitize(name);
    if folder.is_empty() {
        return Err("a run name must not be empty".into());
    }
    if folder.starts_with('.') {
        return Err(format!(
            "run name '{}' would be the folder '{}': a run folder may not start with '.' ('.' \
             and '..' are not folders of their own)",
            text(name),
            text(&folder)
        ));
    }
    if folder.eq_ignore_ascii_case("sweep.json") {
        return Err(format!(
            "run name '{name}' is the name of the sweep's report file"
        ));
    }
    if folder.eq_ignore_ascii_case(PARQUET_FOLDER) {
        return Err(format!(
            "run name '{name}' is the name of the folder of the run set's Parquet results"
        ));
    }
    if folder.len() > MAX_RUN_NAME_LEN {
        return Err(format!(
            "run name '{}...' is longer than {MAX_RUN_NAME_LEN} characters",
            &folder[..40]
        ));
    }
    Ok(folder)
}

impl RunSet {
    /// Reads a run-set file and expands it into jobs.
    pub fn load_jobs(path: &Path) -> Result<Vec<Job>, SystemError> {
        Ok(Self::load(path)?.1)
    }

    /// Reads a run-set file: its base system and its jobs.
    pub fn load(path: &Path) -> Result<(LoadedSystem, Vec<Job>), SystemError> {
        let text = crate::input::read_text_file(path, crate::input::MAX_TEXT_FILE_BYTES).map_err(
            |source| SystemError::Read {
                path: path.to_path_buf(),
                source,
            },
        )?;
        let base_dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
        Self::from_str_with_base(&text, &base_dir, &path.display().to_string())
    }

    pub fn jobs_from_str(text: &str, base_dir: &Path, file: &str) -> Result<Vec<Job>, SystemError> {
        Ok(Self::from_str_with_base(text, base_dir, file)?.1)
    }

    /// Parses run-set text: its base system and its jobs.
    pub fn from_str_with_base(
        text: &str,
        base_dir: &Path,
        file: &str,
    ) -> Result<(LoadedSystem, Vec<Job>), SystemError> {
        let rs: RunSet = serde_json::from_str(text).map_err(|e| SystemError::json(file, &e))?;
        let base = match (&rs.base, &rs.system) {
            // an archive would be read as JSON text ("did not contain valid UTF-8")
            (Some(p), None) if crate::ssp::is_ssp_path(p) => {
                return Err(invalid(
                    file,
                    "base".into(),
                    format!(
                        "'{}' is an SSP: a run set's base is a JSON system description (`master \
                         run` runs an SSP as it is; `master export-ssp` goes the other way)",
                        p.display()
                    ),
                ))
            }
            (Some(p), None) => LoadedSystem::load(&base_dir.join(p))?,
            (None, Some(s)) => LoadedSystem::from_description(s.clone(), base_dir, file),
            _ => {
                return Err(invalid(
                    file,
                    "base".into(),
                    "give exactly one of 'base' (a path) or 'system' (inline)".into(),
                ))
            }
        };
        let jobs = rs.expand(&base, file)?;
        Ok((base, jobs))
    }

    /// Expands into jobs with resolved (absolute-path) system descriptions.
    pub fn expand(&self, base: &LoadedSystem, file: &str) -> Result<Vec<Job>, SystemError> {
        let resolved = base.resolved();
        let mut sets: Vec<(Option<String>, BTreeMap<String, Value>, String)> = Vec::new();
        if !self.product.is_empty() {
            let keys: Vec<&String> = self.product.keys().collect();
            for k in &keys {
                if self.product[*k].is_empty() {
                    return Err(invalid(
                        file,
                        format!("product.{}", text(k)),
                        "empty list of values".into(),
                    ));
                }
            }
            let total = self
                .product
                .values()
                .try_fold(1usize, |n, v| n.checked_mul(v.len()))
                .filter(|&n| n.saturating_add(self.runs.len()) <= MAX_RUNS)
                .ok_or_else(|| {
                    let sizes: Vec<String> =
                        self.product.values().map(|v| v.len().to_string()).collect();
                    let combinations: f64 = self.product.values().map(|v| v.len() as f64).product();
                    invalid(
                        file,
                        "product".into(),
                        format!(
                            "{} = {combinations:e} combinations plus {} listed runs are more than \
                             the {MAX_RUNS} runs a run set may have; split it into several run sets",
                            sizes.join(" x "),
                            self.runs.len()
                        ),
                    )
                })?;
            for mut idx in 0..total {
                let mut p = BTreeMap::new();
                for k in keys.iter().rev() {
                    let vals = &self.product[*k];
                    p.insert((*k).clone(), vals[idx % vals.len()].clone());
                    idx /= vals.len();
                }
                sets.push((None, p, "product".into()));
            }
        }
        for (i, r) in self.runs.iter().enumerate() {
            sets.push((r.name.clone(), r.parameters.clone(), format!("runs[{i}]")));
        }
        if sets.is_empty() {
            sets.push((Some("base".into()), BTreeMap::new(), String::new()));
        }
        if self.runs.len() > MAX_RUNS {
            return Err(invalid(
                file,
                "runs".into(),
                format!(
                    "{} runs are more than the {MAX_RUNS} a run set may have",
                    self.runs.len()
                ),
            ));
        }
        let mut jobs = Vec::new();
        // folder name (lower case: also distinct on case-insensitive file systems) -> run
        let mut folders: std::collections::HashMap<String, String> =
            std::collections::HashMap::new();
        // run-000 .. run-999, run-0000 .. run-9999 for more: the names sort as the runs do
        let width = sets.len().saturating_sub(1).to_string().len().max(3);
        for (n, (name, params, field)) in sets.into_iter().enumerate() {
            let mut sys = resolved.clone();
            for (key, value) in &params {
                let reason = match sys.set_start_value(key, value.clone()) {
                    Ok(()) => continue,
                    Err(StartValueError::NotAReference) => {
                        format!("'{}' is not of the form 'instance.variable'", text(key))
                    }
                    Err(StartValueError::UnknownInstance) => {
                        let inst = key.split_once('.').map_or(key.as_str(), |(i, _)| i);
                        format!("unknown instance '{}'", text(inst))
                    }
                };
                return Err(invalid(file, format!("{field}.{}", text(key)), reason));
            }
            let given = name.unwrap_or_else(|| format!("run-{n:0width$}"));
            let name = run_folder_name(&given).map_err(|r| invalid(file, field.clone(), r))?;
            if let Some(other) = folders.insert(name.to_ascii_lowercase(), given.clone()) {
                let reason = if other == given {
                    format!("run name '{name}' is used twice")
                } else {
                    format!(
                        "run names '{other}' and '{given}' would both write the folder '{name}' \
                         (run names are used twice or differ only in characters replaced by '_' \
                         or in case)"
                    )
                };
                return Err(invalid(file, field, reason));
            }
            jobs.push(Job {
                name,
                parameters: params,
                system: sys,
            });
        }
        Ok(jobs)
    }
}

mod execute;

pub use execute::*;

#[cfg(test)]
mod tests;
