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
    assert rules.principled(base, 1.0, 0.5, 0.0, 1.45, 0.5) == {"type": "conductor", "reflectance": base, "alpha": 0.25}
    assert rules.principled(base, 0.0, 0.0, 1.0, 1.5, 0.5) == {"type": "glass", "ior": 1.5, "alpha": 0.0, "tint": base}
    coated = rules.principled(base, 0.0, 0.2, 0.0, 1.45, 0.5)
    # Specular 0.5 is F0 = 4%, the index 1.5.
    assert coated["type"] == "coated" and coated["ior"] == pytest.approx(1.5) and coated["alpha"] == pytest.approx(0.04)
    assert rules.principled(base, 0.0, 0.2, 0.0, 1.45, 0.0) == {"type": "diffuse", "reflectance": base}
