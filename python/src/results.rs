//! Results tables as the master's files hold them: a CSV written by the master
//! (`master::results::write_results`: a header of RFC 4180 fields, numbers in Rust's shortest
//! round-trip form, Strings and Enumeration item names as text, the column types in
//! `<name>.meta.json` beside it), a Parquet file (the master's reader), or a run's own
//! output. Numbers are parsed with Rust's `f64::from_str`, which is correctly rounded, so
//! every value read back is the bit pattern that was written.
//!
//! A [`Table`] has the columns of the master's files ([`master::output::results_header`]):
//! each recorded variable, and after an Enumeration the column of its item names. Text columns
//! (Strings, item names) hold NaN among the numbers and their texts beside them.

use std::collections::BTreeMap;
use std::path::Path;

use master::coupling::{ColumnInfo, SimOutput, Summary};
use master::output::results_header;
use master::results::{read_metadata, ColumnMetadata, ResultsFormat, ResultsMetadata};
use master::slave::ScalarType;

/// A results table: `header[0]` is `time [s]`; `data` is row-major, `header.len()` per row,
/// NaN in a text column; `texts` holds each text column's values (by column index).
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    pub header: Vec<String>,
    pub data: Vec<f64>,
    pub texts: Vec<(usize, Vec<String>)>,
}

/// The label of the column holding an Enumeration's item names, as the master writes it.
pub fn item_label(label: &str) -> String {
    format!("{label} (item)")
}

/// [`expand`], taking the output: a table of numbers only (no String or Enumeration column)
/// keeps the output's values instead of copying them, so that a long run's results are held
/// once, not twice, on their way to Python.
pub fn expand_owned(out: SimOutput) -> Table {
    let numbers_only = (0..out.header.len()).all(|c| {
        !matches!(
            out.column_info(c).scalar_type(),
            ScalarType::String | ScalarType::Enumeration
        )
    });
    if numbers_only {
        let header = results_header(&out);
        Table {
            header,
            data: out.data,
            texts: Vec::new(),
        }
    } else {
        expand(&out)
    }
}

/// The table of a run's output with the columns the master's files have: a String column as
/// its texts, an Enumeration as its integer followed by its item names.
pub fn expand(out: &SimOutput) -> Table {
    let header = results_header(out);
    let infos: Vec<ColumnInfo> = (0..out.header.len()).map(|c| out.column_info(c)).collect();
    let mut texts: Vec<(usize, Vec<String>)> = Vec::new();
    let mut k = 0;
    for info in &infos {
        match info.scalar_type() {
            ScalarType::String => texts.push((k, Vec::new())),
            ScalarType::Enumeration => {
                k += 1;
                texts.push((k, Vec::new()));
            }
            _ => {}
        }
        k += 1;
    }
    let rows = out.rows().count();
    let mut data = Vec::with_capacity(rows * header.len());
    for row in out.rows() {
        let mut t = texts.iter_mut();
        for (&v, info) in row.iter().zip(&infos) {
            match info.scalar_type() {
                ScalarType::String => {
                    data.push(f64::NAN);
                    if let Some((_, col)) = t.next() {
                        col.push(out.text(v).unwrap_or("").to_string());
                    }
                }
                ScalarType::Enumeration => {
                    data.push(v);
                    data.push(f64::NAN);
                    if let Some((_, col)) = t.next() {
                        col.push(info.item(v).unwrap_or("").to_string());
                    }
                }
                _ => data.push(v),
            }
        }
    }
    Table {
        header,
        data,
        texts,
    }
}

/// A run's summary from JSON: the statistics given, 0 for those missing (a table that did
/// not come from a run has none).
pub fn summary(json: &str) -> Result<Summary, String> {
    let mut v = serde_json::json!({
        "steps": 0, "rejected_steps": 0, "simulated_time_s": 0.0, "wall_time_s": 0.0,
        "realtime_ratio": 0.0,
    });
    let given: serde_json::Value =
        serde_json::from_str(json).map_err(|e| format!("summary: {e}"))?;
    let serde_json::Value::Object(given) = given else {
        return Err(format!("summary: {given} is not an object"));
    };
    if let Some(o) = v.as_object_mut() {
        o.extend(given);
    }
    serde_json::from_value(v).map_err(|e| format!("summary: {e}"))
}

