//! The per-frame search: `SearchConfig`, `FrameFit` and `fit_frame_bits`.

use std::collections::HashMap;

use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use upperpose_core::image::{FrameView, SkinPoints};
use upperpose_core::nalgebra::{Vector2, Vector3};
use upperpose_core::raster::MAX_IMAGE_SIDE;
use upperpose_core::search::apso::SwarmConfig;
use upperpose_core::search::cost::{CostTerms, CostWeights};
use upperpose_core::search::{
    fit_frame, FrameFit, FrameRequest, Mode, Optimizer, SearchConfig, MAX_ITERATIONS,
    MAX_PARTICLES, MAX_THREADS, STAGE_NAMES,
};
use upperpose_core::{skeleton_from_pose, JointLimits, DOF_COUNT};

use crate::convert::{
    array_from_points, int_arg, opt_int_arg, pose_from_array, vector3_from_array,
};
use crate::errors::{self, IntoPy};
use crate::model::{PyBodyModel, PyCamera};

const TERM_NAMES: [&str; 7] = ["sil", "edge", "motion", "skin", "arm", "ratio", "cover"];

fn terms_values(t: &CostTerms) -> [f64; 7] {
    [t.sil, t.edge, t.motion, t.skin, t.arm, t.ratio, t.cover]
}

/// Settings of the search (frozen). Every argument is keyword-only and optional.
///
/// Args:
///     particles: swarm size per stage.
///     iterations: swarm iterations per stage.
///     c0: annealing factor of w = c1 = c2 = c0 * e^(1 - m/M); below 1/e.
///     annealing: anneal (APSO); False keeps the coefficients constant (plain PSO).
///     max_speed: velocity clamp as a fraction of each dimension's range.
///     weights: dict overriding some of the seven cost weights (sil, edge, motion, skin, arm,
///         ratio, cover).
///     limits: "anatomical" (default) or "thesis" (Table 3.5-1).
///     non_penetration: reject arms passing through the torso or each other.
///     threads: worker threads; None uses UPPERPOSE_NUM_THREADS, else one per 64 particles (at
///         most one per core; one at the default 24, where handing work to other threads costs
///         more than it saves).
///     seed: random seed (None: 0); the same seed gives the same fit whatever the thread count.
///     root_window: half-width (metres) of the torso stage's search over the root's X and Y;
///         0 (the default) keeps the root given.
///     initial_root_window: the same in "initial" mode.
///     row_steps: (torso, right arm, left arm): score every n-th image row; 1 is exact.
///     optimizer: "apso" (default), "pso" (no annealing), "simplex" (downhill simplex with
///         straight arms, thesis [1]) or "apsopf" (APSO in a particle filter, silhouette and
///         edge only, thesis [2]); docs/baselines.md.
///     sigma: APSOPF's Gaussian redistribution in half-widths of the search box (default 1).
///     behind_weight: weight of the prior against a hand behind the body (per arm length
///         behind the shoulder beyond `behind_margin`); 0 turns it off.
///     behind_margin: arm lengths a hand may lie behind the shoulder for free.
///     turn_weight: weight of the prior towards a torso facing the camera (per squared radian
///         of turn); 0 turns it off.
///     lean_weight: weight of the prior towards an upright torso (per squared radian of
///         `torso_x`, times the share of the torso's axis outside the image; default 40); 0
///         turns it off.
///     rotation_weight: weight of the prior towards an upper arm not rotated about its own axis
///         (per squared radian of `y_up`, less as the elbow bends; default 1); 0 turns it off.
///     mask_other_arm_edges: an arm's Edge and Motion get no credit for pixels under the other
///         arm (docs/cost.md).
///     sil_by_part_area: divide the Sil and Arm mismatch by the part's nominal area instead of
///         its region's area (docs/cost.md); with False, SPEC 5's normalisation, also pass
///         weights={"sil": 20}.
///     merged_skin: a part whose skin blob is merged with another part's pays the Skin term
///         for its joint's distance to the merged blob's box (docs/cost.md).
#[pyclass(frozen, name = "SearchConfig", module = "upperpose._upperpose")]
#[derive(Clone)]
pub struct PySearchConfig {
    pub inner: SearchConfig,
    limits_name: String,
}

