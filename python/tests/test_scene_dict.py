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
