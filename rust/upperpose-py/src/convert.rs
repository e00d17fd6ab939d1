//! numpy <-> core conversions, with checks that name the argument.

use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2, PyUntypedArrayMethods};
use std::fmt::Display;

use pyo3::exceptions::{PyOverflowError, PyTypeError};
use pyo3::prelude::*;
use pyo3::types::PyBool;
use upperpose_core::nalgebra::Vector3;
use upperpose_core::Pose;

use crate::errors::{self, IntoPy};

/// A float64 1-D array of exactly `n` finite values.
pub fn finite_vector<'a>(
    name: &str,
    array: &'a PyReadonlyArray1<'_, f64>,
    n: usize,
) -> PyResult<&'a [f64]> {
    let values = array
        .as_slice()
        .map_err(|_| PyTypeError::new_err(format!("{name} must be a contiguous float64 array")))?;
    if values.len() != n {
        return Err(errors::input_error(format!(
            "{name} must have shape ({n},), got ({},)",
            values.len()
        )));
    }
    if let Some(bad) = values.iter().find(|v| !v.is_finite()) {
        return Err(errors::input_error(format!(
            "{name} must be finite, got {bad}"
        )));
    }
    Ok(values)
}

/// An integer argument of any size (a Python int or anything with `__index__`) within
/// `low..=high`. pyo3's own conversion says only "OverflowError: can't convert negative int to
/// unsigned"; this names the argument and the range. Booleans and non-integers are a TypeError.
pub fn int_arg<T>(name: &str, value: &Bound<'_, PyAny>, low: T, high: T) -> PyResult<T>
where
    T: Copy + Display + TryFrom<i128> + TryInto<i128>,
{
    let not_int = || {
        PyTypeError::new_err(format!(
            "{name} must be an integer, got {}",
            value
                .get_type()
                .name()
                .map_or_else(|_| "?".to_string(), |n| n.to_string())
        ))
    };
    if value.is_instance_of::<PyBool>() {
        return Err(not_int());
    }
    let got = match value.extract::<i128>() {
        Ok(v) => Some(v),
        Err(err) if err.is_instance_of::<PyOverflowError>(value.py()) => None,
        Err(_) => return Err(not_int()),
    };
    let (lo, hi) = (low.try_into().ok(), high.try_into().ok());
    got.filter(|v| lo.is_none_or(|lo| *v >= lo) && hi.is_none_or(|hi| *v <= hi))
        .and_then(|v| T::try_from(v).ok())
        .ok_or_else(|| {
            let shown =
                got.map_or_else(|| "an integer beyond 2**127".to_string(), |v| v.to_string());
            errors::input_error(format!("{name} must be within {low}..={high}, got {shown}"))
        })
}

/// A keyword argument converted to `T`, its name in the error: a wrong type stays a
/// `TypeError`; a wrong length or a number beyond `T` (pyo3's ValueError, OverflowError) is an
/// `InputError`.
pub fn named_arg<'py, T>(name: &str, value: &Bound<'py, PyAny>) -> PyResult<T>
where
    T: for<'a> FromPyObject<'a, 'py, Error = PyErr>,
{
    value.extract::<T>().map_err(|err| {
        let py = value.py();
        let message = format!("{name}: {}", err.value(py));
        if err.is_instance_of::<PyTypeError>(py) {
            PyTypeError::new_err(message)
        } else {
            errors::input_error(message)
        }
    })
}

/// `int_arg` for an optional argument.
pub fn opt_int_arg<T>(
    name: &str,
    value: Option<&Bound<'_, PyAny>>,
    low: T,
    high: T,
) -> PyResult<Option<T>>
where
    T: Copy + Display + TryFrom<i128> + TryInto<i128>,
{
    value.map(|v| int_arg(name, v, low, high)).transpose()
}

/// The 13 pose angles.
pub fn pose_from_array(array: &PyReadonlyArray1<'_, f64>) -> PyResult<Pose> {
    Pose::from_slice(finite_vector("pose", array, 13)?).py()
}

/// A 3-vector such as the root position.
pub fn vector3_from_array(name: &str, array: &PyReadonlyArray1<'_, f64>) -> PyResult<Vector3<f64>> {
    let v = finite_vector(name, array, 3)?;
    Ok(Vector3::new(v[0], v[1], v[2]))
}

/// An `(N, 3)` float64 array of finite points.
pub fn points_from_array(
    name: &str,
    array: &PyReadonlyArray2<'_, f64>,
) -> PyResult<Vec<Vector3<f64>>> {
    let shape = array.shape();
    if shape[1] != 3 {
        return Err(errors::input_error(format!(
            "{name} must have shape (N, 3), got ({}, {})",
            shape[0], shape[1]
        )));
    }
    let values = array
        .as_slice()
        .map_err(|_| PyTypeError::new_err(format!("{name} must be a contiguous float64 array")))?;
    if let Some(bad) = values.iter().find(|v| !v.is_finite()) {
        return Err(errors::input_error(format!(
            "{name} must be finite, got {bad}"
        )));
    }
    Ok(values
        .chunks_exact(3)
        .map(|c| Vector3::new(c[0], c[1], c[2]))
        .collect())
}

/// Rows of 3-vectors as an `(N, 3)` float64 array.
pub fn array_from_points<'py>(
    py: Python<'py>,
    points: &[Vector3<f64>],
) -> PyResult<Bound<'py, PyAny>> {
    let flat: Vec<f64> = points.iter().flat_map(|p| [p.x, p.y, p.z]).collect();
    Ok(PyArray1::from_vec(py, flat)
        .reshape([points.len(), 3])?
        .into_any())
}
