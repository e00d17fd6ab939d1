//! The per-frame fit (thesis Fig. 3.4.8-2; SPEC 5): torso first (with a small refinement of
//! the root's position), then the right arm, then the left arm, each by an annealed particle
//! swarm over its own angles inside one fixed region of the image.

pub mod apso;
pub mod apsopf;
pub mod constraints;
pub mod cost;
pub mod optimizer;
pub mod rng;
pub mod simplex;
#[cfg(test)]
mod test_functions;

use crate::body::BodyModel;
use crate::camera::Camera;
use crate::error::{finite, positive, CoreError, Result};
use crate::image::{FrameView, PixelBox};
use crate::kinematics::{skeleton_from_pose, Joint, Side, Skeleton};
use crate::outline::{outline_of_solid, Outline};
use crate::parallel;
use crate::pose::{Dof, DofRange, JointLimits, Pose, DOF_COUNT};
use crate::raster::{BitMask, Roi, Scanner};
use crate::solid::{solid_of_part, Part};
use apso::SwarmConfig;
use cost::{evaluate, CostTerms, CostWeights, Scratch, SkinPair, StageMasks, StageRegion};
use nalgebra::Vector3;
pub use optimizer::Optimizer;

/// Where the swarm starts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// The anatomical ranges: the first frame and after a loss.
    Initial,
    /// Windows around the predicted pose.
    Trajectory,
}

/// The three stages, in fitting order.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(usize)]
pub enum Stage {
    Torso = 0,
    RightArm,
    LeftArm,
}

/// Stage names, in order.
pub const STAGE_NAMES: [&str; 3] = ["torso", "right_arm", "left_arm"];

impl Stage {
    pub const ALL: [Stage; 3] = [Stage::Torso, Stage::RightArm, Stage::LeftArm];

    fn dofs(self) -> &'static [Dof] {
        match self {
            Stage::Torso => &[Dof::TorsoY, Dof::TorsoX, Dof::TorsoZ],
            // y_down moves no joint and no cone: it is not searched (docs/body-model.md).
            Stage::RightArm => &[Dof::RightYUp, Dof::RightXUp, Dof::RightZUp, Dof::RightXDown],
            Stage::LeftArm => &[Dof::LeftYUp, Dof::LeftXUp, Dof::LeftZUp, Dof::LeftXDown],
        }
    }

    fn parts(self) -> &'static [Part] {
        match self {
            Stage::Torso => &[Part::Torso, Part::Neck, Part::Head],
            Stage::RightArm => &[Part::RightUpperArm, Part::RightLowerArm],
            Stage::LeftArm => &[Part::LeftUpperArm, Part::LeftLowerArm],
        }
    }

    /// The joint whose skin point this stage matches, and that point's index.
    fn skin_joint(self) -> (Joint, usize) {
        match self {
            Stage::Torso => (Joint::Head, 0),
            Stage::RightArm => (Joint::RightHand, 1),
            Stage::LeftArm => (Joint::LeftHand, 2),
        }
    }

    fn other_arm(self) -> Option<Stage> {
        match self {
            Stage::Torso => None,
            Stage::RightArm => Some(Stage::LeftArm),
            Stage::LeftArm => Some(Stage::RightArm),
        }
    }

    fn side(self) -> Option<Side> {
        match self {
            Stage::Torso => None,
            Stage::RightArm => Some(Side::Right),
            Stage::LeftArm => Some(Side::Left),
        }
    }
}

