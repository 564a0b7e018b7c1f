"""Scenes built in memory (`caustica.Scene.from_dict`): the same pixels as the same scene read
from a file, and errors that name the key and index at fault."""
import numpy as np
import pytest

import caustica

# A floor, a glass ball on it and a point light above and to the right (+x, so a mirrored
# image would differ); the camera at (0, 1, 5) looks down −z.
# pbrt's LookAt camera is left-handed: its image's right is −x, which the matrix says too.
PBRT = """LookAt 0 1 5  0 1 0  0 1 0
Camera "perspective" "float fov" 40
Film "rgb" "integer xresolution" 32 "integer yresolution" 24
WorldBegin
LightSource "point" "rgb I" [5 4 3] "point3 from" [1.5 4 0]
Material "diffuse" "rgb reflectance" [0.5 0.5 0.5]
Shape "trianglemesh" "point3 P" [-4 0 -4  4 0 -4  4 0 4  -4 0 4] "integer indices" [0 2 1 0 3 2]
AttributeBegin
Translate 0 0.7 0
Material "dielectric" "float eta" 1.5
Shape "sphere" "float radius" 0.7
AttributeEnd
"""


def description():
    return {
        "camera": {
            "matrix": np.array([[-1, 0, 0, 0], [0, 1, 0, 1], [0, 0, 1, 5], [0, 0, 0, 1]]),
            "fov": 40,
            "fov_axis": "shorter",
            "width": 32,
            "height": 24,
        },
        "materials": {
            "floor": {"type": "diffuse", "reflectance": 0.5},
            "glass": {"type": "glass", "ior": 1.5},
        },
        "shapes": [
            {
                "type": "mesh",
                "positions": np.array([[-4, 0, -4], [4, 0, -4], [4, 0, 4], [-4, 0, 4]], dtype=np.float64),
                "indices": [[0, 2, 1], [0, 3, 2]],
                "material": "floor",
            },
            {"type": "sphere", "center": [0, 0.7, 0], "radius": 0.7, "material": "glass"},
        ],
        "lights": [{"type": "point", "position": [1.5, 4, 0], "intensity": [5, 4, 3]}],
    }


def test_a_scene_from_a_dict_renders_the_pixels_of_the_same_scene_from_a_file(tmp_path):
    path = tmp_path / "scene.pbrt"
    path.write_text(PBRT)
    scene = caustica.Scene.from_dict(description())
    for integrator in ["path", "vcm"]:
        options = dict(integrator=integrator, passes=2, seed=3, threads=1)
        from_dict = caustica.render(scene, **options)
        from_file = caustica.render(str(path), **options)
        assert from_dict.shape == (24, 32, 3)
        assert from_dict.max() > 0
        np.testing.assert_array_equal(from_dict, from_file)


def test_the_scene_reports_what_it_holds():
    info = caustica.Scene.from_dict(description()).info()
    assert info["scene"] == "<scene from a dict>"
    assert info["lights"] and info["materials"]


@pytest.mark.parametrize(
    "change, error, words",
    [
        (lambda d: d["shapes"][0].update(indices=[[0, 1, 2], [0, 9, 2]]), ValueError, "shapes[0].indices[1]: vertex 9 is out of range (4 vertices)"),
        (lambda d: d["shapes"][1].update(material="gold"), ValueError, 'shapes[1].material: no material named "gold"'),
        (lambda d: d["shapes"][1].update(radios=1), ValueError, "shapes[1].radios: not a key caustica reads here"),
        (lambda d: d["materials"]["glass"].update(ior=0.5), ValueError, "materials.glass.ior"),
        (lambda d: d["shapes"][0].update(positions=np.zeros((4, 2))), ValueError, "shapes[0].positions: expected an array of shape (n, 3)"),
        (lambda d: d["shapes"][0].update(positions=np.full((4, 3), np.nan)), ValueError, "shapes[0].positions[0]: not finite"),
        (lambda d: d["lights"][0].update(type="laser"), ValueError, "lights[0].type"),
        (
            lambda d: d["lights"].append({"type": "area", "corner": [0, 3, 0], "u": [1, 0, 0], "v": [2, 0, 0]}),
            ValueError,
            "lights[1]: the edges `u` and `v` span no area",
        ),
        (lambda d: d["camera"].update(fov="wide"), TypeError, "camera.fov: expected a number"),
    ],
)
def test_errors_name_the_key_and_the_index(change, error, words):
    d = description()
    change(d)
    with pytest.raises(error) as e:
        caustica.Scene.from_dict(d)
    assert words in str(e.value)


