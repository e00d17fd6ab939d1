//! upperpose-core: the geometry behind upperpose, with no Python in it.
//!
//! Units and frames everywhere: angles in radians; lengths in metres in OpenCV's camera frame
//! (X to image right, Y down, Z away from the camera); image coordinates in pixels, origin
//! top-left, x right, y down, integer coordinates at pixel centres. The 13 pose angles follow
//! the order of [`pose::DOF_NAMES`]; the 7 joints that of [`kinematics::JOINT_NAMES`].
#![forbid(unsafe_code)]

pub mod body;
pub mod camera;
pub mod error;
pub mod image;
pub mod kinematics;
pub mod outline;
pub mod parallel;
pub mod pose;
pub mod raster;
pub mod render;
pub mod search;
pub mod solid;

pub use body::BodyModel;
pub use camera::{Camera, Projection};
pub use error::{CoreError, Result};
pub use kinematics::{skeleton_from_pose, Joint, Side, Skeleton, JOINT_NAMES};
pub use nalgebra;
pub use pose::{Dof, DofRange, JointLimits, Pose, DOF_COUNT, DOF_NAMES};
pub use raster::{BitMask, Roi, RowSpans, Scanner, Span};
pub use render::BodyRaster;
pub use solid::{Part, Solid, PART_COUNT, PART_NAMES};
