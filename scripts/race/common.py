"""Shared pieces of scripts/race: paths, fixed settings, and running one render with its metrics."""
import importlib.util, json, os, resource, shlex, subprocess, sys, time

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
VENV = os.path.join(REPO, 'target', 'race-venv')
LLVM_DEFAULT = '/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1'

SIZE = 160           # the reference's resolution (square)
CS_DEPTH = 8         # caustica --depth, the same for every integrator ...
MI_MAX_DEPTH = 10    # ... matching Mitsuba's max_depth of the reference
MI_INTEGRATORS = ('ptracer', 'path')
SCENES = ('point', 'area')


def use_venv(needs=('numpy', 'mitsuba')):
    """Re-run the calling script inside setup.sh's venv when it exists and is not the one running;
    stop with a hint when a module in needs is missing."""
    py = os.path.join(VENV, 'bin', 'python')
    if os.path.exists(py) and os.path.realpath(sys.prefix) != os.path.realpath(VENV):
        os.execv(py, [py] + sys.argv)
    missing = [m for m in needs if importlib.util.find_spec(m) is None]
    if missing:
        sys.exit(f"{', '.join(missing)} missing: run scripts/race/setup.sh")
    if 'DRJIT_LIBLLVM_PATH' not in os.environ and os.path.exists(LLVM_DEFAULT):
        os.environ['DRJIT_LIBLLVM_PATH'] = LLVM_DEFAULT


def ref_dir(explicit=None):
    """The shared reference folder: --ref-dir, else $CAUSTICA_REF_DIR, else ../shared/reference beside the repo."""
    c = explicit or os.environ.get('CAUSTICA_REF_DIR') or os.path.join(REPO, '..', 'shared', 'reference')
    if not os.path.isfile(os.path.join(c, 'mitsuba_cornell_ref.py')):
        sys.exit(f'no mitsuba_cornell_ref.py in {c}: give the shared reference folder with --ref-dir '
                 'or $CAUSTICA_REF_DIR')
    return os.path.abspath(c)


def check_renderer(name):
    """Renderer names are mi-ptracer, mi-path and cs-<caustica integrator>."""
    kind, _, integ = name.partition('-')
    if not integ or kind not in ('mi', 'cs') or (kind == 'mi' and integ not in MI_INTEGRATORS):
        sys.exit(f'unknown renderer {name!r}: use mi-ptracer, mi-path or cs-<integrator>')


def command(renderer, scene, budget, seed, out, ref, caustica, extra=()):
    """The command line of one render."""
    integ = renderer[3:]
    if renderer.startswith('mi-'):
        return [sys.executable, os.path.join(HERE, 'mitsuba_render.py'), scene, integ, str(budget),
                '-o', out, '--seed', str(seed), '--ref-dir', ref, '--max-depth', str(MI_MAX_DEPTH), *extra]
    if scene in SCENES:
        source = [os.path.join(ref, f'cornell_caustics_{scene}.ray'), '--model', 'physical']
    else:
        import throughput_scenes
        source = [throughput_scenes.caustica_scene(scene)]
    return [caustica, 'render', *source,
            '--integrator', integ, '--time', str(budget), '--threads', '1', '--width', str(SIZE),
            '--depth', str(CS_DEPTH), '--seed', str(seed), '-o', out, '--json', *extra]


def children_cpu():
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def run_one(renderer, scene, budget, seed, out, ref, caustica, extra=(), reference=None):
    """Render once (alone on the machine, as far as this script goes) and return the record for
    results.jsonl, or (None, stderr) when the renderer failed. reference: the reference image,
    for the metrics (none computed without it)."""
    cmd = command(renderer, scene, budget, seed, out, ref, caustica, extra)
    load = os.getloadavg()[0]
    cpu0, t0 = children_cpu(), time.perf_counter()
    p = subprocess.run(cmd, capture_output=True, text=True)
    wall, cpu = time.perf_counter() - t0, children_cpu() - cpu0   # one child at a time: the delta is its own
    if p.returncode != 0:
        return None, (p.stderr or p.stdout)[-2000:]
    summary = json.loads(p.stdout.strip().splitlines()[-1])
    rec = {'renderer': renderer, 'scene': scene, 'budget': budget, 'seed': seed, 'load1': round(load, 2),
           'process_wall': round(wall, 4), 'process_cpu': round(cpu, 4),
           'render_seconds': summary['seconds']['render'], 'passes': summary['passes']}
    if renderer.startswith('mi-'):
        rec['spp'] = summary['spp']                       # ptracer: light paths per pixel
        rec['render_cpu'] = summary['seconds']['render_cpu']
    else:
        if summary.get('photons_per_pass'):
            rec['photons'] = summary['photons']   # resized passes count by their share
        if renderer == 'cs-path':   # one camera path per pixel and pass (--aa 1)
            rec['spp'] = summary['passes']
    if reference is not None:
        import metrics
        rec['metrics'] = metrics.measures(metrics.read_exr(out), reference, scene)
    rec.update(summary=summary, cmd=shlex.join(cmd), utc=time.strftime('%Y-%m-%dT%H:%M:%SZ', time.gmtime()))
    return rec, None
