//! Forward kinematics, the posed solids and the joint-angle presets.

use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use upperpose_core::nalgebra::Matrix3;
use upperpose_core::search::constraints::pose_penetrates;
use upperpose_core::search::parts_reaching_camera;
use upperpose_core::solid::{solid_of_part, Solid};
use upperpose_core::{skeleton_from_pose, Dof, JointLimits, Part, Skeleton, PART_NAMES};

use crate::convert::{array_from_points, pose_from_array, vector3_from_array};
use crate::errors;
use crate::model::{PyBodyModel, PyCamera};

fn posed(
    pose: &PyReadonlyArray1<'_, f64>,
    root: &PyReadonlyArray1<'_, f64>,
    body: &PyBodyModel,
) -> PyResult<Skeleton> {
    let pose = pose_from_array(pose)?;
    let root = vector3_from_array("root", root)?;
    Ok(skeleton_from_pose(&pose, &root, &body.inner))
}

fn matrix<'py>(py: Python<'py>, m: &Matrix3<f64>) -> PyResult<Bound<'py, PyAny>> {
    let rows: Vec<f64> = (0..3)
        .flat_map(|r| (0..3).map(move |c| m[(r, c)]))
        .collect();
    Ok(PyArray1::from_vec(py, rows).reshape([3, 3])?.into_any())
}

/// The seven joints of a posed body (SPEC 9 order), metres in the camera frame.
///
/// Args:
///     pose: `(13,)` float64 joint angles in radians, in `ANGLE_NAMES` order.
///     root: `(3,)` float64 position of the root (upper-body centroid), metres.
///     body: body dimensions.
///
/// Returns:
///     `(7, 3)` float64 joint positions in `JOINT_NAMES` order.
///
/// Raises:
///     ValueError: wrong shape or non-finite values.
#[pyfunction(name = "forward_kinematics")]
pub fn forward_kinematics_py<'py>(
    py: Python<'py>,
    pose: PyReadonlyArray1<'py, f64>,
    root: PyReadonlyArray1<'py, f64>,
    body: &PyBodyModel,
) -> PyResult<Bound<'py, PyAny>> {
    let skel = posed(&pose, &root, body)?;
    array_from_points(py, &skel.joints())
}

/// The posed skeleton's frames: joints plus the orientation of the torso and of each limb.
///
/// Args:
///     pose: `(13,)` float64 joint angles in radians.
///     root: `(3,)` float64 root position in metres.
///     body: body dimensions.
///
/// Returns:
///     dict with `joints` `(7, 3)` (the anatomical joints, as `forward_kinematics`),
///     `model_points` `(7, 3)` (the points the solids hang from, same order: the head
///     ellipsoid's centre, the upper-arm cones' tops, the elbows, the forearm cones' ends),
///     `root` and `neck_base` `(3,)`, and `(3, 3)` rotation
///     matrices `torso`, `right_upper`, `right_lower`, `left_upper`, `left_lower` whose columns
///     are the frame's axes in the camera frame (each limb runs along its own +Y).
#[pyfunction(name = "skeleton")]
pub fn skeleton_py<'py>(
    py: Python<'py>,
    pose: PyReadonlyArray1<'py, f64>,
    root: PyReadonlyArray1<'py, f64>,
    body: &PyBodyModel,
) -> PyResult<Bound<'py, PyDict>> {
    let s = posed(&pose, &root, body)?;
    let d = PyDict::new(py);
    d.set_item("joints", array_from_points(py, &s.joints())?)?;
    d.set_item("model_points", array_from_points(py, &s.model_points())?)?;
    d.set_item("root", PyArray1::from_slice(py, s.root.as_slice()))?;
    d.set_item(
        "neck_base",
        PyArray1::from_slice(py, s.neck_base.as_slice()),
    )?;
    d.set_item("torso", matrix(py, &s.torso)?)?;
    d.set_item("right_upper", matrix(py, &s.right.upper)?)?;
    d.set_item("right_lower", matrix(py, &s.right.lower)?)?;
    d.set_item("left_upper", matrix(py, &s.left.upper)?)?;
    d.set_item("left_lower", matrix(py, &s.left.lower)?)?;
    Ok(d)
}

