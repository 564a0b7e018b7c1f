"""The evaluated Blender scene as the dict `caustica.Scene.from_dict` reads: meshes (modifiers
applied, split normals, UVs) per material, the camera, lights in Blender's units, the world's
colour, and materials read from their node trees. What cannot be read is said in `warnings`.
"""

import math
import os
import tempfile

import bpy
import numpy as np

from . import rules


def sampled(source, node, uv):
    """An image (`source`: its file or pixels) sampled as the Image Texture `node` says, through
    the uv transform `uv` if there is one."""
    out = dict(
        source,
        filter="nearest" if node.interpolation == "Closest" else "linear",
        wrap={"REPEAT": "repeat", "EXTEND": "clamp", "MIRROR": "mirror"}.get(node.extension, "repeat"),
    )
    if uv is not None:
        out["uv_transform"] = uv
    return out


class Conversion:
    def __init__(self, depsgraph, width, height, crop=None):
        self.depsgraph = depsgraph
        self.scene = depsgraph.scene_eval
        self.width, self.height = width, height
        # The border's pixels [x begin, x end, y begin, y end], rows from the top; None: all.
        self.crop = crop
        self.warnings = []
        self.materials = {}
        self.meshes = {}
        # Each mesh's parts by material, converted once however many instances place it.
        self.mesh_parts = {}
        # Images' pixels by (name, channel), for maps that read them.
        self.pixel_cache = {}
        self.shapes = []
        self.lights = []
        # Participating media by name: materials' and the world's Volume shaders.
        self.media = {}

    def warn(self, message):
        if message not in self.warnings:
            self.warnings.append(message)

    def run(self):
        for instance in self.depsgraph.object_instances:
            obj = instance.object
            matrix = np.array(instance.matrix_world, dtype=np.float64)
            if obj.type == "MESH":
                if any(m.type == "FLUID" and m.fluid_type == "DOMAIN" for m in obj.original.modifiers):
                    self.warn(
                        f"{obj.name}: a fluid simulation's grids are not read: its volume fills the domain evenly"
                    )
                self.mesh(obj, self.mesh_key(instance, obj), matrix)
            elif obj.type == "LIGHT":
                self.light(obj.data, matrix)
            elif obj.type == "VOLUME":
                self.warn(f"{obj.name}: a volume object (OpenVDB grids) is not read: left out")
        description = {
            "camera": self.camera(),
            "materials": self.materials,
            "meshes": self.meshes,
            "shapes": self.shapes,
            "lights": self.lights + self.world(),
        }
        world_medium = self.world_volume()
        if world_medium is not None:
            description["medium"] = world_medium
        if self.media:
            description["media"] = self.media
        return description

    # ---- the camera -------------------------------------------------------------------------

    def camera(self):
        cam_obj = self.scene.camera
        if cam_obj is None:
            raise ValueError("the scene has no camera")
        cam = cam_obj.data
        if cam.type != "PERSP":
            self.warn(f"camera {cam_obj.name}: only perspective cameras are rendered")
        if self.scene.render.use_motion_blur:
            self.warn("motion blur is not rendered")
        fov = rules.vertical_fov(cam.sensor_fit, cam.sensor_width, cam.sensor_height, cam.lens, self.width, self.height)
        out = {
            "matrix": np.array(cam_obj.matrix_world, dtype=np.float64),
            "fov": fov,
            "fov_axis": "vertical",
            "width": self.width,
            "height": self.height,
        }
        if cam.shift_x != 0.0 or cam.shift_y != 0.0:
            out["shift"] = rules.lens_shift(cam.sensor_fit, cam.shift_x, cam.shift_y, self.width, self.height)
        if self.crop is not None:
            out["crop"] = list(self.crop)
        if cam.dof.use_dof:
            out.update(self.depth_of_field(cam_obj))
        return out

    def depth_of_field(self, cam_obj):
        """Blender's depth of field as a thin lens: radius = focal length / (2 f-stop), in
        scene units as Cycles takes it, focused at the focus object's depth or the distance."""
        cam = cam_obj.data
        dof = cam.dof
        if dof.aperture_blades > 0 or abs(dof.aperture_ratio - 1.0) > 1e-6 or abs(dof.aperture_rotation) > 1e-6:
            self.warn(f"camera {cam_obj.name}: the aperture is rendered round (blades, ratio and rotation are not read)")
        focus = dof.focus_distance
        if dof.focus_object is not None:
            m = np.array(cam_obj.matrix_world, dtype=np.float64)
            forward = -m[:3, 2] / np.linalg.norm(m[:3, 2])
            target = np.array(dof.focus_object.matrix_world.translation, dtype=np.float64)
            focus = float((target - m[:3, 3]) @ forward)
        unit = self.scene.unit_settings.scale_length or 1.0
        radius = rules.aperture_radius(cam.lens, dof.aperture_fstop, unit)
        if focus <= 0.0:
            self.warn(f"camera {cam_obj.name}: the focus is behind the camera: no depth of field")
            return {}
        return {"aperture": radius, "focus_distance": focus}

    # ---- meshes -----------------------------------------------------------------------------

    @staticmethod
    def mesh_key(instance, obj):
        """What makes two placed meshes one: instances (collection instances, particles,
        geometry nodes) and objects without modifiers that share a mesh (linked duplicates)
        and their materials share its arrays; an object with modifiers has its own."""
        materials = tuple(s.material.name if s.material else "" for s in obj.material_slots)
        if instance.is_instance or not obj.original.modifiers:
            return f"{obj.data.name}|{materials}"
        return f"{obj.name}@object"

    def mesh(self, obj, key, matrix):
        parts = self.mesh_parts.get(key)
        if parts is None:
            parts = self.mesh_parts[key] = self.mesh_data(obj, key)
        for name, material in parts:
            self.shapes.append({"type": "instance", "mesh": name, "matrix": matrix, "material": material})

    def mesh_data(self, obj, key):
        """The mesh's triangles by material, into `meshes`: [(mesh name, material name)]."""
        parts = []
        mesh = obj.to_mesh()
        try:
            mesh.calc_loop_triangles()
            if hasattr(mesh, "calc_normals_split"):
                mesh.calc_normals_split()
            n_tris = len(mesh.loop_triangles)
            if n_tris == 0:
                return parts
            tri_loops = np.empty(n_tris * 3, dtype=np.int32)
            mesh.loop_triangles.foreach_get("loops", tri_loops)
            tri_material = np.empty(n_tris, dtype=np.int32)
            mesh.loop_triangles.foreach_get("material_index", tri_material)
            n_loops = len(mesh.loops)
            loop_vertex = np.empty(n_loops, dtype=np.int32)
            mesh.loops.foreach_get("vertex_index", loop_vertex)
            loop_normal = np.empty(n_loops * 3, dtype=np.float32)
            mesh.loops.foreach_get("normal", loop_normal)
            co = np.empty(len(mesh.vertices) * 3, dtype=np.float32)
            mesh.vertices.foreach_get("co", co)
            positions = co.reshape(-1, 3)[loop_vertex[tri_loops]]
            normals = loop_normal.reshape(-1, 3)[tri_loops]
            uvs = None
            if mesh.uv_layers.active is not None:
                uv = np.empty(n_loops * 2, dtype=np.float32)
                mesh.uv_layers.active.data.foreach_get("uv", uv)
                uvs = uv.reshape(-1, 2)[tri_loops]
            slots = [s.material for s in obj.material_slots] or [None]
            for index in np.unique(tri_material):
                material = slots[min(index, len(slots) - 1)]
                name = self.material(material)
                picked = np.nonzero(tri_material == index)[0]
                corners = (picked[:, None] * 3 + np.arange(3)[None, :]).ravel()
                data = {
                    "positions": positions[corners],
                    "normals": normals[corners],
                    "indices": np.arange(len(corners), dtype=np.int64).reshape(-1, 3),
                }
                if uvs is not None:
                    data["uvs"] = uvs[corners]
                mesh_name = f"{key}#{index}"
                self.meshes[mesh_name] = data
                parts.append((mesh_name, name))
        finally:
            obj.to_mesh_clear()
        return parts

    # ---- materials --------------------------------------------------------------------------

    def material(self, material):
        name = material.name if material is not None else "(none)"
        if name in self.materials:
            return name
        if material is None or not material.use_nodes or material.node_tree is None:
            colour = list(material.diffuse_color[:3]) if material is not None else [0.8, 0.8, 0.8]
            self.materials[name] = {"type": "diffuse", "reflectance": colour}
            return name
        output = next(
            (n for n in material.node_tree.nodes if n.type == "OUTPUT_MATERIAL" and n.is_active_output),
            None,
        )
        link = output.inputs["Surface"].links[0] if output and output.inputs["Surface"].is_linked else None
        node = link.from_node if link else None
        volume = self.volume(output, f"material {name}") if output is not None else None
        if volume is not None:
            self.media[name] = volume
        if node is None and volume is not None:
            # Only a volume: Cycles' surface is then invisible, the medium's boundary.
            self.materials[name] = {"type": "boundary", "inside": name}
            return name
        shader = self.shader(node, name)
        if node is not None:
            normal_map = self.normal_map(node, name)
            if normal_map is not None:
                shader["normal_map"] = normal_map
        if volume is not None:
            shader["inside"] = name
        self.materials[name] = shader
        return name

    # ---- volumes ----------------------------------------------------------------------------

    def volume(self, output, what):
        """The medium an output node's Volume socket holds, as Cycles reads it: Volume Scatter
        (σs = colour × density, g = anisotropy), Volume Absorption (σa = (1 − colour) × density),
        Principled Volume (both, its absorption colour taking part) and an Add shader of them;
        None when nothing is linked (or, with a warning, what is not read)."""
        socket = output.inputs.get("Volume")
        if socket is None or not socket.is_linked:
            return None
        medium = {"absorption": [0.0] * 3, "scattering": [0.0] * 3, "g": 0.0}
        if not self.add_volume(socket.links[0].from_node, medium, what):
            return None
        return medium

    def add_volume(self, node, medium, what):
        """Adds the volume shader `node` to `medium`; False (with a warning) if it is not read."""
        def constant(name):
            socket = node.inputs[name]
            if socket.is_linked:
                self.warn(f"{what}: the volume's {name} from a node link is read by the input's own value")
            value = socket.default_value
            return np.array(value[:3], dtype=np.float64) if hasattr(value, "__len__") else float(value)

        if node.type == "ADD_SHADER":
            return all(
                s.is_linked and self.add_volume(s.links[0].from_node, medium, what) for s in node.inputs[:2]
            )
        if node.type == "VOLUME_SCATTER":
            sigma = np.clip(constant("Color"), 0.0, None) * max(constant("Density"), 0.0)
            medium["scattering"] = list(np.array(medium["scattering"]) + sigma)
            medium["g"] = float(np.clip(constant("Anisotropy"), -0.99, 0.99))
            return True
        if node.type == "VOLUME_ABSORPTION":
            sigma = np.clip(1.0 - constant("Color"), 0.0, None) * max(constant("Density"), 0.0)
            medium["absorption"] = list(np.array(medium["absorption"]) + sigma)
            return True
        if node.type == "PRINCIPLED_VOLUME":
            # As Cycles reads it: σs = colour × density and σa = (1 − colour) × (1 − √absorption
            # colour) × density, each clamped at 0 (a mesh has no density attribute: the
            # input's value is the density).
            colour = np.clip(constant("Color"), 0.0, None)
            density = max(constant("Density"), 0.0)
            absorption = np.clip(1.0 - colour, 0.0, None) * np.clip(
                1.0 - np.sqrt(np.clip(constant("Absorption Color"), 0.0, None)), 0.0, None
            )
            medium["scattering"] = list(np.array(medium["scattering"]) + colour * density)
            medium["absorption"] = list(np.array(medium["absorption"]) + absorption * density)
            medium["g"] = float(np.clip(constant("Anisotropy"), -0.99, 0.99))
            if constant("Emission Strength") > 0.0 or constant("Blackbody Intensity") > 0.0:
                self.warn(f"{what}: the volume's emission is not rendered")
            return True
        self.warn(f"{what}: the {node.name} volume node is not read: no medium")
        return False

    def world_volume(self):
        """The world's Volume shader as the medium that fills the scene (its name), or None."""
        world = self.scene.world
        if world is None or not world.use_nodes or world.node_tree is None:
            return None
        output = next((n for n in world.node_tree.nodes if n.type == "OUTPUT_WORLD" and n.is_active_output), None)
        volume = self.volume(output, "world") if output is not None else None
        if volume is None:
            return None
        self.media["(world)"] = volume
        return "(world)"

    def image_file(self, image):
        """A file holding `image`: its own, or a copy of its packed bytes."""
        if image.packed_file is not None:
            suffix = {"PNG": ".png", "JPEG": ".jpg", "OPEN_EXR": ".exr", "HDR": ".hdr", "TARGA": ".tga"}.get(
                image.file_format, ".png"
            )
            path = os.path.join(self.temp_dir(), f"{len(os.listdir(self.temp_dir()))}{suffix}")
            with open(path, "wb") as f:
                f.write(image.packed_file.data)
            return path
        path = bpy.path.abspath(image.filepath, library=image.library)
        return path if os.path.isfile(path) else None

    def temp_dir(self):
        if not hasattr(self, "_temp"):
            self._temp = tempfile.mkdtemp(prefix="caustica-blender-")
        return self._temp

    def texture(self, socket, material, what):
        """The image texture linked straight into `socket`, as the dict reads it; None (with a
        warning) for any other link."""
        node = socket.links[0].from_node
        if node.type == "TEX_IMAGE" and node.image is not None:
            uv = self.uv_transform(node, material, what)
            if uv is False:
                return None
            path = self.image_file(node.image)
            linear = node.image.colorspace_settings.name in {"Non-Color", "Linear", "Raw"}
            if path is not None:
                source = {"file": path, "encoding": "linear" if linear else "srgb"}
            else:
                # An image with no file (generated, or painted and not saved): its pixels,
                # decoded here.
                pixels = self.image_pixels(node.image, "rgb")
                if pixels is None:
                    self.warn(f"material {material}: the image {node.image.name} of {what} has no pixels")
                    return None
                source = {"array": pixels, "encoding": "linear"}
            return sampled(source, node, uv)
        self.warn(f"material {material}: {what} from the {node.name} node is read by the input's own value")
        return None

    def uv_transform(self, image_node, material, what):
        """How an Image Texture node's coordinates come from the active UV map: None for
        straight, a 3×3 matrix for a Mapping node's scale, rotation about z and location
        (Point, Texture or Vector type) on them; False, with a warning, for anything else."""
        vector = image_node.inputs["Vector"]
        if not vector.is_linked:
            return None
        node = vector.links[0].from_node

        def is_uv(link_node, output):
            return (link_node.type == "TEX_COORD" and output == "UV") or link_node.type == "UVMAP"

        if is_uv(node, vector.links[0].from_socket.name):
            return None
        inputs = node.inputs if node.type == "MAPPING" else None
        ok = (
            inputs is not None
            and node.vector_type in {"POINT", "TEXTURE", "VECTOR"}
            and inputs["Vector"].is_linked
            and is_uv(inputs["Vector"].links[0].from_node, inputs["Vector"].links[0].from_socket.name)
            and not any(i.is_linked for i in list(inputs)[1:])
        )
        rotation = list(inputs["Rotation"].default_value) if ok else [0.0, 0.0, 0.0]
        if not ok or abs(rotation[0]) > 1e-6 or abs(rotation[1]) > 1e-6:
            self.warn(
                f"material {material}: the coordinates of {what} ({node.name}) are not the UV map or a Mapping node's scale, z rotation and location on it: the image is not read"
            )
            return False
        scale = list(inputs["Scale"].default_value)
        location = list(inputs["Location"].default_value) if node.vector_type != "VECTOR" else [0.0, 0.0, 0.0]
        return rules.uv_mapping(node.vector_type, location[:2], rotation[2], scale[:2])

    def colour(self, socket, material, what):
        """A colour input: an image texture straight into it, or times a colour by a Mix
        node's Multiply; else its value."""
        if socket.is_linked:
            node = socket.links[0].from_node
            if node.type in {"MIX_RGB", "MIX"} and getattr(node, "blend_type", "") == "MULTIPLY":
                t = self.multiplied(node, material, what)
            else:
                t = self.texture(socket, material, what)
            if t is not None:
                return t
        return list(socket.default_value)[:3]

    def multiplied(self, node, material, what):
        """A Mix node multiplying an image texture by a colour (Fac f): the texture A gives
        A·(1 − f + f·B); a texture B at f = 1 gives A·B."""
        if node.type == "MIX":
            if node.data_type != "RGBA":
                return None
            fac, a, b = node.inputs[0], node.inputs[6], node.inputs[7]
        else:
            fac, a, b = node.inputs["Fac"], node.inputs["Color1"], node.inputs["Color2"]
        if fac.is_linked or a.is_linked == b.is_linked:
            self.warn(f"material {material}: {what} from the {node.name} node is read by the input's own value")
            return None
        f = fac.default_value
        if a.is_linked:
            t, factor = self.texture(a, material, what), [1.0 - f + f * c for c in b.default_value[:3]]
        elif f == 1.0:
            t, factor = self.texture(b, material, what), list(a.default_value[:3])
        else:
            self.warn(f"material {material}: {what} from the {node.name} node is read by the input's own value")
            return None
        if t is None:
            return None
        scale = rules.rgb(t.get("scale", 1.0))
        return dict(t, scale=[x * y for x, y in zip(scale, factor)])

    def normal_map(self, node, material):
        """The tangent-space normal map behind a shader's Normal input, if there is one."""
        normal = node.inputs.get("Normal")
        if normal is None or not normal.is_linked:
            return None
        n = normal.links[0].from_node
        if n.type == "NORMAL_MAP" and n.space == "TANGENT" and n.inputs["Color"].is_linked:
            t = self.texture(n.inputs["Color"], material, "the normal map")
            if t is not None:
                return {"file": t["file"], "strength": n.inputs["Strength"].default_value}
        self.warn(f"material {material}: the {n.name} node on the normal is not read")
        return None

    def scalar(self, socket, material, what):
        """A number input: its value, or an image's pixels linked into it — the image's colour
        (its luminance), its alpha, or one channel through a Separate RGB/XYZ/Color node (as
        Blender's glTF importer links a metallic-roughness texture) — as a linear texture."""
        if not socket.is_linked:
            return float(socket.default_value)
        link = socket.links[0]
        node, output = link.from_node, link.from_socket.name
        channel = None
        if node.type in {"SEPRGB", "SEPXYZ", "SEPARATE_COLOR"} and node.inputs[0].is_linked:
            channel = {"R": 0, "Red": 0, "X": 0, "G": 1, "Green": 1, "Y": 1, "B": 2, "Blue": 2, "Z": 2}.get(output)
            link = node.inputs[0].links[0]
            node, output = link.from_node, link.from_socket.name
            if node.type != "TEX_IMAGE" or output != "Color" or channel is None:
                node = None
        if node is not None and node.type == "TEX_IMAGE" and node.image is not None:
            uv = self.uv_transform(node, material, what)
            if uv is False:
                return float(socket.default_value)
            if channel is None:
                channel = "alpha" if output == "Alpha" else "luminance"
            pixels = self.image_pixels(node.image, channel)
            if pixels is not None:
                return sampled({"array": pixels, "encoding": "linear"}, node, uv)
        self.warn(f"material {material}: {what} from the {socket.links[0].from_node.name} node is read by the input's own value")
        return float(socket.default_value)

    def image_pixels(self, image, channel):
        """One channel of an image's pixels as linear values (rows from the top): 0–2, "alpha",
        "luminance" or "rgb"; an sRGB image's colour is decoded first, as Cycles reads it into a
        number. Each image and channel is read once per conversion."""
        key = (image.name, channel)
        if key not in self.pixel_cache:
            self.pixel_cache[key] = self.read_pixels(image, channel)
        return self.pixel_cache[key]

    def read_pixels(self, image, channel):
        w, h = image.size
        if w == 0 or h == 0:
            return None
        buf = np.empty(w * h * image.channels, dtype=np.float32)
        image.pixels.foreach_get(buf)
        px = buf.reshape(h, w, image.channels)[::-1]
        if channel == "alpha":
            return np.ascontiguousarray(px[..., 3] if image.channels == 4 else np.ones((h, w), np.float32))
        rgb = px[..., :3] if image.channels >= 3 else np.repeat(px[..., :1], 3, axis=2)
        if image.colorspace_settings.name == "sRGB" and not image.is_float:
            rgb = np.where(rgb <= 0.04045, rgb / 12.92, ((rgb + 0.055) / 1.055) ** 2.4)
        if channel == "rgb":
            return np.ascontiguousarray(rgb)
        if channel == "luminance":
            return np.ascontiguousarray(rgb @ np.array([0.2126, 0.7152, 0.0722], dtype=np.float32))
        return np.ascontiguousarray(rgb[..., channel])

    def value(self, socket, material, what):
        """A number input's value; a linked one is read by its own value, with a warning."""
        if socket.is_linked:
            self.warn(f"material {material}: {what} from a node link is read by the input's own value")
        v = socket.default_value
        try:
            return list(v)[:3]
        except TypeError:
            return float(v)

    def shader(self, node, material):
        if node is None:
            return {"type": "diffuse", "reflectance": 0.0}
        kind = node.type
        if kind == "BSDF_PRINCIPLED":
            i = node.inputs
            # Blender 4 renamed the inputs and changed what Specular and the coat mean.
            v4 = "Transmission Weight" in i

            def named(three, four):
                return i[four if v4 else three]

            base = self.colour(i["Base Color"], material, "the base colour")
            metallic = self.scalar(i["Metallic"], material, "metallic")
            roughness = self.scalar(i["Roughness"], material, "roughness")
            transmission = self.scalar(named("Transmission", "Transmission Weight"), material, "transmission")
            ior = self.value(i["IOR"], material, "the IOR")
            specular = self.value(named("Specular", "Specular IOR Level"), material, "specular")
            if v4:
                # Level ½ is the IOR's own reflectance: as Blender 3's Specular of F0 / 0.08.
                specular = ((ior - 1.0) / (ior + 1.0)) ** 2 * 2.0 * specular / 0.08
            clearcoat = self.scalar(named("Clearcoat", "Coat Weight"), material, "clearcoat")
            if v4 and not rules.is_texture(clearcoat):
                # Blender 3's coat weighs a quarter of its input; Blender 4's its input.
                clearcoat = 4.0 * clearcoat
            clearcoat_roughness = self.scalar(
                named("Clearcoat Roughness", "Coat Roughness"), material, "the clearcoat roughness"
            )
            # Subsurface scattering as diffuse reflection of its colour (light does not travel
            # under the surface): Cycles 3 blends the base towards the subsurface colour so.
            sss = i.get("Subsurface")
            if not v4 and sss is not None and (sss.is_linked or sss.default_value > 0.0):
                self.warn(f"material {material}: subsurface scattering is rendered as diffuse reflection of its colour")
                w = self.value(sss, material, "subsurface")
                sss_colour = self.value(i["Subsurface Color"], material, "the subsurface colour")
                if not rules.is_texture(base):
                    base = [(1.0 - w) * b + w * c for b, c in zip(base, sss_colour)]
            # Inputs with no reading yet: said when they would change the picture.
            for unread in ["Subsurface Weight", "Sheen", "Sheen Weight", "Anisotropic"]:
                socket = i.get(unread)
                if socket is not None and (socket.is_linked or socket.default_value > 0.0):
                    self.warn(f"material {material}: the Principled BSDF's {unread} is not rendered")
            if named("Clearcoat Normal", "Coat Normal").is_linked:
                self.warn(f"material {material}: the clearcoat's normal is not read (the coat follows the surface)")
            layering = "fresnel" if v4 else "added"
            out = rules.principled(
                base, metallic, roughness, transmission, ior, specular, clearcoat, clearcoat_roughness, layering
            )
            coverage = self.scalar(i["Alpha"], material, "alpha")
            if rules.is_texture(coverage) or coverage < 1.0:
                out["coverage"] = coverage
            strength = self.value(i["Emission Strength"], material, "emission strength")
            emission = self.colour(named("Emission", "Emission Color"), material, "the emission")
            if rules.is_texture(emission):
                if strength > 0.0:
                    out["emission"] = dict(emission, scale=strength)
                    out["two_sided"] = True
            elif max(emission) * strength > 0.0:
                out["emission"] = [c * strength for c in emission]
                out["two_sided"] = True
            return out
        if kind == "BSDF_DIFFUSE":
            return {"type": "diffuse", "reflectance": self.colour(node.inputs["Color"], material, "the colour")}
        if kind == "BSDF_GLOSSY":
            r = self.scalar(node.inputs["Roughness"], material, "roughness")
            return {"type": "conductor", "reflectance": self.colour(node.inputs["Color"], material, "the colour"), "roughness": r}
        if kind in {"BSDF_GLASS", "BSDF_REFRACTION"}:
            r = self.scalar(node.inputs["Roughness"], material, "roughness")
            return {
                "type": "glass",
                "ior": max(1.0, self.value(node.inputs["IOR"], material, "the IOR")),
                "roughness": r,
                "tint": self.colour(node.inputs["Color"], material, "the colour"),
            }
        if kind == "BSDF_TRANSPARENT":
            # Light passes straight through, tinted: a sheet of index 1.
            return {"type": "thin_glass", "ior": 1.0, "tint": self.colour(node.inputs["Color"], material, "the colour")}
        if kind == "MIX_SHADER":
            fac = self.scalar(node.inputs[0], material, "the mix factor")
            if not rules.is_texture(fac):
                fac = min(1.0, max(0.0, fac))
            parts = []
            for socket in (node.inputs[1], node.inputs[2]):
                parts.append(self.shader(socket.links[0].from_node if socket.is_linked else None, material))
            return {"type": "mix", "amount": fac, "materials": parts}
        if kind == "ADD_SHADER":
            parts = []
            for socket in (node.inputs[0], node.inputs[1]):
                parts.append(self.shader(socket.links[0].from_node if socket.is_linked else None, material))
            return rules.added(*parts)
        if kind == "EMISSION":
            colour = self.colour(node.inputs["Color"], material, "the colour")
            strength = self.value(node.inputs["Strength"], material, "the strength")
            if rules.is_texture(colour):
                emission = dict(colour, scale=strength)
            else:
                emission = [c * strength for c in colour]
            return {"type": "diffuse", "reflectance": 0.0, "emission": emission, "two_sided": True}
        self.warn(f"material {material}: the {node.name} node ({kind}) is not read: grey diffuse instead")
        return {"type": "diffuse", "reflectance": 0.5}

    # ---- lights -----------------------------------------------------------------------------

    def light(self, light, matrix):
        colour = np.array(light.color[:3], dtype=np.float64)
        position = matrix[:3, 3]
        # Blender's lights shine down their local −z.
        direction = matrix[:3, :3] @ np.array([0.0, 0.0, -1.0])
        if light.type in {"POINT", "SPOT"}:
            intensity = list(colour * rules.point_intensity(light.energy))
            if light.type == "POINT":
                # A radius makes a ball of the same intensity: soft shadows, the same power.
                self.lights.append(
                    {"type": "sphere", "position": position, "radius": light.shadow_soft_size, "intensity": intensity}
                )
            elif light.shadow_soft_size > 0.0:
                self.warn(f"light {light.name}: a spot's radius is not rendered (a point spot)")
            if light.type == "SPOT":
                outer, inner = rules.spot_cone(light.spot_size, light.spot_blend)
                self.lights.append(
                    {
                        "type": "spot",
                        "position": position,
                        "direction": direction,
                        "intensity": intensity,
                        "angle": outer,
                        "inner_angle": inner,
                        # Cycles' spots fade as the cosine from their axis.
                        "exponent": 1.0,
                    }
                )
        elif light.type == "SUN":
            self.lights.append(
                {
                    "type": "sun",
                    "direction": direction,
                    "irradiance": list(colour * light.energy),
                    "angle": math.degrees(light.angle),
                }
            )
        elif light.type == "AREA":
            self.area_light(light, matrix, colour)
        else:
            self.warn(f"light {light.name}: {light.type} lights are not rendered")

    def area_light(self, light, matrix, colour):
        sx = light.size
        sy = light.size_y if light.shape in {"RECTANGLE", "ELLIPSE"} else light.size
        round_light = light.shape in {"DISK", "ELLIPSE"}
        # A disk or ellipse is the one inscribed in its size's rectangle.
        area = sx * sy * (math.pi / 4.0 if round_light else 1.0)
        m = matrix[:3, :3]
        radiance = list(colour * rules.area_radiance(light.energy, area))
        settings = getattr(self.scene, "caustica", None)
        mode = settings.area_lights if settings is not None else "AUTO"
        corners = [matrix[:3, 3] + m @ np.array([x * sx / 2.0, y * sy / 2.0, 0.0]) for x in (-1, 1) for y in (-1, 1)]
        if mode == "AUTO" and self.in_view(corners):
            self.warn(
                f"light {light.name}: in the camera's view, so a light the camera does not see (and not seen in mirrors and glass either)"
            )
        elif mode != "LIGHT":
            self.glowing_surface(light, matrix, sx, sy, round_light, radiance)
            return
        # Lit down its −z: u × v points there.
        self.lights.append(
            {
                "type": "area",
                "shape": "ellipse" if round_light else "rectangle",
                "corner": matrix[:3, 3] + m @ np.array([-sx / 2.0, -sy / 2.0, 0.0]),
                "u": m @ np.array([0.0, sy, 0.0]),
                "v": m @ np.array([sx, 0.0, 0.0]),
                "radiance": radiance,
            }
        )

    def in_view(self, points):
        """Whether any of `points` lies in the camera's view (with a margin of a tenth)."""
        cam_obj = self.scene.camera
        if cam_obj is None:
            return False
        cam = cam_obj.data
        fov = math.radians(rules.vertical_fov(cam.sensor_fit, cam.sensor_width, cam.sensor_height, cam.lens, self.width, self.height))
        half_h = math.tan(fov / 2.0) * 1.1 + abs(cam.shift_y) * 2.0
        half_w = half_h * self.width / self.height + abs(cam.shift_x) * 2.0
        to_camera = np.linalg.inv(np.array(cam_obj.matrix_world, dtype=np.float64))
        for p in points:
            x, y, z = (to_camera @ np.append(p, 1.0))[:3]
            if z < 0.0 and abs(x) <= half_w * -z and abs(y) <= half_h * -z:
                return True
        return False

    def glowing_surface(self, light, matrix, sx, sy, round_light, radiance):
        """An area light as a one-sided emitting mesh of its shape (a disk or ellipse as a fan
        of 64 triangles of its area), glowing down its −z."""
        if round_light:
            n = 64
            # The polygon's corners pushed out so its area is the ellipse's.
            grow = math.sqrt(2.0 * math.pi / (n * math.sin(2.0 * math.pi / n)))
            angles = -2.0 * math.pi * np.arange(n) / n
            rim = np.stack([0.5 * sx * grow * np.cos(angles), 0.5 * sy * grow * np.sin(angles), np.zeros(n)], axis=1)
            positions = np.vstack([[0.0, 0.0, 0.0], rim])
            indices = [[0, 1 + i, 1 + (i + 1) % n] for i in range(n)]
        else:
            hx, hy = sx / 2.0, sy / 2.0
            # Clockwise seen from +z: the front faces −z.
            positions = np.array([[-hx, -hy, 0.0], [-hx, hy, 0.0], [hx, hy, 0.0], [hx, -hy, 0.0]])
            indices = [[0, 1, 2], [0, 2, 3]]
        name = f"light {light.name}"
        self.materials[name] = {"type": "diffuse", "reflectance": 0.0, "emission": radiance}
        self.shapes.append(
            {"type": "mesh", "positions": positions, "indices": indices, "matrix": matrix, "material": name}
        )

    def world(self):
        world = self.scene.world
        if world is None:
            return []
        colour, strength = np.array(world.color[:3]), 1.0
        if world.use_nodes and world.node_tree is not None:
            output = next((n for n in world.node_tree.nodes if n.type == "OUTPUT_WORLD" and n.is_active_output), None)
            link = output.inputs["Surface"].links[0] if output and output.inputs["Surface"].is_linked else None
            node = link.from_node if link else None
            if node is None:
                return []
            if node.type != "BACKGROUND":
                self.warn(f"world: the {node.name} node is not read: no world light")
                return []
            strength = node.inputs["Strength"].default_value
            if node.inputs["Strength"].is_linked:
                self.warn("world: the strength from a node link is read by the input's own value")
            if node.inputs["Color"].is_linked:
                sky = self.environment_texture(node.inputs["Color"].links[0].from_node)
                if sky is not None:
                    sky["radiance"] = [strength] * 3
                    return [sky]
            colour = np.array(node.inputs["Color"].default_value[:3])
        radiance = colour * strength
        if radiance.max() <= 0.0:
            return []
        return [{"type": "environment", "radiance": list(radiance)}]

    def environment_texture(self, node):
        """An Environment Texture node (equirectangular, its vector from nothing or a Mapping
        node's rotation) as an environment light's image and rotation; None, with a warning,
        for anything else."""
        if node.type != "TEX_ENVIRONMENT" or node.image is None:
            self.warn(f"world: the {node.name} node on the colour is not read: its colour's value is used")
            return None
        if node.projection != "EQUIRECTANGULAR":
            self.warn(f"world: the {node.name} node's {node.projection} projection is not read: no world light")
            return None
        rotation = None
        if node.inputs["Vector"].is_linked:
            mapping = node.inputs["Vector"].links[0].from_node
            ok = mapping.type == "MAPPING" and mapping.vector_type in {"POINT", "VECTOR"}
            if ok:
                scale = list(mapping.inputs["Scale"].default_value)
                ok = not any(s.is_linked for s in mapping.inputs[1:]) and all(abs(x - 1.0) < 1e-6 for x in scale)
            if not ok:
                self.warn(f"world: the {mapping.name} node on the environment is not read (a Mapping node's rotation is)")
            else:
                rotation = [list(row) for row in mapping.inputs["Rotation"].default_value.to_matrix()]
        sky = {"type": "environment", "rotation": np.array(rules.environment_rotation(rotation))}
        if node.image.is_float:
            path = self.image_file(node.image)
            if path is not None:
                sky["file"] = path
                return sky
        # 8-bit images (decoded as Cycles decodes them), and float images without a file.
        pixels = self.image_pixels(node.image, "rgb")
        if pixels is None:
            self.warn(f"world: the environment image {node.image.name} has no pixels")
            return None
        sky["array"] = pixels
        return sky
