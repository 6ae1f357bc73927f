//! EN 14363 running-stability assessment of recorded signals (`master assess`): reads a results
//! table (ours from `master run`/`study`, or a host's export such as Simpack's), picks the
//! signals, and applies [`crate::en14363`] (band-pass +-2 Hz around the dominant frequency, rms
//! over 100 m windows in 10 m steps) with the lateral-acceleration limit `(12 - m_bogie/5)/2`
//! or the sum-of-guiding-forces limit `(10 + 2 Q0/3)/2`.
//!
//! Input format: one header line of column names, the first column the time in seconds (`[ms]`
//! in milliseconds, another unit refused); then one row of numbers per sample, uniformly
//! sampled. Separators: comma (our CSV, with optional double quotes around names), semicolon,
//! or whitespace. Lines starting with `#` are comments. A column is selected by its full name
//! or by the name without a trailing ` [unit]`; a unit in brackets is checked against the
//! criterion (m/s2 for accelerations; N or kN for forces, kN converted). A Parquet file (`.parquet`, ours or another tool's) is read
//! column by column, its first column the time.
//!
//! The metadata of our results files (inside a Parquet file, `<name>.meta.json` beside a CSV)
//! records their sampling: [`check_bandwidth`] refuses a signal whose recorded pass band
//! (Nyquist frequency, or the anti-aliasing filter of a decimated file) does not reach the
//! upper edge of the band the assessment filters.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use super::{AnalysisError, Artefacts, Table};
use crate::en14363::{
    assess_guiding_forces, assess_lateral_acceleration, AssessError, Assessment, StabilitySettings,
};
use crate::plot::Chart;
use master::decimation::Sampling;
use master::parquet_file::{read_parquet, ColumnData};
use master::results::{read_metadata, ResultsFormat, ResultsMetadata};

/// Which EN 14363 quantity the signals are.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Criterion {
    /// Lateral acceleration [m/s^2]; limit from the bogie mass \[t\].
    LateralAcceleration { bogie_mass_t: f64 },
    /// Sum of guiding forces of a wheelset \[N\]; limit from the static wheel load \[N\].
    GuidingForces { static_wheel_load_n: f64 },
}

/// A parsed results table.
#[derive(Debug, Clone, PartialEq)]
pub struct ResultsTable {
    pub path: PathBuf,
    /// Column names as written (the first is the time).
    pub names: Vec<String>,
    /// Column-major values.
    pub columns: Vec<Vec<f64>>,
    /// The sampling the file's metadata records; `None` without metadata (a host's export).
    pub sampling: Option<Sampling>,
    /// Whether the file has our metadata.
    pub described: bool,
    /// The running speed the file's metadata records (a vehicle FMU's `running.speed` or
    /// `vehicle.speed` parameter, one value): its name and value \[m/s\].
    pub recorded_speed: Option<(String, f64)>,
    /// Columns left out because they hold text (a recorded String, an Enumeration's item
    /// name, a host's label): their names and why, so that asking for one says so.
    pub text_columns: Vec<TextColumn>,
}

/// A column of a results file that holds text, not numbers.
#[derive(Debug, Clone, PartialEq)]
pub struct TextColumn {
    pub name: String,
    /// Where and why, e.g. `results.csv:12: 'AA' is not a number`.
    pub reason: String,
}

fn bad_file(path: &Path, line: usize, reason: String) -> AnalysisError {
    AnalysisError::Input(format!("{}:{line}: {reason}", path.display()))
}

fn split_fields(line: &str, sep: Option<char>) -> Vec<String> {
    let fields: Vec<&str> = match sep {
        Some(c) => line.split(c).collect(),
        None => line.split_whitespace().collect(),
    };
    fields
        .iter()
        .map(|f| f.trim().trim_matches('"').trim().to_string())
        .collect()
}

/// A whitespace-separated header's ` [unit]` fields joined to the name before them
/// (`time [s] a [m/s2]` is two columns, as with the other separators).
fn units_to_names(fields: Vec<String>) -> Vec<String> {
    let mut names: Vec<String> = Vec::with_capacity(fields.len());
    for f in fields {
        match names.last_mut() {
            Some(name) if f.starts_with('[') && f.ends_with(']') && !name.ends_with(']') => {
                name.push(' ');
                name.push_str(&f);
            }
            _ => names.push(f),
        }
    }
    names
}

/// `name [unit]` -> (`name`, `Some(unit)`).
fn split_unit(name: &str) -> (&str, Option<&str>) {
    match (name.rfind(" ["), name.ends_with(']')) {
        (Some(i), true) => (&name[..i], Some(&name[i + 2..name.len() - 1])),
        _ => (name, None),
    }
}