/// Whether either arm of a pose breaks the search's non-penetration rule (SPEC 5): a bone
/// inside the torso, or the two arms' cones overlapping by more than half their radii.
///
/// Args:
///     pose: `(13,)` float64 joint angles in radians.
///     root: `(3,)` float64 root position in metres.
///     body: body dimensions.
#[pyfunction(name = "penetrates")]
pub fn penetrates_py(
    pose: PyReadonlyArray1<'_, f64>,
    root: PyReadonlyArray1<'_, f64>,
    body: &PyBodyModel,
) -> PyResult<bool> {
    let pose = pose_from_array(&pose)?;
    let root = vector3_from_array("root", &root)?;
    Ok(pose_penetrates(&pose, &root, &body.inner))
}

/// The parts ("torso", "right_arm", "left_arm") with a model point or joint nearer a
/// perspective camera than `MIN_JOINT_DEPTH`: the search rejects such candidates. Empty for
/// the other cameras, whose projection does not depend on the depth.
///
/// Args:
///     pose: `(13,)` float64 joint angles in radians.
///     root: `(3,)` float64 root position in metres.
///     body: body dimensions.
///     camera: the camera.
#[pyfunction(name = "reaching_camera")]
pub fn reaching_camera_py(
    pose: PyReadonlyArray1<'_, f64>,
    root: PyReadonlyArray1<'_, f64>,
    body: &PyBodyModel,
    camera: &PyCamera,
) -> PyResult<Vec<&'static str>> {
    let skel = posed(&pose, &root, body)?;
    let near = parts_reaching_camera(&skel, &camera.inner);
    Ok(["torso", "right_arm", "left_arm"]
        .into_iter()
        .zip(near)
        .filter_map(|(part, n)| n.then_some(part))
        .collect())
}

/// The body model's solids for a pose, one dict per part in `PART_NAMES` order.
///
/// A frustum dict has `kind="frustum"`, end centres `p0`, `p1`, cross-section axes `e1`, `e2`
/// and semi-axes `radii0`, `radii1` (metres). An ellipsoid dict has `kind="ellipsoid"`,
/// `centre` and `axes` `(3, 3)` whose columns are the semi-axis vectors.
#[pyfunction(name = "solids")]
pub fn solids_py<'py>(
    py: Python<'py>,
    pose: PyReadonlyArray1<'py, f64>,
    root: PyReadonlyArray1<'py, f64>,
    body: &PyBodyModel,
) -> PyResult<Vec<Bound<'py, PyDict>>> {
    let s = posed(&pose, &root, body)?;
    Part::ALL
        .iter()
        .map(|&part| {
            let d = PyDict::new(py);
            d.set_item("part", PART_NAMES[part as usize])?;
            match solid_of_part(part, &s, &body.inner) {
                Solid::Frustum(f) => {
                    d.set_item("kind", "frustum")?;
                    d.set_item("p0", PyArray1::from_slice(py, f.p0.as_slice()))?;
                    d.set_item("p1", PyArray1::from_slice(py, f.p1.as_slice()))?;
                    d.set_item("e1", PyArray1::from_slice(py, f.e1.as_slice()))?;
                    d.set_item("e2", PyArray1::from_slice(py, f.e2.as_slice()))?;
                    d.set_item("radii0", PyArray1::from_slice(py, &f.radii0))?;
                    d.set_item("radii1", PyArray1::from_slice(py, &f.radii1))?;
                }
                Solid::Ellipsoid(e) => {
                    d.set_item("kind", "ellipsoid")?;
                    d.set_item("centre", PyArray1::from_slice(py, e.centre.as_slice()))?;
                    d.set_item("axes", matrix(py, &e.axes)?)?;
                }
            }
            Ok(d)
        })
        .collect()
}

/// The admissible ranges of the 13 angles under a named preset.
///
/// Args:
///     preset: "anatomical" (the default ranges of SPEC 2) or "thesis" (Table 3.5-1).
///
/// Returns:
///     One list per angle (`ANGLE_NAMES` order) of `(low, high)` intervals in radians; the
///     thesis' x_up has two.
#[pyfunction(name = "joint_limits")]
#[pyo3(signature = (preset = "anatomical"))]
pub fn joint_limits_py(preset: &str) -> PyResult<Vec<Vec<(f64, f64)>>> {
    let limits = match preset {
        "anatomical" => JointLimits::anatomical(),
        "thesis" => JointLimits::thesis(),
        other => {
            return Err(errors::input_error(format!(
                "preset must be 'anatomical' or 'thesis', got {other:?}"
            )))
        }
    };
    Ok(Dof::ALL
        .iter()
        .map(|&d| {
            limits
                .range(d)
                .intervals()
                .iter()
                .map(|i| (i.lo, i.hi))
                .collect()
        })
        .collect())
}
