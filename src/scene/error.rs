//! Scene errors: every one names the file, and the line and column or the body and field.

use crate::BodyError;
use thiserror::Error;

/// Why a scene could not be loaded or built.
#[derive(Clone, Debug, Error, PartialEq)]
pub enum SceneError {
    /// The file could not be read.
    #[error("{file}: cannot read: {message}")]
    Io {
        /// The file.
        file: String,
        /// The operating system's message.
        message: String,
    },
    /// The file is not a valid scene (RON syntax, wrong types, unknown or missing fields).
    #[error("{file}:{line}:{column}: {message}{}", body.as_ref().map(|b| format!(" (in body \"{b}\")")).unwrap_or_default())]
    Parse {
        /// The file.
        file: String,
        /// Line, from 1.
        line: usize,
        /// Column, from 1.
        column: usize,
        /// What ron reported.
        message: String,
        /// The body whose text contains the position, when there is one and it has a name.
        body: Option<String>,
    },
    /// A body is invalid.
    #[error("{file}{}: {}{error}", location(at), entry(index))]
    Body {
        /// The file.
        file: String,
        /// Line and column (from 1) of the field in the file, or of the body when the field is
        /// not written there; `None` for scenes not parsed from text or a body not found in it.
        at: Option<(u32, u32)>,
        /// The body's place in the scene's `bodies` list (from 0), for a body written there:
        /// what names a body without a name. `None` for a generated body.
        index: Option<u32>,
        /// Which body and field.
        error: BodyError,
    },
    /// A scene-level setting is invalid.
    #[error("{file}{}: field `{field}`: {message}", location(at))]
    Setting {
        /// The file.
        file: String,
        /// Line and column (from 1) of the field in the file, when it is written there.
        at: Option<(u32, u32)>,
        /// The field.
        field: String,
        /// What is wrong.
        message: String,
    },
}

impl SceneError {
    /// The error as found in the file `name` whose text is `text`: the file named, and the
    /// line and column of the field (or body) when the text shows where it is.
    pub fn in_file(self, name: &str, text: &str) -> Self {
        match self {
            Self::Body {
                error, at, index, ..
            } => {
                let BodyError::Field {
                    body,
                    field,
                    message,
                } = &error;
                // A repeated name is reported at its later occurrence.
                let last = field == "name" && message.contains("the same name");
                // A body without a name is found by its place in the list.
                let by_index = || {
                    index
                        .and_then(|i| locate_listed_body_field(text, i as usize, field))
                        .map(narrow)
                };
                let at = if body.is_empty() {
                    at.or_else(by_index)
                } else {
                    at.or_else(|| locate_body_field(text, body, field, last).map(narrow))
                        .or_else(by_index)
                };
                Self::Body {
                    file: name.into(),
                    at,
                    index,
                    error,
                }
            }
            Self::Setting {
                field, message, at, ..
            } => Self::Setting {
                file: name.into(),
                at: at.or_else(|| locate_setting(text, &field).map(narrow)),
                field,
                message,
            },
            other => other,
        }
    }

    pub(crate) fn from_ron(file: &str, text: &str, e: ron::error::SpannedError) -> Self {
        let pos = e.span.start;
        // ron's own advice for deep nesting names its API, which a scene's author cannot use.
        let mut message = match e.code {
            ron::Error::ExceededRecursionLimit => {
                "nested too deeply (compounds or brackets more than 128 levels deep)".to_string()
            }
            ref code => code.to_string(),
        };
        if let Some(hint) = hint(text, pos.line, pos.col, &message) {
            message = format!("{message} ({hint})");
        }
        Self::Parse {
            file: file.into(),
            line: pos.line,
            column: pos.col,
            message,
            body: enclosing_body(text, pos.line, pos.col),
        }
    }
}

