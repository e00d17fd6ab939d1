//! Search boxes (anatomical ranges, trajectory windows) and non-penetration (thesis 3.5; SPEC 5).

use crate::body::BodyModel;
use crate::kinematics::{Side, Skeleton};
use crate::pose::{Dof, DofRange, JointLimits, Pose};
use nalgebra::Vector3;

/// Half-width of the trajectory window at 30 frames per second, radians (SPEC 5).
///
/// The torso's turn gets a narrow window: a person facing the camera turns slowly, and a
/// turned torso fits a frontal silhouette almost as well when the model's width is off, so a
/// wide window let the fit drift into a turn it never left (docs/tracker.md).
pub fn window_half_width(dof: Dof) -> f64 {
    match dof {
        Dof::TorsoY => 0.05,
        Dof::TorsoZ | Dof::RightZUp | Dof::LeftZUp => 0.10,
        _ => 0.15,
    }
}

/// The admissible values of `dof` within `half` of `centre`, clipped to the limits. A centre
/// outside the limits is first moved to the nearest admissible value.
pub fn window(limits: &JointLimits, dof: Dof, centre: f64, half: f64) -> DofRange {
    let range = limits.range(dof);
    let c = range.clamp(centre);
    let parts: Vec<(f64, f64)> = range
        .intervals()
        .iter()
        .filter_map(|i| {
            let (lo, hi) = (i.lo.max(c - half), i.hi.min(c + half));
            (lo <= hi).then_some((lo, hi))
        })
        .collect();
    // `c` is admissible, so at least the interval holding it survives.
    DofRange::union(&parts).unwrap_or_else(|_| range.clone())
}

/// Points along a segment, ends included.
fn along(a: &Vector3<f64>, b: &Vector3<f64>, n: usize) -> impl Iterator<Item = Vector3<f64>> {
    let (a, b) = (*a, *b);
    (0..n).map(move |i| a + (b - a) * (i as f64 / (n - 1) as f64))
}

/// Whether a point lies inside the torso's elliptic cylinder.
fn inside_torso(p: &Vector3<f64>, skel: &Skeleton, body: &BodyModel) -> bool {
    let q = skel.torso.transpose() * (p - skel.root);
    let (x, z) = (q.x / body.torso_half_width, q.z / body.torso_half_depth);
    q.y > -body.torso_top && q.y < body.torso_bottom && x * x + z * z < 1.0
}

