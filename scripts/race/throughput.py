#!/usr/bin/env python3
"""Camera paths per second on one core: caustica's path against Mitsuba 3's path (llvm_ad_rgb)
on both reference scenes (point, area) and the benchmark's own (glass: a glass ball over a floor
under a small sphere light; mesh: a 1M-triangle ball there; throughput_scenes.py). The issue's
target: caustica's path at least as fast as Mitsuba's.

A camera path is one sample of one pixel: spp x 160 x 160 per run. Counted per wall second of
the render (caustica: its --json render seconds; Mitsuba: its timed loop, warm kernels) and per
CPU second (caustica: the whole process; Mitsuba: the loop). Runs are one at a time, each of
--seconds (8 s or more: shorter runs overweight start-up and the last pass). Mitsuba is run at
each of --mi-spp-per-pass (larger passes run faster); the target is checked against its best.
Each run is logged to OUT/throughput.jsonl.
"""
import argparse, itertools, json, os, shutil, sys, tempfile

import common


def table(rows):
    """Markdown table of mean/range paths per second, and the cs/mi ratio per scene."""
    groups = {}
    for r in rows:
        how = (f"--threads 1 --depth {common.CS_DEPTH}" if r['renderer'] == 'cs-path'
               else f"{r['summary']['variant']}, {r['summary']['spp_per_pass']} spp/pass")
        n = r['spp'] * common.SIZE * common.SIZE
        cpu = r.get('render_cpu', r['process_cpu'])
        groups.setdefault((r['scene'], r['renderer'], how), []).append((n / r['render_seconds'], n / cpu))
    out = ['| scene | renderer | setting | runs | k paths/s (wall), mean (range) | k paths per CPU-s |',
           '|---|---|---|---:|---:|---:|']
    best = {}
    for (scene, rn, how), v in sorted(groups.items()):
        w = [x[0] / 1e3 for x in v]
        c = [x[1] / 1e3 for x in v]
        m = sum(w) / len(w)
        best[(scene, rn)] = max(best.get((scene, rn), 0), m)
        out.append(f'| {scene} | {rn} | {how} | {len(v)} | {m:.0f} ({min(w):.0f}–{max(w):.0f}) '
                   f'| {sum(c) / len(c):.0f} |')
    out.append('')
    for scene in sorted({k[0] for k in best}):
        cs, mi = best.get((scene, 'cs-path')), best.get((scene, 'mi-path'))
        if cs and mi:
            out.append(f'{scene}: caustica path / Mitsuba path (its best setting) = {cs / mi:.2f}: '
                       + ('target met' if cs >= mi else 'target NOT met'))
    return '\n'.join(out)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    ap.add_argument('--scenes', default='point,area,glass,mesh', help='comma-separated (default: %(default)s)')
    ap.add_argument('--seconds', type=float, default=8, help='budget of each run (default: %(default)s)')
    ap.add_argument('--runs', type=int, default=2, help='runs of each setting, seeds 1..N (default: %(default)s)')
    ap.add_argument('--mi-spp-per-pass', default='4,16', help='Mitsuba pass sizes to try (default: %(default)s)')
    ap.add_argument('--caustica', default=os.path.join(common.REPO, 'target', 'release', 'caustica'),
                    help='caustica binary (default: target/release/caustica)')
    ap.add_argument('--out', default=os.path.join(common.REPO, 'target', 'race'),
                    help='output folder (default: target/race)')
    ap.add_argument('--ref-dir', help='the shared reference folder (as in race.py)')
    ap.add_argument('--append', action='store_true', help='add to OUT/throughput.jsonl (default: start it anew, '
                    'keeping the old one as throughput.prev.jsonl)')
    ap.add_argument('--report-only', action='store_true', help='only print the table of OUT/throughput.jsonl')
    a = ap.parse_args()
    common.use_venv(needs=() if a.report_only else ('numpy', 'mitsuba'))
    os.makedirs(a.out, exist_ok=True)
    results = os.path.join(a.out, 'throughput.jsonl')
    if not a.report_only:
        if a.seconds < 8:
            print(f'note: {a.seconds:g} s runs are shorter than the 8 s the measure asks for', file=sys.stderr)
        if not os.access(a.caustica, os.X_OK):
            sys.exit(f'no caustica binary at {a.caustica}: build it (cargo build --release) or give --caustica')
        ref = common.ref_dir(a.ref_dir)
        if not a.append and os.path.exists(results):
            os.replace(results, os.path.join(a.out, 'throughput.prev.jsonl'))
        settings = [('cs-path', [])] + [('mi-path', ['--spp-per-pass', n]) for n in a.mi_spp_per_pass.split(',')]
        tmp = tempfile.mkdtemp(prefix='race-thr-')
        try:
            with open(results, 'a') as fo:
                for seed, scene, (rn, extra) in itertools.product(range(1, a.runs + 1), a.scenes.split(','), settings):
                    rec, err = common.run_one(rn, scene, a.seconds, seed, os.path.join(tmp, 'out.exr'), ref,
                                              a.caustica, extra)
                    if rec is None:
                        sys.exit(f'{rn} failed:\n{err}')
                    fo.write(json.dumps(rec) + '\n')
                    fo.flush()
                    paths = rec['spp'] * common.SIZE ** 2 / rec['render_seconds']
                    print(f"load {rec['load1']:.2f} {rn} {' '.join(extra):17s} {scene:5s} seed {seed}: "
                          f"{rec['render_seconds']:.2f} s, {rec['spp']} spp, {paths / 1e3:.0f} k paths/s", flush=True)
        finally:
            shutil.rmtree(tmp, ignore_errors=True)
    with open(results) as f:
        rows = [json.loads(l) for l in f if l.strip()]
    print(table(rows))


if __name__ == '__main__':
    main()
