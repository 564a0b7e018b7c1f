#!/usr/bin/env python3
"""Writes scenes/glass_of_water.ray: a tumbler half full of water on a wooden table, lit by a
low lamp: the glass and the water throw a bright caustic into the glass's shadow.

Both are lathed meshes with smooth normals: the glass a closed shell (outer wall, rim, inner
wall, thick base), the water a closed body a hair inside the inner wall (the small gap stands
for the glass-water interface, refracting glass to air to water instead of glass to water).
"""
import math
import sys
from pathlib import Path

SEGMENTS = 96
OUTER, INNER = 1.0, 0.92          # wall radii
HEIGHT, BASE = 2.6, 0.22          # glass height, base thickness
WATER = 1.5                       # water level
GAP = 0.002                       # between water and glass


def lathe(profile, closed_bottom=True, closed_top=True):
    """Points and faces of the surface swept by `profile` [(r, z), ...] (bottom to top, an
    outward-facing side on the left of travel) around the z axis, with fans closing the ends
    where r > 0."""
    points, faces = [], []
    rows = len(profile)
    for r, z in profile:
        for s in range(SEGMENTS):
            a = 2 * math.pi * s / SEGMENTS
            points.append((r * math.cos(a), r * math.sin(a), z))
    for j in range(rows - 1):
        for s in range(SEGMENTS):
            a, b = j * SEGMENTS + s, j * SEGMENTS + (s + 1) % SEGMENTS
            faces.append((a, b, b + SEGMENTS))
            faces.append((a, b + SEGMENTS, a + SEGMENTS))
    if closed_bottom:
        centre = len(points)
        points.append((0.0, 0.0, profile[0][1]))
        for s in range(SEGMENTS):
            faces.append((centre, (s + 1) % SEGMENTS, s))
    if closed_top:
        centre = len(points)
        points.append((0.0, 0.0, profile[-1][1]))
        top = (rows - 1) * SEGMENTS
        for s in range(SEGMENTS):
            faces.append((centre, top + s, top + (s + 1) % SEGMENTS))
    return points, faces


def mesh(points, faces, material):
    p = ",".join(f"({x:.5f},{y:.5f},{z:.5f})" for x, y, z in points)
    f = ",".join(f"({a},{b},{c})" for a, b, c in faces)
    return ["polymesh {", f"\tmaterial = {material};", "\tgennormals;", f"\tpoints = ({p});",
            f"\tfaces = ({f});", "}"]


def main():
    # The glass, from the centre of its underside out, up the outside, over the rim and down
    # the inside to the centre of the inner floor: a closed surface of revolution.
    rim = (OUTER + INNER) / 2
    glass_profile = [(OUTER - 0.04, 0.0), (OUTER, 0.04), (OUTER, HEIGHT - 0.02), (rim, HEIGHT),
                     (INNER, HEIGHT - 0.02), (INNER, BASE + 0.03), (INNER - 0.03, BASE)]
    glass_points, glass_faces = lathe(glass_profile)
    # The lathe closes the underside (outward, down) and the inner floor; the inner floor's fan
    # must face up into the glass's hollow, which is outward for the glass body.
    water_profile = [(INNER - 0.03 - GAP, BASE + GAP), (INNER - GAP, BASE + 0.03 + GAP), (INNER - GAP, WATER)]
    water_points, water_faces = lathe(water_profile)
    glass = "{ transmissive = (0.96, 0.97, 0.97); specular = (0.2, 0.2, 0.2); shininess = 300; index = 1.5; }"
    water = "{ transmissive = (0.93, 0.97, 0.99); specular = (0.1, 0.1, 0.1); shininess = 300; index = 1.33; }"
    lines = [
        "SBT-raytracer 1.0",
        "// A tumbler half full of water on a wooden table under a low lamp: glass and water throw",
        "// a bright caustic into the glass's shadow.",
        "// Written by scripts/scenes/glass_of_water.py; edit that instead.",
        "",
        "camera {",
        "\tposition = (0, -10.5, 5.6);",
        "\tviewdir = (0, 0.9, -0.44);",
        "\tupdir = (0, 0, 1);",
        "\tfov = 38;",
        "}",
        "",
        "point_light { position = (-1.5, 5.5, 3.2); color = (30, 28, 25); "
        "constant_attenuation_coeff = 0; linear_attenuation_coeff = 0; quadratic_attenuation_coeff = 1; }",
        "ambient_light { color = (0.08, 0.08, 0.08); }",
        "",
        "// the table and a wall behind it",
        "translate(0, 0, -0.25, scale(30, 30, 0.5, box { material = { diffuse = (0.55, 0.4, 0.28); ambient = (0.55, 0.4, 0.28); } }))",
        "translate(0, 9, 5, scale(30, 0.5, 10, box { material = { diffuse = (0.7, 0.72, 0.7); ambient = (0.7, 0.72, 0.7); } }))",
        "",
        "// the glass",
    ]
    lines += mesh(glass_points, glass_faces, glass)
    lines.append("// the water")
    lines += mesh(water_points, water_faces, water)
    out = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).resolve().parents[2] / "scenes" / "glass_of_water.ray"
    out.write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
