//! Forward kinematics (thesis Fig. 2.2.3-5): pose and root position to 3D joints and solids.
//!
//! Frames follow SPEC 2: OpenCV's camera frame (X right in the image, Y down, Z away from the
//! camera, metres). The body frame sits at the root with the camera's axes when the torso
//! angles are zero. Every rotation is about the parent's axes, composed `Rz * Ry * Rx`.
//! Signs are chosen so that a positive angle is the named anatomical motion; the left arm
//! mirrors the right through the body's sagittal plane (X -> -X), which flips the sign of its
//! rotations about Y and Z. See docs/body-model.md.

use crate::body::BodyModel;
use crate::pose::{Dof, Pose};
use nalgebra::{Matrix3, Rotation3, Vector3};

/// The seven joints of SPEC 9, in output order.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(usize)]
pub enum Joint {
    Head = 0,
    RightShoulder,
    LeftShoulder,
    RightElbow,
    LeftElbow,
    RightHand,
    LeftHand,
}

/// Joint names in output order.
pub const JOINT_NAMES: [&str; 7] = [
    "head",
    "right_shoulder",
    "left_shoulder",
    "right_elbow",
    "left_elbow",
    "right_hand",
    "left_hand",
];

/// Which arm.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Side {
    Right,
    Left,
}

impl Side {
    /// +1 for the right arm, -1 for the left: the mirror factor on the body's X axis.
    fn mirror(self) -> f64 {
        match self {
            Side::Right => 1.0,
            Side::Left => -1.0,
        }
    }

    /// The arm's five angles: y_up, x_up, z_up, x_down, y_down.
    fn dofs(self) -> [Dof; 5] {
        match self {
            Side::Right => [
                Dof::RightYUp,
                Dof::RightXUp,
                Dof::RightZUp,
                Dof::RightXDown,
                Dof::RightYDown,
            ],
            Side::Left => [
                Dof::LeftYUp,
                Dof::LeftXUp,
                Dof::LeftZUp,
                Dof::LeftXDown,
                Dof::LeftYDown,
            ],
        }
    }
}

/// Euler composition `Rz(z) * Ry(y) * Rx(x)` of Fig. 2.2.3-5.
pub fn euler_zyx(z: f64, y: f64, x: f64) -> Matrix3<f64> {
    let rz = Rotation3::from_axis_angle(&Vector3::z_axis(), z);
    let ry = Rotation3::from_axis_angle(&Vector3::y_axis(), y);
    let rx = Rotation3::from_axis_angle(&Vector3::x_axis(), x);
    (rz * ry * rx).into_inner()
}

/// Orientation of the torso in the camera frame.
pub fn torso_rotation(pose: &Pose) -> Matrix3<f64> {
    euler_zyx(
        pose.get(Dof::TorsoZ),
        pose.get(Dof::TorsoY),
        pose.get(Dof::TorsoX),
    )
}

/// Orientation of the upper arm relative to the torso. At zero the arm hangs along +Y.
/// Right arm: +z_up swings it out to the subject's right (-X), +x_up forwards to the camera
/// (-Z), +y_up turns it inwards (internal rotation). The left arm mirrors these.
pub fn shoulder_rotation(pose: &Pose, side: Side) -> Matrix3<f64> {
    let [y_up, x_up, z_up, _, _] = side.dofs().map(|d| pose.get(d));
    let m = side.mirror();
    euler_zyx(m * z_up, -m * y_up, -x_up)
}

/// Orientation of the forearm relative to the upper arm: +x_down bends the elbow, bringing the
/// hand forwards; y_down twists the forearm about its own axis, so it never moves a joint.
/// The twist is applied first (innermost) for exactly that reason; see docs/body-model.md.
pub fn elbow_rotation(pose: &Pose, side: Side) -> Matrix3<f64> {
    let [_, _, _, x_down, y_down] = side.dofs().map(|d| pose.get(d));
    euler_zyx(0.0, 0.0, -x_down) * euler_zyx(0.0, -side.mirror() * y_down, 0.0)
}

