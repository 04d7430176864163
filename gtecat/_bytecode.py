"""gtecat's own modules compiled once per source text, also where Python writes no bytecode.

With ``PYTHONDONTWRITEBYTECODE`` set (container images often set it) and gtecat installed
from a source tree (``pip install -e``), Python compiles every gtecat module from its source
in every process: about half a second of each process's start, more than the rest of its
import.  When bytecode writing is off, a finder put in front of the import system for
``gtecat.*`` only keeps the compiled modules in gtecat's per-version cache (the folder of
its built C parts, :mod:`gtecat.cbuild`): one file per module, named by the digest of the
module's path and source text, written once and read by every later process.  A changed
source is a new name; an unreadable or foreign file is compiled again.  Python's own caches
work as always when bytecode writing is on (this module then does nothing), and
``GTECAT_PYC_CACHE=0`` turns it off.
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

from ._cache import cache_root

_DIR: list[Path] = []


def _cache_dir(version: str) -> Path:
    tag = sys.implementation.cache_tag or "python"
    return cache_root() / version / "pyc" / tag


class _Loader(importlib.machinery.SourceFileLoader):
    """A source module's code from the cache, compiled and stored there on a miss."""

    def get_code(self, fullname: str) -> CodeType:
        path = self.get_filename(fullname)
        source = self.get_data(path)
        h = hashlib.sha256(importlib.util.MAGIC_NUMBER)
        h.update(os.fsencode(path))
        h.update(b"\0")
        h.update(source)
        cached = _DIR[0] / f"{fullname}-{h.hexdigest()[:32]}.pyc"
        return _kept(cached, path, lambda: self.source_to_code(source, path))


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
        cached.parent.mkdir(parents=True, exist_ok=True)
        tmp = cached.with_name(f"{cached.name}.{os.getpid()}.tmp")
        tmp.write_bytes(marshal.dumps(code))
        os.replace(tmp, cached)
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


# --- the methods dataclasses writes, the functions gtecat writes ---------------------------------
# ``@dataclass`` writes each class's __init__, __repr__, __eq__ (and __setattr__ of a frozen one)
# as source text and compiles it while the module is imported: for gtecat's ~180 dataclasses a
# fifth of a process's import, every process.  The compiled text is kept here like the
# modules': the dataclasses module's ``exec`` (the one name it calls to compile) is looked up
# in this module's store first, for classes of gtecat's own modules only (the globals passed
# name the module); every other class is compiled as always.  The same text gives the same
# code, so a class is what it would be without the store.  One file per Python version, read
# at the first class; the codes compiled anew are added to it at exit.

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


def compiled(source: str, filename: str) -> CodeType:
    """``compile(source, filename, "exec")`` as a gtecat module with ``from __future__ import
    annotations`` compiles it, kept in the cache: the functions gtecat writes at run time (the
    GT fast paths, the compiled binders, a replay's calls).

    They are kept in one store per Python version (:func:`_gen_load`), its index read at
    the first of them (the import's fast paths), each code's bytes from the file held open:
    a function's first call finds its compiled binder with one read, where a file of its
    own cost a path, an open and a read (0.1-0.3 ms of the first call, and the caches the
    call ran in after them).  The codes compiled anew are added to the store at exit
    (:func:`_gen_save`)."""
    if not _DC_FILE:  # (the caches are off)
        return compile(source, filename, "exec", flags=_ANNOTATIONS, dont_inherit=True)
    key = hashlib.sha1(f"{filename}\0{source}".encode("utf-8", "surrogatepass")).hexdigest()
    if not _GEN_FILE:  # the store not read yet
        _gen_load(_DC_FILE[0].parent / f"gen-{sys.implementation.cache_tag}")
    data = _GEN_NEW.get(key)
    if data is None:
        at = _GEN_INDEX.get(key)
        if at is not None:
            data = _gen_bytes(at)
    if data is not None:
        try:
            code = marshal.loads(data)
            if isinstance(code, CodeType) and code.co_filename == filename:
                _GEN_USED.add(key)
                return code
        except (EOFError, ValueError, TypeError):
            pass
    code = compile(source, filename, "exec", flags=_ANNOTATIONS, dont_inherit=True)
    _GEN_NEW[key] = marshal.dumps(code)
    return code


