#!/usr/bin/env python3
"""Writes scenes/prism.ray: Newton's experiment. Sunlight enters a dark room through a slit,
passes a 60° prism of dense flint glass at minimum deviation and spreads into a spectrum on
the far wall.

The glass is SF11 (n_d = 1.78472, V_d = 25.68, Schott's catalogue). At minimum deviation the
ray inside the prism runs parallel to its base, so with the apex down a beam falling at
D/2 below the horizontal leaves rising at D/2, D = 2 asin(n sin(A/2)) − A; the script places
the slit and the prism from that.
"""
import math
import sys
from pathlib import Path

N_D, ABBE = 1.78472, 25.68
APEX = math.radians(60.0)
SIDE = 1.6                  # prism edge in the cross-section
LENGTH = 2.4                # prism length along z
ROOM = (-6.0, 6.0, 0.0, 5.5, -6.0, 6.0)   # x0, x1, y0, y1, z0, z1
WALL = 0.3
SHUTTER = 0.02              # the window wall is thin: a beam at 33° crosses a thick one's slit
SLIT = (0.16, 1.4)          # height, width


def box(x0, y0, z0, x1, y1, z1, material):
    cx, cy, cz = (x0 + x1) / 2, (y0 + y1) / 2, (z0 + z1) / 2
    return (f"translate({cx:.4f}, {cy:.4f}, {cz:.4f}, scale({x1 - x0:.4f}, {y1 - y0:.4f}, {z1 - z0:.4f}, "
            f"box {{ material = {material}; }}))")


def main():
    x0, x1, y0, y1, z0, z1 = ROOM
    deviation = 2 * math.asin(N_D * math.sin(APEX / 2)) - APEX
    slope = math.tan(deviation / 2)
    # The prism, apex down: base (top edge) at height base_y, centred on x = 0.
    base_y = 1.5
    height = SIDE * math.sin(APEX)
    apex = (0.0, base_y - height)
    left, right = (-SIDE / 2, base_y), (SIDE / 2, base_y)
    # The beam crosses the prism half-way down, parallel to the base.
    mid_y = base_y - height / 2
    entry_x, exit_x = -SIDE / 4, SIDE / 4
    slit_y = mid_y + slope * (entry_x - x0)
    spectrum_y = mid_y + slope * (x1 - exit_x)
    assert slit_y + SLIT[0] < y1 and spectrum_y < y1, (slit_y, spectrum_y)
    sun = (math.cos(deviation / 2), -math.sin(deviation / 2), 0.0)

    wall = "{ diffuse = (0.7, 0.7, 0.68); ambient = (0.7, 0.7, 0.68); }"
    floor = "{ diffuse = (0.45, 0.4, 0.36); ambient = (0.45, 0.4, 0.36); }"
    screen = "{ diffuse = (0.9, 0.9, 0.9); ambient = (0.9, 0.9, 0.9); }"
    glass = (f"{{ transmissive = (1, 1, 1); specular = (0.1, 0.1, 0.1); shininess = 200; "
             f"index = {N_D}; abbe = {ABBE}; }}")
    sy0, sy1 = slit_y - SLIT[0] / 2, slit_y + SLIT[0] / 2
    sz0, sz1 = -SLIT[1] / 2, SLIT[1] / 2
    lines = [
        "SBT-raytracer 1.0",
        "// Newton's experiment: sunlight enters a dark room through a slit, passes a 60° prism",
        f"// of SF11 flint glass (n_d = {N_D}, V = {ABBE}) at minimum deviation and spreads into a",
        "// spectrum on the far wall. Written by scripts/scenes/prism.py; edit that instead.",
        "",
        "camera {",
        "\tposition = (-1.2, 2.0, 4.6);",
        "\tviewdir = (0.72, 0.1, -0.69);",
        "\tupdir = (0, 1, 0);",
        "\tfov = 58;",
        "}",
        "",
        f"sun_light {{ direction = ({sun[0]:.5f}, {sun[1]:.5f}, 0); color = (4, 4, 4); angle = 0.53; }}",
        "ambient_light { color = (0.04, 0.04, 0.04); }",
        "",
        "// the room: floor, ceiling, back, front and far walls",
        box(x0 - WALL, y0 - WALL, z0 - WALL, x1 + WALL, y0, z1 + WALL, floor),
        box(x0 - WALL, y1, z0 - WALL, x1 + WALL, y1 + WALL, z1 + WALL, wall),
        box(x0 - WALL, y0, z0 - WALL, x1 + WALL, y1, z0, wall),
        box(x0 - WALL, y0, z1, x1 + WALL, y1, z1 + WALL, wall),
        box(x1, y0, z0, x1 + WALL, y1, z1, screen),
        "// the window wall with its slit",
        box(x0 - SHUTTER, y0, z0, x0, sy0, z1, wall),
        box(x0 - SHUTTER, sy1, z0, x0, y1, z1, wall),
        box(x0 - SHUTTER, sy0, z0, x0, sy1, sz0, wall),
        box(x0 - SHUTTER, sy0, sz1, x0, sy1, z1, wall),
        "// the prism, apex down, its edges along z",
    ]
    za, zb = -LENGTH / 2, LENGTH / 2
    corners = [(*apex, za), (*right, za), (*left, za), (*apex, zb), (*right, zb), (*left, zb)]
    points = ",".join(f"({x:.5f},{y:.5f},{z:.5f})" for x, y, z in corners)
    # Counter-clockwise seen from outside: the ends, then the three sides.
    faces = "(0,2,1),(3,4,5),(0,1,4,3),(1,2,5,4),(2,0,3,5)"
    lines += [
        "polymesh {",
        f"\tmaterial = {glass};",
        f"\tpoints = ({points});",
        f"\tfaces = ({faces});",
        "}",
        "// a thin stand under the prism's apex",
        box(-0.03, y0, -0.8, 0.03, apex[1], 0.8, "{ diffuse = (0.05, 0.05, 0.05); }"),
    ]
    out = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).resolve().parents[2] / "scenes" / "prism.ray"
    out.write_text("\n".join(lines) + "\n")
    print(f"deviation {math.degrees(deviation):.2f}°, slit at y = {slit_y:.3f}, spectrum at y = {spectrum_y:.3f}")


if __name__ == "__main__":
    main()
