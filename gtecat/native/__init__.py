"""The native face of gtecat: ``gts.h``, ``libgts.so`` and the controller they talk to.

* :func:`library_path` - ``libgts.so``, built on first use (``docs/native.md``);
* :func:`include_dir` - where ``gts.h`` is;
* :mod:`.server` - the controller process (``gtecat controller``);
* :mod:`.protocol` - the bytes between them; :mod:`.header`, :mod:`.stubs` - the
  generated C faces of the function table.
"""

from __future__ import annotations

from pathlib import Path


def library_path(*, force_build: bool = False) -> Path:
    """``libgts.so`` for this gtecat, compiled into the cache if needed.

    Raises :class:`~gtecat.native.build.NativeBuildError` when it cannot be built
    (no C compiler): ``ctypes.CDLL(gtecat.native.library_path())``.
    """
    from .build import ensure_built

    return ensure_built(force=force_build).library


def cdll():
    """``ctypes.CDLL`` of libgts with every function's ``argtypes``/``restype`` set from the
    function table: pointers as ``c_void_p`` (so ``0`` works as NULL, as with the vendor
    DLL on 32-bit Windows), scalars in their C types, ``short`` returns.

    A plain ``ctypes.CDLL(library_path())`` works too; without argtypes, pass ``None``
    (not ``0``) for a NULL pointer, since ctypes passes a bare ``0`` as a 32-bit int.
    """
    import ctypes

    from .. import gt
    from ..gt.table import ENUMS, FUNCTIONS, NO_CORE_TWINS, SAME_PARAM_TWINS, SCALARS

    lib = ctypes.CDLL(str(library_path()))

    def ctype(p):
        if p.pointer:
            return ctypes.c_void_p
        if p.ctype in ENUMS:
            return ctypes.c_int
        if p.ctype in SCALARS:
            return getattr(ctypes, SCALARS[p.ctype][0])
        return getattr(gt, p.ctype, None)  # a structure by value (None: argtypes unset)

    for proto in FUNCTIONS.values():
        types = [ctype(p) for p in proto.params]
        if None in types:
            continue
        names = [(proto.name, types)]
        if proto.name in NO_CORE_TWINS:
            own = [ctypes.c_short] * len(NO_CORE_TWINS[proto.name])
            names.append(("GTN_" + proto.name[3:], own))
        elif proto.name in SAME_PARAM_TWINS:
            names.append(("GTN_" + proto.name[3:], types))
        elif proto.gtn:
            names.append(("GTN_" + proto.name[3:], [ctypes.c_short, *types]))
        for name, argtypes in names:
            fn = getattr(lib, name)
            fn.argtypes = argtypes
            fn.restype = ctypes.c_short
    lib.GTE_GetLastError.argtypes = [ctypes.c_char_p, ctypes.c_short]
    lib.GTE_GetLastError.restype = ctypes.c_short
    return lib


def include_dir() -> Path:
    """The directory holding ``gts.h`` (built with the library)."""
    from .build import ensure_built

    return ensure_built().include_dir


__all__ = ["cdll", "include_dir", "library_path"]
