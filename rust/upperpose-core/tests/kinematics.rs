//! Forward kinematics against hand-computed joint positions, and invariants over random poses.

#![allow(clippy::panic, clippy::unwrap_used, clippy::expect_used)] // test code may fail loudly

use nalgebra::Vector3;
use proptest::prelude::*;
use std::f64::consts::FRAC_PI_2;
use upperpose_core::{skeleton_from_pose, BodyModel, Dof, Pose};

const TOL: f64 = 1e-9;

fn close(a: &Vector3<f64>, b: &Vector3<f64>) -> bool {
    (a - b).amax() < TOL
}

fn pose_with(settings: &[(Dof, f64)]) -> Pose {
    let mut p = Pose::default();
    for &(d, v) in settings {
        p.set(d, v);
    }
    p
}

#[test]
fn rest_pose_hangs_the_arms_straight_down() {
    let b = BodyModel::default();
    let root = Vector3::new(0.1, -0.2, 2.5);
    let s = skeleton_from_pose(&Pose::default(), &root, &b);
    let rs = root + Vector3::new(-0.18, -0.20, 0.0);
    let ls = root + Vector3::new(0.18, -0.20, 0.0);
    assert!(close(&s.right.shoulder, &rs));
    assert!(close(&s.left.shoulder, &ls));
    assert!(close(&s.right.elbow, &(rs + Vector3::new(0.0, 0.29, 0.0))));
    assert!(close(&s.right.hand, &(rs + Vector3::new(0.0, 0.63, 0.0))));
    assert!(close(&s.left.hand, &(ls + Vector3::new(0.0, 0.63, 0.0))));
    assert!(close(&s.head, &(root + Vector3::new(0.0, -0.44, 0.0))));
}

#[test]
fn abduction_moves_each_arm_out_to_its_own_side() {
    let b = BodyModel::default();
    let root = Vector3::new(0.0, 0.0, 3.0);
    let s = skeleton_from_pose(
        &pose_with(&[(Dof::RightZUp, FRAC_PI_2), (Dof::LeftZUp, FRAC_PI_2)]),
        &root,
        &b,
    );
    // Subject's right is the image's left (-X).
    assert!(close(
        &s.right.elbow,
        &Vector3::new(-0.18 - 0.29, -0.20, 3.0)
    ));
    assert!(close(
        &s.right.hand,
        &Vector3::new(-0.18 - 0.63, -0.20, 3.0)
    ));
    assert!(close(&s.left.hand, &Vector3::new(0.18 + 0.63, -0.20, 3.0)));
}

#[test]
fn flexion_points_the_arm_at_the_camera_and_the_elbow_bends_forwards() {
    let b = BodyModel::default();
    let root = Vector3::new(0.0, 0.0, 3.0);
    let s = skeleton_from_pose(
        &pose_with(&[(Dof::RightXUp, FRAC_PI_2), (Dof::LeftXDown, FRAC_PI_2)]),
        &root,
        &b,
    );
    assert!(close(
        &s.right.elbow,
        &Vector3::new(-0.18, -0.20, 3.0 - 0.29)
    ));
    assert!(close(
        &s.right.hand,
        &Vector3::new(-0.18, -0.20, 3.0 - 0.63)
    ));
    // Left: upper arm hangs, forearm points at the camera.
    assert!(close(&s.left.elbow, &Vector3::new(0.18, 0.09, 3.0)));
    assert!(close(&s.left.hand, &Vector3::new(0.18, 0.09, 3.0 - 0.34)));
}

#[test]
fn full_flexion_raises_the_arm_overhead() {
    let b = BodyModel::default();
    let s = skeleton_from_pose(
        &pose_with(&[(Dof::LeftXUp, std::f64::consts::PI)]),
        &Vector3::zeros(),
        &b,
    );
    assert!(close(&s.left.hand, &Vector3::new(0.18, -0.20 - 0.63, 0.0)));
}

#[test]
fn humeral_rotation_swings_a_bent_forearm_towards_the_midline() {
    // Elbow bent 90 degrees (forearm towards the camera), then internal rotation of 90 degrees
    // points the right forearm at +X (the midline) and the left one at -X.
    let b = BodyModel::default();
    let p = pose_with(&[
        (Dof::RightXDown, FRAC_PI_2),
        (Dof::RightYUp, FRAC_PI_2),
        (Dof::LeftXDown, FRAC_PI_2),
        (Dof::LeftYUp, FRAC_PI_2),
    ]);
    let s = skeleton_from_pose(&p, &Vector3::zeros(), &b);
    assert!(close(&s.right.hand, &Vector3::new(-0.18 + 0.34, 0.09, 0.0)));
    assert!(close(&s.left.hand, &Vector3::new(0.18 - 0.34, 0.09, 0.0)));
}

