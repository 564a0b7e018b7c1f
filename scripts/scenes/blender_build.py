"""Pieces of Blender scenes the project's Blender scripts and tests build alike: a grey floor,
a light, a camera. Imported inside Blender (`bpy`), with this folder on `sys.path`."""
import bpy


def grey_floor(size, grey=0.5):
    """A square plane of side `size` at the origin, Principled grey `grey` without a specular
    layer (Lambert under Cycles' and caustica's reading alike)."""
    bpy.ops.mesh.primitive_plane_add(size=size)
    floor = bpy.data.materials.new("Floor")
    floor.use_nodes = True
    bsdf = floor.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (grey, grey, grey, 1.0)
    bsdf.inputs["Specular"].default_value = 0.0
    bpy.context.object.data.materials.append(floor)
    return bpy.context.object


def white_world(scene):
    """A world of uniform radiance 1 (a white furnace's sky)."""
    world = bpy.data.worlds.new("World")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    scene.world = world


def add_light(scene, kind, location=(0.0, 0.0, 3.0), name=None, **props):
    """A light of Blender's type `kind` (POINT, SPOT, SUN, AREA) with `props` set, at
    `location`."""
    light = bpy.data.lights.new(name or kind, type=kind)
    for k, v in props.items():
        setattr(light, k, v)
    obj = bpy.data.objects.new(name or kind, light)
    obj.location = location
    scene.collection.objects.link(obj)
    return obj


def camera(scene, location, rotation=(0.0, 0.0, 0.0)):
    """The scene's camera at `location`, turned by the Euler angles `rotation`."""
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    cam.location = location
    cam.rotation_euler = rotation
    scene.collection.objects.link(cam)
    scene.camera = cam
    return cam
