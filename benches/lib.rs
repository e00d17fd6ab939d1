//! Shared inputs for the benchmarks: fixed scenes so numbers do not flap.

#![allow(clippy::panic, clippy::unwrap_used, clippy::expect_used)] // setup failures in a bench should stop it loudly

use upperpose_core::image::{FrameView, SkinPoints};
use upperpose_core::nalgebra::Vector3;
use upperpose_core::search::{FrameRequest, Mode};
use upperpose_core::{
    skeleton_from_pose, BitMask, BodyModel, BodyRaster, Camera, Joint, Part, Pose, Roi, Side,
    Skeleton,
};

/// A 640x480 scene: default body 2.2 m in front of the default camera (focal = 640 px), the
/// right arm raised and bent, the left out to the side. The arm spans about 150 px.
pub struct Scene {
    pub pose: Pose,
    pub root: Vector3<f64>,
    pub body: BodyModel,
    pub camera: Camera,
}

impl Scene {
    pub fn new() -> Self {
        let pose = Pose([
            0.1, 0.05, -0.05, 0.2, 0.6, 0.9, 1.1, 0.0, -0.1, 0.3, 0.5, 0.8, 0.0,
        ]);
        let camera = Camera::perspective(640.0, 319.5, 239.5).unwrap_or_else(|e| panic!("{e}"));
        Scene {
            pose,
            root: Vector3::new(0.0, 0.15, 2.2),
            body: BodyModel::default(),
            camera,
        }
    }

    pub fn skeleton(&self) -> Skeleton {
        skeleton_from_pose(&self.pose, &self.root, &self.body)
    }

    /// The arm's two cones in camera space.
    pub fn side(&self) -> Side {
        Side::Right
    }
}

/// The arm's region in [`Scene`]: its bounding box, padded as the search would.
pub fn arm_roi() -> Roi {
    Roi {
        x: 60,
        y: 60,
        width: 260,
        height: 260,
    }
}

impl Default for Scene {
    fn default() -> Self {
        Self::new()
    }
}

/// Ideal features of the scene: the model's own silhouette, its contours as edges (not
/// dilated), no motion, the projected head and hands as skin points, bare forearms as the
/// skin the arms should cover.
pub struct Features {
    pub sil: Vec<u64>,
    pub edge: Vec<u64>,
    pub motion: Vec<u64>,
    pub skin: SkinPoints,
    pub skin_mask: Vec<u64>,
}

/// Renders [`Features`] of a scene at 640x480.
pub fn ideal_features(s: &Scene) -> Features {
    let skel = s.skeleton();
    let raster = BodyRaster::new(&skel, &s.body, &s.camera, Roi::full(640, 480));
    let mut edge = BitMask::new(Roi::full(640, 480));
    for c in raster.contours() {
        edge.union(&c);
    }
    let mut forearms = BitMask::new(Roi::full(640, 480));
    for part in [Part::RightLowerArm, Part::LeftLowerArm] {
        forearms.fill(&raster.spans(part));
    }
    let joints = skel.joints();
    let point = |j: Joint| s.camera.project(&joints[j as usize]);
    Features {
        skin_mask: forearms.words,
        sil: raster.union().words,
        motion: vec![0; edge.words.len()],
        edge: edge.words,
        skin: SkinPoints {
            points: [
                point(Joint::Head),
                point(Joint::RightHand),
                point(Joint::LeftHand),
            ],
            merged: [None; 3],
        },
    }
}

impl Features {
    /// The features as the search sees them.
    pub fn view(&self) -> FrameView<'_> {
        FrameView::new(640, 480, &self.sil, &self.edge, &self.motion, self.skin)
            .and_then(|v| v.with_skin_mask(&self.skin_mask))
            .unwrap()
    }
}

/// One frame's fit request on the scene: a trajectory search of the parts flagged in `search`
/// (torso, right arm, left arm) from the scene's pose with the right elbow off by a little,
/// as between frames.
pub fn fit_request<'a>(s: &Scene, frame: FrameView<'a>, search: [bool; 3]) -> FrameRequest<'a> {
    let mut prediction = s.pose;
    prediction.0[6] -= 0.08;
    FrameRequest {
        frame,
        prediction,
        root: s.root,
        body: s.body,
        camera: s.camera,
        mode: Mode::Trajectory,
        window_scale: 1.0,
        angle_window_scales: [1.0; 13],
        frame_interval: 1.0 / 30.0,
        search,
        frame_index: 1,
    }
}
