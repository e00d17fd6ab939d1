//! Cameras (thesis 2.4): perspective, orthographic and weak perspective, in pixels.
//!
//! Pixel coordinates: origin top-left, x right, y down; integer coordinates are pixel centres
//! (OpenCV's convention), so pixel `(i, j)` covers `[i - 0.5, i + 0.5] x [j - 0.5, j + 0.5]`.

use crate::error::{finite, positive, CoreError, Result};
use nalgebra::{Matrix3x4, Vector2, Vector3};

/// How 3D points reach the image plane.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Projection {
    /// Pinhole: `u = f X / Z + cx`.
    Perspective,
    /// Parallel projection: `u = f X + cx`, `f` in pixels per metre.
    Orthographic,
    /// Scaled orthographic: `u = f X / z_ref + cx`, exact for points at depth `z_ref`.
    WeakPerspective { reference_depth: f64 },
}

/// Intrinsics and projection model. The camera sits at the origin looking along +Z.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    pub projection: Projection,
    /// Focal length in pixels (pixels per metre for orthographic).
    pub focal: f64,
    pub cx: f64,
    pub cy: f64,
}

/// Nearest depth (metres) at which perspective geometry is drawn; nearer solids are skipped.
pub const NEAR_PLANE: f64 = 0.01;
/// Largest focal length and principal-point offset, pixels: far beyond any real camera for
/// images of at most 8192 pixels a side.
pub const MAX_INTRINSIC_PX: f64 = 1e7;

/// `Ok` when `|value| <= MAX_INTRINSIC_PX`; else an error naming `name`.
fn within_intrinsic(name: &'static str, value: f64) -> Result<f64> {
    if value.abs() <= MAX_INTRINSIC_PX {
        Ok(value)
    } else {
        Err(CoreError::OutOfRange {
            name,
            expected: "within +-1e7 pixels",
            value,
        })
    }
}

impl Camera {
    /// A pinhole camera.
    pub fn perspective(focal: f64, cx: f64, cy: f64) -> Result<Self> {
        Self::checked(Projection::Perspective, focal, cx, cy)
    }

    /// An orthographic camera with `scale` pixels per metre.
    pub fn orthographic(scale: f64, cx: f64, cy: f64) -> Result<Self> {
        Self::checked(Projection::Orthographic, scale, cx, cy)
    }

    /// A weak-perspective camera: orthographic at the scale a pinhole has at `reference_depth`.
    pub fn weak_perspective(focal: f64, cx: f64, cy: f64, reference_depth: f64) -> Result<Self> {
        positive("reference_depth", reference_depth)?;
        Self::checked(
            Projection::WeakPerspective { reference_depth },
            focal,
            cx,
            cy,
        )
    }

    /// The default camera of SPEC 3 for an image: perspective, focal = image width,
    /// principal point at the image centre.
    pub fn default_for_image(width: u32, height: u32) -> Result<Self> {
        Self::perspective(
            f64::from(width),
            (f64::from(width) - 1.0) / 2.0,
            (f64::from(height) - 1.0) / 2.0,
        )
    }

    fn checked(projection: Projection, focal: f64, cx: f64, cy: f64) -> Result<Self> {
        positive("focal", focal)?;
        // Beyond these, projected coordinates of a body in view reach 1e300 and costs overflow.
        within_intrinsic("focal", focal)?;
        within_intrinsic("cx", finite("cx", cx)?)?;
        within_intrinsic("cy", finite("cy", cy)?)?;
        if let Projection::WeakPerspective { reference_depth } = projection {
            if reference_depth < NEAR_PLANE {
                return Err(CoreError::OutOfRange {
                    name: "reference_depth",
                    expected: "at least 0.01 metres",
                    value: reference_depth,
                });
            }
        }
        Ok(Camera {
            projection,
            focal,
            cx,
            cy,
        })
    }

    /// Pixels per metre of the affine cameras; `None` for perspective.
    pub fn affine_scale(&self) -> Option<f64> {
        match self.projection {
            Projection::Perspective => None,
            Projection::Orthographic => Some(self.focal),
            Projection::WeakPerspective { reference_depth } => Some(self.focal / reference_depth),
        }
    }

    /// The 3x4 projection matrix `P` with `(u w, v w, w) = P (X, Y, Z, 1)`.
    pub fn matrix(&self) -> Matrix3x4<f64> {
        match self.affine_scale() {
            None => Matrix3x4::new(
                self.focal, 0.0, self.cx, 0.0, //
                0.0, self.focal, self.cy, 0.0, //
                0.0, 0.0, 1.0, 0.0,
            ),
            Some(s) => Matrix3x4::new(
                s, 0.0, 0.0, self.cx, //
                0.0, s, 0.0, self.cy, //
                0.0, 0.0, 0.0, 1.0,
            ),
        }
    }

    /// Projects a point; `None` when a perspective camera cannot see it (depth <= 0).
    pub fn project(&self, p: &Vector3<f64>) -> Option<Vector2<f64>> {
        match self.affine_scale() {
            None => (p.z > 0.0).then(|| {
                Vector2::new(
                    self.focal * p.x / p.z + self.cx,
                    self.focal * p.y / p.z + self.cy,
                )
            }),
            Some(s) => Some(Vector2::new(s * p.x + self.cx, s * p.y + self.cy)),
        }
    }

    /// Whether the projection is perspective (the camera centre is a point, not a direction).
    pub fn is_perspective(&self) -> bool {
        matches!(self.projection, Projection::Perspective)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pinhole_formula_is_exact() {
        let cam = Camera::perspective(600.0, 320.0, 240.0).unwrap();
        let p = Vector3::new(0.3, -0.2, 2.0);
        let uv = cam.project(&p).unwrap();
        assert_eq!(
            uv,
            Vector2::new(600.0 * 0.3 / 2.0 + 320.0, 600.0 * -0.2 / 2.0 + 240.0)
        );
        assert!(cam.project(&Vector3::new(0.0, 0.0, -1.0)).is_none());
        let h = cam.matrix() * p.push(1.0);
        assert!((h.x / h.z - uv.x).abs() < 1e-12 && (h.y / h.z - uv.y).abs() < 1e-12);
    }

    #[test]
    fn affine_cameras_ignore_depth() {
        let ortho = Camera::orthographic(200.0, 10.0, 20.0).unwrap();
        let weak = Camera::weak_perspective(600.0, 10.0, 20.0, 3.0).unwrap();
        for z in [-5.0, 0.5, 7.0] {
            let p = Vector3::new(0.25, 0.5, z);
            assert_eq!(ortho.project(&p).unwrap(), Vector2::new(60.0, 120.0));
            assert_eq!(weak.project(&p).unwrap(), Vector2::new(60.0, 120.0));
        }
    }

    #[test]
    fn bad_intrinsics_are_named() {
        assert_eq!(
            Camera::perspective(f64::NAN, 0.0, 0.0)
                .unwrap_err()
                .to_string(),
            "focal must be finite, got NaN"
        );
        assert!(Camera::perspective(-1.0, 0.0, 0.0).is_err());
        assert!(Camera::weak_perspective(500.0, 0.0, 0.0, 0.0).is_err());
    }
}
