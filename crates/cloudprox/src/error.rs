//! The crate's error type: bad input only. Solver outcomes and "no contact" are data.

use thiserror::Error as ThisError;

/// Everything that can go wrong in cloudprox because of what the caller passed in.
#[derive(Debug, Clone, PartialEq, ThisError)]
#[non_exhaustive]
pub enum Error {
    /// An input value is out of its domain (NaN coordinates, negative sigma, empty
    /// cloud, non-PSD covariance, thresholds out of order, ...). The message names it.
    #[error("invalid input: {0}")]
    InvalidInput(String),
    /// Two inputs that must agree in length or shape do not.
    #[error("shape mismatch: {what}: expected {expected}, got {got}")]
    Shape {
        /// What was being matched.
        what: String,
        /// The expected size.
        expected: usize,
        /// The size that was given.
        got: usize,
    },
    /// A file could not be opened, read or written (missing, no permission, ...).
    #[error("{path}: {message}")]
    Io {
        /// The file.
        path: String,
        /// What the operating system said, as a kind (`NotFound`, `PermissionDenied`, ...).
        kind: std::io::ErrorKind,
        /// What the operating system said, as text.
        message: String,
    },
    /// A file's content is not valid in its format: corrupt, truncated, or a
    /// variant this reader does not support. The message names file and problem.
    #[error("{path}: not a valid {format} file: {problem}")]
    Format {
        /// The file (or the name given to an in-memory buffer).
        path: String,
        /// The format it was read as (`PLY`, `PCD`, `STL`, ...).
        format: String,
        /// What is wrong, with the line or byte offset where it helps.
        problem: String,
    },
}

/// `Result` with the crate's [`Error`].
pub type Result<T> = std::result::Result<T, Error>;

impl Error {
    /// Shorthand for [`Error::InvalidInput`].
    pub(crate) fn invalid(msg: impl Into<String>) -> Self {
        Error::InvalidInput(msg.into())
    }

    /// An [`Error::Io`] for `path` from a `std::io::Error`.
    pub fn io(path: &std::path::Path, err: &std::io::Error) -> Self {
        Error::Io {
            path: path.display().to_string(),
            kind: err.kind(),
            message: err.to_string(),
        }
    }

    /// An [`Error::Format`].
    pub(crate) fn format(path: &str, format: &str, problem: impl Into<String>) -> Self {
        Error::Format {
            path: path.to_string(),
            format: format.to_string(),
            problem: problem.into(),
        }
    }
}