#[pymethods]
impl PySearchConfig {
    #[new]
    #[pyo3(signature = (*, particles = None, iterations = None, c0 = None, annealing = None, max_speed = None,
                        weights = None, limits = "anatomical", non_penetration = true, threads = None, seed = None,
                        root_window = None, initial_root_window = None, row_steps = None, optimizer = "apso",
                        sigma = None, behind_weight = None, behind_margin = None,
                        turn_weight = None, lean_weight = None, rotation_weight = None, mask_other_arm_edges = true, sil_by_part_area = true,
                        merged_skin = true))]
    #[allow(clippy::too_many_arguments)] // one keyword argument per setting
    fn new(
        particles: Option<Bound<'_, PyAny>>,
        iterations: Option<Bound<'_, PyAny>>,
        c0: Option<f64>,
        annealing: Option<bool>,
        max_speed: Option<f64>,
        weights: Option<HashMap<String, f64>>,
        limits: &str,
        non_penetration: bool,
        threads: Option<Bound<'_, PyAny>>,
        seed: Option<Bound<'_, PyAny>>,
        root_window: Option<f64>,
        initial_root_window: Option<f64>,
        row_steps: Option<(Bound<'_, PyAny>, Bound<'_, PyAny>, Bound<'_, PyAny>)>,
        optimizer: &str,
        sigma: Option<f64>,
        behind_weight: Option<f64>,
        behind_margin: Option<f64>,
        turn_weight: Option<f64>,
        lean_weight: Option<f64>,
        rotation_weight: Option<f64>,
        mask_other_arm_edges: bool,
        sil_by_part_area: bool,
        merged_skin: bool,
    ) -> PyResult<Self> {
        let mut c = SearchConfig::default();
        let d = SwarmConfig::default();
        c.swarm = SwarmConfig {
            particles: opt_int_arg("particles", particles.as_ref(), 1, MAX_PARTICLES)?
                .unwrap_or(d.particles),
            iterations: opt_int_arg("iterations", iterations.as_ref(), 1, MAX_ITERATIONS)?
                .unwrap_or(d.iterations),
            c0: c0.unwrap_or(d.c0),
            annealing: annealing.unwrap_or(d.annealing),
            max_speed: max_speed.unwrap_or(d.max_speed),
        };
        if let Some(w) = weights {
            let mut x = c.weights;
            for (name, value) in w {
                let slot = match name.as_str() {
                    "sil" => &mut x.sil,
                    "edge" => &mut x.edge,
                    "motion" => &mut x.motion,
                    "skin" => &mut x.skin,
                    "arm" => &mut x.arm,
                    "ratio" => &mut x.ratio,
                    "cover" => &mut x.cover,
                    other => {
                        return Err(errors::input_error(format!(
                            "unknown weight {other:?}; weights are {}",
                            TERM_NAMES.join(", ")
                        )))
                    }
                };
                *slot = value;
            }
            c.weights = x;
        }
        c.limits = match limits {
            "anatomical" => JointLimits::anatomical(),
            "thesis" => JointLimits::thesis(),
            other => {
                return Err(errors::input_error(format!(
                    "limits must be 'anatomical' or 'thesis', got {other:?}"
                )))
            }
        };
        c.non_penetration = non_penetration;
        c.mask_other_arm_edges = mask_other_arm_edges;
        c.sil_by_part_area = sil_by_part_area;
        c.merged_skin = merged_skin;
        c.threads = opt_int_arg("threads", threads.as_ref(), 1, MAX_THREADS)?;
        c.seed = opt_int_arg("seed", seed.as_ref(), 0, u64::MAX)?.unwrap_or(0);
        for (v, slot) in [
            (root_window, &mut c.root_window),
            (initial_root_window, &mut c.initial_root_window),
            (behind_weight, &mut c.behind_weight),
            (behind_margin, &mut c.behind_margin),
            (turn_weight, &mut c.turn_weight),
            (lean_weight, &mut c.lean_weight),
            (rotation_weight, &mut c.rotation_weight),
        ] {
            if let Some(v) = v {
                *slot = v;
            }
        }
        if let Some((a, b, d)) = row_steps {
            // Only what is not an i32 is refused here; validate() gives the range.
            c.row_steps = [
                int_arg("row_steps[0]", &a, i32::MIN, i32::MAX)?,
                int_arg("row_steps[1]", &b, i32::MIN, i32::MAX)?,
                int_arg("row_steps[2]", &d, i32::MIN, i32::MAX)?,
            ];
        }
        c.optimizer = Optimizer::from_name(optimizer).ok_or_else(|| {
            errors::input_error(format!(
                "optimizer must be one of apso, pso, simplex, apsopf, got {optimizer:?}"
            ))
        })?;
        if let Some(v) = sigma {
            c.sigma = v;
        }
        c.validate().py()?;
        Ok(PySearchConfig {
            inner: c,
            limits_name: limits.to_string(),
        })
    }

    #[getter]
    fn particles(&self) -> usize {
        self.inner.swarm.particles
    }
    #[getter]
    fn iterations(&self) -> usize {
        self.inner.swarm.iterations
    }
    #[getter]
    fn c0(&self) -> f64 {
        self.inner.swarm.c0
    }
    #[getter]
    fn annealing(&self) -> bool {
        self.inner.swarm.annealing
    }
    #[getter]
    fn max_speed(&self) -> f64 {
        self.inner.swarm.max_speed
    }
    #[getter]
    fn limits(&self) -> &str {
        &self.limits_name
    }
    #[getter]
    fn non_penetration(&self) -> bool {
        self.inner.non_penetration
    }
    #[getter]
    fn threads(&self) -> Option<usize> {
        self.inner.threads
    }
    #[getter]
    fn seed(&self) -> u64 {
        self.inner.seed
    }
    #[getter]
    fn root_window(&self) -> f64 {
        self.inner.root_window
    }
    #[getter]
    fn initial_root_window(&self) -> f64 {
        self.inner.initial_root_window
    }
    #[getter]
    fn behind_weight(&self) -> f64 {
        self.inner.behind_weight
    }
    #[getter]
    fn behind_margin(&self) -> f64 {
        self.inner.behind_margin
    }
    #[getter]
    fn turn_weight(&self) -> f64 {
        self.inner.turn_weight
    }
    #[getter]
    fn lean_weight(&self) -> f64 {
        self.inner.lean_weight
    }
    #[getter]
    fn rotation_weight(&self) -> f64 {
        self.inner.rotation_weight
    }
    #[getter]
    fn mask_other_arm_edges(&self) -> bool {
        self.inner.mask_other_arm_edges
    }
    #[getter]
    fn sil_by_part_area(&self) -> bool {
        self.inner.sil_by_part_area
    }
    #[getter]
    fn merged_skin(&self) -> bool {
        self.inner.merged_skin
    }
    /// Every n-th image row is scored, per stage (torso, right arm, left arm); 1 is exact.
    #[getter]
    fn row_steps(&self) -> (i32, i32, i32) {
        let [a, b, c] = self.inner.row_steps;
        (a, b, c)
    }
    /// The search method: "apso", "pso", "simplex" or "apsopf".
    #[getter]
    fn optimizer(&self) -> &'static str {
        self.inner.optimizer.name()
    }
    /// APSOPF's Gaussian redistribution, in half-widths of the search box.
    #[getter]
    fn sigma(&self) -> f64 {
        self.inner.sigma
    }
    /// The seven cost weights by term name.
    #[getter]
    fn weights(&self) -> HashMap<&'static str, f64> {
        let w: CostWeights = self.inner.weights;
        TERM_NAMES
            .into_iter()
            .zip([w.sil, w.edge, w.motion, w.skin, w.arm, w.ratio, w.cover])
            .collect()
    }

    fn __repr__(&self) -> String {
        let s = &self.inner.swarm;
        format!(
            "SearchConfig(optimizer={:?}, particles={}, iterations={}, c0={}, annealing={}, limits={:?}, seed={})",
            self.inner.optimizer.name(),
            s.particles,
            s.iterations,
            s.c0,
            if s.annealing { "True" } else { "False" },
            self.limits_name,
            self.inner.seed
        )
    }
}

