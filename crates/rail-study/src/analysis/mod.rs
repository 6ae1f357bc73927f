//! Offline analyses behind the `characterise`, `contact-geometry`, `root-locus` and `assess`
//! subcommands: plain functions that compute data from the physics crates and turn it into
//! in-memory result files ([`Artefacts`]: CSV text and SVG figures). The commands only parse
//! options, call these, print a summary and write the artefacts, so a failure anywhere before
//! the write leaves no file behind.
//!
//! * [`figures`]: line charts with logarithmic axes and scatter plots coloured by a third
//!   variable (the plain linear charts come from [`crate::plot`]).
//! * [`damper`], [`actuator`]: hysteresis loops and damper FRFs, actuator FRFs (crate
//!   `fmu-damper`).
//! * [`geometry`]: wheel/rail contact tables and equivalent conicity (crate `wheel-rail`).
//! * [`locus`]: eigenvalues of the linear bogie over speed (crate `fmu-bogie2dof`).
//! * [`locus_figures`]: the eigenvalue table and figures both root loci draw.
//! * [`vehicle_locus`]: eigenvalues of the linear coach over speed, modes named (crate
//!   `fmu-vehicle`).
//! * [`assess`]: EN 14363 assessment of recorded signals (ours or a host's export).

use std::path::{Path, PathBuf};

use crate::plot::{Chart, PlotError};
use master::output::{bytes_unfinished, csv_field, OutputError, Unfinished};

pub mod actuator;
pub mod assess;
pub mod damper;
pub mod figures;
pub mod geometry;
pub mod locus;
pub mod locus_figures;
pub mod vehicle_locus;

