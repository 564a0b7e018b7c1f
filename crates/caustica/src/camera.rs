//! The camera: a pinhole whose image plane is spanned by `u` and `v` (the course's camera, §4;
//! every scene format describes one of these, see [`CameraDesc`]).

use crate::description::{CameraDesc, FovAxis, ThinLens};
use crate::math::{Ray, Vec2, Vec3};

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
    /// Which span keeps its field of view in an image of another aspect ([`Camera::fitted`]).
    pub fov_axis: FovAxis,
    /// A thin lens (depth of field); `None`: a pinhole at `eye`.
    pub lens: Option<ThinLens>,
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
        camera.fov_axis = desc.fov_axis;
        camera.lens = desc.lens.filter(|l| l.radius > 0.0 && l.focus > 0.0);
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
            fov_axis: FovAxis::Vertical,
            lens: None,
        }
    }

    /// The camera for a `width` × `height` image: itself when the image has its aspect (to the
    /// pixel), else widened or narrowed along one axis by the format's rule ([`FovAxis`]), so
    /// the picture is cropped or extended, never stretched.
    pub fn fitted(&self, width: usize, height: usize) -> Camera {
        if self.fits(width, height) {
            return self.clone();
        }
        let aspect = width as f32 / height as f32;
        let (du, dv) = (self.u.length(), self.v.length());
        let (su, sv) = match self.fov_axis {
            FovAxis::Vertical => (dv * aspect, dv),
            FovAxis::Shorter => {
                let s = du.min(dv);
                if aspect >= 1.0 {
                    (s * aspect, s)
                } else {
                    (s, s / aspect)
                }
            }
        };
        let scaled = |axis: Vec3, from: f32, to: f32| if from > 0.0 { axis * (to / from) } else { axis };
        Camera {
            u: scaled(self.u, du, su),
            v: scaled(self.v, dv, sv),
            aspect_ratio: aspect,
            ..self.clone()
        }
    }

    /// Whether a `width` × `height` image has this camera's aspect, to the pixel.
    fn fits(&self, width: usize, height: usize) -> bool {
        let rounded = |a: usize, aspect: f32| ((a as f32 * aspect).round() as usize).max(1);
        height == self.height_for_width(width) || width == rounded(height, self.aspect_ratio)
    }

    /// What [`Camera::fitted`] does for a `width` × `height` image, in words; `None` when the
    /// image has the camera's aspect.
    pub fn fit_note(&self, width: usize, height: usize) -> Option<String> {
        if self.fits(width, height) {
            return None;
        }
        let fitted = self.fitted(width, height);
        let kept = match self.fov_axis {
            FovAxis::Vertical => "the vertical field of view is kept (the format's rule)",
            FovAxis::Shorter => "the field of view spans the shorter side (pbrt's rule)",
        };
        let wider = fitted.aspect_ratio > self.aspect_ratio;
        let (side, change) = match (self.fov_axis, wider) {
            (FovAxis::Vertical, true) => ("sides", "extended"),
            (FovAxis::Vertical, false) => ("sides", "cropped"),
            (FovAxis::Shorter, _) if fitted.u.length() > self.u.length() * 1.0001 => ("sides", "extended"),
            (FovAxis::Shorter, _) if fitted.u.length() < self.u.length() * 0.9999 => ("sides", "cropped"),
            (FovAxis::Shorter, _) if fitted.v.length() > self.v.length() * 1.0001 => ("top and bottom", "extended"),
            (FovAxis::Shorter, _) => ("top and bottom", "cropped"),
        };
        Some(format!(
            "the image is {width}×{height} (aspect {:.3}) and the camera's frame {:.3}: {kept}, so the picture is {change} at the {side}, not stretched",
            fitted.aspect_ratio, self.aspect_ratio
        ))
    }

    /// The primary ray through normalised screen point (sx, sy) ∈ [0, 1]², sy = 0 at the bottom;
    /// the direction is unit length.
    ///
    /// A pinhole's ray is inlined into the caller (returned through memory, it cost the tile's
    /// set-up a stalled reload); a lens's is drawn out of line.
    #[inline(always)]
    pub fn generate_ray(&self, sx: f32, sy: f32) -> Ray {
        let dir = self.look + (sx - 0.5) * self.u + (sy - 0.5) * self.v;
        match self.lens {
            None => Ray::new(self.eye, dir.normalize_or_zero()),
            Some(lens) => self.lens_ray(lens, dir, sx, sy),
        }
    }

    /// [`Camera::generate_ray`] through a thin lens, given the pinhole ray's direction `dir`.
    #[inline(never)]
    fn lens_ray(&self, lens: ThinLens, dir: Vec3, sx: f32, sy: f32) -> Ray {
        // Through the point of the focus plane the pinhole ray meets, from a lens point drawn
        // from the screen point's bits (the same screen point, the same lens point).
        let axis = self.axis();
        let focus_point = self.eye + dir * (lens.focus / dir.dot(axis));
        let origin = self.lens_point(lens, hash_point(&[sx, sy]));
        Ray::new(origin, (focus_point - origin).normalize_or_zero())
    }

    /// The unit normal of the image plane, on the side the camera looks to.
    pub fn axis(&self) -> Vec3 {
        let n = self.u.cross(self.v).normalize_or_zero();
        if n.dot(self.look) < 0.0 {
            -n
        } else {
            n
        }
    }

    /// The lens point at `s` ∈ [0, 1)² (uniform over the aperture's disc).
    pub fn lens_point(&self, lens: ThinLens, s: Vec2) -> Vec3 {
        let d = crate::sampling::sample_uniform_disc(s) * lens.radius;
        self.eye + self.u.normalize_or_zero() * d.x + self.v.normalize_or_zero() * d.y
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

/// Two numbers in [0, 1) from the bits of `values`: the lens point of a screen point or of a
/// point seen through the lens, the same each time the same point is asked for.
pub fn hash_point(values: &[f32]) -> Vec2 {
    let h = values.iter().fold(0x9e37_79b9_7f4a_7c15u64, |h, v| {
        crate::sampling::mix64(h ^ u64::from(v.to_bits()))
    });
    Vec2::new(
        (h >> 40) as f32 / (1u64 << 24) as f32,
        ((h >> 16) & 0xff_ffff) as f32 / (1u64 << 24) as f32,
    )
}