def png(path, rgb_rows):
    """An 8-bit RGB PNG of `rgb_rows` (rows from the top), written with zlib alone."""
    import struct
    import zlib

    h, w = len(rgb_rows), len(rgb_rows[0])
    raw = b"".join(b"\0" + bytes(c for px in row for c in px) for row in rgb_rows)

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    path.write_bytes(
        b"\x89PNG\r\n\x1a\n"
        + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
        + chunk(b"IDAT", zlib.compress(raw))
        + chunk(b"IEND", b"")
    )


def test_textures_from_files_render_as_the_same_pbrt_imagemap(tmp_path):
    png(tmp_path / "tex.png", [[(200, 30, 30), (30, 30, 200)]])
    pbrt = tmp_path / "quad.pbrt"
    pbrt.write_text(
        """LookAt 0 0 3  0 0 0  0 1 0
Camera "perspective" "float fov" 40
Film "rgb" "integer xresolution" 24 "integer yresolution" 24
WorldBegin
LightSource "infinite" "rgb L" [1 1 1]
Texture "t" "spectrum" "imagemap" "string filename" "tex.png" "string filter" "point"
Material "diffuse" "texture reflectance" "t"
Shape "trianglemesh" "point3 P" [-1 -1 0 1 -1 0 1 1 0 -1 1 0] "point2 uv" [0 0 1 0 1 1 0 1] "integer indices" [0 1 2 0 2 3]
"""
    )
    scene = caustica.Scene.from_dict(
        {
            "camera": {
                "matrix": np.array([[-1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 3], [0, 0, 0, 1]]),
                "fov": 40,
                "fov_axis": "shorter",
                "width": 24,
                "height": 24,
            },
            "materials": {"tex": {"type": "diffuse", "reflectance": {"file": str(tmp_path / "tex.png"), "filter": "nearest"}}},
            "shapes": [
                {
                    "type": "mesh",
                    "positions": [[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]],
                    "uvs": [[0, 0], [1, 0], [1, 1], [0, 1]],
                    "indices": [[0, 1, 2], [0, 2, 3]],
                    "material": "tex",
                }
            ],
            "lights": [{"type": "environment", "radiance": 1}],
        }
    )
    options = dict(integrator="path", passes=2, seed=1, threads=1)
    from_dict = caustica.render(scene, **options)
    np.testing.assert_array_equal(from_dict, caustica.render(str(pbrt), **options))
    # The image's left texel (sRGB 200, 30, 30) on the left of the picture: the camera's right
    # is −x here, so the quad's u = 0 edge is on the picture's right.
    right, left = from_dict[12, 20], from_dict[12, 3]
    assert right[0] > right[2] and left[2] > left[0], (left, right)


def test_a_missing_texture_file_is_named():
    d = description()
    d["materials"]["floor"]["reflectance"] = {"file": "/no/such/image.png"}
    with pytest.raises(ValueError) as e:
        caustica.Scene.from_dict(d)
    assert "materials.floor.reflectance.file: no file `/no/such/image.png`" in str(e.value)


def test_a_mix_blends_its_two_materials_in_the_mean():
    # White 0.8 and black mixed at 0.25 under a uniform sky of radiance 1: the floor seen from
    # above has radiance 0.8 × 0.75 = 0.6 (each point shows one of the two).
    scene = caustica.Scene.from_dict(
        {
            "camera": {"eye": [0, 0, 2], "look_at": [0, 0, 0], "fov": 30, "width": 16, "height": 16},
            "materials": {
                "mixed": {
                    "type": "mix",
                    "amount": 0.25,
                    "materials": [{"type": "diffuse", "reflectance": 0.8}, {"type": "diffuse", "reflectance": 0}],
                }
            },
            "shapes": [
                {
                    "type": "mesh",
                    "positions": [[-5, -5, 0], [5, -5, 0], [5, 5, 0], [-5, 5, 0]],
                    "indices": [[0, 1, 2], [0, 2, 3]],
                    "material": "mixed",
                }
            ],
            "lights": [{"type": "environment", "radiance": 1}],
        }
    )
    image = caustica.render(scene, integrator="path", passes=64, seed=2)
    assert image.mean() == pytest.approx(0.6, rel=0.02)


