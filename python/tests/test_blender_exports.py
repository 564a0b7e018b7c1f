"""What Blender's own glTF exporter writes, from `scripts/scenes/blender_export.py` run
headless: the one-file (GLB) and separate forms read and render alike, and the lamp and each
material read as Blender means them. Skipped without `blender` on the PATH."""
import math
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

import caustica

BLENDER = shutil.which("blender")
ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.skipif(BLENDER is None, reason="blender is not on the PATH")
def test_blender_exports_read_as_blender_means_them(tmp_path):
    # No Cycles render (0 samples): the export alone.
    done = subprocess.run(
        [BLENDER, "-b", "--factory-startup", "--python-exit-code", "1", "-P",
         str(ROOT / "scripts" / "scenes" / "blender_export.py"), "--", str(tmp_path), "0"],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    glb = caustica.Scene(str(tmp_path / "scene.glb"))
    separate = caustica.Scene(str(tmp_path / "separate" / "scene.gltf"))
    for scene in [glb, separate]:
        # The one warning: Blender writes glass without a volume, read as solid (the ball is closed).
        assert all("read as solid glass" in w for w in scene.warnings), scene.warnings
        info = scene.info()
        # Blender's 1000 W point light: 1000/(4π) W/sr, as Cycles emits it.
        (lamp,) = info["lights"]
        assert lamp["type"] == "point"
        assert lamp["color"] == pytest.approx([1000.0 / (4.0 * math.pi)] * 3, rel=1e-3)
        materials = info["materials"]
        # Specular 0 in Blender: a bare Lambert floor, no coat (a coat would show as `specular`).
        assert any(m["diffuse"] == [0.5] * 3 and m["specular"] == [0.0] * 3 for m in materials), materials
        # The checker: a texture on the base colour, no coat either.
        assert any(isinstance(m["diffuse"], dict) and m["specular"] == [0.0] * 3 for m in materials), materials
        # Copper: its reflectance, with the gloss of GGX α = 0.3² (Phong exponent 2/α² − 2).
        assert any(
            m["specular"] == pytest.approx([0.95, 0.64, 0.54]) and m["shininess"][0] == pytest.approx(2 / 0.0081 - 2, rel=1e-4)
            for m in materials
        ), materials
        # Glass: clear, index 1.5.
        assert any(m["transmissive"] == [1.0] * 3 and m["index"] == [1.5] * 3 for m in materials), materials
    # The two forms make the same picture.
    options = dict(integrator="vcm", width=24, height=24, passes=2, seed=1, photons=5000)
    a, b = caustica.render(glb, **options), caustica.render(separate, **options)
    np.testing.assert_array_equal(a, b)
    assert a.max() > 0
