"""gtecat's modules compiled once per source where Python writes no bytecode (gtecat._bytecode)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

from gtecat import _bytecode


def test_a_module_is_compiled_once_and_again_when_its_source_changes(tmp_path: Path) -> None:
    cache = tmp_path / "cache"
    old = list(_bytecode._DIR)
    _bytecode._DIR[:] = [cache]
    try:
        src = tmp_path / "mod.py"
        src.write_text("X = 1\n")
        loader = _bytecode._Loader("gtecat_probe", str(src))
        ns: dict = {}
        exec(loader.get_code("gtecat_probe"), ns)
        assert ns["X"] == 1
        (first,) = cache.iterdir()
        ns = {}
        exec(loader.get_code("gtecat_probe"), ns)
        assert ns["X"] == 1 and list(cache.iterdir()) == [first]
        src.write_text("X = 2\n")  # another source: another file, never the old code
        ns = {}
        exec(loader.get_code("gtecat_probe"), ns)
        assert ns["X"] == 2 and len(list(cache.iterdir())) == 2
        for f in cache.iterdir():
            f.write_bytes(b"not marshal data")  # damaged: compiled again
        ns = {}
        exec(loader.get_code("gtecat_probe"), ns)
        assert ns["X"] == 2
    finally:
        _bytecode._DIR[:] = old


def test_only_where_python_writes_no_bytecode(tmp_path: Path) -> None:
    code = "import sys, gtecat.eni.numbers as m; print(type(m.__spec__.loader).__name__)"
    env = {**os.environ, "GTECAT_CACHE_DIR": str(tmp_path)}
    env["PYTHONDONTWRITEBYTECODE"] = "1"
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    assert out.stdout.strip() == "_Loader", out.stderr
    assert any(tmp_path.rglob("gtecat.eni.numbers-*.pyc"))
    env["GTECAT_PYC_CACHE"] = "0"
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    assert out.stdout.strip() == "SourceFileLoader", out.stderr
