#!/usr/bin/env python3
"""Writes scenes/pool.ray: a swimming pool under the sun and a blue sky, whose wavy water
surface (a smooth-normal mesh) focuses sunlight into a caustic net on the tiled floor.
`--murky` writes scenes/pool_murky.ray instead: the same pool of slightly murky water (a medium
that scatters, forward) seen by a camera under water, where the waves' focused sunlight shows
as shafts through the water.

The waves are a sum of sines chosen so that their curvature focuses near the floor: a wave
of amplitude a and wavelength L has peak curvature a(2π/L)², and a water lens of curvature k
focuses at about n / ((n − 1) k) below the surface (n = 1.33), 2 units here.
"""
import math
import sys
from pathlib import Path

HALF = 4.0          # the pool is 8 × 8 inside
DEPTH = 2.0         # floor 2 below the water
GRID = 129          # water vertices per side: 9 or more per wavelength
WAVES = [            # (amplitude, wavelength, direction in degrees, phase)
    (0.018, 0.85, 20.0, 0.3),
    (0.015, 0.72, 80.0, 1.7),
    (0.012, 0.62, 145.0, 4.1),
    (0.010, 0.55, 210.0, 2.6),
]


def height(x, y):
    h = 0.0
    for a, length, deg, phase in WAVES:
        k = 2 * math.pi / length
        dx, dy = math.cos(math.radians(deg)), math.sin(math.radians(deg))
        h += a * math.sin(k * (x * dx + y * dy) + phase)
    return h


def box(x0, y0, z0, x1, y1, z1, material):
    """An axis-aligned box from its corners (the .ray box is the unit cube about the origin)."""
    cx, cy, cz = (x0 + x1) / 2, (y0 + y1) / 2, (z0 + z1) / 2
    return (f"translate({cx:.4f}, {cy:.4f}, {cz:.4f}, scale({x1 - x0:.4f}, {y1 - y0:.4f}, {z1 - z0:.4f}, "
            f"box {{ material = {material}; }}))")


def main():
    murky = "--murky" in sys.argv[1:]
    args = [a for a in sys.argv[1:] if a != "--murky"]
    light_tile = "{ diffuse = (0.75, 0.85, 0.9); ambient = (0.75, 0.85, 0.9); }"
    dark_tile = "{ diffuse = (0.3, 0.55, 0.72); ambient = (0.3, 0.55, 0.72); }"
    grout = "{ diffuse = (0.55, 0.6, 0.62); ambient = (0.55, 0.6, 0.62); }"
    wall = "{ diffuse = (0.8, 0.88, 0.9); ambient = (0.8, 0.88, 0.9); }"
    deck = "{ diffuse = (0.72, 0.66, 0.58); ambient = (0.72, 0.66, 0.58); }"
    lines = [
        "SBT-raytracer 1.0",
        "// A swimming pool under the sun and a blue sky: the wavy water surface (a mesh with",
        "// smooth normals) focuses sunlight into a caustic net on the tiled floor.",
        "// Written by scripts/scenes/pool.py; edit that instead.",
        "",
        "camera {",
        "\tposition = (0, -3.7, -1.3);" if murky else "\tposition = (0, -9.5, 6.5);",
        "\tviewdir = (0, 1, 0.12);" if murky else "\tviewdir = (0, 0.8, -0.62);",
        "\tupdir = (0, 0, 1);",
        "\tfov = 75;" if murky else "\tfov = 50;",
        "}",
        "",
        "sun_light { direction = (0.25, 0.35, -1); color = (1.0, 0.97, 0.9); angle = 0.53; }",
        "environment_light { color = (0.12, 0.17, 0.26); }",
        "ambient_light { color = (0.1, 0.12, 0.14); }",
        "",
        "// the floor: tiles over grout",
        box(-HALF, -HALF, -DEPTH - 0.2, HALF, HALF, -DEPTH - 0.05, grout),
    ]
    tiles = 8
    size = 2 * HALF / tiles
    for j in range(tiles):
        for i in range(tiles):
            x0, y0 = -HALF + i * size, -HALF + j * size
            material = light_tile if (i + j) % 2 == 0 else dark_tile
            lines.append(box(x0 + 0.015, y0 + 0.015, -DEPTH - 0.1, x0 + size - 0.015, y0 + size - 0.015,
                             -DEPTH, material))
    lines.append("// the walls, up to the deck")
    top = 0.25
    lines += [
        box(-HALF - 0.3, -HALF - 0.3, -DEPTH - 0.2, -HALF, HALF + 0.3, top, wall),
        box(HALF, -HALF - 0.3, -DEPTH - 0.2, HALF + 0.3, HALF + 0.3, top, wall),
        box(-HALF, HALF, -DEPTH - 0.2, HALF, HALF + 0.3, top, wall),
        box(-HALF, -HALF - 0.3, -DEPTH - 0.2, HALF, -HALF, top, wall),
    ]
    lines.append("// the deck around the pool")
    lines += [
        box(-12, -12, top - 0.2, 12, -HALF - 0.3, top, deck),
        box(-12, HALF + 0.3, top - 0.2, 12, 12, top, deck),
        box(-12, -HALF - 0.3, top - 0.2, -HALF - 0.3, HALF + 0.3, top, deck),
        box(HALF + 0.3, -HALF - 0.3, top - 0.2, 12, HALF + 0.3, top, deck),
    ]
    n = GRID
    points = []
    for j in range(n):
        for i in range(n):
            x = -HALF + 2 * HALF * i / (n - 1)
            y = -HALF + 2 * HALF * j / (n - 1)
            points.append(f"({x:.3f},{y:.3f},{height(x, y):.4f})")
    faces = []
    for j in range(n - 1):
        for i in range(n - 1):
            a = j * n + i
            faces.append(f"({a},{a + 1},{a + n + 1})")
            faces.append(f"({a},{a + n + 1},{a + n})")
    # Murky water: it scatters a little, mostly forward, and absorbs red most.
    medium = " scattering = (0.05, 0.06, 0.06); absorption = (0.12, 0.04, 0.03); phase = 0.7;" if murky else ""
    lines += [
        "// the water: index 1.33, slightly blue" + (", murky: it scatters sunlight into shafts" if murky else ""),
        "polymesh {",
        "\tmaterial = { transmissive = (0.88, 0.95, 0.98); index = 1.33; specular = (0.3, 0.3, 0.3); shininess = 128;"
        + medium + " };",
        "\tgennormals;",
        "\tpoints = (" + ",".join(points) + ");",
        "\tfaces = (" + ",".join(faces) + ");",
        "}",
    ]
    name = "pool_murky.ray" if murky else "pool.ray"
    out = Path(args[0]) if args else Path(__file__).resolve().parents[2] / "scenes" / name
    out.write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
