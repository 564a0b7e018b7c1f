"""The add-on's conversion rules (`blender/caustica_blender/rules.py`), outside Blender: the
camera's field of view by sensor fit, the lights' units as Cycles has them, and the Principled
BSDF's reading."""
import math
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "blender"))
from caustica_blender import rules  # noqa: E402


def test_the_sensor_fit_decides_which_side_the_lens_angle_spans():
    # Blender's default: a 50 mm lens on a 36 × 24 mm sensor spans 2·atan(18/50) = 39.6°.
    wide = 2.0 * math.degrees(math.atan(18.0 / 50.0))
    # Landscape with AUTO: the width spans it, so the vertical angle is narrower by the aspect.
    vertical = 2.0 * math.degrees(math.atan(18.0 / 50.0 * 1080.0 / 1920.0))
    assert rules.vertical_fov("AUTO", 36.0, 24.0, 50.0, 1920, 1080) == pytest.approx(vertical)
    # Portrait with AUTO: the height is the longer side and spans it.
    assert rules.vertical_fov("AUTO", 36.0, 24.0, 50.0, 1080, 1920) == pytest.approx(wide)
    # VERTICAL: the sensor's height spans the image's height.
    assert rules.vertical_fov("VERTICAL", 36.0, 24.0, 50.0, 1920, 1080) == pytest.approx(
        2.0 * math.degrees(math.atan(12.0 / 50.0))
    )
    # HORIZONTAL on a portrait image: the width still spans the sensor's width.
    assert rules.vertical_fov("HORIZONTAL", 36.0, 24.0, 50.0, 1080, 1920) == pytest.approx(
        2.0 * math.degrees(math.atan(18.0 / 50.0 * 1920.0 / 1080.0))
    )


def test_lights_take_cycles_units():
    assert rules.point_intensity(1000.0) == pytest.approx(1000.0 / (4.0 * math.pi))
    assert rules.area_radiance(500.0, 2.0) == pytest.approx(62.5)
    assert rules.spot_cone(math.radians(60.0), 0.0) == pytest.approx((30.0, 30.0))
    assert rules.spot_cone(math.radians(60.0), 1.0) == pytest.approx((30.0, 0.0), abs=1e-5)
    # Blend ½: half the cosines between the edge and the axis fade.
    c = math.cos(math.radians(30.0))
    assert rules.spot_cone(math.radians(60.0), 0.5)[1] == pytest.approx(math.degrees(math.acos(c + (1 - c) / 2)))


def test_the_principled_bsdf_reads_as_metal_glass_or_coated_base():
    base = [0.8, 0.5, 0.2]
    assert rules.principled(base, 1.0, 0.5, 0.0, 1.45, 0.5) == {"type": "conductor", "reflectance": base, "roughness": 0.5}
    assert rules.principled(base, 0.0, 0.0, 1.0, 1.5, 0.5) == {"type": "glass", "ior": 1.5, "roughness": 0.0, "tint": base}
    coated = rules.principled(base, 0.0, 0.2, 0.0, 1.45, 0.5)
    # Specular 0.5 is F0 = 4%, the index 1.5.
    assert coated["type"] == "coated" and coated["ior"] == pytest.approx(1.5) and coated["roughness"] == 0.2
    # Blender 3's specular lobe adds to the diffuse one.
    assert coated["layering"] == "added"
    assert rules.principled(base, 0.0, 0.2, 0.0, 1.45, 0.0) == {"type": "diffuse", "reflectance": base}


def test_shares_between_the_ends_are_mixes_as_cycles_blends_them():
    base = [0.8, 0.5, 0.2]
    m = rules.principled(base, 0.3, 0.5, 0.6, 1.5, 0.0)
    # Metal takes 0.3; of the rest glass takes 0.6, the diffuse base 0.4.
    assert m["type"] == "mix" and m["amount"] == 0.3 and m["materials"][1]["type"] == "conductor"
    inner = m["materials"][0]
    assert inner["type"] == "mix" and inner["amount"] == 0.6
    assert [p["type"] for p in inner["materials"]] == ["diffuse", "glass"]
    # A texture decides the share point by point: always a mix.
    texture = {"array": [[1.0]], "encoding": "linear"}
    m = rules.principled(base, texture, 0.5, 0.0, 1.5, 0.0)
    assert m["type"] == "mix" and m["amount"] is texture


