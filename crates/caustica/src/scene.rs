//! Scenes: the `.ray` reader and the renderable scene built from it.

pub mod ray_file;
