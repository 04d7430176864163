"""What a cProfile of GT calls saw of the slower ways: the fast-path tests' one count."""

from __future__ import annotations

import cProfile
import pstats


def table_calls(pr: cProfile.Profile, fast: tuple[str, ...] = ()) -> int:
    """How often ``pr`` saw the table path run (gtecat.gt._core's ``call`` / ``run``), and
    gtecat.gt.fast's functions ``fast`` (its own second ways, where a test counts them)."""
    return sum(
        v[1]
        for (file, _, func), v in pstats.Stats(pr).stats.items()  # type: ignore[attr-defined]
        if (func in ("call", "run") and file.endswith("_core.py"))
        or (func in fast and file.endswith("fast.py"))
    )
