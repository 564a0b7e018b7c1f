#!/usr/bin/env python3
"""Markdown tables, equal-error time ratios and a log-log plot from race.py's results.jsonl.

usage: report.py RESULTS.jsonl [--compare cs-vcm] [--md OUT.md] [--plot OUT.png]

Tables give the arithmetic mean over seeds at each budget. The plot's lines and the time ratios
use the geometric mean over seeds (errors spread over decades) at the mean actual seconds.
"""
import argparse, itertools, json, math, os
from collections import defaultdict

import common

METRICS = [('focus_rel_err', 'focus: relative error of the box mean (max over RGB)', '{:.3f}'),
           ('caustic_relmse', 'caustic region relMSE', '{:.4f}'),
           ('image_relmse', 'whole image relMSE (specular excluded)', '{:.4f}')]
ORDER = ['mi-ptracer', 'mi-path', 'cs-vcm', 'cs-ppm', 'cs-lt', 'cs-path']
COLOURS = dict(zip(ORDER, ['tab:blue', 'tab:cyan', 'tab:red', 'tab:green', 'tab:purple', 'tab:orange']))


def load(path):
    with open(path) as f:
        return [r for r in map(json.loads, filter(str.strip, f)) if 'metrics' in r]


def mean(xs):
    return sum(xs) / len(xs)


def geo(xs):
    return math.exp(mean([math.log(max(x, 1e-12)) for x in xs]))


def samples(r):
    """Mitsuba: samples per pixel; caustica: passes."""
    return r['spp'] if r['renderer'].startswith('mi-') else r['passes']


def cpu_per_wall(r):
    """Mitsuba: of its render loop (its import runs threads outside the budget); caustica: of the process."""
    if 'render_cpu' in r:
        return r['render_cpu'] / r['render_seconds']
    return r['process_cpu'] / r['process_wall']


def time_to_reach(curve, e):
    """First time at which curve [(t, err)] falls to e, log-log interpolated: ('=', t);
    ('<', t0) when already below at its first point; ('>', t_last) when never."""
    if curve[0][1] <= e:
        return '<', curve[0][0]
    for (t0, e0), (t1, e1) in zip(curve, curve[1:]):
        if e1 <= e < e0:
            f = math.log(e / e0) / math.log(e1 / e0)
            return '=', t0 * (t1 / t0) ** f
    return '>', curve[-1][0]


def table(head, rows):
    out = ['| ' + ' | '.join(head) + ' |', '|---:|' + '---:|' * (len(head) - 1)]
    out += ['| ' + ' | '.join(r) + ' |' for r in rows]
    return '\n'.join(out) + '\n'


def focus_cell(rs, fmt):
    """Mean unsigned focus error, with the mean signed one."""
    signed = mean([r['metrics']['focus_signed'] for r in rs])
    return f"{fmt.format(mean([r['metrics']['focus_rel_err'] for r in rs]))} ({signed:+.1%})"


def ratio_cell(curve, t, e):
    """The rival's time to reach error e over t, marked when outside its curve."""
    how, tm = time_to_reach(curve, e)
    return ('' if how == '=' else how + ' ') + f'{tm / t:.2f}'


