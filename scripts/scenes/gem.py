#!/usr/bin/env python3
"""Writes scenes/gem.ray: a round brilliant-cut diamond on a white table under a small lamp
and the sun, throwing its fire (rainbow-edged caustic sparks) on the table.

The cut is the classic round brilliant with flat facets: an octagonal table, 8 star and 8
kite (bezel) facets, 16 upper girdle facets on the crown, 8 main and 16 lower girdle facets on
the pavilion. Proportions are Tolkowsky's ideal: table 53%, crown angle 34.5°, pavilion angle
40.75% (of the girdle diameter). Diamond: n_d = 2.417, V_d = 55.3.
"""
import math
import sys
from pathlib import Path

N_D, ABBE = 2.417, 55.3
RADIUS = 1.0                       # girdle radius
TABLE = 0.53                       # table width over the girdle diameter
CROWN = math.radians(34.5)
PAVILION = math.radians(40.75)
GIRDLE = 0.02                      # girdle half-thickness


def ring(count, radius, height, offset=0.0):
    return [(radius * math.cos(2 * math.pi * (i + offset) / count),
             radius * math.sin(2 * math.pi * (i + offset) / count), height) for i in range(count)]


def outward(points, face):
    """The face with its corners counter-clockwise seen from outside (the stone is convex, so
    outside is away from its centre)."""
    centre = [sum(p[k] for p in points) / len(points) for k in range(3)]
    a, b, c = (points[i] for i in face[:3])
    u = [b[k] - a[k] for k in range(3)]
    v = [c[k] - a[k] for k in range(3)]
    n = (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])
    mid = [sum(points[i][k] for i in face) / len(face) for k in range(3)]
    outside = sum(n[k] * (mid[k] - centre[k]) for k in range(3)) > 0
    return face if outside else tuple(reversed(face))


def check_closed(faces):
    """Every edge is shared by exactly two faces, in opposite directions."""
    edges = {}
    for f in faces:
        for a, b in zip(f, f[1:] + f[:1]):
            edges[(a, b)] = edges.get((a, b), 0) + 1
    for (a, b), count in edges.items():
        assert count == 1 and edges.get((b, a)) == 1, f"edge {a}-{b} is not closed"


def main():
    crown_height = (RADIUS - TABLE * RADIUS) * math.tan(CROWN)
    pavilion_depth = RADIUS * math.tan(PAVILION)
    # Rings, bottom to top: culet, pavilion main tips, girdle (16, below and above), crown
    # kite tips, table (8).
    top = GIRDLE + crown_height
    table = ring(8, TABLE * RADIUS / math.cos(math.pi / 8), top, 0.0)
    kite = ring(8, 0.5 * (RADIUS + TABLE * RADIUS), GIRDLE + crown_height / 2, 0.5)
    upper = ring(16, RADIUS, GIRDLE)
    lower = ring(16, RADIUS, -GIRDLE)
    main_tips = ring(8, 0.45 * RADIUS, -GIRDLE - 0.55 * pavilion_depth, 0.0)
    culet = [(0.0, 0.0, -GIRDLE - pavilion_depth)]
    points = table + kite + upper + lower + main_tips + culet
    T, K, U, L, M, C = 0, 8, 16, 32, 48, 56
    faces = [tuple(range(T, T + 8))]                          # the table, seen from above
    for i in range(8):
        a, b = T + i, T + (i + 1) % 8
        k = K + i                                           # kite tip between table corners a and b
        faces.append((a, k, b))                       # star facet
        # the kite: table corner b, kite tips, girdle point under b
        g = U + (2 * i + 2) % 16                            # girdle under table corner b
        faces.append((b, k, g, K + (i + 1) % 8))
        # upper girdle facets: between kite tip k and the girdle points beside it
        g0, g1, g2 = U + 2 * i, U + 2 * i + 1, U + (2 * i + 2) % 16
        faces.append((k, g0, g1))
        faces.append((k, g1, g2))
    for i in range(16):                                       # the girdle band
        a, b = i, (i + 1) % 16
        faces.append((U + a, L + a, L + b, U + b))
    for i in range(8):
        m = M + i                                           # main pavilion tip under girdle 2i
        gprev, g, gnext = L + (2 * i - 1) % 16, L + 2 * i, L + 2 * i + 1
        faces.append((g, m, gprev))                   # lower girdle facets
        faces.append((g, gnext, m))
        faces.append((m, gnext, M + (i + 1) % 8, C))          # main facet between tips
    faces = [outward(points, f) for f in faces]
    check_closed(faces)
    text_points = ",".join(f"({x:.5f},{y:.5f},{z:.5f})" for x, y, z in points)
    text_faces = ",".join("(" + ",".join(str(i) for i in f) + ")" for f in faces)
    lines = [
        "SBT-raytracer 1.0",
        "// A round brilliant-cut diamond on a white table, lit by a small lamp and the sun: its",
        "// fire (caustic sparks with rainbow edges) falls on the table.",
        "// Written by scripts/scenes/gem.py; edit that instead.",
        "",
        "camera {",
        "\tposition = (0, -6.5, 5.0);",
        "\tviewdir = (0, 0.78, -0.62);",
        "\tupdir = (0, 0, 1);",
        "\tfov = 40;",
        "}",
        "",
        "point_light { position = (-2.5, 1.5, 5); color = (14, 13.5, 12.5); "
        "constant_attenuation_coeff = 0; linear_attenuation_coeff = 0; quadratic_attenuation_coeff = 1; }",
        "sun_light { direction = (0.5, 0.6, -1); color = (0.6, 0.6, 0.58); angle = 0.53; }",
        "ambient_light { color = (0.05, 0.05, 0.05); }",
        "",
        "// the table",
        "translate(0, 0, -0.25, scale(30, 30, 0.5, box { material = { diffuse = (0.8, 0.8, 0.78); ambient = (0.8, 0.8, 0.78); } }))",
        "",
        "// the diamond, resting on its pavilion tilted so that its crown faces the lamp",
        f"translate(0, 0, {pavilion_depth * 0.93 + GIRDLE:.4f}, rotate(1, 1, 0, 0.5,",
        "\tpolymesh {",
        f"\t\tmaterial = {{ transmissive = (1, 1, 1); specular = (0.15, 0.15, 0.15); shininess = 400; "
        f"index = {N_D}; abbe = {ABBE}; }};",
        f"\t\tpoints = ({text_points});",
        f"\t\tfaces = ({text_faces});",
        "\t}))",
    ]
    out = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).resolve().parents[2] / "scenes" / "gem.ray"
    out.write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