/// Settings of the search.
#[derive(Debug, Clone, PartialEq)]
pub struct SearchConfig {
    pub swarm: SwarmConfig,
    pub weights: CostWeights,
    pub limits: JointLimits,
    /// Reject poses whose arms pass through the torso or each other.
    pub non_penetration: bool,
    /// Worker threads; `None`: `UPPERPOSE_NUM_THREADS`, else every core.
    pub threads: Option<usize>,
    pub seed: u64,
    /// Half-width in metres of the torso stage's search over the root's X and Y while
    /// tracking; 0 keeps the root given. Off by default: the extra freedom lets the root
    /// absorb differences between the model's shape and the person's, so the root comes from
    /// the image alone (docs/search.md).
    pub root_window: f64,
    /// The same in [`Mode::Initial`].
    pub initial_root_window: f64,
    /// Rasterise and count every n-th image row when scoring candidates (torso, arms): the
    /// cost's sampling density against its price (docs/search.md). 1 is exact.
    pub row_steps: [i32; 3],
    /// The search method: ours (APSO) or a baseline of the thesis' comparison.
    pub optimizer: Optimizer,
    /// APSOPF's Gaussian redistribution, in half-widths of the box.
    pub sigma: f64,
    /// Weight of the prior against a hand behind the body: added to an arm's cost per arm
    /// length that the hand lies behind the shoulder (in the torso's frame) beyond
    /// `behind_margin` arm lengths. 0 turns it off.
    pub behind_weight: f64,
    /// Arm lengths a hand may lie behind the shoulder for free (an arm swinging while
    /// walking goes about 0.3 behind).
    pub behind_margin: f64,
    /// Weight of the prior towards a torso facing the camera: added to the torso stage's cost
    /// per squared radian of turn (`torso_y`). 0 turns it off.
    pub turn_weight: f64,
    /// Weight of the prior towards an upright torso (`torso_x`), per squared radian, times
    /// the share of the torso's axis the image does not show: with the hips below the frame
    /// (a person near the camera) the lean is free to stretch the model's perspective onto
    /// the person's outline. 0 turns it off.
    pub lean_weight: f64,
    /// Weight of the prior towards an upper arm not rotated about its own axis: added to an
    /// arm stage's cost per squared radian of `y_up`, times `(1 + cos x_down) / 2` (full with
    /// the elbow straight, where the rotation is invisible; half at a right angle). 0 turns
    /// it off.
    pub rotation_weight: f64,
    /// An arm's Edge and Motion terms get no credit for feature pixels under the other arm (as
    /// fitted or predicted): otherwise an arm laid over the other one collects that arm's
    /// contour for free (docs/cost.md).
    pub mask_other_arm_edges: bool,
    /// Divide the Sil (and Arm) mismatch by the stage's nominal part area rather than by its
    /// region's area (docs/cost.md). The default weights are for `true`; SPEC 5's `false`
    /// wants `weights.sil` 20.
    pub sil_by_part_area: bool,
    /// A part whose skin blob is merged with another part's (hand on face, hands together)
    /// pays the Skin term for its joint's distance to that blob's box (docs/cost.md).
    pub merged_skin: bool,
}

impl Default for SearchConfig {
    fn default() -> Self {
        SearchConfig {
            swarm: SwarmConfig::default(),
            weights: CostWeights::default(),
            limits: JointLimits::anatomical(),
            non_penetration: true,
            threads: None,
            seed: 0,
            root_window: 0.0,
            initial_root_window: 0.0,
            row_steps: [3, 2, 2],
            optimizer: Optimizer::Apso,
            sigma: 1.0,
            behind_weight: 2.0,
            behind_margin: 0.2,
            turn_weight: 2.0,
            lean_weight: 40.0,
            rotation_weight: 1.0,
            mask_other_arm_edges: true,
            sil_by_part_area: true,
            merged_skin: true,
        }
    }
}

/// Largest swarm per stage: beyond it a frame takes seconds and the particle buffers grow
/// without bound (a typo such as 10^9 particles would otherwise abort on allocation).
pub const MAX_PARTICLES: usize = 10_000;
/// Most swarm iterations per stage, for the same reason.
pub const MAX_ITERATIONS: usize = 10_000;
/// Most worker threads.
pub const MAX_THREADS: usize = 1024;
/// Farthest a skin point or merged box may lie outside the image, pixels.
pub const MAX_POINT_PX: f64 = 1e6;
/// Nearest and farthest root depth (metres) a perspective fit takes.
pub const MIN_ROOT_DEPTH: f64 = 0.1;
pub const MAX_ROOT_DEPTH: f64 = 1000.0;
/// Nearest a perspective fit puts any model point or joint, metres in front of the camera.
/// Nearer, a part fills the frame or cannot be drawn at all, and its joint projects to
/// infinity: an arm of a person filming themselves at arm's length otherwise reached through
/// the camera.
pub const MIN_JOINT_DEPTH: f64 = 0.1;

