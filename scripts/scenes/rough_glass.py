#!/usr/bin/env python3
"""Writes scenes/rough_glass.pbrt: a ball of frosted glass (GGX α 0.3, η 1.5) floating over a
grey floor, lit by a point light behind and above it, so its soft caustic falls on the floor in
front, where the camera sees it beside the ball's shadow. The scene is mirror-symmetric in x
(a handedness mistake cannot move anything) and has one light and two materials, so
scripts/race/rough_glass.py can build the same scene for Mitsuba 3 (`roughdielectric`).

    scripts/scenes/rough_glass.py [ALPHA] [OUT]
"""
import sys
from pathlib import Path

# Shared with scripts/race/rough_glass.py, which imports them.
EYE, TARGET, FOV = (0.0, 4.0, 7.0), (0.0, 0.5, 1.0), 40.0
WIDTH, HEIGHT = 320, 240
LIGHT, INTENSITY = (0.0, 5.0, -2.0), 30.0       # W/sr
CENTRE, RADIUS, ETA = (0.0, 1.5, 0.0), 1.0, 1.5
FLOOR_ALBEDO, FLOOR_HALF = 0.5, 8.0


def scene(alpha):
    h = FLOOR_HALF
    return f"""# pbrt-v4, written by scripts/scenes/rough_glass.py: a ball of frosted glass (GGX alpha {alpha},
# eta {ETA}) over a grey floor under a point light; its soft caustic lies in front of it.
#   caustica render scenes/rough_glass.pbrt --integrator vcm
LookAt {' '.join(map(str, EYE))}   {' '.join(map(str, TARGET))}   0 1 0
Camera "perspective" "float fov" [{FOV}]
Film "rgb" "integer xresolution" [{WIDTH}] "integer yresolution" [{HEIGHT}]
    "string filename" "rough_glass.png"
Integrator "volpath" "integer maxdepth" [10]

WorldBegin

LightSource "point" "point3 from" [{' '.join(map(str, LIGHT))}] "rgb I" [{INTENSITY} {INTENSITY} {INTENSITY}]

AttributeBegin
  Material "diffuse" "rgb reflectance" [{FLOOR_ALBEDO} {FLOOR_ALBEDO} {FLOOR_ALBEDO}]
  Shape "bilinearmesh" "point3 P" [-{h} 0 -{h}  {h} 0 -{h}  -{h} 0 {h}  {h} 0 {h}]
AttributeEnd

AttributeBegin
  Material "dielectric" "float eta" [{ETA}] "float roughness" [{alpha}] "bool remaproughness" false
  Translate {' '.join(map(str, CENTRE))}
  Shape "sphere" "float radius" [{RADIUS}]
AttributeEnd
"""


def main():
    alpha = float(sys.argv[1]) if len(sys.argv) > 1 else 0.3
    root = Path(__file__).resolve().parents[2]
    out = Path(sys.argv[2]) if len(sys.argv) > 2 else root / "scenes" / "rough_glass.pbrt"
    out.write_text(scene(alpha))
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
