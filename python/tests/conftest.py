"""Shared helpers: the repository's scenes and the `caustica` command line to compare with."""

import os
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
SCENES = REPO / "scenes"


def cli_binary() -> Path:
    """The command line built from this checkout (CAUSTICA_BIN overrides)."""
    binary = Path(os.environ.get("CAUSTICA_BIN", REPO / "target" / "release" / "caustica"))
    if not binary.is_file():
        pytest.fail(
            f"these tests compare with the command line, not found at {binary}: "
            "run `cargo build --release` first or set CAUSTICA_BIN"
        )
    return binary


def cli_args(options: dict) -> list[str]:
    """`render()` keywords as the command line's options."""
    args = []
    for key, value in options.items():
        flag = "--" + key.replace("_", "-")
        if value is True:
            args.append(flag)
        elif isinstance(value, (list, tuple)):
            args += [flag, ",".join(str(v) for v in value)]
        elif value is not None and value is not False:
            args += [flag, str(value)]
    return args


def cli(*args, check=True) -> subprocess.CompletedProcess:
    """Runs the command line quietly; fails the test with its stderr when it fails."""
    result = subprocess.run(
        [str(cli_binary()), *map(str, args)], capture_output=True, text=True, timeout=300
    )
    if check and result.returncode != 0:
        pytest.fail(f"caustica {' '.join(map(str, args))} failed:\n{result.stderr}")
    return result


@pytest.fixture
def scenes() -> Path:
    return SCENES
