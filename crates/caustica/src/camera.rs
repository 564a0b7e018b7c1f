//! The camera: a pinhole whose image plane is spanned by `u` and `v` (the course's camera, §4;
//! every scene format describes one of these, see [`CameraDesc`]).

use crate::description::CameraDesc;
use crate::math::{Ray, Vec3};

/// A pinhole camera.
#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    /// Eye position.
    pub eye: Vec3,
    /// Direction to the image-plane centre.
    pub look: Vec3,
    /// Image-plane horizontal span (left to right).
    pub u: Vec3,
    /// Image-plane vertical span (bottom to top).
    pub v: Vec3,
    /// Width / height.
    pub aspect_ratio: f32,
}

impl Default for Camera {
    /// The skeleton's default: at the origin looking down −z, +y up, normalised height 1.
    fn default() -> Self {
        Camera::from_basis(Vec3::ZERO, -Vec3::Z, Vec3::Y, 1.0, 1.0)
    }
}

impl Camera {
    /// The camera a scene describes.
    pub fn from_desc(desc: &CameraDesc) -> Camera {
        let mut camera = Camera::from_basis(desc.position, desc.view, desc.up, desc.height, desc.aspect_ratio);
        if let Some(right) = desc.right {
            camera.u = right * desc.height * desc.aspect_ratio;
        }
        camera
    }

    /// A camera from a view and up vector used as given (§4).
    pub fn from_basis(eye: Vec3, view: Vec3, up: Vec3, h: f32, aspect_ratio: f32) -> Camera {
        let x = up.cross(-view);
        Camera {
            eye,
            look: view,
            u: x * h * aspect_ratio,
            v: up * h,
            aspect_ratio,
        }
    }

    /// The primary ray through normalised screen point (sx, sy) ∈ [0, 1]², sy = 0 at the bottom;
    /// the direction is unit length.
    #[inline]
    pub fn generate_ray(&self, sx: f32, sy: f32) -> Ray {
        let dir = self.look + (sx - 0.5) * self.u + (sy - 0.5) * self.v;
        Ray::new(self.eye, dir.normalize_or_zero())
    }

    /// Where a world point lands on the screen, as (sx, sy) in [0, 1]² when visible; `None`
    /// behind the camera. Inverts [`Camera::generate_ray`].
    pub fn project(&self, p: Vec3) -> Option<(f32, f32)> {
        // Solve eye + s·(look + a·u + b·v) = p for (s, a, b).
        let m = crate::math::Mat3::from_cols(self.look, self.u, self.v);
        if m.determinant().abs() < 1e-20 {
            return None;
        }
        let sol = m.inverse() * (p - self.eye);
        if sol.x <= 0.0 {
            return None;
        }
        Some((sol.y / sol.x + 0.5, sol.z / sol.x + 0.5))
    }

    /// Image height for `width` pixels: round(width / aspect ratio), at least 1.
    pub fn height_for_width(&self, width: usize) -> usize {
        ((width as f32 / self.aspect_ratio).round() as usize).max(1)
    }
}
