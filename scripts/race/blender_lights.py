"""Blender's light units in caustica's add-on against Cycles: a grey floor (Specular 0) lit by
one light of each kind — point, spot, sun, square and disk area lights, an emissive mesh, the
world's colour — rendered by Cycles and by the add-on at the same size, and their means over the
lit floor compared. Cycles converges on a diffuse floor, so the two must agree.

    blender -b --factory-startup --python-use-system-env -P scripts/race/blender_lights.py -- OUT_DIR [SAMPLES]

Needs the caustica package importable (PYTHONPATH) and prints a Markdown table.
"""
import math
import os
import sys

import bpy
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "blender"))
sys.path.insert(0, os.path.join(ROOT, "scripts", "scenes"))
import caustica  # noqa: E402
import caustica_blender  # noqa: E402
from blender_build import add_light, camera, grey_floor  # noqa: E402

argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
out = os.path.abspath(argv[0] if argv else "blender-lights")
samples = int(argv[1]) if len(argv) > 1 else 512
os.makedirs(out, exist_ok=True)
caustica_blender.register()
W, H = 64, 48


def base_scene():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    grey_floor(40.0)
    camera(scene, (0.0, 0.0, 8.0))
    world = bpy.data.worlds.new("World")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
    scene.world = world
    scene.render.resolution_x, scene.render.resolution_y = W, H
    scene.render.resolution_percentage = 100
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    scene.view_settings.view_transform = "Standard"
    return scene


def setups():
    yield "point 1000 W", lambda s: add_light(s, "POINT", energy=1000.0, shadow_soft_size=0.0)
    yield "point 1000 W, radius 0.5 m", lambda s: add_light(s, "POINT", energy=1000.0, shadow_soft_size=0.5)
    yield "spot 1000 W, 60°, blend 0", lambda s: add_light(
        s, "SPOT", energy=1000.0, shadow_soft_size=0.0, spot_size=math.radians(60.0), spot_blend=0.0
    )

    def sun(s):
        o = add_light(s, "SUN", energy=3.0, angle=0.0)
        o.rotation_euler = (math.radians(30.0), 0.0, 0.0)

    yield "sun 3 W/m², 30° from zenith", sun
    yield "square area 1 m, 500 W", lambda s: add_light(s, "AREA", energy=500.0, shape="SQUARE", size=1.0)
    yield "disk area 1 m, 500 W", lambda s: add_light(s, "AREA", energy=500.0, shape="DISK", size=1.0)

    def as_surface(shape):
        def setup(s):
            s.caustica.area_lights = "SURFACE"
            add_light(s, "AREA", energy=500.0, shape=shape, size=1.0)

        return setup

    yield "square area 1 m, 500 W, as a glowing surface", as_surface("SQUARE")
    yield "disk area 1 m, 500 W, as a glowing surface", as_surface("DISK")

    yield "spot 1000 W, 60°, blend 0.5", lambda s: add_light(
        s, "SPOT", energy=1000.0, shadow_soft_size=0.0, spot_size=math.radians(60.0), spot_blend=0.5
    )

    def glowing(s):
        bpy.ops.mesh.primitive_plane_add(size=1.0, location=(0.0, 0.0, 3.0))
        m = bpy.data.materials.new("Glow")
        m.use_nodes = True
        bsdf = m.node_tree.nodes["Principled BSDF"]
        bsdf.inputs["Base Color"].default_value = (0.0, 0.0, 0.0, 1.0)
        bsdf.inputs["Specular"].default_value = 0.0
        bsdf.inputs["Emission"].default_value = (1.0, 1.0, 1.0, 1.0)
        bsdf.inputs["Emission Strength"].default_value = 50.0
        bpy.context.object.data.materials.append(m)

    yield "emissive 1 m square, strength 50", glowing

    def world(s):
        s.world.node_tree.nodes["Background"].inputs["Strength"].default_value = 1.0
        s.world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.8, 0.8, 0.8, 1.0)

    yield "world colour 0.8", world


def render(scene, engine, path):
    scene.render.engine = engine
    if engine == "CYCLES":
        scene.cycles.samples = samples
        scene.cycles.use_denoising = False
        scene.cycles.filter_width = 0.01
        scene.cycles.max_bounces = 4
    else:
        scene.caustica.integrator = "PATH"
        scene.caustica.time_limit = 0.0
        scene.caustica.passes = 256
    scene.render.filepath = path
    bpy.ops.render.render(write_still=True)
    return caustica.read_exr(path)


print("| light | region | caustica | Cycles | difference |")
print("|---|---|---|---|---:|")
for name, setup in setups():
    scene = base_scene()
    setup(scene)
    slug = name.split()[0] + "-" + name.split()[1]
    ours = render(scene, "CAUSTICA", os.path.join(out, slug + "-caustica.exr"))
    theirs = render(scene, "CYCLES", os.path.join(out, slug + "-cycles.exr"))
    # The centre is straight under the light; "ring" leaves out what an emissive square in
    # front of the camera hides.
    for region, (r0, r1, c0, c1) in {"centre": (18, 30, 26, 38), "whole": (0, H, 0, W), "ring": (0, 12, 0, W)}.items():
        a = ours[r0:r1, c0:c1].mean()
        b = theirs[r0:r1, c0:c1].mean()
        print(f"| {name} | {region} | {a:.4f} | {b:.4f} | {100.0 * (a / b - 1.0):+.2f}% |")
