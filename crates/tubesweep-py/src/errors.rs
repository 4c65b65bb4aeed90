//! The one place where core errors become Python exceptions.
//!
//! | core error | Python exception |
//! |---|---|
//! | `InvalidArgument` | `ValueError` naming the argument |
//! | `BadBand` | `ValueError` |
//! | `Interrupted` | `KeyboardInterrupt` |

use pyo3::exceptions::{PyKeyboardInterrupt, PyValueError};
use pyo3::PyErr;
use tubesweep_core::Error;

pub fn to_pyerr(e: Error) -> PyErr {
    match e {
        Error::InvalidArgument { .. } | Error::BadBand { .. } => PyValueError::new_err(e.to_string()),
        Error::Interrupted { .. } => PyKeyboardInterrupt::new_err(e.to_string()),
    }
}