/// One arm in the camera frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArmFrames {
    pub shoulder: Vector3<f64>,
    pub elbow: Vector3<f64>,
    pub hand: Vector3<f64>,
    /// Orientation of the upper arm (its local +Y runs shoulder to elbow).
    pub upper: Matrix3<f64>,
    /// Orientation of the forearm (its local +Y runs elbow to hand).
    pub lower: Matrix3<f64>,
}

/// Where the reported (anatomical) joints sit relative to the points the model's solids hang
/// from, metres; see docs/body-model.md ("Joints") for the figures and their sources.
///
/// The solids are fitted to the image's outline and skin; a body's joint centres lie inside
/// that outline, not on the solids' ends: the glenohumeral centre lies inside the shoulder,
/// under the deltoid and the torso's top edge; the centre of the head lies above the centre of
/// the face (which the head ellipsoid is centred on, as the face is what the image locates);
/// the centre of the palm lies short of the middle of the hand, where the forearm cone ends
/// (the hand's skin blob is measured at its middle).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Anatomy {
    /// Centre of the head above the head ellipsoid's centre, along the torso's -Y.
    pub head_rise: f64,
    /// Glenohumeral centre inwards of the upper-arm cone's top (towards the mid-line).
    pub shoulder_in: f64,
    /// Glenohumeral centre above the upper-arm cone's top, along the torso's -Y.
    pub shoulder_up: f64,
    /// Centre of the palm short of the forearm cone's end, along the forearm.
    pub palm_back: f64,
}

/// Head centre above the head ellipsoid's centre, as a share of the ellipsoid's half height.
pub const HEAD_RISE_SHARE: f64 = 0.25;
/// Glenohumeral centre inwards of the upper-arm cone's top, as a share of its radius there.
pub const SHOULDER_IN_SHARE: f64 = 0.7;
/// Glenohumeral centre above the upper-arm cone's top, as a share of its radius there.
pub const SHOULDER_UP_SHARE: f64 = 0.6;
/// Palm centre short of the forearm cone's end, as a share of the lower arm's length.
pub const PALM_BACK_SHARE: f64 = 0.14;

impl Anatomy {
    /// The offsets for a body: each scales with the dimension it is a share of.
    pub fn of(body: &BodyModel) -> Anatomy {
        Anatomy {
            head_rise: HEAD_RISE_SHARE * body.head_radii[1],
            shoulder_in: SHOULDER_IN_SHARE * body.upper_arm_radii[0],
            shoulder_up: SHOULDER_UP_SHARE * body.upper_arm_radii[0],
            palm_back: PALM_BACK_SHARE * body.lower_arm_length,
        }
    }
}

/// The posed skeleton in the camera frame.
///
/// Its fields are the points the solids hang from (`model_points`); `joints` are the
/// anatomical joint centres of SPEC 9 that the tracker reports.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Skeleton {
    pub root: Vector3<f64>,
    pub torso: Matrix3<f64>,
    /// Centre of the head ellipsoid (the centre of the face).
    pub head: Vector3<f64>,
    /// Midpoint of the shoulders, where the neck starts.
    pub neck_base: Vector3<f64>,
    pub right: ArmFrames,
    pub left: ArmFrames,
    pub anatomy: Anatomy,
}

impl Skeleton {
    /// The seven anatomical joints of SPEC 9 in output order, metres in the camera frame:
    /// centre of the head, glenohumeral centres, elbow centres, centres of the palms.
    pub fn joints(&self) -> [Vector3<f64>; 7] {
        let a = &self.anatomy;
        let up = self.torso.column(1).into_owned();
        let inwards = self.torso.column(0).into_owned();
        // The right shoulder is at -X of the body frame: inwards is +X for it, -X for the left.
        let shoulder = |arm: &ArmFrames, side: Side| {
            arm.shoulder + inwards * (side.mirror() * a.shoulder_in) - up * a.shoulder_up
        };
        let palm = |arm: &ArmFrames| arm.hand - arm.lower.column(1).into_owned() * a.palm_back;
        [
            self.head - up * a.head_rise,
            shoulder(&self.right, Side::Right),
            shoulder(&self.left, Side::Left),
            self.right.elbow,
            self.left.elbow,
            palm(&self.right),
            palm(&self.left),
        ]
    }

