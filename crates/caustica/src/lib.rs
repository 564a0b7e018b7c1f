//! caustica: a photon-mapping renderer for caustics that reads SBT-raytracer `.ray` scenes.
//!
//! The pipeline runs one way (docs/architecture.md): a reader in [`format`] turns a scene file
//! into a format-neutral [`description::SceneDescription`], [`scene::build`] makes it a
//! renderable [`scene::Scene`] (world-space shapes, BVHs, materials, [`light`]s), lights emit
//! [`photon`]s into a photon map, and an [`integrator`] run by a
//! [`RenderSession`](integrator::RenderSession) turns camera rays into a [`film::Film`] that is
//! written as PNG or EXR.
// Unsafe code only in the audited SIMD module (`accel::lanes`).
#![deny(unsafe_code)]
#![warn(missing_docs)]

pub mod accel;
pub mod bsdf;
pub mod camera;
pub mod description;
pub mod diagnostic;
pub mod error;
pub mod film;
pub mod format;
pub mod geometry;
pub mod image_io;
pub mod integrator;
pub mod light;
pub mod loader;
pub mod material;
pub mod math;
pub mod medium;
pub mod photon;
pub mod presets;
pub mod preview;
pub mod progress;
pub mod sampling;
pub mod scene;
pub mod spectrum;
pub mod texture;

pub use error::{Error, ParseError, Result};
