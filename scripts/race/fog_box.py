#!/usr/bin/env python3
"""Fog against Mitsuba 3's `volpath`: the area-lamp variant of scripts/scenes/fog_box.py (a Cornell
box of thin fog, a glass ball, a small square lamp under the ceiling) rendered by Mitsuba (a long
render: the reference) and by caustica's integrators at equal wall time on one core, and the means
of five regions compared: the fog beside the ball, the beam the ball focuses into the fog below
it, the floor's caustic, the back wall and the red wall.

caustica's fog fills the scene as far as the sphere around its bounds (the box's corners lie on
it); Mitsuba's fills a sphere of the same centre and radius with a `null` surface, every shape
inside having the fog on both sides (the glass ball outside only). pbrt's `LookAt` is
left-handed (world −x on the image's right here) and Mitsuba's `look_at` right-handed, so
Mitsuba's image is mirrored left to right before it is compared.

    scripts/race/fog_box.py [--spp 16384] [--time 16] [--integrators vcm,path,lt,ppm] [--reuse]
    scripts/race/fog_box.py --reuse --race [--budgets 4,16] [--seeds 4] [--second-spp 8192]

Writes target/fog_box/{mitsuba,<integrator>}.exr and prints a table. `--race` instead renders
every integrator and Mitsuba's volpath (passes of 4 spp until the budget) on one core at each
budget and seed, and prints their mean errors against the reference: the relative RMS error of
the whole image and of the beam, and the error of the beam's mean. Uses target/race-venv
(scripts/race/setup.sh) and target/release/caustica.
"""
import argparse, json, math, os, subprocess, sys, time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import REPO, use_venv  # noqa: E402

use_venv(('numpy', 'mitsuba'))
import numpy as np  # noqa: E402

sys.path.insert(0, os.path.join(REPO, 'scripts', 'scenes'))
import fog_box as S  # noqa: E402

SIZE = 160
# caustica's --depth N scatters at N + 1 vertices; Mitsuba's max_depth counts the segment to the
# eye as well.
CS_DEPTH, MI_MAX_DEPTH = 20, 22
# Regions (rows, cols; ends exclusive) of the 160×160 image.
REGIONS = {
    'fog': ((60, 90), (30, 55)),
    'beam': ((95, 120), (76, 84)),
    'caustic': ((138, 146), (70, 90)),
    'back wall': ((30, 50), (100, 130)),
    'red wall': ((60, 100), (5, 20)),
}


def region_means(img):
    return {n: float(img[r0:r1, c0:c1, :3].mean()) for n, ((r0, r1), (c0, c1)) in REGIONS.items()}


def mitsuba(spp, threads, out, seed=0):
    import mitsuba as mi, drjit as dr
    scene = load_mitsuba_scene(spp)
    dr.set_thread_count(threads)
    t0 = time.time()
    img = mi.render(scene, spp=spp, seed=seed)
    arr = np.ascontiguousarray(np.array(img)[:, ::-1])
    secs = time.time() - t0
    mi.Bitmap(arr).write(out)
    return arr, secs, mi.variant()


