//! Hostile geometry for the rasteriser and the cost: end-on and zero-length cones, NaN and
//! infinite coordinates, huge and zero radii, a root at the camera, wild cameras and bodies.
//! Nothing may panic; masks stay inside their region; a fit is finite or a clean error.

#![allow(clippy::panic, clippy::unwrap_used, clippy::expect_used)] // test code may fail loudly

use nalgebra::{Matrix3, Vector2, Vector3};
use proptest::prelude::*;
use upperpose_core::image::{FrameView, SkinPoints};
use upperpose_core::outline::outline_of_solid;
use upperpose_core::raster::spans_of_outline;
use upperpose_core::search::{fit_frame, FrameRequest, Mode, SearchConfig};
use upperpose_core::solid::{Ellipsoid, Frustum, Solid};
use upperpose_core::{
    skeleton_from_pose, BitMask, BodyModel, BodyRaster, Camera, Pose, Roi, DOF_COUNT,
};

const W: u32 = 96;
const H: u32 = 72;

/// A coordinate that is ordinary most of the time and hostile otherwise.
fn coordinate() -> impl Strategy<Value = f64> {
    prop_oneof![
        6 => -3.0..3.0f64,
        1 => Just(0.0),
        1 => Just(f64::NAN),
        1 => Just(f64::INFINITY),
        1 => Just(f64::NEG_INFINITY),
        1 => Just(1e300),
        1 => Just(-1e300),
        1 => Just(1e-300),
        1 => Just(f64::MIN_POSITIVE),
    ]
}

/// A length: ordinary, zero, negative, tiny, huge or not a number.
fn radius() -> impl Strategy<Value = f64> {
    prop_oneof![
        4 => 0.0..0.5f64,
        1 => Just(0.0),
        1 => Just(-0.1),
        1 => Just(1e-300),
        1 => Just(1e6),
        1 => Just(1e300),
        1 => Just(f64::NAN),
        1 => Just(f64::INFINITY),
    ]
}

fn point() -> impl Strategy<Value = Vector3<f64>> {
    (coordinate(), coordinate(), coordinate()).prop_map(|(x, y, z)| Vector3::new(x, y, z))
}

/// Cones seen from anywhere, also end-on (both ends on one viewing ray) and of zero length.
fn cone() -> impl Strategy<Value = Frustum> {
    let ends = prop_oneof![
        3 => (point(), point()),
        1 => (point(), 0.0..3.0f64).prop_map(|(p, k)| (p, p * k)), // end-on: along the ray
        1 => point().prop_map(|p| (p, p)),                         // zero length
    ];
    (ends, radius(), radius(), point())
        .prop_map(|((p0, p1), r0, r1, up)| Frustum::cone(p0, p1, r0, r1, &up))
}

fn ellipsoid() -> impl Strategy<Value = Ellipsoid> {
    (point(), proptest::collection::vec(coordinate(), 9)).prop_map(|(centre, a)| Ellipsoid {
        centre,
        axes: Matrix3::from_column_slice(&a),
    })
}

/// Cameras the constructors accept, from intrinsics that are often at or past their limits.
fn camera() -> impl Strategy<Value = Camera> {
    let focal =
        prop_oneof![3 => 10.0..2000.0f64, 1 => Just(1e-300), 1 => Just(1e7), 1 => Just(1e300)];
    let centre =
        prop_oneof![3 => 0.0..100.0f64, 1 => Just(-1e7), 1 => Just(1e7), 1 => Just(-1e300)];
    let depth = prop_oneof![3 => 0.01..100.0f64, 1 => Just(1e-300), 1 => Just(1e300)];
    (0..3u8, focal, centre.clone(), centre, depth).prop_filter_map(
        "refused intrinsics",
        |(kind, f, cx, cy, z)| {
            match kind {
                0 => Camera::perspective(f, cx, cy),
                1 => Camera::orthographic(f, cx, cy),
                _ => Camera::weak_perspective(f, cx, cy, z),
            }
            .ok()
        },
    )
}

/// Regions inside the W x H image, the whole image most often.
fn roi() -> impl Strategy<Value = Roi> {
    prop_oneof![
        2 => Just(Roi::full(W, H)),
        1 => (0..W - 1, 0..H - 1, 1..W, 1..H).prop_map(|(x, y, w, h)| {
            Roi::inside(x.into(), y.into(), w.min(W - x).into(), h.min(H - y).into(), W, H).unwrap()
        }),
    ]
}

/// Every run of a region's spans lies inside the region, and the mask holds no more pixels.
fn assert_inside(solid: &Solid, camera: &Camera, roi: &Roi) -> Result<(), TestCaseError> {
    if let Some(outline) = outline_of_solid(solid, camera) {
        let spans = spans_of_outline(&outline, roi);
        for i in 0..spans.spans.len() {
            let (y, s) = (spans.y(i), spans.spans[i]);
            prop_assert!(
                y >= roi.y && y < roi.y + roi.height as i32,
                "row {y} outside {roi:?}"
            );
            if !s.is_empty() {
                prop_assert!(
                    s.x0 >= roi.x && s.x1 <= roi.x + roi.width as i32,
                    "{s:?} outside {roi:?}"
                );
            }
        }
        let mut mask = BitMask::new(*roi);
        mask.fill(&spans);
        prop_assert!(mask.count() <= u64::from(roi.width) * u64::from(roi.height));
    }
    Ok(())
}

