//! Between two iterations of a solve that runs without the GIL: Ctrl-C and the user's progress
//! callback, with the GIL taken back for an instant.

use pyo3::call::PyCallArgs;
use pyo3::prelude::*;
use tubesweep_core::Control;

/// Checks for Ctrl-C, then calls `progress(*args)` if given. The first error (a
/// `KeyboardInterrupt`, or an exception the callback raised) stops the solve and is kept in
/// `error`, to be raised once the solve has returned.
pub(crate) fn check_in<A>(progress: &Option<Py<PyAny>>, error: &mut Option<PyErr>, args: A) -> Control
where
    A: for<'py> PyCallArgs<'py>,
{
    Python::attach(|py| {
        let done = py.check_signals().and_then(|()| match progress {
            Some(cb) => cb.call1(py, args).map(drop),
            None => Ok(()),
        });
        match done {
            Ok(()) => Control::Continue,
            Err(e) => {
                *error = Some(e);
                Control::Stop
            }
        }
    })
}
