#!/usr/bin/env python3
"""Frosted glass against Mitsuba 3's `roughdielectric`: the scene of scripts/scenes/rough_glass.py
(a rough glass ball over a grey floor under a point light) rendered by Mitsuba (`path`, a long
render: the reference) and by caustica's integrators, and the means of four regions compared:
the lit floor, the soft caustic, the ball itself and the shadow beside the caustic. The lit floor
has a closed form too (the point light's direct light on a Lambertian floor), printed beside.

    scripts/race/rough_glass.py [--alpha 0.3] [--spp 2048] [--time 30] [--integrators path,vcm,ppm,lt]

Writes target/rough_glass/{mitsuba,<integrator>}.exr and prints a table; `--mitsuba-only` stops
after the reference, `--reuse` reads the one an earlier run wrote. Uses target/race-venv (scripts/race/setup.sh) and target/release/caustica.
"""
import argparse, json, math, os, subprocess, sys, time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import REPO, use_venv  # noqa: E402

use_venv(('numpy', 'mitsuba'))
import numpy as np  # noqa: E402

sys.path.insert(0, os.path.join(REPO, 'scripts', 'scenes'))
import rough_glass as S  # noqa: E402

# Regions (rows, cols; ends exclusive) of the 320×240 image, each with its mirror image in x
# where it is off the axis: the lit floor near the front corners, the caustic's bright middle,
# the ball, and the shadow between the caustic and the ball's silhouette. Every bound is a
# multiple of 4, so a render at 80×60 (crates/caustica/tests/it/rough_glass.rs) covers the same
# areas with whole pixels.
REGIONS = {
    'floor': [((204, 236), (12, 52)), ((204, 236), (268, 308))],
    'caustic': [((124, 144), (148, 172))],
    'ball': [((36, 76), (140, 180))],
    'shadow': [((152, 168), (100, 120)), ((152, 168), (200, 220))],
}


def region_means(img):
    out = {}
    for name, boxes in REGIONS.items():
        px = np.concatenate([img[r0:r1, c0:c1, :3].reshape(-1, 3) for (r0, r1), (c0, c1) in boxes])
        out[name] = float(px.mean())
    return out


def floor_closed_form():
    """Radiance of the floor at the floor region's pixels: ρ/π · I cos θ / d², averaged over the
    pixels' centres (the ball blocks none of them)."""
    eye, target = np.array(S.EYE), np.array(S.TARGET)
    fwd = (target - eye) / np.linalg.norm(target - eye)
    right = np.cross(fwd, [0, 1, 0]); right /= np.linalg.norm(right)
    up = np.cross(right, fwd)
    t = math.tan(math.radians(S.FOV) / 2)
    vals = []
    for (r0, r1), (c0, c1) in REGIONS['floor']:
        for r in range(r0, r1):
            for c in range(c0, c1):
                x = (2 * (c + 0.5) / S.WIDTH - 1) * t * S.WIDTH / S.HEIGHT
                y = (1 - 2 * (r + 0.5) / S.HEIGHT) * t
                d = fwd + x * right + y * up
                p = eye + d * (-eye[1] / d[1])
                to = np.array(S.LIGHT) - p
                dist2 = to @ to
                vals.append(S.FLOOR_ALBEDO / math.pi * S.INTENSITY * (to[1] / math.sqrt(dist2)) / dist2)
    return float(np.mean(vals))


