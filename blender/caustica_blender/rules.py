"""How Blender's values become caustica's: plain arithmetic, no Blender (tested outside it,
python/tests/test_blender_rules.py). Lights follow Cycles' units, measured against Cycles by
scripts/race/blender_lights.py."""

import math


def vertical_fov(sensor_fit, sensor_width, sensor_height, lens, width, height):
    """The vertical field of view in degrees of a Blender camera rendering `width`×`height`:
    the sensor's fitted side (AUTO: the image's longer one) spans its own angle."""
    fit = sensor_fit
    if fit == "AUTO":
        fit = "HORIZONTAL" if width >= height else "VERTICAL"
    sensor = sensor_height if sensor_fit == "VERTICAL" else sensor_width
    half = math.atan(0.5 * sensor / lens)
    if fit == "HORIZONTAL":
        half = math.atan(math.tan(half) * height / width)
    return math.degrees(2.0 * half)


def point_intensity(energy):
    """A point or spot light of `energy` watts: its intensity in W/sr, P/(4π)."""
    return energy / (4.0 * math.pi)


def spot_cone(spot_size, blend):
    """A spot of full angle `spot_size` (radians) and `blend`: its outer and inner half-angles in
    degrees. Cycles fades a spot by a smoothstep in the cosine over the blend's share of the
    cosines between its edge and its axis, as caustica fades from the inner cone to the outer."""
    outer = math.degrees(spot_size) / 2.0
    cos_outer = math.cos(math.radians(outer))
    inner = math.degrees(math.acos(min(1.0, cos_outer + (1.0 - cos_outer) * blend)))
    return outer, min(inner, outer)


def area_radiance(energy, area):
    """An area light of `energy` watts and `area` m²: the radiance Cycles gives it, P/(4A)."""
    return energy / (4.0 * area)


def coat_ior(specular):
    """The index whose normal reflectance is Blender's Principled Specular × 0.08."""
    f0 = min(0.99, 0.08 * specular)
    return (1.0 + math.sqrt(f0)) / (1.0 - math.sqrt(f0))


def principled(base, metallic, roughness, transmission, ior, specular):
    """The Principled BSDF's reading: metal from metallic ½, glass from transmission ½, else the
    base colour under a coat of `coat_ior(specular)` (none at Specular 0); GGX α = roughness²."""
    alpha = roughness * roughness
    if metallic >= 0.5:
        return {"type": "conductor", "reflectance": base, "alpha": alpha}
    if transmission >= 0.5:
        return {"type": "glass", "ior": max(1.0, ior), "alpha": alpha, "tint": base}
    if specular > 0.0:
        return {"type": "coated", "reflectance": base, "ior": coat_ior(specular), "alpha": alpha}
    return {"type": "diffuse", "reflectance": base}
