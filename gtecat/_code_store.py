"""The functions gtecat writes at run time, compiled once per text and kept in one store.

The GT fast paths (made at import), each GT function's compiled binder (made at its first
call), the IO readers, a replay's calls: gtecat writes them as source text and compiles it.
Compiling costs more than reading the code back, so each is kept in gtecat's cache folder
(the folder of the dataclass store, :mod:`gtecat._bytecode`), under the digest of its file
name and text: the same text gives the same code.  They are kept in **one store per Python
version**: a process reads its index at the first of them (the import's fast paths) and
each code's bytes from the file it holds open when that code is asked for - a function's
first call finds its compiled binder with one read, where a file of its own cost a path, an
open and a read (0.1-0.3 ms of the first call, and the caches the call ran in after them).
The codes compiled anew are added to the store at exit; a store grown past :data:`_MOST`
keeps what the process used.  A damaged or foreign store, or entry, is compiled again.
``GTECAT_PYC_CACHE=0`` (the caches off) compiles every time.

This module is imported at the first such function, through gtecat's own bytecode cache.
"""

from __future__ import annotations

import atexit
import hashlib
import marshal
import os
import sys
from pathlib import Path
from types import CodeType
from typing import Any

from . import _bytecode
from ._cache import put_file

_ANNOTATIONS = __import__("__future__").annotations.compiler_flag


def compiled(source: str, filename: str) -> CodeType:
    """``compile(source, filename, "exec")`` as a gtecat module with ``from __future__ import
    annotations`` compiles it, kept in the store."""
    folder = _bytecode._DC_FILE
    if not folder:  # (the caches are off)
        return compile(source, filename, "exec", flags=_ANNOTATIONS, dont_inherit=True)
    key = hashlib.sha1(f"{filename}\0{source}".encode("utf-8", "surrogatepass")).hexdigest()
    if not _FILE:  # the store not read yet
        _load(folder[0].parent / f"gen-{sys.implementation.cache_tag}")
    data = _NEW.get(key)
    if data is None:
        at = _INDEX.get(key)
        if at is not None:
            data = _bytes(at)
    if data is not None:
        try:
            code = marshal.loads(data)
            if isinstance(code, CodeType) and code.co_filename == filename:
                _USED.add(key)
                return code
        except (EOFError, ValueError, TypeError):
            pass
    code = compile(source, filename, "exec", flags=_ANNOTATIONS, dont_inherit=True)
    _NEW[key] = marshal.dumps(code)
    return code


# The store: a header, the index of its codes (marshalled: key -> (start, end) in the codes'
# bytes that follow it) and those bytes, each code marshalled.  A process reads the header and
# the index; a code's bytes are read when it is asked for (from the file as it was opened: a
# store replaced meanwhile by another process's is a file of its own), where the platform
# reads at an offset (os.pread), else with the rest of the file at once.
_MAGIC = b"gtecat run-time codes 1\n"
_HEAD = len(_MAGIC) + 8
#: the store's file (once read), its index, where its codes' bytes begin and how they are
#: read (an open file's descriptor, else the bytes themselves), the keys this process found
#: there, the codes it compiled (key -> marshalled code)
_FILE: list[Path] = []
_INDEX: dict[str, Any] = {}
_DATA: list[Any] = [0, None]
_USED: set[str] = set()
_NEW: dict[str, bytes] = {}
#: the most bytes of code the store keeps (one process writes ~0.2 MB; the test suite, which
#: compiles a binder for every function of the table, ~1 MB)
_MOST = 4 << 20
#: more than any store or code of it holds (a damaged file's numbers are not believed)
_SANE = 1 << 28
_PREAD = hasattr(os, "pread")
_pread = getattr(os, "pread", None)


def _open(path: Path, whole: bool) -> tuple[dict[str, Any], int, Any]:
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
        if not data.startswith(_MAGIC):
            raise ValueError("not a store")
        n = int.from_bytes(data[_HEAD - 8 : _HEAD], "little")
        if n > _SANE:
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


def _read(path: Path) -> tuple[dict[str, Any], Any]:
    """The index of the store ``path`` and its codes' bytes, read whole."""
    index, start, data = _open(path, True)
    return index, memoryview(data)[start:] if data is not None else b""


def _load(path: Path) -> None:
    _FILE[:] = [path]
    index, start, source = _open(path, not _PREAD)
    _INDEX.update(index)
    _DATA[:] = [start, source]


def _bytes(at: Any, store: Any = None) -> Any:
    """The bytes of the code at ``at`` (its start and end in the store's codes; ``store``: a
    (start, source) as :data:`_DATA` holds them, that one by default), None where the store
    does not hold them (a file cut short, a foreign index)."""
    start, source = _DATA if store is None else store
    try:
        a, b = at
        if not 0 <= a <= b <= a + _SANE:
            return None
        if type(source) is int:
            data = _pread(source, b - a, start + a)
        else:
            data = source[start + a : start + b]
    except (OSError, TypeError, ValueError, OverflowError):
        return None
    return data if len(data) == b - a else None


def _save() -> None:
    """The codes compiled in this process added to the store (as it stands now: another
    process may have added to it).  A store grown past :data:`_MOST` keeps only what this
    process found there or compiled: the codes of older sources and of one-off runs go."""
    if not _NEW or not _FILE:
        return
    path = _FILE[0]
    try:
        index, data = _read(path)
        kept: dict[str, Any] = {}
        for k, at in index.items():
            code = _bytes(at, (0, data))
            if code is not None:  # (not an entry cut short or foreign)
                kept[k] = code
        kept.update(_NEW)
        if sum(len(v) for v in kept.values()) > _MOST:
            kept = {k: v for k, v in kept.items() if k in _USED or k in _NEW}
        out, start = {}, 0
        for k, v in kept.items():
            out[k] = (start, start + len(v))
            start += len(v)
        head = marshal.dumps(out)
        put_file(path, (_MAGIC + len(head).to_bytes(8, "little") + head, *kept.values()))
    except (OSError, ValueError):
        pass  # a read-only home: compiled again next time
    _NEW.clear()


atexit.register(_save)
