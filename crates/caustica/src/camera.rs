//! The course camera (§4): a pinhole whose image plane is spanned by `u` and `v`.
//!
//! With `viewdir` V and `updir` U the UT skeleton uses the vectors as given: look = V,
//! u = (U × −V)·h·aspect, v = U·h with h = 2·tan(fov/2). Non-unit or non-perpendicular vectors
//! therefore change the field of view or shear the image, exactly as in the course renderer.

use crate::math::{Quat, Ray, Vec3};
use crate::scene::ray_file::ast::{CameraBasis, CameraDesc};

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
    /// The camera of a scene file.
    pub fn from_desc(desc: &CameraDesc) -> Camera {
        let aspect = desc.aspect_ratio.filter(|a| a.is_finite() && *a > 0.0).unwrap_or(1.0);
        let h = desc.fov_degrees.map_or(1.0, |fov| 2.0 * (fov.to_radians() * 0.5).tan());
        let (mut view, mut up) = (-Vec3::Z, Vec3::Y);
        if let Some(q) = desc.quaternion {
            let rotation = Quat::from_xyzw(q[0], q[1], q[2], q[3]).normalize();
            view = rotation * view;
            up = rotation * up;
        }
        let mut basis = desc.basis;
        if let Some(target) = desc.look_at {
            view = target - desc.position;
            up = desc.updir.unwrap_or(if view.cross(Vec3::Y).length_squared() < 1e-12 {
                Vec3::X
            } else {
                Vec3::Y
            });
            basis = CameraBasis::Orthonormal;
        } else if let (Some(v), Some(u)) = (desc.viewdir, desc.updir) {
            view = v;
            up = u;
        }
        match basis {
            CameraBasis::AsGiven => Camera::from_basis(desc.position, view, up, h, aspect),
            CameraBasis::Normalized => Camera::from_basis(
                desc.position,
                view.normalize_or_zero(),
                up.normalize_or_zero(),
                h,
                aspect,
            ),
            CameraBasis::Orthonormal => {
                let z = -view.normalize_or_zero();
                let x = up.cross(z).normalize_or_zero();
                let y = z.cross(x);
                Camera::from_basis(desc.position, -z, y, h, aspect)
            }
        }
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

#[cfg(test)]
mod tests {
    use super::*;

    fn desc() -> CameraDesc {
        CameraDesc {
            position: Vec3::new(0.0, 0.0, 5.0),
            viewdir: Some(-Vec3::Z),
            updir: Some(Vec3::Y),
            look_at: None,
            quaternion: None,
            fov_degrees: Some(90.0),
            aspect_ratio: Some(2.0),
            basis: CameraBasis::AsGiven,
            span: 0..0,
        }
    }

    #[test]
    fn fov_and_aspect_set_the_image_plane() {
        let cam = Camera::from_desc(&desc());
        // fov 90°: h = 2, so the top edge is at 45°.
        let top = cam.generate_ray(0.5, 1.0).dir;
        assert!((top.y.atan2(-top.z).to_degrees() - 45.0).abs() < 1e-3);
        let right = cam.generate_ray(1.0, 0.5).dir;
        assert!((right.x / -right.z - 2.0).abs() < 1e-5, "half-width = aspect · h / 2");
        assert_eq!(cam.height_for_width(512), 256);
        let (sx, sy) = cam.project(Vec3::new(1.0, -0.5, 0.0)).unwrap();
        let back = cam.generate_ray(sx, sy).dir;
        assert!((back - Vec3::new(1.0, -0.5, -5.0).normalize()).length() < 1e-5);
    }

    #[test]
    fn unnormalised_viewdir_narrows_the_view_as_in_the_course() {
        let mut d = desc();
        d.viewdir = Some(-Vec3::Z * 2.0);
        let cam = Camera::from_desc(&d);
        let top = cam.generate_ray(0.5, 1.0).dir;
        // look has length 2, v still spans h = 2: the top edge is at atan(1/2).
        assert!((top.y.atan2(-top.z) - 0.5f32.atan()).abs() < 1e-5);
        d.basis = CameraBasis::Orthonormal;
        let ortho = Camera::from_desc(&d);
        let top = ortho.generate_ray(0.5, 1.0).dir;
        assert!((top.y.atan2(-top.z).to_degrees() - 45.0).abs() < 1e-3);
    }

    #[test]
    fn default_view_and_look_at() {
        let mut d = desc();
        d.viewdir = None;
        d.updir = None;
        d.fov_degrees = None;
        d.position = Vec3::ZERO;
        let cam = Camera::from_desc(&d);
        assert_eq!(cam.generate_ray(0.5, 0.5).dir, -Vec3::Z);
        d.look_at = Some(Vec3::new(3.0, 0.0, 0.0));
        let cam = Camera::from_desc(&d);
        assert!((cam.generate_ray(0.5, 0.5).dir - Vec3::X).length() < 1e-6);
    }
}