/// The running speed `meta` records: the value of every vehicle FMU's running-speed parameter
/// (`running.speed` of RailVehicle, `vehicle.speed` of Bogie2Dof, both in m/s) that the
/// system or the run set gives, if they are one value; `None` when none is given (the FMU's
/// default) or they differ.
fn recorded_speed(meta: &ResultsMetadata) -> Option<(String, f64)> {
    const SPEEDS: [&str; 2] = ["running.speed", "vehicle.speed"];
    let mut found: BTreeMap<String, f64> = BTreeMap::new();
    let instances = meta
        .system
        .as_ref()
        .and_then(|s| s["instances"].as_array())
        .into_iter()
        .flatten();
    for inst in instances {
        let name = inst["name"].as_str().unwrap_or_default();
        for key in SPEEDS {
            if let Some(v) = inst["parameters"][key].as_f64() {
                found.insert(format!("{name}.{key}"), v);
            }
        }
    }
    // a run set's parameters are the run's own, over the system's
    for (key, value) in &meta.parameters {
        let own = key
            .split_once('.')
            .is_some_and(|(_, k)| SPEEDS.contains(&k));
        if let (true, Some(v)) = (own, value.as_f64()) {
            found.insert(key.clone(), v);
        }
    }
    let (name, &v) = found.iter().next()?;
    found.values().all(|&x| x == v).then(|| (name.clone(), v))
}

impl ResultsTable {
    /// Parses `text` (the content of `path`, named in errors with the line number).
    pub fn parse(text: &str, path: &Path) -> Result<Self, AnalysisError> {
        let mut lines = text
            .lines()
            .enumerate()
            .map(|(i, l)| (i + 1, l.trim()))
            .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'));
        let Some((_, header)) = lines.next() else {
            return Err(bad_file(path, 1, "no header line".into()));
        };
        let sep = if header.contains(',') {
            Some(',')
        } else if header.contains(';') {
            Some(';')
        } else {
            None
        };
        // (line, fields, whether each was quoted), one record at a time (a large file's
        // fields kept as texts would take several times its size): a comma-separated file by
        // records (RFC 4180: our writer quotes names with commas and every String value, which
        // may hold a line break), a host's semicolon- or space-separated export by lines
        type Row = (usize, Vec<String>, Vec<bool>);
        let mut records: Box<dyn Iterator<Item = Result<Row, AnalysisError>> + '_> =
            if sep == Some(',') {
                Box::new(master::csv_records::Records::new(text, true).map(|r| {
                    let r = r.map_err(|e| bad_file(path, e.line, e.reason.into()))?;
                    let quoted = r.fields.iter().map(|f| f.quoted).collect();
                    let fields = r
                        .fields
                        .into_iter()
                        .map(|f| {
                            if f.quoted {
                                f.text
                            } else {
                                f.text.trim().to_string()
                            }
                        })
                        .collect();
                    Ok((r.line, fields, quoted))
                }))
            } else {
                Box::new(std::iter::once((1, header)).chain(lines).enumerate().map(
                    move |(k, (no, line))| {
                        let mut fields = split_fields(line, sep);
                        if k == 0 && sep.is_none() {
                            fields = units_to_names(fields);
                        }
                        let quoted = vec![false; fields.len()];
                        Ok((no, fields, quoted))
                    },
                ))
            };
        let Some((_, names, _)) = records.next().transpose()? else {
            return Err(bad_file(path, 1, "no header line".into()));
        };
        if names.len() < 2 {
            return Err(bad_file(
                path,
                1,
                "the header needs a time column and at least one signal".into(),
            ));
        }
        let mut columns = vec![Vec::new(); names.len()];
        // the first field of a column that is quoted (a String), not a number or not finite
        // makes it a column that is left out
        let mut text: Vec<Option<(usize, String)>> = vec![None; names.len()];
        for record in records {
            let (no, fields, quoted) = record?;
            if fields.len() != names.len() {
                return Err(bad_file(
                    path,
                    no,
                    format!("{} fields, the header has {}", fields.len(), names.len()),
                ));
            }
            for (k, f) in fields.iter().enumerate() {
                if text[k].is_some() {
                    continue;
                }
                let (value, is) = match f.parse::<f64>() {
                    Ok(v) if v.is_finite() && !quoted[k] => {
                        columns[k].push(v);
                        continue;
                    }
                    Ok(v) if !quoted[k] => (master::show::num(v).to_string(), "not finite"),
                    _ => (format!("'{}'", master::show::text(f)), "not a number"),
                };
                let column = master::show::text(&names[k]);
                text[k] = Some((no, format!("{value} in column '{column}' is {is}")));
                columns[k] = Vec::new();
            }
        }
        if let Some((no, reason)) = &text[0] {
            return Err(bad_file(path, *no, reason.clone()));
        }
        // text columns are left out, as a Parquet file's texts are
        let (mut kept_names, mut kept, mut text_columns) = (Vec::new(), Vec::new(), Vec::new());
        for ((name, values), text) in names.into_iter().zip(columns).zip(text) {
            match text {
                None => {
                    kept_names.push(name);
                    kept.push(values);
                }
                Some((no, reason)) => {
                    let reason = bad_file(path, no, reason).to_string();
                    text_columns.push(TextColumn { name, reason });
                }
            }
        }
        if kept_names.len() < 2 {
            let reason = text_columns.first().map_or("", |c| c.reason.as_str());
            return Err(AnalysisError::Input(format!(
                "{}: no numeric signal beside the time column ({reason})",
                path.display()
            )));
        }
        Ok(ResultsTable {
            path: path.to_path_buf(),
            names: kept_names,
            columns: kept,
            sampling: None,
            described: false,
            recorded_speed: None,
            text_columns,
        })
    }

