//! The library's integration tests, one module a file, in one test binary (one link instead of one
//! a file). `cargo test -p caustica --test it MODULE::` runs one file's tests.
//!
//! Apart, each its own binary: `fuzz_scene.rs` and `fuzz_formats.rs` install a counting
//! `#[global_allocator]` (and `fuzz_scene` a panic hook and a watchdog that ends the process),
//! which must not see other tests' allocations and panics.

#[path = "../common/mod.rs"]
mod common;

mod absorption;
mod area_light_faces;
mod camera_fit;
mod caustic_scenes;
mod caustics;
mod closed_forms;
mod corpus;
mod corpus_render;
mod density_estimate;
mod extensions;
mod field_scenes;
mod formats;
mod layers;
mod light_tracing;
mod lights;
mod media;
mod photon_budget;
mod physical;
mod rough_glass;
mod shadow_acne;
mod spectral;
mod textures;
mod vcm;
mod whitted;
