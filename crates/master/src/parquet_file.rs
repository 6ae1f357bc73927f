//! Results as Apache Parquet, through the `parquet` crate's column API (no Arrow).
//!
//! One row group, one column per CSV column and of the same name: Reals as DOUBLE (byte-stream
//! split, then zstd: the exponent and high mantissa bytes of smooth signals compress well),
//! Integers and Enumerations as INT32 (an Enumeration followed by its item names), Booleans
//! as BOOLEAN, Strings as UTF-8 text. Then the constant columns of a run of a run set: `run`
//! (its name), its parameters and labels (float64, int32 for the Integers and Enumerations of
//! their FMUs, boolean or text; null where a run does not set one), so that the files of a
//! run set read as one table. The metadata
//! ([`ResultsMetadata`]) is JSON under the file's key [`PARQUET_METADATA_KEY`]
//! (`pyarrow.parquet.read_schema(path).metadata`).
//!
//! The file is built in memory and written atomically ([`crate::output::write_unfinished`]).

use std::io::Read;
use std::path::Path;
use std::sync::Arc;

use parquet::basic::{Compression, Encoding, LogicalType, Repetition, Type as Physical, ZstdLevel};
use parquet::column::reader::ColumnReader;
use parquet::data_type::{BoolType, ByteArray, ByteArrayType, DoubleType, Int32Type};
use parquet::file::metadata::KeyValue;
use parquet::file::properties::{EnabledStatistics, WriterProperties};
use parquet::file::reader::{FileReader, SerializedFileReader};
use parquet::file::writer::SerializedFileWriter;
use parquet::schema::types::{ColumnPath, Type};
use serde_json::Value;

use crate::coupling::SimOutput;
use crate::output::{bytes_unfinished, OutputError, Unfinished};
use crate::results::{ReadError, ResultsMetadata, PARQUET_METADATA_KEY};
use crate::slave::ScalarType;

/// zstd level: 3 is zstd's default; higher levels gain little on float64 signals.
const ZSTD_LEVEL: i32 = 3;

/// Largest results file read [bytes].
pub const MAX_PARQUET_BYTES: u64 = 8 << 30;

/// The kind of a constant column.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ConstantKind {
    Float,
    /// A parameter that is an Integer or Enumeration in its FMU, given as a number in every
    /// run (INT32, as the FMU's own Integer columns).
    Integer,
    Boolean,
    Text,
}

impl ConstantKind {
    /// The kind a JSON value is written as (numbers as float64, so that 300 and 300.5 share
    /// one column).
    pub fn of(v: &Value) -> Option<Self> {
        match v {
            Value::Null => None,
            Value::Number(_) => Some(ConstantKind::Float),
            Value::Bool(_) => Some(ConstantKind::Boolean),
            _ => Some(ConstantKind::Text),
        }
    }

    /// The kind of a column holding values of both kinds.
    pub fn merge(self, other: Self) -> Self {
        match (self, other) {
            (a, b) if a == b => a,
            (ConstantKind::Integer, ConstantKind::Float)
            | (ConstantKind::Float, ConstantKind::Integer) => ConstantKind::Float,
            _ => ConstantKind::Text,
        }
    }
}

/// A constant column: its name, kind and value in this file (`None`: null).
#[derive(Debug, Clone, PartialEq)]
pub struct Constant {
    pub name: String,
    pub kind: ConstantKind,
    pub value: Option<Value>,
}

enum Values {
    Double(Vec<f64>),
    Int(Vec<i32>),
    Bool(Vec<bool>),
    Text(Vec<ByteArray>),
    OptDouble(Vec<f64>, Vec<i16>),
    OptInt(Vec<i32>, Vec<i16>),
    OptBool(Vec<bool>, Vec<i16>),
    OptText(Vec<ByteArray>, Vec<i16>),
}

fn parquet_err(path: &Path) -> impl Fn(parquet::errors::ParquetError) -> OutputError + '_ {
    move |e| OutputError::Io {
        path: path.to_path_buf(),
        source: std::io::Error::other(e.to_string()),
    }
}

