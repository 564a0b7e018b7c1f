"""The throughput benchmark's own scenes, each written for both renderers from one description:

- `glass`: a glass ball (index 1.5) over a grey floor under a small sphere light;
- `mesh`: the same floor and light over a bumpy diffuse ball of 1,006,780 triangles (a PLY
  file both read; flat-shaded in both).

caustica reads a pbrt-v4 file, Mitsuba a dict built here. The files go to target/race/scenes.
"""
import os

import common

SCENES = ('glass', 'mesh')
FOLDER = os.path.join(common.REPO, 'target', 'race', 'scenes')

EYE, TARGET, FOV = (0.0, 1.2, 3.4), (0.0, 0.45, 0.0), 40
LIGHT = ((0.6, 2.2, 0.4), 0.1, 60.0)        # centre, radius, radiance
FLOOR = (5.0, 0.5)                         # half side, reflectance
GLASS = ((0.0, 0.5, 0.0), 0.5, 1.5)        # centre, radius, index
BUMPY = ((0.0, 0.55, 0.0), 0.5, 0.6, 710)  # centre, radius, reflectance, rings


def bumpy_ball_ply(path):
    """A UV sphere of BUMPY's rings (and as many segments), its radius rippled by 4%, as a binary
    PLY (positions only)."""
    import numpy as np
    (cx, cy, cz), r, _, n = BUMPY
    theta = np.linspace(0, np.pi, n + 1)[1:-1]              # rings between the poles
    phi = np.linspace(0, 2 * np.pi, n, endpoint=False)
    t, p = np.meshgrid(theta, phi, indexing='ij')
    rr = r * (1 + 0.04 * np.sin(12 * t) * np.sin(12 * p))
    ring = np.stack([rr * np.sin(t) * np.cos(p), rr * np.cos(t), rr * np.sin(t) * np.sin(p)], -1).reshape(-1, 3)
    verts = np.concatenate([[[0, r, 0]], ring, [[0, -r, 0]]]) + [cx, cy, cz]
    rings = n - 1
    idx = lambda i, j: 1 + i * n + (j % n)
    faces = []
    j = np.arange(n)
    faces.append(np.stack([np.zeros(n, int), idx(0, j + 1), idx(0, j)], -1))       # the north cap
    for i in range(rings - 1):
        a, b, c, d = idx(i, j), idx(i, j + 1), idx(i + 1, j), idx(i + 1, j + 1)
        faces.append(np.stack([a, b, d], -1))
        faces.append(np.stack([a, d, c], -1))
    south = 1 + rings * n
    faces.append(np.stack([np.full(n, south), idx(rings - 1, j), idx(rings - 1, j + 1)], -1))
    faces = np.concatenate(faces).astype('<i4')
    header = (f'ply\nformat binary_little_endian 1.0\nelement vertex {len(verts)}\n'
              'property float x\nproperty float y\nproperty float z\n'
              f'element face {len(faces)}\nproperty list uchar int vertex_indices\nend_header\n')
    rows = np.zeros(len(faces), dtype=[('n', 'u1'), ('i', '<i4', 3)])
    rows['n'], rows['i'] = 3, faces
    with open(path, 'wb') as f:
        f.write(header.encode())
        f.write(verts.astype('<f4').tobytes())
        f.write(rows.tobytes())
    return len(faces)


def caustica_scene(name):
    """The pbrt-v4 file of scene `name` (written once), for caustica."""
    os.makedirs(FOLDER, exist_ok=True)
    path = os.path.join(FOLDER, f'{name}.pbrt')
    if os.path.exists(path):
        return path
    (lx, ly, lz), lr, le = LIGHT
    h, rho = FLOOR
    if name == 'glass':
        (gx, gy, gz), gr, eta = GLASS
        ball = (f'AttributeBegin\n  Material "dielectric" "float eta" [{eta}]\n  Translate {gx} {gy} {gz}\n'
                f'  Shape "sphere" "float radius" [{gr}]\nAttributeEnd\n')
    else:
        ply = os.path.join(FOLDER, 'bumpy_ball.ply')
        if not os.path.exists(ply):
            bumpy_ball_ply(ply)
        ball = (f'Material "diffuse" "rgb reflectance" [{BUMPY[2]} {BUMPY[2]} {BUMPY[2]}]\n'
                f'Shape "plymesh" "string filename" "bumpy_ball.ply"\n')
    # (Scale −1 1 1: pbrt's camera space is left-handed; so the picture is Mitsuba's, not its mirror.)
    text = (f'# scripts/race/throughput_scenes.py: {name}\n'
            'Scale -1 1 1\n'
            f'LookAt {" ".join(map(str, EYE))}  {" ".join(map(str, TARGET))}  0 1 0\n'
            f'Camera "perspective" "float fov" [{FOV}]\n'
            f'Film "rgb" "integer xresolution" [{common.SIZE}] "integer yresolution" [{common.SIZE}]\n'
            'WorldBegin\n'
            f'AttributeBegin\n  AreaLightSource "diffuse" "rgb L" [{le} {le} {le}]\n  Translate {lx} {ly} {lz}\n'
            f'  Shape "sphere" "float radius" [{lr}]\nAttributeEnd\n'
            f'Material "diffuse" "rgb reflectance" [{rho} {rho} {rho}]\n'
            f'Shape "trianglemesh" "point3 P" [{-h} 0 {-h}  {h} 0 {-h}  {h} 0 {h}  {-h} 0 {h}]\n'
            '    "integer indices" [0 2 1  0 3 2]\n'
            + ball)
    with open(path, 'w') as f:
        f.write(text)
    return path


def mitsuba_dict(mi, name):
    """Scene `name` as a Mitsuba 3 dict (its integrator left to the caller)."""
    T = mi.ScalarTransform4f
    (lx, ly, lz), lr, le = LIGHT
    h, rho = FLOOR
    d = {
        'type': 'scene',
        'sensor': {'type': 'perspective', 'fov': FOV, 'fov_axis': 'smaller',
                   'to_world': T().look_at(origin=EYE, target=TARGET, up=[0, 1, 0]),
                   'film': {'type': 'hdrfilm', 'width': common.SIZE, 'height': common.SIZE,
                            'rfilter': {'type': 'box'}}},
        'light': {'type': 'sphere', 'center': [lx, ly, lz], 'radius': lr,
                  'emitter': {'type': 'area', 'radiance': {'type': 'rgb', 'value': [le, le, le]}}},
        'floor': {'type': 'rectangle', 'to_world': T().rotate([1, 0, 0], -90).scale([h, h, 1]),
                  'bsdf': {'type': 'diffuse', 'reflectance': {'type': 'rgb', 'value': [rho, rho, rho]}}},
    }
    if name == 'glass':
        c, r, eta = GLASS
        d['ball'] = {'type': 'sphere', 'center': list(c), 'radius': r,
                     'bsdf': {'type': 'dielectric', 'int_ior': eta, 'ext_ior': 1.0}}
    else:
        caustica_scene(name)   # writes the PLY
        rho_b = BUMPY[2]
        d['ball'] = {'type': 'ply', 'filename': os.path.join(FOLDER, 'bumpy_ball.ply'), 'face_normals': True,
                     'bsdf': {'type': 'diffuse', 'reflectance': {'type': 'rgb', 'value': [rho_b] * 3}}}
    return d