/// The fit of one frame (frozen).
#[pyclass(frozen, name = "FrameFit", module = "upperpose._upperpose")]
pub struct PyFrameFit {
    fit: FrameFit,
    joints_3d: Vec<Vector3<f64>>,
    joints_2d: Vec<Vector2<f64>>,
}

#[pymethods]
impl PyFrameFit {
    /// `(13,)` float64 fitted angles in radians.
    #[getter]
    fn pose<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.fit.pose.0)
    }
    /// `(3,)` float64 root position in metres (refined by the torso stage).
    #[getter]
    fn root<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, self.fit.root.as_slice())
    }
    /// `(7, 3)` float64 joints in metres, camera frame.
    #[getter]
    fn joints_3d<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        array_from_points(py, &self.joints_3d)
    }
    /// `(7, 2)` float64 joints in pixels (NaN for a joint a pinhole cannot see).
    #[getter]
    fn joints_2d<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let flat: Vec<f64> = self.joints_2d.iter().flat_map(|p| [p.x, p.y]).collect();
        Ok(PyArray1::from_vec(py, flat)
            .reshape([self.joints_2d.len(), 2])?
            .into_any())
    }
    /// Total cost: the sum of the three stages' weighted costs at the fit.
    #[getter]
    fn cost(&self) -> f64 {
        self.fit.cost
    }
    /// Weighted cost of each stage: torso, right_arm, left_arm.
    #[getter]
    fn stage_costs(&self) -> HashMap<&'static str, f64> {
        STAGE_NAMES.into_iter().zip(self.fit.stage_costs).collect()
    }
    /// Unweighted terms per stage: `{stage: {term: value}}`.
    #[getter]
    fn terms<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (stage, t) in STAGE_NAMES.iter().zip(&self.fit.terms) {
            let inner: HashMap<&str, f64> = TERM_NAMES.into_iter().zip(terms_values(t)).collect();
            d.set_item(stage, inner)?;
        }
        Ok(d)
    }
    /// Number of cost evaluations spent.
    #[getter]
    fn evaluations(&self) -> usize {
        self.fit.evaluations
    }

    fn __repr__(&self) -> String {
        format!(
            "FrameFit(cost={:.4}, evaluations={})",
            self.fit.cost, self.fit.evaluations
        )
    }
}