/// A JSON number that is a 32-bit integer (`2` or `2.0`), as an FMI Integer holds it.
pub fn integer_value(v: &Value) -> Option<i32> {
    let x = v.as_f64()?;
    (x.fract() == 0.0 && x >= f64::from(i32::MIN) && x <= f64::from(i32::MAX)).then_some(x as i32)
}

fn text(s: &str) -> ByteArray {
    ByteArray::from(s.as_bytes().to_vec())
}

/// Writes `out` with `meta` and the constant columns to `path` atomically.
pub fn write_results_parquet(
    path: &Path,
    out: &SimOutput,
    meta: &ResultsMetadata,
    constants: &[Constant],
) -> Result<(), OutputError> {
    results_parquet_unfinished(path, out, meta, constants)?.commit()
}

/// [`write_results_parquet`], not yet committed.
pub fn results_parquet_unfinished(
    path: &Path,
    out: &SimOutput,
    meta: &ResultsMetadata,
    constants: &[Constant],
) -> Result<Unfinished, OutputError> {
    let perr = parquet_err(path);
    let w = out.header.len().max(1);
    let n = out.data.len() / w;
    let column = |c: usize| (0..n).map(move |k| out.data[k * w + c]);
    let mut fields: Vec<Arc<Type>> = Vec::new();
    let mut values: Vec<Values> = Vec::new();
    let mut props = WriterProperties::builder()
        .set_compression(Compression::ZSTD(
            ZstdLevel::try_new(ZSTD_LEVEL).map_err(&perr)?,
        ))
        .set_statistics_enabled(EnabledStatistics::Chunk)
        .set_key_value_metadata(Some(vec![KeyValue::new(
            PARQUET_METADATA_KEY.to_string(),
            serde_json::to_string(meta).map_err(|source| OutputError::Json {
                path: path.to_path_buf(),
                source,
            })?,
        )]));
    let mut add = |name: &str, physical: Physical, logical: Option<LogicalType>, rep| {
        Type::primitive_type_builder(name, physical)
            .with_repetition(rep)
            .with_logical_type(logical)
            .build()
            .map(|t| fields.push(Arc::new(t)))
    };
    let mut names: Vec<String> = Vec::new();
    for (c, label) in out.header.iter().enumerate() {
        let info = out.column_info(c);
        names.push(label.clone());
        match info.scalar_type() {
            ScalarType::Real => {
                add(label, Physical::DOUBLE, None, Repetition::REQUIRED).map_err(&perr)?;
                props = props
                    .set_column_dictionary_enabled(ColumnPath::new(vec![label.clone()]), false)
                    .set_column_encoding(
                        ColumnPath::new(vec![label.clone()]),
                        Encoding::BYTE_STREAM_SPLIT,
                    );
                values.push(Values::Double(column(c).collect()));
            }
            ScalarType::Integer | ScalarType::Enumeration => {
                add(label, Physical::INT32, None, Repetition::REQUIRED).map_err(&perr)?;
                values.push(Values::Int(column(c).map(|v| v as i32).collect()));
                if info.scalar_type() == ScalarType::Enumeration {
                    let item = format!("{label} (item)");
                    add(
                        &item,
                        Physical::BYTE_ARRAY,
                        Some(LogicalType::String),
                        Repetition::REQUIRED,
                    )
                    .map_err(&perr)?;
                    names.push(item);
                    values.push(Values::Text(
                        column(c)
                            .map(|v| text(info.item(v).unwrap_or("")))
                            .collect(),
                    ));
                }
            }
            ScalarType::Boolean => {
                add(label, Physical::BOOLEAN, None, Repetition::REQUIRED).map_err(&perr)?;
                values.push(Values::Bool(column(c).map(|v| v != 0.0).collect()));
            }
            ScalarType::String => {
                add(
                    label,
                    Physical::BYTE_ARRAY,
                    Some(LogicalType::String),
                    Repetition::REQUIRED,
                )
                .map_err(&perr)?;
                values.push(Values::Text(
                    column(c).map(|v| text(out.text(v).unwrap_or(""))).collect(),
                ));
            }
        }
    }
    for k in constants {
        // a parameter named like a recorded column keeps both
        let mut name = k.name.clone();
        while names.contains(&name) {
            name.push_str(" (parameter)");
        }
        names.push(name.clone());
        let def = vec![i16::from(k.value.is_some()); n];
        let some = if k.value.is_some() { n } else { 0 };
        match k.kind {
            ConstantKind::Float => {
                add(&name, Physical::DOUBLE, None, Repetition::OPTIONAL).map_err(&perr)?;
                let v = k.value.as_ref().and_then(Value::as_f64).unwrap_or(f64::NAN);
                values.push(Values::OptDouble(vec![v; some], def));
            }
            ConstantKind::Integer => {
                add(&name, Physical::INT32, None, Repetition::OPTIONAL).map_err(&perr)?;
                // the kind is Integer only where every run's value is one (see
                // `integer_value`); anything else is null rather than a rounded number
                let v = k.value.as_ref().and_then(integer_value);
                let some = if v.is_some() { some } else { 0 };
                let def = vec![i16::from(v.is_some()); n];
                values.push(Values::OptInt(vec![v.unwrap_or(0); some], def));
            }
            ConstantKind::Boolean => {
                add(&name, Physical::BOOLEAN, None, Repetition::OPTIONAL).map_err(&perr)?;
                let v = k.value.as_ref().and_then(Value::as_bool).unwrap_or(false);
                values.push(Values::OptBool(vec![v; some], def));
            }
            ConstantKind::Text => {
                add(
                    &name,
                    Physical::BYTE_ARRAY,
                    Some(LogicalType::String),
                    Repetition::OPTIONAL,
                )
                .map_err(&perr)?;
                let v = match &k.value {
                    Some(Value::String(s)) => s.clone(),
                    Some(other) => other.to_string(),
                    None => String::new(),
                };
                values.push(Values::OptText(vec![text(&v); some], def));
            }
        }
    }
    let schema = Type::group_type_builder("results")
        .with_fields(fields)
        .build()
        .map_err(&perr)?;
    let mut buf: Vec<u8> = Vec::new();
    let mut writer = SerializedFileWriter::new(&mut buf, Arc::new(schema), Arc::new(props.build()))
        .map_err(&perr)?;
    let mut group = writer.next_row_group().map_err(&perr)?;
    let mut values = values.into_iter();
    while let Some(mut col) = group.next_column().map_err(&perr)? {
        let Some(v) = values.next() else {
            return Err(perr(parquet::errors::ParquetError::General(
                "more columns in the schema than values".into(),
            )));
        };
        match v {
            Values::Double(x) => col.typed::<DoubleType>().write_batch(&x, None, None),
            Values::Int(x) => col.typed::<Int32Type>().write_batch(&x, None, None),
            Values::Bool(x) => col.typed::<BoolType>().write_batch(&x, None, None),
            Values::Text(x) => col.typed::<ByteArrayType>().write_batch(&x, None, None),
            Values::OptDouble(x, d) => col.typed::<DoubleType>().write_batch(&x, Some(&d), None),
            Values::OptInt(x, d) => col.typed::<Int32Type>().write_batch(&x, Some(&d), None),
            Values::OptBool(x, d) => col.typed::<BoolType>().write_batch(&x, Some(&d), None),
            Values::OptText(x, d) => col.typed::<ByteArrayType>().write_batch(&x, Some(&d), None),
        }
        .map_err(&perr)?;
        col.close().map_err(&perr)?;
    }
    group.close().map_err(&perr)?;
    writer.close().map_err(&perr)?;
    bytes_unfinished(path, &buf)
}

