//! The error type of data I/O: every variant says which file and where.

use paperbsdf_core::ParamError;

/// An error reading or writing project data; the message names the file and,
/// where it applies, the line, column and field.
#[derive(Debug, thiserror::Error)]
pub enum DataError {
    /// The file could not be read or written.
    #[error("{file}: {source}")]
    Io {
        /// The file.
        file: String,
        /// The operating system's error.
        #[source]
        source: std::io::Error,
    },
    /// The file's syntax or structure is wrong (missing field, unknown key, wrong type).
    #[error("{file}:{line}:{column}: {message}")]
    Syntax {
        /// The file (or `<inline>` for inline JSON).
        file: String,
        /// 1-based line.
        line: usize,
        /// 1-based column (0 when unknown).
        column: usize,
        /// What is wrong.
        message: String,
    },
    /// A parameter is outside its allowed range or otherwise invalid.
    #[error("{file}:{line}: {source}")]
    Param {
        /// The file.
        file: String,
        /// 1-based line of the parameter (0 when it could not be located).
        line: usize,
        /// The parameter error (names the parameter, value and range).
        #[source]
        source: ParamError,
    },
    /// A field of a CSV row is wrong.
    #[error("{file}:{line}: field `{field}`: {message}")]
    Field {
        /// The file.
        file: String,
        /// 1-based line.
        line: usize,
        /// Column name.
        field: String,
        /// What is wrong.
        message: String,
    },
    /// Anything else about a file.
    #[error("{file}: {message}")]
    Other {
        /// The file.
        file: String,
        /// What is wrong.
        message: String,
    },
}
