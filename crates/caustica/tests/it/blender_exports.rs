//! What Blender's own glTF exporter writes, from `scripts/scenes/blender_export.py` run
//! headless: the one-file (GLB) and separate forms read and render alike, and the lamp and each
//! material read as Blender means them. Without `blender` on the PATH the test is reported as
//! ignored (build.rs).

use caustica::description::PhysicalMaterial;
use caustica::light::Light;
use caustica::loader::{load, LoadSettings};
use caustica::material::Channel;
use caustica::math::Vec3;
use std::path::Path;
use std::process::Command;

#[test]
#[cfg_attr(not(caustica_blender), ignore = "blender is not on the PATH")]
fn blender_exports_read_as_blender_means_them() {
    let dir = std::env::temp_dir().join(format!("caustica-blender-{}", std::process::id()));
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scripts/scenes/blender_export.py");
    // No Cycles render (0 samples): the export alone.
    let out = Command::new("blender")
        .args(["-b", "--factory-startup", "-P"])
        .arg(&script)
        .arg("--")
        .arg(&dir)
        .arg("0")
        .output()
        .expect("blender runs");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let glb = load(&dir.join("scene.glb"), &LoadSettings::default()).unwrap_or_else(|e| panic!("{e}"));
    let separate = load(&dir.join("separate/scene.gltf"), &LoadSettings::default()).unwrap_or_else(|e| panic!("{e}"));
    for scene in [&glb, &separate] {
        // The one warning: Blender writes glass without a volume, read as solid (the ball is closed).
        assert!(
            scene.warnings().iter().all(|w| w.contains("read as solid glass")),
            "{:?}",
            scene.warnings()
        );
        // Blender's 1000 W point light: 1000/(4π) W/sr, as Cycles emits it.
        let lamps: Vec<Vec3> = (0..scene.lights().len())
            .filter_map(|i| match scene.lights().get(i) {
                Some(Light::Point { color, .. }) => Some(*color),
                _ => None,
            })
            .collect();
        assert_eq!(lamps.len(), 1, "{lamps:?}");
        let want = 1000.0 / (4.0 * std::f32::consts::PI);
        assert!(
            (lamps[0] - Vec3::splat(want)).abs().max_element() < 1e-3 * want,
            "{lamps:?}"
        );
        let materials = scene.materials();
        // Specular 0 in Blender: a bare Lambert floor of the base colour, no coat.
        let floor = materials
            .iter()
            .find(|m| m.diffuse == Channel::Constant(Vec3::splat(0.5)))
            .expect("the floor");
        assert_eq!(floor.physical, None, "{floor:?}");
        // The checker: a texture on the base colour, no coat either.
        assert!(materials.iter().any(|m| matches!(m.diffuse, Channel::Texture(_))
            && m.physical.is_none()
            && m.metallic_roughness.is_none()));
        // Copper: a conductor of the base colour's reflectance, GGX α = 0.3².
        assert!(
            materials.iter().any(|m| matches!(m.physical,
                Some(PhysicalMaterial::Conductor { reflectance: Some(Channel::Constant(r)), roughness, .. })
                    if (r - Vec3::new(0.95, 0.64, 0.54)).abs().max_element() < 1e-6 && (roughness - 0.09).abs() < 1e-6)),
            "{materials:?}"
        );
        // Glass: smooth, index 1.5, clear.
        assert!(
            materials
                .iter()
                .any(|m| m.transmissive == Channel::Constant(Vec3::ONE)
                    && m.index == Channel::Constant(Vec3::splat(1.5))),
            "{materials:?}"
        );
    }
    // The two forms make the same picture.
    let a = crate::common::render_integrator(&glb, "vcm", 24, 2, 5_000, 1);
    let b = crate::common::render_integrator(&separate, "vcm", 24, 2, 5_000, 1);
    assert_eq!(a.pixels, b.pixels);
    assert!(a.pixels.iter().any(|p| p.max_element() > 0.0), "lit");
    let _ = std::fs::remove_dir_all(&dir);
}