def quad(material, size=5.0, z=0.0):
    s = size
    return {
        "type": "mesh",
        "positions": [[-s, -s, z], [s, -s, z], [s, s, z], [-s, s, z]],
        "uvs": [[0, 0], [1, 0], [1, 1], [0, 1]],
        "indices": [[0, 1, 2], [0, 2, 3]],
        "material": material,
    }


def looking_down(materials, shapes, lights, size=16, fov=30):
    return {
        "camera": {"eye": [0, 0, 2], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov": fov, "width": size, "height": size},
        "materials": materials,
        "shapes": shapes,
        "lights": lights,
    }


SKY = [{"type": "environment", "radiance": 1}]


def test_textures_from_arrays_render_as_the_same_image_files(tmp_path):
    rows = [[(200, 30, 30), (30, 30, 200)], [(10, 220, 10), (250, 250, 250)]]
    png(tmp_path / "tex.png", rows)
    pixels = np.array(rows, dtype=np.uint8)
    options = dict(integrator="path", passes=2, seed=1, threads=1)

    def render(reflectance):
        d = looking_down({"t": {"type": "diffuse", "reflectance": reflectance}}, [quad("t", 0.5)], SKY)
        return caustica.render(caustica.Scene.from_dict(d), **options)

    from_file = render({"file": str(tmp_path / "tex.png"), "filter": "nearest"})
    # 8-bit arrays are stored values, sRGB-decoded as a colour file's are: the same pixels.
    np.testing.assert_array_equal(render({"array": pixels, "filter": "nearest"}), from_file)
    # Float arrays are linear values: the decoded texels give the same pixels again.
    c = pixels / 255.0
    linear = np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4).astype(np.float32)
    np.testing.assert_allclose(render({"array": linear, "filter": "nearest"}), from_file, rtol=1e-5, atol=1e-7)


@pytest.mark.parametrize(
    "texture, words",
    [
        ({"array": np.zeros((2, 2, 5))}, "1 to 4 channels"),
        ({"array": np.zeros((2, 2), dtype=np.int32)}, "8- or 16-bit unsigned integers or floats"),
        ({"array": np.full((2, 2), np.inf)}, "value 0 is not finite"),
        ({"array": np.zeros((2, 2)), "file": "x.png"}, "a `file` or an `array`, not both"),
    ],
)
def test_bad_pixel_arrays_are_named(texture, words):
    d = looking_down({"t": {"type": "diffuse", "reflectance": texture}}, [quad("t")], SKY)
    with pytest.raises((ValueError, TypeError)) as e:
        caustica.Scene.from_dict(d)
    assert "materials.t.reflectance" in str(e.value) and words in str(e.value)


def test_instances_of_a_mesh_render_as_copies_of_its_arrays():
    tri = {"positions": [[-1, -1, 0], [1, -1, 0], [0, 1, 0]], "indices": [[0, 1, 2]]}
    left = np.array([[1, 0, 0, -1.2], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]])
    right = np.array([[0.5, 0, 0, 1.2], [0, 0.5, 0, 0], [0, 0, 0.5, 0], [0, 0, 0, 1]])
    materials = {"white": {"type": "diffuse", "reflectance": 0.8}}
    lights = [{"type": "point", "position": [0, 0, 3], "intensity": 5}]
    copies = looking_down(materials, [dict(tri, type="mesh", matrix=m, material="white") for m in (left, right)], lights, fov=80)
    instances = looking_down(
        materials, [{"type": "instance", "mesh": "tri", "matrix": m, "material": "white"} for m in (left, right)], lights, fov=80
    )
    instances["meshes"] = {"tri": tri}
    options = dict(integrator="path", passes=2, seed=1, threads=1)
    a = caustica.render(caustica.Scene.from_dict(copies), **options)
    assert a.max() > 0
    np.testing.assert_array_equal(caustica.render(caustica.Scene.from_dict(instances), **options), a)
    instances["shapes"][0]["mesh"] = "square"
    with pytest.raises(ValueError, match=r'shapes\[0\]\.mesh: no mesh named "square"'):
        caustica.Scene.from_dict(instances)


