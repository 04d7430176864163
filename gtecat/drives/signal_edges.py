"""Exact edges of window-shaped switch signals crossed between two position samples.

Homing (home switch cams) and the touch probe (probe input marks) both need the
*exact* position where a signal changes inside one cycle's travel, so that a result
never depends on the cycle time or the speed.  A signal is active on a union of
``[low, high)`` windows (DESIGN.md, machine description).

Why not ``AxisMachine.home_edges`` / ``probe_edges``: they evaluate the level before
every boundary at the cycle's start sample, so a window crossed entirely within one
cycle yields only its first edge, and two touching windows ``[a, b)`` ``[b, c)`` yield
a spurious pair at ``b``.  Here windows are merged first and each boundary's
direction is fixed by the window, which is exact for any step length.
"""

from __future__ import annotations

from collections.abc import Iterable
from functools import lru_cache

Window = tuple[float, float]


def merge_windows(windows: Iterable[Window]) -> tuple[Window, ...]:
    """The same active set as disjoint, sorted windows (overlapping or touching ones joined).

    (A machine description's windows are a tuple of pairs: merged once and kept, since every
    homing start and touch probe arms them again.)"""
    if type(windows) is tuple:
        try:
            return _merged(windows)
        except TypeError:  # (a pair that is a list: not hashable)
            pass
    return _merge(windows)


@lru_cache(maxsize=256)
def _merged(windows: tuple[Window, ...]) -> tuple[Window, ...]:
    return _merge(windows)


def _merge(windows: Iterable[Window]) -> tuple[Window, ...]:
    out: list[list[float]] = []
    for lo, hi in sorted((float(a), float(b)) for a, b in windows):
        if hi <= lo:
            continue
        if out and lo <= out[-1][1]:
            out[-1][1] = max(out[-1][1], hi)
        else:
            out.append([lo, hi])
    return tuple((a, b) for a, b in out)


def window_edges(windows: tuple[Window, ...], p0: float, p1: float) -> list[tuple[float, bool]]:
    """Edges ``(position, rising)`` met moving from sample ``p0`` to sample ``p1``, in order.

    ``windows`` must come from :func:`merge_windows`.  ``rising`` means the signal
    becomes active.  The level at a sample is ``low <= x < high``; an edge belongs to
    the step in which the sampled level changes: moving up, boundaries in
    ``(p0, p1]``; moving down, boundaries in ``(p1, p0]``.
    """
    out: list[tuple[float, bool]] = []
    if p1 > p0:
        for lo, hi in windows:
            if hi <= p0:
                continue
            if lo > p1:
                break
            if p0 < lo <= p1:
                out.append((lo, True))
            if p0 < hi <= p1:
                out.append((hi, False))
    elif p1 < p0:
        for lo, hi in reversed(windows):
            if lo > p0:
                continue
            if hi <= p1:
                break
            if p1 < hi <= p0:
                out.append((hi, True))
            if p1 < lo <= p0:
                out.append((lo, False))
    return out


def level(windows: tuple[Window, ...], pos: float) -> bool:
    """Whether the signal is active at ``pos``."""
    return any(lo <= pos < hi for lo, hi in windows)
