#!/usr/bin/env python3
"""Writes the profile-guided build's training scenes beside the project's own (standard library
only):

- `lamp_glass.pbrt`: a glass ball and a metal ball over a floor under a small sphere lamp;
- `lamp_mesh.pbrt`: a rippled ball of about 500,000 triangles (a binary PLY) there, beyond the
  caches;
- `lamp_glass_mesh.pbrt`: a rippled glass ball of 20,000 triangles there, within them;
- `lamp_plates.pbrt`: four metal plates from mirror-smooth to rough under four lamps of four
  sizes;
- `textured.gltf`: a floor with a colour map, a rough metal ball and a plastic ball, a point
  light and a camera;
- `textured.obj`: many_textures.py's rippled sheet with its MTL and colour maps.

    python3 scripts/pgo/training_scenes.py OUT_DIR
"""
import base64
import json
import math
import struct
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / 'scenes'))
import many_textures  # noqa: E402  (its PNG writer)

LAMP = 'AttributeBegin\n  AreaLightSource "diffuse" "rgb L" [60 60 60]\n  Translate 0.6 2.2 0.4\n' \
       '  Shape "sphere" "float radius" [0.1]\nAttributeEnd\n'
FLOOR = 'Material "diffuse" "rgb reflectance" [0.5 0.5 0.5]\n' \
        'Shape "trianglemesh" "point3 P" [-5 0 -5  5 0 -5  5 0 5  -5 0 5] "integer indices" [0 2 1  0 3 2]\n'
CAMERA = 'LookAt 0 1.2 3.4  0 0.45 0  0 1 0\nCamera "perspective" "float fov" [40]\nWorldBegin\n'


def ball(rings, segments, centre, radius, ripple):
    """Vertices and triangles of a UV sphere whose radius ripples by `ripple`."""
    verts = []
    for i in range(rings + 1):
        t = math.pi * i / rings
        for j in range(segments):
            p = 2 * math.pi * j / segments
            r = radius * (1 + ripple * math.sin(12 * t) * math.sin(12 * p))
            verts.append((centre[0] + r * math.sin(t) * math.cos(p), centre[1] + r * math.cos(t),
                          centre[2] + r * math.sin(t) * math.sin(p)))
    tris = []
    for i in range(rings):
        for j in range(segments):
            a, b = i * segments + j, i * segments + (j + 1) % segments
            c, d = a + segments, b + segments
            tris += [(a, b, d), (a, d, c)]
    return verts, tris


def ply(path, verts, tris):
    header = (f'ply\nformat binary_little_endian 1.0\nelement vertex {len(verts)}\n'
              'property float x\nproperty float y\nproperty float z\n'
              f'element face {len(tris)}\nproperty list uchar int vertex_indices\nend_header\n')
    body = b''.join(struct.pack('<3f', *v) for v in verts) + b''.join(struct.pack('<B3i', 3, *t) for t in tris)
    path.write_bytes(header.encode() + body)


