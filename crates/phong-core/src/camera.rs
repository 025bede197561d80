//! Cameras: look-at placement and a perspective (as `gluPerspective`) or
//! orthographic projection.
//!
//! A perspective camera gives a view direction per point (local viewer), an
//! orthographic one a constant direction (infinite viewer): seed 000, the
//! slide on the view direction ("costante con proiezione ortografica,
//! diversa per ogni punto per proiezione prospettica").

use crate::{Error, View};
use glam::{Mat4, Vec3, Vec4};

/// How the camera projects.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Projection {
    /// Perspective with vertical field of view `fov_y_deg` in (0, 180) degrees, as `gluPerspective`.
    Perspective {
        /// Vertical field of view, degrees.
        fov_y_deg: f32,
    },
    /// Orthographic; the view volume is `height` world units tall.
    Orthographic {
        /// Height of the view volume, world units.
        height: f32,
    },
}

/// Which view vector the shading uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Viewer {
    /// `V = normalize(eye − P)`, per point.
    Local,
    /// One constant `V = normalize(eye − target)`.
    Infinite,
}

/// A look-at camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    eye: Vec3,
    target: Vec3,
    up: Vec3,
    projection: Projection,
    near: f32,
    far: f32,
}

impl Camera {
    /// A camera at `eye` looking at `target` with `up` (not parallel to the view direction),
    /// clipping at `0 < near < far` (orthographic: `near` may be <= 0, `near < far`).
    pub fn new(eye: Vec3, target: Vec3, up: Vec3, projection: Projection, near: f32, far: f32) -> Result<Self, Error> {
        for (what, v) in [("camera position", eye), ("camera target", target)] {
            if !v.is_finite() {
                return Err(Error::InvalidPosition {
                    what,
                    value: v.to_array(),
                });
            }
        }
        let fwd = (target - eye).normalize_or_zero();
        if fwd == Vec3::ZERO {
            return Err(Error::InvalidDirection {
                what: "camera target − position",
                value: (target - eye).to_array(),
            });
        }
        let upn = up.normalize_or_zero();
        if upn == Vec3::ZERO {
            return Err(Error::InvalidDirection {
                what: "camera up",
                value: up.to_array(),
            });
        }
        if fwd.cross(upn).length() < 1e-6 {
            return Err(Error::Degenerate(format!(
                "camera up [{}, {}, {}] is parallel to the view direction (from position to target); give another `up`",
                up.x, up.y, up.z
            )));
        }
        match projection {
            Projection::Perspective { fov_y_deg } => {
                if !(fov_y_deg > 0.0 && fov_y_deg < 180.0) {
                    return Err(Error::OutOfRange {
                        what: "fov",
                        range: "in (0, 180) degrees",
                        value: fov_y_deg,
                    });
                }
                if !(near > 0.0 && near.is_finite()) {
                    return Err(Error::OutOfRange {
                        what: "near",
                        range: "> 0 for a perspective camera",
                        value: near,
                    });
                }
            }
            Projection::Orthographic { height } => {
                if !(height > 0.0 && height.is_finite()) {
                    return Err(Error::OutOfRange {
                        what: "height",
                        range: "> 0",
                        value: height,
                    });
                }
                if !near.is_finite() {
                    return Err(Error::OutOfRange {
                        what: "near",
                        range: "finite",
                        value: near,
                    });
                }
            }
        }
        if !(far > near && far.is_finite()) {
            return Err(Error::OutOfRange {
                what: "far",
                range: "finite and > near",
                value: far,
            });
        }
        Ok(Camera {
            eye,
            target,
            up: upn,
            projection,
            near,
            far,
        })
    }

    /// Eye position.
    pub fn eye(&self) -> Vec3 {
        self.eye
    }
    /// Point looked at.
    pub fn target(&self) -> Vec3 {
        self.target
    }
    /// The projection.
    pub fn projection(&self) -> Projection {
        self.projection
    }
    /// Near clipping distance.
    pub fn near(&self) -> f32 {
        self.near
    }
    /// Far clipping distance.
    pub fn far(&self) -> f32 {
        self.far
    }
    /// Unit view direction, eye towards target.
    pub fn forward(&self) -> Vec3 {
        (self.target - self.eye).normalize()
    }

    /// `view_from_world`, as `gluLookAt`: rows `s`, `u`, `−f` with
    /// `f = normalize(target − eye)`, `s = normalize(f × up)`, `u = s × f`, then `−eye`.
    pub fn view_from_world(&self) -> Mat4 {
        let f = self.forward();
        let s = f.cross(self.up).normalize();
        let u = s.cross(f);
        Mat4::from_cols(
            Vec4::new(s.x, u.x, -f.x, 0.0),
            Vec4::new(s.y, u.y, -f.y, 0.0),
            Vec4::new(s.z, u.z, -f.z, 0.0),
            Vec4::new(-s.dot(self.eye), -u.dot(self.eye), f.dot(self.eye), 1.0),
        )
    }

