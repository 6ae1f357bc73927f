//! Reading a results CSV written by the master (`output::write_csv_atomic`): a header of
//! RFC 4180 fields, then rows of numbers in Rust's shortest round-trip form. Parsed with Rust's
//! `f64::from_str`, which is correctly rounded, so every value read back is the bit pattern
//! that was written.

use std::path::Path;

/// A results table: `header[0]` is `time [s]`; `data` is row-major, `header.len()` per row.
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    pub header: Vec<String>,
    pub data: Vec<f64>,
}

/// Splits one CSV line into fields (RFC 4180 quoting: `"a,b"`, `""` inside quotes).
pub fn split_csv_line(line: &str) -> Result<Vec<String>, String> {
    let mut fields = Vec::new();
    let mut field = String::new();
    let mut chars = line.chars().peekable();
    let mut quoted = false;
    let mut at_start = true;
    while let Some(c) = chars.next() {
        match (quoted, c) {
            (false, '"') if at_start => {
                quoted = true;
                at_start = false;
            }
            (false, '"') => return Err("a quote inside an unquoted field".into()),
            (true, '"') => {
                if chars.peek() == Some(&'"') {
                    chars.next();
                    field.push('"');
                } else {
                    quoted = false;
                    if !matches!(chars.peek(), None | Some(',')) {
                        return Err("text after a closing quote".into());
                    }
                }
            }
            (false, ',') => {
                fields.push(std::mem::take(&mut field));
                at_start = true;
            }
            (_, c) => {
                field.push(c);
                at_start = false;
            }
        }
    }
    if quoted {
        return Err("unterminated quoted field".into());
    }
    fields.push(field);
    Ok(fields)
}

/// Splits a column label `name [unit]` into its name and unit (`None` when it has none).
pub fn split_label(label: &str) -> (&str, Option<&str>) {
    match label.strip_suffix(']').and_then(|l| l.rsplit_once(" [")) {
        Some((name, unit)) if !name.is_empty() => (name, Some(unit)),
        _ => (label, None),
    }
}

/// Parses the text of a results CSV; `file` names it in messages.
pub fn parse_csv(text: &str, file: &str) -> Result<Table, String> {
    let mut lines = text.lines();
    let head = lines
        .next()
        .ok_or_else(|| format!("{file}: empty file (no header line)"))?;
    let header = split_csv_line(head).map_err(|e| format!("{file}: line 1: {e}"))?;
    let mut data = Vec::new();
    for (i, line) in lines.enumerate() {
        let n = i + 2;
        if line.is_empty() {
            continue;
        }
        let before = data.len();
        for (k, field) in line.split(',').enumerate() {
            let x: f64 = field.trim().parse().map_err(|_| {
                let col = header.get(k).map_or("?", String::as_str);
                format!("{file}: line {n}, column '{col}': '{field}' is not a number")
            })?;
            data.push(x);
        }
        let got = data.len() - before;
        if got != header.len() {
            return Err(format!(
                "{file}: line {n} has {got} values but the header has {} columns",
                header.len()
            ));
        }
    }
    Ok(Table { header, data })
}

/// Reads a results CSV file.
pub fn read_csv(path: &Path) -> Result<Table, String> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| format!("cannot read '{}': {e}", path.display()))?;
    parse_csv(&text, &path.display().to_string())
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
        let t = read_csv(&p).unwrap();
        assert_eq!(t.header, header);
        let want: Vec<u64> = rows.iter().flatten().map(|x| x.to_bits()).collect();
        let got: Vec<u64> = t.data.iter().map(|x| x.to_bits()).collect();
        // NaN has one canonical bit pattern in Rust's formatting and parsing
        assert_eq!(got, want);
    }

    #[test]
    fn malformed_files_name_line_and_column() {
        let e = parse_csv("time [s],a.x [m]\n0,1\n0.1,x\n", "r.csv").unwrap_err();
        assert_eq!(e, "r.csv: line 3, column 'a.x [m]': 'x' is not a number");
        let e = parse_csv("time [s],a.x [m]\n0,1,2\n", "r.csv").unwrap_err();
        assert_eq!(e, "r.csv: line 2 has 3 values but the header has 2 columns");
        assert!(parse_csv("", "r.csv").unwrap_err().contains("empty file"));
        assert!(parse_csv("\"time,1\n", "r.csv")
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
}