impl SearchConfig {
    /// Checks every setting's range; the one place they are checked (the Python binding
    /// only converts names to values).
    pub fn validate(&self) -> Result<()> {
        let count = |name: &'static str, value: usize, max: usize, expected: &'static str| {
            if value == 0 || value > max {
                return Err(CoreError::OutOfRange {
                    name,
                    expected,
                    value: value as f64,
                });
            }
            Ok(())
        };
        count(
            "particles",
            self.swarm.particles,
            MAX_PARTICLES,
            "within 1..=10000",
        )?;
        count(
            "iterations",
            self.swarm.iterations,
            MAX_ITERATIONS,
            "within 1..=10000",
        )?;
        if let Some(threads) = self.threads {
            count("threads", threads, MAX_THREADS, "within 1..=1024")?;
        }
        positive("c0", self.swarm.c0)?;
        if !(self.swarm.max_speed > 0.0 && self.swarm.max_speed <= 1.0) {
            return Err(CoreError::OutOfRange {
                name: "max_speed",
                expected: "in (0, 1]",
                value: self.swarm.max_speed,
            });
        }
        let w = &self.weights;
        for (name, value) in [
            ("weights[sil]", w.sil),
            ("weights[edge]", w.edge),
            ("weights[motion]", w.motion),
            ("weights[skin]", w.skin),
            ("weights[arm]", w.arm),
            ("weights[ratio]", w.ratio),
            ("weights[cover]", w.cover),
        ] {
            finite(name, value)?;
        }
        for (name, value) in [
            ("root_window", self.root_window),
            ("initial_root_window", self.initial_root_window),
            ("behind_weight", self.behind_weight),
            ("behind_margin", self.behind_margin),
            ("turn_weight", self.turn_weight),
            ("lean_weight", self.lean_weight),
            ("rotation_weight", self.rotation_weight),
        ] {
            if !(value >= 0.0 && value.is_finite()) {
                return Err(CoreError::OutOfRange {
                    name,
                    expected: ">= 0",
                    value,
                });
            }
        }
        for (name, step) in ["row_steps[0]", "row_steps[1]", "row_steps[2]"]
            .into_iter()
            .zip(self.row_steps)
        {
            if step < 1 {
                return Err(CoreError::OutOfRange {
                    name,
                    expected: ">= 1",
                    value: f64::from(step),
                });
            }
        }
        positive("sigma", self.sigma)?;
        Ok(())
    }
}

/// One frame's inputs.
#[derive(Debug, Clone, Copy)]
pub struct FrameRequest<'a> {
    pub frame: FrameView<'a>,
    /// The predicted pose: the centre of the trajectory windows and the pose of every part
    /// not searched.
    pub prediction: Pose,
    /// The root's position estimated from the image, metres.
    pub root: Vector3<f64>,
    pub body: BodyModel,
    pub camera: Camera,
    pub mode: Mode,
    /// Multiplies the trajectory windows (widen after a poor fit).
    pub window_scale: f64,
    /// Multiplies each angle's trajectory window on top of `window_scale` (`Dof` order, >= 0;
    /// 0 pins the angle at the prediction): a fast arm gets a wider window.
    pub angle_window_scales: [f64; DOF_COUNT],
    /// Seconds since the previous frame; windows scale with it (SPEC 5).
    pub frame_interval: f64,
    /// Which stages to search (motion flags); the others keep the prediction.
    pub search: [bool; 3],
    /// Keys the random streams, with the seed.
    pub frame_index: u64,
}

/// The fit of one frame.
#[derive(Debug, Clone, PartialEq)]
pub struct FrameFit {
    pub pose: Pose,
    pub root: Vector3<f64>,
    /// Each stage's terms at the fitted pose.
    pub terms: [CostTerms; 3],
    /// Each stage's weighted cost at the fitted pose.
    pub stage_costs: [f64; 3],
    /// The sum of the stage costs.
    pub cost: f64,
    pub evaluations: usize,
}

/// Pixels per metre at the root's depth.
fn pixels_per_metre(camera: &Camera, root: &Vector3<f64>) -> f64 {
    camera
        .affine_scale()
        .unwrap_or(camera.focal / root.z.max(1e-6))
}

fn outlines(
    parts: &[Part],
    skel: &Skeleton,
    body: &BodyModel,
    camera: &Camera,
) -> Option<Vec<Outline>> {
    parts
        .iter()
        .map(|&p| outline_of_solid(&solid_of_part(p, skel, body), camera))
        .collect()
}

/// A full-frame mask of some parts of the posed body.
fn mask_of(
    parts: &[Part],
    skel: &Skeleton,
    body: &BodyModel,
    camera: &Camera,
    width: u32,
    height: u32,
) -> BitMask {
    let full = Roi::full(width, height);
    let mut m = BitMask::new(full);
    for &p in parts {
        if let Some(o) = outline_of_solid(&solid_of_part(p, skel, body), camera) {
            let mut spans = crate::raster::RowSpans::default();
            Scanner::new(&o).spans_into(&full, &mut spans);
            m.fill(&spans);
        }
    }
    m
}

