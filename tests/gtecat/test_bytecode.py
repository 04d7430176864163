"""gtecat's modules compiled once per source where Python writes no bytecode (gtecat._bytecode)."""

from __future__ import annotations

import marshal
import os
import subprocess
import sys
from pathlib import Path

import pytest

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


def test_dataclass_methods_kept_compiled(tmp_path: Path, monkeypatch) -> None:
    """The methods @dataclass writes for a class of gtecat's are compiled once and read back;
    the class behaves as one compiled afresh; a class of another module is left alone."""
    import dataclasses
    import types

    if not _bytecode._DC_FILE:  # (GTECAT_PYC_CACHE=0 in this process)
        _bytecode.install_dataclass_cache("test")
    store = tmp_path / "dataclass-store"
    monkeypatch.setattr(_bytecode, "_DC_FILE", [store, store])
    monkeypatch.setattr(_bytecode, "_DC_CODES", {})
    monkeypatch.setattr(_bytecode, "_DC_NEW", {})
    source = (
        "from dataclasses import dataclass\n"
        "@dataclass(frozen=True, slots=True)\n"
        "class P:\n    a: int\n    b: str = 'x'\n"
    )

    def define(name: str) -> type:
        mod = types.ModuleType(name)
        monkeypatch.setitem(sys.modules, name, mod)
        exec(source, vars(mod))
        return vars(mod)["P"]

    def check(cls: type) -> None:
        # as exec compiles it in the dataclasses module: annotations are objects, not text
        assert cls.__init__.__annotations__["return"] is None
        p = cls(1)
        assert repr(p).endswith("P(a=1, b='x')") and p == cls(1, "x") and p != cls(2)
        try:
            p.a = 3  # type: ignore[misc]
        except dataclasses.FrozenInstanceError:
            pass
        else:
            raise AssertionError("a frozen class took an assignment")

    assert vars(dataclasses)["exec"] is _bytecode._dc_exec
    check(define("elsewhere_probe"))
    assert not _bytecode._DC_NEW  # another module's class: compiled as always
    check(define("gtecat._probe_dc"))
    made = dict(_bytecode._DC_NEW)
    assert made
    _bytecode._dc_save()
    _bytecode._DC_CODES.clear()
    _bytecode._dc_load()  # read back from the store
    assert set(made) <= set(_bytecode._DC_CODES)
    check(define("gtecat._probe_dc2"))
    assert not _bytecode._DC_NEW  # nothing compiled again
    store.write_bytes(b"damaged")
    _bytecode._DC_CODES.clear()
    _bytecode._dc_load()
    check(define("gtecat._probe_dc3"))  # compiled again


def _fresh_store(tmp_path: Path, monkeypatch) -> None:
    """The store of run-time functions in ``tmp_path``, nothing read or compiled yet."""
    monkeypatch.setattr(_bytecode, "_DC_FILE", [tmp_path / "dataclass-store"])
    monkeypatch.setattr(_bytecode, "_GEN_INDEX", {})
    monkeypatch.setattr(_bytecode, "_GEN_NEW", {})
    monkeypatch.setattr(_bytecode, "_GEN_DATA", [0, None])
    monkeypatch.setattr(_bytecode, "_GEN_USED", set())
    monkeypatch.setattr(_bytecode, "_GEN_FILE", [])


def _new_process() -> None:
    """What a new process starts with (the store on disk as the last one left it)."""
    _bytecode._GEN_INDEX.clear()
    _bytecode._GEN_USED.clear()
    _bytecode._GEN_FILE.clear()
    _bytecode._GEN_DATA[:] = [0, None]