fn hostile_pose() -> impl Strategy<Value = Pose> {
    let angle = prop_oneof![40 => -4.0..4.0f64, 1 => Just(f64::NAN), 1 => Just(1e300), 1 => Just(f64::INFINITY)];
    proptest::collection::vec(angle, DOF_COUNT).prop_map(|a| Pose(a.try_into().unwrap()))
}

/// Body dimensions as the core's own struct allows them, before any validation.
fn hostile_body() -> impl Strategy<Value = BodyModel> {
    (radius(), radius(), radius(), radius()).prop_map(|(arm, cone, torso, head)| {
        let d = BodyModel::default();
        BodyModel {
            upper_arm_length: if arm.is_finite() {
                arm
            } else {
                d.upper_arm_length
            },
            upper_arm_radii: [cone, cone],
            lower_arm_radii: [cone, cone],
            torso_half_width: torso,
            head_radii: [head, head, head],
            ..d
        }
    })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 2000, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn cones_rasterise_inside_their_region(f in cone(), cam in camera(), roi in roi()) {
        assert_inside(&Solid::Frustum(f), &cam, &roi)?;
    }

    #[test]
    fn ellipsoids_rasterise_inside_their_region(e in ellipsoid(), cam in camera(), roi in roi()) {
        assert_inside(&Solid::Ellipsoid(e), &cam, &roi)?;
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 400, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn whole_bodies_render_inside_their_region(
        pose in hostile_pose(), root in point(), body in hostile_body(), cam in camera(), roi in roi()
    ) {
        let skel = skeleton_from_pose(&pose, &root, &body);
        let raster = BodyRaster::new(&skel, &body, &cam, roi);
        let area = u64::from(roi.width) * u64::from(roi.height);
        prop_assert!(raster.union().count() <= area);
        for contour in raster.contours() {
            prop_assert!(contour.count() <= area);
        }
    }

    #[test]
    fn regions_never_wrap_round(
        x in prop_oneof![any::<i64>(), (i64::MAX - 200)..=i64::MAX],
        y in prop_oneof![any::<i64>(), 0..i64::from(H)],
        w in prop_oneof![any::<i64>(), 1..=200i64],
        h in prop_oneof![any::<i64>(), 1..=i64::from(H)],
    ) {
        if let Ok(r) = Roi::inside(x, y, w, h, W, H) {
            prop_assert!(r.x >= 0 && r.y >= 0 && r.width >= 1 && r.height >= 1);
            prop_assert!(r.x as u32 + r.width <= W && r.y as u32 + r.height <= H);
        }
    }
}

/// A frame with some silhouette and edge on it and hostile skin points.
struct Planes {
    sil: Vec<u64>,
    edge: Vec<u64>,
    motion: Vec<u64>,
}

fn planes(fill: u64) -> Planes {
    let n = (W as usize).div_ceil(64) * H as usize;
    Planes {
        sil: vec![fill; n],
        edge: vec![fill.rotate_left(7); n],
        motion: vec![0; n],
    }
}

fn skin_point() -> impl Strategy<Value = Option<Vector2<f64>>> {
    prop_oneof![
        2 => Just(None),
        2 => (0.0..96.0f64, 0.0..72.0f64).prop_map(|(x, y)| Some(Vector2::new(x, y))),
        1 => (coordinate(), coordinate()).prop_map(|(x, y)| Some(Vector2::new(x, y))),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 600, failure_persistence: None, ..ProptestConfig::default() })]

    /// The whole cost and search: an error, or a fit whose every number is finite.
    #[test]
    fn fits_are_finite_or_a_clean_error(
        prediction in hostile_pose(),
        root in prop_oneof![
            3 => (-0.5..0.5f64, -0.5..0.5f64, 0.3..6.0f64).prop_map(|(x, y, z)| Vector3::new(x, y, z)),
            1 => Just(Vector3::zeros()),                      // at the camera
            1 => Just(Vector3::new(0.0, 0.0, 1e-12)),
            1 => point(),
        ],
        body in prop_oneof![2 => Just(BodyModel::default()), 1 => hostile_body()],
        cam in camera(),
        fill in any::<u64>(),
        skin in proptest::collection::vec(skin_point(), 3),
        mode in prop_oneof![Just(Mode::Trajectory), Just(Mode::Initial)],
        window_scale in prop_oneof![8 => 0.1..4.0f64, 1 => Just(1e300), 1 => Just(f64::NAN)],
        search in any::<[bool; 3]>(),
    ) {
        let p = planes(fill);
        let mut points = SkinPoints::default();
        for (slot, s) in points.points.iter_mut().zip(&skin) {
            *slot = *s;
        }
        let req = FrameRequest {
            frame: FrameView::new(W, H, &p.sil, &p.edge, &p.motion, points).unwrap(),
            prediction,
            root,
            body,
            camera: cam,
            mode,
            window_scale,
            angle_window_scales: [1.0; DOF_COUNT],
            frame_interval: 1.0 / 30.0,
            search,
            frame_index: 0,
        };
        let config = SearchConfig {
            swarm: upperpose_core::search::apso::SwarmConfig { particles: 4, iterations: 2, ..Default::default() },
            threads: Some(1),
            ..SearchConfig::default()
        };
        match fit_frame(&req, &config) {
            Err(err) => prop_assert!(!err.to_string().is_empty()),
            Ok(fit) => {
                prop_assert!(fit.pose.0.iter().all(|a| a.is_finite()), "pose {:?}", fit.pose);
                prop_assert!(fit.root.iter().all(|v| v.is_finite()), "root {:?}", fit.root);
                prop_assert!(fit.cost.is_finite() && fit.stage_costs.iter().all(|c| c.is_finite()), "cost {}", fit.cost);
            }
        }
    }
}
