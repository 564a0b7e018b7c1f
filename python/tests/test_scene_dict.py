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
