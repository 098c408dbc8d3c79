//! Errors of reading and checking a world. Every message says where (`file:line:col`
//! for syntax, the field path such as `obstacles[2].radius` for meaning), what is wrong
//! and how to fix it, so the binary only has to print it.

use thiserror::Error;

/// Why a world could not be read, parsed, overridden or validated.
#[derive(Debug, Error)]
pub enum WorldError {
    /// The world file could not be read.
    #[error("{path}: cannot read the world file")]
    Read {
        /// The path as given.
        path: String,
        /// The underlying I/O error.
        #[source]
        source: std::io::Error,
    },
    /// The text is not valid RON for a world (bad syntax, unknown field, wrong type).
    #[error("{origin}:{line}:{col}: {message}")]
    Syntax {
        /// File name or other origin of the text.
        origin: String,
        /// 1-based line of the error.
        line: usize,
        /// 1-based column of the error.
        col: usize,
        /// What is wrong and how to fix it.
        message: String,
    },
    /// The world parses but a value is out of range or inconsistent with another.
    #[error("{location}: {field} {problem}; {fix}")]
    Invalid {
        /// `file:line:col` of the culprit where it is in the text, else the file name
        /// (and the override that set it, if any).
        location: String,
        /// Dotted field path of the culprit, e.g. `obstacles[2].radius`.
        field: String,
        /// What is wrong, with the offending value and the rule it breaks.
        problem: String,
        /// How to fix it.
        fix: String,
    },
    /// An override names a path that does not exist.
    #[error("--set {path}: no such setting; valid paths are: {valid}")]
    UnknownSetting {
        /// The path as given.
        path: String,
        /// Every valid path, comma-separated.
        valid: String,
    },
    /// An override without `=` (found by the forty-first session's review: it was echoed
    /// as `--set PATH=:`).
    #[error(
        "--set {given}: expected PATH=VALUE, e.g. `swarm.detection_radius=0.03`; give the value after `=`"
    )]
    NoValue {
        /// The override as given.
        given: String,
    },
    /// An override is malformed or its value does not parse as the field's type.
    #[error("--set {path}={value}: {message}")]
    BadSetting {
        /// The path as given.
        path: String,
        /// The value as given.
        value: String,
        /// What is wrong and how to fix it.
        message: String,
    },
}

impl WorldError {
    /// The field path of a validation error (`None` for other kinds).
    pub fn field(&self) -> Option<&str> {
        match self {
            WorldError::Invalid { field, .. } => Some(field),
            _ => None,
        }
    }
}
