"""Manual example 5-5's C++ listing (examples/example_5_5_init.cpp), built with libgts as a user
builds it and run in a folder holding GTS800.cfg: its ``GT_Open(CHANNEL_PCI_ECATCH)`` takes the
header's default param, its ``GT_LoadConfig`` of the controller's own path
(``\\\\hard disk\\\\CPAC\\\\GTS800.cfg``) finds the file by its name.  By default the listing is
only compiled against ``gts.h`` (the Python twin, tests/gtecat/test_examples_ch5.py, runs the
same calls); ``GTECAT_LONG=1`` also links and runs it (a controller process of its own)."""

from __future__ import annotations

import os
import shutil
import subprocess

import pytest

from .conftest import ROOT, compiled_once, native_env, needs_cxx

pytestmark = [needs_cxx, pytest.mark.xdist_group("c_clients")]
SRC = ROOT / "examples" / "example_5_5_init.cpp"


def test_example_5_5_cpp_compiles_as_written(libgts):
    cmd = ["g++", "-fsyntax-only", "-Wall", *libgts.cflags(), str(SRC)]  # unused argc: -Wextra
    r = subprocess.run(cmd, capture_output=True, text=True)
    assert r.returncode == 0 and "warning" not in r.stderr, r.stderr


@pytest.mark.skipif(os.environ.get("GTECAT_LONG") != "1", reason="GTECAT_LONG=1 runs it")
def test_example_5_5_cpp_runs(libgts, tmp_path_factory, tmp_path):
    exe = compiled_once(tmp_path_factory, libgts, SRC, "g++")
    shutil.copy(ROOT / "examples" / "GTS800.cfg", tmp_path)
    r = subprocess.run(
        [str(exe)], cwd=tmp_path, env=native_env(), capture_output=True, text=True, timeout=120
    )
    assert r.returncode == 0, r.stdout + r.stderr
    assert r.stdout == "EtherCAT ready, GT_LoadConfig returned 0\n"