def sky_array():
    """A smooth latitude–longitude sky: red grows with u, green with v, blue constant."""
    h, w = 64, 128
    u = (np.arange(w) + 0.5) / w
    v = (np.arange(h) + 0.5) / h
    sky = np.empty((h, w, 3), dtype=np.float32)
    sky[..., 0] = 0.2 + u[None, :]
    sky[..., 1] = 0.2 + v[:, None]
    sky[..., 2] = 0.5
    return sky


def sky_at(direction):
    """The sky's value along a world direction (caustica's map frame: +y up, the centre −z, u
    = 0.75 towards +x), bilinear as the texture reads it (away from the seam)."""
    d = direction / np.linalg.norm(direction)
    u = (0.5 + np.arctan2(d[0], -d[2]) / (2 * np.pi)) % 1.0
    v = np.arccos(np.clip(d[1], -1, 1)) / np.pi
    return np.array([0.2 + u, 0.2 + v, 0.5])


def test_an_environment_from_an_array_is_seen_along_each_pixels_direction_turned_by_its_rotation():
    # A quarter turn about y: the map's −z looks along −x.
    rotation = np.array([[0, 0, 1], [0, 1, 0], [-1, 0, 0]], dtype=np.float64)
    for r in (None, rotation):
        light = {"type": "environment", "array": sky_array()}
        if r is not None:
            light["rotation"] = r
        d = {
            "camera": {"eye": [0, 0, 0], "look_at": [0.3, 0.2, -1], "fov": 40, "width": 24, "height": 16},
            "lights": [light],
        }
        image = caustica.render(caustica.Scene.from_dict(d), integrator="path", passes=16, seed=1, threads=1)
        # The pixel centres' directions, as the camera spans them (right-handed, +y up).
        view = np.array([0.3, 0.2, -1.0]) / np.linalg.norm([0.3, 0.2, -1.0])
        right = np.cross(view, [0, 1, 0])
        right /= np.linalg.norm(right)
        up = np.cross(right, view)
        h = 2 * np.tan(np.radians(20))
        for y, x in [(2, 3), (8, 12), (13, 20)]:
            sx, sy = (x + 0.5) / 24 - 0.5, 0.5 - (y + 0.5) / 16
            world = view + right * sx * h * 1.5 + up * sy * h
            local = world if r is None else r.T @ world
            np.testing.assert_allclose(image[y, x], sky_at(local), rtol=0.01)


def test_lens_shift_and_crop_show_the_pixels_of_a_wider_and_a_whole_image():
    sky = {"type": "environment", "array": sky_array()}

    def render(**camera):
        d = {"camera": dict({"eye": [0, 0, 0], "look_at": [0, 0.1, -1], "fov": 40}, **camera), "lights": [sky]}
        return caustica.render(caustica.Scene.from_dict(d), integrator="path", passes=16, seed=1, threads=1)

    def same_view(a, b):
        # The sky's texels are read unfiltered: a pixel across a texel edge shows each side
        # in the share its jittered samples fall on, up to a few percent apart in 16 passes;
        # a view off by a pixel would be off by its gradient, 4% in red across the image.
        np.testing.assert_allclose(a, b, rtol=0.02)
        np.testing.assert_allclose(a.mean(axis=(0, 1)), b.mean(axis=(0, 1)), rtol=0.002)

    wide = render(width=64, height=24)
    # A quarter of the image's width to the right: pixels 24–56 of an image twice as wide.
    same_view(render(width=32, height=24, shift=[0.25, 0.0]), wide[:, 24:56])
    # A crop: the same pixels as the whole image's.
    cropped = render(width=64, height=24, crop=[10, 30, 4, 20])
    assert cropped.shape == (16, 20, 3)
    same_view(cropped, wide[4:20, 10:30])
    with pytest.raises(ValueError, match=r"camera\.crop: \[x begin, x end, y begin, y end\] within the 64×24 image"):
        render(width=64, height=24, crop=[10, 70, 4, 20])


def test_coverage_lets_the_sky_through_in_proportion():
    # A black quad of coverage ¼ over a sky of radiance 1, seen from above: ¾ of the sky.
    for coverage in (0.25, {"array": np.full((4, 4), 0.25, dtype=np.float32), "encoding": "linear"}):
        d = looking_down({"black": {"type": "diffuse", "reflectance": 0, "coverage": coverage}}, [quad("black")], SKY)
        image = caustica.render(caustica.Scene.from_dict(d), integrator="path", passes=64, seed=2)
        assert image.mean() == pytest.approx(0.75, rel=0.02)