/// The area of a stage's parts seen from the front, arms side-on, in square metres.
fn nominal_area_m2(stage: Stage, b: &BodyModel) -> f64 {
    match stage {
        Stage::Torso => {
            2.0 * b.torso_half_width * (b.torso_top + b.torso_bottom)
                + 2.0 * b.neck_radius * b.neck_length
                + std::f64::consts::PI * b.head_radii[0] * b.head_radii[1]
        }
        Stage::RightArm | Stage::LeftArm => {
            b.upper_arm_length * (b.upper_arm_radii[0] + b.upper_arm_radii[1])
                + b.lower_arm_length * (b.lower_arm_radii[0] + b.lower_arm_radii[1])
        }
    }
}

/// The stage's region: the parts' box at the current pose, grown by what the search can reach.
fn stage_roi(stage: Stage, req: &FrameRequest, skel: &Skeleton, half: &[f64]) -> Option<Roi> {
    let ppm = pixels_per_metre(&req.camera, &skel.root);
    let b = &req.body;
    let reach_m = match (stage, req.mode) {
        (Stage::Torso, Mode::Trajectory) => {
            half.iter().take(3).sum::<f64>() * 0.6 + half.get(3).copied().unwrap_or(0.0)
        }
        (Stage::Torso, Mode::Initial) => 0.45 + half.get(3).copied().unwrap_or(0.0),
        (_, Mode::Trajectory) => {
            (half[0] + half[1] + half[2]) * (b.upper_arm_length + b.lower_arm_length)
                + half[3] * b.lower_arm_length
        }
        (_, Mode::Initial) => 0.0,
    };
    let (mut x0, mut y0, mut x1, mut y1) = match (stage.side(), req.mode) {
        (Some(side), Mode::Initial) => {
            // Everything the arm can reach: a ball around the shoulder.
            let s = req.camera.project(&skel.arm(side).shoulder)?;
            let r = (b.upper_arm_length + b.lower_arm_length + b.upper_arm_radii[0]) * ppm;
            (s.x - r, s.y - r, s.x + r, s.y + r)
        }
        _ => {
            let mut acc = (
                f64::INFINITY,
                f64::INFINITY,
                f64::NEG_INFINITY,
                f64::NEG_INFINITY,
            );
            for o in outlines(stage.parts(), skel, b, &req.camera)? {
                if let Some(bb) = o.bounds() {
                    acc = (
                        acc.0.min(bb.0),
                        acc.1.min(bb.1),
                        acc.2.max(bb.2),
                        acc.3.max(bb.3),
                    );
                }
            }
            acc
        }
    };
    let pad = reach_m * ppm + 4.0;
    x0 = (x0 - pad).floor().max(0.0);
    y0 = (y0 - pad).floor().max(0.0);
    x1 = (x1 + pad).ceil().min(f64::from(req.frame.width));
    y1 = (y1 + pad).ceil().min(f64::from(req.frame.height));
    (x1 > x0 && y1 > y0).then_some(Roi {
        x: x0 as i32,
        y: y0 as i32,
        width: (x1 - x0) as u32,
        height: (y1 - y0) as u32,
    })
}

/// The box of the stage's parts as posed, with a margin of 2 px for rounding, inside `roi`.
fn part_box(stage: Stage, req: &FrameRequest, skel: &Skeleton, roi: Roi) -> Option<Roi> {
    let (mut x0, mut y0, mut x1, mut y1) = (i32::MAX, i32::MAX, i32::MIN, i32::MIN);
    for o in outlines(stage.parts(), skel, &req.body, &req.camera)? {
        if let Some(b) = o.bounds() {
            // Saturating: a part reaching past the camera plane has bounds beyond i32, which
            // `as` clamps to i32::MIN/MAX; plain arithmetic would then overflow.
            x0 = x0.min((b.0.floor() as i32).saturating_sub(2));
            y0 = y0.min((b.1.floor() as i32).saturating_sub(2));
            x1 = x1.max((b.2.ceil() as i32).saturating_add(3));
            y1 = y1.max((b.3.ceil() as i32).saturating_add(3));
        }
    }
    let (x0, y0) = (x0.max(roi.x), y0.max(roi.y));
    let x1 = x1.min(roi.x + roi.width as i32).max(x0);
    let y1 = y1.min(roi.y + roi.height as i32).max(y0);
    Some(Roi {
        x: x0,
        y: y0,
        width: (x1 - x0) as u32,
        height: (y1 - y0) as u32,
    })
}

/// Whether some point of `body` posed with its root at `root` could lie nearer a perspective
/// camera than `MIN_JOINT_DEPTH`: no point lies farther from the root than the shoulder's
/// offset and the whole arm, or the head's offset and its largest radius.
fn may_reach_camera(camera: &Camera, root: &Vector3<f64>, body: &BodyModel) -> bool {
    let arm = body.shoulder_width / 2.0
        + body.shoulder_height
        + body.upper_arm_radii[0]
        + body.upper_arm_length
        + body.lower_arm_length;
    let head = body.shoulder_height
        + body.head_offset
        + body.head_radii.iter().fold(0.0_f64, |a, &r| a.max(r));
    camera.is_perspective() && root.z - arm.max(head) < MIN_JOINT_DEPTH
}

