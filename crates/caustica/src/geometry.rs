//! Shapes in world space and their ray intersections.

pub mod triangle;
