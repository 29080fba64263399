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
    #[error("{file}: {error}")]
    Body {
        /// The file.
        file: String,
        /// Which body and field.
        error: BodyError,
    },
    /// A scene-level setting is invalid.
    #[error("{file}: field `{field}`: {message}")]
    Setting {
        /// The file.
        file: String,
        /// The field.
        field: String,
        /// What is wrong.
        message: String,
    },
}

impl SceneError {
    pub(crate) fn in_file(self, name: &str) -> Self {
        match self {
            Self::Body { error, .. } => Self::Body {
                file: name.into(),
                error,
            },
            Self::Setting { field, message, .. } => Self::Setting {
                file: name.into(),
                field,
                message,
            },
            other => other,
        }
    }

    pub(crate) fn from_ron(file: &str, text: &str, e: ron::error::SpannedError) -> Self {
        let pos = e.span.start;
        Self::Parse {
            file: file.into(),
            line: pos.line,
            column: pos.col,
            message: e.code.to_string(),
            body: enclosing_body(text, pos.line, pos.col),
        }
    }
}

/// The name of the `Body(...)` whose text encloses line/column, found from the source text:
/// the last `Body(` before the position, and the first `name: "..."` after it.
fn enclosing_body(text: &str, line: usize, column: usize) -> Option<String> {
    let offset: usize = text
        .split_inclusive('\n')
        .take(line.saturating_sub(1))
        .map(str::len)
        .sum::<usize>()
        + column.saturating_sub(1);
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
