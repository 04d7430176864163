"""numpy's OpenBLAS threads when the emulator is imported first
(``gtecat.numpy_with_one_blas_thread``): one thread, the environment left as it was."""

from __future__ import annotations

import functools
import json
import os
import subprocess
import sys

import pytest

_NAMES = ("OPENBLAS_NUM_THREADS", "GOTO_NUM_THREADS", "OMP_NUM_THREADS")

#: (the environment's count after the code ran, the process's threads: 1 + OpenBLAS's extra)
_PROBE = (
    "import json, os\n"
    "{code}\n"
    "count = os.environ.get('OPENBLAS_NUM_THREADS')\n"
    "print(json.dumps([count, len(os.listdir('/proc/self/task'))]))\n"
)


def _after(code: str, **env_extra: str) -> tuple[str | None, int]:
    env = {k: v for k, v in os.environ.items() if k not in _NAMES}
    env.update(env_extra)
    out = subprocess.run(
        [sys.executable, "-c", _PROBE.format(code=code)],
        env=env,
        capture_output=True,
        text=True,
        timeout=60,
        check=True,
    )
    count, threads = json.loads(out.stdout)
    return count, threads


needs_proc = pytest.mark.skipif(
    not os.path.isdir("/proc/self/task"), reason="threads counted in /proc (Linux only)"
)


#: what gtecat.gt's import does first, alone (a process without the GT layer's import)
_ONE_THREAD = "import gtecat; gtecat.numpy_with_one_blas_thread(); import numpy"


@functools.cache
def _threads_of_plain_numpy(**env_extra: str) -> int:
    """The threads of a process that imports numpy alone (with ``env_extra``)."""
    return _after("import numpy", **env_extra)[1]


@needs_proc
def test_the_emulator_starts_numpy_with_one_thread_and_leaves_the_environment() -> None:
    assert _after("from gtecat import gt") == (None, 1)


@needs_proc
def test_import_gtecat_alone_does_not_touch_numpy() -> None:
    """The pytest plugin and a command's help import ``gtecat`` only: a program's numpy
    then starts as it would without gtecat."""
    code = "import gtecat, sys; assert 'numpy' not in sys.modules; import numpy"
    assert _after(code) == (None, _threads_of_plain_numpy())


@needs_proc
@pytest.mark.parametrize("name", ["OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS"])
@pytest.mark.sample(1)
def test_a_count_the_process_chose_is_kept(name: str) -> None:
    """(``GOTO_NUM_THREADS`` is looked at the same way: one of the three names.  The default
    run takes one of the two names, two processes each: GTECAT_LONG=1 runs both.)"""
    count, threads = _after(_ONE_THREAD, **{name: "2"})
    assert count == ("2" if name == "OPENBLAS_NUM_THREADS" else None)
    assert threads == _threads_of_plain_numpy(**{name: "2"})


@needs_proc
def test_numpy_loaded_before_is_left_as_it_started() -> None:
    assert _after(f"import numpy; {_ONE_THREAD}") == (None, _threads_of_plain_numpy())