def test_roughness_and_mix_shares_from_textures_are_their_values_point_by_point():
    options = dict(integrator="path", passes=4, seed=3, threads=1)
    lights = [{"type": "point", "position": [0.5, 0.3, 1.5], "intensity": 3}]

    def render(material):
        d = looking_down({"m": material}, [quad("m")], lights)
        return caustica.render(caustica.Scene.from_dict(d), **options)

    flat = lambda v: {"array": np.full((4, 4), v, dtype=np.float32), "encoding": "linear"}  # noqa: E731
    metal = {"type": "conductor", "reflectance": 0.9}
    a = render(dict(metal, roughness=0.5))
    assert a.max() > 0
    np.testing.assert_allclose(render(dict(metal, roughness=flat(0.5))), a, rtol=1e-5, atol=1e-7)
    parts = [{"type": "diffuse", "reflectance": 0.8}, dict(metal, roughness=0.3)]
    b = render({"type": "mix", "amount": 0.25, "materials": parts})
    np.testing.assert_array_equal(render({"type": "mix", "amount": flat(0.25), "materials": parts}), b)


def test_a_clear_coat_reflects_its_weight_times_fresnel():
    # Black under a smooth coat of index 1.5, seen head-on under a sky of radiance 1: it
    # reflects F(0) = 0.04 of the sky times the weight (the view's 5° off the normal change F
    # by under 0.1%).
    for weight in (1.0, 0.5):
        m = {"type": "diffuse", "reflectance": 0, "clearcoat": {"weight": weight, "roughness": 0, "ior": 1.5}}
        d = looking_down({"m": m}, [quad("m")], SKY, fov=10)
        image = caustica.render(caustica.Scene.from_dict(d), integrator="path", passes=16, seed=2)
        assert image.mean() == pytest.approx(0.04 * weight, rel=0.01)


def test_a_mix_emits_what_it_says_whichever_part_a_point_shows():
    parts = [{"type": "diffuse", "reflectance": 0}, {"type": "conductor", "reflectance": 0.0}]
    m = {"type": "mix", "amount": 0.5, "materials": parts, "emission": 2.0, "two_sided": True}
    d = looking_down({"m": m}, [quad("m")], [])
    image = caustica.render(caustica.Scene.from_dict(d), integrator="path", passes=4, seed=2)
    np.testing.assert_allclose(image, 2.0, rtol=1e-6)


def test_render_settings_in_the_dict_are_the_renders_defaults():
    d = description()
    d["render"] = {"integrator": "ppm", "passes": 3, "photons": 20_000, "max_depth": 4}
    scene = caustica.Scene.from_dict(d)
    with caustica.progressive(scene, threads=1, seed=1) as run:
        images = list(run)
    assert len(images) == 3
    plain = caustica.Scene.from_dict(description())
    np.testing.assert_array_equal(
        images[-1],
        caustica.render(plain, integrator="ppm", passes=3, photons=20_000, depth=3, threads=1, seed=1),
    )
    d["render"]["integrator"] = "bdpt"
    with pytest.raises(ValueError, match=r'render\.integrator: "path", "ppm", "lt" or "vcm", not "bdpt"'):
        caustica.Scene.from_dict(d)


def test_a_sphere_light_lights_the_floor_under_it_as_a_point_of_its_intensity():
    # A ball of intensity I wholly above a plane gives it the irradiance I·cos/d² of a point at
    # its centre: under it, ρ/π · I/h², exact; and its shadow edges soften.
    for light in (
        {"type": "point", "position": [0, 0, 2], "intensity": 8},
        {"type": "sphere", "position": [0, 0, 2], "radius": 0.5, "intensity": 8},
    ):
        d = looking_down({"floor": {"type": "diffuse", "reflectance": 0.5}}, [quad("floor")], [light], fov=10)
        d["camera"]["eye"] = [0, 0, 1]
        image = caustica.render(caustica.Scene.from_dict(d), integrator="path", passes=16, seed=2)
        assert image[6:10, 6:10].mean() == pytest.approx(0.5 / np.pi * 8 / 4, rel=0.01), light["type"]
    with pytest.raises(ValueError, match=r"lights\[0\]\.radius: a radius is not negative"):
        light["radius"] = -1
        caustica.Scene.from_dict(d)


