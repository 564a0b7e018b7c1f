#!/usr/bin/env python3
"""Scenes for the light side's waves (BENCHMARKS.md, "Light paths and vcm on large meshes"),
written to target/race/scenes beside the throughput benchmark's bumpy ball (made if missing):

- `inside`: the camera and the sphere light inside the bumpy ball scaled four times, so every
  ray, the light's included, meets the million triangles;
- `mesh_glass`: the throughput benchmark's `mesh` with a glass ball beside the bumpy one, whose
  caustic gives vcm focus pixels.

    scripts/race/light_side_scenes.py
"""
import os

import throughput_scenes as ts

LIGHT_INSIDE = (0.3, 0.5, -0.2)


def write_inside():
    path = os.path.join(ts.FOLDER, 'inside.pbrt')
    ts.caustica_scene('mesh')   # writes the PLY
    _, lr, le = ts.LIGHT
    (cx, cy, cz), _, rho, _ = ts.BUMPY
    text = ('# scripts/race/light_side_scenes.py: inside\n'
            'LookAt 0 0 0  0 0 -1  0 1 0\n'
            'Camera "perspective" "float fov" [60]\n'
            f'Film "rgb" "integer xresolution" [{ts.common.SIZE}] "integer yresolution" [{ts.common.SIZE}]\n'
            'WorldBegin\n'
            f'AttributeBegin\n  AreaLightSource "diffuse" "rgb L" [{le} {le} {le}]\n'
            f'  Translate {" ".join(map(str, LIGHT_INSIDE))}\n  Shape "sphere" "float radius" [{lr}]\nAttributeEnd\n'
            f'Material "diffuse" "rgb reflectance" [{rho} {rho} {rho}]\n'
            f'AttributeBegin\n  Scale 4 4 4\n  Translate {-cx} {-cy} {-cz}\n'
            '  Shape "plymesh" "string filename" "bumpy_ball.ply"\nAttributeEnd\n')
    with open(path, 'w') as f:
        f.write(text)
    return path


def write_mesh_glass():
    path = os.path.join(ts.FOLDER, 'mesh_glass.pbrt')
    with open(ts.caustica_scene('mesh')) as f:
        text = f.read().replace(': mesh\n', ': mesh_glass\n', 1)
    _, _, eta = ts.GLASS
    text += (f'AttributeBegin\n  Material "dielectric" "float eta" [{eta}]\n  Translate 0.9 0.35 0.5\n'
             '  Shape "sphere" "float radius" [0.35]\nAttributeEnd\n')
    with open(path, 'w') as f:
        f.write(text)
    return path


if __name__ == '__main__':
    for p in (write_inside(), write_mesh_glass()):
        print(p)
