"""Bad input raises Python exceptions with the command line's messages; panics do not escape."""

import numpy as np
import pytest

import caustica

BAD_SYNTAX = """SBT-raytracer 1.0
sphere {
  material = { diffuse = (1, 0, 0); }
  bogus = 3;
}
"""


def test_a_missing_file_is_file_not_found(tmp_path):
    missing = tmp_path / "missing.ray"
    with pytest.raises(FileNotFoundError) as info:
        caustica.render(missing)
    assert info.value.filename == str(missing)
    with pytest.raises(FileNotFoundError):
        caustica.Scene(missing)


def test_a_malformed_scene_names_file_line_and_column(tmp_path):
    path = tmp_path / "bad.ray"
    path.write_text(BAD_SYNTAX)
    for call in (lambda: caustica.Scene(path), lambda: caustica.render(path), lambda: caustica.photons(path)):
        with pytest.raises(caustica.SceneError) as info:
            call()
        error = info.value
        assert str(error).startswith(f"{path}:4:3: ")
        assert (error.path, error.line, error.column) == (str(path), 4, 3)
        assert "bogus" in error.reason
        assert isinstance(error, ValueError)


def test_errors_found_while_building_point_into_the_file(tmp_path):
    (tmp_path / "broken.png").write_bytes(b"not an image")
    path = tmp_path / "texture.ray"
    path.write_text('SBT-raytracer 1.0\n\nsphere { material = { diffuse = map("broken.png"); } }\n')
    with pytest.raises(caustica.SceneError) as info:
        caustica.Scene(path)
    assert str(info.value).startswith(f"{path}:3:")
    assert "broken.png" in str(info.value)


def test_a_missing_image_is_a_warning_and_the_scene_loads(tmp_path):
    path = tmp_path / "texture.ray"
    path.write_text('SBT-raytracer 1.0\n\nsphere { material = { diffuse = map("nowhere.png"); } }\n')
    scene = caustica.Scene(path)
    assert any("nowhere.png` is missing: the texture reads mid grey" in w for w in scene.warnings), scene.warnings


def test_a_misspelt_keyword_gets_help(tmp_path):
    path = tmp_path / "typo.ray"
    path.write_text("SBT-raytracer 1.0\nspher { }\n")
    with pytest.raises(caustica.SceneError) as info:
        caustica.Scene(path)
    assert info.value.line == 2
    assert info.value.help is not None and "sphere" in info.value.help


@pytest.mark.parametrize(
    "options,error,words",
    [
        (dict(wdth=64), TypeError, "unexpected keyword argument 'wdth'"),
        (dict(output="x.png"), TypeError, "returned as an array"),
        (dict(width="64"), TypeError, "width must be a whole number"),
        (dict(width=True), TypeError, "width must be a whole number"),
        (dict(no_aim=1), TypeError, "no_aim must be True or False"),
        (dict(radius="big"), TypeError, "radius must be a number"),
        (dict(photons_per_light="10,20"), TypeError, "list of whole numbers"),
        (dict(width=-5), ValueError, "out of range"),
        (dict(width=0), ValueError, "at least 1 pixel"),
        (dict(width=100_000), ValueError, "too large"),
        (dict(cone_filter=0.5), ValueError, "cone_filter must be 0 (off) or at least 1"),
        (dict(model="photon"), ValueError, "unknown model `photon`"),
        (dict(model="course", integrator="ppm"), ValueError, "renders the physical model"),
        (dict(passes=8), ValueError, "belong to the physical model"),
        (dict(model="physical", passes="5..3"), ValueError, "5..3"),
        (dict(model="physical", alpha=1.5), ValueError, "alpha must lie strictly between 0 and 1"),
        (dict(photons=10**9), ValueError, "max_memory"),
        (dict(threads=0), ValueError, "threads must be between 1 and 1024"),
        (dict(dialect="klingon"), ValueError, "unknown dialect"),
        (dict(spectral="yes"), TypeError, "spectral must be True or False"),
        (dict(model="physical", spectral=True, no_spectral=True), ValueError, "contradict"),
    ],
    ids=lambda v: str(v)[:30],
)
def test_bad_options_are_refused_before_any_work(scenes, options, error, words):
    with pytest.raises(error) as info:
        caustica.render(scenes / "ring.ray", **options)
    assert words in str(info.value)


def test_load_options_go_to_the_scene_not_beside_it(scenes):
    scene = caustica.Scene(scenes / "ring.ray")
    with pytest.raises(ValueError, match="give them to caustica.Scene"):
        caustica.render(scene, cone_quirks=True)


def test_a_panic_comes_back_as_an_exception_and_the_module_goes_on(scenes):
    with pytest.raises(caustica.InternalError, match="deliberate panic"):
        caustica._caustica._panic_on_worker()
    assert isinstance(caustica.InternalError("x"), RuntimeError)
    assert caustica.render(scenes / "ring.ray", width=8, photons=0).shape == (8, 8, 3)


def test_a_damaged_partial_file_is_refused(tmp_path):
    part = tmp_path / "bad.part"
    part.write_bytes(b"caustica-partial 1\nwidth 2\nheight 2\nfingerprint x\npasses 0..1\n\n" + b"\0" * 10)
    with pytest.raises(OSError, match="truncated or damaged"):
        caustica.merge([part])
    with pytest.raises(ValueError, match="no partial files"):
        caustica.merge([])
    assert not np.any([p.name.endswith(".tmp") for p in tmp_path.iterdir()])


def test_an_error_far_along_one_long_line_shows_a_window_of_it(tmp_path):
    # A glTF written on one line, cut short 200,000 characters in: its error lies past any
    # column a report could pad to, and the excerpt must be a window, not the whole line.
    body = '{"asset":{"version":"2.0","extras":{"note":"' + "x" * 200_000 + '"}},"scenes":[{"nodes":[0'
    path = tmp_path / "cut.gltf"
    path.write_text(body)
    with pytest.raises(caustica.SceneError) as info:
        caustica.Scene(path)
    error = info.value
    assert error.line == 1 and error.column > 200_000
    assert str(error).startswith(f"{path}:1:{error.column}: ")
    lines = error.excerpt.splitlines()
    assert len(lines) == 3 and all(len(line) < 200 for line in lines)
    assert "…" in lines[1] and "^" in lines[2]
    assert len(str(error)) < 1000