def gltf(path):
    """A floor with an embedded colour map, two balls of glTF's metal-roughness materials."""
    floor_p = [(-4, 0, -4), (4, 0, -4), (4, 0, 4), (-4, 0, 4)]
    floor_uv = [(0, 0), (4, 0), (4, 4), (0, 4)]
    sv, st = ball(48, 96, (0, 0, 0), 0.5, 0.0)
    blob = b''.join(struct.pack('<3f', *p) for p in floor_p) + b''.join(struct.pack('<2f', *t) for t in floor_uv)
    blob += struct.pack('<6H', 0, 2, 1, 0, 3, 2)
    off_sv = len(blob)
    blob += b''.join(struct.pack('<3f', *p) for p in sv)
    off_st = len(blob)
    blob += b''.join(struct.pack('<3I', *t) for t in st)
    lo = [min(p[k] for p in sv) for k in range(3)]
    hi = [max(p[k] for p in sv) for k in range(3)]
    many_textures.png(path.with_suffix('.png'), 64, [(200, 60, 40), (230, 220, 200)], 8)
    image = base64.b64encode(path.with_suffix('.png').read_bytes()).decode()
    doc = {
        'asset': {'version': '2.0'},
        'scene': 0,
        'scenes': [{'nodes': [0, 1, 2, 3, 4]}],
        'nodes': [
            {'mesh': 0},
            {'mesh': 1, 'translation': [-0.6, 0.5, 0]},
            {'mesh': 2, 'translation': [0.6, 0.5, 0]},
            {'camera': 0, 'translation': [0, 1.2, 3.4], 'rotation': [-0.11, 0, 0, 0.994]},
            {'extensions': {'KHR_lights_punctual': {'light': 0}}, 'translation': [1, 3, 1]},
        ],
        'cameras': [{'type': 'perspective', 'perspective': {'yfov': 0.7, 'znear': 0.01}}],
        'extensionsUsed': ['KHR_lights_punctual'],
        'extensions': {'KHR_lights_punctual': {'lights': [{'type': 'point', 'intensity': 300}]}},
        'meshes': [
            {'primitives': [{'attributes': {'POSITION': 0, 'TEXCOORD_0': 1}, 'indices': 2, 'material': 0}]},
            {'primitives': [{'attributes': {'POSITION': 3}, 'indices': 4, 'material': 1}]},
            {'primitives': [{'attributes': {'POSITION': 3}, 'indices': 4, 'material': 2}]},
        ],
        'materials': [
            {'pbrMetallicRoughness': {'baseColorTexture': {'index': 0}, 'metallicFactor': 0, 'roughnessFactor': 0.9}},
            {'pbrMetallicRoughness': {'baseColorFactor': [0.9, 0.7, 0.4, 1], 'metallicFactor': 1, 'roughnessFactor': 0.3}},
            {'pbrMetallicRoughness': {'baseColorFactor': [0.2, 0.4, 0.8, 1], 'metallicFactor': 0, 'roughnessFactor': 0.2}},
        ],
        'textures': [{'source': 0}],
        'images': [{'uri': 'data:image/png;base64,' + image}],
        'buffers': [{'byteLength': len(blob), 'uri': 'data:application/octet-stream;base64,' + base64.b64encode(blob).decode()}],
        'bufferViews': [
            {'buffer': 0, 'byteOffset': 0, 'byteLength': 48},
            {'buffer': 0, 'byteOffset': 48, 'byteLength': 32},
            {'buffer': 0, 'byteOffset': 80, 'byteLength': 12},
            {'buffer': 0, 'byteOffset': off_sv, 'byteLength': off_st - off_sv},
            {'buffer': 0, 'byteOffset': off_st, 'byteLength': len(blob) - off_st},
        ],
        'accessors': [
            {'bufferView': 0, 'componentType': 5126, 'count': 4, 'type': 'VEC3', 'min': [-4, 0, -4], 'max': [4, 0, 4]},
            {'bufferView': 1, 'componentType': 5126, 'count': 4, 'type': 'VEC2'},
            {'bufferView': 2, 'componentType': 5123, 'count': 6, 'type': 'SCALAR'},
            {'bufferView': 3, 'componentType': 5126, 'count': len(sv), 'type': 'VEC3', 'min': lo, 'max': hi},
            {'bufferView': 4, 'componentType': 5125, 'count': 3 * len(st), 'type': 'SCALAR'},
        ],
    }
    path.write_text(json.dumps(doc))


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    out = Path(sys.argv[1])
    out.mkdir(parents=True, exist_ok=True)
    (out / 'lamp_glass.pbrt').write_text(
        CAMERA + LAMP + FLOOR
        + 'AttributeBegin\n  Material "dielectric" "float eta" [1.5]\n  Translate 0 0.5 0\n'
          '  Shape "sphere" "float radius" [0.5]\nAttributeEnd\n'
        + 'AttributeBegin\n  Material "conductor" "float roughness" [0.1]\n  Translate -1.2 0.3 0.4\n'
          '  Shape "sphere" "float radius" [0.3]\nAttributeEnd\n')
    verts, tris = ball(500, 500, (0, 0.55, 0), 0.5, 0.04)
    ply(out / 'rippled_ball.ply', verts, tris)
    (out / 'lamp_mesh.pbrt').write_text(
        CAMERA + LAMP + FLOOR + 'Material "diffuse" "rgb reflectance" [0.6 0.6 0.6]\n'
                                'Shape "plymesh" "string filename" "rippled_ball.ply"\n')
    verts, tris = ball(100, 100, (0, 0.55, 0), 0.5, 0.04)
    ply(out / 'rippled_glass.ply', verts, tris)
    (out / 'lamp_glass_mesh.pbrt').write_text(
        CAMERA + LAMP + FLOOR + 'Material "dielectric" "float eta" [1.33]\n'
                                'Shape "plymesh" "string filename" "rippled_glass.ply"\n')
    plates = ''
    for k, roughness in enumerate((0.002, 0.02, 0.1, 0.3)):
        z = -0.9 + 0.6 * k
        plates += (f'AttributeBegin\n  Material "conductor" "float roughness" [{roughness}]\n'
                   f'  Translate 0 {0.2 + 0.15 * k} {z}\n  Rotate {-60 + 12 * k} 1 0 0\n'
                   '  Shape "trianglemesh" "point3 P" [-1 0 -0.25  1 0 -0.25  1 0 0.25  -1 0 0.25] '
                   '"integer indices" [0 2 1  0 3 2]\nAttributeEnd\n')
    for k, radius in enumerate((0.01, 0.04, 0.12, 0.3)):
        plates += (f'AttributeBegin\n  AreaLightSource "diffuse" "rgb L" [{0.8 / radius ** 2:.1f} {0.6 / radius ** 2:.1f} {0.5 / radius ** 2:.1f}]\n'
                   f'  Translate {-1.2 + 0.8 * k} 1.8 -1.5\n  Shape "sphere" "float radius" [{radius}]\nAttributeEnd\n')
    (out / 'lamp_plates.pbrt').write_text(CAMERA + FLOOR + plates)
    gltf(out / 'textured.gltf')
    subprocess.run([sys.executable, str(HERE.parent / 'scenes' / 'many_textures.py'), str(out), '200000', '6', '256'],
                   check=True, stdout=subprocess.DEVNULL)
    (out / 'many_textures.obj').rename(out / 'textured.obj')


if __name__ == '__main__':
    main()
