//! `upperpose._upperpose`: the Python face of upperpose-core. Conversion and wrappers only;
//! users import `upperpose`, never this module directly.

mod convert;
mod errors;
mod kinematics;
mod model;
mod render;
mod search;

use pyo3::prelude::*;
use upperpose_core::{DOF_NAMES, JOINT_NAMES, PART_NAMES};

#[pymodule]
fn _upperpose(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("ANGLE_NAMES", DOF_NAMES.to_vec())?;
    m.add("JOINT_NAMES", JOINT_NAMES.to_vec())?;
    m.add("PART_NAMES", PART_NAMES.to_vec())?;
    m.add("MIN_JOINT_DEPTH", upperpose_core::search::MIN_JOINT_DEPTH)?;
    m.add(
        "UpperposeError",
        m.py().get_type::<errors::UpperposeError>(),
    )?;
    m.add("SearchError", m.py().get_type::<errors::SearchError>())?;
    m.add("InputError", errors::input_error_type(m.py())?)?;
    m.add_class::<model::PyBodyModel>()?;
    m.add_class::<model::PyCamera>()?;
    m.add_function(wrap_pyfunction!(kinematics::forward_kinematics_py, m)?)?;
    m.add_function(wrap_pyfunction!(kinematics::skeleton_py, m)?)?;
    m.add_function(wrap_pyfunction!(kinematics::solids_py, m)?)?;
    m.add_function(wrap_pyfunction!(kinematics::penetrates_py, m)?)?;
    m.add_function(wrap_pyfunction!(kinematics::reaching_camera_py, m)?)?;
    m.add_function(wrap_pyfunction!(kinematics::joint_limits_py, m)?)?;
    m.add_function(wrap_pyfunction!(render::render_masks_py, m)?)?;
    m.add_function(wrap_pyfunction!(render::render_labels_py, m)?)?;
    m.add_class::<search::PySearchConfig>()?;
    m.add_class::<search::PyFrameFit>()?;
    m.add_function(wrap_pyfunction!(search::fit_frame_bits_py, m)?)?;
    Ok(())
}
