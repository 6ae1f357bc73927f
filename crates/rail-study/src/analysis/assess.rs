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

use std::path::{Path, PathBuf};

use super::{AnalysisError, Artefacts, Table};
use crate::en14363::{
    assess_guiding_forces, assess_lateral_acceleration, AssessError, Assessment, StabilitySettings,
};
use crate::plot::Chart;
use master::decimation::Sampling;
use master::parquet_file::{read_parquet, ColumnData};
use master::results::{read_metadata, ResultsFormat};

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
        let mut table = Self::parse(&text, path)?;
        let meta = read_metadata(path).map_err(|e| input(&e))?;
        table.described = meta.is_some();
        table.sampling = meta.and_then(|m| m.sampling);
        table.check_recorded_rate()
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
            described: meta.is_some(),
            sampling: meta.and_then(|m| m.sampling),
            text_columns,
        }
        .check_recorded_rate()
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
        // the first step unlike the usual one (the median): a single gap in a long record
        // shifts the mean step off every step, so the mean would point at the first sample
        let mut steps: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
        let mid = steps.len() / 2;
        let usual = *steps.select_nth_unstable_by(mid, f64::total_cmp).1;
        let off = |step: f64| (step - usual).abs() > 1e-6 * usual.abs() + 1e-12;
        if let Some(w) = t.windows(2).find(|w| off(w[1] - w[0])) {
            // to the nanosecond: the differences of times carry rounding noise
            let ns = |x: f64| (x * scale * 1e9).round() / 1e9;
            return Err(AnalysisError::Input(format!(
                "{}: the time column is not uniformly sampled (step {} s after t = {} s, \
                 where the others are {} s): resample the signals first",
                self.path.display(),
                ns(w[1] - w[0]),
                ns(w[0]),
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
    /// narrower below f0 than above it.
    pub fn band_notes(&self) -> Vec<String> {
        self.signals
            .iter()
            .filter(|(_, a)| {
                let (f0, (lo, hi)) = (a.dominant_frequency_hz, a.band_hz);
                f0 - lo < hi - f0 - 1e-9
            })
            .map(|(name, a)| {
                format!(
                    "signal '{name}': dominant frequency {:.2} Hz: the band's lower edge is \
                     clamped to {} Hz (band {:.2}-{:.2} Hz, narrower below it than above)",
                    a.dominant_frequency_hz, a.band_hz.0, a.band_hz.0, a.band_hz.1
                )
            })
            .collect()
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
                "  {name}: dominant {:.2} Hz, band {:.2}-{:.2} Hz, max rms {} {u} over {} windows: {}\n",
                a.dominant_frequency_hz,
                a.band_hz.0,
                a.band_hz.1,
                fixed(a.max_rms, 3),
                a.rms.len(),
                if a.stable { "within the limit" } else { "LIMIT EXCEEDED" }
            ));
        }
        for note in self.notes() {
            s.push_str(&format!("note: {note}\n"));
        }
        s.push_str(&format!(
            "verdict: {} (max rms {} {u}, {} % of the limit)\n",
            if self.stable() { "stable" } else { "unstable" },
            fixed(self.max_rms(), 3),
            fixed(100.0 * self.max_rms() / self.limit(), 0)
        ));
        s
    }

    /// assess.csv (rms along the track per signal) and assess.svg.
    pub fn add_artefacts(&self, files: &mut Artefacts) -> Result<(), AnalysisError> {
        let u = self.unit();
        let mut t = Table::new(&["signal index", "window centre [m]", &format!("rms [{u}]")]);
        let mut chart = Chart::new(
            &format!("EN 14363 rms at {:.1} km/h", self.speed_kmh),
            "position along the track [m]",
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
        let mut legend = format!(
            "signal index,signal,dominant frequency [Hz],max rms [{u}],limit [{u}],stable\n"
        );
        for (k, (name, a)) in self.signals.iter().enumerate() {
            legend.push_str(&format!(
                "{k},{},{},{},{},{}\n",
                master::output::csv_field(name),
                a.dominant_frequency_hz,
                a.max_rms,
                a.limit,
                a.stable
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
        (Criterion::LateralAcceleration { .. }, Some(u)) => {
            matches!(u, "m/s2" | "m/s^2" | "m s-2").then_some(1.0)
        }
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
                Criterion::LateralAcceleration { .. } => "lateral-acceleration (m/s2)",
                Criterion::GuidingForces { .. } => "guiding-force (N or kN)",
            }
        ))
    })
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
mod tests {
    use super::*;
    use std::f64::consts::PI;

    fn sine_table(amp: f64, f: f64, fs: f64, secs: f64, unit: &str) -> String {
        let n = (secs * fs) as usize;
        let mut s = format!("time [s],\"a, quoted [{unit}]\",other [m]\n");
        for k in 0..n {
            let t = k as f64 / fs;
            s.push_str(&format!("{t},{},{}\n", amp * (2.0 * PI * f * t).sin(), 0.0));
        }
        s
    }

    /// A name given without its unit that fits several columns asks for the unit; a full name
    /// that two columns share names the file's fault instead.
    #[test]
    fn a_column_is_found_by_its_name_and_ambiguity_is_named() {
        let text = "time [s],a [m/s2],a [g],b [m],b [m]\n0,1,2,3,4\n0.1,1,2,3,4\n";
        let t = ResultsTable::parse(text, Path::new("x.csv")).unwrap();
        assert_eq!(t.find("a [g]").unwrap(), 2);
        let e = t.find("a").unwrap_err().to_string();
        assert!(e.contains("give the full name with its unit"), "{e}");
        let e = t.find("b [m]").unwrap_err().to_string();
        assert!(
            e.contains("2 columns are named 'b [m]': the file must name each column once"),
            "{e}"
        );
    }

    #[test]
    fn the_time_column_is_read_in_seconds_or_milliseconds_and_any_other_unit_refused() {
        let in_s = sine_table(6.0, 4.0, 500.0, 10.0, "m/s2");
        let rate = |text: &str| {
            ResultsTable::parse(text, Path::new("x.csv"))
                .unwrap()
                .sampling_rate_hz()
        };
        assert_eq!(rate(&in_s).unwrap(), 500.0);
        // the same samples with the time in ms
        let in_ms: String = in_s
            .lines()
            .enumerate()
            .map(|(i, l)| {
                if i == 0 {
                    l.replace("time [s]", "time [ms]")
                } else {
                    let (t, rest) = l.split_once(',').unwrap();
                    format!("{},{rest}", t.parse::<f64>().unwrap() * 1e3)
                }
            })
            .collect::<Vec<_>>()
            .join("\n");
        assert!((rate(&in_ms).unwrap() - 500.0).abs() < 1e-9);
        let in_min = in_s.replacen("time [s]", "time [min]", 1);
        let e = rate(&in_min).unwrap_err().to_string();
        assert!(
            e.contains("the time column 'time [min]' is in min: give it in s (or ms)"),
            "{e}"
        );
    }

    /// The lateral-acceleration criterion (6.1 t bogie, 300 km/h) on the quoted column of a
    /// sine table of `amp` m/s2 at `f` Hz, `secs` long at 500 Hz.
    fn assess_sine(amp: f64, f: f64, secs: f64) -> AssessReport {
        let text = sine_table(amp, f, 500.0, secs, "m/s2");
        let table = ResultsTable::parse(&text, Path::new("x.csv")).unwrap();
        assess_table(
            &table,
            &["a, quoted".to_string()],
            300.0,
            Criterion::LateralAcceleration { bogie_mass_t: 6.1 },
            &StabilitySettings::default(),
        )
        .unwrap()
    }

    #[test]
    fn sine_of_known_rms_is_assessed_against_the_limit() {
        // amplitude 6 m/s2 -> rms 4.24 < 5.39; amplitude 8 -> 5.66 > 5.39
        for (amp, stable) in [(6.0, true), (8.0, false)] {
            let r = assess_sine(amp, 4.0, 10.0);
            let a = &r.signals[0].1;
            assert!((a.dominant_frequency_hz - 4.0).abs() < 0.1, "{a:?}");
            assert!((r.limit() - 5.39).abs() < 1e-12);
            assert!(
                (a.max_rms - amp / 2f64.sqrt()).abs() < 0.02 * amp,
                "{} vs {}",
                a.max_rms,
                amp / 2f64.sqrt()
            );
            assert_eq!(r.stable(), stable);
            let mut files = Artefacts::default();
            r.add_artefacts(&mut files).unwrap();
            assert_eq!(
                files.names(),
                vec!["assess.csv", "assess.svg", "assess_summary.csv"]
            );
            assert!(r.summary().contains(if stable {
                "verdict: stable"
            } else {
                "verdict: unstable"
            }));
        }
    }

    /// The guiding-force criterion (70 kN wheel load) on the quoted column of a 20 kN sine
    /// table at 300 km/h, its header's unit replaced by `header_unit` (None: no unit).
    fn assess_forces(header_unit: Option<&str>) -> Result<AssessReport, AnalysisError> {
        let text = sine_table(20.0, 5.0, 500.0, 10.0, "kN");
        let text = match header_unit {
            Some(u) => text.replace("[kN]", &format!("[{u}]")),
            None => text.replace(" [kN]", ""),
        };
        let table = ResultsTable::parse(&text, Path::new("f.csv")).unwrap();
        assess_table(
            &table,
            &["a, quoted".to_string()],
            300.0,
            Criterion::GuidingForces {
                static_wheel_load_n: 70e3,
            },
            &StabilitySettings::default(),
        )
    }

    #[test]
    fn a_band_clamped_below_2_1_hz_is_noted() {
        let at = |f: f64| assess_sine(6.0, f, 20.0);
        assert!(at(4.0).band_notes().is_empty());
        let low = at(1.0);
        let notes = low.band_notes();
        assert_eq!(notes.len(), 1, "{notes:?}");
        assert!(
            notes[0].contains("dominant frequency 1.00 Hz")
                && notes[0].contains("clamped to 0.1 Hz"),
            "{notes:?}"
        );
        assert!(low.summary().contains("note: signal 'a, quoted'"));
    }

    #[test]
    fn a_column_without_a_unit_is_assessed_with_a_note_saying_what_was_assumed() {
        let r = assess_forces(None).unwrap();
        assert_eq!(r.unitless, ["a, quoted"]);
        let summary = r.summary();
        assert!(
            summary.contains("note: column 'a, quoted' names no unit: its values were taken in N"),
            "{summary}"
        );
        // a labelled column gets no note
        let r = assess_forces(Some("kN")).unwrap();
        assert!(r.unit_notes().is_empty() && !r.summary().contains("note:"));
    }

    #[test]
    fn forces_in_kn_are_converted_and_wrong_units_refused() {
        let text = sine_table(20.0, 5.0, 500.0, 10.0, "kN");
        let table = ResultsTable::parse(&text, Path::new("f.csv")).unwrap();
        let r = assess_table(
            &table,
            &["a, quoted".to_string()],
            300.0,
            Criterion::GuidingForces {
                static_wheel_load_n: 70e3,
            },
            &StabilitySettings::default(),
        )
        .unwrap();
        // reported in kN: 20 kN amplitude -> 14.1 kN rms against (10 + 2*70/3)/2 = 28.3 kN
        assert!(
            (r.signals[0].1.max_rms - 14.14).abs() < 0.3,
            "{:?}",
            r.signals[0].1.max_rms
        );
        assert!(r.stable());
        let e = assess_table(
            &table,
            &["a, quoted".to_string()],
            300.0,
            Criterion::LateralAcceleration { bogie_mass_t: 6.1 },
            &StabilitySettings::default(),
        )
        .unwrap_err();
        assert!(e.to_string().contains("wrong unit"), "{e}");
    }

    #[test]
    fn bad_tables_name_the_file_and_line() {
        let p = Path::new("bad.csv");
        let e = ResultsTable::parse("time,a\n0,1\n0.1,x\n", p).unwrap_err();
        assert!(
            e.to_string().contains("bad.csv:3") && e.to_string().contains("'x'"),
            "{e}"
        );
        let e = ResultsTable::parse("time,a\nx,1\n", p).unwrap_err();
        assert!(
            e.to_string().contains("bad.csv:2: 'x' in column 'time'"),
            "{e}"
        );
        // a text column (a recorded String, an Enumeration's item) is left out; asking for it
        // says why
        let csv = "time,model,model (item),a,label\n0,1,nonlinear,2,AA\n0.1,1,nonlinear,3,\n";
        let t = ResultsTable::parse(csv, p).unwrap();
        assert_eq!(t.names, vec!["time", "model", "a"]);
        assert_eq!(t.columns[2], vec![2.0, 3.0]);
        let e = t.find("model (item)").unwrap_err().to_string();
        assert!(
            e.contains("bad.csv:2: 'nonlinear' in column 'model (item)' is not a number"),
            "{e}"
        );
        assert!(e.ends_with("signal 'model (item)' is not numeric"), "{e}");
        let e = t.find("label").unwrap_err().to_string();
        assert!(e.contains("bad.csv:2: 'AA'"), "{e}");
        // a String is quoted by our writer: text whatever it holds (a number, NaN, a line
        // break); a column with a value that is not finite is left out, named when asked for
        let csv =
            "time,s,t,u,a,b\n0,\"12\",\"NaN\",\"two\nlines\",2,inf\n0.1,\"13\",\"x\",\"y\",3,1\n";
        let t = ResultsTable::parse(csv, p).unwrap();
        assert_eq!(t.names, vec!["time", "a"]);
        assert_eq!(t.columns[1], vec![2.0, 3.0]);
        let e = t.find("b").unwrap_err().to_string();
        assert!(
            e.contains("bad.csv:2: inf in column 'b' is not finite"),
            "{e}"
        );
        let e = t.find("s").unwrap_err().to_string();
        assert!(e.contains("'12' in column 's' is not a number"), "{e}");
        // a quoted field left open is named at the line its record starts on
        let e = ResultsTable::parse("time,a\n0,1\n0.1,\"2\n", p).unwrap_err();
        assert!(
            e.to_string()
                .contains("bad.csv:3: unterminated quoted field"),
            "{e}"
        );
        let e = ResultsTable::parse("time,a\n0,1,2\n", p).unwrap_err();
        assert!(e.to_string().contains("bad.csv:2"), "{e}");
        let e = ResultsTable::parse("time,a\n0,NaN\n", p).unwrap_err();
        assert!(e.to_string().contains("not finite"), "{e}");
        let e = ResultsTable::parse("# only a comment\n", p).unwrap_err();
        assert!(e.to_string().contains("no header"), "{e}");
        // whitespace and semicolons, comments
        let t = ResultsTable::parse("# c\ntime a b\n0 1 2\n1 3 4\n", p).unwrap();
        assert_eq!(t.columns[2], vec![2.0, 4.0]);
        let t = ResultsTable::parse("time;a\n0;1\n", p).unwrap();
        assert_eq!(t.names, vec!["time", "a"]);
        // metadata of another recording: 10 Hz recorded beside a 1 kHz time column
        let mut t = ResultsTable::parse("time,a\n0,1\n0.001,2\n0.002,3\n", p).unwrap();
        t.sampling = Some(Sampling {
            rate_hz: 10.0,
            passband_hz: 5.0,
            decimation: None,
        });
        let e = t.clone().check_recorded_rate().unwrap_err().to_string();
        assert!(
            e.contains("records a sampling rate of 10 Hz") && e.contains("1000 Hz"),
            "{e}"
        );
        t.sampling = Some(Sampling {
            rate_hz: 1000.0,
            passband_hz: 500.0,
            decimation: None,
        });
        assert!(t.check_recorded_rate().is_ok());
        // a whitespace-separated header carries units as the others do
        let t = ResultsTable::parse("time [ms]   a [m/s2]\n0 1\n1 3\n", p).unwrap();
        assert_eq!(t.names, vec!["time [ms]", "a [m/s2]"]);
        assert_eq!(t.columns[1], vec![1.0, 3.0]);
        // unknown signal lists the available ones
        let e = t.find("b").unwrap_err();
        assert!(e.to_string().contains("the signals are: a"), "{e}");
        // non-uniform time
        let t = ResultsTable::parse("time,a\n0,1\n0.1,1\n0.3,1\n0.4,1\n", p).unwrap();
        let e = t.sampling_rate_hz().unwrap_err();
        assert!(e.to_string().contains("not uniformly sampled"), "{e}");
        // one missing sample in a long record is named where it is, against the usual step
        let mut text = String::from("time,a\n");
        for k in (0..1000).filter(|&k| k != 700) {
            text.push_str(&format!("{},1\n", k as f64 * 1e-3));
        }
        let e = ResultsTable::parse(&text, p)
            .unwrap()
            .sampling_rate_hz()
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("(step 0.002 s after t = 0.699 s, where the others are 0.001 s)"),
            "{e}"
        );
        // a NaN or an infinity inside the time column of columns given as such (Python's
        // assess_stability; a file's are refused when read): a NaN passes every step comparison
        for bad in [f64::NAN, f64::INFINITY] {
            let mut t = ResultsTable::parse("time,a\n0,1\n0.1,1\n0.2,1\n0.3,1\n", p).unwrap();
            t.columns[0][2] = bad;
            let e = t.sampling_rate_hz().unwrap_err().to_string();
            assert!(e.contains("the time column (first column) holds"), "{e}");
            assert!(e.contains("at sample 3"), "{e}");
        }
    }

    #[test]
    fn too_short_records_are_refused() {
        let table = ResultsTable::parse(
            &sine_table(1.0, 4.0, 200.0, 1.0, "m/s2"),
            Path::new("s.csv"),
        )
        .unwrap();
        let e = assess_table(
            &table,
            &["other".to_string()],
            200.0,
            Criterion::LateralAcceleration { bogie_mass_t: 6.1 },
            &StabilitySettings::default(),
        )
        .unwrap_err();
        assert!(e.to_string().contains("less than one 100 m window"), "{e}");
    }
}
