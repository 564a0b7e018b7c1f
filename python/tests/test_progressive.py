"""progressive(): the running mean pass by pass, cancelling, and partial files merged as the
command line merges them."""

import threading
import time

import numpy as np
import pytest

import caustica
from conftest import cli, cli_args

PPM = dict(model="physical", width=32, photons=3000)


def test_each_pass_yields_the_running_mean(scenes):
    scene = caustica.Scene(scenes / "glass_sphere.ray")
    run = caustica.progressive(scene, passes=4, **PPM)
    assert run.size == scene.size(32) and run.integrator == "ppm"
    images = list(run)
    assert len(images) == 4 and run.passes == 4 and run.pass_ranges == [(0, 4)]
    for n, image in enumerate(images, start=1):
        assert np.array_equal(image, caustica.render(scene, passes=n, **PPM)), f"after pass {n}"
    assert np.array_equal(run.image(), images[-1])
    # Iterating a finished run yields nothing more.
    assert list(run) == []


def test_the_course_model_yields_its_one_image(scenes):
    options = dict(width=24, photons=2000)
    images = list(caustica.progressive(scenes / "ring.ray", **options))
    assert len(images) == 1
    assert np.array_equal(images[0], caustica.render(scenes / "ring.ray", **options))


def test_a_time_limit_ends_the_run(scenes):
    start = time.perf_counter()
    images = list(caustica.progressive(scenes / "glass_sphere.ray", time=0.3, **PPM))
    assert len(images) >= 1
    assert time.perf_counter() - start < 10


def test_vcm_fills_a_time_limit_as_the_command_line_does(scenes):
    # The session's rule: vcm's last pass is resized to the time left and ends the run.
    start = time.perf_counter()
    run = caustica.progressive(scenes / "glass_sphere.ray", model="physical", integrator="vcm", width=32, time=0.3)
    images = list(run)
    assert len(images) >= 1 and run.passes == len(images)
    assert np.isfinite(images[-1]).all() and np.array_equal(run.image(), images[-1])
    assert list(run) == []
    assert time.perf_counter() - start < 10


def test_cancel_stops_the_pass_in_flight_and_keeps_the_rest(scenes):
    options = dict(model="physical", width=160, photons=200_000, passes=1000)
    run = caustica.progressive(scenes / "glass_sphere.ray", **options)
    seen = 0
    started = None
    for _ in run:
        seen += 1
        if seen == 2:
            # Cancelled from another thread while the third pass renders.
            threading.Timer(0.05, run.cancel).start()
            started = time.perf_counter()
    stopped = time.perf_counter() - started
    # The third pass, or one after it on a machine faster than 50 ms a pass, was cut short.
    assert seen >= 2 and run.passes == seen
    assert stopped < 5, f"the run took {stopped:.1f} s to stop"
    expected = caustica.render(scenes / "glass_sphere.ray", **{**options, "passes": seen})
    assert np.array_equal(run.image(), expected)
    assert list(run) == []


def test_a_with_block_cancels_the_run(scenes):
    with caustica.progressive(scenes / "glass_sphere.ray", passes=100, **PPM) as run:
        next(run)
    assert list(run) == [] and run.passes == 1


def test_parts_of_a_split_run_merge_as_on_the_command_line(tmp_path, scenes):
    scene = scenes / "glass_sphere.ray"
    first, second = tmp_path / "a.part", tmp_path / "b.part"
    # Passes 0..2 from the command line, 2..4 from Python.
    cli("render", scene, "--quiet", "--passes", "0..2", "--partial", first, *cli_args(PPM))
    run = caustica.progressive(scene, passes="2..4", partial=second, **PPM)
    assert len(list(run)) == 2 and second.is_file()
    whole = caustica.render(scene, passes=4, **PPM)
    assert np.array_equal(caustica.merge([first, second]), whole)
    merged_exr = tmp_path / "merged.exr"
    cli("merge", first, second, "-o", merged_exr, "--quiet")
    assert np.array_equal(caustica.read_exr(merged_exr), whole)
    # A run merges a part into its own sums; the passes the part holds are not rendered again.
    run = caustica.progressive(scene, passes=4, **PPM)
    run.merge(first)
    images = list(run)
    assert len(images) == 2 and run.pass_ranges == [(0, 4)]
    assert np.array_equal(images[-1], whole)
    # The merged sums written by merge(partial=) are a part like any other.
    both = tmp_path / "both.part"
    caustica.merge([second, first], partial=both)
    assert np.array_equal(caustica.merge([both]), whole)


def test_parts_that_do_not_belong_together_are_refused(tmp_path, scenes):
    scene = scenes / "glass_sphere.ray"
    first, other = tmp_path / "a.part", tmp_path / "other.part"
    caustica.render(scene, passes=2, partial=first, **PPM)
    caustica.render(scene, passes="2..3", partial=other, **{**PPM, "seed": 1})
    with pytest.raises(ValueError, match="different runs"):
        caustica.merge([first, other])
    with pytest.raises(ValueError, match="twice"):
        caustica.merge([first, first])
    run = caustica.progressive(scene, passes=2, **PPM)
    with pytest.raises(ValueError, match="different runs"):
        run.merge(other)
    course = caustica.progressive(scene, width=16, photons=0)
    with pytest.raises(ValueError, match="keeps no sums"):
        course.merge(first)


def test_an_interrupted_partial_keeps_the_passes_done(tmp_path, scenes):
    part = tmp_path / "run.part"
    run = caustica.progressive(scenes / "glass_sphere.ray", passes=50, partial=part, **PPM)
    next(run)
    next(run)
    run.cancel()
    assert list(run) == []
    assert np.array_equal(caustica.merge([part]), caustica.render(scenes / "glass_sphere.ray", passes=2, **PPM))


def test_the_report_is_what_the_command_line_prints(scenes, tmp_path):
    """The library's one report: Python's progressive run and `render --json` agree on every
    field but the times and the files written (vcm's balanced count included)."""
    import json

    options = dict(model="physical", integrator="vcm", width=32, passes=2)
    run = caustica.progressive(scenes / "glass_sphere.ray", **options)
    list(run)
    ours = run.report()
    theirs = json.loads(
        cli("render", scenes / "glass_sphere.ray", "-o", tmp_path / "r.png", "--json", *cli_args(options)).stdout
    )
    assert ours["passes"] == 2 and ours["complete"] and ours["photons_per_pass"] > 0
    assert set(ours["seconds"]) == {"parse", "build", "render", "total"}
    for key, value in ours.items():
        if key != "seconds":
            assert theirs[key] == value, key
