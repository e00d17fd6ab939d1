//! Exact projected outlines of the solids (thesis 2.4, 3.2.2).
//!
//! An ellipsoid (and a flat disc, its degenerate case) projects to an ellipse under every
//! camera here: with the dual quadric `Q*`, the outline's dual conic is `P Q* P^T`. A frustum
//! is the convex hull of its two end discs, and projection keeps convex hulls, so its outline
//! is the convex hull of two ellipses: the two ellipses plus the quadrilateral spanned by the
//! four points where the silhouette generators (the lateral lines whose tangent plane passes
//! through the camera centre) meet the end circles. Without such generators the camera looks
//! down the frustum and one ellipse holds the other.

use crate::camera::{Camera, NEAR_PLANE};
use crate::solid::{Ellipsoid, Frustum, Solid};
use nalgebra::{Vector2, Vector3};

/// A filled image ellipse `{p : (p - c)^T S^-1 (p - c) <= 1}` with `S = [[sxx, sxy], [sxy, syy]]`
/// (pixels). `S` may be singular: then the ellipse is a segment and covers no area.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ellipse {
    pub cx: f64,
    pub cy: f64,
    pub sxx: f64,
    pub sxy: f64,
    pub syy: f64,
}

impl Ellipse {
    /// Determinant of the shape matrix: `(area / pi)^2`.
    pub fn det(&self) -> f64 {
        self.sxx * self.syy - self.sxy * self.sxy
    }

    /// Whether the point lies inside or on the ellipse.
    pub fn contains(&self, x: f64, y: f64) -> bool {
        let det = self.det();
        if det <= 0.0 {
            return false;
        }
        let (dx, dy) = (x - self.cx, y - self.cy);
        (self.syy * dx * dx - 2.0 * self.sxy * dx * dy + self.sxx * dy * dy) <= det
    }
}

/// The projected outline of one convex solid: the union of up to two ellipses and a convex
/// quadrilateral, which is itself convex.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Outline {
    pub ellipses: [Option<Ellipse>; 2],
    /// Vertices in order around the quadrilateral, or `None` when the hull is the ellipses alone.
    pub quad: Option<[Vector2<f64>; 4]>,
}

impl Outline {
    /// The outline's bounding box `(x0, y0, x1, y1)` in pixels, or `None` if it is empty.
    pub fn bounds(&self) -> Option<(f64, f64, f64, f64)> {
        let mut b = (
            f64::INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NEG_INFINITY,
        );
        let mut grow = |x0: f64, y0: f64, x1: f64, y1: f64| {
            b = (b.0.min(x0), b.1.min(y0), b.2.max(x1), b.3.max(y1));
        };
        for e in self.ellipses.iter().flatten() {
            let (hx, hy) = (e.sxx.max(0.0).sqrt(), e.syy.max(0.0).sqrt());
            grow(e.cx - hx, e.cy - hy, e.cx + hx, e.cy + hy);
        }
        for v in self.quad.iter().flatten() {
            grow(v.x, v.y, v.x, v.y);
        }
        (b.0 <= b.2 && b.1 <= b.3).then_some(b)
    }
}

/// The image ellipse of an ellipsoid or disc, or `None` when a perspective camera cannot see
/// all of it (some of it lies nearer than [`NEAR_PLANE`]).
pub fn ellipse_of_ellipsoid(e: &Ellipsoid, camera: &Camera) -> Option<Ellipse> {
    if camera.is_perspective() {
        // Nearest depth of the ellipsoid: centre minus its support along Z.
        let support_z = e.axes.row(2).norm();
        if e.centre.z - support_z < NEAR_PLANE {
            return None;
        }
    }
    // Q* = T diag(1, 1, 1, -1) T^T with T = [[axes, centre], [0, 1]] mapping the unit sphere
    // onto the ellipsoid; with P = [A | b] the dual conic P Q* P^T is (A axes)(A axes)^T - m m^T
    // where m = A centre + b.
    let p = camera.matrix();
    let a = p.fixed_view::<3, 3>(0, 0);
    let m_axes = a * e.axes;
    let m = a * e.centre + p.column(3);
    let dual = m_axes * m_axes.transpose() - m * m.transpose();
    // Normalise to dual[2][2] = -1; then dual = [[S - c c^T, -c], [-c^T, -1]].
    let w = -dual[(2, 2)];
    if w <= 0.0 || !w.is_finite() {
        return None;
    }
    // Only the five entries used are divided.
    let n = |r: usize, c: usize| dual[(r, c)] / w;
    let (cx, cy) = (-n(0, 2), -n(1, 2));
    Some(Ellipse {
        cx,
        cy,
        sxx: n(0, 0) + cx * cx,
        sxy: n(0, 1) + cx * cy,
        syy: n(1, 1) + cy * cy,
    })
}

