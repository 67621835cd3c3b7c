//! The crate's error type: bad input only. Solver outcomes and "no contact" are data.

use thiserror::Error as ThisError;

/// Everything that can go wrong in cloudprox because of what the caller passed in.
#[derive(Debug, Clone, PartialEq, ThisError)]
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
}

/// `Result` with the crate's [`Error`].
pub type Result<T> = std::result::Result<T, Error>;

impl Error {
    /// Shorthand for [`Error::InvalidInput`].
    pub(crate) fn invalid(msg: impl Into<String>) -> Self {
        Error::InvalidInput(msg.into())
    }
}
