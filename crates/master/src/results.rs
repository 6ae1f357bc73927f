//! Results files: CSV (with a JSON metadata file beside it) or Apache Parquet (metadata
//! inside), and what both carry besides the numbers ([`ResultsMetadata`]): each column's
//! unit, type and FMU variable, the sampling ([`Sampling`]: rate, pass band, decimation and
//! anti-aliasing filter), the run summary, and for a run of a run set its name, parameters
//! and system description.
//!
//! Both formats carry the same values: Reals as float64 (CSV in Rust's shortest round-trip
//! form), Integers and Enumerations as integers (an Enumeration followed by a column of its
//! item names), Booleans as booleans (0/1 in CSV), Strings as text.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde_json::Value;

use crate::coupling::{ColumnInfo, SimOutput, Summary};
use crate::decimation::Sampling;
use crate::output::{json_unfinished, results_csv_unfinished, OutputError, Unfinished};
pub use crate::parquet_file::{Constant, ConstantKind};

/// Version of the metadata layout, written into every file.
pub const METADATA_VERSION: u32 = 1;
/// Key of the metadata (JSON) in a Parquet file's key-value metadata.
pub const PARQUET_METADATA_KEY: &str = "railfmu.results";

/// Results file format.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum ResultsFormat {
    /// Comma-separated text, metadata in `<name>.meta.json` beside it.
    Csv,
    /// Apache Parquet: one column per variable, compressed, metadata inside.
    Parquet,
}

/// Results larger than this many values are written as Parquet when no format is asked for
/// (a 15 s run at 1 kHz with 60 recorded variables is 900 000 values, about 18 MB of CSV).
pub const PARQUET_FROM_VALUES: u64 = 200_000;

impl ResultsFormat {
    /// The file extension.
    pub fn extension(self) -> &'static str {
        match self {
            ResultsFormat::Csv => "csv",
            ResultsFormat::Parquet => "parquet",
        }
    }

    /// The format named `name` ("csv" or "parquet", its [`Self::extension`]).
    pub fn from_name(name: &str) -> Option<Self> {
        [ResultsFormat::Csv, ResultsFormat::Parquet]
            .into_iter()
            .find(|f| f.extension() == name)
    }

    /// The other format.
    pub fn other(self) -> Self {
        match self {
            ResultsFormat::Csv => ResultsFormat::Parquet,
            ResultsFormat::Parquet => ResultsFormat::Csv,
        }
    }

    /// The format of a file name by its extension, if it is one of ours.
    pub fn of_path(path: &Path) -> Option<Self> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "csv" => Some(ResultsFormat::Csv),
            "parquet" | "pq" => Some(ResultsFormat::Parquet),
            _ => None,
        }
    }

    /// The format chosen by size: Parquet from [`PARQUET_FROM_VALUES`] values (rows times
    /// columns) on, CSV below.
    pub fn by_size(rows: u64, columns: u64) -> Self {
        if rows.saturating_mul(columns) >= PARQUET_FROM_VALUES {
            ResultsFormat::Parquet
        } else {
            ResultsFormat::Csv
        }
    }
}

/// A recorded column as the metadata lists it.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ColumnMetadata {
    /// The column's name in the file (CSV header), e.g. `bogie.wheelset_front.y [m]`.
    pub label: String,
    #[serde(flatten)]
    pub info: ColumnInfo,
}

/// Where a run comes from: the run of a run set (name, parameters, resolved system
/// description) and further constant columns its caller adds (e.g. a study's configuration).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RunContext {
    pub run: Option<String>,
    pub parameters: BTreeMap<String, Value>,
    /// Constant columns besides the parameters (name, value).
    pub labels: BTreeMap<String, Value>,
    pub system: Option<Value>,
    /// The kind of every constant column of the run set (parameters and labels of all its
    /// runs), so that every file of the set has the same columns; empty: this run's own.
    pub kinds: BTreeMap<String, ConstantKind>,
    /// How the rows were sampled is not known (a table of unknown origin written again): the
    /// metadata then record no sampling, rather than a full band the rows may not have.
    pub sampling_unknown: bool,
}

