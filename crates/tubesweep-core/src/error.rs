//! Errors of the core. Every failure a caller can provoke is a variant here; the Python bindings
//! map each one to a Python exception in a single place.

use std::fmt;

/// What went wrong, with enough context for the message to name the argument and the fix.
#[derive(Debug, Clone, PartialEq)]
pub enum Error {
    /// An argument has a bad value; `argument` names it, `message` says why and what to do.
    InvalidArgument { argument: &'static str, message: String },
    /// The band is not usable for the requested method (e.g. an inner-tube node lacks a
    /// neighbour in the extension layer).
    BadBand { message: String },
    /// The caller asked the solver to stop (e.g. Ctrl-C in Python).
    Interrupted { iterations: usize },
}

impl Error {
    pub fn invalid(argument: &'static str, message: impl Into<String>) -> Self {
        Error::InvalidArgument {
            argument,
            message: message.into(),
        }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::InvalidArgument { argument, message } => write!(f, "{argument}: {message}"),
            Error::BadBand { message } => write!(f, "{message}"),
            Error::Interrupted { iterations } => {
                write!(f, "solve interrupted after {iterations} iterations")
            }
        }
    }
}

impl std::error::Error for Error {}

pub type Result<T> = std::result::Result<T, Error>;
