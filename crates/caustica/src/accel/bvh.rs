//! BVH
