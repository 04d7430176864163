"""numpy's OpenBLAS thread count when gtecat is imported first (``gtecat._one_blas_thread``)."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

_PROBE = (
    "import os, sys\n"
    "{first}\n"
    "import gtecat\n"
    "print(os.environ.get('OPENBLAS_NUM_THREADS', '-'))\n"
)


def _blas_threads_after_import(env_extra: dict[str, str], first: str = "") -> str:
    env = {k: v for k, v in os.environ.items()
           if k not in ("OPENBLAS_NUM_THREADS", "GOTO_NUM_THREADS", "OMP_NUM_THREADS")}
    env.update(env_extra)
    out = subprocess.run([sys.executable, "-c", _PROBE.format(first=first)], env=env,
                         capture_output=True, text=True, timeout=60, check=True)
    return out.stdout.strip()


def test_one_thread_when_nothing_chose_a_count() -> None:
    assert _blas_threads_after_import({}) == "1"


@pytest.mark.parametrize("name", ["OPENBLAS_NUM_THREADS", "GOTO_NUM_THREADS", "OMP_NUM_THREADS"])
def test_a_count_the_process_chose_is_kept(name: str) -> None:
    want = "3" if name == "OPENBLAS_NUM_THREADS" else "-"
    assert _blas_threads_after_import({name: "3"}) == want


def test_numpy_loaded_before_is_left_as_it_started() -> None:
    assert _blas_threads_after_import({}, first="import numpy") == "-"
