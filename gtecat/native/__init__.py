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


def include_dir() -> Path:
    """The directory holding ``gts.h`` (built with the library)."""
    from .build import ensure_built

    return ensure_built().include_dir


__all__ = ["include_dir", "library_path"]