def mitsuba(alpha, spp, out):
    import mitsuba as mi
    mi.set_variant('llvm_ad_rgb')
    T = mi.ScalarTransform4f
    scene = mi.load_dict({
        'type': 'scene',
        'integrator': {'type': 'path', 'max_depth': 12},
        'sensor': {'type': 'perspective', 'fov': S.FOV, 'fov_axis': 'smaller',
                   'to_world': T().look_at(origin=S.EYE, target=S.TARGET, up=[0, 1, 0]),
                   'film': {'type': 'hdrfilm', 'width': S.WIDTH, 'height': S.HEIGHT,
                            'rfilter': {'type': 'box'}, 'pixel_format': 'rgb'},
                   'sampler': {'type': 'independent', 'sample_count': spp}},
        'light': {'type': 'point', 'position': list(S.LIGHT),
                  'intensity': {'type': 'rgb', 'value': S.INTENSITY}},
        'floor': {'type': 'rectangle',
                  'to_world': T().rotate([1, 0, 0], -90).scale(S.FLOOR_HALF),
                  'bsdf': {'type': 'twosided', 'bsdf': {'type': 'diffuse',
                           'reflectance': {'type': 'rgb', 'value': S.FLOOR_ALBEDO}}}},
        'ball': {'type': 'sphere', 'center': list(S.CENTRE), 'radius': S.RADIUS,
                 'bsdf': {'type': 'roughdielectric', 'distribution': 'ggx', 'alpha': alpha,
                          'int_ior': S.ETA, 'ext_ior': 1.0}},
    })
    t0 = time.time()
    img = mi.render(scene, spp=spp)
    arr = np.array(img)   # the render runs here: Dr.Jit evaluates lazily
    secs = time.time() - t0
    mi.Bitmap(img).write(out)
    return arr, secs


def caustica(integrator, scene, seconds, out):
    binary = os.path.join(REPO, 'target', 'release', 'caustica')
    cmd = [binary, 'render', scene, '--integrator', integrator, '--time', str(seconds),
           '--depth', '10', '-o', out, '--json']
    p = subprocess.run(cmd, capture_output=True, text=True, check=True)
    return json.loads(p.stdout.strip().splitlines()[-1])


def read_exr(path):
    import mitsuba as mi
    if mi.variant() is None:
        mi.set_variant('scalar_rgb')
    return np.array(mi.Bitmap(path).convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('--alpha', type=float, default=0.3)
    ap.add_argument('--spp', type=int, default=2048)
    ap.add_argument('--time', type=float, default=30)
    ap.add_argument('--integrators', default='path,vcm,ppm,lt')
    ap.add_argument('--mitsuba-only', action='store_true')
    ap.add_argument('--reuse', action='store_true', help="read the reference an earlier run wrote to OUT instead of rendering it")
    ap.add_argument('--out', default=os.path.join(REPO, 'target', 'rough_glass'))
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    scene = os.path.join(a.out, 'rough_glass.pbrt')
    with open(scene, 'w') as f:
        f.write(S.scene(a.alpha))
    ref_path = os.path.join(a.out, 'mitsuba.exr')
    if a.reuse and os.path.exists(ref_path):
        ref, budget = read_exr(ref_path), 'earlier run'
    else:
        ref, secs = mitsuba(a.alpha, a.spp, ref_path)
        budget = f'{a.spp} spp, {secs:.0f} s'
    rows = [('mitsuba path', budget, region_means(ref))]
    if not a.mitsuba_only:
        for integ in filter(None, a.integrators.split(',')):
            out = os.path.join(a.out, f'{integ}.exr')
            summary = caustica(integ, scene, a.time, out)
            rows.append((f'caustica {integ}', f"{summary['passes']} passes, {a.time:.0f} s", region_means(read_exr(out))))
    names = list(REGIONS)
    print(f'rough glass α {a.alpha}: region means (linear, mean of R, G, B); closed-form floor {floor_closed_form():.5f}')
    print('| renderer | budget | ' + ' | '.join(names) + ' |')
    print('|---|---|' + '---:|' * len(names))
    base = rows[0][2]
    for who, budget, m in rows:
        cells = [f'{m[n]:.5f}' + ('' if who.startswith('mitsuba') else f' ({100 * (m[n] / base[n] - 1):+.1f}%)') for n in names]
        print(f'| {who} | {budget} | ' + ' | '.join(cells) + ' |')


if __name__ == '__main__':
    main()
