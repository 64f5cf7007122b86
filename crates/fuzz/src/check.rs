//! What a target answers for one input, and the checks of that answer: no number that is not
//! finite and no `null` in an answer, every refusal on one line.

use serde_json::Value;

/// One answer a target computed, as the command line would print it.
#[derive(Debug, Clone, PartialEq)]
pub enum Answer {
    /// JSON (`--format json`), built by serde_json from the engine's answer. serde_json writes a
    /// NaN or an infinity as `null`, so a `null` anywhere is a number that was not finite (the
    /// contract omits values that do not exist, it never writes `null`).
    Json {
        /// Which answer (`power at hover`, `log info`).
        what: &'static str,
        /// The value.
        value: Value,
    },
    /// CSV text whose last `computed` columns are numbers aloft computed (the other columns are
    /// the input's, passed through).
    Csv {
        /// Which answer.
        what: &'static str,
        /// The text.
        text: String,
        /// How many trailing columns aloft computed.
        computed: usize,
    },
}

/// A refusal: the line `aloft: error: ...` the command line would print, and where it came from.
#[derive(Debug, Clone, PartialEq)]
pub struct Refusal {
    /// Which step refused (`vehicle`, `plan`).
    pub what: &'static str,
    /// The message as the CLI renders it (the error and its causes through `one_line`).
    pub line: String,
    /// Whether the error is the engine's boundary check of an answer ([`aloft::Error::NonFinite`]):
    /// an input the models accepted led to a number that is not finite.
    pub non_finite: bool,
}

/// What a target did with one input.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Outcome {
    /// Whether the parser accepted the input (answers may still refuse).
    pub accepted: bool,
    /// The answers computed.
    pub answers: Vec<Answer>,
    /// The refusals, one per failed step.
    pub refusals: Vec<Refusal>,
    /// Invariants of the target that failed (a round trip that did not hold).
    pub broken: Vec<Problem>,
}

impl Outcome {
    /// An input the parser refused.
    pub fn refused(what: &'static str, e: &aloft::Error) -> Self {
        let mut o = Self::default();
        o.refuse(what, e);
        o
    }

    /// Record a refusal of one step.
    pub fn refuse(&mut self, what: &'static str, e: &aloft::Error) {
        self.refusals.push(Refusal {
            what,
            line: aloft::engine::error_line(e),
            non_finite: matches!(e, aloft::Error::NonFinite { .. }),
        });
    }

    /// Record an answer as JSON.
    pub fn json<T: serde::Serialize>(&mut self, what: &'static str, answer: &T) {
        let value = serde_json::to_value(answer)
            .unwrap_or_else(|e| Value::String(format!("the answer did not serialise: {e}")));
        self.answers.push(Answer::Json { what, value });
    }

    /// Record the answer or the refusal of one step.
    pub fn step<T: serde::Serialize>(&mut self, what: &'static str, r: &Result<T, aloft::Error>) {
        match r {
            Ok(a) => self.json(what, a),
            Err(e) => self.refuse(what, e),
        }
    }
}

/// A failed check of an answer or a refusal.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Problem {
    /// The check (`null-in-json`, `non-finite-csv`, `multi-line-error`, ...).
    pub check: &'static str,
    /// What and where.
    pub detail: String,
}

/// Characters that move a terminal to another line, or that a reader splitting lines splits at
/// (Python's `str.splitlines` splits at all of these).
fn breaks_line(c: char) -> bool {
    matches!(
        c,
        '\n' | '\r' | '\u{0b}' | '\u{0c}' | '\u{1c}'
            ..='\u{1e}' | '\u{85}' | '\u{2028}' | '\u{2029}'
    )
}

/// Checks whose failure is reported as a note, not a finding: the engine refused an answer that
/// was not finite (exit 2 with a message naming the field, as the contract allows), which says
/// that an input the models accepted leads to an overflow or a NaN inside them.
pub fn is_note(p: &Problem) -> bool {
    p.check == "non-finite-answer"
}

