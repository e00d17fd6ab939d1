//! Shared inputs for the benchmarks: fixed, seeded scenes so numbers do not flap.

use upperpose_core::{BodyModel, Camera, Pose};

/// A 640x480 scene: default body 2.5 m in front of the default camera, arms raised and bent.
pub fn scene() -> (Pose, nalgebra_free::Vec3, BodyModel, Camera) {
    let mut pose = Pose::default();
    pose.0 = [0.1, 0.05, -0.05, 0.2, 0.6, 0.9, 1.1, 0.0, -0.1, 0.3, 0.5, 0.8, 0.0];
    let camera = Camera::default_for_image(640, 480).unwrap_or_else(|_| unreachable!());
    (pose, [0.0, 0.1, 2.5], BodyModel::default(), camera)
}

/// A plain 3-vector so the benches need not depend on nalgebra directly.
pub mod nalgebra_free {
    pub type Vec3 = [f64; 3];
}
