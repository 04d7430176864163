"""The functions gtecat writes at run time, kept compiled in one store (gtecat._code_store)."""

from __future__ import annotations

import marshal
import sys
from pathlib import Path

import pytest

from gtecat import _bytecode, _code_store


def _fresh_store(tmp_path: Path, monkeypatch) -> None:
    """The store of run-time functions in ``tmp_path``, nothing read or compiled yet."""
    monkeypatch.setattr(_bytecode, "_DC_FILE", [tmp_path / "dataclass-store"])
    monkeypatch.setattr(_code_store, "_INDEX", {})
    monkeypatch.setattr(_code_store, "_NEW", {})
    monkeypatch.setattr(_code_store, "_DATA", [0, None])
    monkeypatch.setattr(_code_store, "_USED", set())
    monkeypatch.setattr(_code_store, "_FILE", [])


def _new_process() -> None:
    """What a new process starts with (the store on disk as the last one left it)."""
    _code_store._INDEX.clear()
    _code_store._USED.clear()
    _code_store._FILE.clear()
    _code_store._DATA[:] = [0, None]


@pytest.mark.parametrize("pread", [True, False], ids=["pread", "whole"])
def test_functions_written_at_run_time_kept_compiled(tmp_path: Path, monkeypatch, pread) -> None:
    """A function gtecat writes at run time is compiled as its module would (annotations as
    text), kept in one store with the others (added to it at exit, its index read in one go,
    each code when asked for - or the whole file where the platform cannot read at an
    offset), and compiled again from a damaged store or entry."""
    _fresh_store(tmp_path, monkeypatch)
    if not pread or not _code_store._PREAD:
        monkeypatch.setattr(_code_store, "_PREAD", False)
    source = "def f(x: int) -> int:\n    return x + 1\n"
    ns: dict = {}
    exec(_code_store.compiled(source, "<probe>"), ns)
    assert ns["f"](1) == 2 and ns["f"].__annotations__ == {"x": "int", "return": "int"}
    (store,) = _code_store._FILE
    assert not store.exists() and len(_code_store._NEW) == 1
    exec(_code_store.compiled("def g():\n    return 5\n", "<probe g>"), ns)
    _code_store._save()  # (at exit)
    assert store.exists() and not _code_store._NEW
    kept = store.read_bytes()
    _new_process()
    again = _code_store.compiled(source, "<probe>")
    assert again.co_filename == "<probe>" and not _code_store._NEW  # read back, not compiled
    exec(again, ns)
    assert ns["f"](2) == 3 and len(_code_store._INDEX) == 2
    assert _code_store.compiled(source, "<probe 2>").co_filename == "<probe 2>"  # (another file)
    _code_store._NEW.clear()
    _code_store._save()  # nothing new: the store is left as it is
    assert store.read_bytes() == kept
    # a damaged entry is compiled again
    index, codes = _code_store._read(store)
    assert len(index) == 2 and len(codes) > 100
    store.write_bytes(kept[: -len(codes)] + b"\0" * len(codes))
    _new_process()
    exec(_code_store.compiled(source, "<probe>"), ns)
    assert ns["f"](3) == 4 and len(_code_store._NEW) == 1
    _code_store._NEW.clear()
    # a store cut short: the function whose bytes it lost compiled again, the other read
    store.write_bytes(kept[:-5])
    _new_process()
    _code_store.compiled(source, "<probe>")
    assert not _code_store._NEW
    _code_store.compiled("def g():\n    return 5\n", "<probe g>")
    assert len(_code_store._NEW) == 1
    _code_store._NEW.clear()
    # a damaged store: every function compiled again, the store written anew at exit
    huge = _code_store._MAGIC + (1 << 62).to_bytes(8, "little")
    index, _ = _code_store._read(store)
    foreign = {k: v for k, v in zip(index, [(0, 1 << 90), ("a", 1)], strict=True)}
    head = marshal.dumps(foreign)
    foreign_index = _code_store._MAGIC + len(head).to_bytes(8, "little") + head
    for damaged in (b"damaged", kept[:40], b"", huge, foreign_index):
        store.write_bytes(damaged)
        _new_process()
        exec(_code_store.compiled(source, "<probe>"), ns)
        assert ns["f"](4) == 5 and len(_code_store._NEW) == 1
        _code_store._save()
        _new_process()
        _code_store._load(store)
        assert len(_code_store._INDEX) == 1


def test_the_store_of_run_time_functions_keeps_what_is_used_once_it_is_full(
    tmp_path: Path, monkeypatch
) -> None:
    """Another process's functions already in the store are kept (read again at exit); past
    the store's size, only what this process found there or compiled is kept."""
    _fresh_store(tmp_path, monkeypatch)

    def process(*names: str) -> None:  # a process compiling these functions, then its exit
        _new_process()
        for n in names:
            _code_store.compiled(f"def {n}():\n    return {n!r}\n", f"<{n}>")
        _code_store._save()

    def kept() -> set[str]:
        index, data = _code_store._read(_bytecode._DC_FILE[0].parent / _GEN_NAME)
        return {marshal.loads(data[a:b]).co_filename for a, b in index.values()}

    process("a", "b")
    process("c")  # another process: its function added, the others stay
    assert kept() == {"<a>", "<b>", "<c>"}
    monkeypatch.setattr(_code_store, "_MOST", 1)  # (full)
    process("b", "d")
    assert kept() == {"<b>", "<d>"}


_GEN_NAME = f"gen-{sys.implementation.cache_tag}"


def test_a_process_keeps_its_functions_for_the_next(tmp_path: Path) -> None:
    """Written at a process's exit, read back by the next process; with the caches off,
    compiled every time and nothing kept."""
    import os
    import subprocess

    code = (
        "from gtecat import _code_store as s\n"
        "ns = {}\n"
        "exec(s.compiled('def f():\\n    return 7\\n', '<probe>'), ns)\n"
        "print(ns['f'](), len(s._NEW))\n"
    )
    env = {**os.environ, "GTECAT_CACHE_DIR": str(tmp_path)}
    env.pop("GTECAT_PYC_CACHE", None)
    runs = [
        subprocess.run(
            [sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True
        ).stdout.split()
        for _ in range(2)
    ]
    assert runs == [["7", "1"], ["7", "0"]], runs
    assert len(list(tmp_path.rglob(_GEN_NAME))) == 1
    env["GTECAT_PYC_CACHE"] = "0"
    off = subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True
    )
    assert off.stdout.split() == ["7", "0"], off.stderr
