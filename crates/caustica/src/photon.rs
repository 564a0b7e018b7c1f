//! Photons: emission from lights, specular paths, the photon map and the radiance estimate.

pub mod kd_tree;