def test_a_uv_transform_reads_the_image_where_transformed_coordinates_would():
    rows = [[(200, 30, 30), (30, 30, 200)], [(10, 220, 10), (250, 250, 250)]]
    texture = {"array": np.array(rows, dtype=np.uint8), "filter": "nearest"}
    # uv' = R(30°)·(2u, 3v) + (0.25, 0.1), as numpy rows on (u, v, 1).
    c, s = np.cos(np.radians(30)), np.sin(np.radians(30))
    m = np.array([[2 * c, -3 * s, 0.25], [2 * s, 3 * c, 0.1], [0, 0, 1]])
    options = dict(integrator="path", passes=2, seed=1, threads=1)

    def render(texture, uvs):
        q = dict(quad("t", 0.5), uvs=uvs)
        d = looking_down({"t": {"type": "diffuse", "reflectance": texture}}, [q], SKY)
        return caustica.render(caustica.Scene.from_dict(d), **options)

    uvs = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=np.float64)
    moved = (m @ np.c_[uvs, np.ones(4)].T).T[:, :2]
    a = render(dict(texture, uv_transform=m), uvs)
    np.testing.assert_allclose(a, render(texture, moved), rtol=1e-4, atol=1e-6)
    # Not the untransformed image.
    assert np.abs(a - render(texture, uvs)).max() > 0.05
    with pytest.raises(ValueError, match="uv_transform: expected a 3×3 affine matrix"):
        render(dict(texture, uv_transform=np.eye(3) * 2), uvs)


def test_a_thin_lens_blurs_what_is_out_of_focus_by_its_circle_of_confusion():
    # A small glowing square 4 away, the lens focused at 2 with an aperture of radius 0.1: on the
    # focus plane its light spreads over a disc of radius 0.1·|4 − 2|/4 = 0.05 around its image,
    # whose pixels' mean squared distance from the centre is r²/2. The light it sends in is kept.
    fov, size = 20.0, 64
    glow = {"type": "diffuse", "reflectance": 0, "emission": 50.0, "two_sided": True}
    s = 0.01
    square = {
        "type": "mesh",
        "positions": [[-s, -s, -4], [s, -s, -4], [s, s, -4], [-s, s, -4]],
        "indices": [[0, 1, 2], [0, 2, 3]],
        "material": "glow",
    }

    def render(**lens):
        camera = dict({"eye": [0, 0, 0], "look_at": [0, 0, -1], "fov": fov, "width": size, "height": size}, **lens)
        d = {"camera": camera, "materials": {"glow": glow}, "shapes": [square], "lights": []}
        return caustica.render(caustica.Scene.from_dict(d), integrator="path", passes=256, seed=1).sum(axis=2)

    pinhole = render()
    blurred = render(aperture=0.1, focus_distance=2.0)
    np.testing.assert_allclose(blurred.sum(), pinhole.sum(), rtol=0.02)
    # Pixels per unit on the focus plane: size / (2·2·tan(fov/2)).
    per_unit = size / (2 * 2.0 * np.tan(np.radians(fov / 2)))
    y, x = np.mgrid[0:size, 0:size] + 0.5
    r2 = ((x - size / 2) ** 2 + (y - size / 2) ** 2) * blurred
    radius = np.sqrt(2 * r2.sum() / blurred.sum())
    assert radius == pytest.approx(0.05 * per_unit, rel=0.1)
    # In focus, the square stays as sharp as the pinhole shows it.
    sharp = render(aperture=0.1, focus_distance=4.0)
    r2 = ((x - size / 2) ** 2 + (y - size / 2) ** 2) * sharp
    assert np.sqrt(2 * r2.sum() / sharp.sum()) < 0.25 * radius