fn plane<'a>(
    name: &str,
    array: &'a PyReadonlyArray2<'_, u64>,
    height: usize,
    stride: usize,
) -> PyResult<&'a [u64]> {
    let shape = array.shape();
    if shape != [height, stride] {
        return Err(errors::input_error(format!(
            "{name} must have shape ({height}, {stride}), got ({}, {})",
            shape[0], shape[1]
        )));
    }
    array
        .as_slice()
        .map_err(|_| PyTypeError::new_err(format!("{name} must be a C-contiguous uint64 array")))
}

/// Fits one frame from bit-packed features (use `upperpose.fit_frame`, which takes a
/// `FrameFeatures`).
///
/// Args:
///     sil, edge, motion: `(H, ceil(W/64))` uint64 bit planes (bit i of word k = pixel 64k+i).
///     points: `(3, 2)` float64 head, right-hand, left-hand skin points; NaN rows are ignored.
///     merged_boxes: `(3, 4)` float64 per part (x0, y0, x1, y1): the box of the merged blob
///         that holds the part; NaN rows (or None) for parts that are not merged.
///     skin_mask: `(H, ceil(W/64))` uint64 bit plane of the skin the arms should cover (I_skin
///         without the head's blob) for the Cover term; None leaves the term out.
///     width: image width in pixels (the planes' height gives H).
///     prediction: `(13,)` predicted pose.
///     root: `(3,)` root position in metres.
///     body, camera: the model and camera.
///     mode: "trajectory" or "initial".
///     window_scale: multiplies the trajectory windows, > 0.
///     frame_interval: seconds since the previous frame, > 0.
///     search: stage names to search ("torso", "right_arm", "left_arm").
///     frame_index: keys the random streams.
///     config: the search settings.
///     angle_window_scales: `(13,)` multipliers of each angle's trajectory window on top of
///         `window_scale` (>= 0; 0 pins the angle at the prediction); all 1 when None.
///
/// Returns:
///     The `FrameFit`.
#[pyfunction(name = "fit_frame_bits")]
#[pyo3(signature = (sil, edge, motion, points, width, prediction, root, body, camera, mode, window_scale,
                    frame_interval, search, frame_index, config, angle_window_scales=None, merged_boxes=None,
                    skin_mask=None))]
