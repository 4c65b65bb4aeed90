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
    /// `fix` says what the caller can change.
    OutOfMemory {
        what: &'static str,
        bytes: u128,
        fix: &'static str,
    },
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
            Error::OutOfMemory { what, bytes, fix } => write!(
                f,
                "{what} needs about {:.1} GiB, which could not be allocated; {fix}",
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
    try_filled_or(what, "use a coarser grid (fewer nodes per axis)", n, value)
}

/// [`try_filled`] of `rows × width` entries (a batch's values, one row per source), whose
/// failure says `fix`.
pub fn try_filled_or<T: Clone>(what: &'static str, fix: &'static str, n: usize, value: T) -> Result<Vec<T>> {
    let mut v = Vec::new();
    let bytes = (n as u128) * (std::mem::size_of::<T>() as u128);
    v.try_reserve_exact(n)
        .map_err(|_| Error::OutOfMemory { what, bytes, fix })?;
    v.resize(n, value);
    Ok(v)
}

/// `rows × width` values of a batch (one row per source), or [`Error::OutOfMemory`] saying how
/// to ask for fewer (the product may overflow: then too).
pub fn batch_rows(rows: usize, width: usize, fix: &'static str) -> Result<Vec<f64>> {
    match rows.checked_mul(width) {
        Some(n) => try_filled_or("the batch's values (sources × points)", fix, n, 0.0),
        None => Err(Error::OutOfMemory {
            what: "the batch's values (sources × points)",
            bytes: (rows as u128) * (width as u128) * 8,
            fix,
        }),
    }
}

pub type Result<T> = std::result::Result<T, Error>;

#[cfg(test)]
mod tests {
    use super::*;

    /// A batch too large for memory is an error that says how large and what to do, whether its
    /// size overflows or its allocation fails (the process aborted before).
    #[test]
    fn a_batch_too_large_is_an_error_not_an_abort() {
        for (rows, width) in [(1usize << 40, 1usize << 30), (1usize << 30, 1usize << 30)] {
            let e = batch_rows(rows, width, "pass at=").unwrap_err();
            assert!(matches!(e, Error::OutOfMemory { .. }));
            let text = e.to_string();
            assert!(text.contains("could not be allocated; pass at="), "{text}");
        }
        assert_eq!(batch_rows(3, 4, "").unwrap(), vec![0.0; 12]);
    }
}
