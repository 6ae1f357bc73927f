//! The records of a comma-separated results file as the master writes it (RFC 4180): a field in
//! double quotes may hold commas, doubled quotes and line breaks (a String value can), so a
//! record is not always a line. One reader for every reader of such files (the Python
//! package's results, `master assess`).

/// One field of a record.
#[derive(Debug, Clone, PartialEq)]
pub struct Field {
    /// The field's text: a quoted field without its quotes and with `""` as `"`; an unquoted
    /// one as written.
    pub text: String,
    /// Whether the field was in double quotes (the master quotes every String value).
    pub quoted: bool,
}

/// One record and the line (from 1) it starts on.
#[derive(Debug, Clone, PartialEq)]
pub struct Record {
    pub line: usize,
    pub fields: Vec<Field>,
}

impl Record {
    /// The fields' texts.
    pub fn texts(&self) -> Vec<String> {
        self.fields.iter().map(|f| f.text.clone()).collect()
    }
}

/// A record that is not RFC 4180, at the line it starts on.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("line {line}: {reason}")]
pub struct CsvError {
    pub line: usize,
    pub reason: &'static str,
}

/// The records of a text, separated by `,`, one at a time, so that a reader keeps only what
/// it converts them into (a large file's fields as texts take several times the file's size);
/// after an error it ends. Empty lines are skipped and so, with `skip_comments`, are lines
/// starting with `#` (outside quotes). A line break inside quotes belongs to the field;
/// `\r\n` ends a record as `\n` does.
pub struct Records<'a> {
    chars: std::iter::Peekable<std::str::Chars<'a>>,
    line: usize,
    skip_comments: bool,
    failed: bool,
}

impl<'a> Records<'a> {
    pub fn new(text: &'a str, skip_comments: bool) -> Self {
        Records {
            chars: text.chars().peekable(),
            line: 1,
            skip_comments,
            failed: false,
        }
    }

    fn record(&mut self) -> Option<Result<Record, CsvError>> {
        let chars = &mut self.chars;
        loop {
            // at the start of a record: skip empty and comment lines
            match chars.peek() {
                None => return None,
                Some('\n') => {
                    chars.next();
                    self.line += 1;
                    continue;
                }
                Some('\r') => {
                    chars.next();
                    continue;
                }
                Some('#') if self.skip_comments => {
                    for c in chars.by_ref() {
                        if c == '\n' {
                            break;
                        }
                    }
                    self.line += 1;
                    continue;
                }
                Some(_) => break,
            }
        }
        let start = self.line;
        let err = |reason| {
            Some(Err(CsvError {
                line: start,
                reason,
            }))
        };
        let mut fields = Vec::new();
        let mut field = String::new();
        let mut quoted = false;
        let mut in_quotes = false;
        let mut at_start = true;
        loop {
            let Some(c) = chars.next() else {
                if in_quotes {
                    return err("unterminated quoted field");
                }
                break;
            };
            match (in_quotes, c) {
                (false, '"') if at_start => {
                    quoted = true;
                    in_quotes = true;
                    at_start = false;
                }
                (false, '"') => return err("a quote inside an unquoted field"),
                (true, '"') => {
                    if chars.peek() == Some(&'"') {
                        chars.next();
                        field.push('"');
                    } else {
                        in_quotes = false;
                        if !matches!(chars.peek(), None | Some(',' | '\n' | '\r')) {
                            return err("text after a closing quote");
                        }
                    }
                }
                (false, ',') => {
                    fields.push(Field {
                        text: std::mem::take(&mut field),
                        quoted,
                    });
                    quoted = false;
                    at_start = true;
                }
                (false, '\r') if chars.peek() == Some(&'\n') => {}
                (false, '\n') => {
                    self.line += 1;
                    break;
                }
                (_, c) => {
                    if c == '\n' {
                        self.line += 1;
                    }
                    field.push(c);
                    at_start = false;
                }
            }
        }
        fields.push(Field {
            text: field,
            quoted,
        });
        Some(Ok(Record {
            line: start,
            fields,
        }))
    }
}

impl Iterator for Records<'_> {
    type Item = Result<Record, CsvError>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.failed {
            return None;
        }
        let r = self.record();
        self.failed = matches!(r, Some(Err(_)));
        r
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every record of `text` at once.
    fn records(text: &str, skip_comments: bool) -> Result<Vec<Record>, CsvError> {
        Records::new(text, skip_comments).collect()
    }

    fn texts(text: &str) -> Vec<(usize, Vec<String>)> {
        records(text, true)
            .unwrap()
            .iter()
            .map(|r| (r.line, r.texts()))
            .collect()
    }

    #[test]
    fn quoted_fields_hold_commas_quotes_and_line_breaks() {
        let text = "time [s],\"x,y [m]\",s\r\n0,1.5,\"a \"\"b\"\"\"\n\n# note\n0.1,2,\"two\nlines\"\n0.2,3,\n";
        assert_eq!(
            texts(text),
            vec![
                (1, vec!["time [s]".into(), "x,y [m]".into(), "s".into()]),
                (2, vec!["0".into(), "1.5".into(), "a \"b\"".into()]),
                (5, vec!["0.1".into(), "2".into(), "two\nlines".into()]),
                (7, vec!["0.2".into(), "3".into(), "".into()]),
            ]
        );
        let r = records("1,\"2\",3", false).unwrap();
        let quoted: Vec<bool> = r[0].fields.iter().map(|f| f.quoted).collect();
        assert_eq!(quoted, vec![false, true, false]);
        // without comment skipping, '#' starts a field like any other character
        assert_eq!(
            records("#a,b\n", false).unwrap()[0].texts(),
            vec!["#a", "b"]
        );
    }

    /// One record at a time, the same as the whole list; after a malformed record it ends.
    #[test]
    fn records_one_at_a_time_end_at_the_first_error() {
        let text = "a,b\n1,\"x\ny\"\n2,3\n";
        let one: Vec<Record> = Records::new(text, false).map(Result::unwrap).collect();
        assert_eq!(one, records(text, false).unwrap());
        assert_eq!(one.len(), 3);
        let mut it = Records::new("a,b\n1,x\"y\n2,3\n", false);
        assert!(it.next().unwrap().is_ok());
        assert_eq!(it.next().unwrap().unwrap_err().line, 2);
        assert!(it.next().is_none());
    }

    #[test]
    fn a_malformed_record_names_the_line_it_starts_on() {
        let e = records("a,b\n1,\"open\n2,3\n", false).unwrap_err();
        assert_eq!(
            e,
            CsvError {
                line: 2,
                reason: "unterminated quoted field"
            }
        );
        let e = records("a,b\n1,x\"y\n", false).unwrap_err();
        assert_eq!(e.to_string(), "line 2: a quote inside an unquoted field");
        let e = records("a,b\n1,\"x\"y\n", false).unwrap_err();
        assert_eq!(e.reason, "text after a closing quote");
    }
}