/// Which parts of a posed body (trunk, right arm, left arm) have a point nearer a perspective
/// camera than `MIN_JOINT_DEPTH`, the points the search checks (none for other cameras).
pub fn parts_reaching_camera(skel: &Skeleton, camera: &Camera) -> [bool; 3] {
    if !camera.is_perspective() {
        return [false; 3];
    }
    [
        near_camera(&trunk_top_points(skel)),
        near_camera(&arm_points(skel, Side::Right)),
        near_camera(&arm_points(skel, Side::Left)),
    ]
}

/// Whether any of `points` lies nearer the camera than `MIN_JOINT_DEPTH`.
fn near_camera(points: &[Vector3<f64>]) -> bool {
    points.iter().any(|p| p.z < MIN_JOINT_DEPTH)
}

/// An arm's model points and reported joints: the cone's top, the elbow, the cone's end, the
/// glenohumeral centre and the palm.
fn arm_points(skel: &Skeleton, side: Side) -> [Vector3<f64>; 5] {
    let arm = skel.arm(side);
    let joints = skel.joints();
    let (shoulder, palm) = match side {
        Side::Right => (Joint::RightShoulder, Joint::RightHand),
        Side::Left => (Joint::LeftShoulder, Joint::LeftHand),
    };
    [
        arm.shoulder,
        arm.elbow,
        arm.hand,
        joints[shoulder as usize],
        joints[palm as usize],
    ]
}

/// The trunk's points: the head ellipsoid's centre, the centre of the head, the neck's base.
fn trunk_top_points(skel: &Skeleton) -> [Vector3<f64>; 3] {
    [
        skel.head,
        skel.joints()[Joint::Head as usize],
        skel.neck_base,
    ]
}

/// Share of the torso's axis (top to bottom of its cylinder, sampled at `AXIS_SAMPLES`
/// points) that projects outside a `width` x `height` image or not at all.
pub fn unseen_share(
    skel: &Skeleton,
    body: &BodyModel,
    camera: &Camera,
    width: u32,
    height: u32,
) -> f64 {
    const AXIS_SAMPLES: usize = 16;
    let down = skel.torso.column(1).into_owned();
    let top = skel.root - down * body.torso_top;
    let length = body.torso_top + body.torso_bottom;
    let unseen = (0..AXIS_SAMPLES)
        .filter(|&k| {
            let p = top + down * (length * (k as f64 + 0.5) / AXIS_SAMPLES as f64);
            camera.project(&p).is_none_or(|q| {
                !(q.x >= 0.0 && q.y >= 0.0 && q.x < f64::from(width) && q.y < f64::from(height))
            })
        })
        .count();
    unseen as f64 / AXIS_SAMPLES as f64
}

/// Everything one stage needs to score candidates.
struct StageSetup<'a> {
    stage: Stage,
    req: &'a FrameRequest<'a>,
    config: &'a SearchConfig,
    region: StageRegion,
    base_pose: Pose,
    base_root: Vector3<f64>,
    /// The skeleton of `base_pose` at `base_root`.
    base_skel: Skeleton,
    skin_target: Option<PixelBox>,
    shoulder_px: f64,
    /// Search dimensions: the stage's angles, plus root dx, dy for the torso.
    bounds: Vec<DofRange>,
    /// Whether a candidate may come nearer the camera than `MIN_JOINT_DEPTH` at all (most
    /// people stand too far away for any check to be needed).
    may_reach_camera: bool,
    /// Whether each arm (right, left) of the base keeps `MIN_JOINT_DEPTH` from the camera.
    base_arms_clear: [bool; 2],
    /// Share of the base torso's axis outside the image (`unseen_share`); the torso stage's
    /// only, and only with a lean prior to weigh.
    unseen_trunk: f64,
}