    /// Reads a file: Parquet by its extension, else text; with the sampling of its metadata.
    pub fn load(path: &Path) -> Result<Self, AnalysisError> {
        let input = |e: &dyn std::fmt::Display| AnalysisError::Input(e.to_string());
        if ResultsFormat::of_path(path) == Some(ResultsFormat::Parquet) {
            return Self::load_parquet(path);
        }
        // a regular file of bounded size (a FIFO or /dev/zero would hang the command)
        let text = master::input::read_text_file(path, master::input::MAX_TEXT_FILE_BYTES)
            .map_err(|e| AnalysisError::Input(format!("{}: {e}", path.display())))?;
        let table = Self::parse(&text, path)?;
        let meta = read_metadata(path).map_err(|e| input(&e))?;
        table.with_metadata(meta)
    }

    /// The table as its results metadata describes it (its sampling, the running speed it
    /// records), when it has any: a file's, or that of results held in memory (Python's
    /// `Results.metadata`), whose sampling must be the time column's.
    pub fn with_metadata(mut self, meta: Option<ResultsMetadata>) -> Result<Self, AnalysisError> {
        self.described = meta.is_some();
        self.recorded_speed = meta.as_ref().and_then(recorded_speed);
        self.sampling = meta.and_then(|m| m.sampling);
        self.check_recorded_rate()
    }

    /// The rate the metadata records is the time column's: metadata of another recording (a
    /// CSV replaced beside its `.meta.json`) would set the band check wrong.
    fn check_recorded_rate(self) -> Result<Self, AnalysisError> {
        if let (Some(s), Ok(fs)) = (&self.sampling, self.sampling_rate_hz()) {
            if (s.rate_hz - fs).abs() > 1e-3 * fs {
                return Err(AnalysisError::Input(format!(
                    "{}: its metadata records a sampling rate of {} Hz, but its time column is \
                     sampled at {} Hz: the metadata is another recording's",
                    self.path.display(),
                    master::show::num(s.rate_hz),
                    master::show::num(fs)
                )));
            }
        }
        Ok(self)
    }

    /// A Parquet file's numeric columns without nulls (texts and empty parameters left out).
    fn load_parquet(path: &Path) -> Result<Self, AnalysisError> {
        let (columns, meta) =
            read_parquet(path).map_err(|e| AnalysisError::Input(e.to_string()))?;
        let mut names = Vec::new();
        let mut values = Vec::new();
        let mut text_columns = Vec::new();
        for (name, data) in columns {
            match data {
                ColumnData::Numbers(x) => {
                    if let Some(x) = x.into_iter().collect::<Option<Vec<f64>>>() {
                        names.push(name);
                        values.push(x);
                    }
                }
                _ => text_columns.push(TextColumn {
                    reason: format!("{}: column '{name}' holds text", path.display()),
                    name,
                }),
            }
        }
        if names.len() < 2 {
            return Err(AnalysisError::Input(format!(
                "{}: the file needs a time column and at least one numeric signal",
                path.display()
            )));
        }
        if let Some((name, _)) = names
            .iter()
            .zip(&values)
            .find(|(_, x)| x.iter().any(|v| !v.is_finite()))
        {
            return Err(AnalysisError::Input(format!(
                "{}: column '{name}' has values that are not finite",
                path.display()
            )));
        }
        ResultsTable {
            path: path.to_path_buf(),
            names,
            columns: values,
            described: false,
            recorded_speed: None,
            sampling: None,
            text_columns,
        }
        .with_metadata(meta)
    }