def report(rows, compare=None):
    """(markdown text, curves, scenes, renderers); curves[(scene, renderer, metric)] =
    [(mean seconds, geometric mean error)] over the budgets."""
    by = defaultdict(list)
    for r in rows:
        by[(r['scene'], r['renderer'], r['budget'])].append(r)
    scenes = [s for s in ('point', 'area') if any(k[0] == s for k in by)]
    present = {k[1] for k in by}
    renderers = [x for x in ORDER if x in present] + sorted(present - set(ORDER))
    budgets = sorted({k[2] for k in by})
    loads, ratio = [r['load1'] for r in rows], [cpu_per_wall(r) for r in rows]
    seeds = ', '.join(map(str, sorted({r['seed'] for r in rows})))
    md = [f'{len(rows)} runs, seeds {seeds}; 1-min load average before a run {min(loads):.2f}–{max(loads):.2f}; '
          f'CPU/wall of a render {min(ratio):.2f}–{max(ratio):.2f}.\n']
    curves = {}

    def grid(scene, cell):
        body = [[f'{b:g}'] + [cell(by[(scene, rn, b)]) if by.get((scene, rn, b)) else '' for rn in renderers]
                for b in budgets]
        return table(['budget s'] + renderers, body)

    for s in scenes:
        md.append(f'## {s} light\n')
        for key, title, fmt in METRICS:
            if key == 'focus_rel_err':
                md.append(f'{title}, mean over seeds (signed mean, of the RGB sum)\n')
                md.append(grid(s, lambda rs: focus_cell(rs, fmt)))
            else:
                md.append(f'{title}, mean over seeds\n')
                md.append(grid(s, lambda rs: fmt.format(mean([r['metrics'][key] for r in rs]))))
        md.append('actual render seconds, samples (Mitsuba: spp; caustica: passes), mean over seeds\n')
        md.append(grid(s, lambda rs: f"{mean([r['render_seconds'] for r in rs]):.2f} s, "
                                     f"{mean([samples(r) for r in rs]):.0f}"))
        for rn in renderers:
            groups = [by[(s, rn, b)] for b in budgets if by.get((s, rn, b))]
            for key, _, _ in METRICS:
                curves[(s, rn, key)] = [(mean([r['render_seconds'] for r in g]), geo([r['metrics'][key] for r in g]))
                                        for g in groups]

    # equal-error time ratios of one caustica renderer against each Mitsuba renderer
    if compare not in renderers:
        fallback = next((x for x in renderers if x.startswith('cs-')), None)
        if compare:
            md.append(f'({compare} has no runs here; the time ratios are for {fallback}.)\n')
        compare = fallback
    rivals = [x for x in renderers if x.startswith('mi-')]
    if not (compare and rivals):
        return '\n'.join(md), curves, scenes, renderers
    md.append(f'## time to equal error: {compare} against Mitsuba\n')
    md.append(f"Ratio = the time the Mitsuba renderer needs to reach the error {compare} reached, over {compare}'s "
              f'time (geometric means over seeds, log-log interpolation); > 1: {compare} is faster. "> x": not '
              "reached by Mitsuba's longest run, so at least x; \"< x\": Mitsuba was already below it at its "
              'shortest run.\n')
    for s in scenes:
        mine = [b for b in budgets if by.get((s, compare, b))]
        for other in rivals:
            body = [[f'{b:g}'] + [ratio_cell(curves[(s, other, key)], *curves[(s, compare, key)][i])
                                  for key, _, _ in METRICS] for i, b in enumerate(mine)]
            md.append(f'{s} light, {compare} vs {other}\n')
            md.append(table([f'{compare} budget s'] + [k for k, _, _ in METRICS], body))
    return '\n'.join(md), curves, scenes, renderers


def plot(path, rows, curves, scenes, renderers):
    """One row of three panels (the metrics) per scene; error against actual seconds, log-log."""
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(len(scenes), 3, figsize=(15, 4.2 * len(scenes)), squeeze=False)
    others = itertools.cycle(['tab:brown', 'tab:pink', 'tab:olive', 'tab:gray'])
    colour = {rn: COLOURS.get(rn) or next(others) for rn in renderers}
    for i, s in enumerate(scenes):
        for j, (key, title, _) in enumerate(METRICS):
            ax = axes[i][j]
            for rn in renderers:
                c = colour[rn]
                pts = curves.get((s, rn, key), [])
                ax.plot([p[0] for p in pts], [p[1] for p in pts], 's--' if rn.startswith('mi-') else 'o-',
                        color=c, label=rn)
                raw = [(r['render_seconds'], max(r['metrics'][key], 1e-6)) for r in rows
                       if r['scene'] == s and r['renderer'] == rn]
                ax.plot([p[0] for p in raw], [p[1] for p in raw], '.', color=c, alpha=0.35)
            ax.set_xscale('log')
            ax.set_yscale('log')
            ax.set_xlabel('render seconds (one core)')
            ax.set_title(f'{s} light: {title}', fontsize=9)
            ax.grid(True, which='both', alpha=0.3)
            if i == 0 and j == 0:
                ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def write(results, compare=None, md_path=None, png_path=None):
    """Print the tables, and write them and the plot when paths are given."""
    rows = load(results) if os.path.exists(results) else []
    if not rows:
        print(f'no runs with metrics in {results}')
        return
    md, curves, scenes, renderers = report(rows, compare)
    print(md)
    if md_path:
        with open(md_path, 'w') as f:
            f.write(md)
    if png_path:
        plot(png_path, rows, curves, scenes, renderers)
    print('\n'.join(f'wrote {p}' for p in (md_path, png_path) if p))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('results')
    ap.add_argument('--compare', help='caustica renderer for the time ratios (default: cs-vcm, else the first cs-*)')
    ap.add_argument('--md', help='write the tables here too')
    ap.add_argument('--plot', help='write the plot (PNG) here')
    a = ap.parse_args()
    common.use_venv(needs=('matplotlib',) if a.plot else ())
    write(a.results, a.compare, a.md, a.plot)


if __name__ == '__main__':
    main()