/// Closest distance between two segments.
fn segment_distance(
    p0: &Vector3<f64>,
    p1: &Vector3<f64>,
    q0: &Vector3<f64>,
    q1: &Vector3<f64>,
) -> f64 {
    let (d1, d2, r) = (p1 - p0, q1 - q0, p0 - q0);
    let (a, e, f) = (d1.dot(&d1), d2.dot(&d2), d2.dot(&r));
    let (c, b) = (d1.dot(&r), d1.dot(&d2));
    let denom = a * e - b * b;
    let mut s = if denom > 1e-12 {
        ((b * f - c * e) / denom).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let mut t = if e > 1e-12 { (b * s + f) / e } else { 0.0 };
    if t < 0.0 {
        t = 0.0;
        s = if a > 1e-12 {
            (-c / a).clamp(0.0, 1.0)
        } else {
            0.0
        };
    } else if t > 1.0 {
        t = 1.0;
        s = if a > 1e-12 {
            ((b - c) / a).clamp(0.0, 1.0)
        } else {
            0.0
        };
    }
    ((p0 + d1 * s) - (q0 + d2 * t)).norm()
}

/// Whether the arm on `side` penetrates the torso or the other arm.
///
/// The arm's bones (cone axes) may not enter the torso cylinder, which lets the arm's flesh
/// touch it (arms at rest hang against the body); two arms' cones may overlap by up to half
/// their radii (hands touching when clapping), no more.
pub fn arm_penetrates(skel: &Skeleton, body: &BodyModel, side: Side) -> bool {
    let arm = skel.arm(side);
    // The shoulder itself sits on the torso's edge; test from a little below it.
    let start = arm.shoulder + (arm.elbow - arm.shoulder) * 0.2;
    if along(&start, &arm.elbow, 5)
        .chain(along(&arm.elbow, &arm.hand, 7))
        .any(|p| inside_torso(&p, skel, body))
    {
        return true;
    }
    let other = skel.arm(match side {
        Side::Right => Side::Left,
        Side::Left => Side::Right,
    });
    let r_up = (body.upper_arm_radii[0] + body.upper_arm_radii[1]) / 2.0;
    let r_low = (body.lower_arm_radii[0] + body.lower_arm_radii[1]) / 2.0;
    let segments =
        |a: &crate::kinematics::ArmFrames| [(a.shoulder, a.elbow, r_up), (a.elbow, a.hand, r_low)];
    for (p0, p1, rp) in segments(arm) {
        for (q0, q1, rq) in segments(other) {
            if segment_distance(&p0, &p1, &q0, &q1) < 0.5 * (rp + rq) {
                return true;
            }
        }
    }
    false
}

/// Whether either arm of the pose penetrates.
pub fn pose_penetrates(pose: &Pose, root: &Vector3<f64>, body: &BodyModel) -> bool {
    let skel = crate::kinematics::skeleton_from_pose(pose, root, body);
    arm_penetrates(&skel, body, Side::Right) || arm_penetrates(&skel, body, Side::Left)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn resting_and_a_pose_arms_do_not_penetrate() {
        let b = BodyModel::default();
        let root = Vector3::new(0.0, 0.0, 2.5);
        assert!(!pose_penetrates(&Pose::default(), &root, &b));
        let mut a = Pose::default();
        a.set(Dof::RightZUp, 0.6);
        a.set(Dof::LeftZUp, 0.6);
        assert!(!pose_penetrates(&a, &root, &b));
    }

    #[test]
    fn an_arm_through_the_chest_penetrates() {
        // Adducted across the body without flexing forwards: the upper arm passes through the torso.
        let b = BodyModel::default();
        let mut p = Pose::default();
        p.set(Dof::RightZUp, -0.3);
        p.set(Dof::RightXDown, 1.6);
        p.set(Dof::RightYUp, 1.5);
        assert!(pose_penetrates(&p, &Vector3::new(0.0, 0.0, 2.5), &b));
    }

    #[test]
    fn forearms_crossed_in_front_of_the_body_do_not_penetrate_the_torso_but_each_other() {
        let b = BodyModel::default();
        let root = Vector3::new(0.0, 0.0, 2.5);
        let mut p = Pose::default();
        for (x_up, y_up, x_down) in [
            (Dof::RightXUp, Dof::RightYUp, Dof::RightXDown),
            (Dof::LeftXUp, Dof::LeftYUp, Dof::LeftXDown),
        ] {
            p.set(x_up, 0.5);
            p.set(y_up, 0.8);
            p.set(x_down, 1.6);
        }
        let skel = crate::kinematics::skeleton_from_pose(&p, &root, &b);
        // Both forearms lie in front of the chest at the same depth: they cross through each other.
        assert!(!along(&skel.right.elbow, &skel.right.hand, 7).any(|q| inside_torso(&q, &skel, &b)));
        assert!(arm_penetrates(&skel, &b, Side::Right));
    }

    #[test]
    fn windows_clip_to_the_limits_and_respect_unions() {
        let anat = JointLimits::anatomical();
        let w = window(&anat, Dof::RightXDown, 0.05, 0.15);
        assert_eq!((w.lo(), w.hi()), (0.0, 0.2));
        let thesis = JointLimits::thesis();
        let pi = std::f64::consts::PI;
        let w = window(&thesis, Dof::RightXUp, 2.3, 1.3);
        assert_eq!(w.intervals().len(), 2);
        assert!(!w.contains(1.5) && w.contains(1.01) && w.contains(2.3));
        // A centre in the gap goes to the nearer wall first.
        let w = window(&thesis, Dof::RightXUp, pi / 3.0 + 0.05, 0.1);
        assert!((w.hi() - pi / 3.0).abs() < 1e-12 && w.intervals().len() == 1);
        // A centre beyond the limits is brought back first.
        let w = window(&anat, Dof::RightXDown, 5.0, 0.15);
        assert_eq!((w.lo(), w.hi()), (2.45, 2.6));
    }

    #[test]
    fn segment_distance_is_exact_for_known_cases() {
        let o = Vector3::zeros();
        let x = Vector3::x();
        let d = segment_distance(
            &o,
            &x,
            &Vector3::new(0.5, 1.0, -1.0),
            &Vector3::new(0.5, 1.0, 1.0),
        );
        assert!((d - 1.0).abs() < 1e-12);
        let d = segment_distance(
            &o,
            &x,
            &Vector3::new(2.0, 0.0, 0.0),
            &Vector3::new(3.0, 0.0, 0.0),
        );
        assert!((d - 1.0).abs() < 1e-12);
    }
}
