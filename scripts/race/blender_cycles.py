"""caustica's add-on against Cycles at equal time on one core, on the race's Cornell box built in
Blender (`blender_cornell.py`'s scene): Cycles' path tracer, Cycles with shadow caustics
(manifold next-event estimation: the glass ball a caster, the walls receivers, the lamp a
caustics light), and caustica's `vcm`, each for the same wall-clock seconds, compared with
Mitsuba's reference by scripts/race/metrics.py's measures (the focus's relative error, the
caustic region's and the whole image's relMSE).

    PYTHONPATH=python blender -b --factory-startup --python-use-system-env \\
        -P scripts/race/blender_cycles.py -- OUT_DIR [SECONDS ...]

Prints a Markdown table.
"""
import os
import runpy
import sys

import bpy

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
out = os.path.abspath(argv[0] if argv else "blender-cycles")
budgets = [float(b) for b in argv[1:]] or [2.0, 8.0, 32.0]
os.makedirs(out, exist_ok=True)
# blender_cornell.py's builder, without its own renders.
sys.argv = [sys.argv[0], "--", out, "0"]
cornell = runpy.run_path(os.path.join(ROOT, "scripts", "race", "blender_cornell.py"), run_name="cornell")
build, caustica = cornell["build"], cornell["caustica"]
import metrics  # noqa: E402  (on the path blender_cornell.py set)

reference = caustica.read_exr(os.path.join(ROOT, "..", "shared", "reference", "cornell_caustics_point_ref.exr"))
reference = reference.astype("float64")


def setup(renderer, seconds):
    scene = build(principled_glass=False)
    scene.render.threads_mode = "FIXED"
    scene.render.threads = 1
    if renderer == "caustica vcm":
        scene.caustica.time_limit = seconds
        return scene
    scene.render.engine = "CYCLES"
    c = scene.cycles
    c.device = "CPU"
    c.samples = 1 << 20
    c.time_limit = seconds
    c.use_denoising = False
    c.use_adaptive_sampling = False
    c.max_bounces = 10
    c.caustics_reflective = True
    c.caustics_refractive = True
    c.filter_width = 0.01
    if renderer == "Cycles, shadow caustics":
        for obj in scene.objects:
            if obj.type == "MESH":
                is_glass = obj.active_material is not None and obj.active_material.name == "Glass"
                obj.cycles.is_caustics_caster = is_glass
                obj.cycles.is_caustics_receiver = not is_glass
            elif obj.type == "LIGHT":
                obj.data.cycles.is_caustics_light = True
    return scene


print("| renderer | seconds | focus error | caustic region relMSE | image relMSE |")
print("|---|---:|---:|---:|---:|")
for seconds in budgets:
    for renderer in ["caustica vcm", "Cycles path", "Cycles, shadow caustics"]:
        scene = setup(renderer, seconds)
        scene.render.filepath = os.path.join(out, f"{renderer.replace(' ', '-').replace(',', '')}-{seconds:g}.exr")
        bpy.ops.render.render(write_still=True)
        image = caustica.read_exr(scene.render.filepath).astype("float64")
        m = metrics.measures(image, reference, "point")
        print(
            f"| {renderer} | {seconds:g} | {m['focus_rel_err']:.3f} ({100 * m['focus_signed']:+.0f}%) "
            f"| {m['caustic_relmse']:.4f} | {m['image_relmse']:.4f} |"
        )
