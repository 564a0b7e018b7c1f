"""caustica: a photon-mapping renderer for caustics, from Python.

Render a `.ray` scene to a numpy array, watch a progressive render converge pass by pass,
merge the partial sums of runs split across machines, and look at the caustic photon map::

    import caustica

    image = caustica.render("scenes/ring.ray", width=256, aa=2)      # (h, w, 3) float32
    scene = caustica.Scene("scenes/glass_sphere.ray")
    for mean in caustica.progressive(scene, model="physical", passes=32):
        ...
    photons = caustica.photons(scene, photons=50_000)
    photons.positions, photons.reflected

Options are those of ``caustica render`` with ``_`` for ``-`` and give the same pixels as the
command line. Calls release the GIL while they work, and Ctrl-C stops them.
"""

from ._caustica import (
    InternalError,
    Photons,
    Progressive,
    Scene,
    SceneError,
    __version__,
    merge,
    photons,
    progressive,
    read_exr,
    render,
)

__all__ = [
    "InternalError",
    "Photons",
    "Progressive",
    "Scene",
    "SceneError",
    "__version__",
    "merge",
    "photons",
    "progressive",
    "read_exr",
    "render",
]
