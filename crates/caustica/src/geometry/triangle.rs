//! triangle