def load_mitsuba_scene(spp):
    """The scene for Mitsuba (llvm_ad_rgb where Dr.Jit finds LLVM, else scalar_rgb)."""
    import mitsuba as mi
    if mi.variant() is None:
        try:
            mi.set_variant('llvm_ad_rgb')
        except Exception:
            mi.set_variant('scalar_rgb')
    T = mi.ScalarTransform4f
    sigma_t = S.SIGMA_A + S.SIGMA_S
    fog = {'type': 'homogeneous', 'sigma_t': sigma_t, 'albedo': {'type': 'rgb', 'value': S.SIGMA_S / sigma_t},
           'phase': {'type': 'hg', 'g': S.G}}
    white = {'type': 'twosided', 'bsdf': {'type': 'diffuse', 'reflectance': {'type': 'rgb', 'value': 0.7}}}
    red = {'type': 'twosided', 'bsdf': {'type': 'diffuse', 'reflectance': {'type': 'rgb', 'value': [0.6, 0.1, 0.1]}}}
    green = {'type': 'twosided', 'bsdf': {'type': 'diffuse', 'reflectance': {'type': 'rgb', 'value': [0.1, 0.5, 0.1]}}}

    def wall(to_world, bsdf):
        return {'type': 'rectangle', 'to_world': to_world, 'bsdf': bsdf, 'interior': {'type': 'ref', 'id': 'fog'},
                'exterior': {'type': 'ref', 'id': 'fog'}}

    h = S.LAMP_HALF
    scene = mi.load_dict({
        'type': 'scene',
        'integrator': {'type': 'volpath', 'max_depth': MI_MAX_DEPTH},
        'sensor': {'type': 'perspective', 'fov': S.FOV, 'fov_axis': 'smaller',
                   'to_world': T().look_at(origin=S.EYE, target=S.TARGET, up=[0, 1, 0]),
                   'film': {'type': 'hdrfilm', 'width': SIZE, 'height': SIZE,
                            'rfilter': {'type': 'box'}, 'pixel_format': 'rgb'},
                   'sampler': {'type': 'independent', 'sample_count': spp}},
        'fog': fog,
        'volume': {'type': 'sphere', 'center': [0, 1, 0], 'radius': math.sqrt(3), 'bsdf': {'type': 'null'},
                   'interior': {'type': 'ref', 'id': 'fog'}},
        'floor': wall(T().rotate([1, 0, 0], -90), white),
        'ceiling': wall(T().translate([0, 2, 0]).rotate([1, 0, 0], 90), white),
        'back': wall(T().translate([0, 1, -1]), white),
        'left': wall(T().translate([-1, 1, 0]).rotate([0, 1, 0], 90), red),
        'right': wall(T().translate([1, 1, 0]).rotate([0, 1, 0], -90), green),
        'lamp': {'type': 'rectangle', 'to_world': T().translate([0, 1.99, 0]).rotate([1, 0, 0], 90).scale([h, h, 1]),
                 'emitter': {'type': 'area', 'radiance': {'type': 'rgb', 'value': S.LAMP_RADIANCE}},
                 'bsdf': {'type': 'diffuse', 'reflectance': {'type': 'rgb', 'value': 0.0}},
                 'interior': {'type': 'ref', 'id': 'fog'}, 'exterior': {'type': 'ref', 'id': 'fog'}},
        'ball': {'type': 'sphere', 'center': list(S.BALL), 'radius': S.RADIUS,
                 'bsdf': {'type': 'dielectric', 'int_ior': S.ETA, 'ext_ior': 1.0},
                 'exterior': {'type': 'ref', 'id': 'fog'}},
    })
    return scene


def mitsuba_for(seconds, seed, scene_dict_holder={}):
    """Mitsuba's volpath on one thread for `seconds`: passes of 4 spp after a warm-up pass."""
    import mitsuba as mi, drjit as dr
    dr.set_thread_count(1)
    if 'scene' not in scene_dict_holder:
        scene_dict_holder['scene'] = load_mitsuba_scene(4)
    scene = scene_dict_holder['scene']
    np.array(mi.render(scene, spp=4, seed=10_000_000 + seed))
    t0, total, passes = time.time(), None, 0
    last = 0.0
    while time.time() - t0 + 0.5 * last < seconds:
        p0 = time.time()
        img = np.array(mi.render(scene, spp=4, seed=seed * 1_000_003 + passes))
        last = time.time() - p0
        total = img if total is None else total + img
        passes += 1
    # Reading an EXR later hangs with a pool of one thread; the pool idles while caustica runs.
    dr.set_thread_count(2)
    return np.ascontiguousarray((total / passes)[:, ::-1]), passes * 4


def caustica(integrator, scene, seconds, out, seed=0):
    binary = os.path.join(REPO, 'target', 'release', 'caustica')
    cmd = [binary, 'render', scene, '--integrator', integrator, '--time', str(seconds), '--threads', '1',
           '--width', str(SIZE), '--height', str(SIZE), '--depth', str(CS_DEPTH), '--seed', str(seed), '-o', out,
           '--json']
    p = subprocess.run(cmd, capture_output=True, text=True, check=True)
    return json.loads(p.stdout.strip().splitlines()[-1])


def read_exr(path):
    import mitsuba as mi
    if mi.variant() is None:
        mi.set_variant('scalar_rgb')
    return np.array(mi.Bitmap(path).convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32))


def errors(img, ref, ref_var=None):
    """Relative RMS error of the image without the lamp (pixels the reference sees above 2 and
    those within two pixels of them: the lamp, its edges and its image in the ball, whose
    coverage noise at radiance 60 would outweigh everything else), and of the beam; the beam mean's error; and with `ref_var` (the
    reference's own variance per pixel) the beam's error against the truth: its squared error
    less what the reference's noise adds to it (an unbiased estimate, as the two are
    independent)."""
    (r0, r1), (c0, c1) = REGIONS['beam']
    lamp = ref.max(axis=2) > 2.0
    near = np.zeros_like(lamp)
    for dy in range(-2, 3):
        for dx in range(-2, 3):
            near |= np.roll(np.roll(lamp, dy, axis=0), dx, axis=1)
    keep = ~near
    whole = math.sqrt(float(((img - ref) ** 2)[keep].mean())) / float(ref[keep].mean())
    b, rb = img[r0:r1, c0:c1], ref[r0:r1, c0:c1]
    mse = float(((b - rb) ** 2).mean())
    beam = math.sqrt(mse) / float(rb.mean())
    truth = float('nan')
    if ref_var is not None:
        # Negative when the estimate falls below zero (noise in the noise): shown with its sign.
        left = mse - float(ref_var[r0:r1, c0:c1].mean())
        truth = math.copysign(math.sqrt(abs(left)), left) / float(rb.mean())
    return whole, beam, abs(float(b.mean()) / float(rb.mean()) - 1), truth


