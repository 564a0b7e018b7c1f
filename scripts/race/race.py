#!/usr/bin/env python3
"""The caustics race: caustica's integrators against Mitsuba 3 on the shared reference's Cornell
boxes, one core each, at a ladder of equal wall-time budgets; errors against the reference images.

Renders run strictly one at a time, in the order seed, scene, budget, renderer (so all renderers
at a budget see about the same machine load). Each run appends one line to OUT/results.jsonl
(load average, wall and CPU time, samples, the three errors, the exact command); then
OUT/tables.md and OUT/race.png are written (see report.py, and README.md for the metrics).

Renderers: mi-ptracer and mi-path (Mitsuba 3, llvm_ad_rgb, mitsuba_render.py) and cs-NAME
(caustica's integrator NAME: render --time T --threads 1 --width 160 --depth 8 --seed S).
A renderer that fails is reported and left out of the rest of the ladder.
"""
import argparse, itertools, json, os, shlex, shutil, sys, tempfile

import common
import report


def parse_extra(items):
    """['cs-vcm=--photons 1000', ...] -> {'cs-vcm': ['--photons', '1000'], ...}"""
    out = {}
    for it in items:
        name, sep, args = it.partition('=')
        if not sep:
            sys.exit(f'--extra-args takes RENDERER=ARGS, not {it!r}')
        common.check_renderer(name)
        out.setdefault(name, []).extend(shlex.split(args))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    arg = ap.add_argument
    arg('--scenes', default='point,area', help='comma-separated: point, area (default: %(default)s)')
    arg('--budgets', default='0.5,1,2,4,8,16', help='wall-time budgets in seconds (default: %(default)s)')
    arg('--renderers', default='mi-ptracer,mi-path,cs-vcm,cs-ppm,cs-lt,cs-path',
        help='comma-separated: mi-ptracer, mi-path, cs-<caustica integrator> (default: %(default)s)')
    arg('--seeds', type=int, default=4, help='runs per scene, budget and renderer: seeds FIRST_SEED onwards (default: %(default)s)')
    arg('--first-seed', type=int, default=1, help='start the seeds here, to add seeds to a run with --append '
        '(default: %(default)s)')
    arg('--caustica', default=os.path.join(common.REPO, 'target', 'release', 'caustica'),
        help='caustica binary (default: target/release/caustica)')
    arg('--out', default=os.path.join(common.REPO, 'target', 'race'), help='output folder (default: target/race)')
    arg('--ref-dir', help='the shared reference folder (default: $CAUSTICA_REF_DIR, or ../shared/reference '
        'beside the repo)')
    arg('--extra-args', action='append', default=[], metavar='RENDERER=ARGS',
        help="extra flags for one renderer, e.g. 'cs-vcm=--photons 100000' or 'mi-path=--spp-per-pass 16'; "
        'repeatable')
    arg('--compare', default='cs-vcm', help='caustica renderer of the equal-error time ratios when it has runs, '
        'else the first cs-* (default: %(default)s)')
    arg('--append', action='store_true', help='add to OUT/results.jsonl (default: start it anew, keeping the '
        'old one as results.prev.jsonl)')
    arg('--keep-images', action='store_true', help='keep every EXR in OUT/images')
    arg('--report-only', action='store_true', help='only remake the tables and plot from OUT/results.jsonl')
    a = ap.parse_args()
    common.use_venv(('numpy', 'mitsuba', 'matplotlib'))   # after parsing: --help needs nothing installed
    os.makedirs(a.out, exist_ok=True)
    results = os.path.join(a.out, 'results.jsonl')
    if not a.report_only:
        ladder(a, results)
    report.write(results, a.compare, os.path.join(a.out, 'tables.md'), os.path.join(a.out, 'race.png'))


def ladder(a, results):
    import metrics
    scenes = a.scenes.split(',')
    budgets = [float(b) for b in a.budgets.split(',')]
    renderers = a.renderers.split(',')
    for s in scenes:
        if s not in common.SCENES:
            sys.exit(f'unknown scene {s!r}: use point, area')
    for r in renderers:
        common.check_renderer(r)
    extra = parse_extra(a.extra_args)
    if any(r.startswith('cs-') for r in renderers) and not os.access(a.caustica, os.X_OK):
        sys.exit(f'no caustica binary at {a.caustica}: build it (cargo build --release) or give --caustica')
    ref = common.ref_dir(a.ref_dir)
    refs = {s: metrics.read_exr(os.path.join(ref, f'cornell_caustics_{s}_ref.exr')) for s in scenes}
    if not a.append and os.path.exists(results):
        os.replace(results, os.path.join(a.out, 'results.prev.jsonl'))
    images = os.path.join(a.out, 'images')
    if a.keep_images:
        os.makedirs(images, exist_ok=True)
    tmp = tempfile.mkdtemp(prefix='race-')
    failed = set()
    # seed, scene, budget, renderer: the renderers at one budget run back to back, under similar load
    runs = list(itertools.product(range(a.first_seed, a.first_seed + a.seeds), scenes, budgets, renderers))
    try:
        with open(results, 'a') as fo:
            for i, (seed, scene, budget, r) in enumerate(runs, 1):
                if r in failed:
                    continue
                out = os.path.join(images if a.keep_images else tmp, f'{r}-{scene}-{budget:g}s-seed{seed}.exr')
                rec, err = common.run_one(r, scene, budget, seed, out, ref, a.caustica, extra.get(r, []), refs[scene])
                if rec is None:
                    failed.add(r)
                    print(f'{r} failed, left out from now on:\n{err}', file=sys.stderr, flush=True)
                    continue
                fo.write(json.dumps(rec) + '\n')
                fo.flush()
                print(f'[{i}/{len(runs)}] ' + progress(rec), flush=True)
                if not a.keep_images:
                    os.remove(out)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def progress(rec):
    """One line about a finished run."""
    m, r = rec['metrics'], rec['renderer']
    n = rec['spp'] if r.startswith('mi-') else rec['passes']
    return (f"load {rec['load1']:.2f} {r:11s} {rec['scene']:5s} {rec['budget']:4g} s seed {rec['seed']}: "
            f"{rec['render_seconds']:.2f} s (process cpu {rec['process_cpu']:.2f} wall {rec['process_wall']:.2f}) "
            f"n {n:4d}  focus {m['focus_rel_err']:.3f} ({m['focus_signed']:+.3f}) "
            f"caustic {m['caustic_relmse']:.4f} image {m['image_relmse']:.4f}")


if __name__ == '__main__':
    main()