/// The four 3D points where the frustum's two silhouette generators meet its end circles, in
/// order around the quadrilateral they span, or `None` when the camera looks down the frustum.
pub fn silhouette_generators(f: &Frustum, camera: &Camera) -> Option<[Vector3<f64>; 4]> {
    let axis = f.p1 - f.p0;
    let length = axis.norm();
    if length <= 0.0 {
        return None;
    }
    let a = axis / length;
    // Work where the cross-sections are circles: scale e1 by 1/radii0[0] and e2 by 1/radii0[1].
    // Affine maps keep tangency, so generators found there map back to the true ones.
    let [a0, b0] = f.radii0;
    let slope = (f.radii1[0] / a0 - 1.0) / length; // d(radius)/d(axis) in the scaled frame
    let to_scaled =
        |v: &Vector3<f64>| Vector3::new(v.dot(&f.e1) / a0, v.dot(&f.e2) / b0, v.dot(&a));
    // With the cross-section direction u, the lateral normal is u - slope * a; the generator
    // is on the silhouette when that normal is perpendicular to the viewing ray.
    let (d, rhs) = if camera.is_perspective() {
        let d = to_scaled(&f.p0); // p0 minus the camera centre, which is the origin
        (d, -1.0 + slope * d.z)
    } else {
        let d = to_scaled(&Vector3::z());
        (d, slope * d.z)
    };
    let rho = d.x.hypot(d.y);
    if rho <= 0.0 {
        return None;
    }
    let c = rhs / rho;
    if !(c > -1.0 && c < 1.0) {
        return None;
    }
    let s = (1.0 - c * c).sqrt();
    let (wx, wy) = (d.x / rho, d.y / rho);
    let lift = |ux: f64, uy: f64, centre: &Vector3<f64>, r: &[f64; 2]| {
        centre + f.e1 * (r[0] * ux) + f.e2 * (r[1] * uy)
    };
    let (upx, upy) = (c * wx - s * wy, c * wy + s * wx);
    let (umx, umy) = (c * wx + s * wy, c * wy - s * wx);
    Some([
        lift(upx, upy, &f.p0, &f.radii0),
        lift(upx, upy, &f.p1, &f.radii1),
        lift(umx, umy, &f.p1, &f.radii1),
        lift(umx, umy, &f.p0, &f.radii0),
    ])
}

/// The outline of a solid, or `None` when a perspective camera cannot see all of it.
pub fn outline_of_solid(solid: &Solid, camera: &Camera) -> Option<Outline> {
    match solid {
        Solid::Ellipsoid(e) => Some(Outline {
            ellipses: [Some(ellipse_of_ellipsoid(e, camera)?), None],
            quad: None,
        }),
        Solid::Frustum(f) => {
            let e0 = ellipse_of_ellipsoid(&f.end_disc(0), camera)?;
            let e1 = ellipse_of_ellipsoid(&f.end_disc(1), camera)?;
            let quad = match silhouette_generators(f, camera) {
                Some(g) => {
                    let mut q = [Vector2::zeros(); 4];
                    for (dst, p) in q.iter_mut().zip(&g) {
                        *dst = camera.project(p)?;
                    }
                    Some(q)
                }
                None => None,
            };
            Some(Outline {
                ellipses: [Some(e0), Some(e1)],
                quad,
            })
        }
    }
}