/// The header the master writes for the columns of `meta`, and which of its columns hold
/// texts.
fn described_header(time: &str, columns: &[ColumnMetadata]) -> (Vec<String>, Vec<bool>) {
    let mut header = vec![time.to_string()];
    let mut text = vec![false];
    for c in columns {
        header.push(c.label.clone());
        text.push(c.info.scalar_type() == ScalarType::String);
        if c.info.scalar_type() == ScalarType::Enumeration {
            header.push(item_label(&c.label));
            text.push(true);
        }
    }
    (header, text)
}

/// The run output a table stands for, to be written by the master's writers: its columns
/// described by `columns` (as the metadata of the file or run it came from lists them;
/// empty: every column a Real, or a String where the table holds texts). The item-name
/// columns are left out (the writers derive them from the values); a String's texts become
/// indices into `strings`.
pub fn collapse(table: &Table, columns: &[ColumnMetadata]) -> Result<SimOutput, String> {
    if table.header.is_empty() {
        return Err("a results table needs a time column (the header is empty)".into());
    }
    let n = table.header.len();
    if !table.data.len().is_multiple_of(n) {
        return Err(format!(
            "{} values do not fill rows of {n} columns",
            table.data.len()
        ));
    }
    let rows = table.data.len() / n;
    let texts: BTreeMap<usize, &Vec<String>> = table.texts.iter().map(|(c, t)| (*c, t)).collect();
    if let Some((c, t)) = texts.iter().find(|(_, t)| t.len() != rows) {
        return Err(format!(
            "column '{}' has {} texts for {rows} rows",
            table.header.get(*c).map_or("?", String::as_str),
            t.len()
        ));
    }
    let infos: Vec<ColumnInfo> = if columns.is_empty() {
        (1..table.header.len())
            .map(|c| {
                let (name, unit) = split_label(&table.header[c]);
                ColumnInfo {
                    ty: texts.contains_key(&c).then_some(ScalarType::String),
                    name: name.to_string(),
                    unit: unit.map(str::to_string),
                    ..ColumnInfo::default()
                }
            })
            .collect()
    } else {
        let time = table.header.first().map_or("time [s]", String::as_str);
        let (expected, _) = described_header(time, columns);
        if expected != table.header {
            return Err(format!(
                "the columns [{}] are not those their metadata describes [{}]",
                table.header.join(", "),
                expected.join(", ")
            ));
        }
        columns.iter().map(|c| c.info.clone()).collect()
    };
    // the kept columns: every one but an Enumeration's item names
    let mut keep = vec![0usize];
    let mut c = 1;
    for info in &infos {
        keep.push(c);
        c += if info.scalar_type() == ScalarType::Enumeration {
            2
        } else {
            1
        };
    }
    let mut strings: Vec<String> = Vec::new();
    let mut index: BTreeMap<&str, usize> = BTreeMap::new();
    let mut data = Vec::with_capacity(rows * keep.len());
    for r in 0..rows {
        for (k, &c) in keep.iter().enumerate() {
            let is_string = k > 0 && infos[k - 1].scalar_type() == ScalarType::String;
            if !is_string {
                data.push(table.data[r * n + c]);
                continue;
            }
            let text = texts.get(&c).map_or("", |t| t[r].as_str());
            let i = *index.entry(text).or_insert_with(|| {
                strings.push(text.to_string());
                strings.len() - 1
            });
            data.push(i as f64);
        }
    }
    Ok(SimOutput {
        header: keep.iter().map(|&c| table.header[c].clone()).collect(),
        data,
        summary: Summary {
            steps: 0,
            rejected_steps: 0,
            simulated_time_s: 0.0,
            wall_time_s: 0.0,
            realtime_ratio: 0.0,
            terminated: None,
            failed: None,
        },
        columns: infos,
        strings,
        decimation: None,
    })
}