impl RunContext {
    /// The constant columns of a Parquet file: `run`, then every parameter and label of the
    /// run set (null where this run has none).
    pub fn constants(&self) -> Vec<Constant> {
        // the run set's kinds were found from every run's values, this run's among them
        let mut kinds = self.kinds.clone();
        for (k, kind) in constant_kinds(self.parameters.iter().chain(&self.labels)) {
            kinds.entry(k).or_insert(kind);
        }
        let mut out = Vec::with_capacity(kinds.len() + 1);
        if let Some(run) = &self.run {
            out.push(Constant {
                name: "run".into(),
                kind: ConstantKind::Text,
                value: Some(Value::String(run.clone())),
            });
        }
        for (name, kind) in kinds {
            let value = self
                .parameters
                .get(&name)
                .or_else(|| self.labels.get(&name))
                .filter(|v| !v.is_null())
                .cloned();
            out.push(Constant { name, kind, value });
        }
        out
    }
}

/// The kinds of the constant columns of a set of runs (parameters and labels).
pub fn constant_kinds<'a, I>(values: I) -> BTreeMap<String, ConstantKind>
where
    I: IntoIterator<Item = (&'a String, &'a Value)>,
{
    let mut kinds: BTreeMap<String, ConstantKind> = BTreeMap::new();
    for (k, v) in values {
        if let Some(kind) = ConstantKind::of(v) {
            let e = kinds.entry(k.clone()).or_insert(kind);
            *e = e.merge(kind);
        }
    }
    kinds
}

/// `kinds` with the columns in `integers` (parameters that are Integers or Enumerations in
/// their FMUs, labels that are whole numbers by nature) made [`ConstantKind::Integer`] where
/// every run gave them as whole numbers: a JSON number alone does not say whether `2` is an
/// Integer or a Real.
pub fn with_integer_kinds<'a, I>(
    mut kinds: BTreeMap<String, ConstantKind>,
    integers: &std::collections::BTreeSet<String>,
    values: I,
) -> BTreeMap<String, ConstantKind>
where
    I: IntoIterator<Item = (&'a String, &'a Value)>,
{
    let mut whole: BTreeMap<&str, bool> = BTreeMap::new();
    for (k, v) in values {
        if integers.contains(k) && !v.is_null() {
            let e = whole.entry(k.as_str()).or_insert(true);
            *e &= crate::parquet_file::integer_value(v).is_some();
        }
    }
    for (k, all_whole) in whole {
        if let (true, Some(kind @ ConstantKind::Float)) = (all_whole, kinds.get_mut(k)) {
            *kind = ConstantKind::Integer;
        }
    }
    kinds
}

/// What a results file carries besides the numbers.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ResultsMetadata {
    pub version: u32,
    /// The sampling of the rows; `None` with fewer than two rows, or when not known (see
    /// [`RunContext::sampling_unknown`]).
    pub sampling: Option<Sampling>,
    /// The recorded columns in file order after the time (an Enumeration's item column is
    /// not listed).
    pub columns: Vec<ColumnMetadata>,
    /// Texts of String values are written as text; this list is not needed to read them.
    pub summary: Summary,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub run: Option<String>,
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub parameters: BTreeMap<String, Value>,
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub labels: BTreeMap<String, Value>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub system: Option<Value>,
}

impl ResultsMetadata {
    pub fn of(out: &SimOutput, ctx: &RunContext) -> Self {
        ResultsMetadata {
            version: METADATA_VERSION,
            sampling: if ctx.sampling_unknown {
                None
            } else {
                out.sampling()
            },
            columns: (1..out.header.len())
                .map(|c| ColumnMetadata {
                    label: out.header[c].clone(),
                    info: out.column_info(c),
                })
                .collect(),
            summary: out.summary.clone(),
            run: ctx.run.clone(),
            parameters: ctx.parameters.clone(),
            labels: ctx.labels.clone(),
            system: ctx.system.clone(),
        }
    }
}

