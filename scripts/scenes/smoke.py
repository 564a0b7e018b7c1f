#!/usr/bin/env python3
"""Writes scenes/smoke.pbrt: a small lamp behind a round bottle of water on a table, in drifting
smoke. The smoke is a pbrt-v4 `uniformgrid` density (puffs of smoke summed on a 32×20×32 grid),
the bottle a glass ball of index 1.33; the ball focuses the lamp into a beam that lights the
smoke in front of it and a caustic on the table.

With --puff it writes instead one small, dense puff in an otherwise empty box (no haze): the
sparse grid the benchmarks use for the majorant grid (BENCHMARKS.md, "Density grids").

    scripts/scenes/smoke.py [--puff] [OUT]
"""
import math
import sys
from pathlib import Path

NX, NY, NZ = 32, 20, 32
BOX = ((-2.0, 0.0, -2.0), (2.0, 2.4, 2.0))       # the grid's box, world units
# Puffs of smoke: centre, radius, density.
PUFFS = [
    ((-0.8, 0.9, -0.4), 0.9, 0.9),
    ((0.5, 1.2, 0.3), 1.0, 0.8),
    ((1.2, 0.6, -0.8), 0.7, 0.7),
    ((-0.2, 1.7, 0.9), 0.8, 0.6),
    ((0.9, 1.5, -1.2), 0.6, 0.5),
]


# The sparse variant: one dense puff, nothing around it.
PUFF = [((-0.3, 0.9, 0.0), 0.35, 12.0)]


def density(x, y, z, puffs=None):
    d = 0.15 if puffs is None else 0.0  # a thin haze everywhere in the box
    for (cx, cy, cz), r, a in PUFFS if puffs is None else puffs:
        q = ((x - cx) ** 2 + (y - cy) ** 2 + (z - cz) ** 2) / (r * r)
        d += a * math.exp(-2.0 * q)
    # Thinner towards the top, as smoke rising and spreading.
    return d * (1.0 - 0.3 * y / BOX[1][1])


def grid(puffs=None):
    (x0, y0, z0), (x1, y1, z1) = BOX
    values = []
    for k in range(NZ):
        for j in range(NY):
            for i in range(NX):
                x = x0 + (x1 - x0) * (i + 0.5) / NX
                y = y0 + (y1 - y0) * (j + 0.5) / NY
                z = z0 + (z1 - z0) * (k + 0.5) / NZ
                values.append(f"{density(x, y, z, puffs):.4f}")
    return values


def scene(puffs=None):
    values = grid(puffs)
    rows = "\n        ".join(" ".join(values[i:i + 20]) for i in range(0, len(values), 20))
    (x0, y0, z0), (x1, y1, z1) = BOX
    return f"""# pbrt-v4, written by scripts/scenes/smoke.py: a lamp behind a round bottle of water on a
# table, in smoke (a uniformgrid density). The bottle focuses the lamp into a beam in the smoke.
#   caustica render scenes/smoke.pbrt
# (The medium comes before LookAt: a grid lies in the space of the transform where it is made.)
MakeNamedMedium "smoke" "string type" "uniformgrid"
    "rgb sigma_a" [0.05 0.05 0.05] "rgb sigma_s" [0.5 0.5 0.5] "float g" [0.5]
    "integer nx" [{NX}] "integer ny" [{NY}] "integer nz" [{NZ}]
    "point3 p0" [{x0} {y0} {z0}] "point3 p1" [{x1} {y1} {z1}]
    "float density" [
        {rows}
    ]
LookAt 0 1.3 4.6   0 0.7 0   0 1 0
MediumInterface "" "smoke"
Camera "perspective" "float fov" [38]
Film "rgb" "integer xresolution" [400] "integer yresolution" [300] "string filename" "smoke.png"
Integrator "bdpt" "integer maxdepth" [20]
WorldBegin
# The lamp, behind the bottle and a little higher.
LightSource "point" "rgb I" [6 6 5] "point3 from" [0 0.9 -1.6]
# The table, and a wall far behind.
Material "diffuse" "rgb reflectance" [0.55 0.5 0.45]
Shape "bilinearmesh" "point3 P" [-6 0 -6  6 0 -6  -6 0 6  6 0 6]
Material "diffuse" "rgb reflectance" [0.4 0.4 0.42]
Shape "bilinearmesh" "point3 P" [-6 0 -3  6 0 -3  -6 4 -3  6 4 -3]
# The bottle: water in a round glass, read as one glass ball of water's index.
AttributeBegin
  Material "dielectric" "float eta" [1.33]
  Translate 0 0.45 0
  Shape "sphere" "float radius" [0.45]
AttributeEnd
"""


if __name__ == "__main__":
    args = sys.argv[1:]
    puffs = PUFF if "--puff" in args else None
    args = [a for a in args if a != "--puff"]
    name = "smoke_puff.pbrt" if puffs else "smoke.pbrt"
    out = Path(args[0]) if args else Path(__file__).resolve().parents[2] / "scenes" / name
    out.write_text(scene(puffs))
    print(f"wrote {out}")