/// Splits a column label `name [unit]` into its name and unit (`None` when it has none).
pub fn split_label(label: &str) -> (&str, Option<&str>) {
    match label.strip_suffix(']').and_then(|l| l.rsplit_once(" [")) {
        Some((name, unit)) if !name.is_empty() => (name, Some(unit)),
        _ => (label, None),
    }
}

/// Parses the text of a results CSV; `file` names it in messages. `columns` (the file's
/// metadata, empty when it has none) tells which columns hold texts; every other field is a
/// number.
pub fn parse_csv(text: &str, file: &str, columns: &[ColumnMetadata]) -> Result<Table, String> {
    // records, not lines: a quoted String may hold a line break; one at a time, so that a
    // large file is held as its numbers, not also as the texts of its fields
    let mut records = master::csv_records::Records::new(text, false);
    let header = records
        .next()
        .transpose()
        .map_err(|e| format!("{file}: {e}"))?
        .ok_or_else(|| format!("{file}: empty file (no header line)"))?
        .texts();
    let time = header.first().map_or("", String::as_str);
    let is_text = match described_header(time, columns) {
        (described, text) if !columns.is_empty() && described == header => text,
        // no metadata, or metadata of other columns (not the master's pair): numbers only
        _ => vec![false; header.len()],
    };
    let mut texts: Vec<(usize, Vec<String>)> = (0..header.len())
        .filter(|&c| is_text[c])
        .map(|c| (c, Vec::new()))
        .collect();
    let mut data = Vec::new();
    for record in records {
        let record = record.map_err(|e| format!("{file}: {e}"))?;
        let n = record.line;
        if record.fields.len() != header.len() {
            return Err(format!(
                "{file}: line {n} has {} values but the header has {} columns",
                record.fields.len(),
                header.len()
            ));
        }
        let mut t = texts.iter_mut();
        for (k, field) in record.fields.into_iter().enumerate() {
            let field = field.text;
            if is_text[k] {
                data.push(f64::NAN);
                if let Some((_, col)) = t.next() {
                    col.push(field);
                }
                continue;
            }
            let x: f64 = field.trim().parse().map_err(|_| {
                format!(
                    "{file}: line {n}, column '{}': '{}' is not a number",
                    master::show::text(&header[k]),
                    master::show::text(&field)
                )
            })?;
            data.push(x);
        }
    }
    Ok(Table {
        header,
        data,
        texts,
    })
}

/// Reads a results file (CSV, with its metadata beside it when there is one, or Parquet
/// written by the master): the table and the metadata (`None`: a CSV without any).
pub fn read_results(path: &Path) -> Result<(Table, Option<ResultsMetadata>), String> {
    if ResultsFormat::of_path(path) == Some(ResultsFormat::Parquet) {
        let (out, meta) =
            master::parquet_file::read_results_parquet(path).map_err(|e| e.to_string())?;
        return Ok((expand(&out), Some(meta)));
    }
    let meta = read_metadata(path).map_err(|e| e.to_string())?;
    // a regular file only: a FIFO would block the caller (and Ctrl-C) for ever, /dev/zero
    // would fill the memory
    let text = master::input::open_regular_file(path)
        .and_then(|mut f| {
            let mut text = String::new();
            std::io::Read::read_to_string(&mut f, &mut text).map(|_| text)
        })
        .map_err(|e| format!("cannot read '{}': {e}", path.display()))?;
    let columns = meta.as_ref().map_or(&[][..], |m| &m.columns[..]);
    let table = parse_csv(&text, &path.display().to_string(), columns)?;
    Ok((table, meta))
}

#[cfg(test)]
mod tests {
    use super::*;
    use master::output::write_csv_atomic;

