"""gtecat's own modules compiled once per source text, also where Python writes no bytecode.

With ``PYTHONDONTWRITEBYTECODE`` set (container images often set it) and gtecat installed
from a source tree (``pip install -e``), Python compiles every gtecat module from its source
in every process: about half a second of each process's start, more than the rest of its
import.  When bytecode writing is off, a finder put in front of the import system for
``gtecat.*`` only keeps the compiled modules in gtecat's per-version cache (the folder of
its built C parts, :mod:`gtecat.cbuild`): one file per module, named by the digest of the
module's path and source text, written once and read by every later process.  A changed
source is a new name; an unreadable or foreign file is compiled again.  A module whose own
``__pycache__`` file is current (``pip install`` writes them) is read from there first.
Python's own caches work as always when bytecode writing is on (this module then does
nothing), and ``GTECAT_PYC_CACHE=0`` turns it off.
"""

from __future__ import annotations

import hashlib
import importlib.machinery
import importlib.util
import marshal
import os
import sys
from collections.abc import Callable
from pathlib import Path
from types import CodeType
from typing import Any

from ._cache import cache_root, put_file

_DIR: list[Path] = []


def _cache_dir(version: str) -> Path:
    tag = sys.implementation.cache_tag or "python"
    return cache_root() / version / "pyc" / tag


class _Loader(importlib.machinery.SourceFileLoader):
    """A source module's code from the cache, compiled and stored there on a miss."""

    def get_code(self, fullname: str) -> CodeType:
        path = self.get_filename(fullname)
        code = _installed(path)
        if code is not None:
            return code
        source = self.get_data(path)
        h = hashlib.sha256(importlib.util.MAGIC_NUMBER)
        h.update(os.fsencode(path))
        h.update(b"\0")
        h.update(source)
        cached = _DIR[0] / f"{fullname}-{h.hexdigest()[:32]}.pyc"
        return _kept(cached, path, lambda: self.source_to_code(source, path))


def _installed(path: str) -> CodeType | None:
    """The code of Python's own bytecode file of ``path`` where it is current (a timestamp
    pyc whose source time and size are the source's, of this Python), else None.

    ``pip install`` writes these for every module of an installed package, and Python reads
    them with bytecode writing off too; a source tree nobody compiled has none (or stale
    ones), and the cache above serves it.  Read here as the import system reads them
    (PEP 552's header: magic, flags 0, the source's mtime and size).
    """
    try:
        pyc = importlib.util.cache_from_source(path)
        with open(pyc, "rb") as f:
            data = f.read()
        st = os.stat(path)
    except (NotImplementedError, OSError, ValueError):
        return None
    if (
        len(data) < 16
        or data[:4] != importlib.util.MAGIC_NUMBER
        or data[4:8] != b"\0\0\0\0"
        or int.from_bytes(data[8:12], "little") != int(st.st_mtime) & 0xFFFFFFFF
        or int.from_bytes(data[12:16], "little") != st.st_size & 0xFFFFFFFF
    ):
        return None
    try:
        code = marshal.loads(memoryview(data)[16:])
    except (EOFError, ValueError, TypeError):
        return None
    return code if isinstance(code, CodeType) and code.co_filename == path else None


def _kept(cached: Path, filename: str, make: Callable[[], CodeType]) -> CodeType:
    """The code kept in file ``cached`` (compiled from ``filename``), else ``make()``'s, kept
    there (written under another name and renamed); an unreadable or foreign file is made
    again, a read-only home only costs the compiling next time."""
    try:
        code = marshal.loads(cached.read_bytes())
        if isinstance(code, CodeType) and code.co_filename == filename:
            return code
    except (OSError, EOFError, ValueError, TypeError):
        pass
    code = make()
    try:
        put_file(cached, (marshal.dumps(code),))
    except OSError:
        pass
    return code


class _Finder:
    """Finds ``gtecat.*`` modules as the path finder does, with :class:`_Loader`."""

    @classmethod
    def find_spec(cls, name: str, path: Any = None, target: Any = None) -> Any:
        if not name.startswith("gtecat."):
            return None
        spec = importlib.machinery.PathFinder.find_spec(name, path, target)
        loader = spec.loader if spec is not None else None
        if type(loader) is importlib.machinery.SourceFileLoader:
            spec.loader = _Loader(loader.name, loader.path)
        return spec

    @classmethod
    def invalidate_caches(cls) -> None:
        pass


