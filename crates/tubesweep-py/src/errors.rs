//! The one place where core errors become Python exceptions.
//!
//! | core error | Python exception |
//! |---|---|
//! | `InvalidArgument` | `ValueError` naming the argument |
//! | `BadBand` | `ValueError` |
//! | `Interrupted` | `KeyboardInterrupt` |
//! | `OutOfMemory` | `MemoryError` |

use pyo3::exceptions::{PyKeyboardInterrupt, PyMemoryError, PyValueError};
use pyo3::PyErr;
use tubesweep_core::Error;

pub fn to_pyerr(e: Error) -> PyErr {
    match e {
        Error::InvalidArgument { .. } | Error::BadBand { .. } => PyValueError::new_err(e.to_string()),
        Error::Interrupted { .. } => PyKeyboardInterrupt::new_err(e.to_string()),
        Error::OutOfMemory { .. } => PyMemoryError::new_err(e.to_string()),
    }
}