/// A column read back: numbers (Integers, Booleans as 0/1) or texts; `None` is a null.
#[derive(Debug, Clone, PartialEq)]
pub enum ColumnData {
    Numbers(Vec<Option<f64>>),
    Texts(Vec<Option<String>>),
}

/// Every column of a Parquet file of flat columns (ours or another tool's), by name, and
/// the file's metadata (`None` when it is not ours).
pub type ParquetTable = (Vec<(String, ColumnData)>, Option<ResultsMetadata>);

/// Records read per call: memory grows with what the file holds, not with the row count
/// its metadata claims (a hostile file may claim any).
const READ_BATCH: usize = 1 << 16;

fn read_column<T: parquet::data_type::DataType>(
    mut r: parquet::column::reader::ColumnReaderImpl<T>,
    rows: usize,
    max_def: i16,
) -> parquet::errors::Result<Vec<Option<T::T>>>
where
    T::T: Clone,
{
    let mut values: Vec<T::T> = Vec::with_capacity(rows.min(READ_BATCH));
    let mut defs: Vec<i16> = Vec::with_capacity(rows.min(READ_BATCH));
    loop {
        let (records, _, _) = r.read_records(
            READ_BATCH,
            (max_def > 0).then_some(&mut defs),
            None,
            &mut values,
        )?;
        if records == 0 {
            break;
        }
    }
    if max_def == 0 {
        return Ok(values.into_iter().map(Some).collect());
    }
    let mut it = values.into_iter();
    Ok(defs
        .iter()
        .map(|&d| if d == max_def { it.next() } else { None })
        .collect())
}

