"""Shared pieces of the native tests: compilers (a missing one is a skip with its reason)."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from gtecat.native import header

needs_cc = pytest.mark.skipif(
    shutil.which("gcc") is None, reason="no C compiler (gcc) on PATH: the C tests cannot run"
)
needs_cxx = pytest.mark.skipif(
    shutil.which("g++") is None, reason="no C++ compiler (g++) on PATH: the C++ tests cannot run"
)


@pytest.fixture
def gts_h(tmp_path: Path) -> Path:
    """A freshly generated gts.h in a directory of its own."""
    d = tmp_path / "include"
    d.mkdir()
    path = d / "gts.h"
    path.write_text(header.render(), encoding="utf-8")
    return path
