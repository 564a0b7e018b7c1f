//! The cylinder: radius 1 about +z, z ∈ [0, 1] — the cone with equal radii, built exactly.

use super::cone::Cone;

/// The cylinder as a cone with equal radii (no course slope clamp: that quirk belongs to `cone`).
pub fn cylinder(capped: bool) -> Cone {
    Cone {
        bottom_radius: 1.0,
        top_radius: 1.0,
        height: 1.0,
        capped,
        doubled_normal_z: false,
    }
}
