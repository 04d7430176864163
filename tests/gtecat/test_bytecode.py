"""gtecat's modules compiled once per source where Python writes no bytecode (gtecat._bytecode)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from gtecat import _bytecode


@pytest.fixture
def cache(tmp_path: Path):
    """The modules' cache folder of these tests (the process's own put back after)."""
    old = list(_bytecode._DIR)
    _bytecode._DIR[:] = [tmp_path / "cache"]
    yield tmp_path / "cache"
    _bytecode._DIR[:] = old


def test_a_module_is_compiled_once_and_again_when_its_source_changes(
    tmp_path: Path, cache: Path
) -> None:
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


def test_only_where_python_writes_no_bytecode(tmp_path: Path) -> None:
    code = "import sys, gtecat.eni.numbers as m; print(type(m.__spec__.loader).__name__)"
    env = {**os.environ, "GTECAT_CACHE_DIR": str(tmp_path)}
    env["PYTHONDONTWRITEBYTECODE"] = "1"
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    assert out.stdout.strip() == "_Loader", out.stderr
    # (kept in the cache unless the installed bytecode file is current: read from there)
    import gtecat.eni.numbers as m

    kept = any(tmp_path.rglob("gtecat.eni.numbers-*.pyc"))
    assert kept != (_bytecode._installed(m.__file__) is not None)
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


def test_a_current_installed_bytecode_file_is_read_first(tmp_path: Path, cache: Path) -> None:
    """``pip install`` writes each module's ``__pycache__`` file: where it is current (the
    source's time and size in its header, this Python's magic) its code is taken, nothing is
    compiled or kept; a stale, damaged, hash-based or foreign one is passed over."""
    import marshal
    import py_compile

    _STAMP = py_compile.PycInvalidationMode.TIMESTAMP  # (as pip writes them)
    src = tmp_path / "mod.py"
    src.write_text("X = 1\n")
    pyc = Path(py_compile.compile(str(src), doraise=True, invalidation_mode=_STAMP))
    # (the file's code says X = 3: proof that it, not the source, was read)
    data = bytearray(pyc.read_bytes())
    code = compile("X = 3\n", str(src), "exec")
    pyc.write_bytes(bytes(data[:16]) + marshal.dumps(code))
    loader = _bytecode._Loader("gtecat_probe", str(src))
    ns: dict = {}
    exec(loader.get_code("gtecat_probe"), ns)
    assert ns["X"] == 3 and not cache.exists()

    # another source of another size: stale, compiled from the source and kept
    src.write_text("X = 22\n")
    ns = {}
    exec(loader.get_code("gtecat_probe"), ns)
    assert ns["X"] == 22 and len(list(cache.iterdir())) == 1
    assert _bytecode._installed(str(src)) is None

    py_compile.compile(str(src), doraise=True, invalidation_mode=_STAMP)
    fresh = pyc.read_bytes()
    assert _bytecode._installed(str(src)) is not None
    for header in (
        b"\0\0\0\0" + fresh[4:16],  # another Python's magic
        fresh[:4] + b"\1\0\0\0" + fresh[8:16],  # hash-based
        fresh[:8]
        + (int.from_bytes(fresh[8:12], "little") + 1).to_bytes(4, "little")
        + fresh[12:16],  # another source time
    ):
        pyc.write_bytes(header + fresh[16:])
        assert _bytecode._installed(str(src)) is None
    py_compile.compile(str(src), doraise=True, invalidation_mode=_STAMP)
    assert _bytecode._installed(str(src)) is not None
    pyc.write_bytes(pyc.read_bytes()[:20])  # cut short: damaged
    assert _bytecode._installed(str(src)) is None
    foreign = compile("X = 5\n", "elsewhere.py", "exec")
    py_compile.compile(str(src), doraise=True, invalidation_mode=_STAMP)
    pyc.write_bytes(pyc.read_bytes()[:16] + marshal.dumps(foreign))
    assert _bytecode._installed(str(src)) is None
