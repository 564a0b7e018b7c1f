# %% [markdown]
# # Comparing caustica's integrators from Python
#
# A notebook-style script (cells marked `# %%`, so Jupyter, VS Code and plain `python` all run
# it): it renders the glass sphere with the three physical integrators for the same time, keeps
# each one's error against a long reference after every pass, and writes PNG images, the
# error-against-time plot and a plot of the caustic photons.
#
#     pip install ./python matplotlib
#     python docs/python-example.py [OUTPUT_DIR] [SECONDS_PER_INTEGRATOR]
#
# Run it from the repository root (it reads `scenes/`).

# %%
import sys
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

import caustica

out = Path(sys.argv[1] if len(sys.argv) > 1 else "python-example")
budget = float(sys.argv[2]) if len(sys.argv) > 2 else 8.0
out.mkdir(parents=True, exist_ok=True)
scene = caustica.Scene("scenes/glass_sphere.ray")
options = dict(model="physical", width=128, photons=100_000)
print(scene, "renders at", scene.size(options["width"]))


def save_png(image: np.ndarray, path: Path, exposure: float = 0.0) -> None:
    """Tone-maps linear radiance as `caustica render -o x.png` does for the physical model:
    2^exposure, x / (1 + x), then the sRGB curve."""
    x = np.maximum(image * 2.0**exposure, 0.0)
    x = x / (1.0 + x)
    srgb = np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)
    plt.imsave(path, np.clip(srgb, 0.0, 1.0))


# %% [markdown]
# ## A reference
#
# Progressive photon mapping run four times as long as each integrator below gets (a reference of
# ppm's own favours ppm a little: a long path-traced one is fairer, and slower). Its sums are
# kept in a partial file, so a later run (or `caustica render --partial`) can add passes to it and
# `caustica.merge()` joins them.

# %%
reference_run = caustica.progressive(
    scene, integrator="ppm", time=4 * budget, passes=1_000_000, partial=out / "reference.part", **options
)
for reference in reference_run:
    pass
print(f"reference: {reference_run.passes} ppm passes")
save_png(reference, out / "reference.png")

# %% [markdown]
# ## Error against time
#
# Each integrator runs for the same time; after every pass the running mean is compared with the
# reference: the mean absolute difference over the pixels the reference lights, relative to their
# mean (less swayed by the odd bright pixel of a single pass than an RMS error).

# %%
lit = reference.mean(axis=2) > 1e-3


def relative_error(image: np.ndarray) -> float:
    return float(np.mean(np.abs(image[lit] - reference[lit])) / np.mean(reference[lit]))


curves = {}
for integrator in ["ppm", "gi", "path"]:
    run = caustica.progressive(scene, integrator=integrator, time=budget, passes=1_000_000, seed=1, **options)
    start = time.perf_counter()
    points = []
    for image in run:
        points.append((time.perf_counter() - start, relative_error(image)))
    curves[integrator] = np.array(points)
    save_png(image, out / f"{integrator}.png")
    print(f"{integrator}: {run.passes} passes, error {points[-1][1]:.3f}")

fig, ax = plt.subplots(figsize=(6, 4))
for integrator, points in curves.items():
    ax.loglog(points[:, 0], points[:, 1], marker=".", label=integrator)
ax.set_xlabel("seconds")
ax.set_ylabel("relative mean absolute error")
ax.set_title("glass sphere, 128 pixels wide")
ax.legend()
fig.tight_layout()
fig.savefig(out / "error_vs_time.png", dpi=120)

# %% [markdown]
# ## The caustic photons
#
# The course model's caustic photon map as arrays: where photons landed on the receiver, seen
# face-on — the floor under the ring (the xy plane), the wall behind the lens (the yz plane, at
# x = -7.75) — coloured by their paths: reflected by the ring, refracted by the lens.

# %%
ring = caustica.photons("scenes/ring.ray", photons=20_000)
lens = caustica.photons("scenes/lens.ray", photons=20_000)
on_wall = lens.positions[:, 0] < -7.0
views = [
    ("ring, on the floor", ring.positions[:, [0, 1]], ring.refracted),
    ("lens, on the wall", lens.positions[on_wall][:, [1, 2]], lens.refracted[on_wall]),
]
fig, axes = plt.subplots(1, 2, figsize=(8, 4))
for ax, (title, points, refracted) in zip(axes, views):
    colours = np.where(refracted, "tab:blue", "goldenrod")
    ax.scatter(points[:, 0], points[:, 1], s=0.2, c=colours, linewidths=0)
    ax.set_title(f"{title}: {len(points)} photons")
    ax.set_aspect("equal")
fig.tight_layout()
fig.savefig(out / "photons.png", dpi=120)
print("written to", out)