/// Every problem of an outcome.
pub fn problems(o: &Outcome) -> Vec<Problem> {
    let mut out = o.broken.clone();
    for a in &o.answers {
        match a {
            Answer::Json { what, value } => {
                let mut path = Vec::new();
                json_problems(what, value, &mut path, &mut out);
            }
            Answer::Csv {
                what,
                text,
                computed,
            } => csv_problems(what, text, *computed, &mut out),
        }
    }
    for r in &o.refusals {
        if r.line.trim().is_empty() {
            out.push(Problem {
                check: "empty-error",
                detail: format!("{}: the error message is empty", r.what),
            });
        }
        if r.line.chars().any(breaks_line) {
            out.push(Problem {
                check: "multi-line-error",
                detail: format!("{}: {:?}", r.what, r.line),
            });
        }
        if r.non_finite {
            out.push(Problem {
                check: "non-finite-answer",
                detail: format!("{}: {}", r.what, r.line),
            });
        }
    }
    out
}

fn json_problems(what: &str, v: &Value, path: &mut Vec<String>, out: &mut Vec<Problem>) {
    match v {
        Value::Null => out.push(Problem {
            check: "null-in-json",
            detail: format!("{what}: {} is null", path.join(".")),
        }),
        Value::Number(n) => {
            if n.as_f64().is_some_and(|x| !x.is_finite()) {
                out.push(Problem {
                    check: "non-finite-json",
                    detail: format!("{what}: {} is {n}", path.join(".")),
                });
            }
        }
        Value::Array(items) => {
            for (k, x) in items.iter().enumerate() {
                path.push(k.to_string());
                json_problems(what, x, path, out);
                path.pop();
            }
        }
        Value::Object(map) => {
            for (k, x) in map {
                path.push(k.clone());
                json_problems(what, x, path, out);
                path.pop();
            }
        }
        Value::Bool(_) | Value::String(_) => {}
    }
}

fn csv_problems(what: &str, text: &str, computed: usize, out: &mut Vec<Problem>) {
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(true)
        .flexible(true)
        .from_reader(text.as_bytes());
    for (row, record) in reader.records().enumerate() {
        let record = match record {
            Ok(r) => r,
            Err(e) => {
                out.push(Problem {
                    check: "unreadable-csv",
                    detail: format!("{what}: row {}: {e}", row + 1),
                });
                return;
            }
        };
        let n = record.len();
        for (k, field) in record.iter().enumerate().skip(n.saturating_sub(computed)) {
            if !field.parse::<f64>().is_ok_and(f64::is_finite) {
                out.push(Problem {
                    check: "non-finite-csv",
                    detail: format!("{what}: row {} column {k} is {field:?}", row + 1),
                });
                return;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nulls_and_bad_csv_numbers_are_problems() {
        let mut o = Outcome::default();
        o.json("x", &serde_json::json!({"a": 1.0, "b": [1, null]}));
        o.json("nan", &f64::NAN);
        o.answers.push(Answer::Csv {
            what: "csv",
            text: "note,p\nx,1.5\ny,inf\n".into(),
            computed: 1,
        });
        let p = problems(&o);
        let checks: Vec<&str> = p.iter().map(|p| p.check).collect();
        assert_eq!(checks, ["null-in-json", "null-in-json", "non-finite-csv"]);
        assert!(p[0].detail.contains("b.1"), "{:?}", p[0]);
        assert!(p[2].detail.contains("row 2"), "{:?}", p[2]);
    }

    #[test]
    fn a_refusal_must_be_one_non_empty_line() {
        let line = |l: &str| Outcome {
            refusals: vec![Refusal {
                what: "t",
                line: l.into(),
                non_finite: false,
            }],
            ..Outcome::default()
        };
        assert!(problems(&line("bad value 3 at row 2")).is_empty());
        assert_eq!(problems(&line("a\rb"))[0].check, "multi-line-error");
        assert_eq!(problems(&line(" "))[0].check, "empty-error");
    }

    #[test]
    fn the_cli_line_joins_causes_once() {
        let e = aloft::Error::VehicleFormat {
            origin: "v.toml".into(),
            message: "TOML parse error at line 1\n  |\n1 | x\n  | ^\nexpected".into(),
        };
        assert_eq!(
            aloft::engine::error_line(&e),
            "invalid vehicle description v.toml: TOML parse error at line 1: expected"
        );
    }
}