#[test]
fn forearm_twist_moves_no_joint() {
    let b = BodyModel::default();
    let base = pose_with(&[
        (Dof::RightXUp, 0.7),
        (Dof::RightXDown, 1.2),
        (Dof::RightYUp, 0.4),
    ]);
    let mut twisted = base;
    twisted.set(Dof::RightYDown, 1.3);
    let a = skeleton_from_pose(&base, &Vector3::zeros(), &b).joints();
    let t = skeleton_from_pose(&twisted, &Vector3::zeros(), &b).joints();
    for (x, y) in a.iter().zip(&t) {
        assert!(close(x, y));
    }
}

#[test]
fn torso_angles_turn_and_lean_the_whole_upper_body() {
    let b = BodyModel::default();
    // Turn: the right shoulder goes away from the camera.
    let s = skeleton_from_pose(
        &pose_with(&[(Dof::TorsoY, FRAC_PI_2)]),
        &Vector3::zeros(),
        &b,
    );
    assert!(close(&s.right.shoulder, &Vector3::new(0.0, -0.20, 0.18)));
    // Sideways lean: the head tips to +X (the subject's left).
    let s = skeleton_from_pose(
        &pose_with(&[(Dof::TorsoZ, FRAC_PI_2)]),
        &Vector3::zeros(),
        &b,
    );
    assert!(close(&s.head, &Vector3::new(0.44, 0.0, 0.0)));
    // Forward lean of 90 degrees: the head comes at the camera, arms hang along -Z... of the torso.
    let s = skeleton_from_pose(
        &pose_with(&[(Dof::TorsoX, FRAC_PI_2)]),
        &Vector3::zeros(),
        &b,
    );
    assert!(close(&s.head, &Vector3::new(0.0, 0.0, -0.44)));
    assert!(close(
        &s.right.hand,
        &Vector3::new(-0.18, 0.0, -0.20 + 0.63)
    ));
}

#[test]
fn composed_angles_follow_rz_ry_rx() {
    // Torso x = 0.3 then right arm abducted 90 degrees: the arm stays horizontal in the
    // leaning torso's frame: elbow = shoulder + R_x(0.3) * (-0.29, 0, 0) = shoulder - 0.29 X.
    let b = BodyModel::default();
    let s = skeleton_from_pose(
        &pose_with(&[(Dof::TorsoX, 0.3), (Dof::RightZUp, FRAC_PI_2)]),
        &Vector3::zeros(),
        &b,
    );
    let (c, sn) = (0.3f64.cos(), 0.3f64.sin());
    let shoulder = Vector3::new(-0.18, -0.20 * c, -0.20 * sn);
    assert!(close(&s.right.shoulder, &shoulder));
    assert!(close(
        &s.right.elbow,
        &(shoulder + Vector3::new(-0.29, 0.0, 0.0))
    ));
}

proptest! {
    #[test]
    fn segment_lengths_hold_for_any_pose(angles in proptest::collection::vec(-3.2..3.2f64, 13),
                                         x in -1.0..1.0f64, y in -1.0..1.0f64, z in 0.5..5.0f64) {
        let b = BodyModel::default();
        let pose = Pose::from_slice(&angles).unwrap();
        let s = skeleton_from_pose(&pose, &Vector3::new(x, y, z), &b);
        for arm in [&s.right, &s.left] {
            prop_assert!(((arm.elbow - arm.shoulder).norm() - b.upper_arm_length).abs() < TOL);
            prop_assert!(((arm.hand - arm.elbow).norm() - b.lower_arm_length).abs() < TOL);
        }
        prop_assert!(((s.right.shoulder - s.left.shoulder).norm() - b.shoulder_width).abs() < TOL);
        prop_assert!(((s.head - s.neck_base).norm() - b.head_offset).abs() < TOL);
    }

    #[test]
    fn left_arm_mirrors_the_right(arm in proptest::collection::vec(-3.2..3.2f64, 5)) {
        // Same angles on both arms, torso upright: the left joints are the right ones with X negated.
        let b = BodyModel::default();
        let mut angles = vec![0.0; 3];
        angles.extend(&arm);
        angles.extend(&arm);
        let s = skeleton_from_pose(&Pose::from_slice(&angles).unwrap(), &Vector3::zeros(), &b);
        let mirror = |v: &Vector3<f64>| Vector3::new(-v.x, v.y, v.z);
        prop_assert!(close(&s.left.elbow, &mirror(&s.right.elbow)));
        prop_assert!(close(&s.left.hand, &mirror(&s.right.hand)));
    }
}

