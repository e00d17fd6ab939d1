//! The rasteriser against exact ray casting of the 3D solids, over 1000 random poses.

#![allow(clippy::panic, clippy::unwrap_used, clippy::expect_used)] // test code may fail loudly

mod common;

use nalgebra::Vector3;
use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};
use upperpose_core::solid::solid_of_part;
use upperpose_core::{
    skeleton_from_pose, BodyModel, BodyRaster, Camera, Dof, JointLimits, Part, Pose, Roi,
};

const W: i32 = 640;
const H: i32 = 480;

/// Poses uniform in the anatomical ranges, or (one case in four) with an arm pointing nearly
/// at the camera so its cones are seen almost end-on.
fn pose_strategy() -> impl Strategy<Value = Pose> {
    let limits = JointLimits::anatomical();
    let ranges: Vec<(f64, f64)> = Dof::ALL
        .iter()
        .map(|&d| (limits.range(d).lo(), limits.range(d).hi()))
        .collect();
    let uniform = ranges.iter().map(|&(lo, hi)| lo..=hi).collect::<Vec<_>>();
    (
        uniform,
        0..4u8,
        1.35..1.8f64,
        -0.15..0.15f64,
        0.0..0.35f64,
        any::<bool>(),
    )
        .prop_map(|(angles, mode, x_up, z_up, x_down, right)| {
            let mut pose = Pose(angles.try_into().unwrap_or([0.0; 13]));
            if mode == 0 {
                let (dx, dz, dd) = if right {
                    (Dof::RightXUp, Dof::RightZUp, Dof::RightXDown)
                } else {
                    (Dof::LeftXUp, Dof::LeftZUp, Dof::LeftXDown)
                };
                pose.set(dx, x_up);
                pose.set(dz, z_up);
                pose.set(dd, x_down);
                pose.set(Dof::TorsoX, 0.0);
                pose.set(Dof::TorsoY, 0.0);
            }
            pose
        })
}

fn camera_strategy() -> impl Strategy<Value = Camera> {
    prop_oneof![
        6 => (400.0..1000.0f64).prop_map(|f| Camera::perspective(f, 319.5, 239.5).unwrap()),
        1 => (150.0..300.0f64).prop_map(|s| Camera::orthographic(s, 319.5, 239.5).unwrap()),
        1 => (400.0..1000.0f64, 2.0..3.5f64).prop_map(|(f, z)| Camera::weak_perspective(f, 319.5, 239.5, z).unwrap()),
    ]
}

/// Compares every part's mask with the ray-cast reference; returns a description of the first
/// failure.
fn check_scene(pose: &Pose, root: Vector3<f64>, camera: &Camera) -> Result<(), String> {
    let body = BodyModel::default();
    let skel = skeleton_from_pose(pose, &root, &body);
    let raster = BodyRaster::new(&skel, &body, camera, Roi::full(W as u32, H as u32));
    for part in Part::ALL {
        let solid = solid_of_part(part, &skel, &body);
        let mask = raster.silhouette(part);
        let (x0, y0, x1, y1) = common::pixel_bounds(&solid, camera, W, H);
        let reference =
            |x: i32, y: i32| common::ray_hits(&solid, camera, f64::from(x), f64::from(y));
        let (mut inter, mut uni, mut area) = (0u64, 0u64, 0u64);
        for y in y0..y1 {
            for x in x0..x1 {
                let (r, m) = (reference(x, y), mask.get(x, y));
                inter += u64::from(r && m);
                uni += u64::from(r || m);
                area += u64::from(r);
                if r != m {
                    // Every disagreement must touch the reference's outline.
                    let near_outline =
                        (-1..=1).any(|dy| (-1..=1).any(|dx| reference(x + dx, y + dy) != r));
                    if !near_outline {
                        return Err(format!(
                            "{part:?}: pixel ({x}, {y}) differs away from the outline"
                        ));
                    }
                }
            }
        }
        // Nothing drawn outside the reference's bounding box.
        let outside = mask.count()
            - (y0..y1)
                .flat_map(|y| (x0..x1).map(move |x| (x, y)))
                .filter(|&(x, y)| mask.get(x, y))
                .count() as u64;
        if outside != 0 {
            return Err(format!(
                "{part:?}: {outside} pixels drawn outside the solid's bounds"
            ));
        }
        if area >= 1000 {
            let iou = inter as f64 / uni as f64;
            if iou < 0.98 {
                return Err(format!("{part:?}: IoU {iou:.4} over {area} px"));
            }
        }
    }
    Ok(())
}