    /// Index of a column by full name or by name without its ` [unit]`.
    pub fn find(&self, name: &str) -> Result<usize, AnalysisError> {
        let hits: Vec<usize> = (1..self.names.len())
            .filter(|&i| self.names[i] == name || split_unit(&self.names[i]).0 == name)
            .collect();
        match hits.as_slice() {
            [i] => Ok(*i),
            [] => {
                let text = self
                    .text_columns
                    .iter()
                    .find(|c| c.name == name || split_unit(&c.name).0 == name);
                if let Some(c) = text {
                    return Err(AnalysisError::Input(format!(
                        "{}: signal '{name}' is not numeric",
                        c.reason
                    )));
                }
                let list: Vec<&str> = self.names[1..].iter().map(|n| split_unit(n).0).collect();
                Err(AnalysisError::Input(format!(
                    "{}: no signal '{name}'; the signals are: {}",
                    self.path.display(),
                    list.join(", ")
                )))
            }
            // the full name given, and still several: the file has two columns of one name
            hits if hits.iter().all(|&i| self.names[i] == name) => {
                Err(AnalysisError::Input(format!(
                    "{}: {} columns are named '{name}': the file must name each column once",
                    self.path.display(),
                    hits.len()
                )))
            }
            _ => Err(AnalysisError::Input(format!(
                "{}: '{name}' matches several columns; give the full name with its unit",
                self.path.display()
            ))),
        }
    }

    /// Seconds per unit of the time column: 1 for `[s]` or no unit, 1e-3 for `[ms]`; any other
    /// unit is refused (`time [min]` read as seconds would put the windows 60 times off).
    fn time_scale_s(&self) -> Result<f64, AnalysisError> {
        let name = self.names.first().map_or("", String::as_str);
        match split_unit(name).1.map(str::trim) {
            None | Some("s") => Ok(1.0),
            Some("ms") => Ok(1e-3),
            Some(unit) => Err(AnalysisError::Input(format!(
                "{}: the time column '{name}' is in {unit}: give it in s (or ms)",
                self.path.display()
            ))),
        }
    }

    /// Sampling rate from the time column \[Hz\] (in s, or in ms when its name says `[ms]`);
    /// the sampling must be uniform.
    pub fn sampling_rate_hz(&self) -> Result<f64, AnalysisError> {
        let scale = self.time_scale_s()?;
        let t = &self.columns[0];
        if t.len() < 3 {
            return Err(AnalysisError::Input(format!(
                "{}: {} samples, too few to assess",
                self.path.display(),
                t.len()
            )));
        }
        if let Some(k) = t.iter().position(|x| !x.is_finite()) {
            // a NaN compares false with every step, so the uniformity check below passes it
            return Err(AnalysisError::Input(format!(
                "{}: the time column (first column) holds {} at sample {}",
                self.path.display(),
                t[k],
                k + 1
            )));
        }
        let dt = (t[t.len() - 1] - t[0]) / (t.len() - 1) as f64;
        if !(dt > 0.0 && dt.is_finite()) {
            return Err(AnalysisError::Input(format!(
                "{}: the time column (first column) does not increase",
                self.path.display()
            )));
        }
        // uniform: every time within 1 % of a step of the grid t0 + k dt, or within the
        // rounding of a float32 time (2 of its units in the last place, which grow with t); a
        // host's export prints its times rounded (1024 Hz to six decimals, a float32 column),
        // which moves them by less, while a gap or a variable step moves them by a step or more
        let grid_off =
            |k: usize| (t[k] - (t[0] + k as f64 * dt)).abs() > (0.01 * dt).max(2.4e-7 * t[k].abs());
        if let Some(k) = (1..t.len()).find(|&k| grid_off(k)) {
            // name the first step unlike the usual one (the median): a single gap in a long
            // record shifts the mean step off every step, so the mean would point at the first
            // sample
            let mut steps: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
            let mid = steps.len() / 2;
            let usual = *steps.select_nth_unstable_by(mid, f64::total_cmp).1;
            let at = t
                .windows(2)
                .position(|w| ((w[1] - w[0]) - usual).abs() > 0.01 * usual)
                .unwrap_or(k - 1);
            // to the nanosecond: the differences of times carry rounding noise
            let ns = |x: f64| (x * scale * 1e9).round() / 1e9;
            return Err(AnalysisError::Input(format!(
                "{}: the time column is not uniformly sampled (step {} s after t = {} s, \
                 where the others are {} s): resample the signals first",
                self.path.display(),
                ns(t[at + 1] - t[at]),
                ns(t[at]),
                ns(usual)
            )));
        }
        Ok(1.0 / (dt * scale))
    }
}

