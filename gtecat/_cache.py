"""gtecat's per-user cache folder, in a module with no imports of gtecat's own (the bytecode
cache finds it while ``gtecat`` itself is being imported)."""

from __future__ import annotations

import os
from pathlib import Path


def cache_root() -> Path:
    """``$GTECAT_CACHE_DIR``, else ``$XDG_CACHE_HOME/gtecat``, else ``~/.cache/gtecat``."""
    env = os.environ.get("GTECAT_CACHE_DIR")
    if env:
        return Path(env)
    xdg = os.environ.get("XDG_CACHE_HOME")
    base = Path(xdg) if xdg else Path.home() / ".cache"
    return base / "gtecat"