#[test]
fn silhouettes_match_ray_casting_over_1000_random_poses() {
    let mut runner = TestRunner::new_with_rng(
        Config {
            cases: 1000,
            failure_persistence: None,
            ..Config::default()
        },
        TestRng::deterministic_rng(RngAlgorithm::ChaCha),
    );
    let root =
        (-0.3..0.3f64, -0.1..0.3f64, 1.6..4.0f64).prop_map(|(x, y, z)| Vector3::new(x, y, z));
    let result = runner.run(
        &(pose_strategy(), root, camera_strategy()),
        |(pose, root, camera)| check_scene(&pose, root, &camera).map_err(TestCaseError::fail),
    );
    if let Err(e) = result {
        panic!("{e}");
    }
}

#[test]
fn cone_seen_exactly_end_on_is_a_disc() {
    // The right arm points straight at the camera from the optical axis: the lower arm's
    // outline is the near end's disc, which must still match the reference.
    let mut pose = Pose::default();
    pose.set(Dof::RightXUp, std::f64::consts::FRAC_PI_2);
    let body = BodyModel::default();
    let cam = Camera::perspective(600.0, 319.5, 239.5).unwrap();
    // Put the right shoulder on the optical axis.
    let root = Vector3::new(body.shoulder_width / 2.0, body.shoulder_height, 2.0);
    check_scene(&pose, root, &cam).unwrap();
    let skel = skeleton_from_pose(&pose, &root, &body);
    let hand = cam.project(&skel.right.hand).unwrap();
    assert!((hand.x - 319.5).abs() < 1e-9 && (hand.y - 239.5).abs() < 1e-9);
}

#[test]
fn body_behind_the_camera_draws_nothing() {
    let body = BodyModel::default();
    let cam = Camera::perspective(600.0, 319.5, 239.5).unwrap();
    for z in [-2.0, 0.0, 0.05] {
        let skel = skeleton_from_pose(&Pose::default(), &Vector3::new(0.0, 0.0, z), &body);
        let raster = BodyRaster::new(&skel, &body, &cam, Roi::full(640, 480));
        assert_eq!(raster.union().count(), 0, "root at z = {z}");
    }
}

/// The labels as `visible` defines them: part `k + 1` where its visible mask is set.
fn labels_from_visible(raster: &BodyRaster) -> Vec<u8> {
    let roi = raster.roi;
    let mut out = vec![0u8; roi.width as usize * roi.height as usize];
    for (k, vis) in raster.visible().iter().enumerate() {
        for y in 0..roi.height as i32 {
            for x in 0..roi.width as i32 {
                if vis.get(roi.x + x, roi.y + y) {
                    out[y as usize * roi.width as usize + x as usize] = k as u8 + 1;
                }
            }
        }
    }
    out
}

#[test]
fn labels_are_the_visible_parts_over_random_poses_and_regions() {
    let mut runner = TestRunner::new_with_rng(
        Config {
            cases: 200,
            failure_persistence: None,
            ..Config::default()
        },
        TestRng::deterministic_rng(RngAlgorithm::ChaCha),
    );
    let root =
        (-0.3..0.3f64, -0.1..0.3f64, 1.2..4.0f64).prop_map(|(x, y, z)| Vector3::new(x, y, z));
    let roi = (0..600i64, 0..440i64, 1..640i64, 1..480i64).prop_map(|(x, y, w, h)| {
        Roi::inside(x, y, w.min(640 - x), h.min(480 - y), 640, 480).unwrap()
    });
    let result = runner.run(
        &(pose_strategy(), root, camera_strategy(), roi),
        |(pose, root, camera, roi)| {
            let body = BodyModel::default();
            let skel = skeleton_from_pose(&pose, &root, &body);
            let raster = BodyRaster::new(&skel, &body, &camera, roi);
            let labels = raster.labels();
            prop_assert!(labels.iter().any(|&l| l > 0) || raster.union().count() == 0);
            prop_assert_eq!(labels, labels_from_visible(&raster));
            Ok(())
        },
    );
    if let Err(e) = result {
        panic!("{e}");
    }
}
