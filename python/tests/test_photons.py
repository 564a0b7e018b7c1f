"""photons(): the caustic photon map as arrays, the very photons `caustica photons --ply` writes."""

import numpy as np

import caustica
from conftest import cli


def read_ply(path):
    """The binary PLY of `caustica photons --ply`: position, colour, power, flags."""
    data = path.read_bytes()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    count = int(next(line for line in data[:end].decode().splitlines() if line.startswith("element vertex")).split()[2])
    record = np.dtype(
        [("position", "<f4", 3), ("colour", "u1", 3), ("power", "<f4", 3), ("flags", "u1")]
    )
    return np.frombuffer(data, dtype=record, count=count, offset=end)


def test_the_arrays_are_the_command_lines_photons(tmp_path, scenes):
    for scene, options in [
        ("ring.ray", dict(photons=3000, seed=4)),
        ("lens.ray", dict(photons=2000, no_aim=True, max_emitted=2_000_000)),
    ]:
        ours = caustica.photons(scenes / scene, **options)
        ply = tmp_path / "photons.ply"
        args = []
        for key, value in options.items():
            args += [f"--{key.replace('_', '-')}"] + ([] if value is True else [str(value)])
        cli("photons", scenes / scene, "-o", tmp_path / "map.png", "--ply", ply, "--quiet", *args)
        theirs = read_ply(ply)
        assert len(ours) == len(theirs) > 0
        assert np.array_equal(ours.positions, theirs["position"])
        assert np.array_equal(ours.powers, theirs["power"])
        assert np.array_equal(ours.reflected, theirs["flags"] & 1 != 0)
        assert np.array_equal(ours.refracted, theirs["flags"] & 2 != 0)


def test_shapes_types_and_paths(scenes):
    ring = caustica.photons(scenes / "ring.ray", photons=2000)
    n = len(ring)
    assert n >= 2000 and ring.emitted > n
    for array in (ring.positions, ring.powers, ring.directions):
        assert array.shape == (n, 3) and array.dtype == np.float32
    assert ring.reflected.dtype == np.bool_ and ring.reflected.shape == (n,)
    assert np.allclose(np.linalg.norm(ring.directions, axis=1), 1.0, atol=1e-4)
    # The ring is metal: its caustic photons are reflected, none refracted. Reflected off the
    # ring's inside, they come down, nearly all onto the floor (at z = 0; the rest on the ring).
    assert ring.reflected.all() and not ring.refracted.any()
    assert (ring.directions[:, 2] < 0).all()
    assert (np.abs(ring.positions[:, 2]) < 1e-3).mean() > 0.9
    lens = caustica.photons(scenes / "lens.ray", photons=2000)
    assert lens.refracted.all()


def test_no_photons_gives_empty_arrays(scenes):
    none = caustica.photons(scenes / "ring.ray", photons=0)
    assert len(none) == 0 and none.positions.shape == (0, 3)