#[test]
fn reported_joints_are_anatomical_centres_inside_the_solids() {
    let b = BodyModel::default();
    let root = Vector3::new(0.1, -0.2, 2.5);
    let s = skeleton_from_pose(&Pose::default(), &root, &b);
    let j = s.joints();
    let m = s.model_points();
    // Head: 0.25 of the ellipsoid's half height (0.11 m) above its centre (the face's).
    assert!(close(&j[0], &(m[0] + Vector3::new(0.0, -0.0275, 0.0))));
    assert!(close(&j[0], &(root + Vector3::new(0.0, -0.4675, 0.0))));
    // Shoulders: 0.7 and 0.6 of the upper arm's top radius (0.05 m) inwards of and above the
    // cone's top, i.e. 3.5 cm in and 3 cm up; inside the torso's width (half width 0.16 m) and
    // inside the deltoid, the ball of the cone's top radius.
    assert!(close(&j[1], &(root + Vector3::new(-0.145, -0.23, 0.0))));
    assert!(close(&j[2], &(root + Vector3::new(0.145, -0.23, 0.0))));
    for k in [1, 2] {
        assert!((j[k].x - root.x).abs() < b.torso_half_width);
        assert!((j[k] - m[k]).norm() < b.upper_arm_radii[0]);
    }
    // Elbows are the cone's joint; palms 0.14 of the lower arm (0.34 m) short of the cone's end.
    assert!(close(&j[3], &m[3]));
    assert!(close(&j[5], &(m[5] - Vector3::new(0.0, 0.0476, 0.0))));
    assert!(close(
        &j[6],
        &(root + Vector3::new(0.18, -0.20 + 0.29 + 0.34 - 0.0476, 0.0))
    ));
}

#[test]
fn anatomical_offsets_turn_with_the_torso_and_the_forearm() {
    let b = BodyModel::default();
    let root = Vector3::new(0.0, 0.0, 3.0);
    // Torso leaning sideways by 90 degrees: "up" for the head is now the body's -Y, which
    // points along the camera's +X; the forearm bent to point at the camera keeps the palm on it.
    let pose = pose_with(&[(Dof::TorsoZ, FRAC_PI_2), (Dof::RightXDown, FRAC_PI_2)]);
    let s = skeleton_from_pose(&pose, &root, &b);
    let j = s.joints();
    let m = s.model_points();
    let up = -s.torso.column(1).into_owned();
    assert!(close(&(j[0] - m[0]), &(up * 0.0275)));
    let forearm = (m[5] - m[3]).normalize();
    assert!(close(&(m[5] - j[5]), &(forearm * 0.0476)));
    assert!(forearm.z < -0.99, "the bent forearm points at the camera");
    // The shoulder centre stays 3.5 cm inwards and 3 cm up in the torso's own frame.
    let local = s.torso.transpose() * (j[1] - m[1]);
    assert!(close(&local, &Vector3::new(0.035, -0.03, 0.0)));
}

proptest! {
    #[test]
    fn anatomical_joints_keep_their_offsets_in_any_pose(
        angles in proptest::collection::vec(-1.5f64..1.5, 13),
        scale in 0.8f64..1.2,
    ) {
        let mut b = BodyModel::default();
        b.lower_arm_length *= scale;
        b.head_radii[1] *= scale;
        b.upper_arm_radii[0] *= scale;
        let pose = Pose::from_slice(&angles).unwrap();
        let s = skeleton_from_pose(&pose, &Vector3::new(0.0, 0.1, 2.5), &b);
        let (j, m) = (s.joints(), s.model_points());
        prop_assert!(((j[0] - m[0]).norm() - 0.25 * b.head_radii[1]).abs() < 1e-9);
        prop_assert!(((j[5] - m[5]).norm() - 0.14 * b.lower_arm_length).abs() < 1e-9);
        let r = b.upper_arm_radii[0];
        prop_assert!(((j[1] - m[1]).norm() - r * (0.7f64.powi(2) + 0.6f64.powi(2)).sqrt()).abs() < 1e-9);
        prop_assert!((j[3] - m[3]).norm() < 1e-12);
    }
}