/// The metadata file of a CSV results file: `results.csv` -> `results.meta.json`.
pub fn csv_metadata_path(csv: &Path) -> PathBuf {
    csv.with_extension("meta.json")
}

/// Writes `out` as `format` to `path` atomically (a CSV with its metadata file beside it).
pub fn write_results(
    path: &Path,
    out: &SimOutput,
    format: ResultsFormat,
    ctx: &RunContext,
) -> Result<(), OutputError> {
    prepare_results(path, out, format, ctx)?.commit()
}

/// Results written in full beside their destination, not yet in place: [`Self::commit`]
/// puts them there, so a command that writes several files can write all of them before it
/// replaces any earlier one.
pub struct PreparedResults {
    files: Vec<Unfinished>,
    /// A CSV's metadata file: removed before the CSV is renamed into place, so that a CSV
    /// never sits beside the metadata of another run.
    metadata: Option<PathBuf>,
}

impl PreparedResults {
    pub fn commit(self) -> Result<(), OutputError> {
        if let Some(meta_path) = &self.metadata {
            crate::output::remove_stale_file(meta_path).map_err(|source| OutputError::Io {
                path: meta_path.clone(),
                source,
            })?;
        }
        let mut files = self.files.into_iter();
        let Some(results) = files.next() else {
            return Ok(());
        };
        let path = results.path().to_path_buf();
        results.commit()?;
        for f in files {
            if let Err(e) = f.commit() {
                // a CSV whose metadata cannot be put beside it is removed again
                let _ = crate::output::remove_stale_file(&path);
                return Err(e);
            }
        }
        Ok(())
    }
}

/// [`write_results`] up to the files' renaming ([`PreparedResults::commit`]).
pub fn prepare_results(
    path: &Path,
    out: &SimOutput,
    format: ResultsFormat,
    ctx: &RunContext,
) -> Result<PreparedResults, OutputError> {
    let meta = ResultsMetadata::of(out, ctx);
    match format {
        ResultsFormat::Csv => {
            let meta_path = csv_metadata_path(path);
            // refused before anything is written: a folder (or FIFO) where the metadata goes
            if meta_path
                .symlink_metadata()
                .is_ok_and(|m| !m.is_file() && !m.file_type().is_symlink())
            {
                return Err(OutputError::Io {
                    path: meta_path,
                    source: std::io::Error::new(
                        std::io::ErrorKind::InvalidInput,
                        "exists and is not a file, so the results' metadata cannot go there",
                    ),
                });
            }
            let csv = results_csv_unfinished(path, out)?;
            let meta = json_unfinished(&meta_path, &meta)?;
            Ok(PreparedResults {
                files: vec![csv, meta],
                metadata: Some(meta_path),
            })
        }
        ResultsFormat::Parquet => Ok(PreparedResults {
            files: vec![crate::parquet_file::results_parquet_unfinished(
                path,
                out,
                &meta,
                &ctx.constants(),
            )?],
            metadata: None,
        }),
    }
}

/// Whether the results file `path` of `format` was written by the master: a Parquet file's
/// footer, or a CSV's metadata file beside it, reads as the master's metadata (only those are
/// read, not the values).
pub fn written_by_master(path: &Path, format: ResultsFormat) -> bool {
    match format {
        ResultsFormat::Parquet => crate::parquet_file::footer_metadata(path).is_some(),
        ResultsFormat::Csv => {
            path.symlink_metadata().is_ok_and(|m| m.is_file())
                && crate::input::read_text_file(
                    &csv_metadata_path(path),
                    crate::input::MAX_TEXT_FILE_BYTES,
                )
                .is_ok_and(|text| serde_json::from_str::<ResultsMetadata>(&text).is_ok())
        }
    }
}

