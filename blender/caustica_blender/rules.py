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


def lens_shift(sensor_fit, shift_x, shift_y, width, height):
    """Blender's lens shift (in units of the sensor's fitted side: AUTO the image's longer
    side) in units of the image's longer side, as `Scene.from_dict` reads it."""
    side = {"HORIZONTAL": width, "VERTICAL": height}.get(sensor_fit, max(width, height))
    f = side / max(width, height)
    return [shift_x * f, shift_y * f]


def border(min_x, max_x, min_y, max_y, width, height):
    """Blender's render border (fractions, y from the bottom) in pixels [x begin, x end, y begin,
    y end], rows from the top, as Blender's render result sizes it."""
    x0, x1 = int(min_x * width), int(max_x * width)
    y0, y1 = int(min_y * height), int(max_y * height)
    return [x0, max(x1, x0 + 1), height - max(y1, y0 + 1), height - y0]


def aperture_radius(lens_mm, fstop, unit_scale=1.0):
    """The aperture radius in scene units of a lens of `lens_mm` at f-stop `fstop`: half the
    focal length over the f-stop, the millimetres in metres over the scene's unit scale."""
    return 0.5 * lens_mm * 1e-3 / max(fstop, 1e-6) / unit_scale


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


def is_texture(value):
    return isinstance(value, dict)


def mix(first, second, amount):
    """`second` with the share `amount` (a number or a texture), else `first`; the ends alone
    where the share is a number at 0 or 1."""
    if not is_texture(amount):
        if amount <= 0.0:
            return first
        if amount >= 1.0:
            return second
    return {"type": "mix", "amount": amount, "materials": [first, second]}


def principled(
    base, metallic, roughness, transmission, ior, specular, clearcoat=0.0, clearcoat_roughness=0.03, layering="added"
):
    """The Principled BSDF as Cycles blends it: metal with the share `metallic`; the rest glass
    with the share `transmission`, else the base colour under a coat of `coat_ior(specular)`
    (bare at Specular 0), the coat's light added to the base's or taken from it as `layering`
    says. Shares are mixes (numbers or textures); roughness r (a number or a
    texture) is GGX α = r². A clear coat of weight ¼·`clearcoat` (Cycles' Disney coat) covers it."""
    opaque = {"type": "diffuse", "reflectance": base}
    if specular > 0.0:
        # Blender 3's Principled adds its specular lobe to the whole diffuse one ("added");
        # Blender 4's takes the specular's share from it ("fresnel"). A varnish's layered coat
        # would be a third darker still.
        opaque = {
            "type": "coated",
            "reflectance": base,
            "ior": coat_ior(specular),
            "roughness": roughness,
            "layering": layering,
        }
    glass = {"type": "glass", "ior": max(1.0, ior), "roughness": roughness, "tint": base}
    metal = {"type": "conductor", "reflectance": base, "roughness": roughness}
    out = mix(mix(opaque, glass, transmission), metal, metallic)
    if is_texture(clearcoat) or clearcoat > 0.0:
        weight = clearcoat if is_texture(clearcoat) else min(1.0, 0.25 * clearcoat)
        if is_texture(weight):
            weight = dict(weight, scale=0.25)
        out = dict(out, clearcoat={"weight": weight, "roughness": clearcoat_roughness, "ior": 1.5})
    return out


def added(first, second):
    """Cycles' Add Shader: the sum of two closures. An emission added to a surface is that
    surface emitting; two surfaces are a half-and-half mix of each at twice its colours (the
    same sum in the mean)."""
    for a, b in ((first, second), (second, first)):
        if a == {"type": "diffuse", "reflectance": 0.0}:
            # Nothing linked: adds nothing.
            return b
    for a, b in ((first, second), (second, first)):
        if a.get("type") == "diffuse" and a.get("reflectance") in (0.0, [0.0, 0.0, 0.0]) and "emission" in a:
            out = dict(b)
            emission = a["emission"]
            if "emission" in b and not is_texture(b["emission"]) and not is_texture(emission):
                emission = [x + y for x, y in zip(rgb(b["emission"]), rgb(emission))]
            out["emission"] = emission
            out["two_sided"] = True
            return out
    return {"type": "mix", "amount": 0.5, "materials": [scaled(first, 2.0), scaled(second, 2.0)]}


def rgb(value):
    return [float(value)] * 3 if isinstance(value, (int, float)) else list(value)


def scaled(material, factor):
    """`material` with its colours (reflectance, tint, emission) times `factor`; a metal's
    reflectance is at most 1."""
    out = dict(material)
    if out.get("type") == "mix":
        out["materials"] = [scaled(m, factor) for m in out["materials"]]
    for key in ("reflectance", "tint", "emission"):
        if key not in out:
            continue
        value = out[key]
        if is_texture(value):
            scale = rgb(value.get("scale", 1.0))
            out[key] = dict(value, scale=[factor * s for s in scale])
        else:
            limit = 1.0 if out.get("type") == "conductor" and key == "reflectance" else float("inf")
            out[key] = [min(limit, factor * x) for x in rgb(value)]
    return out


def uv_mapping(kind, location, angle, scale):
    """A Mapping node on texture coordinates as a 3×3 matrix on (u, v, 1): Point and Vector
    map uv to R(S·uv) + L (Vector without L), Texture is the inverse of Point."""
    c, s = math.cos(angle), math.sin(angle)
    sx, sy = scale
    lx, ly = location if kind != "VECTOR" else (0.0, 0.0)
    point = [[c * sx, -s * sy, lx], [s * sx, c * sy, ly], [0.0, 0.0, 1.0]]
    if kind != "TEXTURE":
        return point
    # Inverse: S⁻¹ Rᵀ (uv − L).
    if sx == 0.0 or sy == 0.0:
        return [[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 1.0]]
    rt = [[c / sx, s / sx], [-s / sy, c / sy]]
    return [
        [rt[0][0], rt[0][1], -(rt[0][0] * lx + rt[0][1] * ly)],
        [rt[1][0], rt[1][1], -(rt[1][0] * lx + rt[1][1] * ly)],
        [0.0, 0.0, 1.0],
    ]


def environment_rotation(mapping_rotation=None):
    """The world-from-map rotation of Blender's equirectangular environment (z up, the image's
    centre towards +x, its u turning towards −y) in caustica's map frame (+y up, the centre
    towards −z, u towards +x); `mapping_rotation` is a Mapping node's 3×3 rotation applied to
    the lookup direction."""
    blender_from_map = [[0.0, 0.0, -1.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]
    if mapping_rotation is None:
        return blender_from_map
    # The texture is looked up at R·d: the world direction is Rᵀ times the map's.
    rt = [[mapping_rotation[j][i] for j in range(3)] for i in range(3)]
    return [[sum(rt[i][k] * blender_from_map[k][j] for k in range(3)) for j in range(3)] for i in range(3)]