    /// The points the solids hang from, in `joints` order: the head ellipsoid's centre (the
    /// face), the upper-arm cones' tops, the elbows, the forearm cones' ends (the middle of the
    /// hand). The image's head and hand points are measured against these.
    pub fn model_points(&self) -> [Vector3<f64>; 7] {
        [
            self.head,
            self.right.shoulder,
            self.left.shoulder,
            self.right.elbow,
            self.left.elbow,
            self.right.hand,
            self.left.hand,
        ]
    }

    /// One arm.
    pub fn arm(&self, side: Side) -> &ArmFrames {
        match side {
            Side::Right => &self.right,
            Side::Left => &self.left,
        }
    }
}

/// One arm in the camera frame, hanging from a torso with orientation `torso` at `root`.
fn arm_frames(
    pose: &Pose,
    side: Side,
    root: &Vector3<f64>,
    torso: &Matrix3<f64>,
    body: &BodyModel,
) -> ArmFrames {
    let shoulder_local = Vector3::new(
        -side.mirror() * body.shoulder_width / 2.0,
        -body.shoulder_height,
        0.0,
    );
    let upper = torso * shoulder_rotation(pose, side);
    let lower = upper * elbow_rotation(pose, side);
    let shoulder = root + torso * shoulder_local;
    let elbow = shoulder + upper * Vector3::new(0.0, body.upper_arm_length, 0.0);
    let hand = elbow + lower * Vector3::new(0.0, body.lower_arm_length, 0.0);
    ArmFrames {
        shoulder,
        elbow,
        hand,
        upper,
        lower,
    }
}

impl Skeleton {
    /// This skeleton with the arm on `side` posed by `pose`'s angles and everything else kept:
    /// an arm stage's candidates differ from their base only there.
    pub fn with_arm(&self, pose: &Pose, side: Side, body: &BodyModel) -> Skeleton {
        let mut s = *self;
        let arm = arm_frames(pose, side, &self.root, &self.torso, body);
        match side {
            Side::Right => s.right = arm,
            Side::Left => s.left = arm,
        }
        s
    }

    /// This skeleton with the trunk (root, torso, neck, head) posed by `pose` at `root` and the
    /// arms kept as they were, so no longer attached: only for the trunk's own parts, which the
    /// torso stage scores without the arms.
    pub fn with_trunk(&self, pose: &Pose, root: &Vector3<f64>, body: &BodyModel) -> Skeleton {
        let torso = torso_rotation(pose);
        let (head, neck_base) = trunk_points(root, &torso, body);
        Skeleton {
            root: *root,
            torso,
            head,
            neck_base,
            ..*self
        }
    }
}

/// The head's centre and the neck's base of a torso with orientation `torso` at `root`.
fn trunk_points(
    root: &Vector3<f64>,
    torso: &Matrix3<f64>,
    body: &BodyModel,
) -> (Vector3<f64>, Vector3<f64>) {
    let at = |local: Vector3<f64>| root + torso * local;
    (
        at(Vector3::new(
            0.0,
            -body.shoulder_height - body.head_offset,
            0.0,
        )),
        at(Vector3::new(0.0, -body.shoulder_height, 0.0)),
    )
}

/// Poses the body: `root` is the root's position in the camera frame (metres).
pub fn skeleton_from_pose(pose: &Pose, root: &Vector3<f64>, body: &BodyModel) -> Skeleton {
    let torso = torso_rotation(pose);
    let (head, neck_base) = trunk_points(root, &torso, body);
    Skeleton {
        root: *root,
        torso,
        head,
        neck_base,
        right: arm_frames(pose, Side::Right, root, &torso, body),
        left: arm_frames(pose, Side::Left, root, &torso, body),
        anatomy: Anatomy::of(body),
    }
}
