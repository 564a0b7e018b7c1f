"""Type stubs of caustica's native module (re-exported by the `caustica` package)."""

import os
from collections.abc import Iterator, Sequence
from types import TracebackType
from typing import Any, Literal, TypedDict, Unpack

import numpy as np
import numpy.typing as npt

Image = npt.NDArray[np.float32]
"""A float32 array of shape (height, width, 3): linear RGB, rows from the top."""

PathLike = str | os.PathLike[str]

__version__: str

class RenderOptions(TypedDict, total=False):
    """The options of `caustica render`, `-` written `_`; the defaults are the command line's."""

    model: Literal["course", "physical"] | None
    integrator: Literal["whitted", "path", "ppm", "gi", "lt", "vcm"] | None
    width: int
    height: int | None
    aa: int
    depth: int | None  # bounces after the first surface seen: light from at most depth + 1 surfaces
    threads: int | None
    seed: int
    photons: int
    max_emitted: int | None
    photons_per_light: Sequence[int] | None
    no_aim: bool
    max_memory: int
    k: int
    radius: float | None
    cone_filter: float
    no_estimate_reuse: bool
    passes: int | str | None
    time: float | None
    partial: PathLike | None
    footprint: float | None
    alpha: float
    no_camera_specular: bool
    vertex_connections: bool
    no_beams: bool
    spectral: bool | None
    no_spectral: bool
    cone_quirks: bool
    dialect: Literal["tokenizer", "dictionary", "hkust"] | None

class ProgressiveOptions(RenderOptions, total=False):
    """`render()`'s options and the seconds between writes of the `partial` file."""

    save_every: float

class PhotonOptions(TypedDict, total=False):
    """The options of `caustica photons` that choose the photons."""

    photons: int
    max_emitted: int | None
    photons_per_light: Sequence[int] | None
    no_aim: bool
    max_memory: int
    seed: int
    threads: int | None
    cone_quirks: bool
    dialect: Literal["tokenizer", "dictionary", "hkust"] | None

class SceneError(ValueError):
    """A scene file is malformed; the message starts with file:line:col."""

    path: str
    line: int
    column: int
    reason: str
    help: str | None
    excerpt: str
    """The line around the place (a window of it when it is long) with a caret under it."""

class InternalError(RuntimeError):
    """A bug in caustica (a Rust panic caught before it reached Python)."""

class Scene:
    """A scene file read and built once (`Scene()`: the built-in ring scene)."""

    def __init__(
        self,
        path: PathLike | None = None,
        *,
        cone_quirks: bool = False,
        dialect: Literal["tokenizer", "dictionary", "hkust"] | None = None,
    ) -> None: ...
    @staticmethod
    def from_dict(description: dict[str, Any]) -> Scene:
        """A scene described in memory: `camera`, `materials` by name (images from files or
        numpy arrays), `meshes` by name, `shapes` (meshes from numpy arrays, instances of
        `meshes`, spheres), `lights` and `render` settings, in radiometric units (docs/python.md,
        "Scenes from Python"). A key or value that cannot be used raises ValueError or TypeError
        naming it."""
    def info(self) -> dict[str, Any]:
        """What was read: the same dict as `caustica info --json` prints."""
    @property
    def path(self) -> str:
        """The file as it was named."""
    @property
    def warnings(self) -> list[str]:
        """Remarks made while reading and building."""
    def size(self, width: int = 512, height: int | None = None) -> tuple[int, int]:
        """(width, height) of a render `width` pixels wide."""
    def camera_fit(self, width: int = 512, height: int | None = None) -> str | None:
        """How a render of this size fits the camera when their aspects differ (cropped or
        extended by the format's rule, never stretched); None when they agree."""

SceneLike = Scene | PathLike | None

class Progressive:
    """A progressive render; iterating yields the running mean after each pass."""

    def __iter__(self) -> Iterator[Image]: ...
    def __next__(self) -> Image: ...
    def __enter__(self) -> Progressive: ...
    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        traceback: TracebackType | None,
    ) -> bool: ...
    def cancel(self) -> None:
        """Stops the run (from any thread): the pass in flight is dropped."""
    def image(self) -> Image:
        """The mean of the passes so far."""
    def merge(self, *parts: PathLike) -> None:
        """Adds the sums of partial files of the same run."""
    def save_partial(self, path: PathLike) -> None:
        """Writes the sums of the passes so far, for merge() or `caustica merge`."""
    @property
    def passes(self) -> int:
        """Passes held: rendered here or merged in."""
    @property
    def pass_ranges(self) -> list[tuple[int, int]]:
        """The passes held, as half-open ranges."""
    @property
    def size(self) -> tuple[int, int]:
        """(width, height) of the image."""
    @property
    def integrator(self) -> str:
        """whitted, path, ppm, gi, lt or vcm."""
    @property
    def fingerprint(self) -> str:
        """What must agree for two runs' sums to merge."""
    def report(self) -> dict[str, Any]:
        """The run so far: the fields `caustica render --json` prints but the files and preview."""

class Photons:
    """Stored caustic photons, one row each, in the photon map's order."""

    @property
    def positions(self) -> npt.NDArray[np.float32]:
        """(n, 3): where each photon landed."""
    @property
    def powers(self) -> npt.NDArray[np.float32]:
        """(n, 3): each photon's power, RGB."""
    @property
    def directions(self) -> npt.NDArray[np.float32]:
        """(n, 3): the unit direction each photon travelled (into the surface)."""
    @property
    def reflected(self) -> npt.NDArray[np.bool_]:
        """(n,): the path met a mirror."""
    @property
    def refracted(self) -> npt.NDArray[np.bool_]:
        """(n,): the path went through glass."""
    @property
    def emitted(self) -> int:
        """Photons emitted to store these."""
    @property
    def cap_reached(self) -> bool:
        """Whether a light stopped at the emission cap before storing its share."""
    def __len__(self) -> int: ...

def render(scene: SceneLike = None, **options: Unpack[RenderOptions]) -> Image:
    """Renders a scene: the pixels `caustica render SCENE --… -o image.exr` writes."""

def progressive(scene: SceneLike = None, **options: Unpack[ProgressiveOptions]) -> Progressive:
    """Starts a progressive render; nothing is rendered until it is iterated."""

def merge(parts: Sequence[PathLike], *, partial: PathLike | None = None) -> Image:
    """The image of the merged partial files of one run (`caustica merge`)."""

def photons(scene: SceneLike = None, **options: Unpack[PhotonOptions]) -> Photons:
    """Traces the course model's caustic photons (`caustica photons`)."""

def read_exr(path: PathLike) -> Image:
    """Reads an OpenEXR file as a float32 (height, width, 3) array."""