/// Removes the results file `path` written as `format` (a CSV together with its metadata
/// file), if there is one. Only regular files and symbolic links are removed (a folder or a
/// FIFO of that name is left alone); a missing file is no error.
pub fn remove_results(path: &Path, format: ResultsFormat) -> Result<(), OutputError> {
    let mut files = vec![path.to_path_buf()];
    if format == ResultsFormat::Csv {
        files.push(csv_metadata_path(path));
    }
    for file in files {
        crate::output::remove_stale_file(&file)
            .map_err(|source| OutputError::Io { path: file, source })?;
    }
    Ok(())
}

/// Why a results file cannot be read.
#[derive(Debug, thiserror::Error)]
pub enum ReadError {
    #[error("cannot read '{path}': {source}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("'{path}' is not a results file: {reason}")]
    Invalid { path: PathBuf, reason: String },
}

/// The metadata of a results file: inside a Parquet file, beside a CSV (`None` when a CSV
/// has no metadata file, e.g. a host's export).
pub fn read_metadata(path: &Path) -> Result<Option<ResultsMetadata>, ReadError> {
    match ResultsFormat::of_path(path) {
        Some(ResultsFormat::Parquet) => {
            crate::parquet_file::read_results_parquet(path).map(|(_, m)| Some(m))
        }
        _ => {
            let meta = csv_metadata_path(path);
            // no file of that name: a host's export without metadata; anything else of that
            // name (a FIFO, a folder, a dangling link) is refused below, not taken as none
            if meta
                .symlink_metadata()
                .is_err_and(|e| e.kind() == std::io::ErrorKind::NotFound)
            {
                return Ok(None);
            }
            let text = crate::input::read_text_file(&meta, crate::input::MAX_TEXT_FILE_BYTES)
                .map_err(|source| ReadError::Io {
                    path: meta.clone(),
                    source,
                })?;
            serde_json::from_str(&text)
                .map(Some)
                .map_err(|e| ReadError::Invalid {
                    path: meta,
                    reason: e.to_string(),
                })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::ResultsFormat;

    #[test]
    fn a_format_is_named_by_its_extension_and_has_one_other() {
        for f in [ResultsFormat::Csv, ResultsFormat::Parquet] {
            assert_eq!(ResultsFormat::from_name(f.extension()), Some(f));
            assert_ne!(f.other(), f);
            assert_eq!(f.other().other(), f);
        }
        assert_eq!(ResultsFormat::from_name("CSV"), None);
        assert_eq!(ResultsFormat::from_name("pq"), None);
    }

    /// A CSV without metadata file has none; a metadata name taken by something other than a
    /// file (a folder, a FIFO, a dangling link) is an error, not "no metadata" (which would
    /// assess a signal without its recorded pass band).
    #[test]
    fn metadata_beside_a_csv_is_a_file_or_absent() {
        let dir = tempfile::tempdir().unwrap();
        let csv = dir.path().join("r.csv");
        std::fs::write(&csv, "time [s],x\n0,1\n").unwrap();
        assert!(super::read_metadata(&csv).unwrap().is_none());
        let meta = dir.path().join("r.meta.json");
        std::fs::create_dir(&meta).unwrap();
        assert!(super::read_metadata(&csv).is_err());
        std::fs::remove_dir(&meta).unwrap();
        std::os::unix::fs::symlink(dir.path().join("gone"), &meta).unwrap();
        assert!(super::read_metadata(&csv).is_err());
        std::fs::remove_file(&meta).unwrap();
        let status = std::process::Command::new("mkfifo")
            .arg(&meta)
            .status()
            .unwrap();
        assert!(status.success());
        let e = super::read_metadata(&csv).unwrap_err().to_string();
        assert!(e.contains("r.meta.json"), "{e}");
    }
}
