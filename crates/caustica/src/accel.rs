//! Acceleration structures: the bounding volume hierarchy over all shapes, and the packets
//! that stand in for it in scenes of few squares and spheres.

pub mod bvh;
pub mod lanes;
pub mod shape_packets;
