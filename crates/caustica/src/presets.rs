//! Built-in scenes: the default scene of `caustica render` and small scenes for tests.

/// The default scene: a gold ring on a floor, lit by one point light, casting a nephroid.
pub const RING: &str = include_str!("../../../scenes/ring.ray");