/// The assessment of each selected signal and the overall verdict.
#[derive(Debug, Clone, PartialEq)]
pub struct AssessReport {
    pub criterion: Criterion,
    pub speed_kmh: f64,
    /// (signal name as given, its assessment)
    pub signals: Vec<(String, Assessment)>,
    /// The assessed columns whose names give no unit (` [unit]`): their values are taken in
    /// the criterion's unit (m/s2, or N), which [`Self::unit_notes`] says.
    pub unitless: Vec<String>,
}

impl AssessReport {
    pub fn max_rms(&self) -> f64 {
        self.signals
            .iter()
            .map(|(_, a)| a.max_rms)
            .fold(0.0, f64::max)
    }

    pub fn limit(&self) -> f64 {
        self.signals.first().map_or(f64::NAN, |(_, a)| a.limit)
    }

    pub fn stable(&self) -> bool {
        self.signals.iter().all(|(_, a)| a.stable)
    }

    /// Unit of the rms and the limit: `m/s2` or `kN`.
    pub fn unit(&self) -> &'static str {
        match self.criterion {
            Criterion::LateralAcceleration { .. } => "m/s2",
            Criterion::GuidingForces { .. } => "kN",
        }
    }

    /// The notes on the assessment: [`Self::unit_notes`], then [`Self::band_notes`].
    pub fn notes(&self) -> Vec<String> {
        let mut notes = self.unit_notes();
        notes.extend(self.band_notes());
        notes
    }

    /// One note per signal whose band's lower edge, f0 minus the half band, was clamped to
    /// 0.1 Hz (a dominant frequency below 2.1 Hz with the criterion's +-2 Hz): the band is
    /// narrower below f0 than above it; and one per signal whose f0 was given but whose
    /// spectrum peaks outside the band (the rms then leaves out the signal's main oscillation).
    pub fn band_notes(&self) -> Vec<String> {
        let mut notes = Vec::new();
        for (name, a) in &self.signals {
            let (f0, (lo, hi)) = (a.dominant_frequency_hz, a.band_hz);
            if f0 - lo < hi - f0 - 1e-9 {
                notes.push(format!(
                    "signal '{name}': {} {:.2} Hz: the band's lower edge is clamped to {} Hz \
                     (band {:.2}-{:.2} Hz, narrower below it than above)",
                    if a.f0_given {
                        "f0 (given)"
                    } else {
                        "dominant frequency"
                    },
                    f0,
                    lo,
                    lo,
                    hi
                ));
            }
            if !a.f0_given {
                continue;
            }
            match a.spectrum_peak_hz {
                Some(peak) if !(lo..=hi).contains(&peak) => notes.push(format!(
                    "signal '{name}': f0 = {f0:.2} Hz was given, but its spectrum peaks at \
                     {peak:.2} Hz, outside the assessed band {lo:.2}-{hi:.2} Hz: the rms leaves \
                     out the signal's main oscillation"
                )),
                Some(_) => {}
                None => notes.push(format!(
                    "signal '{name}': f0 = {f0:.2} Hz was given; the record has no spectral \
                     peak to compare it with"
                )),
            }
        }
        notes
    }

    /// One note per assessed column without a unit: its values were taken as m/s2 (or N).
    pub fn unit_notes(&self) -> Vec<String> {
        let assumed = match self.criterion {
            Criterion::LateralAcceleration { .. } => "m/s2",
            Criterion::GuidingForces { .. } => "N",
        };
        self.unitless
            .iter()
            .map(|c| {
                format!(
                    "column '{c}' names no unit: its values were taken in {assumed} (name it \
                     '{c} [unit]' to have it checked{})",
                    if assumed == "N" {
                        ", or converted from kN"
                    } else {
                        ""
                    }
                )
            })
            .collect()
    }

    pub fn summary(&self) -> String {
        let u = self.unit();
        let mut s = format!(
            "EN 14363 rms criterion at {:.1} km/h, limit {} {u}\n",
            self.speed_kmh,
            fixed(self.limit(), 3)
        );
        for (name, a) in &self.signals {
            s.push_str(&format!(
                "  {name}: {} {:.2} Hz, band {:.2}-{:.2} Hz, max rms {} {u} over {} windows: {}\n",
                if a.f0_given { "f0 (given)" } else { "dominant" },
                a.dominant_frequency_hz,
                a.band_hz.0,
                a.band_hz.1,
                fixed(a.max_rms, 3),
                a.rms.len(),
                if a.stable {
                    "within the limit"
                } else {
                    "LIMIT EXCEEDED"
                }
            ));
        }
        for note in self.notes() {
            s.push_str(&format!("note: {note}\n"));
        }
        s.push_str(&format!(
            "verdict: {} (max rms {} {u}, {} % of the limit{})\n",
            if self.stable() { "stable" } else { "unstable" },
            fixed(self.max_rms(), 3),
            fixed(100.0 * self.max_rms() / self.limit(), 0),
            if self.unitless.is_empty() {
                String::new()
            } else {
                format!(
                    "; with the unit of {} assumed, see the note",
                    self.unitless
                        .iter()
                        .map(|c| format!("'{c}'"))
                        .collect::<Vec<_>>()
                        .join(", ")
                )
            }
        ));
        s
    }

    /// The criterion's quantity as `--quantity` names it.
    fn quantity(&self) -> &'static str {
        match self.criterion {
            Criterion::LateralAcceleration { .. } => "acceleration",
            Criterion::GuidingForces { .. } => "guiding-force",
        }
    }

    /// Whether signal `name` (as given) was assessed with its unit assumed (its column names
    /// none).
    fn unit_assumed(&self, name: &str) -> bool {
        self.unitless
            .iter()
            .any(|c| c == name || split_unit(c).0 == name)
    }

    /// The key numbers for `assess.json`: verdict, limit, largest rms and each signal's
    /// assessment, with `band_check` as in [`Self::add_artefacts`].
    pub fn results_json(&self, band_check: &str) -> serde_json::Value {
        let signals: Vec<serde_json::Value> = self
            .signals
            .iter()
            .map(|(name, a)| {
                serde_json::json!({
                    "signal": name,
                    "dominant_frequency_hz": a.dominant_frequency_hz,
                    "f0_given": a.f0_given,
                    "band_hz": [a.band_hz.0, a.band_hz.1],
                    "max_rms": a.max_rms,
                    "stable": a.stable,
                    "unit_assumed": self.unit_assumed(name),
                })
            })
            .collect();
        serde_json::json!({
            "quantity": self.quantity(),
            "unit": self.unit(),
            "speed_kmh": self.speed_kmh,
            "limit": self.limit(),
            "max_rms": self.max_rms(),
            "stable": self.stable(),
            "band_check": band_check,
            "signals": signals,
        })
    }

    /// assess.csv (rms along the track per signal), assess.svg and assess_summary.csv (one
    /// row per signal with what it was assessed with; `band_check` says whether the recorded
    /// band was checked: `covered`, `unrecorded` or `narrower, accepted`).
    pub fn add_artefacts(
        &self,
        files: &mut Artefacts,
        band_check: &str,
    ) -> Result<(), AnalysisError> {
        let u = self.unit();
        let mut t = Table::new(&[
            "signal index",
            "window centre from the record's start [m]",
            &format!("rms [{u}]"),
        ]);
        let mut chart = Chart::new(
            &format!("EN 14363 rms at {:.1} km/h", self.speed_kmh),
            "window centre from the record's start [m]",
            &format!("rms [{u}]"),
        );
        for (k, (name, a)) in self.signals.iter().enumerate() {
            for &(x, r) in &a.rms {
                t.rows.push(vec![k as f64, x, r]);
            }
            chart = chart.with_series(name, a.rms.clone());
        }
        chart = chart.with_limit(
            self.limit(),
            &format!("limit {} {u}", fixed(self.limit(), 3)),
        );
        if self.signals.len() > 2 {
            // several signals' rms along the track overlap into one band: a panel each
            chart = chart.one_panel_per_series();
        }
        files.add_table("assess.csv", &t)?;
        files.add_lines("assess.svg", &chart)?;
        let quantity = self.quantity();
        let mut legend = format!(
            "signal index,signal,dominant frequency [Hz],max rms [{u}],limit [{u}],stable,\
             f0 given,band low [Hz],band high [Hz],speed [km/h],quantity,unit assumed,band check\n"
        );
        for (k, (name, a)) in self.signals.iter().enumerate() {
            legend.push_str(&format!(
                "{k},{},{},{},{},{},{},{},{},{},{quantity},{},{}\n",
                master::output::csv_field(name),
                a.dominant_frequency_hz,
                a.max_rms,
                a.limit,
                a.stable,
                a.f0_given,
                a.band_hz.0,
                a.band_hz.1,
                self.speed_kmh,
                self.unit_assumed(name),
                master::output::csv_field(band_check)
            ));
        }
        files.add_text("assess_summary.csv", legend);
        Ok(())
    }
}

