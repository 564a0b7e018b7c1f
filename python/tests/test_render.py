"""render() and Scene: the command line's pixels and `info --json`, from Python."""

import json
import threading
import time

import numpy as np
import pytest

import caustica
from conftest import cli, cli_args


def cli_image(tmp_path, scene, options):
    out = tmp_path / "cli.exr"
    scene_args = [] if scene is None else [scene]
    cli("render", *scene_args, "-o", out, "--quiet", *cli_args(options))
    return caustica.read_exr(out)


def test_render_returns_a_linear_float_image(scenes):
    image = caustica.render(scenes / "ring.ray", width=64, height=48, photons=5000)
    assert image.shape == (48, 64, 3)
    assert image.dtype == np.float32
    assert image.flags["C_CONTIGUOUS"]
    # Linear, not clamped to [0, 1] as an 8-bit image would be: the nephroid is brighter than 1.
    assert np.isfinite(image).all() and image.min() >= 0.0 and image.max() > 1.0


COURSE = [
    ("ring.ray", dict(width=48, aa=2, photons=5000, k=50, seed=3)),
    ("lens.ray", dict(width=40, photons=4000, cone_filter=0, no_estimate_reuse=True, depth=3)),
    ("ring_double.ray", dict(width=32, photons_per_light=[1500, 500], radius=0.2, no_aim=True, max_emitted=400000)),
]

PHYSICAL = [
    ("glass_sphere.ray", dict(model="physical", width=40, passes=3, photons=5000)),
    ("glass_sphere.ray", dict(integrator="gi", width=24, passes=2, photons=3000, k=20, alpha=0.5)),
    ("glass_sphere.ray", dict(integrator="path", width=32, passes="1..3", depth=8, no_camera_specular=True)),
    ("ring.ray", dict(integrator="ppm", width=32, passes=2, photons=4000, footprint=3, seed=7)),
    ("glass_sphere.ray", dict(model="physical", width=24, passes=2, photons=3000, spectral=True)),
    ("glass_sphere.ray", dict(integrator="path", width=24, passes=2, spectral=True)),
]


@pytest.mark.parametrize("scene,options", COURSE + PHYSICAL, ids=lambda v: str(v)[:40])
def test_pixels_equal_the_command_lines_exr(tmp_path, scenes, scene, options):
    ours = caustica.render(scenes / scene, **options)
    theirs = cli_image(tmp_path, scenes / scene, options)
    assert ours.shape == theirs.shape
    assert np.array_equal(ours, theirs), f"largest difference {np.abs(ours - theirs).max()}"


def test_spectral_keywords_choose_the_transport_as_the_command_line_does(tmp_path, scenes):
    # The glass ball, made dispersive: spectral by default, RGB with no_spectral or spectral=False.
    text = (scenes / "glass_sphere.ray").read_text()
    assert "index = 1.5;" in text
    path = tmp_path / "dispersive.ray"
    path.write_text(text.replace("index = 1.5;", "index = 1.5; abbe = 30;"))
    options = dict(model="physical", width=24, passes=2, photons=3000)
    default = caustica.render(path, **options)
    assert np.array_equal(default, caustica.render(path, spectral=True, **options))
    assert np.array_equal(default, cli_image(tmp_path, path, options))
    rgb = caustica.render(path, no_spectral=True, **options)
    assert not np.array_equal(rgb, default)
    assert np.array_equal(rgb, caustica.render(path, spectral=False, **options))
    assert np.array_equal(rgb, cli_image(tmp_path, path, {**options, "no_spectral": True}))
    # Without dispersion RGB is the default, and spectral=True changes the image.
    plain = scenes / "glass_sphere.ray"
    assert not np.array_equal(caustica.render(plain, spectral=True, **options), caustica.render(plain, **options))


def test_the_built_in_scene_and_a_loaded_scene_render_as_the_command_line(tmp_path, scenes):
    options = dict(width=32, photons=3000)
    builtin = caustica.render(**options)
    assert np.array_equal(builtin, cli_image(tmp_path, None, options))
    scene = caustica.Scene(scenes / "ring.ray")
    assert np.array_equal(caustica.render(scene, **options), builtin)
    assert np.array_equal(caustica.render(str(scenes / "ring.ray"), **options), builtin)


# A pbrt-v4 file whose Film, Sampler and Integrator set the size, passes, depth and photons.
PBRT = """LookAt 0 1.2 3  0 0.3 0  0 1 0
Camera "perspective" "float fov" [40]
Film "rgb" "integer xresolution" [40] "integer yresolution" [30]
Sampler "independent" "integer pixelsamples" [3]
Integrator "sppm" "integer maxdepth" [5] "integer photonsperiteration" [4000]
WorldBegin
LightSource "point" "point3 from" [0.5 2 0.5] "rgb I" [4 4 4]
Material "diffuse" "rgb reflectance" [0.7 0.7 0.7]
Shape "bilinearmesh" "point3 P" [-2 0 -2  2 0 -2  -2 0 2  2 0 2]
Material "dielectric" "float eta" 1.5
AttributeBegin
  Translate 0 0.4 0
  Shape "sphere" "float radius" [0.35]
AttributeEnd
"""


