//! Acceleration structures: the bounding volume hierarchy over all shapes.

pub mod bvh;
