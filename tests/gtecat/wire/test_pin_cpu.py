"""``gtecat serve --cpu N``: the server runs on one CPU, a bad number is a clear error."""

import os
import subprocess
import sys

import pytest

from gtecat.wire.serve import WireError, pin_to_cpu


def test_pin_to_cpu_sets_the_affinity_in_a_child() -> None:
    cpu = max(os.sched_getaffinity(0))
    code = (
        "import os; from gtecat.wire.serve import pin_to_cpu; "
        f"pin_to_cpu({cpu}); print(sorted(os.sched_getaffinity(0)))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == f"[{cpu}]"


def test_a_cpu_that_does_not_exist_is_a_wire_error() -> None:
    with pytest.raises(WireError, match="cannot run on CPU 4096"):
        pin_to_cpu(4096)


def test_serve_with_a_bad_cpu_says_why_without_a_traceback() -> None:
    out = subprocess.run(
        [
            sys.executable,
            "-m",
            "gtecat",
            "serve",
            "--iface",
            "lo",
            "--cpu",
            "4096",
            "--eni",
            "examples/manual_fig5_2.eni",
            "--duration",
            "0.1",
        ],
        capture_output=True,
        text=True,
        timeout=60,
        cwd=os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(__file__)))),
    )
    assert out.returncode != 0
    assert "cannot run on CPU 4096" in out.stderr
    assert "Traceback" not in out.stderr
