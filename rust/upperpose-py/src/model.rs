//! `BodyModel` and `Camera`: frozen Python classes over the core types.

use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray2};
use pyo3::prelude::*;
use upperpose_core::raster::MAX_IMAGE_SIDE;
use upperpose_core::{BodyModel, Camera, Projection};

use crate::convert::{int_arg, named_arg, points_from_array};
use crate::errors::IntoPy;

/// Body dimensions in metres (adult averages by default; see docs/body-model.md).
///
/// Every argument is keyword-only and optional; omitted ones take the adult default.
#[pyclass(frozen, name = "BodyModel", module = "upperpose._upperpose")]
#[derive(Clone)]
pub struct PyBodyModel {
    pub inner: BodyModel,
}

macro_rules! body_fields {
    ($($field:ident: $ty:ty),* $(,)?) => {
        #[pymethods]
        impl PyBodyModel {
            #[new]
            #[pyo3(signature = (*, $($field = None),*))]
            #[allow(clippy::too_many_arguments)] // one keyword argument per dimension
            fn new($($field: Option<Bound<'_, PyAny>>),*) -> PyResult<Self> {
                let mut inner = BodyModel::default();
                $(if let Some(v) = $field { inner.$field = named_arg::<$ty>(stringify!($field), &v)?; })*
                inner.validate().py()?;
                Ok(PyBodyModel { inner })
            }

            $(
                #[getter]
                fn $field(&self) -> $ty {
                    self.inner.$field
                }
            )*

            /// The dimensions as a dict, suitable for `BodyModel(**d)`.
            fn as_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, pyo3::types::PyDict>> {
                let d = pyo3::types::PyDict::new(py);
                $(d.set_item(stringify!($field), self.inner.$field)?;)*
                Ok(d)
            }

            fn __repr__(&self) -> String {
                let parts: Vec<String> = vec![$(format!("{}={:?}", stringify!($field), self.inner.$field)),*];
                format!("BodyModel({})", parts.join(", "))
            }

            fn __eq__(&self, other: &Self) -> bool {
                self.inner == other.inner
            }
        }
    };
}

body_fields!(
    shoulder_width: f64,
    shoulder_height: f64,
    head_offset: f64,
    head_radii: [f64; 3],
    neck_length: f64,
    neck_radius: f64,
    torso_top: f64,
    torso_bottom: f64,
    torso_half_width: f64,
    torso_half_depth: f64,
    upper_arm_length: f64,
    upper_arm_radii: [f64; 2],
    lower_arm_length: f64,
    lower_arm_radii: [f64; 2],
);

/// A camera at the origin looking along +Z (OpenCV's frame), projecting to pixels.
///
/// Build one with `Camera.perspective`, `Camera.orthographic`, `Camera.weak_perspective` or
/// `Camera.for_image`.
#[pyclass(frozen, name = "Camera", module = "upperpose._upperpose")]
#[derive(Clone)]
pub struct PyCamera {
    pub inner: Camera,
}

#[pymethods]
impl PyCamera {
    /// A pinhole camera: `u = focal * X / Z + cx`, `v = focal * Y / Z + cy`.
    ///
    /// Args:
    ///     focal: focal length in pixels, > 0.
    ///     cx: principal point x in pixels.
    ///     cy: principal point y in pixels.
    #[staticmethod]
    fn perspective(focal: f64, cx: f64, cy: f64) -> PyResult<Self> {
        Ok(PyCamera {
            inner: Camera::perspective(focal, cx, cy).py()?,
        })
    }

    /// A parallel projection: `u = scale * X + cx`, `v = scale * Y + cy`.
    ///
    /// Args:
    ///     scale: pixels per metre, > 0.
    ///     cx: image x of the camera axis in pixels.
    ///     cy: image y of the camera axis in pixels.
    #[staticmethod]
    fn orthographic(scale: f64, cx: f64, cy: f64) -> PyResult<Self> {
        Ok(PyCamera {
            inner: Camera::orthographic(scale, cx, cy).py()?,
        })
    }

    /// Weak perspective (scaled orthographic): `u = focal * X / reference_depth + cx`.
    ///
    /// Args:
    ///     focal: focal length in pixels, > 0.
    ///     cx: principal point x in pixels.
    ///     cy: principal point y in pixels.
    ///     reference_depth: the depth in metres at which it equals the pinhole, > 0.
    #[staticmethod]
    fn weak_perspective(focal: f64, cx: f64, cy: f64, reference_depth: f64) -> PyResult<Self> {
        Ok(PyCamera {
            inner: Camera::weak_perspective(focal, cx, cy, reference_depth).py()?,
        })
    }

    /// The default pinhole camera for an image (SPEC 3): principal point at the image centre
    /// and, unless given, focal length equal to the image width.
    ///
    /// Args:
    ///     width: image width in pixels, 1..=8192.
    ///     height: image height in pixels, 1..=8192.
    ///     focal: focal length in pixels; defaults to `width`.
    #[staticmethod]
    #[pyo3(signature = (width, height, focal = None))]
    fn for_image(
        width: &Bound<'_, PyAny>,
        height: &Bound<'_, PyAny>,
        focal: Option<f64>,
    ) -> PyResult<Self> {
        let width = int_arg("width", width, 1, MAX_IMAGE_SIDE)?;
        let height = int_arg("height", height, 1, MAX_IMAGE_SIDE)?;
        let base = Camera::default_for_image(width, height).py()?;
        let inner = match focal {
            Some(f) => Camera::perspective(f, base.cx, base.cy).py()?,
            None => base,
        };
        Ok(PyCamera { inner })
    }

    /// "perspective", "orthographic" or "weak_perspective".
    #[getter]
    fn kind(&self) -> &'static str {
        match self.inner.projection {
            Projection::Perspective => "perspective",
            Projection::Orthographic => "orthographic",
            Projection::WeakPerspective { .. } => "weak_perspective",
        }
    }

    /// Focal length in pixels (pixels per metre for orthographic).
    #[getter]
    fn focal(&self) -> f64 {
        self.inner.focal
    }

    #[getter]
    fn cx(&self) -> f64 {
        self.inner.cx
    }

    #[getter]
    fn cy(&self) -> f64 {
        self.inner.cy
    }

    /// Depth in metres of weak perspective's reference plane; None for other kinds.
    #[getter]
    fn reference_depth(&self) -> Option<f64> {
        match self.inner.projection {
            Projection::WeakPerspective { reference_depth } => Some(reference_depth),
            _ => None,
        }
    }

    /// Projects 3D points (metres, camera frame) to pixels.
    ///
    /// Args:
    ///     points: `(N, 3)` float64.
    ///
    /// Returns:
    ///     `(N, 2)` float64 pixel coordinates; NaN rows for points a pinhole cannot see
    ///     (depth <= 0).
    ///
    /// Raises:
    ///     ValueError: wrong shape or non-finite values.
    fn project<'py>(
        &self,
        py: Python<'py>,
        points: PyReadonlyArray2<'py, f64>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let pts = points_from_array("points", &points)?;
        let flat: Vec<f64> = pts
            .iter()
            .flat_map(|p| match self.inner.project(p) {
                Some(uv) => [uv.x, uv.y],
                None => [f64::NAN, f64::NAN],
            })
            .collect();
        Ok(PyArray1::from_vec(py, flat)
            .reshape([pts.len(), 2])?
            .into_any())
    }

    fn __repr__(&self) -> String {
        let c = &self.inner;
        match c.projection {
            Projection::Perspective => format!(
                "Camera.perspective(focal={}, cx={}, cy={})",
                c.focal, c.cx, c.cy
            ),
            Projection::Orthographic => format!(
                "Camera.orthographic(scale={}, cx={}, cy={})",
                c.focal, c.cx, c.cy
            ),
            Projection::WeakPerspective { reference_depth } => format!(
                "Camera.weak_perspective(focal={}, cx={}, cy={}, reference_depth={})",
                c.focal, c.cx, c.cy, reference_depth
            ),
        }
    }

    fn __eq__(&self, other: &Self) -> bool {
        self.inner == other.inner
    }
}