fn check_unit(
    table: &ResultsTable,
    col: usize,
    criterion: Criterion,
) -> Result<f64, AnalysisError> {
    let (_, unit) = split_unit(&table.names[col]);
    let scale = match (criterion, unit) {
        (_, None) => Some(1.0),
        (Criterion::LateralAcceleration { .. }, Some(u)) => match u {
            "m/s2" | "m/s^2" | "m/s\u{b2}" | "m s-2" | "m s^-2" | "m\u{b7}s-2" => Some(1.0),
            // standard gravity (the unit hosts and accelerometers give)
            "g" => Some(9.806_65),
            _ => None,
        },
        (Criterion::GuidingForces { .. }, Some("N")) => Some(1.0),
        (Criterion::GuidingForces { .. }, Some("kN")) => Some(1e3),
        (Criterion::GuidingForces { .. }, Some(_)) => None,
    };
    scale.ok_or_else(|| {
        AnalysisError::Input(format!(
            "{}: column '{}' has the wrong unit for the {} criterion",
            table.path.display(),
            table.names[col],
            match criterion {
                Criterion::LateralAcceleration { .. } => "lateral-acceleration (m/s2 or g)",
                Criterion::GuidingForces { .. } => "guiding-force (N or kN)",
            }
        ))
    })
}