/// The name of the `Body(...)` whose text encloses line/column, found from the source text:
/// the last `Body(` before the position, and the first `name: "..."` after it.
fn enclosing_body(text: &str, line: usize, column: usize) -> Option<String> {
    let offset = byte_offset(text, line, column);
    let before = text.get(..offset.min(text.len()))?;
    let start = before.rfind("Body(")?;
    // The position must still be inside that body's parentheses.
    let mut depth = 0i32;
    for ch in before[start..].chars() {
        depth += match ch {
            '(' => 1,
            ')' => -1,
            _ => 0,
        };
        if depth == 0 && ch == ')' {
            return None;
        }
    }
    let rest = &text[start..];
    let name_at = rest.find("name:")?;
    let after = rest[name_at + 5..].trim_start().strip_prefix('"')?;
    Some(after[..after.find('"')?].to_string())
}

/// `:line:column` of a location, or nothing.
/// The byte range of a `Body(...)` whose `Body(` starts at `open`: from its `(` to the
/// matching `)` (or the end of the text).
fn body_span(text: &str, open: usize) -> (usize, usize) {
    let start = open + "Body".len();
    let mut depth = 0i32;
    for (i, ch) in text[start..].char_indices() {
        depth += match ch {
            '(' => 1,
            ')' => -1,
            _ => 0,
        };
        if depth == 0 {
            return (start, start + i);
        }
    }
    (start, text.len())
}

/// A line and column as stored in an error (a file of more than 4·10⁹ lines or columns
/// saturates).
fn narrow((line, column): (usize, usize)) -> (u32, u32) {
    let n = |x: usize| u32::try_from(x).unwrap_or(u32::MAX);
    (n(line), n(column))
}

/// `bodies[i]: ` for a body of the scene's list, so that a body without a name is named too.
fn entry(index: &Option<u32>) -> String {
    index.map(|i| format!("bodies[{i}]: ")).unwrap_or_default()
}

/// Where the `index`-th `Body(...)` of the `bodies` list writes `field` (or where that body
/// starts, when it does not write the field).
fn locate_listed_body_field(text: &str, index: usize, field: &str) -> Option<(usize, usize)> {
    let mut search = find_key(text, 0, text.len(), "bodies")?;
    let mut open = search;
    for _ in 0..=index {
        open = search + text[search..].find("Body(")?;
        search = open + "Body(".len();
    }
    let (start, end) = body_span(text, open);
    let key = field.rsplit('.').next().unwrap_or(field);
    Some(line_column(
        text,
        find_key(text, start, end, key).unwrap_or(open),
    ))
}

fn location(at: &Option<(u32, u32)>) -> String {
    at.map(|(line, column)| format!(":{line}:{column}"))
        .unwrap_or_default()
}

/// Line and column (from 1) of byte `offset` of `text`.
fn line_column(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let start = before.rfind('\n').map_or(0, |i| i + 1);
    (line, before[start..].chars().count() + 1)
}

/// Byte offset of the first `key:` in `text[from..to]` (the key a whole word, spaces allowed
/// before the colon), skipping `//` comments.
fn find_key(text: &str, from: usize, to: usize, key: &str) -> Option<usize> {
    let region = text.get(from..to.min(text.len()))?;
    let mut search = 0;
    while let Some(i) = region[search..].find(key) {
        let at = search + i;
        search = at + key.len();
        let before_ok = region[..at]
            .chars()
            .next_back()
            .is_none_or(|c| !(c.is_alphanumeric() || c == '_'));
        let after_ok = region[at + key.len()..].trim_start().starts_with(':');
        let line_start = region[..at].rfind('\n').map_or(0, |n| n + 1);
        let commented = region[line_start..at].contains("//");
        if before_ok && after_ok && !commented {
            return Some(from + at);
        }
    }
    None
}

