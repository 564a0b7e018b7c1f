//! Pictures of the photon map: photons drawn through the camera as points, and PLY export.

use super::{Photon, REFLECTED, REFRACTED};
use crate::error::Result;
use crate::film::Film;
use crate::image_io::write_atomically;
use crate::math::{Ray, Vec3};
use crate::scene::Scene;
use std::io::Write;
use std::path::Path;

/// The colour a photon is drawn in: reflected yellow, refracted blue, both green, direct white.
pub fn photon_color(flags: u8) -> Vec3 {
    match (flags & REFLECTED != 0, flags & REFRACTED != 0) {
        (true, false) => Vec3::new(1.0, 0.85, 0.1),
        (false, true) => Vec3::new(0.25, 0.45, 1.0),
        (true, true) => Vec3::new(0.3, 1.0, 0.4),
        (false, false) => Vec3::ONE,
    }
}

/// Draws the photons the camera can see as one-pixel points on black.
pub fn draw_photons(scene: &Scene, photons: &[Photon], width: usize, height: usize) -> Film {
    let mut film = Film::new(width, height);
    let camera = scene.camera().fitted(width, height);
    for photon in photons {
        let Some((sx, sy)) = camera.project(photon.position) else {
            continue;
        };
        if !(0.0..1.0).contains(&sx) || !(0.0..1.0).contains(&sy) {
            continue;
        }
        let to = photon.position - camera.eye;
        let distance = to.length();
        let ray = Ray::new(camera.eye, to / distance);
        let visible = scene
            .intersect(&ray, f32::INFINITY)
            .is_none_or(|hit| hit.t >= distance * (1.0 - 1e-3));
        if !visible {
            continue;
        }
        let x = ((sx * width as f32) as usize).min(width - 1);
        let y = (((1.0 - sy) * height as f32) as usize).min(height - 1);
        film.pixels[y * width + x] = photon_color(photon.flags);
    }
    film
}

/// Writes photons as a binary little-endian PLY point cloud with position, colour (path kind),
/// power and flags.
pub fn write_ply(path: &Path, photons: &[Photon]) -> Result<()> {
    write_atomically(path, |tmp| {
        let file = std::fs::File::create(tmp).map_err(|e| e.to_string())?;
        let mut w = std::io::BufWriter::new(file);
        let header = format!(
            "ply\nformat binary_little_endian 1.0\ncomment caustica photon map\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\nproperty float power_r\nproperty float power_g\nproperty float power_b\nproperty uchar flags\nend_header\n",
            photons.len()
        );
        w.write_all(header.as_bytes()).map_err(|e| e.to_string())?;
        for p in photons {
            let mut record = Vec::with_capacity(31);
            for c in p.position.to_array() {
                record.extend_from_slice(&c.to_le_bytes());
            }
            record.extend(photon_color(p.flags).to_array().map(|c| (c * 255.0) as u8));
            for c in p.power().to_array() {
                record.extend_from_slice(&c.to_le_bytes());
            }
            record.push(p.flags);
            w.write_all(&record).map_err(|e| e.to_string())?;
        }
        w.flush().map_err(|e| e.to_string())
    })
}
