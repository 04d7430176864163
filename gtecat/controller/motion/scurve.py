"""The pulse-card drive planner: T (trapezoid) and jerk-limited S-curve drives.

Sources: the MCX314 thesis and the ADT850 manual.

The MCX314-family chips behind the ADT850 (the ADT850 manual, chapter 5 "速度曲线") and the
MCX314 library of the MCX314 thesis (4.4) drive an axis from an initial speed ``SV`` to a
drive speed ``V``:

* **T** (直线加/减速): the speed ramps linearly with ``A`` up, ``D`` down (``D = A``
  when symmetric, the ADT850 manual 3.3).
* **S** (S 曲线): the acceleration grows linearly with the jerk ``K`` from 0 to ``A``,
  stays, and falls back to 0 as the speed nears ``V`` (the ADT850 manual 3.4: *partial* S, the
  a/b/c sections); when ``V`` comes before ``A`` is reached the b section vanishes
  (*full* S).  Deceleration mirrors it with ``D`` and the same jerk.

Units are the controller's (pulse, pulse/ms, pulse/ms², pulse/ms³); the compat layers
turn the seeds' register values into them (``V·M`` PPS, ``A·125·M`` PPS/s,
``62.5e6/K·M`` PPS/s²).  ``jerk = inf`` is the T shape.

Model (what an independent computation reproduces)
--------------------------------------------------
A drive is a list of constant-jerk pieces ``(t0, s0, v0, a0, j)``:
``s = s0 + v0·τ + a0·τ²/2 + j·τ³/6``.  A ramp from ``va`` to ``vb`` (``Δv = |vb - va|``)
lasts ``Δv/A + A/K`` when ``Δv >= A²/K`` (partial S: jerk ``A/K``, constant ``Δv/A -
A/K``, jerk ``A/K``) else ``2·sqrt(Δv/K)`` (full S), ``Δv/A`` for T; its speed curve is
point-symmetric, so it covers ``(va + vb)/2 · duration``.

* **Start**: the speed jumps from 0 to ``SV`` (the chips output their first pulses at the
  initial speed); ``V <= SV`` is a constant-speed drive at ``V`` (the ADT850 manual 3.1/3.6).
* **Fixed drive, automatic deceleration** (定量驱动, 自动减速): up to a peak ``vp``,
  cruise, down to ``SV`` exactly at the target, then 0.  ``vp = V`` when the distance
  allows it, else the largest ``vp`` whose up and down ramps fit (found by bisection,
  to float precision; the cruise takes the rest).  *Triangle prevention* (the ADT850 manual 3.2,
  T only when asked): acceleration stops once the up and down ramps would use half the
  pulses, so such a short move cruises over the middle half.
* **Manual deceleration** (手动减速, ``set_dec_pos`` / ``ManualDec``): up to ``V``, the
  deceleration to ``SV`` starts when ``manual_dec`` pulses are out (not before the up
  ramp ends, for an S ramp), then ``SV`` until the last pulse; a target reached
  earlier ends the drive at once (the chip runs out of pulses).
* **No deceleration** (interpolation with deceleration disabled, the ADT850 manual 5.4): up to
  ``V`` and on to the end, where the drive stops at once.
* **Continuous drive** (连续驱动): up to ``V``, then on until stopped.

Sampling: ``start`` happens at the current cycle (t = 0); the k-th ``step()`` is the
closed form at ``t = k·cycle_ms``; the first sample at or after the end is exactly the
target with zero speed (``done``).  Samples never pass the target.

Commands while driving: :meth:`SCurvePlanner.decelerate` (``dec_stop``) brings the
acceleration to zero with the jerk, then ramps down to ``SV`` and stops (a constant-speed
drive stops at once, the ADT850 manual 5.3); :meth:`SCurvePlanner.change_speed` (``set_speed``
while driving, the ADT850 manual 3.6) re-plans the same way toward the new ``V``; an S fixed drive
keeps its speed (the ADT850 manual: "S曲线加/减速的定量脉冲驱动在驱动中不能变更驱动速度").
:meth:`stop` (GT_Stop, limits) hands over to the constant-deceleration
:class:`~.stop.StopRamp` as every planner does.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ...errors import ParameterError
from . import checks
from .stop import StopKind, StopRamp

_IDLE, _MOVE, _STOP = 0, 1, 2
_EPS_T = 1e-9

Piece = tuple[float, float, float, float, float]
"""``(t0, s0, v0, a0, j)``: ``s = s0 + v0·τ + a0·τ²/2 + j·τ³/6`` from ``t0`` to the next piece."""


@dataclass(frozen=True, slots=True)
class SCurveParams:
    """One drive's speed curve: ``vel_start`` SV, ``vel`` V (pulse/ms), ``acc`` A, ``dec`` D
    (pulse/ms², 0 = ``acc``: symmetric), ``jerk`` K (pulse/ms³, ``inf`` = T shape),
    ``triangle`` triangle prevention (T fixed drives, the ADT850 manual 3.2)."""

    vel_start: float
    vel: float
    acc: float = 1.0
    dec: float = 0.0
    jerk: float = math.inf
    triangle: bool = False

    def __post_init__(self) -> None:
        vs = checks.non_negative("vel_start", self.vel_start)
        v = checks.positive("vel", self.vel)
        a = checks.positive("acc", self.acc)
        d = checks.non_negative("dec", self.dec) or a
        j = self.jerk
        if isinstance(j, bool) or not isinstance(j, (int, float)) or not j > 0 or j != j:
            raise ParameterError(f"jerk must be > 0 (inf for a T curve), got {j!r}")
        for name, value in (("vel_start", vs), ("vel", v), ("acc", a), ("dec", d)):
            object.__setattr__(self, name, value)
        object.__setattr__(self, "jerk", float(j))

    @property
    def s_curve(self) -> bool:
        return math.isfinite(self.jerk)

    @property
    def constant(self) -> bool:
        """``V <= SV``: a constant-speed drive at ``V``."""
        return self.vel <= self.vel_start


# --- ramps ------------------------------------------------------------------------------------
def ramp_time(dv: float, a: float, j: float) -> float:
    """Duration of a ramp by ``|dv|`` with acceleration limit ``a`` and jerk ``j``."""
    dv = abs(dv)
    if dv == 0.0:
        return 0.0
    if not math.isfinite(j):
        return dv / a
    if dv >= a * a / j:
        return dv / a + a / j
    return 2.0 * math.sqrt(dv / j)


def ramp_distance(va: float, vb: float, a: float, j: float) -> float:
    """Distance of the ramp ``va -> vb`` (point-symmetric speed curve: mean speed x time)."""
    return 0.5 * (va + vb) * ramp_time(vb - va, a, j)


def ramp_pieces(t: float, s: float, va: float, vb: float, a: float, j: float) -> list[Piece]:
    """The constant-jerk pieces of the ramp ``va -> vb`` starting at ``(t, s)``."""
    dv = vb - va
    if dv == 0.0:
        return []
    g = 1.0 if dv > 0.0 else -1.0
    dv = abs(dv)
    if not math.isfinite(j):
        return [(t, s, va, g * a, 0.0)]
    if dv >= a * a / j:
        tj, tc, ap = a / j, dv / a - a / j, a
    else:
        tj, tc = math.sqrt(dv / j), 0.0
        ap = j * tj
    out: list[Piece] = []
    p = (t, s, va, 0.0, g * j)
    out.append(p)
    t, s, v, acc = _advance(p, tj)
    if tc > 0.0:
        p = (t, s, v, acc, 0.0)
        out.append(p)
        t, s, v, acc = _advance(p, tc)
    out.append((t, s, v, g * ap, -g * j))
    return out


def _advance(p: Piece, tau: float) -> tuple[float, float, float, float]:
    t0, s0, v0, a0, j = p
    return (
        t0 + tau,
        s0 + tau * (v0 + tau * (0.5 * a0 + tau * j / 6.0)),
        v0 + tau * (a0 + 0.5 * j * tau),
        a0 + j * tau,
    )


def _end_of(pieces: list[Piece], t_end: float) -> tuple[float, float, float, float]:
    p = pieces[-1]
    return _advance(p, t_end - p[0])


class DriveProfile:
    """One drive as closed-form pieces over the distance from its start (module docstring).

    ``length`` is None for a continuous drive (``duration`` is then infinite).
    """

    __slots__ = ("duration", "length", "pieces", "v_end", "v_start")

    def __init__(
        self, pieces: list[Piece], duration: float, length: float | None, v_end: float
    ) -> None:
        self.pieces = pieces
        self.duration = duration
        self.length = length
        self.v_end = v_end
        self.v_start = pieces[0][2] if pieces else v_end

    def piece_at(self, t: float, hint: int = 0) -> int:
        ps = self.pieces
        i = min(hint, len(ps) - 1)
        if ps[i][0] > t:
            i = 0
        while i + 1 < len(ps) and ps[i + 1][0] <= t:
            i += 1
        return i

    def state(self, t: float, hint: int = 0) -> tuple[float, float, float, float, int]:
        """``(s, v, a, j, piece)`` at ``t`` ms (the end state from ``duration`` on)."""
        if t >= self.duration:
            return (self.length or 0.0), self.v_end, 0.0, 0.0, len(self.pieces) - 1
        i = self.piece_at(max(t, 0.0), hint)
        p = self.pieces[i]
        _, s, v, a = _advance(p, max(t, 0.0) - p[0])
        if self.length is not None:
            s = min(s, self.length)
        return s, v, a, p[4], i

    def s(self, t: float) -> float:
        return self.state(t)[0]

    def v(self, t: float) -> float:
        return self.state(t)[1]

    def a(self, t: float) -> float:
        return self.state(t)[2]


def _peak(budget: float, v0: float, prm: SCurveParams) -> float:
    """Largest peak ``vp`` in ``[v0, V]`` whose ramps ``v0 -> vp -> SV`` fit in ``budget``."""
    vs, a, d, j = prm.vel_start, prm.acc, prm.dec, prm.jerk

    def need(vp: float) -> float:
        return ramp_distance(v0, vp, a if vp >= v0 else d, j) + ramp_distance(vp, vs, d, j)

    hi = prm.vel
    if need(hi) <= budget:
        return hi
    if hi <= v0:
        return v0
    lo = v0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if mid in (lo, hi):
            break
        if need(mid) <= budget:
            lo = mid
        else:
            hi = mid
    return lo


def plan_drive(
    length: float | None,
    prm: SCurveParams,
    v0: float | None = None,
    *,
    decel: str = "auto",
    manual_dec: float = 0.0,
) -> DriveProfile:
    """The drive over ``length`` pulses (None: continuous) from speed ``v0`` (None: a start,
    the jump to SV), deceleration ``"auto"``, ``"manual"`` (at ``manual_dec`` pulses) or
    ``"none"`` (module docstring)."""
    vs, vmax, a, d, j = prm.vel_start, prm.vel, prm.acc, prm.dec, prm.jerk
    if prm.constant:  # V <= SV: constant speed at V, no ramps
        pieces: list[Piece] = [(0.0, 0.0, vmax, 0.0, 0.0)]
        if length is None:
            return DriveProfile(pieces, math.inf, None, vmax)
        return DriveProfile(pieces, length / vmax if length > 0 else 0.0, length, vmax)
    start = vs if v0 is None else max(v0, 0.0)
    if length is None:  # continuous
        acc = a if vmax >= start else d
        pieces = ramp_pieces(0.0, 0.0, start, vmax, acc, j)
        t = s = 0.0
        if pieces:
            t, s, _, _ = _end_of(pieces, ramp_time(vmax - start, acc, j))
        pieces.append((t, s, vmax, 0.0, 0.0))
        return DriveProfile(pieces, math.inf, None, vmax)
    if length <= 0.0:
        return DriveProfile([(0.0, 0.0, 0.0, 0.0, 0.0)], 0.0, 0.0, 0.0)
    if decel == "none":
        return _run_to_end(length, start, vmax, a, d, j)
    if decel == "manual":
        return _manual(length, start, prm, max(manual_dec, 0.0))
    # automatic deceleration
    down = ramp_distance(start, vs, d, j)
    if start > vs and down > length:  # cannot stop in time: a linear ramp that does
        a_eff = (start * start - vs * vs) / (2.0 * length)
        pieces = [(0.0, 0.0, start, -a_eff, 0.0)]
        return DriveProfile(pieces, (start - vs) / a_eff, length, vs)
    budget = 0.5 * length if prm.triangle and not prm.s_curve else length
    vp = _peak(budget, start, prm)
    up = a if vp >= start else d
    pieces = ramp_pieces(0.0, 0.0, start, vp, up, j)
    t = s = 0.0
    if pieces:
        t, s, _, _ = _end_of(pieces, ramp_time(vp - start, up, j))
    cruise = max(length - s - ramp_distance(vp, vs, d, j), 0.0)
    if cruise > 0.0 or not pieces:
        pieces.append((t, s, vp, 0.0, 0.0))
        t += cruise / vp if vp > 0.0 else 0.0
        s += cruise
    pieces.extend(ramp_pieces(t, s, vp, vs, d, j))
    return DriveProfile(pieces, t + ramp_time(vp - vs, d, j), length, vs)


def _run_to_end(length: float, start: float, vmax: float, a: float, d: float, j: float):
    acc = a if vmax >= start else d
    pieces = ramp_pieces(0.0, 0.0, start, vmax, acc, j)
    t_r = ramp_time(vmax - start, acc, j)
    if pieces:
        t, s, _, _ = _end_of(pieces, t_r)
        if s >= length:  # the end comes during the ramp
            return DriveProfile(pieces, _time_at(pieces, length, t_r), length, _v_at_end(pieces))
    else:
        t = s = 0.0
    pieces.append((t, s, vmax, 0.0, 0.0))
    return DriveProfile(pieces, t + (length - s) / vmax, length, vmax)


def _manual(length: float, start: float, prm: SCurveParams, point: float) -> DriveProfile:
    vs, vmax, a, d, j = prm.vel_start, prm.vel, prm.acc, prm.dec, prm.jerk
    acc = a if vmax >= start else d
    pieces = ramp_pieces(0.0, 0.0, start, vmax, acc, j)
    t_r = ramp_time(vmax - start, acc, j)
    t, s, v = 0.0, 0.0, start
    if pieces:
        if not prm.s_curve and point < _end_of(pieces, t_r)[1]:  # T: decelerate mid-ramp
            tau = _time_at(pieces, min(point, length), t_r)
            t, s, v, _ = _advance(pieces[-1], tau)
        else:
            t, s, v, _ = _end_of(pieces, t_r)
    if s < point:
        pieces.append((t, s, v, 0.0, 0.0))
        t += (point - s) / v
        s = point
    pieces.extend(ramp_pieces(t, s, v, vs, d, j))
    t += ramp_time(v - vs, d, j)
    s_after = _end_of(pieces, t)[1] if pieces else s
    if s_after < length:
        pieces.append((t, s_after, vs, 0.0, 0.0))
        t += (length - s_after) / vs if vs > 0 else math.inf
    elif s_after > length:  # out of pulses during the deceleration: stop at once
        t = _time_at(pieces, length, t)
    v_end = DriveProfile(pieces, math.inf, None, 0.0).state(t)[1]
    return DriveProfile(pieces, t, length, v_end)


def _time_at(pieces: list[Piece], s_goal: float, t_hi: float) -> float:
    """The time the (monotone) pieces reach ``s_goal`` (bisection to float precision)."""
    prof = DriveProfile(pieces, math.inf, None, 0.0)
    lo, hi = 0.0, t_hi
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if mid in (lo, hi):
            break
        if prof.state(mid)[0] < s_goal:
            lo = mid
        else:
            hi = mid
    return hi


def _v_at_end(pieces: list[Piece]) -> float:
    return pieces[-1][2]


class SCurvePlanner:
    """One profile's pulse-card drive: ``start``, ``step`` per cycle, ``decelerate``, ``stop``.

    Follows :class:`gtecat.controller.motion.Planner`; ``jerk`` and ``acc`` of the last
    sample give the seeds' drive-phase status bits.
    """

    def __init__(self, cycle_ms: float = 1.0, pos: float = 0.0) -> None:
        self._T = checks.positive("cycle_ms", cycle_ms)
        self._stop = StopRamp(self._T)
        self.prm: SCurveParams | None = None
        self.hold(pos)

    # --- state --------------------------------------------------------------------------
    def hold(self, pos: float) -> None:
        """Stand still at ``pos``; any drive is dropped (``sudden_stop`` pulses stop here)."""
        self._pos = checks.real("pos", pos)
        self._vel = self._acc = self._jerk = 0.0
        self._mode = _IDLE
        self._k = 0
        self._hint = 0
        self._t_off = 0.0
        self._base = self._start = self._pos
        self._dir = 1
        self._end: float | None = None  # where the current profile ends (None: continuous)
        self._clamp: float | None = None  # a fixed drive's target: never passed
        self._decel, self._manual = "auto", 0.0
        self.profile: DriveProfile | None = None
        self.stopping = StopKind.NONE
        self.decelerating = False

    @property
    def done(self) -> bool:
        return self._mode == _IDLE

    @property
    def pos(self) -> float:
        return self._pos

    @property
    def vel(self) -> float:
        return self._vel

    @property
    def acc(self) -> float:
        return self._acc

    @property
    def jerk(self) -> float:
        return self._jerk

    @property
    def continuous(self) -> bool:
        return self._mode == _MOVE and self._end is None

    @property
    def time(self) -> float:
        """ms since the current profile started (re-plans start a new one)."""
        return self._k * self._T - self._t_off

    # --- commands -----------------------------------------------------------------------
    def start(
        self,
        pos: float,
        distance: float | None,
        prm: SCurveParams,
        direction: int = 1,
        *,
        decel: str = "auto",
        manual_dec: float = 0.0,
    ) -> None:
        """Drive ``distance`` pulses (>= 0; None: continuous) in ``direction`` (+1/-1)."""
        if not isinstance(prm, SCurveParams):
            raise ParameterError(f"prm must be SCurveParams, got {type(prm).__name__}")
        if direction not in (1, -1):
            raise ParameterError(f"direction={direction!r}: +1 or -1")
        if decel not in ("auto", "manual", "none"):
            raise ParameterError(f"decel={decel!r}: 'auto', 'manual' or 'none'")
        length = None if distance is None else checks.non_negative("distance", distance)
        self.hold(checks.real("pos", pos))
        self.prm = prm
        self._dir = direction
        self._decel, self._manual = decel, checks.non_negative("manual_dec", manual_dec)
        if length is not None:
            self._end = self._clamp = self._pos + direction * length
            if length == 0.0:
                return
        self.profile = plan_drive(length, prm, None, decel=decel, manual_dec=self._manual)
        self._mode = _MOVE
        self._vel = direction * self.profile.v_start
        if self.profile.pieces:  # the drive's state at its start: a status read before the
            a0, j = self.profile.pieces[0][3:5]  # first cycle sees it accelerating (D2)
            self._acc, self._jerk = direction * a0, direction * j

    def decelerate(self) -> None:
        """``dec_stop``: ramp down to SV (S: the acceleration to 0 first) and stop there;
        a constant-speed drive stops at once (the ADT850 manual 5.3)."""
        if self._mode != _MOVE or self.prm is None or self.decelerating:
            return
        prm = self.prm
        if prm.constant:
            self._finish(self._pos)
            return
        self.decelerating = True
        self._replan(None)

    def change_speed(self, vel: float) -> bool:
        """``set_speed`` while driving: re-plan toward ``vel``; False when refused (an S
        fixed drive, a constant-speed drive, decelerating)."""
        prm = self.prm
        if self._mode != _MOVE or prm is None or self.decelerating:
            return False
        if prm.constant or (prm.s_curve and self._end is not None):
            return False
        self.prm = SCurveParams(prm.vel_start, vel, prm.acc, prm.dec, prm.jerk, prm.triangle)
        if self.prm.constant:
            self.prm = prm
            return False
        self._replan(self.prm)
        return True

    def stop(
        self, dec: float, abrupt: bool = False, origin: tuple[float, float] | None = None
    ) -> None:
        """GT_Stop, a limit: the constant-deceleration stop ramp from the last sample."""
        if origin is None:
            if self._mode == _IDLE:
                return
            origin = (self._pos, self._vel)
        self._stop.start(origin[0], origin[1], dec)
        self._pos, self._vel = origin
        self._acc = self._jerk = 0.0
        self._mode = _STOP
        self.stopping = StopKind.ABRUPT if abrupt else StopKind.SMOOTH
        if self._stop.done:
            self._finish(self._pos)

    # --- cycle --------------------------------------------------------------------------
    def step(self) -> tuple[float, float, float]:
        """One controller cycle: ``(pos, vel, acc)``."""
        if self._mode == _MOVE:
            self._k += 1
            prof = self.profile
            assert prof is not None
            t = self.time
            if t >= prof.duration - _EPS_T * (1.0 + prof.duration * 1e-3):
                assert self._end is not None
                self._finish(self._end)
                return self._pos, 0.0, 0.0
            s, v, a, j, self._hint = prof.state(t, self._hint)
            g = self._dir
            p = self._base + g * s
            if self._clamp is not None:
                p = min(p, self._clamp) if g > 0 else max(p, self._clamp)
            self._pos, self._vel, self._acc, self._jerk = p, g * v, g * a, g * j
        elif self._mode == _STOP:
            self._pos, self._vel, self._acc = self._stop.step()
            if self._stop.done:
                self._finish(self._pos)
        return self._pos, self._vel, self._acc

    # --- internals ----------------------------------------------------------------------
    def _finish(self, pos: float) -> None:
        self._pos = pos
        self._vel = self._acc = self._jerk = 0.0
        self._mode = _IDLE
        self.decelerating = False

    def _replan(self, prm: SCurveParams | None) -> None:
        """Re-plan from the last sample: an S acceleration goes to 0 with the jerk first, then
        ``prm``'s drive (to the fixed drive's target, or on); ``prm`` None: down to SV, stop."""
        cur = self.prm
        assert cur is not None
        g = self._dir
        v, a = g * self._vel, g * self._acc
        j = cur.jerk
        pieces: list[Piece] = []
        t = s = 0.0
        if a != 0.0 and math.isfinite(j):
            p0 = (0.0, 0.0, v, a, -math.copysign(j, a))
            pieces.append(p0)
            t, s, v, _ = _advance(p0, abs(a) / j)
        v = max(v, 0.0)
        if prm is None:  # decelerate to SV and stop
            vs = cur.vel_start
            down = SCurveParams(vs, max(v, vs), cur.acc, cur.dec, j)
            dist = ramp_distance(v, vs, cur.dec, j) if v > vs else 0.0
            if self._clamp is not None:
                dist = min(dist, max(g * (self._clamp - self._pos) - s, 0.0))
            rest = plan_drive(dist, down, v, decel="auto")
            length: float | None = s + dist
        else:
            left = None if self._end is None else max(g * (self._end - self._pos) - s, 0.0)
            done = g * (self._pos - self._start) + s
            point = max(self._manual - done, 0.0)
            rest = plan_drive(left, prm, v, decel=self._decel, manual_dec=point)
            length = None if left is None else s + left
        for p in rest.pieces:
            pieces.append((p[0] + t, p[1] + s, p[2], p[3], p[4]))
        self._base = self._pos
        self._end = None if length is None else self._pos + g * length
        self.profile = DriveProfile(pieces, t + rest.duration, length, rest.v_end)
        self._t_off = self._k * self._T
        self._hint = 0


__all__ = [
    "DriveProfile",
    "SCurveParams",
    "SCurvePlanner",
    "plan_drive",
    "ramp_distance",
    "ramp_pieces",
    "ramp_time",
]