/// Where the body named `body` sets `field` (its last dotted part: `shape.radius` is
/// `radius:`), or where its name is when the field is not written; with `last`, the last body
/// of that name (a repeated name).
fn locate_body_field(text: &str, body: &str, field: &str, last: bool) -> Option<(usize, usize)> {
    let quoted = format!("\"{body}\"");
    let key = field.rsplit('.').next().unwrap_or(field);
    // Every body of that name: (where its name is, where it sets the field).
    let mut found = Vec::new();
    let mut search = 0;
    while let Some(at) = find_key(text, search, text.len(), "name") {
        search = at + 4;
        let Some(value) = text[search..].trim_start().strip_prefix(':') else {
            continue;
        };
        if !value.trim_start().starts_with(&quoted) {
            continue;
        }
        // The body's parentheses: from the last `Body(` before its name to the matching `)`.
        let Some(open) = text[..at].rfind("Body(") else {
            continue;
        };
        let (start, end) = body_span(text, open);
        found.push((at, find_key(text, start, end, key)));
    }
    // A repeated name: its later body. Otherwise the first body of that name that writes the
    // field (two bodies of one name: the error may be the second's), else the first.
    let (name_at, field_at) = if last {
        *found.last()?
    } else {
        found
            .iter()
            .copied()
            .find(|f| f.1.is_some())
            .or_else(|| found.first().copied())?
    };
    Some(line_column(text, field_at.unwrap_or(name_at)))
}

/// Where a scene-level `field` is written (`resolver.substeps`: `substeps:` after
/// `resolver:`; `generators[1].count`: `count:` after `generators:`), if it is.
fn locate_setting(text: &str, field: &str) -> Option<(usize, usize)> {
    let mut parts = field.split('.');
    let first = parts.next()?;
    let first = first.split('[').next().unwrap_or(first);
    let mut at = find_key(text, 0, text.len(), first)?;
    if let Some(last) = parts.next_back() {
        let last = last.split('[').next().unwrap_or(last);
        at = find_key(text, at, text.len(), last)?;
    }
    Some(line_column(text, at))
}

/// A hint for three of ron's messages that do not say what is wrong: a fraction where a
/// whole number is expected (`steps: 10.5` is read as 10 followed by `.5`: "Expected comma"),
/// an optional setting written with its type (`sleep: Some(SleepSettings(...))`), and a
/// resolver's settings in double parentheses (`SoftStep((substeps: 4))`: "Expected
/// identifier").
fn hint(text: &str, line: usize, column: usize, message: &str) -> Option<&'static str> {
    let offset = byte_offset(text, line, column);
    let here = text.get(offset.min(text.len())..)?;
    let before = text.get(..offset.min(text.len()))?;
    let after_digit = before.trim_end().ends_with(|c: char| c.is_ascii_digit());
    let fraction = here.trim_start().starts_with('.') || here.trim_start().starts_with(['e', 'E']);
    if after_digit && fraction {
        return Some("a whole number is expected here, without a fraction or exponent");
    }
    // An optional struct written as `Some(...)` or with its type's name (`SleepSettings(...)`,
    // `Camera(...)`): ron reads the name as an unexpected field, or `Some((` as an identifier
    // missing (`Some(2.0)` around a number is fine, and an error after it is another one).
    let named_type = message
        .split_once("Unexpected field named `")
        .is_some_and(|(_, rest)| rest.starts_with(|c: char| c.is_ascii_uppercase()));
    let line = [
        before.rsplit('\n').next().unwrap_or(""),
        here.split('\n').next().unwrap_or(""),
    ]
    .concat();
    if named_type || line.contains("Some((") {
        return Some(
            "write the settings' fields in parentheses, without `Some` or the type's name: \
             `sleep: (enabled: false)`, `camera: (position: (0.0, 5.0, 10.0))`",
        );
    }
    // A resolver's settings in double parentheses (`SoftStep((substeps: 4))`, the form an
    // environment variable of the test harness takes): ron reads the inner `(` as an
    // identifier missing.
    if line.contains("SoftStep((") || line.contains("Millington((") {
        return Some(
            "write the resolver's settings in one pair of parentheses: \
             `resolver: SoftStep(substeps: 4)`",
        );
    }
    None
}

/// Byte offset of `line` and `column` (from 1, as ron reports them) in `text`.
fn byte_offset(text: &str, line: usize, column: usize) -> usize {
    text.split_inclusive('\n')
        .take(line.saturating_sub(1))
        .map(str::len)
        .sum::<usize>()
        + column.saturating_sub(1)
}
