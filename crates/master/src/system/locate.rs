//! Where a field of a JSON document starts, for the line of an error message: the path the
//! error names (`instances[3].name`, `connections[6].to`, `instances[0].parameters.vehicle.speed`,
//! whose last key holds dots) is followed through the text, so that the line is that field's,
//! not the first line holding the same text.

/// Byte offset of the value at `path` in `text`, `None` when the text does not hold it (or is
/// not JSON there). Keys are compared as written (a key with escapes is not found).
pub fn value_offset(text: &str, path: &str) -> Option<usize> {
    let b = text.as_bytes();
    find(b, skip_ws(b, 0), path, 0)
}

/// At most this deep: a document nested deeper is not followed (no stack overflow).
const MAX_DEPTH: usize = 64;

fn skip_ws(b: &[u8], mut i: usize) -> usize {
    while i < b.len() && b[i].is_ascii_whitespace() {
        i += 1;
    }
    i
}

/// End of the string starting at `i` (just past its closing quote).
fn string_end(b: &[u8], i: usize) -> Option<usize> {
    let mut j = i + 1;
    while j < b.len() {
        match b[j] {
            b'\\' => j += 2,
            b'"' => return Some(j + 1),
            _ => j += 1,
        }
    }
    None
}

/// End of the value starting at `i`.
fn skip_value(b: &[u8], i: usize, depth: usize) -> Option<usize> {
    if depth > MAX_DEPTH {
        return None;
    }
    match *b.get(i)? {
        b'"' => string_end(b, i),
        open @ (b'{' | b'[') => {
            let close = if open == b'{' { b'}' } else { b']' };
            let mut j = skip_ws(b, i + 1);
            if b.get(j) == Some(&close) {
                return Some(j + 1);
            }
            loop {
                if open == b'{' {
                    j = skip_ws(b, string_end(b, j)?);
                    if b.get(j) != Some(&b':') {
                        return None;
                    }
                    j = skip_ws(b, j + 1);
                }
                j = skip_ws(b, skip_value(b, j, depth + 1)?);
                match b.get(j)? {
                    b',' => j = skip_ws(b, j + 1),
                    c if *c == close => return Some(j + 1),
                    _ => return None,
                }
            }
        }
        _ => {
            let mut j = i;
            while j < b.len() && !matches!(b[j], b',' | b'}' | b']') && !b[j].is_ascii_whitespace()
            {
                j += 1;
            }
            (j > i).then_some(j)
        }
    }
}

/// The value at `rest` below the value starting at `i`.
fn find(b: &[u8], i: usize, rest: &str, depth: usize) -> Option<usize> {
    if rest.is_empty() {
        return Some(i);
    }
    if depth > MAX_DEPTH {
        return None;
    }
    match *b.get(i)? {
        b'{' => {
            let mut j = skip_ws(b, i + 1);
            while b.get(j) == Some(&b'"') {
                let key_end = string_end(b, j)?;
                let key = std::str::from_utf8(&b[j + 1..key_end - 1]).ok()?;
                let colon = skip_ws(b, key_end);
                if b.get(colon) != Some(&b':') {
                    return None;
                }
                let value = skip_ws(b, colon + 1);
                if let Some(after) = rest.strip_prefix(key) {
                    let below = after.strip_prefix('.').unwrap_or(after);
                    if after.is_empty() || after.starts_with('.') || after.starts_with('[') {
                        if let Some(at) = find(b, value, below, depth + 1) {
                            return Some(at);
                        }
                    }
                }
                j = skip_ws(b, skip_value(b, value, depth + 1)?);
                if b.get(j) == Some(&b',') {
                    j = skip_ws(b, j + 1);
                }
            }
            None
        }
        b'[' => {
            let (index, after) = rest.strip_prefix('[')?.split_once(']')?;
            let index: usize = index.parse().ok()?;
            let below = after.strip_prefix('.').unwrap_or(after);
            let mut j = skip_ws(b, i + 1);
            for _ in 0..index {
                j = skip_ws(b, skip_value(b, j, depth + 1)?);
                if b.get(j) != Some(&b',') {
                    return None;
                }
                j = skip_ws(b, j + 1);
            }
            find(b, j, below, depth + 1)
        }
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_field_is_found_by_its_path_not_by_its_text() {
        let text = r#"{
  "instances": [
    {"name": "a", "fmu": "x.fmu", "parameters": {"vehicle.speed": 1, "k": [1, {"z": 2}]}},
    {"name": "b", "fmu": "x.fmu"},
    {"name": "a", "fmu": "x.fmu"}
  ],
  "order": ["a", "b", "a"]
}"#;
        let line =
            |path: &str| value_offset(text, path).map(|at| text[..at].matches('\n').count() + 1);
        assert_eq!(line("instances[2].name"), Some(5));
        assert_eq!(line("instances[0].name"), Some(3));
        assert_eq!(line("order[2]"), Some(7));
        assert_eq!(line("instances[0].parameters.vehicle.speed"), Some(3));
        assert_eq!(
            &text[value_offset(text, "instances[0].parameters.k[1].z").unwrap()..][..1],
            "2"
        );
        for missing in [
            "instances[3].name",
            "instances[0].parameters.vehicle",
            "nothing",
            "order[x]",
        ] {
            assert_eq!(line(missing), None, "{missing}");
        }
        // not JSON, or nested beyond reason: no line, no panic
        assert_eq!(value_offset("{\"a\": [1, 2", "a[1]"), Some(10));
        assert_eq!(value_offset("{\"a\": ", "a[0]"), None);
        let deep = format!("{}{}", "[".repeat(10_000), "]".repeat(10_000));
        assert_eq!(value_offset(&deep, &"[0]".repeat(10_000)), None);
    }
}