def test_light_tracing_and_vcm_see_through_the_lens_as_camera_paths_do():
    # A checker floor under a point light, seen through a lens focused in front of it: light
    # tracing (which finds the pixel from the lens point) and vcm against path tracing, block by
    # block (measured: light tracing within 0.6%; the pinhole's blocks differ by up to 21%).
    rows = [[(220, 220, 220), (120, 120, 120)], [(120, 120, 120), (220, 220, 220)]]
    floor = {"type": "diffuse", "reflectance": {"array": np.array(rows, dtype=np.uint8), "filter": "nearest"}}
    d = {
        "camera": {"eye": [0, 2, 3], "look_at": [0, 0, 0], "fov": 40, "width": 32, "height": 32,
                   "aperture": 0.15, "focus_distance": 2.0},
        "materials": {"floor": floor},
        "shapes": [{
            "type": "mesh",
            "positions": [[-2, 0, -2], [2, 0, -2], [2, 0, 2], [-2, 0, 2]],
            "uvs": [[0, 0], [1, 0], [1, 1], [0, 1]],
            "indices": [[0, 2, 1], [0, 3, 2]],
            "material": "floor",
        }],
        "lights": [{"type": "point", "position": [0.5, 3, 0.5], "intensity": 10}],
    }
    scene = caustica.Scene.from_dict(d)
    path = caustica.render(scene, integrator="path", passes=128, seed=1, depth=1)
    lt = caustica.render(scene, integrator="lt", passes=128, seed=1, depth=1)
    blocks = lambda a: a.sum(axis=2).reshape(4, 8, 4, 8).mean(axis=(1, 3))  # noqa: E731
    bp, bl = blocks(path), blocks(lt)
    lit = bp > 0.2 * bp.max()
    assert lit.sum() >= 8
    np.testing.assert_allclose(bl[lit], bp[lit], rtol=0.05)
    # vcm weighs both against each other through the lens as well.
    vcm = blocks(caustica.render(scene, integrator="vcm", passes=64, seed=1, depth=1))
    np.testing.assert_allclose(vcm[lit], bp[lit], rtol=0.05)
    # The lens matters here: the pinhole's blocks differ.
    d["camera"]["aperture"] = 0.0
    pinhole = blocks(caustica.render(caustica.Scene.from_dict(d), integrator="path", passes=128, seed=1, depth=1))
    assert np.abs(pinhole[lit] / bp[lit] - 1).max() > 0.1


def test_media_fill_objects_and_the_scene():
    # A ball of fog that scatters everything, bounded by a `boundary`, under a white sky: the
    # furnace, every pixel 1 (also with the fog as the scene's `medium`, the ball then only the
    # scene's extent). Unknown names and a boundary without a medium are errors. vcm's beam
    # queries lose light past the ball's curved edge when their radius (pixels wide) is a fair
    # part of it: 8% at 8 px, about 1% at 64.
    fog = {"scattering": [2, 1.5, 1], "g": 0.5}
    d = {
        "camera": {"eye": [0, 0, 4], "look_at": [0, 0, 0], "fov": 30, "width": 8, "height": 8},
        "media": {"fog": fog},
        "materials": {"edge": {"type": "boundary", "inside": "fog"}},
        "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "edge"}],
        "lights": SKY,
    }
    for integrator, passes, size in (("path", 256, 8), ("vcm", 16, 64)):
        image = caustica.render(caustica.Scene.from_dict(d), integrator=integrator, passes=passes, seed=2,
                                width=size, height=size)
        np.testing.assert_allclose(image.mean(axis=(0, 1)), 1.0, rtol=0.02, err_msg=integrator)
    d["medium"] = "fog"
    d["materials"]["edge"] = {"type": "diffuse", "reflectance": 1, "coverage": 0}
    image = caustica.render(caustica.Scene.from_dict(d), integrator="vcm", passes=16, seed=2, width=64, height=64)
    np.testing.assert_allclose(image.mean(axis=(0, 1)), 1.0, rtol=0.02)
    d["materials"]["edge"] = {"type": "boundary", "inside": "smoke"}
    with pytest.raises(ValueError, match=r'materials\.edge\.inside: no medium named "smoke"'):
        caustica.Scene.from_dict(d)
    d["materials"]["edge"] = {"type": "boundary"}
    with pytest.raises(ValueError, match=r"materials\.edge: a boundary has a medium"):
        caustica.Scene.from_dict(d)
    d["materials"]["edge"] = {"type": "boundary", "inside": "fog"}
    d["media"]["fog"] = {"scattering": 1, "g": 1}
    with pytest.raises(ValueError, match=r"media\.fog\.g: a mean cosine strictly between"):
        caustica.Scene.from_dict(d)
