//! One error type for everything that can be wrong with a scene the user gave.

use std::path::PathBuf;

use thiserror::Error;

/// Why a scene could not be loaded. Its `Display` is one line.
#[derive(Clone, Debug, Error, PartialEq)]
pub enum LoadError {
    /// Something at a known place in a scene file.
    #[error("{origin}:{line}:{column}: {key}: {message}")]
    At {
        /// File name (or other origin) of the text.
        origin: String,
        /// 1-based line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// Key path, e.g. `material[1].reflectance`.
        key: String,
        /// What is wrong and what was expected.
        message: String,
    },
    /// The file could not be read.
    #[error("{path}: cannot read the scene file: {reason}")]
    Unreadable {
        /// The path.
        path: PathBuf,
        /// The system's reason.
        reason: String,
    },
    /// Neither a file nor a built-in scene.
    #[error("'{name}' is neither a scene file nor a built-in scene (built-ins: {known})")]
    UnknownScene {
        /// What was asked for.
        name: String,
        /// The built-in names.
        known: String,
    },
}

impl LoadError {
    /// The process exit code for this error: 2, bad input.
    pub fn exit_code(&self) -> u8 {
        2
    }
}

/// 1-based (line, column) of a byte offset in `text`.
pub(crate) fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let offset = offset.min(text.len());
    let before = &text.as_bytes()[..offset];
    let line = before.iter().filter(|&&b| b == b'\n').count() + 1;
    let start = before.iter().rposition(|&b| b == b'\n').map_or(0, |p| p + 1);
    let column = String::from_utf8_lossy(&before[start..]).chars().count() + 1;
    (line, column)
}