impl StageSetup<'_> {
    fn candidate(&self, x: &[f64]) -> (Pose, Vector3<f64>) {
        let mut p = self.base_pose;
        let dofs = self.stage.dofs();
        for (k, &d) in dofs.iter().enumerate() {
            p.set(d, x[k]);
        }
        let mut r = self.base_root;
        if x.len() > dofs.len() {
            r.x += x[dofs.len()];
            r.y += x[dofs.len() + 1];
        }
        (p, r)
    }

    /// The skeleton of a candidate. Only the stage's own part moves: repose just that
    /// (docs/search.md).
    fn skeleton(&self, pose: &Pose, root: &Vector3<f64>) -> Skeleton {
        let body = &self.req.body;
        match self.stage.side() {
            Some(side) => self.base_skel.with_arm(pose, side, body),
            None => self.base_skel.with_trunk(pose, root, body),
        }
    }

    fn terms(
        &self,
        pose: &Pose,
        root: &Vector3<f64>,
        scratch: &mut EvalScratch,
    ) -> Option<CostTerms> {
        self.terms_of(&self.skeleton(pose, root), scratch)
    }

    /// The stage's terms for a candidate's skeleton; `None` when it is rejected.
    fn terms_of(&self, skel: &Skeleton, scratch: &mut EvalScratch) -> Option<CostTerms> {
        let req = self.req;
        if let (Some(side), true) = (self.stage.side(), self.config.non_penetration) {
            if constraints::arm_penetrates(skel, &req.body, side) {
                return None;
            }
        }
        scratch.pieces.clear();
        for &p in self.stage.parts() {
            let o = outline_of_solid(&solid_of_part(p, skel, &req.body), &req.camera)?;
            scratch.pieces.push(Scanner::new(&o));
        }
        let (joint, _) = self.stage.skin_joint();
        let skin = self.skin_target.and_then(|image| {
            let model = req.camera.project(&skel.model_points()[joint as usize])?;
            Some(SkinPair { model, image })
        });
        Some(evaluate(
            &self.region,
            &scratch.pieces,
            skin.as_slice(),
            self.shoulder_px,
            &mut scratch.cost,
        ))
    }

    fn cost(&self, x: &[f64], scratch: &mut EvalScratch) -> f64 {
        let (p, r) = self.candidate(x);
        let skel = self.skeleton(&p, &r);
        if self.reaches_camera(&p, &r, &skel) {
            return f64::INFINITY;
        }
        self.terms_of(&skel, scratch).map_or(f64::INFINITY, |t| {
            t.total(&self.config.weights) + self.behind(&skel) + self.rest(&p)
        })
    }

    /// Whether a candidate puts a point of the stage's part nearer the camera than
    /// `MIN_JOINT_DEPTH` (perspective only). The torso stage's candidate is checked with the
    /// arms attached to it, so that turning or leaning the trunk cannot push an arm through
    /// the camera; an arm already that near in the base is left to its own stage.
    fn reaches_camera(&self, pose: &Pose, root: &Vector3<f64>, skel: &Skeleton) -> bool {
        if !self.may_reach_camera {
            return false;
        }
        match self.stage.side() {
            Some(side) => near_camera(&arm_points(skel, side)),
            None => {
                let whole = skeleton_from_pose(pose, root, &self.req.body);
                near_camera(&trunk_top_points(&whole))
                    || [Side::Right, Side::Left]
                        .into_iter()
                        .zip(self.base_arms_clear)
                        .any(|(side, clear)| clear && near_camera(&arm_points(&whole, side)))
            }
        }
    }

    /// The priors towards rest of the angles the image hardly shows (docs/search.md): the
    /// torso's turn (it changes the outline little, and the arms follow a drifting turn) and
    /// each upper arm's rotation about its own axis (invisible while the elbow is straight,
    /// and a drifted one bends the elbow out of the plane the person bends it in).
    fn rest(&self, pose: &Pose) -> f64 {
        let c = &self.config;
        match self.stage {
            Stage::Torso => {
                c.turn_weight * pose.get(Dof::TorsoY).powi(2)
                    + c.lean_weight * self.unseen_trunk * pose.get(Dof::TorsoX).powi(2)
            }
            Stage::RightArm => {
                Self::rotation(c.rotation_weight, pose, Dof::RightYUp, Dof::RightXDown)
            }
            Stage::LeftArm => Self::rotation(c.rotation_weight, pose, Dof::LeftYUp, Dof::LeftXDown),
        }
    }

    /// The rotation prior, weakened as the elbow bends and the forearm shows the rotation:
    /// full with the elbow straight, half at a right angle.
    fn rotation(weight: f64, pose: &Pose, rotation: Dof, bend: Dof) -> f64 {
        weight * pose.get(rotation).powi(2) * 0.5 * (1.0 + pose.get(bend).cos())
    }

    /// The prior against a hand behind the body (docs/search.md): the silhouette of an arm
    /// swung forwards is nearly the mirror image of one swung backwards, and people facing a
    /// camera rarely reach behind themselves. `skel` is the candidate's: in an arm stage its
    /// torso is the base's and its arm the candidate's, as a full reposing would give.
    fn behind(&self, skel: &Skeleton) -> f64 {
        let (Some(side), w) = (self.stage.side(), self.config.behind_weight) else {
            return 0.0;
        };
        if w == 0.0 {
            return 0.0;
        }
        let b = &self.req.body;
        let arm = skel.arm(side);
        // Depth of the hand behind the shoulder in the torso's frame (+Z: away from the camera).
        let d = skel.torso.transpose() * (arm.hand - arm.shoulder);
        w * (d.z / (b.upper_arm_length + b.lower_arm_length) - self.config.behind_margin).max(0.0)
    }
}