# The store of the functions gtecat writes at run time: a header, the index of its codes
# (marshalled: key -> (start, end) in the codes' bytes that follow it) and those bytes, each
# code marshalled.  A process reads the header and the index; a code's bytes are read when it
# is asked for (from the file as it was opened: a store replaced meanwhile by another
# process's is a file of its own), where the platform reads at an offset (os.pread), else
# with the rest of the file at once.
_GEN_MAGIC = b"gtecat run-time codes 1\n"
#: the store's file (once read), its index, where its codes' bytes begin and how they are
#: read (an open file's descriptor, else the bytes themselves), the keys this process found
#: there, the codes it compiled (key -> marshalled code)
_GEN_FILE: list[Path] = []
_GEN_INDEX: dict[str, Any] = {}
_GEN_DATA: list[Any] = [0, None]
_GEN_USED: set[str] = set()
_GEN_NEW: dict[str, bytes] = {}
#: the most bytes of code the store keeps (one process writes ~0.2 MB; the test suite, which
#: compiles a binder for every function of the table, ~1 MB)
_GEN_MOST = 4 << 20
#: more than any store or code of it holds (a damaged file's numbers are not believed)
_GEN_SANE = 1 << 28
_HEAD = len(_GEN_MAGIC) + 8


def _gen_open(path: Path, whole: bool) -> tuple[dict[str, Any], int, Any]:
    """The index of the store ``path``, where its codes' bytes begin, and an open descriptor
    of the file (``whole``: the file's bytes instead); ({}, 0, None) for a missing,
    unreadable or foreign file."""
    fd = None
    try:
        if whole:
            data: Any = path.read_bytes()
        else:
            fd = os.open(path, os.O_RDONLY | getattr(os, "O_CLOEXEC", 0))
            data = os.pread(fd, 1 << 16, 0)  # (the header and most indexes)
        if not data.startswith(_GEN_MAGIC):
            raise ValueError("not a store")
        n = int.from_bytes(data[_HEAD - 8 : _HEAD], "little")
        if n > _GEN_SANE:
            raise ValueError("not a store")
        if fd is not None and _HEAD + n > len(data):
            data = os.pread(fd, _HEAD + n, 0)
        index = marshal.loads(memoryview(data)[_HEAD : _HEAD + n])
        if type(index) is not dict:
            raise ValueError("not a store")
    except (OSError, EOFError, ValueError, TypeError):
        if fd is not None:
            os.close(fd)
        return {}, 0, None
    return index, _HEAD + n, fd if fd is not None else data


def _gen_read(path: Path) -> tuple[dict[str, Any], Any]:
    """The index of the store ``path`` and its codes' bytes, read whole."""
    index, start, data = _gen_open(path, True)
    return index, memoryview(data)[start:] if data is not None else b""


def _gen_load(path: Path) -> None:
    _GEN_FILE[:] = [path]
    index, start, source = _gen_open(path, not _PREAD)
    _GEN_INDEX.update(index)
    _GEN_DATA[:] = [start, source]


def _gen_bytes(at: Any, store: Any = None) -> Any:
    """The bytes of the code at ``at`` (its start and end in the store's codes; ``store``: a
    (start, source) as :data:`_GEN_DATA` holds them, that one by default), None where the
    store does not hold them (a file cut short, a foreign index)."""
    start, source = _GEN_DATA if store is None else store
    try:
        a, b = at
        if not 0 <= a <= b <= a + _GEN_SANE:
            return None
        if type(source) is int:
            data = _pread(source, b - a, start + a)
        else:
            data = source[start + a : start + b]
    except (OSError, TypeError, ValueError, OverflowError):
        return None
    return data if len(data) == b - a else None


_PREAD = hasattr(os, "pread")
_pread = getattr(os, "pread", None)


def _gen_save() -> None:
    """The codes compiled in this process added to the store (as it stands now: another
    process may have added to it).  A store grown past :data:`_GEN_MOST` keeps only what this
    process found there or compiled: the codes of older sources and of one-off runs go."""
    if not _GEN_NEW or not _GEN_FILE:
        return
    path = _GEN_FILE[0]
    try:
        index, data = _gen_read(path)
        kept: dict[str, Any] = {}
        for k, at in index.items():
            code = _gen_bytes(at, (0, data))
            if code is not None:  # (not an entry cut short or foreign)
                kept[k] = code
        kept.update(_GEN_NEW)
        if sum(len(v) for v in kept.values()) > _GEN_MOST:
            kept = {k: v for k, v in kept.items() if k in _GEN_USED or k in _GEN_NEW}
        out, start = {}, 0
        for k, v in kept.items():
            out[k] = (start, start + len(v))
            start += len(v)
        head = marshal.dumps(out)
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_name(f"{path.name}.{os.getpid()}.tmp")
        with open(tmp, "wb") as f:
            f.write(_GEN_MAGIC + len(head).to_bytes(8, "little") + head)
            f.writelines(kept.values())
        os.replace(tmp, path)
    except (OSError, ValueError):
        pass  # a read-only home: compiled again next time
    _GEN_NEW.clear()


_ANNOTATIONS = __import__("__future__").annotations.compiler_flag


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
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_name(f"{path.name}.{os.getpid()}.tmp")
        tmp.write_bytes(marshal.dumps(kept))
        os.replace(tmp, path)
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
    atexit.register(_gen_save)