#[allow(clippy::too_many_arguments)]
pub fn fit_frame_bits_py(
    py: Python<'_>,
    sil: PyReadonlyArray2<'_, u64>,
    edge: PyReadonlyArray2<'_, u64>,
    motion: PyReadonlyArray2<'_, u64>,
    points: PyReadonlyArray2<'_, f64>,
    width: Bound<'_, PyAny>,
    prediction: PyReadonlyArray1<'_, f64>,
    root: PyReadonlyArray1<'_, f64>,
    body: &PyBodyModel,
    camera: &PyCamera,
    mode: &str,
    window_scale: f64,
    frame_interval: f64,
    search: Vec<String>,
    frame_index: Bound<'_, PyAny>,
    config: &PySearchConfig,
    angle_window_scales: Option<PyReadonlyArray1<'_, f64>>,
    merged_boxes: Option<PyReadonlyArray2<'_, f64>>,
    skin_mask: Option<PyReadonlyArray2<'_, u64>>,
) -> PyResult<PyFrameFit> {
    let width = int_arg("width", &width, 1, MAX_IMAGE_SIDE)?;
    let frame_index = int_arg("frame_index", &frame_index, 0, u64::MAX)?;
    let mut scales = [1.0; DOF_COUNT];
    if let Some(a) = &angle_window_scales {
        let got = a.as_slice().map_err(|_| {
            PyTypeError::new_err("angle_window_scales must be a C-contiguous float64 array")
        })?;
        if got.len() != DOF_COUNT {
            return Err(errors::input_error(format!(
                "angle_window_scales must have {DOF_COUNT} values, got {}",
                got.len()
            )));
        }
        scales.copy_from_slice(got);
    }
    let height = sil.shape()[0];
    let stride = (width as usize).div_ceil(64);
    let (s, e, m) = (
        plane("sil", &sil, height, stride)?,
        plane("edge", &edge, height, stride)?,
        plane("motion", &motion, height, stride)?,
    );
    if points.shape() != [3, 2] {
        return Err(errors::input_error(format!(
            "points must have shape (3, 2), got {:?}",
            points.shape()
        )));
    }
    let pts = points
        .as_slice()
        .map_err(|_| PyTypeError::new_err("points must be a C-contiguous float64 array"))?;
    let mut skin = SkinPoints::default();
    for (k, slot) in skin.points.iter_mut().enumerate() {
        let (x, y) = (pts[2 * k], pts[2 * k + 1]);
        *slot = (x.is_finite() && y.is_finite()).then(|| Vector2::new(x, y));
    }
    if let Some(boxes) = &merged_boxes {
        if boxes.shape() != [3, 4] {
            return Err(errors::input_error(format!(
                "merged_boxes must have shape (3, 4), got {:?}",
                boxes.shape()
            )));
        }
        let b = boxes.as_slice().map_err(|_| {
            PyTypeError::new_err("merged_boxes must be a C-contiguous float64 array")
        })?;
        for (k, slot) in skin.merged.iter_mut().enumerate() {
            let v = &b[4 * k..4 * k + 4];
            *slot = (v.iter().all(|x| x.is_finite()) && v[0] <= v[2] && v[1] <= v[3])
                .then(|| [Vector2::new(v[0], v[1]), Vector2::new(v[2], v[3])]);
        }
    }
    let mode = match mode {
        "trajectory" => Mode::Trajectory,
        "initial" => Mode::Initial,
        other => {
            return Err(errors::input_error(format!(
                "mode must be 'trajectory' or 'initial', got {other:?}"
            )))
        }
    };
    let mut flags = [false; 3];
    for name in &search {
        match STAGE_NAMES.iter().position(|s| s == name) {
            Some(i) => flags[i] = true,
            None => {
                return Err(errors::input_error(format!(
                    "unknown stage {name:?} in search; stages are {}",
                    STAGE_NAMES.join(", ")
                )))
            }
        }
    }
    let height = u32::try_from(height).map_err(|_| errors::input_error("features are too tall"))?;
    let mut frame = FrameView::new(width, height, s, e, m, skin).py()?;
    if let Some(mask) = &skin_mask {
        frame = frame
            .with_skin_mask(plane("skin_mask", mask, height as usize, stride)?)
            .py()?;
    }
    let req = FrameRequest {
        frame,
        prediction: pose_from_array(&prediction)?,
        root: vector3_from_array("root", &root)?,
        body: body.inner,
        camera: camera.inner,
        mode,
        window_scale,
        angle_window_scales: scales,
        frame_interval,
        search: flags,
        frame_index,
    };
    let config = &config.inner;
    let (fit, joints_3d, joints_2d) = errors::run_core(py, || {
        let fit = fit_frame(&req, config)?;
        let joints = skeleton_from_pose(&fit.pose, &fit.root, &req.body).joints();
        let j2: Vec<Vector2<f64>> = joints
            .iter()
            .map(|j| {
                req.camera
                    .project(j)
                    .unwrap_or(Vector2::new(f64::NAN, f64::NAN))
            })
            .collect();
        Ok((fit, joints.to_vec(), j2))
    })?;
    Ok(PyFrameFit {
        fit,
        joints_3d,
        joints_2d,
    })
}