/// Reusable buffers of one evaluating thread: no evaluation allocates.
#[derive(Debug, Default)]
struct EvalScratch {
    pieces: Vec<Scanner>,
    cost: Scratch,
}

/// Runs one stage on `pose` and `root` in place; returns the stage's terms at the result and
/// the number of cost evaluations.
fn run_stage(
    stage: Stage,
    req: &FrameRequest,
    config: &SearchConfig,
    pool: &rayon::ThreadPool,
    pose: &mut Pose,
    root: &mut Vector3<f64>,
) -> (CostTerms, usize) {
    let b = &req.body;
    let skel = skeleton_from_pose(pose, root, b);
    let scale = req.window_scale * req.frame_interval * 30.0;
    let mut half: Vec<f64> = stage
        .dofs()
        .iter()
        .map(|&d| constraints::window_half_width(d) * scale * req.angle_window_scales[d as usize])
        .collect();
    let root_half = match req.mode {
        Mode::Initial => config.initial_root_window,
        Mode::Trajectory => config.root_window * req.window_scale,
    };
    let search_root = stage == Stage::Torso && root_half > 0.0;
    if search_root {
        half.push(root_half);
    }
    let Some(roi) = stage_roi(stage, req, &skel, &half) else {
        return (CostTerms::default(), 0); // the part is out of the image: keep it as predicted
    };
    let draw = |parts: &[Part]| {
        mask_of(
            parts,
            &skel,
            b,
            &req.camera,
            req.frame.width,
            req.frame.height,
        )
    };
    // The Cover term is only counted when it is weighed and the frame has a skin mask.
    let skin_mask = req
        .frame
        .skin_mask
        .filter(|_| stage.side().is_some() && config.weights.cover != 0.0);
    // The other arm is drawn once: it is part of the base and, for the edge mask and the
    // skin it already covers, on its own.
    let other_parts = match stage.other_arm() {
        Some(other) if config.mask_other_arm_edges || skin_mask.is_some() => other.parts(),
        _ => &[],
    };
    let other = (!other_parts.is_empty()).then(|| draw(other_parts));
    let rest: Vec<Part> = Part::ALL
        .iter()
        .copied()
        .filter(|p| !stage.parts().contains(p) && !other_parts.contains(p))
        .collect();
    let mut base = draw(&rest);
    if let Some(arm) = &other {
        base.union(arm);
    }
    let claimed = other.as_ref().filter(|_| config.mask_other_arm_edges);
    // The Arm term is only counted when it is weighed.
    let torso =
        (stage.side().is_some() && config.weights.arm != 0.0).then(|| draw(Stage::Torso.parts()));
    // Skin over the torso cone (not the neck or head) that the other arm leaves uncovered.
    let front_skin = skin_mask.map(|skin| {
        let mut front = draw(&[Part::Torso]);
        for (w, s) in front.words.iter_mut().zip(skin.words) {
            *w &= s;
        }
        if let Some(arm) = &other {
            front.subtract(arm);
        }
        front
    });
    // A stage that is not searched is scored once, where it stands: count only around that.
    let reach = if req.search[stage as usize] {
        roi
    } else {
        part_box(stage, req, &skel, roi).unwrap_or(roi)
    };
    let step = config.row_steps[stage as usize];
    let mut region = StageRegion::new(
        &req.frame,
        roi,
        reach,
        step,
        StageMasks {
            base: &base,
            torso: torso.as_ref(),
            front_skin: front_skin.as_ref(),
            claimed,
        },
    );
    if config.sil_by_part_area {
        let ppm = pixels_per_metre(&req.camera, root);
        region = region.normalised_by(nominal_area_m2(stage, b) * ppm * ppm);
    }

    let mut bounds: Vec<DofRange> = stage
        .dofs()
        .iter()
        .zip(&half)
        .map(|(&d, &h)| match req.mode {
            Mode::Initial => config.limits.range(d).clone(),
            Mode::Trajectory => constraints::window(&config.limits, d, pose.get(d), h),
        })
        .collect();
    if search_root {
        let r = DofRange::new(-root_half, root_half).unwrap_or_else(|_| bounds[0].clone());
        bounds.push(r.clone());
        bounds.push(r);
    }
    let setup = StageSetup {
        stage,
        req,
        config,
        region,
        base_pose: *pose,
        base_root: *root,
        base_skel: skel,
        skin_target: {
            let (k, skin) = (stage.skin_joint().1, &req.frame.skin);
            let merged = skin.merged[k].filter(|_| config.merged_skin);
            skin.points[k].map(|p| [p, p]).or(merged)
        },
        shoulder_px: b.shoulder_width * pixels_per_metre(&req.camera, root),
        bounds,
        may_reach_camera: may_reach_camera(&req.camera, root, b),
        base_arms_clear: [Side::Right, Side::Left]
            .map(|side| !near_camera(&arm_points(&skel, side))),
        unseen_trunk: if stage == Stage::Torso && config.lean_weight > 0.0 {
            unseen_share(&skel, b, &req.camera, req.frame.width, req.frame.height)
        } else {
            0.0
        },
    };
    let mut evaluations = 0;
    if req.search[stage as usize] {
        let mut start: Vec<f64> = stage.dofs().iter().map(|&d| pose.get(d)).collect();
        if search_root {
            start.extend([0.0, 0.0]);
        }
        let mut rng = rng::Rng::for_stage(config.seed, req.frame_index, stage as u64);
        let result = optimizer::minimise(
            config,
            &setup.bounds,
            &start,
            &mut rng,
            pool,
            EvalScratch::default,
            |scratch, x| setup.cost(x, scratch),
        );
        evaluations = result.evaluations;
        if result.cost.is_finite() {
            (*pose, *root) = setup.candidate(&result.best);
        }
    }
    let terms = setup
        .terms(pose, root, &mut EvalScratch::default())
        .unwrap_or_default();
    (terms, evaluations)
}

