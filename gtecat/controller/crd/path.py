"""Segment geometry of a coordinate system: lines, arcs and helices in 1-4 coordinates.

Every motion segment knows its start and end (coordinate vectors in profile
pulses, doubles), its length ``length`` along the path and ``point(s)`` for a
path distance ``0 <= s <= length``.  ``point(length)`` is the target exactly as
given (no rounding, no accumulated error): a segment ends where it was asked to.

* :class:`Line`: ``p0 + (p1 - p0)·s/L``; every point lies on the line.
* :class:`Arc`: a circular arc in the plane of two coordinates (XY, YZ or ZX,
  the angle counted from the first toward the second), optionally with a third
  coordinate moving linearly with the angle (a helix).  The radius is the
  start radius; when the end lies off that circle by a rounding (at most
  :data:`RADIUS_TOL` pulse) the radius changes linearly with the angle so the
  end is still exact.  ``s`` maps to the angle linearly (constant speed on the
  arc).  ``circleDir`` 0 is clockwise, 1 counter-clockwise (vendor header).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from ...errors import ParameterError

#: how far the end of an arc may lie off the circle through its start (pulse)
RADIUS_TOL = 1.0
PLANES = {"XY": (0, 1), "YZ": (1, 2), "ZX": (2, 0)}
CW, CCW = 0, 1

Vec = tuple[float, ...]


def _norm(v: Sequence[float]) -> float:
    return math.sqrt(sum(x * x for x in v))


@dataclass(frozen=True, slots=True)
class Line:
    start: Vec
    end: Vec
    #: derived once (a segment is sampled every cycle): its length and end - start
    length: float = field(init=False, repr=False, compare=False)
    _delta: Vec = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        delta = tuple(b - a for a, b in zip(self.start, self.end, strict=True))
        object.__setattr__(self, "_delta", delta)
        object.__setattr__(self, "length", _norm(delta))

    def point(self, s: float) -> Vec:
        ln = self.length
        if s >= ln or ln == 0.0:
            return self.end
        u = max(s, 0.0) / ln
        return tuple(a + d * u for a, d in zip(self.start, self._delta, strict=True))

    def points(self, s: np.ndarray, out: np.ndarray) -> None:
        """:meth:`point` of each path distance of ``s`` into ``out`` (one row per
        coordinate): the same operations, so each value is bit for bit the scalar one."""
        ln = self.length
        if ln == 0.0:
            out[:] = np.array(self.end)[:, None]
            return
        u = _fraction(s, ln)
        for k, (a, d) in enumerate(zip(self.start, self._delta, strict=True)):
            np.multiply(u, d, out=out[k])
            out[k] += a
        _ends(s, ln, self.end, out)

    def tangent(self, at_end: bool) -> Vec:
        ln = self.length
        return tuple(d / ln for d in self._delta)


@dataclass(frozen=True, slots=True)
class Arc:
    start: Vec
    end: Vec
    center: tuple[float, float]  #: absolute, in the plane's two coordinates
    plane: tuple[int, int]
    sweep: float  #: signed angle (radian), positive counter-clockwise
    axis3: int | None = None  #: the helix's linear coordinate
    #: derived once (a segment is sampled every cycle): start and end radius, start angle,
    #: the helix's rise and the length along the path
    r0: float = field(init=False, repr=False, compare=False)
    r1: float = field(init=False, repr=False, compare=False)
    theta0: float = field(init=False, repr=False, compare=False)
    rise: float = field(init=False, repr=False, compare=False)
    length: float = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        i, j = self.plane
        start, end, (cx, cy) = self.start, self.end, self.center
        r0 = math.hypot(start[i] - cx, start[j] - cy)
        r1 = math.hypot(end[i] - cx, end[j] - cy)
        rise = 0.0 if self.axis3 is None else end[self.axis3] - start[self.axis3]
        planar = abs(self.sweep) * 0.5 * (r0 + r1)
        put = object.__setattr__
        put(self, "r0", r0)
        put(self, "r1", r1)
        put(self, "theta0", math.atan2(start[j] - cy, start[i] - cx))
        put(self, "rise", rise)
        put(self, "length", math.hypot(planar, rise))

    def point(self, s: float) -> Vec:
        ln = self.length
        if s >= ln or ln == 0.0:
            return self.end
        u = max(s, 0.0) / ln
        i, j = self.plane
        r0 = self.r0
        r = r0 + (self.r1 - r0) * u
        th = self.theta0 + self.sweep * u
        out = list(self.start)
        cx, cy = self.center
        out[i] = cx + r * math.cos(th)
        out[j] = cy + r * math.sin(th)
        if self.axis3 is not None:
            k = self.axis3
            out[k] = self.start[k] + self.rise * u
        return tuple(out)

    def points(self, s: np.ndarray, out: np.ndarray) -> None:
        """:meth:`point` of each path distance of ``s`` into ``out`` (one row per
        coordinate): the same operations, so each value is bit for bit the scalar one (the
        cosines and sines are ``math``'s, as :meth:`point` takes them: numpy's may differ in
        the last bit)."""
        ln = self.length
        if ln == 0.0:
            out[:] = np.array(self.end)[:, None]
            return
        u = _fraction(s, ln)
        i, j = self.plane
        r0 = self.r0
        r = r0 + (self.r1 - r0) * u
        th = (self.theta0 + self.sweep * u).tolist()
        n = len(th)
        cx, cy = self.center
        for k, x in enumerate(self.start):
            if k != i and k != j:
                out[k] = x
        np.multiply(r, np.fromiter(map(math.cos, th), np.float64, n), out=out[i])
        out[i] += cx
        np.multiply(r, np.fromiter(map(math.sin, th), np.float64, n), out=out[j])
        out[j] += cy
        if self.axis3 is not None:
            k = self.axis3
            np.multiply(u, self.rise, out=out[k])
            out[k] += self.start[k]
        _ends(s, ln, self.end, out)

    def tangent(self, at_end: bool) -> Vec:
        i, j = self.plane
        th = self.theta0 + (self.sweep if at_end else 0.0)
        r = self.r1 if at_end else self.r0
        sgn = 1.0 if self.sweep > 0 else -1.0
        t = [0.0] * len(self.start)
        w = abs(self.sweep) * r
        t[i], t[j] = -math.sin(th) * sgn * w, math.cos(th) * sgn * w
        if self.axis3 is not None:
            t[self.axis3] = self.rise
        n = _norm(t) or 1.0
        return tuple(x / n for x in t)


def _fraction(s: np.ndarray, ln: float) -> np.ndarray:
    """``max(s, 0.0) / ln`` of each ``s`` (``max`` keeps ``s`` unless 0.0 is larger)."""
    return np.where(0.0 > s, 0.0, s) / ln


def _ends(s: np.ndarray, ln: float, end: Vec, out: np.ndarray) -> None:
    """The points at or past the end of a segment are its end exactly."""
    at_end = s >= ln
    if at_end.any():
        out[:, at_end] = np.array(end)[:, None]


def arc_center(
    start: Vec, end: Vec, plane: tuple[int, int], radius: float, direction: int
) -> tuple[float, float]:
    """Centre of the arc of ``radius`` from ``start`` to ``end`` (GT_ArcXYR and kin).

    ``radius > 0``: the arc of at most 180°, ``< 0``: the longer one (vendor
    convention).  ParameterError when the chord is longer than the diameter
    or start and end coincide (a full circle needs a centre: GT_ArcXYC).
    """
    i, j = plane
    x0, y0, x1, y1 = start[i], start[j], end[i], end[j]
    dx, dy = x1 - x0, y1 - y0
    d = math.hypot(dx, dy)
    rad = abs(radius)
    if radius == 0.0 or d == 0.0:
        raise ParameterError(
            f"radius={radius}: an arc by radius needs start != end and radius != 0 "
            "(a full circle takes the centre form, GT_ArcXYC)"
        )
    if d > 2.0 * rad + RADIUS_TOL:
        raise ParameterError(f"radius={radius}: the chord ({d:.3f} pulse) exceeds the diameter")
    h = math.sqrt(max(rad * rad - 0.25 * d * d, 0.0))
    nx, ny = -dy / d, dx / d  # left of the chord
    side = 1.0 if direction == CCW else -1.0
    if radius < 0.0:
        side = -side
    return 0.5 * (x0 + x1) + side * h * nx, 0.5 * (y0 + y1) + side * h * ny


def make_arc(
    start: Vec,
    end: Vec,
    center: tuple[float, float],
    plane: tuple[int, int],
    direction: int,
    axis3: int | None = None,
    prefer_major: bool | None = None,
) -> Arc:
    """An :class:`Arc` from ``start`` to ``end`` around the absolute ``center``.

    End on start: a full turn.  ``prefer_major`` (radius form) picks the sweep
    when start and end are diametrically opposite within rounding.
    """
    if direction not in (CW, CCW):
        raise ParameterError(f"circleDir={direction}: 0 (clockwise) or 1 (counter-clockwise)")
    i, j = plane
    r0 = math.hypot(start[i] - center[0], start[j] - center[1])
    r1 = math.hypot(end[i] - center[0], end[j] - center[1])
    if r0 == 0.0:
        raise ParameterError("the arc's centre lies on its start point (radius 0)")
    if abs(r1 - r0) > RADIUS_TOL:
        raise ParameterError(
            f"the end lies {abs(r1 - r0):.3f} pulse off the circle through the start "
            f"(radius {r0:.3f}); at most {RADIUS_TOL} is accepted"
        )
    t0 = math.atan2(start[j] - center[1], start[i] - center[0])
    t1 = math.atan2(end[j] - center[1], end[i] - center[0])
    tau = 2.0 * math.pi
    same = start[i] == end[i] and start[j] == end[j]
    if direction == CCW:
        sweep = tau if same else (t1 - t0) % tau
    else:
        sweep = -tau if same else -((t0 - t1) % tau)
    if not same and abs(sweep) < 1e-12:
        sweep = tau if direction == CCW else -tau
    if prefer_major is not None and abs(abs(sweep) - math.pi) < 1e-9:
        pass  # half circle: either reading is the same arc
    return Arc(tuple(start), tuple(end), center, plane, sweep, axis3)


Segment = Line | Arc
