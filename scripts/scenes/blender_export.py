"""Builds a small scene in Blender and writes it as Blender's glTF exporter writes it, in both
forms (one .glb, and .gltf + .bin + .png), with a Cycles render of it beside them: what a
Blender user hands caustica. A glass ball over a grey floor under a point light (its caustic
lies under it), a copper ball of roughness 0.3, and a cube whose faces carry a checker image
texture; the camera is Blender's default 16:9 one.

    blender -b --factory-startup -P scripts/scenes/blender_export.py -- OUT_DIR [CYCLES_SAMPLES]

OUT_DIR receives scene.glb, separate/scene.gltf (with its .bin and image), and, unless
CYCLES_SAMPLES is 0, cycles.exr (320×180, path tracing, filter width 0.01 px so pixels are box
averages). The floor lit straight from the lamp converges in Cycles, so caustica's render of
either file can be compared with it there; the caustic cannot be (Cycles' path tracer does not
find it).
"""
import math
import os
import sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from blender_build import add_light, camera  # noqa: E402

argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
out = os.path.abspath(argv[0] if argv else "blender-export")
samples = int(argv[1]) if len(argv) > 1 else 256
os.makedirs(os.path.join(out, "separate"), exist_ok=True)

bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene


def principled(name, **inputs):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    bsdf = m.node_tree.nodes["Principled BSDF"]
    for key, value in inputs.items():
        bsdf.inputs[key].default_value = value
    return m, bsdf


def place(obj, material):
    obj.data.materials.append(material)
    return obj


# The floor: 10 m square, grey, rough.
bpy.ops.mesh.primitive_plane_add(size=10.0, location=(0.0, 0.0, 0.0))
floor, _ = principled("Floor", **{"Base Color": (0.5, 0.5, 0.5, 1.0), "Roughness": 1.0, "Specular": 0.0})
place(bpy.context.object, floor)

# Glass: transmission 1, IOR 1.5, smooth; a closed mesh, so the exporter's file reads as solid glass.
bpy.ops.mesh.primitive_uv_sphere_add(segments=64, ring_count=32, radius=0.8, location=(0.0, 0.0, 0.8))
bpy.ops.object.shade_smooth()
glass, _ = principled(
    "Glass", **{"Base Color": (1.0, 1.0, 1.0, 1.0), "Transmission": 1.0, "IOR": 1.5, "Roughness": 0.0}
)
place(bpy.context.object, glass)

# Copper, roughness 0.3.
bpy.ops.mesh.primitive_uv_sphere_add(segments=48, ring_count=24, radius=0.6, location=(2.0, 1.2, 0.6))
bpy.ops.object.shade_smooth()
copper, _ = principled(
    "Copper", **{"Base Color": (0.95, 0.64, 0.54, 1.0), "Metallic": 1.0, "Roughness": 0.3}
)
place(bpy.context.object, copper)

# A cube with a checker image texture (8×8 texels, sRGB) on its base colour.
image = bpy.data.images.new("checker", width=8, height=8)
pixels = []
for y in range(8):
    for x in range(8):
        v = 0.9 if (x + y) % 2 == 0 else 0.1
        pixels += [v, v * 0.5, 0.1, 1.0]
image.pixels = pixels
image.filepath_raw = os.path.join(out, "checker.png")
image.file_format = "PNG"
image.save()
bpy.ops.mesh.primitive_cube_add(size=1.0, location=(-2.0, 1.0, 0.5))
boxed, bsdf = principled("Checker", **{"Roughness": 1.0, "Specular": 0.0})
tex = boxed.node_tree.nodes.new("ShaderNodeTexImage")
tex.image = image
tex.interpolation = "Closest"
boxed.node_tree.links.new(tex.outputs["Color"], bsdf.inputs["Base Color"])
place(bpy.context.object, boxed)

# A 1000 W point light above the glass ball, point-sized.
add_light(scene, "POINT", (0.0, 0.0, 4.0), "Lamp", energy=1000.0, shadow_soft_size=0.0)

# Blender's default camera placement and lens; 16:9.
camera(scene, (7.36, -6.93, 4.96), (math.radians(63.6), 0.0, math.radians(46.7))).data.lens = 50.0

# No world light: the lamp alone.
world = bpy.data.worlds.new("World")
world.use_nodes = True
world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
scene.world = world

scene.render.resolution_x, scene.render.resolution_y = 320, 180
scene.render.resolution_percentage = 100

common = dict(export_cameras=True, export_lights=True, export_apply=True)
bpy.ops.export_scene.gltf(filepath=os.path.join(out, "scene.glb"), export_format="GLB", **common)
bpy.ops.export_scene.gltf(
    filepath=os.path.join(out, "separate", "scene.gltf"), export_format="GLTF_SEPARATE", **common
)

if samples > 0:
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = samples
    scene.cycles.use_denoising = False
    scene.cycles.max_bounces = 8
    scene.cycles.caustics_reflective = True
    scene.cycles.caustics_refractive = True
    scene.cycles.filter_width = 0.01
    scene.view_settings.view_transform = "Standard"
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    scene.render.filepath = os.path.join(out, "cycles.exr")
    bpy.ops.render.render(write_still=True)
