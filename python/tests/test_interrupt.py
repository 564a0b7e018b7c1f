"""Ctrl-C stops a render: each case runs in a child Python that gets SIGINT mid-render."""

import signal
import subprocess
import sys
import textwrap
import time

from conftest import REPO

PRELUDE = """
import signal, sys, time
import numpy as np
import caustica
# A child started from a shell in the background may inherit SIGINT ignored.
signal.signal(signal.SIGINT, signal.default_int_handler)
"""


def run_and_interrupt(script: str, after: float = 1.0) -> tuple[str, float]:
    """Runs `script`, sends SIGINT `after` seconds past its first line of output, and returns
    its output and the seconds it took to exit after the signal."""
    child = subprocess.Popen(
        [sys.executable, "-c", textwrap.dedent(PRELUDE) + textwrap.dedent(script)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        cwd=REPO,
    )
    first = child.stdout.readline()
    assert first.strip() == "started", first + child.stderr.read()
    time.sleep(after)
    sent = time.perf_counter()
    child.send_signal(signal.SIGINT)
    out, err = child.communicate(timeout=120)
    return out + err, time.perf_counter() - sent


def test_ctrl_c_stops_a_render():
    # Uninterrupted this takes tens of seconds on two cores.
    output, seconds = run_and_interrupt(
        """
        print("started", flush=True)
        try:
            caustica.render("scenes/ring.ray", width=512, aa=8, photons=100000)
            print("finished")
        except KeyboardInterrupt:
            print("interrupted")
        """
    )
    assert "interrupted" in output and "finished" not in output, output
    assert seconds < 5, f"{seconds:.1f} s from Ctrl-C to exit"


def test_ctrl_c_in_a_progressive_loop_drops_only_the_pass_in_flight():
    output, seconds = run_and_interrupt(
        """
        options = dict(model="physical", width=160, photons=300000, passes=100000)
        run = caustica.progressive("scenes/glass_sphere.ray", **options)
        next(run)
        print("started", flush=True)
        try:
            for image in run:
                pass
        except KeyboardInterrupt:
            done = run.passes
            print("interrupted after", done, "passes", flush=True)
            # The run goes on where it stopped, and its mean is that of the passes done.
            next(run)
            assert run.passes == done + 1
            expected = caustica.render("scenes/glass_sphere.ray", **{**options, "passes": done + 1})
            print("resumed", "equal" if np.array_equal(run.image(), expected) else "different")
        """,
        after=0.3,
    )
    assert "interrupted after" in output and "resumed equal" in output, output
