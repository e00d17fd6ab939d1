//! Shared inputs for the benchmarks: fixed scenes so numbers do not flap.

#![allow(clippy::panic, clippy::unwrap_used, clippy::expect_used)] // setup failures in a bench should stop it loudly

use upperpose_core::nalgebra::Vector3;
use upperpose_core::{skeleton_from_pose, BodyModel, Camera, Pose, Side, Skeleton};

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

impl Default for Scene {
    fn default() -> Self {
        Self::new()
    }
}
