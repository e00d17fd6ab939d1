//! Rendering the body model into masks, for overlays, debugging and tests.

use numpy::{PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use upperpose_core::nalgebra::Vector3;
use upperpose_core::{
    skeleton_from_pose, BitMask, BodyModel, BodyRaster, Camera, Part, Pose, Roi, PART_NAMES,
};

use crate::convert::{int_arg, pose_from_array, vector3_from_array};
use crate::errors::IntoPy;
use crate::model::{PyBodyModel, PyCamera};

/// Unpacks a bit mask into one byte (0 or 1) per pixel, row-major.
fn bytes_from_mask(mask: &BitMask) -> Vec<u8> {
    let (w, h) = (mask.roi.width as usize, mask.roi.height as usize);
    let mut out = vec![0u8; w * h];
    for (r, row_out) in out.chunks_exact_mut(w).enumerate().take(h) {
        let row = mask.row(r);
        for (c, px) in row_out.iter_mut().enumerate() {
            *px = (row[c / 64] >> (c % 64) & 1) as u8;
        }
    }
    out
}

/// The posed body and the region to draw, from the render functions' Python arguments.
struct RasterArgs {
    pose: Pose,
    root: Vector3<f64>,
    body: BodyModel,
    camera: Camera,
    roi: Roi,
}

impl RasterArgs {
    fn raster(&self) -> BodyRaster {
        let skel = skeleton_from_pose(&self.pose, &self.root, &self.body);
        BodyRaster::new(&skel, &self.body, &self.camera, self.roi)
    }
}

/// Checks the arguments: a finite pose and root, a region inside the image.
#[allow(clippy::too_many_arguments)]
fn raster_args<'py>(
    pose: PyReadonlyArray1<'py, f64>,
    root: PyReadonlyArray1<'py, f64>,
    body: &PyBodyModel,
    camera: &PyCamera,
    width: Bound<'py, PyAny>,
    height: Bound<'py, PyAny>,
    roi: Option<[Bound<'py, PyAny>; 4]>,
) -> PyResult<RasterArgs> {
    // The core names a side beyond its limit; here only what cannot be a u32 is refused.
    let width = int_arg("width", &width, 0, u32::MAX)?;
    let height = int_arg("height", &height, 0, u32::MAX)?;
    let roi = match roi {
        Some([x, y, w, h]) => Some((
            int_arg("roi[0]", &x, i64::MIN, i64::MAX)?,
            int_arg("roi[1]", &y, i64::MIN, i64::MAX)?,
            int_arg("roi[2]", &w, i64::MIN, i64::MAX)?,
            int_arg("roi[3]", &h, i64::MIN, i64::MAX)?,
        )),
        None => None,
    };
    let pose = pose_from_array(&pose)?;
    let root = vector3_from_array("root", &root)?;
    let (x, y, w, h) = roi.unwrap_or((0, 0, i64::from(width), i64::from(height)));
    let roi = Roi::inside(x, y, w, h, width, height).py()?;
    Ok(RasterArgs {
        pose,
        root,
        body: body.inner,
        camera: camera.inner,
        roi,
    })
}

/// Rasterises the body model for a pose into uint8 masks inside a region of the image.
///
/// A pixel is set when its centre lies inside the exact projected outline of a part
/// (convex hull of each cone's two end ellipses; ellipses for the head).
///
/// Args:
///     pose: `(13,)` float64 joint angles in radians.
///     root: `(3,)` float64 root position in metres, camera frame.
///     body: body dimensions.
///     camera: the camera.
///     width: image width in pixels.
///     height: image height in pixels.
///     roi: `(x, y, w, h)` region to draw, inside the image; the whole image when None.
///
/// Returns:
///     dict of `(h, w)` uint8 arrays over the region: `silhouette` (0/1, all parts),
///     `labels` (0 background, k + 1 where part k of `PART_NAMES` is the nearest visible),
///     `contour` (0/1, the visible one-pixel outline of every part), and for each part name
///     its whole silhouette (`name`) and its visible contour (`name + "_contour"`).
///
/// Raises:
///     ValueError: wrong shapes, non-finite values, or a region outside the image.
#[pyfunction(name = "render_masks")]
#[pyo3(signature = (pose, root, body, camera, width, height, roi = None))]
#[allow(clippy::too_many_arguments)]
pub fn render_masks_py<'py>(
    py: Python<'py>,
    pose: PyReadonlyArray1<'py, f64>,
    root: PyReadonlyArray1<'py, f64>,
    body: &PyBodyModel,
    camera: &PyCamera,
    width: Bound<'py, PyAny>,
    height: Bound<'py, PyAny>,
    roi: Option<[Bound<'py, PyAny>; 4]>,
) -> PyResult<Bound<'py, PyDict>> {
    let raster_args = raster_args(pose, root, body, camera, width, height, roi)?;
    let roi = raster_args.roi;
    let rendered = py.detach(move || {
        let raster = raster_args.raster();
        let contours = raster.contours();
        let mut all_contours = BitMask::new(roi);
        for con in &contours {
            all_contours.union(con);
        }
        let parts: Vec<(Vec<u8>, Vec<u8>)> = Part::ALL
            .iter()
            .zip(&contours)
            .map(|(&p, c)| (bytes_from_mask(&raster.silhouette(p)), bytes_from_mask(c)))
            .collect();
        (
            bytes_from_mask(&raster.union()),
            raster.labels(),
            bytes_from_mask(&all_contours),
            parts,
        )
    });
    let (union, labels, contour, parts) = rendered;
    let shape = [roi.height as usize, roi.width as usize];
    let d = PyDict::new(py);
    let put = |key: &str, data: Vec<u8>| -> PyResult<()> {
        d.set_item(key, PyArray1::from_vec(py, data).reshape(shape)?)
    };
    put("silhouette", union)?;
    put("labels", labels)?;
    put("contour", contour)?;
    for (name, (sil, con)) in PART_NAMES.iter().zip(parts) {
        put(name, sil)?;
        put(&format!("{name}_contour"), con)?;
    }
    Ok(d)
}

/// The body model's part labels for a pose: `render_masks(...)["labels"]` alone, several times
/// cheaper (drawn straight from the parts' spans, nearest part last).
///
/// Args: as `render_masks`.
///
/// Returns:
///     `(h, w)` uint8 over the region: 0 background, k + 1 where part k of `PART_NAMES` is the
///     nearest visible.
///
/// Raises:
///     ValueError: wrong shapes, non-finite values, or a region outside the image.
#[pyfunction(name = "render_labels")]
#[pyo3(signature = (pose, root, body, camera, width, height, roi = None))]
#[allow(clippy::too_many_arguments)]
pub fn render_labels_py<'py>(
    py: Python<'py>,
    pose: PyReadonlyArray1<'py, f64>,
    root: PyReadonlyArray1<'py, f64>,
    body: &PyBodyModel,
    camera: &PyCamera,
    width: Bound<'py, PyAny>,
    height: Bound<'py, PyAny>,
    roi: Option<[Bound<'py, PyAny>; 4]>,
) -> PyResult<Bound<'py, PyArray2<u8>>> {
    let raster_args = raster_args(pose, root, body, camera, width, height, roi)?;
    let shape = [
        raster_args.roi.height as usize,
        raster_args.roi.width as usize,
    ];
    let labels = py.detach(move || raster_args.raster().labels());
    PyArray1::from_vec(py, labels).reshape(shape)
}