    /// `clip_from_view` for an image of `aspect` = width / height, with
    /// OpenGL's clip volume (`−w <= z <= w`): `gluPerspective` or `glOrtho`.
    pub fn clip_from_view(&self, aspect: f32) -> Mat4 {
        match self.projection {
            Projection::Perspective { fov_y_deg } => {
                // gluPerspective: f = cot(fov/2); diag(f/aspect, f, (far+near)/(near−far)),
                // z row 2·far·near/(near−far), w = −z.
                let f = 1.0 / (fov_y_deg.to_radians() * 0.5).tan();
                let (n, fa) = (self.near, self.far);
                Mat4::from_cols(
                    Vec4::new(f / aspect, 0.0, 0.0, 0.0),
                    Vec4::new(0.0, f, 0.0, 0.0),
                    Vec4::new(0.0, 0.0, (fa + n) / (n - fa), -1.0),
                    Vec4::new(0.0, 0.0, 2.0 * fa * n / (n - fa), 0.0),
                )
            }
            Projection::Orthographic { height } => {
                // glOrtho(−w, w, −h, h, near, far) with h = height/2, w = h·aspect.
                let h = height * 0.5;
                let w = h * aspect;
                let (n, fa) = (self.near, self.far);
                Mat4::from_cols(
                    Vec4::new(1.0 / w, 0.0, 0.0, 0.0),
                    Vec4::new(0.0, 1.0 / h, 0.0, 0.0),
                    Vec4::new(0.0, 0.0, -2.0 / (fa - n), 0.0),
                    Vec4::new(0.0, 0.0, -(fa + n) / (fa - n), 1.0),
                )
            }
        }
    }

    /// `clip_from_world = clip_from_view · view_from_world`.
    pub fn clip_from_world(&self, aspect: f32) -> Mat4 {
        self.clip_from_view(aspect) * self.view_from_world()
    }

    /// The default viewer of this camera: local for perspective, infinite for orthographic.
    pub fn default_viewer(&self) -> Viewer {
        match self.projection {
            Projection::Perspective { .. } => Viewer::Local,
            Projection::Orthographic { .. } => Viewer::Infinite,
        }
    }

    /// The [`View`] that shading uses for `viewer`.
    pub fn view(&self, viewer: Viewer) -> View {
        match viewer {
            Viewer::Local => View::Local { eye: self.eye },
            Viewer::Infinite => View::Infinite {
                to_viewer: self.eye - self.target,
            },
        }
    }

    /// View-space depth of `p` (distance along the view direction).
    pub fn depth_of(&self, p: Vec3) -> f32 {
        (p - self.eye).dot(self.forward())
    }
}

/// OpenGL's viewport transform for a `width × height` image stored top row first: clip-space
/// `c` (`w > 0`) to window `x` right and `y` down in pixels, and depth in [0, 1]
/// (`glDepthRange(0, 1)`); with `1/w`. Every renderer projects with this arithmetic (the CPU's
/// setup, its labels, the GPU's checks; the WGSL and the AVX2 projection repeat it, tested).
#[inline]
pub fn window_from_clip(c: Vec4, width: f32, height: f32) -> (Vec3, f32) {
    let iw = 1.0 / c.w;
    let x = (c.x * iw * 0.5 + 0.5) * width;
    let y = (0.5 - c.y * iw * 0.5) * height;
    (Vec3::new(x, y, c.z * iw * 0.5 + 0.5), iw)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn perspective_maps_near_and_far_to_clip_bounds() {
        let c = Camera::new(
            Vec3::new(0.0, 0.0, 5.0),
            Vec3::ZERO,
            Vec3::Y,
            Projection::Perspective { fov_y_deg: 90.0 },
            1.0,
            10.0,
        )
        .unwrap();
        let m = c.clip_from_world(1.0);
        // A point on the near plane maps to z/w = −1, on the far plane to +1.
        let p = m * Vec4::new(0.0, 0.0, 4.0, 1.0);
        assert!((p.z / p.w + 1.0).abs() < 1e-5);
        let p = m * Vec4::new(0.0, 0.0, -5.0, 1.0);
        assert!((p.z / p.w - 1.0).abs() < 1e-5);
        // fov 90°: at distance 2 the half height is 2, so y = 2 maps to y/w = 1.
        let p = m * Vec4::new(0.0, 2.0, 3.0, 1.0);
        assert!((p.y / p.w - 1.0).abs() < 1e-5);
    }

    #[test]
    fn orthographic_height() {
        let c = Camera::new(
            Vec3::new(0.0, 0.0, 5.0),
            Vec3::ZERO,
            Vec3::Y,
            Projection::Orthographic { height: 4.0 },
            0.1,
            10.0,
        )
        .unwrap();
        let p = c.clip_from_world(2.0) * Vec4::new(4.0, 2.0, 0.0, 1.0);
        assert!((p.x / p.w - 1.0).abs() < 1e-6 && (p.y / p.w - 1.0).abs() < 1e-6);
        assert_eq!(c.default_viewer(), Viewer::Infinite);
        assert_eq!(c.view(Viewer::Infinite).at(Vec3::new(1.0, 2.0, 3.0)), Vec3::Z);
    }

    #[test]
    fn rejects_bad_cameras() {
        let p = Projection::Perspective { fov_y_deg: 45.0 };
        assert!(Camera::new(Vec3::ONE, Vec3::ONE, Vec3::Y, p, 0.1, 10.0).is_err());
        assert!(Camera::new(Vec3::Y, Vec3::ZERO, Vec3::Y, p, 0.1, 10.0).is_err());
        assert!(Camera::new(Vec3::Z, Vec3::ZERO, Vec3::Y, p, 0.0, 10.0).is_err());
        assert!(Camera::new(Vec3::Z, Vec3::ZERO, Vec3::Y, p, 1.0, 0.5).is_err());
        let bad = Projection::Perspective { fov_y_deg: 180.0 };
        assert!(Camera::new(Vec3::Z, Vec3::ZERO, Vec3::Y, bad, 0.1, 10.0).is_err());
    }
}