def install(version: str) -> None:
    """Put the finder in front when Python writes no bytecode (once per process)."""
    if not sys.dont_write_bytecode or os.environ.get("GTECAT_PYC_CACHE", "1") == "0":
        return
    if any(f is _Finder for f in sys.meta_path):
        return
    _DIR[:] = [_cache_dir(version)]
    # just before the path finder: finders put in front of it (pytest's assertion rewriting
    # of plugins, coverage tools) keep their turn
    at = next(
        (k for k, f in enumerate(sys.meta_path) if f is importlib.machinery.PathFinder),
        len(sys.meta_path),
    )
    sys.meta_path.insert(at, _Finder)


# --- the methods dataclasses writes --------------------------------------------------------------
# ``@dataclass`` writes each class's __init__, __repr__, __eq__ (and __setattr__ of a frozen one)
# as source text and compiles it while the module is imported: for gtecat's ~180 dataclasses a
# fifth of a process's import, every process.  The compiled text is kept here like the
# modules': the dataclasses module's ``exec`` (the one name it calls to compile) is looked up
# in this module's store first, for classes of gtecat's own modules only (the globals passed
# name the module); every other class is compiled as always.  The same text gives the same
# code, so a class is what it would be without the store.  One file per Python version, read
# at the first class; the codes compiled anew are added to it at exit.  (The functions gtecat
# writes at run time have a store of their own: gtecat._code_store.)

_DC_CODES: dict[str, CodeType] = {}
_DC_NEW: dict[str, CodeType] = {}
_DC_FILE: list[Path] = []
_builtin_exec = exec


def _dc_exec(source: Any, globals: Any = None, locals: Any = None) -> None:
    if type(source) is str and type(globals) is dict:
        name = globals.get("__name__")
        if type(name) is str and name.startswith("gtecat."):
            if not _DC_FILE[1:]:  # the store not read yet
                _DC_FILE.append(_DC_FILE[0])
                _dc_load()
            key = hashlib.sha1(source.encode("utf-8", "surrogatepass")).hexdigest()
            code = _DC_CODES.get(key)
            if code is None:
                # as exec compiles it there: no __future__ of this module's (annotations
                # stay objects, not text)
                code = compile(source, "<string>", "exec", dont_inherit=True)
                _DC_CODES[key] = _DC_NEW[key] = code
            _builtin_exec(code, globals, locals)
            return
    if type(source) is str:  # (a text exec'd here would take this module's __future__)
        source = compile(source, "<string>", "exec", dont_inherit=True)
    _builtin_exec(source, globals, locals)


def _dc_load() -> None:
    try:
        codes = marshal.loads(_DC_FILE[0].read_bytes())
    except (OSError, EOFError, ValueError, TypeError):
        return
    if type(codes) is dict:
        _DC_CODES.update(
            (k, v) for k, v in codes.items() if type(k) is str and isinstance(v, CodeType)
        )


def _dc_save() -> None:
    """The codes compiled in this process added to the store (a store grown past what one
    version of gtecat writes starts again: the classes changed many times)."""
    if not _DC_NEW:
        return
    path = _DC_FILE[0]
    try:
        try:
            kept = marshal.loads(path.read_bytes())
        except (OSError, EOFError, ValueError, TypeError):
            kept = {}
        if type(kept) is not dict or len(kept) > _DC_MOST:
            kept = {}
        kept.update(_DC_NEW)
        put_file(path, (marshal.dumps(kept),))
    except (OSError, ValueError):
        pass  # a read-only home: compiled again next time
    _DC_NEW.clear()


#: the most codes the store keeps (gtecat's classes write ~700)
_DC_MOST = 4000


def install_dataclass_cache(version: str) -> None:
    """Keep the methods of gtecat's dataclasses compiled (once per process; ``GTECAT_PYC_CACHE=0``
    turns it off with the bytecode cache)."""
    import atexit
    import dataclasses

    if os.environ.get("GTECAT_PYC_CACHE", "1") == "0" or _DC_FILE:
        return
    if vars(dataclasses).get("exec", _dc_exec) is not _dc_exec:
        return  # someone else's exec there: left alone
    try:
        folder = _cache_dir(version).parent
    except (RuntimeError, KeyError, OSError):  # (no home folder to put a cache in)
        return
    _DC_FILE.append(folder / f"dataclass-{sys.implementation.cache_tag}-2")
    dataclasses.exec = _dc_exec  # type: ignore[attr-defined]
    atexit.register(_dc_save)
