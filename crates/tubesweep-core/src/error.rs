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
    /// An allocation sized by the arguments could not be made (`Vec::try_reserve` failed):
    /// reported instead of aborting the process.
    OutOfMemory { what: &'static str, bytes: u128 },
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
            Error::OutOfMemory { what, bytes } => write!(
                f,
                "{what} needs about {:.1} GiB, which could not be allocated; use a coarser grid (fewer nodes per axis)",
                *bytes as f64 / (1u64 << 30) as f64
            ),
        }
    }
}

impl std::error::Error for Error {}

/// A vector of `n` copies of `value`, or [`Error::OutOfMemory`] (naming `what`) when the
/// allocation fails or its size overflows: for allocations whose size comes from the caller's
/// arguments (a grid's shape), where the global allocator's failure would abort the process.
pub fn try_filled<T: Clone>(what: &'static str, n: usize, value: T) -> Result<Vec<T>> {
    let mut v = Vec::new();
    let bytes = (n as u128) * (std::mem::size_of::<T>() as u128);
    v.try_reserve_exact(n).map_err(|_| Error::OutOfMemory { what, bytes })?;
    v.resize(n, value);
    Ok(v)
}

pub type Result<T> = std::result::Result<T, Error>;