/// The master's metadata in the footer of the Parquet file `path`, if it is a regular file
/// (not a link) written by the master. Only the footer is read.
pub fn footer_metadata(path: &Path) -> Option<ResultsMetadata> {
    if !path.symlink_metadata().is_ok_and(|m| m.is_file()) {
        return None;
    }
    let file = crate::input::open_regular_file(path).ok()?;
    let reader = SerializedFileReader::new(file).ok()?;
    reader
        .metadata()
        .file_metadata()
        .key_value_metadata()
        .and_then(|kv| kv.iter().find(|k| k.key == PARQUET_METADATA_KEY))
        .and_then(|k| k.value.as_deref())
        .and_then(|json| serde_json::from_str::<ResultsMetadata>(json).ok())
}

/// Whether `path` is a run's table of a run set written by the master: [`footer_metadata`]
/// naming a run.
pub fn is_run_table(path: &Path) -> bool {
    footer_metadata(path).is_some_and(|m| m.run.is_some())
}

/// Reads every column of a Parquet file.
pub fn read_parquet(path: &Path) -> Result<ParquetTable, ReadError> {
    let invalid = |reason: String| ReadError::Invalid {
        path: path.to_path_buf(),
        reason,
    };
    let io = |source| ReadError::Io {
        path: path.to_path_buf(),
        source,
    };
    let file = crate::input::open_regular_file(path).map_err(io)?;
    let mut bytes = Vec::new();
    file.take(MAX_PARQUET_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(io)?;
    if bytes.len() as u64 > MAX_PARQUET_BYTES {
        return Err(invalid(format!(
            "larger than the {MAX_PARQUET_BYTES} bytes read"
        )));
    }
    let pe = |e: parquet::errors::ParquetError| invalid(e.to_string());
    let reader = SerializedFileReader::new(bytes::Bytes::from(bytes)).map_err(pe)?;
    let file_meta = reader.metadata().file_metadata();
    let meta = match file_meta
        .key_value_metadata()
        .and_then(|kv| kv.iter().find(|k| k.key == PARQUET_METADATA_KEY))
        .and_then(|k| k.value.as_deref())
    {
        Some(json) => Some(
            serde_json::from_str::<ResultsMetadata>(json)
                .map_err(|e| invalid(format!("metadata '{PARQUET_METADATA_KEY}': {e}")))?,
        ),
        None => None,
    };
    let schema = file_meta.schema_descr();
    let mut columns: Vec<(String, ColumnData)> = schema
        .columns()
        .iter()
        .map(|c| {
            let texts = c.physical_type() == Physical::BYTE_ARRAY;
            let name = c.path().parts().join(".");
            let data = if texts {
                ColumnData::Texts(Vec::new())
            } else {
                ColumnData::Numbers(Vec::new())
            };
            (name, data)
        })
        .collect();
    for g in 0..reader.num_row_groups() {
        let group = reader.get_row_group(g).map_err(pe)?;
        let rows = usize::try_from(group.metadata().num_rows()).unwrap_or(0);
        for (i, (name, data)) in columns.iter_mut().enumerate() {
            let max_def = schema.column(i).max_def_level();
            let nums = |v: Vec<Option<f64>>, data: &mut ColumnData| {
                if let ColumnData::Numbers(x) = data {
                    x.extend(v);
                }
            };
            match group.get_column_reader(i).map_err(pe)? {
                ColumnReader::DoubleColumnReader(r) => {
                    nums(read_column(r, rows, max_def).map_err(pe)?, data);
                }
                ColumnReader::FloatColumnReader(r) => {
                    let v = read_column(r, rows, max_def).map_err(pe)?;
                    nums(v.into_iter().map(|x| x.map(f64::from)).collect(), data);
                }
                ColumnReader::Int32ColumnReader(r) => {
                    let v = read_column(r, rows, max_def).map_err(pe)?;
                    nums(v.into_iter().map(|x| x.map(f64::from)).collect(), data);
                }
                ColumnReader::Int64ColumnReader(r) => {
                    let v = read_column(r, rows, max_def).map_err(pe)?;
                    nums(v.into_iter().map(|x| x.map(|x| x as f64)).collect(), data);
                }
                ColumnReader::BoolColumnReader(r) => {
                    let v = read_column(r, rows, max_def).map_err(pe)?;
                    let v = v.into_iter().map(|x| x.map(|b| f64::from(u8::from(b))));
                    nums(v.collect(), data);
                }
                ColumnReader::ByteArrayColumnReader(r) => {
                    let v = read_column(r, rows, max_def).map_err(pe)?;
                    if let ColumnData::Texts(x) = data {
                        for b in v {
                            x.push(match b {
                                Some(b) => Some(
                                    b.as_utf8()
                                        .map_err(|e| invalid(format!("column '{name}': {e}")))?
                                        .to_string(),
                                ),
                                None => None,
                            });
                        }
                    }
                }
                _ => {
                    return Err(invalid(format!(
                        "column '{name}' has a type results files do not use"
                    )))
                }
            }
        }
    }
    Ok((columns, meta))
}

/// Reads a results file we wrote back into the recorded output (time and the recorded
/// columns; the constant columns are in the metadata) and its metadata.
pub fn read_results_parquet(path: &Path) -> Result<(SimOutput, ResultsMetadata), ReadError> {
    let invalid = |reason: String| ReadError::Invalid {
        path: path.to_path_buf(),
        reason,
    };
    let (columns, meta) = read_parquet(path)?;
    let meta = meta.ok_or_else(|| {
        invalid(format!(
            "no '{PARQUET_METADATA_KEY}' metadata (not written by the master)"
        ))
    })?;
    let find = |label: &str| {
        columns
            .iter()
            .find(|(n, _)| n == label)
            .map(|(_, d)| d)
            .ok_or_else(|| invalid(format!("no column '{label}'")))
    };
    let Some((time_label, _)) = columns.first() else {
        return Err(invalid("no columns".into()));
    };
    let mut header = vec![time_label.clone()];
    header.extend(meta.columns.iter().map(|c| c.label.clone()));
    let mut strings: Vec<String> = Vec::new();
    let mut cols: Vec<Vec<f64>> = Vec::with_capacity(header.len());
    for label in &header {
        let col = match find(label)? {
            ColumnData::Numbers(x) => x
                .iter()
                .map(|v| v.ok_or_else(|| invalid(format!("a null in column '{label}'"))))
                .collect::<Result<Vec<f64>, _>>()?,
            ColumnData::Texts(x) => x
                .iter()
                .map(|v| {
                    let t = v.clone().unwrap_or_default();
                    let i = strings.iter().position(|s| *s == t).unwrap_or_else(|| {
                        strings.push(t);
                        strings.len() - 1
                    });
                    i as f64
                })
                .collect(),
        };
        cols.push(col);
    }
    let n = cols.first().map_or(0, Vec::len);
    if cols.iter().any(|c| c.len() != n) {
        return Err(invalid("columns of different lengths".into()));
    }
    let mut data = Vec::with_capacity(n * header.len());
    for k in 0..n {
        data.extend(cols.iter().map(|c| c[k]));
    }
    let out = SimOutput {
        header,
        data,
        summary: meta.summary.clone(),
        columns: meta.columns.iter().map(|c| c.info.clone()).collect(),
        strings,
        decimation: meta.sampling.as_ref().and_then(|s| s.decimation.clone()),
    };
    Ok((out, meta))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::coupling::{ColumnInfo, Summary};
    use crate::output::write_results_csv;
    use crate::results::{write_results, ResultsFormat, RunContext};
    use std::collections::BTreeMap;

    /// Results with a column of every type.
    fn every_type() -> SimOutput {
        let col = |ty, unit: Option<&str>, items: Vec<(i32, String)>| ColumnInfo {
            ty: Some(ty),
            unit: unit.map(str::to_string),
            name: "a.v".into(),
            causality: "output".into(),
            instance: "a".into(),
            fmu_guid: "{guid}".into(),
            items,
            ..Default::default()
        };
        SimOutput {
            header: vec![
                "time [s]".into(),
                "a.x [m]".into(),
                "a.n".into(),
                "a.b".into(),
                "a.e".into(),
                "a.s".into(),
            ],
            data: vec![
                0.0, 1.5, 3.0, 1.0, 2.0, 0.0, 0.5, -2.2e-7, -4.0, 0.0, 1.0, 1.0, 1.0, 0.1, 7.0,
                1.0, 2.0, 0.0,
            ],
            summary: Summary {
                steps: 2,
                rejected_steps: 0,
                simulated_time_s: 1.0,
                wall_time_s: 0.25,
                realtime_ratio: 4.0,
                terminated: None,
                failed: None,
            },
            columns: vec![
                col(ScalarType::Real, Some("m"), vec![]),
                col(ScalarType::Integer, None, vec![]),
                col(ScalarType::Boolean, None, vec![]),
                col(
                    ScalarType::Enumeration,
                    None,
                    vec![(1, "Option 1".into()), (2, "Option, 2".into())],
                ),
                col(ScalarType::String, None, vec![]),
            ],
            strings: vec!["Set me!".into(), "say \"hi\"".into()],
            decimation: None,
        }
    }

    #[test]
    fn parquet_carries_the_values_of_the_csv_and_the_metadata() {
        let out = every_type();
        let dir = tempfile::tempdir().unwrap();
        let ctx = RunContext {
            run: Some("run-007".into()),
            parameters: BTreeMap::from([
                ("a.k".to_string(), serde_json::json!(300)),
                ("a.count".to_string(), serde_json::json!(4)),
            ]),
            labels: BTreeMap::from([("configuration".to_string(), serde_json::json!("passive"))]),
            system: Some(serde_json::json!({"instances": []})),
            kinds: BTreeMap::from([
                ("a.k".to_string(), ConstantKind::Float),
                ("a.count".to_string(), ConstantKind::Integer),
                ("a.seed".to_string(), ConstantKind::Integer),
            ]),
            sampling_unknown: false,
        };
        let pq = dir.path().join("r.parquet");
        write_results(&pq, &out, ResultsFormat::Parquet, &ctx).unwrap();
        let (back, meta) = read_results_parquet(&pq).unwrap();
        // the same CSV from both
        let (a, b) = (dir.path().join("a.csv"), dir.path().join("b.csv"));
        write_results_csv(&a, &out).unwrap();
        write_results_csv(&b, &back).unwrap();
        assert_eq!(
            std::fs::read_to_string(&a).unwrap(),
            std::fs::read_to_string(&b).unwrap()
        );
        assert_eq!(back.data, out.data);
        assert_eq!(meta.columns[0].info.unit.as_deref(), Some("m"));
        assert_eq!(meta.summary, out.summary);
        assert_eq!(meta.run.as_deref(), Some("run-007"));
        assert!(meta.system.is_some());
        // the constant columns: run, configuration, every parameter of the set (null if unset)
        let (columns, _) = read_parquet(&pq).unwrap();
        let get = |n: &str| columns.iter().find(|(c, _)| c == n).map(|(_, d)| d.clone());
        assert_eq!(
            get("run"),
            Some(ColumnData::Texts(vec![Some("run-007".into()); 3]))
        );
        assert_eq!(
            get("configuration"),
            Some(ColumnData::Texts(vec![Some("passive".into()); 3]))
        );
        assert_eq!(get("a.k"), Some(ColumnData::Numbers(vec![Some(300.0); 3])));
        assert_eq!(
            get("a.count"),
            Some(ColumnData::Numbers(vec![Some(4.0); 3]))
        );
        assert_eq!(get("a.seed"), Some(ColumnData::Numbers(vec![None; 3])));
        // a Real parameter is a DOUBLE column, an Integer one INT32 (as pandas reads them)
        let file = SerializedFileReader::new(std::fs::File::open(&pq).unwrap()).unwrap();
        let schema = file.metadata().file_metadata().schema_descr_ptr();
        let physical = |n: &str| {
            let c = schema.columns().iter().find(|c| c.name() == n).unwrap();
            c.physical_type()
        };
        assert_eq!(physical("a.k"), Physical::DOUBLE);
        assert_eq!(physical("a.count"), Physical::INT32);
        assert_eq!(physical("a.seed"), Physical::INT32);
        assert_eq!(
            get("a.e (item)"),
            Some(ColumnData::Texts(vec![
                Some("Option, 2".into()),
                Some("Option 1".into()),
                Some("Option, 2".into())
            ]))
        );
        // only the file is left in the folder (written atomically)
        let names: Vec<String> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n.starts_with('.'))
            .collect();
        assert!(names.is_empty(), "{names:?}");
    }

    #[test]
    fn integer_parameters_are_integer_columns_when_every_run_gives_a_whole_number() {
        use crate::results::{constant_kinds, with_integer_kinds};
        let runs = [
            serde_json::json!({"a.seed": 1, "a.k": 300, "a.order": 2, "a.mode": "fast"}),
            serde_json::json!({"a.seed": 2.0, "a.k": 310, "a.order": 2.5, "a.mode": 3}),
        ];
        let runs: Vec<BTreeMap<String, Value>> = runs
            .iter()
            .map(|r| serde_json::from_value(r.clone()).unwrap())
            .collect();
        let values = || runs.iter().flatten();
        let integers = ["a.seed", "a.order", "a.mode"].map(String::from).into();
        let kinds = with_integer_kinds(constant_kinds(values()), &integers, values());
        // a.k is a Real of its FMU whatever its values; a.order is not whole in every run;
        // a.mode is given by item name in one run
        assert_eq!(kinds["a.seed"], ConstantKind::Integer);
        assert_eq!(kinds["a.k"], ConstantKind::Float);
        assert_eq!(kinds["a.order"], ConstantKind::Float);
        assert_eq!(kinds["a.mode"], ConstantKind::Text);
        assert_eq!(integer_value(&serde_json::json!(2.0)), Some(2));
        assert_eq!(integer_value(&serde_json::json!(3e9)), None);
        assert_eq!(integer_value(&serde_json::json!("2")), None);
    }

    #[test]
    fn a_file_that_is_not_parquet_is_a_clear_error() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("x.parquet");
        std::fs::write(&p, "time,x\n0,1\n").unwrap();
        let e = read_parquet(&p).unwrap_err().to_string();
        assert!(
            e.contains("x.parquet") && e.contains("not a results file"),
            "{e}"
        );
        let e = read_parquet(&dir.path().join("none.parquet")).unwrap_err();
        assert!(matches!(e, ReadError::Io { .. }));
    }
}
