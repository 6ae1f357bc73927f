//! Results files of one full-rate study run: Parquet against CSV, and where the bytes go.

use std::path::Path;
use std::time::Instant;

use master::runset::run_job;
use master::system::PreparedSystem;

use crate::{load_average, repo, Report};

/// Size and read time of the results of one full-rate 15 s run of the coach study
/// (passive, 300 km/h, track seed 1) as Parquet and as CSV, and of the CSV decimated to
/// 100 Hz through the anti-aliasing filter; read as `master assess` reads them
/// ([`rail_study::analysis::assess::ResultsTable::load`]), best of 5.
pub fn results_files(r: &mut Report) {
    use master::decimation::decimate;
    use master::results::{write_results, ResultsFormat, RunContext};
    use rail_study::analysis::assess::ResultsTable;
    use rail_study::study::config::{RunRequest, Sources};
    use rail_study::study::configurations::configuration;
    use rail_study::study::VehicleModel;
    let sources = Sources {
        fmus: repo().join("dist"),
        systems: None,
    };
    let Some(passive) = configuration("passive") else {
        return r.line("- results files: no passive configuration".into());
    };
    let system = match sources.system(VehicleModel::Coach, passive) {
        Ok(s) => s,
        Err(e) => return r.line(format!("- results files: not measured ({e})")),
    };
    let prepared = PreparedSystem::prepare(&system).unwrap();
    let job = RunRequest::new("", VehicleModel::Coach, passive, 300.0, Some(1), 15.0)
        .job(&system)
        .unwrap();
    let cancel = std::sync::atomic::AtomicBool::new(false);
    let out = run_job(&prepared, &job, &cancel).unwrap();
    let dir = tempfile::tempdir().unwrap();
    // as a run set stores it: the run's name and parameters as constant columns
    let ctx = RunContext {
        run: Some("sweep-passive_v300_s1".into()),
        parameters: job.parameters.clone(),
        ..RunContext::default()
    };
    let files = [
        (
            "Parquet, full rate",
            "full.parquet",
            ResultsFormat::Parquet,
            1,
        ),
        ("CSV, full rate", "full.csv", ResultsFormat::Csv, 1),
        (
            "CSV, 100 Hz (anti-aliased)",
            "small.csv",
            ResultsFormat::Csv,
            10,
        ),
    ];
    r.line(String::new());
    r.line(format!(
        "## Results files of one 15 s run (coach, passive, 300 km/h: {} rows x {} columns at 1 kHz)",
        out.rows().count(),
        out.header.len()
    ));
    r.line(String::new());
    r.line("| file | size | read time (best of 5) | load average |".into());
    r.line("|---|---|---|---|".into());
    let mut sizes = Vec::new();
    for (what, name, format, factor) in files {
        let path = dir.path().join(name);
        write_results(&path, &decimate(&out, factor).unwrap(), format, &ctx).unwrap();
        let bytes = std::fs::metadata(&path).unwrap().len();
        let best = (0..5)
            .map(|_| {
                let started = Instant::now();
                let t = ResultsTable::load(&path).unwrap();
                std::hint::black_box(t.columns.len());
                started.elapsed().as_secs_f64()
            })
            .fold(f64::INFINITY, f64::min);
        sizes.push((bytes, best));
        r.line(format!(
            "| {what} | {:.2} MB | {:.1} ms | {} |",
            bytes as f64 / 1e6,
            best * 1e3,
            load_average()
        ));
    }
    r.line(format!(
        "- full rate: Parquet / CSV size {:.2}, read time {:.2}; Parquet at the full rate / CSV at 100 Hz size {:.2}",
        sizes[0].0 as f64 / sizes[1].0 as f64,
        sizes[0].1 / sizes[1].1,
        sizes[0].0 as f64 / sizes[2].0 as f64
    ));
    parquet_columns(r, &dir.path().join("full.parquet"), &out.header, sizes[2].0);
}

/// Where the bytes of a full-rate Parquet results file go: the compressed size of each
/// column chunk (from the file's footer), grouped as the time, the recorded signals and the
/// constant columns (run name and parameters), against the CSV at 100 Hz (`csv_100hz_bytes`).
fn parquet_columns(r: &mut Report, path: &Path, header: &[String], csv_100hz_bytes: u64) {
    use parquet::file::reader::{FileReader, SerializedFileReader};
    let reader = SerializedFileReader::new(std::fs::File::open(path).unwrap()).unwrap();
    let meta = reader.metadata();
    let rows = meta.file_metadata().num_rows() as f64;
    let mut time = 0i64;
    let mut signals: Vec<(String, i64)> = Vec::new();
    let mut constants = (0usize, 0i64);
    for g in meta.row_groups() {
        for c in g.columns() {
            let name = c.column_path().string();
            let bytes = c.compressed_size();
            if name == header[0] {
                time += bytes;
            } else if header.contains(&name) {
                match signals.iter_mut().find(|(n, _)| *n == name) {
                    Some(s) => s.1 += bytes,
                    None => signals.push((name, bytes)),
                }
            } else {
                constants.0 += 1;
                constants.1 += bytes;
            }
        }
    }
    let file = std::fs::metadata(path).unwrap().len() as i64;
    let signal_bytes: i64 = signals.iter().map(|s| s.1).sum();
    let mut per_value: Vec<f64> = signals.iter().map(|s| s.1 as f64 / rows).collect();
    per_value.sort_by(f64::total_cmp);
    let rest = file - time - signal_bytes - constants.1;
    r.line(String::new());
    r.line("Where the full-rate Parquet file's bytes go (compressed column chunks; float64, zstd level 3, byte-stream split):".into());
    r.line(String::new());
    r.line("| columns | count | bytes | bytes per row and column |".into());
    r.line("|---|---|---|---|".into());
    r.line(format!("| time | 1 | {time} | {:.2} |", time as f64 / rows));
    if let (Some(lo), Some(hi)) = (per_value.first(), per_value.last()) {
        r.line(format!(
            "| signals | {} | {signal_bytes} | {:.2} ({lo:.2} to {hi:.2}) |",
            signals.len(),
            signal_bytes as f64 / rows / signals.len() as f64
        ));
    }
    r.line(format!(
        "| run name and parameters (constant) | {} | {} | {:.3} |",
        constants.0,
        constants.1,
        constants.1 as f64 / rows / constants.0.max(1) as f64
    ));
    r.line(format!(
        "| footer and metadata (units, FMU variables, system) | | {rest} | |"
    ));
    r.line(format!(
        "- the CSV at 100 Hz is {:.2} bytes per full-rate row and column; the full-rate signals alone take {:.2} times the whole 100 Hz CSV",
        csv_100hz_bytes as f64 / rows / header.len() as f64,
        signal_bytes as f64 / csv_100hz_bytes as f64
    ));
}
