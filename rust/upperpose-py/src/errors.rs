//! Exceptions and the one mapping from core errors to Python ones.

use pyo3::create_exception;
use pyo3::exceptions::{PyException, PyValueError};
use pyo3::PyErr;
use upperpose_core::CoreError;

create_exception!(
    _upperpose,
    UpperposeError,
    PyException,
    "Base class of the errors upperpose raises for reasons other than bad arguments."
);

/// Core errors are all about argument values, so they surface as `ValueError` with the core's
/// message, which names the argument, what it must be and what it was.
pub fn to_pyerr(err: CoreError) -> PyErr {
    PyValueError::new_err(err.to_string())
}

/// `?`-friendly conversion of core results.
pub trait IntoPy<T> {
    fn py(self) -> pyo3::PyResult<T>;
}

impl<T> IntoPy<T> for Result<T, CoreError> {
    fn py(self) -> pyo3::PyResult<T> {
        self.map_err(to_pyerr)
    }
}