/// A guiding force without a unit is taken in N; values that never reach 1 kN as N are
/// those of a force in kN (a wheelset's guiding forces are kN), which taken in N would pass
/// any limit: refused, asking for the unit.
fn check_unitless_force(
    table: &ResultsTable,
    col: usize,
    criterion: Criterion,
    x: &[f64],
) -> Result<(), AnalysisError> {
    let force = matches!(criterion, Criterion::GuidingForces { .. });
    if !force || split_unit(&table.names[col]).1.is_some() {
        return Ok(());
    }
    let peak = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    if peak >= 1e3 {
        return Ok(());
    }
    let name = &table.names[col];
    Err(AnalysisError::Input(format!(
        "{}: column '{name}' names no unit and its largest value is {}: as a force in N that \
         is below 1 kN, so it is likely in kN; name its unit in the header ('{name} [kN]' or \
         '{name} [N]')",
        table.path.display(),
        master::show::num(peak)
    )))
}

/// Whether the recorded band of `table` covers what `report` assessed: `Err` names each
/// signal whose assessed band reaches above the pass band its metadata records (decimated
/// with too low a rate, or through too narrow an anti-aliasing filter); `Ok(Some(note))`
/// when the file records no sampling (its band cannot be checked).
pub fn check_bandwidth(
    table: &ResultsTable,
    report: &AssessReport,
) -> Result<Option<String>, AnalysisError> {
    let Some(s) = &table.sampling else {
        return Ok(Some(format!(
            "{}: no record of how the signals were sampled ({}); if they were decimated \
             without an anti-aliasing filter, content above their Nyquist frequency is folded \
             into the assessed band and the rms is wrong",
            table.path.display(),
            if table.described {
                "its metadata has no sampling"
            } else {
                "no metadata"
            }
        )));
    };
    let narrow: Vec<String> = report
        .signals
        .iter()
        .filter(|(_, a)| a.band_hz.1 > s.passband_hz)
        .map(|(name, a)| {
            format!(
                "'{name}' is assessed in {:.2}-{:.2} Hz",
                a.band_hz.0, a.band_hz.1
            )
        })
        .collect();
    if narrow.is_empty() {
        return Ok(None);
    }
    let how = match &s.decimation {
        Some(d) => format!(
            "decimated by {} from {} Hz through a low-pass of cut-off {} Hz",
            d.factor, d.source_rate_hz, d.cutoff_hz
        ),
        None => "not decimated".to_string(),
    };
    Err(AnalysisError::Input(format!(
        "{}: the signals are recorded at {} Hz ({how}) and carry {:.2} Hz at most, but {}: \
         record at a higher rate (or pass --accept-narrow-band to assess anyway)",
        table.path.display(),
        s.rate_hz,
        s.passband_hz,
        narrow.join(", ")
    )))
}