fn check(req: &FrameRequest) -> Result<()> {
    positive("window_scale", req.window_scale)?;
    positive("frame_interval", req.frame_interval)?;
    for &s in &req.angle_window_scales {
        if !(s.is_finite() && s >= 0.0) {
            return Err(CoreError::OutOfRange {
                name: "angle_window_scales",
                expected: "finite and >= 0",
                value: s,
            });
        }
    }
    for (name, v) in [
        ("root[0]", req.root.x),
        ("root[1]", req.root.y),
        ("root[2]", req.root.z),
    ] {
        finite(name, v)?;
    }
    // A skin point farther out would make its squared distance, and the cost, infinite.
    let skin = &req.frame.skin;
    let corners = skin.merged.iter().flatten().flatten();
    for p in skin.points.iter().flatten().chain(corners) {
        for v in [p.x, p.y] {
            if !(v.abs() <= MAX_POINT_PX) {
                return Err(CoreError::OutOfRange {
                    name: "skin point",
                    expected: "within +-1e6 pixels",
                    value: v,
                });
            }
        }
    }
    // Nearer, the body reaches through the camera; farther, it is smaller than a pixel. Either
    // way no stage could be scored and the fit would report cost 0 after no evaluation.
    if req.camera.is_perspective() && !(MIN_ROOT_DEPTH..=MAX_ROOT_DEPTH).contains(&req.root.z) {
        return Err(CoreError::OutOfRange {
            name: "root[2]",
            expected: "within 0.1..=1000 metres in front of the camera",
            value: req.root.z,
        });
    }
    req.body.validate()
}

/// Fits one frame: torso, right arm, left arm.
pub fn fit_frame(req: &FrameRequest, config: &SearchConfig) -> Result<FrameFit> {
    config.validate()?;
    check(req)?;
    let threads = parallel::resolve_threads(config.threads, config.swarm.particles)?;
    let pool = parallel::pool(threads)?;
    let config = &*optimizer::effective(config);
    let mut pose = config.limits.clamp(&req.prediction);
    // y_down is not searched; keep the prediction's value even outside the limits' clamp.
    let mut root = req.root;
    let mut terms = [CostTerms::default(); 3];
    let mut evaluations = 0;
    for stage in Stage::ALL {
        let (t, n) = run_stage(stage, req, config, &pool, &mut pose, &mut root);
        terms[stage as usize] = t;
        evaluations += n;
    }
    let stage_costs = terms.map(|t| t.total(&config.weights));
    Ok(FrameFit {
        pose,
        root,
        terms,
        stage_costs,
        cost: stage_costs.iter().sum(),
        evaluations,
    })
}