def test_the_clear_coat_is_a_quarter_of_cycles_clearcoat_input():
    m = rules.principled([0.5] * 3, 0.0, 0.5, 0.0, 1.45, 0.5, clearcoat=1.0, clearcoat_roughness=0.1)
    assert m["clearcoat"] == {"weight": 0.25, "roughness": 0.1, "ior": 1.5}
    assert "clearcoat" not in rules.principled([0.5] * 3, 0.0, 0.5, 0.0, 1.45, 0.5)


def test_the_add_shader_sums_its_two_closures():
    diffuse = {"type": "diffuse", "reflectance": [0.4, 0.4, 0.4]}
    glow = {"type": "diffuse", "reflectance": 0.0, "emission": [2.0, 1.0, 0.5], "two_sided": True}
    assert rules.added(glow, diffuse) == {**diffuse, "emission": [2.0, 1.0, 0.5], "two_sided": True}
    assert rules.added(diffuse, {"type": "diffuse", "reflectance": 0.0}) == diffuse
    metal = {"type": "conductor", "reflectance": [0.9, 0.6, 0.3], "roughness": 0.2}
    m = rules.added(diffuse, metal)
    assert m["type"] == "mix" and m["amount"] == 0.5
    assert m["materials"][0]["reflectance"] == [0.8, 0.8, 0.8]
    # A metal reflects at most all the light.
    assert m["materials"][1]["reflectance"] == [1.0, 1.0, 0.6]


def test_lens_shift_and_border_in_the_units_the_scene_dict_reads():
    # AUTO: the longer side is the unit either way.
    assert rules.lens_shift("AUTO", 0.1, -0.2, 1920, 1080) == [0.1, -0.2]
    # VERTICAL on a landscape image: the height is the unit, 1080/1920 of the longer side.
    assert rules.lens_shift("VERTICAL", 0.1, 0.0, 1920, 1080) == pytest.approx([0.05625, 0.0])
    # A border over the left half and the bottom quarter of a 200×100 image: rows 75–100.
    assert rules.border(0.0, 0.5, 0.0, 0.25, 200, 100) == [0, 100, 75, 100]


def test_the_environment_rotation_points_the_image_centre_along_blenders_x():
    r = rules.environment_rotation()
    centre = [sum(r[i][j] * d for j, d in enumerate([0.0, 0.0, -1.0])) for i in range(3)]
    up = [sum(r[i][j] * d for j, d in enumerate([0.0, 1.0, 0.0])) for i in range(3)]
    quarter = [sum(r[i][j] * d for j, d in enumerate([1.0, 0.0, 0.0])) for i in range(3)]
    assert centre == [1.0, 0.0, 0.0] and up == [0.0, 0.0, 1.0]
    # u = 0.75 is where Blender's u = 0.5 − atan2(y, x)/2π is 0.75: towards −y.
    assert quarter == [0.0, -1.0, 0.0]
    # A Mapping node's 90° about z: the texture is looked up at Rz·d.
    rz = [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]
    r = rules.environment_rotation(rz)
    centre = [sum(r[i][j] * d for j, d in enumerate([0.0, 0.0, -1.0])) for i in range(3)]
    # Looked up at R·d: the image's centre (+x in Blender's frame) is seen along Rᵀ·x = −y.
    assert centre == [0.0, -1.0, 0.0]


def test_a_texture_mapping_is_the_inverse_of_a_point_mapping():
    point = rules.uv_mapping("POINT", [0.3, -0.2], 0.4, [2.0, 0.5])
    texture = rules.uv_mapping("TEXTURE", [0.3, -0.2], 0.4, [2.0, 0.5])
    product = [[sum(point[i][k] * texture[k][j] for k in range(3)) for j in range(3)] for i in range(3)]
    flat = [x for row in product for x in row]
    assert flat == pytest.approx([1, 0, 0, 0, 1, 0, 0, 0, 1], abs=1e-12)
    # Vector mappings ignore the location.
    assert rules.uv_mapping("VECTOR", [5.0, 5.0], 0.0, [2.0, 3.0]) == [[2.0, -0.0, 0.0], [0.0, 3.0, 0.0], [0.0, 0.0, 1.0]]


def test_the_aperture_is_half_the_focal_length_over_the_f_stop():
    # 50 mm at f/2: a radius of 12.5 mm, in metres; in a scene whose unit is a centimetre, 1.25.
    assert rules.aperture_radius(50.0, 2.0) == pytest.approx(0.0125)
    assert rules.aperture_radius(50.0, 2.0, 0.01) == pytest.approx(1.25)
