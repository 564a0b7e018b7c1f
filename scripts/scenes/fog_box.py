#!/usr/bin/env python3
"""Writes scenes/fog_box.pbrt: a Cornell box filled with thin fog, a glass ball hanging in it and
a spot light above shining down through the ball, which focuses its light into a bright beam in
the fog and a caustic on the floor. vcm and light tracing (`lt`) render the beam; a path tracer
cannot reach a spot light through glass. `--area` puts a small square lamp in place of the spot (the
scene an independent volumetric path tracer can render too).

    scripts/scenes/fog_box.py [--area] [OUT]
"""
import sys
from pathlib import Path

EYE, TARGET, FOV = (0.0, 1.0, 3.9), (0.0, 1.0, 0.0), 40.0
WIDTH, HEIGHT = 320, 320
LIGHT, INTENSITY, CONE = (0.0, 1.95, 0.0), 8.0, 20.0      # W/sr, degrees
LAMP_HALF, LAMP_RADIANCE = 0.1, 60.0
BALL, RADIUS, ETA = (0.0, 1.25, 0.0), 0.3, 1.5
SIGMA_A, SIGMA_S, G = 0.02, 0.15, 0.2                       # per unit of length


def quad(points):
    flat = " ".join(f"{c:g}" for p in points for c in p)
    return f'Shape "bilinearmesh" "point3 P" [{flat}]'


def scene(area):
    light = (
        f"""AttributeBegin
  AreaLightSource "diffuse" "rgb L" [{LAMP_RADIANCE} {LAMP_RADIANCE} {LAMP_RADIANCE}]
  {quad([(-LAMP_HALF, 1.99, -LAMP_HALF), (LAMP_HALF, 1.99, -LAMP_HALF), (-LAMP_HALF, 1.99, LAMP_HALF), (LAMP_HALF, 1.99, LAMP_HALF)])}
AttributeEnd"""
        if area
        else f"""LightSource "spot" "rgb I" [{INTENSITY} {INTENSITY} {INTENSITY}] "point3 from" [{LIGHT[0]} {LIGHT[1]} {LIGHT[2]}]
    "point3 to" [{LIGHT[0]} 0 {LIGHT[2]}] "float coneangle" [{CONE}] "float conedeltaangle" [3]"""
    )
    return f"""# pbrt-v4, written by scripts/scenes/fog_box.py: a Cornell box of thin fog, a glass ball and
# {'a small square lamp' if area else 'a spot light'} above it; the ball focuses the light into a beam in the fog.
#   caustica render scenes/fog_box{'_area' if area else ''}.pbrt   (bdpt: caustica renders it with vcm)
LookAt {' '.join(map(str, EYE))}   {' '.join(map(str, TARGET))}   0 1 0
MakeNamedMedium "fog" "string type" "homogeneous"
    "rgb sigma_a" [{SIGMA_A} {SIGMA_A} {SIGMA_A}] "rgb sigma_s" [{SIGMA_S} {SIGMA_S} {SIGMA_S}] "float g" [{G}]
MediumInterface "" "fog"
Camera "perspective" "float fov" [{FOV}]
Film "rgb" "integer xresolution" [{WIDTH}] "integer yresolution" [{HEIGHT}]
    "string filename" "fog_box{'_area' if area else ''}.png"
Integrator "bdpt" "integer maxdepth" [20]
WorldBegin
{light}
# The box: white floor, ceiling and back, red left and green right walls, open at the front.
# The fog is the camera's medium, so it fills the scene (as far as the sphere around it); every
# shape has it outside, and the glass ball clear air inside.
Material "diffuse" "rgb reflectance" [0.7 0.7 0.7]
{quad([(-1, 0, -1), (1, 0, -1), (-1, 0, 1), (1, 0, 1)])}
{quad([(-1, 2, -1), (1, 2, -1), (-1, 2, 1), (1, 2, 1)])}
{quad([(-1, 0, -1), (1, 0, -1), (-1, 2, -1), (1, 2, -1)])}
Material "diffuse" "rgb reflectance" [0.6 0.1 0.1]
{quad([(-1, 0, -1), (-1, 0, 1), (-1, 2, -1), (-1, 2, 1)])}
Material "diffuse" "rgb reflectance" [0.1 0.5 0.1]
{quad([(1, 0, -1), (1, 0, 1), (1, 2, -1), (1, 2, 1)])}
AttributeBegin
  Material "dielectric" "float eta" [{ETA}]
  Translate {BALL[0]} {BALL[1]} {BALL[2]}
  Shape "sphere" "float radius" [{RADIUS}]
AttributeEnd
"""


if __name__ == "__main__":
    args = [a for a in sys.argv[1:] if a != "--area"]
    area = "--area" in sys.argv[1:]
    root = Path(__file__).resolve().parents[2]
    out = Path(args[0]) if args else root / "scenes" / ("fog_box_area.pbrt" if area else "fog_box.pbrt")
    out.write_text(scene(area))
    print(f"wrote {out}")