/// Failure of an analysis. Messages name the model, file or option concerned.
#[derive(Debug, thiserror::Error)]
pub enum AnalysisError {
    #[error("damper model: {0}")]
    Damper(#[from] fmu_damper::StepError),
    #[error("damper parameters: {0}")]
    DamperParam(#[from] fmu_damper::ParamError),
    #[error("{0}")]
    Profile(#[from] wheel_rail::ProfileError),
    #[error("contact geometry: {0}")]
    Contact(#[from] wheel_rail::ContactError),
    #[error("equivalent conicity: {0}")]
    Conicity(#[from] wheel_rail::ConicityError),
    #[error("contact geometry: {0}")]
    Geometry(String),
    /// An error of a linear model's eigen-analysis (the message starts with the model).
    #[error("linear model of the {0}")]
    LinearModel(String),
    /// A results table or signal that cannot be assessed (message names file, line, column).
    #[error("{0}")]
    Input(String),
    #[error("invalid option {option} = {}: {reason}", master::show::text(.value))]
    Option {
        option: &'static str,
        value: String,
        reason: String,
    },
    #[error("interrupted")]
    Cancelled,
    #[error("{0}")]
    Output(#[from] OutputError),
    #[error("{0}")]
    Plot(#[from] PlotError),
}

/// Prints a command's summary and the list of written files to stdout. A closed stdout
/// (`master ... | head`) is not an error: the files are already written.
pub fn print_report(summary: &str, files: &Artefacts, dir: &Path) {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    let _ = write!(out, "{summary}");
    let _ = writeln!(
        out,
        "wrote {} files to {}: {}",
        files.files.len(),
        dir.display(),
        files.names().join(", ")
    );
}

/// Returns [`AnalysisError::Cancelled`] once `cancel` is set (Ctrl-C).
pub fn check_cancel(cancel: &std::sync::atomic::AtomicBool) -> Result<(), AnalysisError> {
    if cancel.load(std::sync::atomic::Ordering::SeqCst) {
        Err(AnalysisError::Cancelled)
    } else {
        Ok(())
    }
}

/// A numeric table: header (names with units) and rows of equal length.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Table {
    pub header: Vec<String>,
    pub rows: Vec<Vec<f64>>,
}

impl Table {
    pub fn new(header: &[&str]) -> Self {
        Table {
            header: header.iter().map(|h| h.to_string()).collect(),
            rows: Vec::new(),
        }
    }

    /// CSV text; numbers with Rust's shortest round-trip formatting. Rows whose length differs
    /// from the header are an error naming the table.
    pub fn to_csv(&self, name: &str) -> Result<String, OutputError> {
        let mut out = String::new();
        let head: Vec<String> = self.header.iter().map(|h| csv_field(h)).collect();
        out.push_str(&head.join(","));
        out.push('\n');
        for (i, row) in self.rows.iter().enumerate() {
            if row.len() != self.header.len() {
                return Err(OutputError::RowLength {
                    path: PathBuf::from(name),
                    row: i,
                    got: row.len(),
                    expected: self.header.len(),
                });
            }
            let cells: Vec<String> = row.iter().map(|v| v.to_string()).collect();
            out.push_str(&cells.join(","));
            out.push('\n');
        }
        Ok(out)
    }
}

/// Result files of an analysis, held in memory until everything has been computed.
#[derive(Debug, Clone, Default)]
pub struct Artefacts {
    /// (file name inside the output folder, content)
    pub files: Vec<(String, Vec<u8>)>,
}

impl Artefacts {
    pub fn add_text(&mut self, name: &str, text: String) {
        self.files.push((name.to_string(), text.into_bytes()));
    }

    pub fn add_table(&mut self, name: &str, table: &Table) -> Result<(), OutputError> {
        let text = table.to_csv(name)?;
        self.add_text(name, text);
        Ok(())
    }

    /// Adds a line chart drawn by [`crate::plot`] (linear axes).
    pub fn add_lines(&mut self, name: &str, chart: &Chart) -> Result<(), PlotError> {
        self.add_text(name, chart.to_svg(false)?);
        Ok(())
    }

    /// Adds a line chart with the given axis scales.
    pub fn add_scaled_lines(
        &mut self,
        name: &str,
        chart: &Chart,
        x: figures::Scale,
        y: figures::Scale,
    ) -> Result<(), PlotError> {
        self.add_text(name, figures::lines_svg(chart, x, y)?);
        Ok(())
    }

    pub fn names(&self) -> Vec<&str> {
        self.files.iter().map(|(n, _)| n.as_str()).collect()
    }

    /// Creates `dir` (and parents) and writes every file into a temporary file beside its
    /// destination, none committed yet: a failed write (a full disk) removes the ones written
    /// and leaves the folder as it was.
    pub fn stage_all(&self, dir: &Path) -> Result<Vec<Unfinished>, OutputError> {
        std::fs::create_dir_all(dir).map_err(|source| OutputError::Io {
            path: dir.to_path_buf(),
            source,
        })?;
        // every file checked before the first is written: a folder in place of one of them
        // must not leave the others new and the rest from an earlier call
        let paths: Vec<PathBuf> = self.files.iter().map(|(name, _)| dir.join(name)).collect();
        master::output::check_outputs_apart(&[], &paths)?;
        self.files
            .iter()
            .zip(&paths)
            .map(|((_, bytes), path)| bytes_unfinished(path, bytes))
            .collect()
    }

    /// Writes every file ([`Self::stage_all`]) and only then renames them onto their names,
    /// so that a failed write replaces none of the earlier files; returns the paths written.
    pub fn write_all(&self, dir: &Path) -> Result<Vec<PathBuf>, OutputError> {
        commit_all(self.stage_all(dir)?)
    }
}

/// Renames staged files onto their destinations, in order; returns their paths.
pub fn commit_all(staged: Vec<Unfinished>) -> Result<Vec<PathBuf>, OutputError> {
    let mut written = Vec::with_capacity(staged.len());
    for file in staged {
        written.push(file.path().to_path_buf());
        file.commit()?;
    }
    Ok(written)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_csv_and_row_length_error() {
        let mut t = Table::new(&["f [Hz]", "a,b"]);
        t.rows.push(vec![1.0, 2.5]);
        assert_eq!(t.to_csv("t.csv").unwrap(), "f [Hz],\"a,b\"\n1,2.5\n");
        t.rows.push(vec![1.0]);
        let e = t.to_csv("t.csv").unwrap_err();
        assert!(e.to_string().contains("t.csv") && e.to_string().contains("row 1"));
    }

    #[test]
    fn artefacts_are_written_only_on_request() {
        let d = tempfile::tempdir().unwrap();
        let out = d.path().join("sub/dir");
        let mut a = Artefacts::default();
        a.add_text("x.csv", "a\n1\n".into());
        assert!(!out.exists());
        let paths = a.write_all(&out).unwrap();
        assert_eq!(paths.len(), 1);
        assert_eq!(std::fs::read_to_string(&paths[0]).unwrap(), "a\n1\n");
        assert_eq!(a.names(), vec!["x.csv"]);
    }

    #[test]
    fn a_set_that_cannot_be_written_in_full_replaces_none_of_the_earlier_files() {
        let d = tempfile::tempdir().unwrap();
        let mut a = Artefacts::default();
        a.add_text("a.csv", "new a\n".into());
        a.add_text("b.csv", "new b\n".into());
        std::fs::write(d.path().join("a.csv"), "old a\n").unwrap();
        std::fs::write(d.path().join("b.csv"), "old b\n").unwrap();
        // staged, not committed: the earlier files stay until the whole set is written
        let staged = a.stage_all(d.path()).unwrap();
        assert_eq!(staged.len(), 2);
        let read = |n: &str| std::fs::read_to_string(d.path().join(n)).unwrap();
        assert_eq!(
            (read("a.csv"), read("b.csv")),
            ("old a\n".into(), "old b\n".into())
        );
        drop(staged);
        let names = |d: &Path| {
            let mut v: Vec<String> = std::fs::read_dir(d)
                .unwrap()
                .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
                .collect();
            v.sort();
            v
        };
        // dropped (a later file failed): no temporary file left, nothing replaced
        assert_eq!(names(d.path()), vec!["a.csv", "b.csv"]);
        assert_eq!(read("a.csv"), "old a\n");
        let written = a.write_all(d.path()).unwrap();
        assert_eq!(written.len(), 2);
        assert_eq!(
            (read("a.csv"), read("b.csv")),
            ("new a\n".into(), "new b\n".into())
        );
    }
}
