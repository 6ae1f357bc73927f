//! The numeric CSV files the Python side of the tests writes (fmpy, the SSP hosts): a header
//! line, then rows of numbers.

use std::path::Path;

/// Header and rows of the CSV file at `path`; an unreadable file or a cell that is not a number
/// is an error naming the file.
pub fn read_csv(path: &Path) -> Result<(Vec<String>, Vec<Vec<f64>>), String> {
    let err = |e: String| format!("{}: {e}", path.display());
    let text = std::fs::read_to_string(path).map_err(|e| err(e.to_string()))?;
    let mut lines = text.lines();
    let header = lines
        .next()
        .ok_or_else(|| err("empty file".into()))?
        .split(',')
        .map(str::to_string)
        .collect();
    let rows = lines
        .enumerate()
        .map(|(k, l)| {
            l.split(',')
                .map(|x| {
                    x.parse::<f64>()
                        .map_err(|_| err(format!("line {}: '{x}' is not a number", k + 2)))
                })
                .collect()
        })
        .collect::<Result<_, _>>()?;
    Ok((header, rows))
}
