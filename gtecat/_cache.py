"""gtecat's per-user cache folder, in a module with no imports of gtecat's own (the bytecode
cache finds it while ``gtecat`` itself is being imported)."""

from __future__ import annotations

import contextlib
import os
from collections.abc import Iterable
from pathlib import Path


def cache_root() -> Path:
    """``$GTECAT_CACHE_DIR``, else ``$XDG_CACHE_HOME/gtecat``, else ``~/.cache/gtecat``."""
    env = os.environ.get("GTECAT_CACHE_DIR")
    if env:
        return Path(env)
    xdg = os.environ.get("XDG_CACHE_HOME")
    base = Path(xdg) if xdg else Path.home() / ".cache"
    return base / "gtecat"


def put_file(path: Path, chunks: Iterable[bytes]) -> None:
    """``path`` made to hold ``chunks``, whole: written beside it under a name of this
    process's, then renamed over it, so a process that reads it meanwhile (or two that write
    it at once) finds the old file or a whole new one, never a part.  An OSError (a full
    disk, a read-only home) leaves no temporary file behind and is raised."""
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f"{path.name}.{os.getpid()}.tmp")
    try:
        with open(tmp, "wb") as f:
            f.writelines(chunks)
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            tmp.unlink()
        raise
