//! The study's wall time with this build against an earlier build of the `master` binary,
//! measured in one run: the quick study (`master study --quick`) with the earlier binary and
//! with this one alternately, in pairs (the order swapped from one pair to the next, so a
//! drifting machine load favours neither), wall and CPU time of each, the ratio per pair and
//! its median, the load average beside every figure. The first pair also checks that both give
//! the same runs (every results.csv byte for byte, every Parquet file's values; a build that
//! writes the other format is reported, not compared).
//!
//! `MASTER_BEFORE=/path/to/earlier/master cargo bench -p rail-study --bench study_wall`;
//! optional `STUDY_PAIRS` (default 3), `STUDY_JOBS` (default: all cores); needs dist/.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)] // bench code

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use common::{cpu_seconds, load_average};

fn dist() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../dist")
}

/// One quick study with `binary` into `out`: (wall [s], CPU of the child [s], load before).
fn study(binary: &Path, out: &Path, jobs: &str) -> (f64, f64, f64) {
    let load = load_average();
    let cpu0 = cpu_seconds(true);
    let started = Instant::now();
    let status = Command::new(binary)
        .args(["--quiet", "study", "--quick", "--jobs", jobs, "--fmus"])
        .arg(dist())
        .arg("--out")
        .arg(out)
        .stdout(std::process::Stdio::null())
        .status()
        .unwrap();
    assert!(status.success(), "{} failed", binary.display());
    (
        started.elapsed().as_secs_f64(),
        cpu_seconds(true) - cpu0,
        load,
    )
}

/// Relative paths of every results file (results.csv, *.parquet) below `dir/runs`.
fn results(dir: &Path) -> Vec<PathBuf> {
    let mut found = Vec::new();
    let mut todo = vec![dir.join("runs")];
    while let Some(d) = todo.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                todo.push(p);
            } else if p.file_name().is_some_and(|n| n == "results.csv")
                || p.extension().is_some_and(|e| e == "parquet")
            {
                found.push(p.strip_prefix(dir).unwrap().to_path_buf());
            }
        }
    }
    found.sort();
    found
}

fn main() {
    let Some(before) = std::env::var_os("MASTER_BEFORE").map(PathBuf::from) else {
        eprintln!("set MASTER_BEFORE to an earlier build of the master binary to compare with");
        return;
    };
    if !dist().join("Bogie2Dof.fmu").exists() {
        eprintln!("dist/ not built: skipping");
        return;
    }
    let now = PathBuf::from(env!("CARGO_BIN_EXE_master"));
    let pairs: usize = std::env::var("STUDY_PAIRS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(3);
    let jobs = std::env::var("STUDY_JOBS").unwrap_or_else(|_| {
        std::thread::available_parallelism()
            .map_or(1, |n| n.get())
            .to_string()
    });
    let tmp = tempfile::tempdir().unwrap();
    let mut ratios = Vec::new();
    for pair in 0..pairs {
        let (a, b) = (tmp.path().join("before"), tmp.path().join("now"));
        let _ = (std::fs::remove_dir_all(&a), std::fs::remove_dir_all(&b));
        let (old, new) = if pair % 2 == 0 {
            let old = study(&before, &a, &jobs);
            (old, study(&now, &b, &jobs))
        } else {
            let new = study(&now, &b, &jobs);
            (study(&before, &a, &jobs), new)
        };
        println!(
            "pair {}: before {:.1} s wall, {:.1} s CPU (load {:.2}); now {:.1} s wall, {:.1} s CPU (load {:.2}); wall ratio before/now {:.2}, CPU ratio {:.2}",
            pair + 1,
            old.0,
            old.1,
            old.2,
            new.0,
            new.1,
            new.2,
            old.0 / new.0,
            old.1 / new.1
        );
        ratios.push((old.0 / new.0, old.1 / new.1));
        if pair == 0 {
            let files = results(&a);
            if files != results(&b) {
                println!(
                    "runs not compared: the two builds wrote different results files ({} and {})",
                    files.len(),
                    results(&b).len()
                );
            } else {
                // a Parquet file holds the run's wall time in its metadata: compare the values
                let same = |f: &PathBuf| {
                    if f.extension().is_some_and(|e| e == "parquet") {
                        let read = |d: &Path| {
                            master::parquet_file::read_results_parquet(&d.join(f))
                                .unwrap()
                                .0
                        };
                        let (x, y) = (read(&a), read(&b));
                        x.header == y.header && x.data == y.data
                    } else {
                        std::fs::read(a.join(f)).unwrap() == std::fs::read(b.join(f)).unwrap()
                    }
                };
                let differing: Vec<&PathBuf> = files.iter().filter(|f| !same(f)).collect();
                println!(
                    "runs compared: {} results files, {} differ {:?}",
                    files.len(),
                    differing.len(),
                    differing
                );
            }
        }
    }
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    println!(
        "median over {pairs} pairs: wall ratio before/now {:.2}, CPU ratio {:.2} (jobs {jobs}, load now {:.2})",
        median(ratios.iter().map(|r| r.0).collect()),
        median(ratios.iter().map(|r| r.1).collect()),
        load_average()
    );
}
