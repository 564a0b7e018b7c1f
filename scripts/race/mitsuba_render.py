#!/usr/bin/env python3
"""Render the shared reference's Cornell box with Mitsuba 3 for a time budget, on one core.

usage: mitsuba_render.py {point|area|glass|mesh} {ptracer|path} SECONDS -o OUT.exr [--seed S] [options]

The Cornell boxes (point, area) are the reference's own: ../shared/reference/mitsuba_cornell_ref.py is executed with
mi.load_dict intercepted, so its dict is captured without rendering or copying the script; the
throughput benchmark's glass and mesh scenes come from throughput_scenes.py. Only
the integrator is replaced ({'type': ptracer|path, 'max_depth': 10}, the reference's cut).

Passes of a fixed size (1 spp for ptracer, 4 for path: Dr.Jit's kernels bake the sample count in,
so every new size is a new compile) are rendered with seeds S*1000003 + pass and averaged. One
discarded warm-up pass before the clock starts pays the compile (or the load from ~/.drjit). A
pass is started only while elapsed + half the last pass is below the budget.
Prints one JSON line (timings, passes, spp, paths/s) and writes OUT.exr (linear RGB, float32).
"""
import time

T_START = time.perf_counter()
import argparse, json, os, resource, sys

import common


def cpu_seconds():
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


class _Captured(Exception):
    pass


def scene_dict(mi, light, ref):
    """The reference script's scene dict for light 'point' or 'area', captured at mi.load_dict."""
    path = os.path.join(ref, 'mitsuba_cornell_ref.py')
    got = {}

    def capture(d, *a, **k):
        got['d'] = d
        raise _Captured

    saved = sys.argv, mi.load_dict, mi.set_variant
    sys.argv = [path, light, '1', '1', os.devnull]     # the script's own arguments: light passes spp out
    mi.load_dict, mi.set_variant = capture, lambda *a, **k: None   # keep the caller's variant
    try:
        with open(path) as f:
            exec(compile(f.read(), path, 'exec'), {'__name__': '__refscene__', '__file__': path})
    except _Captured:
        pass
    finally:
        sys.argv, mi.load_dict, mi.set_variant = saved
    if 'd' not in got:
        sys.exit(f'{path} did not call mi.load_dict')
    return got['d']


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    import throughput_scenes
    ap.add_argument('scene', choices=common.SCENES + throughput_scenes.SCENES)
    ap.add_argument('integrator', choices=common.MI_INTEGRATORS)
    ap.add_argument('seconds', type=float)
    ap.add_argument('-o', '--output', required=True)
    ap.add_argument('--seed', type=int, default=0)
    ap.add_argument('--variant', default='llvm_ad_rgb', help='llvm_ad_rgb (default) or scalar_rgb (no JIT)')
    ap.add_argument('--threads', type=int, default=1, help='Dr.Jit pool size; 1 (default): no worker threads')
    ap.add_argument('--spp-per-pass', type=int, help='default: 1 for ptracer, 4 for path')
    ap.add_argument('--no-warmup', action='store_true', help='compile inside the budget')
    ap.add_argument('--clock', choices=['wall', 'cpu'], default='wall', help='budget in wall or process CPU seconds')
    ap.add_argument('--max-depth', type=int, default=common.MI_MAX_DEPTH)
    ap.add_argument('--ref-dir')
    a = ap.parse_args()

    if 'DRJIT_LIBLLVM_PATH' not in os.environ and os.path.exists(common.LLVM_DEFAULT):
        os.environ['DRJIT_LIBLLVM_PATH'] = common.LLVM_DEFAULT
    import numpy as np
    import mitsuba as mi
    import drjit as dr
    mi.set_variant(a.variant)
    dr.set_thread_count(a.threads)   # 0 and 1: all work on this thread (DRJIT_NUM_THREADS is ignored)
    t_import = time.perf_counter() - T_START

    spp = a.spp_per_pass or (1 if a.integrator == 'ptracer' else 4)
    if a.scene in throughput_scenes.SCENES:
        d = throughput_scenes.mitsuba_dict(mi, a.scene)
    else:
        d = scene_dict(mi, a.scene, common.ref_dir(a.ref_dir))
    d['integrator'] = {'type': a.integrator, 'max_depth': a.max_depth}
    t0 = time.perf_counter()
    scene = mi.load_dict(d)
    t_load = time.perf_counter() - t0
    width, height = scene.sensors()[0].film().size()

    def render(seed):
        return np.array(mi.render(scene, spp=spp, seed=seed), dtype=np.float64)  # array() forces evaluation

    warm = None
    if not a.no_warmup:
        t0 = time.perf_counter()
        render(0xFFFFFF - a.seed)
        warm = time.perf_counter() - t0

    clock = time.perf_counter if a.clock == 'wall' else cpu_seconds
    acc, passes, last, first = None, 0, 0.0, None
    wall0, cpu0 = time.perf_counter(), cpu_seconds()
    start = clock()
    while passes == 0 or clock() - start + 0.5 * last < a.seconds:
        p0 = clock()
        img = render(a.seed * 1000003 + passes)
        last = clock() - p0
        first = last if first is None else first
        acc = img if acc is None else acc + img
        passes += 1
    wall, cpu = time.perf_counter() - wall0, cpu_seconds() - cpu0
    pool = dr.thread_count()
    # OpenEXR's writer waits on the thread pool that set_thread_count(1) emptied and would
    # deadlock: restore workers before writing.
    dr.set_thread_count(max(2, os.cpu_count() or 2))
    mi.Bitmap((acc / passes).astype(np.float32), mi.Bitmap.PixelFormat.RGB).write(a.output)
    paths = passes * spp * width * height   # ptracer: light paths; path: camera paths
    print(json.dumps({
        'renderer': 'mitsuba', 'variant': a.variant, 'mitsuba': mi.__version__, 'drjit': dr.__version__,
        'scene': a.scene, 'integrator': a.integrator, 'max_depth': a.max_depth, 'budget': a.seconds,
        'clock': a.clock, 'warmup': not a.no_warmup, 'threads': a.threads, 'dr_thread_count': pool,
        'width': width, 'height': height, 'spp_per_pass': spp, 'passes': passes, 'spp': passes * spp,
        'seconds': {'import': round(t_import, 4), 'load': round(t_load, 4),
                    'warmup': None if warm is None else round(warm, 4), 'first_pass': round(first, 4),
                    'render': round(wall, 4), 'render_cpu': round(cpu, 4),
                    'total': round(time.perf_counter() - T_START, 4)},
        'paths_per_second': round(paths / wall), 'output': a.output}))


if __name__ == '__main__':
    main()