def race(ref, scene, out, budgets, seeds, integrators, score_only, ref_var=None):
    """Renders (or with `score_only` reads) each renderer's image at each budget and seed."""
    print('| renderer | budget | image rel. RMSE (no lamp) | beam rel. RMSE | beam mean error | '
          'beam rel. RMSE, reference noise removed | passes |')
    print('|---|---:|---:|---:|---:|---:|---:|')
    for budget in budgets:
        for who in ['mi-volpath'] + [f'cs-{i}' for i in integrators]:
            errs, work = [], []
            for seed in range(1, seeds + 1):
                path = os.path.join(out, f'race_{who}_{budget}_{seed}.exr')
                if score_only:
                    work.append('-')
                elif who == 'mi-volpath':
                    img, spp = mitsuba_for(budget, seed)
                    import mitsuba as mi
                    mi.Bitmap(img).write(path)
                    work.append(f'{spp} spp')
                else:
                    summary = caustica(who[3:], scene, budget, path, seed)
                    work.append(str(summary['passes']))
                img = read_exr(path)
                errs.append(errors(img[:, :, :3], ref[:, :, :3], ref_var))
            e = np.mean(np.array(errs), axis=0)
            print(f'| {who} | {budget:g} s | {e[0]:.4f} | {e[1]:.4f} | {100 * e[2]:.2f}% | {e[3]:.4f} | '
                  f'{", ".join(work)} |', flush=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('--spp', type=int, default=16384)
    ap.add_argument('--threads', type=int, default=2, help="the reference's threads")
    ap.add_argument('--time', type=float, default=16)
    ap.add_argument('--integrators', default='vcm,path,lt,ppm')
    ap.add_argument('--race', action='store_true', help='the equal-time race against the reference')
    ap.add_argument('--budgets', default='4,16')
    ap.add_argument('--seeds', type=int, default=4)
    ap.add_argument('--score-only', action='store_true', help="score the race's images an earlier run wrote")
    ap.add_argument('--reuse', action='store_true', help="read the reference an earlier run wrote")
    ap.add_argument('--second-spp', type=int, default=0,
                    help="also render (or with --reuse read) an independent second reference of this many spp: "
                         "the two give the first one's noise, which --race then takes out of the beam's error")
    ap.add_argument('--out', default=os.path.join(REPO, 'target', 'fog_box'))
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    scene = os.path.join(a.out, 'fog_box_area.pbrt')
    with open(scene, 'w') as f:
        f.write(S.scene(True))
    ref_path = os.path.join(a.out, 'mitsuba.exr')
    if a.reuse and os.path.exists(ref_path):
        ref, budget = read_exr(ref_path), 'earlier run'
    else:
        ref, secs, variant = mitsuba(a.spp, a.threads, ref_path)
        budget = f'{a.spp} spp, {secs:.0f} s on {a.threads} threads ({variant})'
    ref_var = None
    if a.second_spp:
        second_path = os.path.join(a.out, f'mitsuba_second_{a.second_spp}.exr')
        if a.reuse and os.path.exists(second_path):
            second = read_exr(second_path)
        else:
            second, secs, _ = mitsuba(a.second_spp, a.threads, second_path, seed=1)
            print(f'second reference: {a.second_spp} spp in {secs:.0f} s')
        # E[(A − B)²] = Var A + Var B, and Var B = Var A · spp_A / spp_B.
        ref_var = (ref[:, :, :3] - second[:, :, :3]) ** 2 / (1 + a.spp / a.second_spp)
    if a.race:
        race(ref, scene, a.out, [float(b) for b in a.budgets.split(',')], a.seeds,
             list(filter(None, a.integrators.split(','))), a.score_only, ref_var)
        return
    rows = [('mitsuba volpath', budget, region_means(ref))]
    for integ in filter(None, a.integrators.split(',')):
        out = os.path.join(a.out, f'{integ}.exr')
        summary = caustica(integ, scene, a.time, out)
        rows.append((f'caustica {integ}', f"{summary['passes']} passes, {a.time:.0f} s, 1 thread", region_means(read_exr(out))))
    names = list(REGIONS)
    print('fog box (area lamp): region means (linear, mean of R, G, B)')
    print('| renderer | budget | ' + ' | '.join(names) + ' |')
    print('|---|---|' + '---:|' * len(names))
    base = rows[0][2]
    for who, budget, m in rows:
        cells = [f'{m[n]:.5f}' + ('' if who.startswith('mitsuba') else f' ({100 * (m[n] / base[n] - 1):+.1f}%)') for n in names]
        print(f'| {who} | {budget} | ' + ' | '.join(cells) + ' |')


if __name__ == '__main__':
    main()
