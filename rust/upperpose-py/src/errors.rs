//! The exception tree and the one mapping from core errors to Python ones.
//!
//! `UpperposeError` is the base of everything upperpose raises on purpose. `InputError` (also a
//! `ValueError`, so `except ValueError` keeps working) says an argument's value is not allowed;
//! `SearchError` that a search could not run. `upperpose.exceptions` adds `VideoError`.

use pyo3::create_exception;
use pyo3::exceptions::{PyException, PyValueError};
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::{PyDict, PyTuple, PyType};
use upperpose_core::CoreError;

create_exception!(
    _upperpose,
    UpperposeError,
    PyException,
    "Base class of the errors upperpose raises."
);
create_exception!(
    _upperpose,
    SearchError,
    UpperposeError,
    "A search could not run."
);

static INPUT_ERROR: PyOnceLock<Py<PyType>> = PyOnceLock::new();

/// The `InputError` class. A class declared by pyo3 has one base, so this one, which derives
/// from both `UpperposeError` and `ValueError`, is made with `type()` once per interpreter.
pub fn input_error_type(py: Python<'_>) -> PyResult<Bound<'_, PyType>> {
    let ty = INPUT_ERROR.get_or_try_init(py, || -> PyResult<Py<PyType>> {
        let bases = PyTuple::new(
            py,
            [
                py.get_type::<UpperposeError>().into_any(),
                py.get_type::<PyValueError>().into_any(),
            ],
        )?;
        let namespace = PyDict::new(py);
        namespace.set_item("__module__", "upperpose.exceptions")?;
        namespace.set_item(
            "__doc__",
            "An argument's value is not allowed (also a ValueError); the message names it.",
        )?;
        let made = py
            .get_type::<PyType>()
            .call1(("InputError", bases, namespace))?;
        Ok(made.cast_into::<PyType>()?.unbind())
    })?;
    Ok(ty.bind(py).clone())
}

/// An `InputError` with `message`.
pub fn input_error(message: impl Into<String>) -> PyErr {
    let message = message.into();
    Python::attach(|py| match input_error_type(py) {
        Ok(ty) => PyErr::from_type(ty, message),
        Err(err) => err,
    })
}

/// Core errors are all about argument values: `InputError` with the core's message, which
/// names the argument, what it must be and what it was.
pub fn to_pyerr(err: CoreError) -> PyErr {
    input_error(err.to_string())
}

/// `?`-friendly conversion of core results.
pub trait IntoPy<T> {
    fn py(self) -> PyResult<T>;
}

impl<T> IntoPy<T> for Result<T, CoreError> {
    fn py(self) -> PyResult<T> {
        self.map_err(to_pyerr)
    }
}

/// Runs a core computation without the GIL, maps its error and then lets a Ctrl-C that arrived
/// meanwhile through as `KeyboardInterrupt`.
pub fn run_core<T, F>(py: Python<'_>, work: F) -> PyResult<T>
where
    T: Send,
    F: Send + FnOnce() -> Result<T, CoreError>,
{
    let out = py.detach(work).py()?;
    py.check_signals()?;
    Ok(out)
}