@pytest.mark.parametrize("pread", [True, False], ids=["pread", "whole"])
def test_functions_written_at_run_time_kept_compiled(tmp_path: Path, monkeypatch, pread) -> None:
    """A function gtecat writes at run time is compiled as its module would (annotations as
    text), kept in one store with the others (added to it at exit, its index read in one go,
    each code when asked for - or the whole file where the platform cannot read at an
    offset), and compiled again from a damaged store or entry."""
    _fresh_store(tmp_path, monkeypatch)
    if not pread or not _bytecode._PREAD:
        monkeypatch.setattr(_bytecode, "_PREAD", False)
    source = "def f(x: int) -> int:\n    return x + 1\n"
    ns: dict = {}
    exec(_bytecode.compiled(source, "<probe>"), ns)
    assert ns["f"](1) == 2 and ns["f"].__annotations__ == {"x": "int", "return": "int"}
    (store,) = _bytecode._GEN_FILE
    assert not store.exists() and len(_bytecode._GEN_NEW) == 1
    exec(_bytecode.compiled("def g():\n    return 5\n", "<probe g>"), ns)
    _bytecode._gen_save()  # (at exit)
    assert store.exists() and not _bytecode._GEN_NEW
    kept = store.read_bytes()
    _new_process()
    again = _bytecode.compiled(source, "<probe>")
    assert again.co_filename == "<probe>" and not _bytecode._GEN_NEW  # read back, not compiled
    exec(again, ns)
    assert ns["f"](2) == 3 and len(_bytecode._GEN_INDEX) == 2
    assert _bytecode.compiled(source, "<probe 2>").co_filename == "<probe 2>"  # (another file)
    _bytecode._GEN_NEW.clear()
    _bytecode._gen_save()  # nothing new: the store is left as it is
    assert store.read_bytes() == kept
    # a damaged entry is compiled again
    index, codes = _bytecode._gen_read(store)
    assert len(index) == 2 and len(codes) > 100
    store.write_bytes(kept[: -len(codes)] + b"\0" * len(codes))
    _new_process()
    exec(_bytecode.compiled(source, "<probe>"), ns)
    assert ns["f"](3) == 4 and len(_bytecode._GEN_NEW) == 1
    _bytecode._GEN_NEW.clear()
    # a store cut short: the function whose bytes it lost compiled again, the other read
    store.write_bytes(kept[:-5])
    _new_process()
    _bytecode.compiled(source, "<probe>")
    assert not _bytecode._GEN_NEW
    _bytecode.compiled("def g():\n    return 5\n", "<probe g>")
    assert len(_bytecode._GEN_NEW) == 1
    _bytecode._GEN_NEW.clear()
    # a damaged store: every function compiled again, the store written anew at exit
    huge = _bytecode._GEN_MAGIC + (1 << 62).to_bytes(8, "little")
    index, _ = _bytecode._gen_read(store)
    foreign = {k: v for k, v in zip(index, [(0, 1 << 90), ("a", 1)], strict=True)}
    head = marshal.dumps(foreign)
    foreign_index = _bytecode._GEN_MAGIC + len(head).to_bytes(8, "little") + head
    for damaged in (b"damaged", kept[:40], b"", huge, foreign_index):
        store.write_bytes(damaged)
        _new_process()
        exec(_bytecode.compiled(source, "<probe>"), ns)
        assert ns["f"](4) == 5 and len(_bytecode._GEN_NEW) == 1
        _bytecode._gen_save()
        _new_process()
        _bytecode._gen_load(store)
        assert len(_bytecode._GEN_INDEX) == 1


def test_the_store_of_run_time_functions_keeps_what_is_used_once_it_is_full(
    tmp_path: Path, monkeypatch
) -> None:
    """Another process's functions already in the store are kept (read again at exit); past
    the store's size, only what this process found there or compiled is kept."""
    _fresh_store(tmp_path, monkeypatch)

    def process(*names: str) -> None:  # a process compiling these functions, then its exit
        _new_process()
        for n in names:
            _bytecode.compiled(f"def {n}():\n    return {n!r}\n", f"<{n}>")
        _bytecode._gen_save()

    def kept() -> set[str]:
        index, data = _bytecode._gen_read(_bytecode._DC_FILE[0].parent / _GEN_NAME)
        return {marshal.loads(data[a:b]).co_filename for a, b in index.values()}

    process("a", "b")
    process("c")  # another process: its function added, the others stay
    assert kept() == {"<a>", "<b>", "<c>"}
    monkeypatch.setattr(_bytecode, "_GEN_MOST", 1)  # (full)
    process("b", "d")
    assert kept() == {"<b>", "<d>"}


_GEN_NAME = f"gen-{sys.implementation.cache_tag}"
