"""Manual example 5-5's C++ listing (examples/example_5_5_init.cpp), built with libgts as a user
builds it and run in a folder holding GTS800.cfg: its ``GT_Open(CHANNEL_PCI_ECATCH)`` takes the
header's default param, its ``GT_LoadConfig`` of the controller's own path
(``\\hard disk\\CPAC\\GTS800.cfg``) finds the file by its name."""

from __future__ import annotations

import shutil
import subprocess

import pytest

from .conftest import ROOT, compiled_once, native_env, needs_cxx

pytestmark = [needs_cxx, pytest.mark.xdist_group("c_clients")]


def test_example_5_5_cpp_as_written(libgts, tmp_path_factory, tmp_path):
    exe = compiled_once(tmp_path_factory, libgts, ROOT / "examples" / "example_5_5_init.cpp", "g++")
    shutil.copy(ROOT / "examples" / "GTS800.cfg", tmp_path)
    r = subprocess.run(
        [str(exe)], cwd=tmp_path, env=native_env(), capture_output=True, text=True, timeout=120
    )
    assert r.returncode == 0, r.stdout + r.stderr
    assert r.stdout == "EtherCAT ready, GT_LoadConfig returned 0\n"
