"""The race's Cornell box (`../shared/reference/cornell_caustics_point.ray`: a glass ball and a
mirror ball under a 2 W/sr point light) built in Blender, rendered through the add-on, and
compared with the independent reference (Mitsuba 3's particle tracer at 16,384 samples a pixel,
`cornell_caustics_point_ref.exr`) on the floor and on the glass ball's caustic, once with the
Glass BSDF and once with Principled glass. The balls are UV spheres (256 × 128), smooth shaded.

    PYTHONPATH=python blender -b --factory-startup --python-use-system-env \\
        -P scripts/race/blender_cornell.py -- OUT_DIR [SECONDS]

Prints a Markdown table of region means; the focus and caustic region are scripts/race/README.md's
(rows and columns from the top-left of the 160 × 160 image, less the pixels that see a ball).
"""
import math
import os
import sys

import bpy
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "blender"))
sys.path.insert(0, os.path.join(ROOT, "scripts", "race"))
import caustica  # noqa: E402
import caustica_blender  # noqa: E402
from metrics import CAUSTIC, FOCUS, dilate, specular_mask  # noqa: E402

argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
out = os.path.abspath(argv[0] if argv else "blender-cornell")
seconds = float(argv[1]) if len(argv) > 1 else 30.0
os.makedirs(out, exist_ok=True)
reference = os.path.join(ROOT, "..", "shared", "reference", "cornell_caustics_point_ref.exr")
caustica_blender.register()


def diffuse(name, rgb):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    p = m.node_tree.nodes["Principled BSDF"]
    p.inputs["Base Color"].default_value = (*rgb, 1.0)
    p.inputs["Specular"].default_value = 0.0
    return m


def shader(name, kind, **inputs):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    nodes = m.node_tree.nodes
    nodes.remove(nodes["Principled BSDF"])
    n = nodes.new(kind)
    for k, v in inputs.items():
        n.inputs[k].default_value = v
    m.node_tree.links.new(n.outputs["BSDF"], nodes["Material Output"].inputs["Surface"])
    return m


def wall(location, rotation, material):
    bpy.ops.mesh.primitive_plane_add(size=2.0, location=location, rotation=rotation)
    bpy.context.object.data.materials.append(material)


def ball(centre, material):
    bpy.ops.mesh.primitive_uv_sphere_add(segments=256, ring_count=128, radius=0.35, location=centre)
    bpy.ops.object.shade_smooth()
    bpy.context.object.data.materials.append(material)


def build(principled_glass):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    white = diffuse("White", (0.75, 0.75, 0.75))
    half = math.pi / 2.0
    # The file's y is up; Blender's planes face +z, turned as the file turns its squares.
    wall((0, 0, 0), (-half, 0, 0), white)
    wall((0, 2, 0), (half, 0, 0), white)
    wall((0, 1, -1), (0, 0, 0), white)
    wall((-1, 1, 0), (0, half, 0), diffuse("Red", (0.63, 0.065, 0.05)))
    wall((1, 1, 0), (0, -half, 0), diffuse("Green", (0.14, 0.45, 0.09)))
    if principled_glass:
        glass = bpy.data.materials.new("Glass")
        glass.use_nodes = True
        p = glass.node_tree.nodes["Principled BSDF"]
        p.inputs["Transmission"].default_value = 1.0
        p.inputs["IOR"].default_value = 1.5
        p.inputs["Roughness"].default_value = 0.0
        p.inputs["Base Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    else:
        glass = shader("Glass", "ShaderNodeBsdfGlass", IOR=1.5, Roughness=0.0, Color=(1, 1, 1, 1))
    ball((-0.45, 0.35, -0.2), glass)
    ball((0.45, 0.35, 0.3), shader("Mirror", "ShaderNodeBsdfGlossy", Roughness=0.0, Color=(1, 1, 1, 1)))
    light = bpy.data.lights.new("Lamp", type="POINT")
    light.energy = 2.0 * 4.0 * math.pi  # 2 W/sr
    light.shadow_soft_size = 0.0
    lamp = bpy.data.objects.new("Lamp", light)
    lamp.location = (0.0, 1.8, 0.0)
    scene.collection.objects.link(lamp)
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    cam.data.sensor_fit = "AUTO"  # a square image: 40° both ways
    cam.data.angle = math.radians(40.0)
    cam.location = (0.0, 1.0, 3.6)
    scene.collection.objects.link(cam)
    scene.camera = cam
    scene.world = None
    scene.render.engine = "CAUSTICA"
    scene.caustica.integrator = "VCM"
    scene.caustica.time_limit = seconds
    scene.render.resolution_x, scene.render.resolution_y = 160, 160
    scene.render.resolution_percentage = 100
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    return scene


def main():
    ref = caustica.read_exr(reference)
    # The reference's particle tracer leaves every pixel that sees a specular ball black: those
    # pixels are left out (metrics.py's mask; the whole image's grown by a pixel).
    keep = ~specular_mask("point")
    regions = {
        "floor, front (150–159, all)": (np.s_[150:160, :], keep),
        "back wall (20–80, 20–140)": (np.s_[20:81, 20:141], keep),
        "focus (135–139, 41–45, 17 px)": (FOCUS, keep),
        "caustic region (134–142, 36–60, 141 px)": (CAUSTIC, keep),
        "whole image": (np.s_[:, :], ~dilate(~keep)),
    }
    print("| glass | region | add-on | reference | difference |")
    print("|---|---|---:|---:|---:|")
    for name, principled_glass in [("Glass BSDF", False), ("Principled", True)]:
        scene = build(principled_glass)
        scene.render.filepath = os.path.join(out, name.replace(" ", "-") + ".exr")
        bpy.ops.render.render(write_still=True)
        image = caustica.read_exr(scene.render.filepath)
        for region, (where, mask) in regions.items():
            a = float(image[where][mask[where]].mean())
            b = float(ref[where][mask[where]].mean())
            print(f"| {name} | {region} | {a:.4f} | {b:.4f} | {100.0 * (a / b - 1.0):+.1f}% |")


if __name__ == "__main__":
    main()