    #[test]
    fn what_the_master_writes_reads_back_bit_for_bit() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("results.csv");
        let header = vec![
            "time [s]".to_string(),
            "a.x, quoted \"name\" [m]".to_string(),
            "a.n".to_string(),
        ];
        let rows = [
            vec![0.0, 0.1 + 0.2, -0.0],
            vec![1e-3, f64::MIN_POSITIVE, 1.0 / 3.0],
            vec![2e-3, f64::NAN, f64::NEG_INFINITY],
        ];
        write_csv_atomic(&p, &header, rows.iter().map(|r| r.as_slice())).unwrap();
        let (t, meta) = read_results(&p).unwrap();
        assert!(meta.is_none() && t.texts.is_empty());
        assert_eq!(t.header, header);
        let want: Vec<u64> = rows.iter().flatten().map(|x| x.to_bits()).collect();
        let got: Vec<u64> = t.data.iter().map(|x| x.to_bits()).collect();
        // NaN has one canonical bit pattern in Rust's formatting and parsing
        assert_eq!(got, want);
    }

    #[test]
    fn a_fifo_or_a_device_is_refused_without_reading_it() {
        let dir = tempfile::tempdir().unwrap();
        let fifo = dir.path().join("r.csv");
        let made = std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap();
        assert!(made.success());
        // (a read would block: nobody writes to the FIFO)
        for path in [fifo.as_path(), Path::new("/dev/zero")] {
            let e = read_results(path).unwrap_err();
            assert!(e.contains("not a regular file"), "{e}");
        }
    }

    #[test]
    fn malformed_files_name_line_and_column() {
        let e = parse_csv("time [s],a.x [m]\n0,1\n0.1,x\n", "r.csv", &[]).unwrap_err();
        assert_eq!(e, "r.csv: line 3, column 'a.x [m]': 'x' is not a number");
        let e = parse_csv("time [s],a.x [m]\n0,1,2\n", "r.csv", &[]).unwrap_err();
        assert_eq!(e, "r.csv: line 2 has 3 values but the header has 2 columns");
        assert!(parse_csv("", "r.csv", &[])
            .unwrap_err()
            .contains("empty file"));
        assert!(parse_csv("\"time,1\n", "r.csv", &[])
            .unwrap_err()
            .contains("unterminated"));
    }

    #[test]
    fn labels_split_into_name_and_unit() {
        assert_eq!(split_label("time [s]"), ("time", Some("s")));
        assert_eq!(
            split_label("bogie.a[2] [m/s2]"),
            ("bogie.a[2]", Some("m/s2"))
        );
        assert_eq!(split_label("ctrl.mode"), ("ctrl.mode", None));
        assert_eq!(split_label("ctrl.v[1]"), ("ctrl.v[1]", None));
    }

    /// A run's output with a column of every type (two rows).
    fn every_type() -> SimOutput {
        use master::coupling::Summary;
        let col = |label: &str, ty, items: Vec<(i32, String)>| ColumnInfo {
            ty: Some(ty),
            name: split_label(label).0.to_string(),
            unit: split_label(label).1.map(str::to_string),
            items,
            ..Default::default()
        };
        let labels = ["a.x [m]", "a.n", "a.b", "a.e", "a.s"];
        let types = [
            ScalarType::Real,
            ScalarType::Integer,
            ScalarType::Boolean,
            ScalarType::Enumeration,
            ScalarType::String,
        ];
        let items = vec![(1, "Option 1".to_string()), (2, "Option, 2".to_string())];
        SimOutput {
            header: std::iter::once("time [s]")
                .chain(labels)
                .map(str::to_string)
                .collect(),
            data: vec![0.0, 1.5, 3.0, 1.0, 2.0, 0.0, 0.5, -2.0, -4.0, 0.0, 1.0, 1.0],
            summary: Summary {
                steps: 1,
                rejected_steps: 0,
                simulated_time_s: 0.5,
                wall_time_s: 0.0,
                realtime_ratio: 0.0,
                terminated: None,
                failed: None,
            },
            columns: labels
                .iter()
                .zip(types)
                .map(|(l, t)| {
                    let items = if t == ScalarType::Enumeration {
                        items.clone()
                    } else {
                        vec![]
                    };
                    col(l, t, items)
                })
                .collect(),
            strings: vec!["Set me!".into(), "say \"hi\",\nthen bye".into()],
            decimation: None,
        }
    }

    fn bits(x: &[f64]) -> Vec<u64> {
        x.iter().map(|v| v.to_bits()).collect()
    }

    #[test]
    fn a_runs_output_has_the_columns_and_texts_of_the_masters_files() {
        let out = every_type();
        let t = expand(&out);
        assert_eq!(
            t.header,
            [
                "time [s]",
                "a.x [m]",
                "a.n",
                "a.b",
                "a.e",
                "a.e (item)",
                "a.s"
            ]
        );
        let nan = f64::NAN;
        assert_eq!(
            bits(&t.data),
            bits(&[0.0, 1.5, 3.0, 1.0, 2.0, nan, nan, 0.5, -2.0, -4.0, 0.0, 1.0, nan, nan])
        );
        assert_eq!(
            t.texts,
            vec![
                (5, vec!["Option, 2".to_string(), "Option 1".to_string()]),
                (
                    6,
                    vec!["Set me!".to_string(), "say \"hi\",\nthen bye".to_string()]
                ),
            ]
        );
        // and back: the output the master's writers take
        let meta = master::results::ResultsMetadata::of(&out, &Default::default());
        let back = collapse(&t, &meta.columns).unwrap();
        assert_eq!(back.header, out.header);
        assert_eq!(back.columns, out.columns);
        assert_eq!(bits(&back.data), bits(&out.data));
        assert_eq!(back.strings, out.strings);
        // columns their metadata does not describe are refused
        let mut other = t.clone();
        other.header[5] = "a.e item".into();
        assert!(collapse(&other, &meta.columns)
            .unwrap_err()
            .contains("not those their metadata describes"));
    }

    #[test]
    fn the_masters_csv_and_parquet_files_read_back_with_their_texts() {
        use master::results::{write_results, RunContext};
        let out = every_type();
        let dir = tempfile::tempdir().unwrap();
        let want = expand(&out);
        for name in ["r.csv", "r.parquet"] {
            let p = dir.path().join(name);
            let format = ResultsFormat::of_path(&p).unwrap();
            write_results(&p, &out, format, &RunContext::default()).unwrap();
            let (t, meta) = read_results(&p).unwrap();
            assert!(meta.is_some(), "{name}");
            assert_eq!(t.header, want.header, "{name}");
            assert_eq!(bits(&t.data), bits(&want.data), "{name}");
            assert_eq!(t.texts, want.texts, "{name}");
        }
        // a CSV without its metadata is numbers only: a text is refused by name
        std::fs::remove_file(dir.path().join("r.meta.json")).unwrap();
        let e = read_results(&dir.path().join("r.csv")).unwrap_err();
        assert!(
            e.contains("column 'a.e (item)': 'Option, 2' is not a number"),
            "{e}"
        );
    }

    #[test]
    fn a_summary_has_every_statistic() {
        let s = summary(r#"{"steps": 3, "wall_time_s": 0.5}"#).unwrap();
        assert_eq!((s.steps, s.rejected_steps, s.wall_time_s), (3, 0, 0.5));
        assert_eq!(summary("{}").unwrap().simulated_time_s, 0.0);
        assert!(summary(r#"{"steps": "many"}"#)
            .unwrap_err()
            .starts_with("summary: "));
        assert!(summary("[]").unwrap_err().contains("not an object"));
    }

    #[test]
    fn a_table_without_metadata_is_reals_and_strings() {
        let t = Table {
            header: vec!["time [s]".into(), "a.x [m]".into(), "a.s".into()],
            data: vec![0.0, 1.0, f64::NAN, 1.0, 2.0, f64::NAN],
            texts: vec![(2, vec!["p".into(), "q".into()])],
        };
        let out = collapse(&t, &[]).unwrap();
        assert_eq!(out.strings, ["p", "q"]);
        assert_eq!(out.data, [0.0, 1.0, 0.0, 1.0, 2.0, 1.0]);
        assert_eq!(out.columns[0].unit.as_deref(), Some("m"));
        assert_eq!(out.columns[1].ty, Some(ScalarType::String));
        let short = Table {
            texts: vec![(2, vec!["p".into()])],
            ..t
        };
        assert!(collapse(&short, &[])
            .unwrap_err()
            .contains("1 texts for 2 rows"));
    }
}
