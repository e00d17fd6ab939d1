//! numpy <-> core conversions, with checks that name the argument.

use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
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
