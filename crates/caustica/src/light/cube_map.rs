//! Cube maps (skyboxes): six images around the scene, turned into the latitude–longitude map that
//! [`Environment`](super::Environment) samples, so one representation serves as the course
//! model's background and the physical model's sky.
//!
//! Faces are given in the order +x, −x, +y, −y, +z, −z. Two layouts:
//! - [`SkyboxLayout::Inside`]: the image of face ±a is what an observer at the centre sees
//!   looking along ±a, upright and unmirrored, +y up; the top face (+y) has its bottom edge
//!   towards −z, the bottom face (−y) its top edge towards −z. This is how `front` (−z), `back`,
//!   `left` (−x), `right`, `top` and `bottom` skybox images are drawn.
//! - [`SkyboxLayout::UtCubeMap`]: the UT course skeleton's `CubeMap::getColor` (2018–2019), whose
//!   x axis is mirrored: the `posx` image is seen looking along −x and `negx` along +x, and the
//!   top and bottom images are turned.

use super::environment::uv_to_direction;
use crate::description::SkyboxLayout;
use crate::math::{Vec2, Vec3};
use crate::texture::Texture;

/// The face (index into the six images) a unit direction looks into, and where on it (u to
/// the right, v up, both in [0, 1]).
pub fn face_lookup(layout: SkyboxLayout, d: Vec3) -> (usize, Vec2) {
    let a = d.abs();
    let at = |s: f32, t: f32, m: f32| Vec2::new(0.5 * (s / m + 1.0), 0.5 * (t / m + 1.0));
    match layout {
        SkyboxLayout::Inside => {
            if a.x >= a.y && a.x >= a.z {
                if d.x > 0.0 {
                    (0, at(d.z, d.y, a.x))
                } else {
                    (1, at(-d.z, d.y, a.x))
                }
            } else if a.y >= a.z {
                if d.y > 0.0 {
                    (2, at(d.x, d.z, a.y))
                } else {
                    (3, at(d.x, -d.z, a.y))
                }
            } else if d.z > 0.0 {
                (4, at(-d.x, d.y, a.z))
            } else {
                (5, at(d.x, d.y, a.z))
            }
        }
        SkyboxLayout::UtCubeMap => {
            if a.x >= a.y && a.x >= a.z {
                if d.x < 0.0 {
                    (0, at(-d.z, d.y, a.x))
                } else {
                    (1, at(d.z, d.y, a.x))
                }
            } else if a.y >= a.z {
                if d.y > 0.0 {
                    (2, at(-d.x, -d.z, a.y))
                } else {
                    (3, at(-d.x, d.z, a.y))
                }
            } else if d.z > 0.0 {
                (4, at(-d.x, d.y, a.z))
            } else {
                (5, at(d.x, d.y, a.z))
            }
        }
    }
}

/// The latitude–longitude image of a cube map (the environment's layout), 4N × 2N texels for
/// faces of N texels across (at most 4096 × 2048), each the bilinear value of its face at the
/// texel's centre direction.
pub fn to_lat_long(faces: &[Texture; 6], layout: SkyboxLayout) -> Texture {
    let n = faces.iter().map(Texture::width).max().unwrap_or(1).clamp(1, 1024);
    let (w, h) = (4 * n, 2 * n);
    let mut texels = Vec::with_capacity(w * h);
    for y in 0..h {
        for x in 0..w {
            let uv = Vec2::new((x as f32 + 0.5) / w as f32, (y as f32 + 0.5) / h as f32);
            let (face, st) = face_lookup(layout, uv_to_direction(uv));
            texels.push(faces[face].lookup(st));
        }
    }
    Texture::new(w, h, texels).expect("the size matches")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::Environment;
    use crate::math::Mat3;

    /// Face i is grey level i+1 over 10; with a horizontal ramp in red (red = u) and a vertical
    /// one in green (green = v, up).
    fn faces() -> [Texture; 6] {
        std::array::from_fn(|i| {
            let n = 32;
            let texels = (0..n * n)
                .map(|k| {
                    let (x, y) = (k % n, k / n);
                    let u = (x as f32 + 0.5) / n as f32;
                    let v = 1.0 - (y as f32 + 0.5) / n as f32;
                    Vec3::new(u, v, (i + 1) as f32 / 10.0)
                })
                .collect();
            Texture::new(n, n, texels).unwrap()
        })
    }

    /// Looking at the centre of each face finds that face's centre; moving right and up on the
    /// face (as the layout says the observer sees it) raises u and v.
    #[test]
    fn inside_faces_are_upright_and_unmirrored() {
        // (looking along, the observer's right, the observer's up).
        let views = [
            (Vec3::X, Vec3::Z, Vec3::Y),
            (-Vec3::X, -Vec3::Z, Vec3::Y),
            (Vec3::Y, Vec3::X, Vec3::Z),
            (-Vec3::Y, Vec3::X, -Vec3::Z),
            (Vec3::Z, -Vec3::X, Vec3::Y),
            (-Vec3::Z, Vec3::X, Vec3::Y),
        ];
        for (i, (look, right, up)) in views.into_iter().enumerate() {
            // Right-handed: looking along `look`, right × up points back at the observer.
            assert!((right.cross(up) + look).length() < 1e-6, "face {i}");
            let (face, uv) = face_lookup(SkyboxLayout::Inside, look);
            assert_eq!(face, i);
            assert!((uv - Vec2::splat(0.5)).length() < 1e-6);
            let (_, moved) = face_lookup(SkyboxLayout::Inside, (look + 0.4 * right + 0.2 * up).normalize());
            assert!((moved - Vec2::new(0.7, 0.6)).length() < 1e-5, "face {i}: {moved}");
        }
    }

    #[test]
    fn the_ut_layout_swaps_the_x_faces() {
        assert_eq!(face_lookup(SkyboxLayout::UtCubeMap, -Vec3::X).0, 0);
        assert_eq!(face_lookup(SkyboxLayout::UtCubeMap, Vec3::X).0, 1);
        let (face, uv) = face_lookup(SkyboxLayout::UtCubeMap, Vec3::new(0.4, 0.2, -1.0).normalize());
        assert_eq!(face, 5);
        assert!((uv - Vec2::new(0.7, 0.6)).length() < 1e-5);
    }

    /// The environment made from the cube map returns, in any direction, the face texel the
    /// direction looks at (to the lat-long map's resolution).
    #[test]
    fn the_lat_long_map_reproduces_the_faces() {
        let faces = faces();
        let env = Environment::new(
            Vec3::ONE,
            Some(to_lat_long(&faces, SkyboxLayout::Inside)),
            Mat3::IDENTITY,
        );
        let mut rng = crate::sampling::Rng::new(9, 0);
        for _ in 0..2000 {
            let d = crate::sampling::sample_uniform_sphere(rng.uniform2());
            let (face, uv) = face_lookup(SkyboxLayout::Inside, d);
            let seen = env.radiance(d);
            let expected = faces[face].lookup(uv);
            // Off the cube's edges, one lat-long texel spans at most ~2 face texels.
            let near_edge = uv.min_element() < 0.05 || uv.max_element() > 0.95;
            if !near_edge {
                assert!(
                    (seen - expected).abs().max_element() < 0.08,
                    "{d}: {seen} vs {expected}"
                );
                assert!((seen.z - expected.z).abs() < 1e-6, "{d}: the face's own grey");
            }
        }
    }
}
