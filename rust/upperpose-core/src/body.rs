//! Body dimensions in metres: adult averages by default, each settable so that start-up can
//! fit the person in front of the camera.

use crate::error::{positive, Result};

/// Dimensions of the upper-body model. Distances in metres, measured in the body frame
/// (X to the subject's left, Y down, Z away from the camera; origin at the root, the
/// centroid of the upper body).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyModel {
    /// Distance between the two shoulder joint centres.
    pub shoulder_width: f64,
    /// Height of the shoulder joints above the root.
    pub shoulder_height: f64,
    /// Height of the head centre above the midpoint of the shoulders.
    pub head_offset: f64,
    /// Semi-axes of the head ellipsoid: half width (X), half height (Y), half depth (Z).
    pub head_radii: [f64; 3],
    /// Length and radius of the neck cylinder, which rises from the midpoint of the shoulders.
    pub neck_length: f64,
    pub neck_radius: f64,
    /// Torso elliptic cylinder: top above the root, bottom below it, half width, half depth.
    /// The bottom reaches the hips: in a camera's view the body goes on below the chest, often
    /// to the frame's edge, and a shorter torso leaves that silhouette unexplained.
    pub torso_top: f64,
    pub torso_bottom: f64,
    pub torso_half_width: f64,
    pub torso_half_depth: f64,
    /// Shoulder-to-elbow length and the upper-arm cone radii at shoulder and elbow.
    pub upper_arm_length: f64,
    pub upper_arm_radii: [f64; 2],
    /// Elbow-to-palm-centre length and the lower-arm cone radii at elbow and hand.
    pub lower_arm_length: f64,
    pub lower_arm_radii: [f64; 2],
}

impl Default for BodyModel {
    /// Adult averages (anthropometric tables; rounded to the centimetre).
    fn default() -> Self {
        BodyModel {
            shoulder_width: 0.36,
            shoulder_height: 0.20,
            head_offset: 0.24,
            head_radii: [0.078, 0.11, 0.095],
            neck_length: 0.13,
            neck_radius: 0.055,
            torso_top: 0.23,
            torso_bottom: 0.5,
            torso_half_width: 0.16,
            torso_half_depth: 0.11,
            upper_arm_length: 0.29,
            upper_arm_radii: [0.05, 0.04],
            lower_arm_length: 0.34,
            lower_arm_radii: [0.037, 0.032],
        }
    }
}

impl BodyModel {
    /// Checks that every dimension is finite and positive, naming the first that is not.
    pub fn validate(&self) -> Result<()> {
        let b = self;
        let named = [
            ("shoulder_width", b.shoulder_width),
            ("shoulder_height", b.shoulder_height),
            ("head_offset", b.head_offset),
            ("head_radii[0]", b.head_radii[0]),
            ("head_radii[1]", b.head_radii[1]),
            ("head_radii[2]", b.head_radii[2]),
            ("neck_length", b.neck_length),
            ("neck_radius", b.neck_radius),
            ("torso_top", b.torso_top),
            ("torso_bottom", b.torso_bottom),
            ("torso_half_width", b.torso_half_width),
            ("torso_half_depth", b.torso_half_depth),
            ("upper_arm_length", b.upper_arm_length),
            ("upper_arm_radii[0]", b.upper_arm_radii[0]),
            ("upper_arm_radii[1]", b.upper_arm_radii[1]),
            ("lower_arm_length", b.lower_arm_length),
            ("lower_arm_radii[0]", b.lower_arm_radii[0]),
            ("lower_arm_radii[1]", b.lower_arm_radii[1]),
        ];
        for (name, value) in named {
            positive(name, value)?;
        }
        Ok(())
    }
}