/// What the recorded band left to say about an assessment of [`assess_checked`].
#[derive(Debug)]
pub enum BandRemark {
    /// The table records no sampling, so its band could not be checked (the note of
    /// [`check_bandwidth`]).
    Unrecorded(String),
    /// The band is narrower than the one assessed, and the caller accepted it (the refusal
    /// [`check_bandwidth`] would have given).
    Narrow(AnalysisError),
}

/// What `master assess` does with a table: [`assess_table`], then [`check_bandwidth`]; a band
/// narrower than the one assessed is refused unless `accept_narrow_band`.
pub fn assess_checked(
    table: &ResultsTable,
    signals: &[String],
    speed_kmh: f64,
    criterion: Criterion,
    settings: &StabilitySettings,
    accept_narrow_band: bool,
) -> Result<(AssessReport, Option<BandRemark>), AnalysisError> {
    let report = assess_table(table, signals, speed_kmh, criterion, settings)?;
    let remark = match check_bandwidth(table, &report) {
        Ok(note) => note.map(BandRemark::Unrecorded),
        Err(e) if accept_narrow_band => Some(BandRemark::Narrow(e)),
        Err(e) => return Err(e),
    };
    Ok((report, remark))
}

/// Assesses each named signal of `table` at a constant `speed_kmh`.
pub fn assess_table(
    table: &ResultsTable,
    signals: &[String],
    speed_kmh: f64,
    criterion: Criterion,
    settings: &StabilitySettings,
) -> Result<AssessReport, AnalysisError> {
    if signals.is_empty() {
        return Err(AnalysisError::Input("no --signal given".into()));
    }
    if !(speed_kmh.is_finite() && speed_kmh > 0.0) {
        return Err(AnalysisError::Option {
            option: "--speed",
            value: master::show::num(speed_kmh).to_string(),
            reason: "must be a speed > 0 km/h".into(),
        });
    }
    if let Some((name, v)) = &table.recorded_speed {
        // a speed given in m/s, or another run's: the 100 m windows would span other times
        if (speed_kmh / 3.6 - v).abs() > 5e-3 * v {
            return Err(AnalysisError::Input(format!(
                "{}: the speed given, {} km/h, is not the running speed its metadata records: \
                 '{name}' = {} m/s ({} km/h)",
                table.path.display(),
                master::show::num(speed_kmh),
                master::show::num(*v),
                master::show::num((v * 3.6 * 1e3).round() / 1e3)
            )));
        }
    }
    let fs = table.sampling_rate_hz()?;
    let duration = table.columns[0].len() as f64 / fs;
    let assessed_m = settings.assessed_m(duration, speed_kmh);
    if assessed_m < settings.window_m {
        return Err(AnalysisError::Input(format!(
            "{}: {duration:.2} s at {} km/h minus {} s skipped covers {} m, less than one {} m \
             window",
            table.path.display(),
            master::show::num(speed_kmh),
            master::show::num(settings.skip_s),
            master::show::num(assessed_m.max(0.0).round()),
            settings.window_m
        )));
    }
    let mut out = Vec::with_capacity(signals.len());
    let mut unitless = Vec::new();
    for name in signals {
        let col = table.find(name)?;
        let scale = check_unit(table, col, criterion)?;
        if split_unit(&table.names[col]).1.is_none() {
            unitless.push(table.names[col].clone());
        }
        let x: Vec<f64> = table.columns[col].iter().map(|v| v * scale).collect();
        check_unitless_force(table, col, criterion, &x)?;
        let a = match criterion {
            Criterion::LateralAcceleration { bogie_mass_t } => {
                assess_lateral_acceleration(&x, fs, speed_kmh / 3.6, bogie_mass_t, settings)
            }
            Criterion::GuidingForces {
                static_wheel_load_n,
            } => assess_guiding_forces(&x, fs, speed_kmh / 3.6, static_wheel_load_n, settings),
        }
        .map_err(|e: AssessError| {
            AnalysisError::Input(format!("{}: signal '{name}': {e}", table.path.display()))
        })?;
        out.push((name.clone(), a));
    }
    Ok(AssessReport {
        criterion,
        speed_kmh,
        signals: out,
        unitless,
    })
}

/// `x` with `decimals` decimals, or in scientific notation once it has more than nine digits
/// before the point (a signal of 1e308 would otherwise print 300 of them).
fn fixed(x: f64, decimals: usize) -> String {
    if x.abs() < 1e9 || !x.is_finite() {
        format!("{x:.decimals$}")
    } else {
        format!("{x:.decimals$e}")
    }
}

#[cfg(test)]
mod tests;