def gltf_quad_under_a_light(path):
    """A glTF 2.0 file: a floor, a camera, a point light. A `.gltf` path gets one JSON file with
    its buffer as a data URI; a `.glb` path the binary container, the buffer in its BIN chunk."""
    import base64
    import struct

    positions = [-2, 0, -2, 2, 0, -2, 2, 0, 2, -2, 0, 2]
    indices = [0, 2, 1, 0, 3, 2]
    data = struct.pack("<12f", *positions) + struct.pack("<6H", *indices) + b"\0\0"
    gltf = {
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": 20.0}]}},
        "scene": 0,
        "scenes": [{"nodes": [0, 1, 2]}],
        "nodes": [
            {"mesh": 0},
            {"camera": 0, "translation": [0, 1.5, 3], "rotation": [-0.2588190, 0, 0, 0.9659258]},
            {"translation": [0, 1.5, 0], "extensions": {"KHR_lights_punctual": {"light": 0}}},
        ],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "aspectRatio": 1.5, "znear": 0.01}}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "material": 0}]}],
        "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.8, 0.8, 1], "metallicFactor": 0}}],
        "buffers": [{"byteLength": len(data), "uri": "data:application/octet-stream;base64," + base64.b64encode(data).decode()}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 48},
            {"buffer": 0, "byteOffset": 48, "byteLength": 12},
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-2, 0, -2], "max": [2, 0, 2]},
            {"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"},
        ],
    }
    if path.suffix == ".glb":
        del gltf["buffers"][0]["uri"]
        text = json.dumps(gltf).encode()
        text += b" " * (-len(text) % 4)
        chunks = struct.pack("<II", len(text), 0x4E4F534A) + text + struct.pack("<II", len(data), 0x004E4942) + data
        path.write_bytes(struct.pack("<III", 0x46546C67, 2, 12 + len(chunks)) + chunks)
    else:
        path.write_text(json.dumps(gltf))
    return path


@pytest.mark.parametrize(
    "options",
    [dict(), dict(width=24), dict(passes=2, photons=2000), dict(model="course", photons=2000), dict(depth=2)],
    ids=str,
)
def test_a_pbrt_file_renders_as_the_command_line_with_its_own_settings(tmp_path, options):
    """The file's Film, Sampler and Integrator fill what the options leave, as on the command line."""
    path = tmp_path / "ball.pbrt"
    path.write_text(PBRT)
    ours = caustica.render(path, **options)
    theirs = cli_image(tmp_path, path, options)
    assert ours.shape == theirs.shape
    if "width" not in options:
        assert ours.shape == (30, 40, 3), "the Film's resolution"
    assert np.array_equal(ours, theirs), f"largest difference {np.abs(ours - theirs).max()}"


@pytest.mark.parametrize("suffix", [".gltf", ".glb"])
@pytest.mark.parametrize("options", [dict(width=32, passes=2), dict(width=32, model="course")], ids=str)
def test_a_gltf_file_renders_as_the_command_line(tmp_path, options, suffix):
    """glTF is in physical units: both front ends read it with the physical model by default."""
    path = gltf_quad_under_a_light(tmp_path / ("floor" + suffix))
    ours = caustica.render(path, **options)
    theirs = cli_image(tmp_path, path, options)
    assert ours.shape == theirs.shape
    assert ours.max() > 0.0, "the floor is lit"
    assert np.array_equal(ours, theirs), f"largest difference {np.abs(ours - theirs).max()}"
    if suffix == ".glb":
        # The two containers of one model render the same.
        other = gltf_quad_under_a_light(tmp_path / "floor.gltf")
        assert np.array_equal(ours, caustica.render(other, **options))


def test_a_square_image_of_a_wide_camera_is_cropped_and_said_so(tmp_path):
    """An image of another aspect than the camera's is cropped by the format's rule, not
    stretched; Python says so as the command line's --json does, and renders its pixels."""
    path = gltf_quad_under_a_light(tmp_path / "floor.gltf")
    scene = caustica.Scene(path)
    note = scene.camera_fit(32, 32)
    assert note is not None and "cropped at the sides" in note
    assert scene.camera_fit(48, 32) is None, "the camera's own 3:2"
    options = dict(width=32, height=32, passes=1)
    report = json.loads(cli("render", path, "-o", tmp_path / "fit.png", "--json", *cli_args(options)).stdout)
    assert report["camera_fit"] == note
    assert np.array_equal(caustica.render(scene, **options), cli_image(tmp_path, path, options))


def test_the_thread_count_does_not_change_the_image(scenes):
    options = dict(width=32, model="physical", passes=2, photons=3000)
    one = caustica.render(scenes / "glass_sphere.ray", threads=1, **options)
    two = caustica.render(scenes / "glass_sphere.ray", threads=2, **options)
    assert np.array_equal(one, two)


def test_info_is_the_command_lines_json(scenes):
    for name in ["ring.ray", "glass_sphere.ray", "pool.ray", "magnifier_sun.ray"]:
        path = str(scenes / name)
        ours = caustica.Scene(path).info()
        theirs = json.loads(cli("info", path, "--json").stdout)
        # Only the seconds spent loading differ between two loads.
        assert ours.pop("seconds").keys() == theirs.pop("seconds").keys() == {"parse", "build"}
        assert ours == theirs
        assert ours["scene"] == path


def test_scene_size_follows_the_camera(scenes):
    scene = caustica.Scene(scenes / "ring.ray")
    assert scene.size(64) == caustica.render(scene, width=64, photons=0).shape[1::-1]
    assert scene.size(64, 10) == (64, 10)
    assert scene.path == str(scenes / "ring.ray")


def test_the_gil_is_released_while_rendering(scenes):
    """Another Python thread keeps running during a render of about a second."""
    started, done = threading.Event(), threading.Event()

    def work():
        started.set()
        caustica.render(scenes / "ring.ray", width=256, aa=3, photons=50000)
        done.set()

    thread = threading.Thread(target=work)
    thread.start()
    started.wait()
    # Steps this thread takes while the render runs: with the GIL held, none (one at most, before
    # the render begins); released, one every few milliseconds.
    steps = 0
    while not done.is_set():
        time.sleep(0.002)
        steps += 1
    thread.join()
    assert steps >= 20, f"the main thread ran only {steps} times during the render"
