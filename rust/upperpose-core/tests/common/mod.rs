//! Independent references for the integration tests: exact ray casting against the 3D solids.

#![allow(dead_code, clippy::panic, clippy::unwrap_used, clippy::expect_used)] // test code may fail loudly

use nalgebra::Vector3;
use upperpose_core::solid::{Ellipsoid, Frustum, Solid};
use upperpose_core::Camera;

/// The viewing ray through pixel centre `(u, v)`: origin and direction, and whether only
/// `t > 0` counts (perspective) or the whole line (parallel projection).
fn ray(camera: &Camera, u: f64, v: f64) -> (Vector3<f64>, Vector3<f64>, bool) {
    match camera.affine_scale() {
        None => (
            Vector3::zeros(),
            Vector3::new(
                (u - camera.cx) / camera.focal,
                (v - camera.cy) / camera.focal,
                1.0,
            ),
            true,
        ),
        Some(s) => (
            Vector3::new((u - camera.cx) / s, (v - camera.cy) / s, 0.0),
            Vector3::z(),
            false,
        ),
    }
}

/// Whether the quadratic `a t^2 + b t + c` is <= 0 somewhere in `[t0, t1]`.
fn quadratic_nonpositive_in(a: f64, b: f64, c: f64, t0: f64, t1: f64) -> bool {
    if t0 > t1 {
        return false;
    }
    let f = |t: f64| (a * t + b) * t + c;
    if f(t0) <= 0.0 || f(t1) <= 0.0 {
        return true;
    }
    if a > 0.0 {
        let tv = -b / (2.0 * a);
        return tv > t0 && tv < t1 && f(tv) <= 0.0;
    }
    false
}

fn hits_frustum(f: &Frustum, o: &Vector3<f64>, d: &Vector3<f64>, forward_only: bool) -> bool {
    let axis = f.p1 - f.p0;
    let length = axis.norm();
    let a = axis / length;
    let k = (f.radii1[0] / f.radii0[0] - 1.0) / length;
    let rel = o - f.p0;
    // Local scaled coordinates along the ray: x(t) = x0 + t xd, ...
    let (x0, xd) = (rel.dot(&f.e1) / f.radii0[0], d.dot(&f.e1) / f.radii0[0]);
    let (y0, yd) = (rel.dot(&f.e2) / f.radii0[1], d.dot(&f.e2) / f.radii0[1]);
    let (z0, zd) = (rel.dot(&a), d.dot(&a));
    // t range where 0 <= z <= length.
    let (mut t0, mut t1) = if zd.abs() < 1e-15 {
        if z0 < 0.0 || z0 > length {
            return false;
        }
        (f64::NEG_INFINITY, f64::INFINITY)
    } else {
        let (ta, tb) = (-z0 / zd, (length - z0) / zd);
        (ta.min(tb), ta.max(tb))
    };
    if forward_only {
        t0 = t0.max(0.0);
    }
    if !t0.is_finite() || !t1.is_finite() {
        // A parallel ray along the cross-section: bound t by the solid's size instead.
        t0 = t0.max(-1e3);
        t1 = t1.min(1e3);
    }
    // x^2 + y^2 - (1 + k z)^2 <= 0
    let (r0, rd) = (1.0 + k * z0, k * zd);
    let qa = xd * xd + yd * yd - rd * rd;
    let qb = 2.0 * (x0 * xd + y0 * yd - r0 * rd);
    let qc = x0 * x0 + y0 * y0 - r0 * r0;
    quadratic_nonpositive_in(qa, qb, qc, t0, t1)
}

fn hits_ellipsoid(e: &Ellipsoid, o: &Vector3<f64>, d: &Vector3<f64>) -> bool {
    let Some(inv) = e.axes.try_inverse() else {
        return false;
    };
    let (p, q) = (inv * (o - e.centre), inv * d);
    let (a, b, c) = (q.dot(&q), 2.0 * p.dot(&q), p.dot(&p) - 1.0);
    b * b - 4.0 * a * c >= 0.0
}

/// Whether the viewing ray through pixel centre `(u, v)` meets the solid.
pub fn ray_hits(solid: &Solid, camera: &Camera, u: f64, v: f64) -> bool {
    let (o, d, forward_only) = ray(camera, u, v);
    match solid {
        Solid::Frustum(f) => hits_frustum(f, &o, &d, forward_only),
        Solid::Ellipsoid(e) => hits_ellipsoid(e, &o, &d),
    }
}

/// A pixel box holding the solid's projection: the projected corners of a 3D box around it.
pub fn pixel_bounds(
    solid: &Solid,
    camera: &Camera,
    width: i32,
    height: i32,
) -> (i32, i32, i32, i32) {
    let (centre, half): (Vector3<f64>, Vector3<f64>) = match solid {
        Solid::Frustum(f) => {
            let r = f.radii0[0]
                .max(f.radii0[1])
                .max(f.radii1[0])
                .max(f.radii1[1]);
            let lo = f.p0.inf(&f.p1) - Vector3::repeat(r);
            let hi = f.p0.sup(&f.p1) + Vector3::repeat(r);
            ((lo + hi) / 2.0, (hi - lo) / 2.0)
        }
        Solid::Ellipsoid(e) => {
            let h = Vector3::new(
                e.axes.row(0).norm(),
                e.axes.row(1).norm(),
                e.axes.row(2).norm(),
            );
            (e.centre, h)
        }
    };
    let (mut x0, mut y0, mut x1, mut y1) = (
        f64::INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NEG_INFINITY,
    );
    for i in 0..8 {
        let sx = if i & 1 == 0 { -1.0 } else { 1.0 };
        let sy = if i & 2 == 0 { -1.0 } else { 1.0 };
        let sz = if i & 4 == 0 { -1.0 } else { 1.0 };
        let p = centre + Vector3::new(sx * half.x, sy * half.y, sz * half.z);
        let uv = camera
            .project(&p)
            .expect("test scenes keep solids in front of the camera");
        x0 = x0.min(uv.x);
        y0 = y0.min(uv.y);
        x1 = x1.max(uv.x);
        y1 = y1.max(uv.y);
    }
    let clampx = |v: f64| (v as i32).clamp(0, width);
    let clampy = |v: f64| (v as i32).clamp(0, height);
    (
        clampx(x0.floor() - 1.0),
        clampy(y0.floor() - 1.0),
        clampx(x1.ceil() + 2.0),
        clampy(y1.ceil() + 2.0),
    )
}
