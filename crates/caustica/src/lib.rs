//! caustica: a photon-mapping renderer for caustics that reads SBT-raytracer `.ray` scenes.
//!
//! The pipeline runs one way: a `.ray` file is parsed into a plain [`scene::ray_file::ast`]
//! description, built into a [`scene::Scene`] (world-space shapes, BVH, lights, materials),
//! lights emit photons into a [`photon`] map, and an [`integrator`] turns camera rays into a
//! [`film::Film`] that is written as PNG or EXR.
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod accel;
pub mod error;
pub mod geometry;
pub mod math;
pub mod photon;
pub mod scene;

pub use error::{Error, ParseError, Result};
