//! One error type for everything that can be wrong with a scene the user gave.

use std::path::PathBuf;

use thiserror::Error;

/// Why a scene could not be loaded. Its `Display` is always one line, starting with the file
/// name, so a command-line tool can print it as it is.
#[derive(Clone, Debug, Error, PartialEq)]
pub enum LoadError {
    /// Something wrong at a known place in a scene file: TOML syntax, an unknown key, a
    /// value of the wrong type, or a value the scene's validation rejects.
    #[error("{origin}:{line}:{column}: {key}: {message}")]
    At {
        /// File name (or other origin) of the text.
        origin: String,
        /// 1-based line.
        line: usize,
        /// 1-based column, in characters.
        column: usize,
        /// Key path, e.g. `material[1].reflectance`.
        key: String,
        /// What is wrong and what was expected.
        message: String,
    },
    /// The file could not be read (missing, a directory, no permission, not UTF-8).
    #[error("{path}: cannot read the scene file: {reason}")]
    Unreadable {
        /// The path as given.
        path: PathBuf,
        /// The system's reason.
        reason: String,
    },
    /// Something wrong in a model file (OBJ, MTL, glTF): the file, the line when the format
    /// has lines, and the element (face, vertex, material, accessor) with what was expected.
    #[error("{origin}{}: {message}", .line.map_or_else(String::new, |l| format!(":{l}")))]
    Model {
        /// File name of the model (or its MTL).
        origin: String,
        /// 1-based line, for text formats.
        line: Option<usize>,
        /// What is wrong, naming the element.
        message: String,
    },
    /// The argument is neither an existing file nor a built-in scene name.
    #[error("'{name}' is neither a scene file nor a built-in scene (built-ins: {known})")]
    UnknownScene {
        /// What was asked for.
        name: String,
        /// The built-in names, comma-separated.
        known: String,
    },
}

impl LoadError {
    /// The process exit code for this error: 2 (bad input), the same for every variant, so a
    /// script can tell "your scene is wrong" from a crash or an internal error.
    pub fn exit_code(&self) -> u8 {
        2
    }
}
