//! The body's solids in 3D: elliptic frustums (arm cones, torso, neck) and an ellipsoid (head).

use crate::body::BodyModel;
use crate::kinematics::{Side, Skeleton};
use nalgebra::{Matrix3, Vector3};

/// A frustum whose cross-sections are similar ellipses: semi-axes `radii0` along `(e1, e2)` at
/// `p0`, scaled linearly to `radii1` at `p1`. A truncated cone has equal semi-axes; the torso's
/// elliptic cylinder has equal ends.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frustum {
    pub p0: Vector3<f64>,
    pub p1: Vector3<f64>,
    /// Unit vectors perpendicular to the axis and to each other.
    pub e1: Vector3<f64>,
    pub e2: Vector3<f64>,
    pub radii0: [f64; 2],
    pub radii1: [f64; 2],
}

/// An ellipsoid: `axes` holds the three semi-axis vectors as columns. A zero column makes it a
/// flat elliptic disc.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ellipsoid {
    pub centre: Vector3<f64>,
    pub axes: Matrix3<f64>,
}

/// One convex solid of the body model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Solid {
    Frustum(Frustum),
    Ellipsoid(Ellipsoid),
}

impl Frustum {
    /// A circular truncated cone between two points; `r0` at `p0`, `r1` at `p1`.
    /// `up` is any direction not parallel to the axis; it only orients the cross-section frame.
    pub fn cone(p0: Vector3<f64>, p1: Vector3<f64>, r0: f64, r1: f64, up: &Vector3<f64>) -> Self {
        let axis = (p1 - p0).normalize();
        let mut e1 = up.cross(&axis);
        if e1.norm_squared() < 1e-12 {
            // `up` is parallel to the axis: any direction that is not will do.
            let other = if axis.x.abs() < 0.9 {
                Vector3::x()
            } else {
                Vector3::y()
            };
            e1 = other.cross(&axis);
        }
        let e1 = e1.normalize();
        let e2 = axis.cross(&e1);
        Frustum {
            p0,
            p1,
            e1,
            e2,
            radii0: [r0, r0],
            radii1: [r1, r1],
        }
    }

    /// The end disc at `p0` (`end = 0`) or `p1` (`end = 1`) as a flat ellipsoid.
    pub fn end_disc(&self, end: usize) -> Ellipsoid {
        let (c, r) = if end == 0 {
            (self.p0, self.radii0)
        } else {
            (self.p1, self.radii1)
        };
        Ellipsoid {
            centre: c,
            axes: Matrix3::from_columns(&[self.e1 * r[0], self.e2 * r[1], Vector3::zeros()]),
        }
    }
}

/// The parts of the body model, in the order of every per-part array.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[repr(usize)]
pub enum Part {
    Torso = 0,
    Neck,
    Head,
    RightUpperArm,
    RightLowerArm,
    LeftUpperArm,
    LeftLowerArm,
}

/// Number of parts.
pub const PART_COUNT: usize = 7;

/// Part names in index order.
pub const PART_NAMES: [&str; PART_COUNT] = [
    "torso",
    "neck",
    "head",
    "right_upper_arm",
    "right_lower_arm",
    "left_upper_arm",
    "left_lower_arm",
];

impl Part {
    /// All parts in index order.
    pub const ALL: [Part; PART_COUNT] = [
        Part::Torso,
        Part::Neck,
        Part::Head,
        Part::RightUpperArm,
        Part::RightLowerArm,
        Part::LeftUpperArm,
        Part::LeftLowerArm,
    ];

    /// The two cones of one arm: upper, lower.
    pub fn arm(side: Side) -> [Part; 2] {
        match side {
            Side::Right => [Part::RightUpperArm, Part::RightLowerArm],
            Side::Left => [Part::LeftUpperArm, Part::LeftLowerArm],
        }
    }
}

/// The solid of one part of the posed body.
pub fn solid_of_part(part: Part, skel: &Skeleton, body: &BodyModel) -> Solid {
    let t = &skel.torso;
    let (x, y, z) = (
        t.column(0).into_owned(),
        t.column(1).into_owned(),
        t.column(2).into_owned(),
    );
    let arm_cone = |side: Side, lower: bool| {
        let arm = skel.arm(side);
        // The cross-section frame follows the limb's own x axis so it turns with the limb.
        if lower {
            let up = arm.lower.column(0).into_owned();
            Frustum::cone(
                arm.elbow,
                arm.hand,
                body.lower_arm_radii[0],
                body.lower_arm_radii[1],
                &up,
            )
        } else {
            let up = arm.upper.column(0).into_owned();
            Frustum::cone(
                arm.shoulder,
                arm.elbow,
                body.upper_arm_radii[0],
                body.upper_arm_radii[1],
                &up,
            )
        }
    };
    match part {
        Part::Torso => Solid::Frustum(Frustum {
            p0: skel.root - y * body.torso_top,
            p1: skel.root + y * body.torso_bottom,
            e1: x,
            e2: z,
            radii0: [body.torso_half_width, body.torso_half_depth],
            radii1: [body.torso_half_width, body.torso_half_depth],
        }),
        Part::Neck => Solid::Frustum(Frustum {
            p0: skel.neck_base,
            p1: skel.neck_base - y * body.neck_length,
            e1: x,
            e2: z,
            radii0: [body.neck_radius; 2],
            radii1: [body.neck_radius; 2],
        }),
        Part::Head => Solid::Ellipsoid(Ellipsoid {
            centre: skel.head,
            axes: Matrix3::from_columns(&[
                x * body.head_radii[0],
                y * body.head_radii[1],
                z * body.head_radii[2],
            ]),
        }),
        Part::RightUpperArm => Solid::Frustum(arm_cone(Side::Right, false)),
        Part::RightLowerArm => Solid::Frustum(arm_cone(Side::Right, true)),
        Part::LeftUpperArm => Solid::Frustum(arm_cone(Side::Left, false)),
        Part::LeftLowerArm => Solid::Frustum(arm_cone(Side::Left, true)),
    }
}

impl Solid {
    /// A point inside the solid used to order parts by depth (painter's algorithm).
    pub fn centre(&self) -> Vector3<f64> {
        match self {
            Solid::Frustum(f) => (f.p0 + f.p1) / 2.0,
            Solid::Ellipsoid(e) => e.centre,
        }
    }
}
