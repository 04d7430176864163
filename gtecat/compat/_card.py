"""What the ADT850 and MCX314 layers share: one pulse card's registers over the controller's axes.

Both manuals describe MCX314-family chips: four step/dir axes X, Y, Z, W/U, each with a
range R (multiplier ``M = 8000000/R``), initial speed SV, drive speed V, acceleration A,
deceleration D and jerk parameter K as register values.  A :class:`PulseCard` keeps those
registers and turns them into controller units (ADT850 manual 3.1-3.6, MCX314 manual 4.4):

    speed PPS = V·M        acceleration PPS/s = A·125·M        jerk PPS/s² = 62.5e6/K·M

(pulse/ms = PPS/1000, pulse/ms² = PPS/s/1e6, pulse/ms³ = PPS/s²/1e9).  Drives run on the
controller core: a single-axis drive is the profile's :class:`~gtecat.controller.motion.
scurve.SCurvePlanner` (mode ``CARD_DRIVE``); an interpolation is a segment of coordinate
system 1 (X-Y, X-Y-Z, X-Y-Z-W) or 2 (Z-W) whose speed is planned in base pulses
(:mod:`gtecat.controller.crd.base_pulse`).  The card runs on the pulse-card personality
(``gts:4``, :mod:`gtecat.controller.card`).

Decisions where the manuals are silent:

* **Opening.**  The card is the controller ``GT_Open(card="gts:4", ...)`` opens; if one
  is open already (a test opened it with its machine and ``clock="lockstep"``), that one
  is used.  Opening switches the four amplifiers on (the manuals' cards drive from power-up)
  and turns off what a pulse card does not do: the following-error check, the alarm input
  (until enabled) and the controller's own soft limits.
* **Counters.**  The logic position counter (LP) is the axis planned position, the real
  position counter (EP) the encoder, both plus an offset that ``set_command_pos`` /
  ``LPS`` (and the EP twins) write at any time, moving nothing.
* **Inputs** of axis N come from the machine description of axis N: LMT+/LMT- its limit
  switches, STOP0 (ADT850) / IN0 (MCX314) the home switch, STOP1 / IN1 the encoder
  index (on in the cycle an index pulse passes), STOP2 / IN2 probe 1, ALARM the
  amplifier's fault, INPOS the amplifier standing within 1 pulse of the plan.
* **Electrical levels and logic settings** (ADT850 manual chapter 3 wiring, 1.1, 1.3-1.13,
  6.1; MCX314 manual 4.6).  Every input has an electrical level (0 low, 1 high), and the
  card sees a signal *active* when the level equals the signal's logic setting (0
  low-active, the power-up setting of all of them).  The level comes from the wiring:
  the amplifier's INPOS and ALARM outputs, the encoder's Z and the probe are pulled low
  while on (the open-collector / NPN wiring of chapter 3, for which the card's "n"
  signals are low-active); a limit or home switch is low while hit when the machine
  description says ``switch_wiring = "normally_open"``, high while hit when it says
  ``"normally_closed"``.  Decision, as for the GT layer's configuration files: a machine
  description that does not say how its switches are wired has them wired the way the
  program's logic setting expects (a hit switch is active, read at the active level).
  So a logic setting that disagrees with the wiring acts as on the card: a limit active
  everywhere but on the switch, an alarm while the amplifier is fine, a STOP1 search
  that ends at once.  The card, not the controller, stops at limits and alarms: at once
  (a sudden stop; an interpolation brakes at once along its path) or, with the
  limit's "decelerate" mode, as a decelerating stop.
* **INPOS** (ADT850 manual 1.12, 5 "伺服马达对应的信号", 9.5; MCX314 manual ``EnableInPos``): when
  valid, a drive whose pulses are out stays "driving" until the card sees INPOS active;
  an interpolation stays running until every axis of it does.  Not wired (or a stepper)
  and set valid, a drive never ends - as 9.5 warns.
* **A stop signal or a COMP register** (soft limit) stops the drive in its own shape:
  an accelerating drive decelerates to SV, a constant-speed drive stops at once (ADT850 manual
  1.3); an interpolation brakes along its path with the master axis's D.
* **Errors.**  ADT850 calls return the manual's codes and never raise; MCX314 calls are
  ``void`` in the manual: they return None and raise :class:`CompatError` (a
  ParameterError) naming the manual's range.  :func:`last_error` gives the reason of the
  last failure of either.
"""

from __future__ import annotations

import ctypes
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from gtecat.drives.faults import forced_level

from ..controller.crd import bank, make_arc
from ..controller.crd.base_pulse import BaseSpeed, base_length
from ..controller.crd.path import CCW, CW, Line, Segment
from ..controller.crd.system import CoordSystem, CrdParams, Motion
from ..controller.epoch import changed as readers_changed
from ..controller.motion.scurve import SCurveParams, SCurvePlanner, plan_drive
from ..controller.motion.stop import STOP_DEC_MAX, StopDecel
from ..controller.profile import PrfMode
from ..controller.resources import AxisResources, axis_resources
from ..errors import CommandError, ParameterError

AXES = (1, 2, 3, 4)
R_BASE = 8_000_000
#: the eight inputs of an axis, in the order of the ADT850's read_di bits (6.1)
SIGNALS = ("LMT+", "LMT-", "STOP0", "STOP1", "STOP2", "INPOS", "ALARM", "IN")
LMTP, LMTM, STOP0, STOP1, STOP2, INPOS, ALARM, GPIN = range(8)
#: get_status bit while a drive waits without pulses (INPOS, Z/W after a broken interpolation)
WAITING = 0x100
LIMIT_NEG, LIMIT_POS, HOME = 0x1, 0x2, 0x4  # 60FDh bits
_PROBE1 = 1 << 16  # 60FDh probe input 1
#: the abrupt stop of "immediate" limits and sudden stops, pulse/ms² (GT_SetStopDec's maximum)
IMMEDIATE = STOP_DEC_MAX


class CompatError(ParameterError):
    """A card function called outside what its manual documents (MCX314 layer: raised)."""


_LAST: list[str] = [""]


def last_error() -> str:
    """The reason of the most recent failed compat call ("" when none failed)."""
    return _LAST[0]


def set_last_error(reason: str) -> None:
    _LAST[0] = reason


def out(ptr: Any, value: Any) -> None:
    """``*ptr = value`` for ctypes ``byref``/``pointer``/instances and one-element lists."""
    if ptr is None:
        raise CompatError("a NULL pointer was passed for an output")
    obj = getattr(ptr, "_obj", None)  # byref(x)
    if obj is not None:
        ptr = obj
    if isinstance(ptr, ctypes._Pointer):
        ptr = ptr.contents
    if isinstance(ptr, ctypes._SimpleCData):
        ptr.value = value
        return
    if isinstance(ptr, list):
        if not ptr:
            ptr.append(value)
        else:
            ptr[0] = value
        return
    raise CompatError(f"cannot write an output through {type(ptr).__name__}")


def integer(name: str, value: Any, lo: int, hi: int) -> int:
    """An integer in ``[lo, hi]`` (the manual's range) or CompatError.

    Like the GT layer's argument checks, a float is refused even when it is integral (1.0):
    the manuals' parameters are C integers, and a float there is a caller's mistake."""
    if isinstance(value, bool) or not isinstance(value, int):
        raise CompatError(f"{name}={value!r}: an integer is expected")
    if not lo <= value <= hi:
        raise CompatError(f"{name}={value} out of the manual's range {lo}..{hi}")
    return int(value)


def real(name: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise CompatError(f"{name}={value!r}: a number is expected")
    x = float(value)
    if not math.isfinite(x):
        raise CompatError(f"{name}={value!r}: a finite number is expected")
    return x


@dataclass(slots=True)
class AxisRegs:
    """One axis's registers, as the manuals' chips hold them (defaults: decided, see above)."""

    m: float = 1.0  #: multiplier M = 8000000 / R
    sv: int = 1
    v: int = 1
    a: int = 1
    d: int = 1
    k: int = 1
    s_curve: bool = False
    asym: bool = False  #: decelerate with D (else with A)
    manual: bool = False  #: manual deceleration at ``dec_pos``
    dec_pos: int = 0
    lp_off: float = 0.0
    ep_off: float = 0.0
    comp: list[int] = field(default_factory=lambda: [0, 0])  #: COMP+, COMP-
    soft: list[bool] = field(default_factory=lambda: [False, False])
    soft_ep: bool = False  #: COMP registers compare with EP (else LP)
    limit_decel: bool = False
    stop_on: list[bool] = field(default_factory=lambda: [False, False, False])
    #: the active level of each input (SIGNALS order): 0 low, 1 high (all low at power-up)
    logic: list[int] = field(default_factory=lambda: [0] * 8)
    inpos_on: bool = False  #: a drive ends only when INPOS is active
    alarm_on: bool = False  #: ALARM stops a drive at once
    await_inpos: bool = False  #: the pulses of a drive are out; INPOS is awaited
    #: registers by name: the real counter's mode, end points, settings kept without effect
    settings: dict[str, Any] = field(default_factory=dict)
    stopdata: int = 0
    stopped_by_user: bool = False
    last_acc: float = 0.0  #: pulse/ms², the last nonzero acceleration of a drive
    ring: bool = False  #: variable ring counters: LP in 0..COMP+, EP in 0..COMP- (4.3)

    def vel(self, value: float | None = None) -> float:
        """pulse/ms of a speed register value."""
        return (self.v if value is None else value) * self.m / 1000.0

    def params(self, triangle: bool = False) -> SCurveParams:
        """The drive's curve from the registers (ADT850 manual 3.1-3.6)."""
        acc = self.a * 125.0 * self.m / 1e6
        dec = (self.d if self.asym else self.a) * 125.0 * self.m / 1e6
        jerk = 62.5e6 / self.k * self.m / 1e9 if self.s_curve else math.inf
        return SCurveParams(self.vel(self.sv), self.vel(), acc, dec, jerk, triangle)


def _ring(value: float, top: int | None) -> float:
    """A counter with the variable ring on: it counts 0..``top`` and wraps both ways
    (ADT850 manual 4.3: COMP+ the logic counter's, COMP- the real counter's largest value)."""
    if top is None or top < 0:
        return value
    return value % (top + 1)


class PulseCard:
    """One opened card: the controller, the registers of its four axes, the outputs."""

    def __init__(self, ctl: Any, name: str) -> None:
        self.ctl = ctl
        self.name = name
        self.regs = {n: AxisRegs() for n in AXES}
        self.outputs = 0
        self.general_inputs = 0  #: the IN terminals (nothing in the machine drives them)
        #: a STOP2 stop clears the real position counter at the signal (ADT850 1.5, 9.4)
        self.stop2_clears_ep = False
        self.cycle_ms = ctl.clock.cycle_ns / 1e6
        self._index_seen = dict.fromkeys(AXES, False)
        self._was_pulsing = dict.fromkeys(AXES, False)
        #: cards whose controllers run one cycle after each of this card's (multi-card)
        self.followers: list[PulseCard] = []
        #: the layer's own state of this card (adt850: interpolation settings)
        self.layer: Any = None
        for n in AXES:
            r = self.res(n)
            r.safety.pos_err = 2**31  # an open-loop pulse card has no following-error check
            r.safety.alarm_on = False  # the card watches ALARM and the limits itself
            r.safety.positive_on = r.safety.negative_on = False
            r.clear_flags()
            self._limit_mode(n)
        ctl.post_cycle.append(self._post)
        readers_changed()  # (the axes' flags changed without a GT call: controller/epoch.py)

    # --- access -------------------------------------------------------------------------
    def res(self, axis: int) -> AxisResources:
        return axis_resources(self.ctl, axis)

    def tick(self) -> None:
        """A host call happened (auto clock: it costs virtual time, so polling loops end)."""
        self.ctl.clock.on_call()

    def wait_cycle(self) -> None:
        self.ctl.clock.advance_ns(self.ctl.clock.cycle_ns)

    def close(self) -> None:
        if self._post in self.ctl.post_cycle:
            self.ctl.post_cycle.remove(self._post)
        for f in self.followers:
            f.close()
            f.ctl.close()
        self.followers = []

    # --- counters -----------------------------------------------------------------------
    def lp(self, axis: int) -> float:
        regs = self.regs[axis]
        return _ring(self.res(axis).ax.prf_pos + regs.lp_off, regs.comp[0] if regs.ring else None)

    def counted(self, axis: int) -> float:
        """The encoder as the real position counter counts it (ADT850 manual 1.6, MCX314 manual
        ``EncoderMode``/``EncoderCWCCW``): the direction (1: reversed) and, for A/B input,
        the multiplication (4x is the encoder's own count; 2x half of it, 1x a quarter).

        Decision: the emulated amplifiers give A/B quadrature (chapter 3's encoder
        wiring).  Set to up/down pulse input (value 1), the counter takes A as up and B
        as down pulses: one up and one down per period, so it holds its reading."""
        value, direction, freq = self.count_mode(axis)
        scale = (1.0, 0.5, 0.25)[freq] if value == 0 else 0.0
        return (-1.0 if direction else 1.0) * scale * self.res(axis).enc_pos

    def count_mode(self, axis: int, *mode: int) -> tuple[int, int, int]:
        """The real counter's ``(input, direction, multiplication)``; with ``mode`` given,
        set them (any of the three, None keeps it), the counter keeping its reading."""
        old = self.regs[axis].settings.get("count_mode", (0, 0, 0))
        if not mode:
            return old
        keep = self.ep(axis)
        new = tuple(o if v is None else v for o, v in zip(old, mode, strict=True))
        self.regs[axis].settings["count_mode"] = new
        self.set_ep(axis, round(keep))
        return new

    def ep(self, axis: int) -> float:
        regs = self.regs[axis]
        return _ring(self.counted(axis) + regs.ep_off, regs.comp[1] if regs.ring else None)

    def set_lp(self, axis: int, value: int) -> None:
        self.regs[axis].lp_off = value - self.res(axis).ax.prf_pos

    def set_ep(self, axis: int, value: int) -> None:
        self.regs[axis].ep_off = value - self.counted(axis)

    def speed(self, axis: int) -> float:
        """The axis's current speed in V units (PPS / M)."""
        r = self.res(axis)
        return abs(r.prf_vel) * 1000.0 / self.regs[axis].m

    def accel(self, axis: int, held: bool = False) -> float:
        """The current acceleration in A units (PPS/s / (125·M)); ``held``: the last
        nonzero one while the acceleration is 0 (a register that holds its value)."""
        r = self.res(axis)
        acc = abs(r.prf_acc) or (self.regs[axis].last_acc if held else 0.0)
        return acc * 1e6 / (125.0 * self.regs[axis].m)

    # --- inputs -------------------------------------------------------------------------
    def din(self, axis: int) -> int:
        acc = self.res(axis).ax.io.get(0x60FD)
        return acc.get() if acc is not None else 0

    def _machine(self, axis: int) -> Any:
        ch = self.ctl.backend.drive(axis).channel(0)
        return ch.machine, ch.machine_position

    def source_on(self, axis: int, k: int) -> bool:
        """Whether the source of input ``k`` (:data:`SIGNALS`) is on: the machine's switch
        hit, the index passing this cycle, the probe mark, the amplifier in position or in
        fault.  Nothing drives the general input IN."""
        if k in (LMTP, LMTM):
            return bool(self.din(axis) & (LIMIT_POS if k == LMTP else LIMIT_NEG))
        if k == STOP0:
            return bool(self.din(axis) & HOME)
        if k == STOP1:
            return self._index_seen[axis]
        if k == STOP2:  # (the machine's mark, as the field leaves it: probe_missing)
            ch = self.ctl.backend.drive(axis).channel(0)
            on = _PROBE1 if ch.machine.probe_active(1, ch.machine_position) else 0
            return bool(forced_level(on, *ch.forced_switches()) & _PROBE1)
        if k == INPOS:
            r = self.res(axis)
            return r.profile.planner.done and abs(r.axis_error) <= 1.0
        if k == ALARM:
            return self.res(axis).drive_faulted()
        return bool(self.general_inputs >> (axis - 1) & 1)

    def level(self, axis: int, k: int) -> int:
        """The electrical level of input ``k`` (0 low, 1 high): module docstring,
        "Electrical levels".  A switch (limits, STOP0) is low while hit when normally
        open, high when normally closed, and wired as the logic setting expects where
        the machine description does not say; the other signals are low while on."""
        on = self.source_on(axis, k)
        if k in (LMTP, LMTM, STOP0):
            wiring = self._machine(axis)[0].switch_wiring
            nc = self.regs[axis].logic[k] == 1 if wiring is None else wiring == "normally_closed"
            return int(on == nc)
        return 0 if on else 1

    def active(self, axis: int, k: int) -> bool:
        """Whether the card sees input ``k`` active: its level equals its logic setting."""
        return self.level(axis, k) == self.regs[axis].logic[k]

    def limit(self, axis: int, positive: bool) -> bool:
        return self.active(axis, LMTP if positive else LMTM)

    def stop_input(self, axis: int, k: int) -> bool:
        """STOP0/1/2 (IN0/1/2) as the card sees it (its logic setting applied)."""
        return self.active(axis, STOP0 + k)

    def signal_ahead(self, axis: int, k: int, direction: int, limits: bool = True) -> bool:
        """Whether a search in ``direction`` can meet STOP``k`` (or, with ``limits``, a
        limit switch): the machine description has a home-switch window (STOP0), an index
        (STOP1) or a probe mark (STOP2) ahead, or a limit switch in that direction.  A
        signal the card sees active where its source is off (a logic setting against the
        wiring) counts as met."""
        m, at = self._machine(axis)
        if limits and (m.positive_limit if direction > 0 else m.negative_limit) is not None:
            return True
        if k < 3 and self.active(axis, STOP0 + k) != self.source_on(axis, STOP0 + k):
            return True
        if k == 1:
            return m.index_offset is not None
        if k == 0:
            return any((hi > at) if direction > 0 else (lo <= at) for lo, hi in m.home_switch)
        if k == 2:
            return any((hi > at) if direction > 0 else (lo <= at) for lo, hi in m.probe1)
        return False

    def alarm(self, axis: int) -> bool:
        """The ALARM input as the card sees it (whether or not it is valid)."""
        return self.active(axis, ALARM)

    def inpos(self, axis: int) -> bool:
        return self.active(axis, INPOS)

    # --- state --------------------------------------------------------------------------
    def crd_of(self, axis: int) -> CoordSystem | None:
        """The running coordinate system that moves ``axis``."""
        for c in bank(self.ctl).systems.values():
            if c.running and c.prm is not None and axis in c.prm.axes():
                return c
        return None

    def pulsing(self, axis: int) -> bool:
        """The axis puts out pulses (a drive or an interpolation runs it)."""
        return not self.res(axis).profile.planner.done

    def driving(self, axis: int) -> bool:
        """The drive is not over: pulses, or (INPOS valid) pulses out and INPOS awaited."""
        if self.pulsing(axis):
            return True
        regs = self.regs[axis]
        if regs.await_inpos and (not regs.inpos_on or self.inpos(axis)):
            regs.await_inpos = False
        return regs.await_inpos

    def planner(self, axis: int) -> SCurvePlanner | None:
        p = self.res(axis).profile.planner
        return p if isinstance(p, SCurvePlanner) else None

    def phase(self, axis: int) -> tuple[float, float, bool]:
        """``(acc, jerk, s_curve)`` of the axis's drive now (interpolations: of the path)."""
        c = self.crd_of(axis)
        if c is not None:
            plan = c.plan
            if c.stopping:
                return -1.0, 0.0, False
            if isinstance(plan, BaseSpeed):
                _, _, a, j = plan.state(c.t)
                return a, j, any(p[4] != 0.0 for p in plan.profile.pieces)
            return 0.0, 0.0, False
        p = self.planner(axis)
        if p is None:
            r = self.res(axis)
            return r.prf_acc, 0.0, False
        s = p.prm is not None and p.prm.s_curve
        g = 1.0 if p.vel >= 0 else -1.0
        return g * p.acc, g * p.jerk, s

    def status_word(self, axis: int) -> int:
        """ADT850 get_status / the chip's drive bits: 0 when the drive is over (module doc);
        :data:`WAITING` alone while the pulses are out and INPOS is awaited."""
        if not self.driving(axis):
            return 0
        if not self.pulsing(axis):
            return WAITING
        regs = self.regs[axis]
        src = self.ep(axis) if regs.soft_ep else self.lp(axis)
        w = 0
        if src >= regs.comp[0]:
            w |= 0x01
        if src >= regs.comp[1]:
            w |= 0x02
        a, j, s = self.phase(axis)
        eps = 1e-12
        if a > eps or (a >= -eps and j > 0):  # a ramp's first instant: a = 0, jerk > 0
            w |= 0x04
        elif a < -eps or j < 0:
            w |= 0x10
        else:
            w |= 0x08
        if s and (a > eps or a < -eps or j != 0.0):
            mag_grows = (a > eps and j > 0) or (a < -eps and j < 0) or abs(a) <= eps
            w |= 0x20 if mag_grows and j != 0.0 else 0x40 if j == 0.0 else 0x80
        return w

    # --- drives -------------------------------------------------------------------------
    def _limit_mode(self, axis: int) -> None:
        regs = self.regs[axis]
        dec = regs.params().dec if regs.limit_decel else IMMEDIATE
        prof = self.res(axis).profile
        prof.stop_dec = StopDecel(prof.stop_dec.smooth, min(max(dec, 1e-9), IMMEDIATE))

    def drive(self, axis: int, distance: int | None, direction: int) -> None:
        """``pmove`` / ``continue_move`` / TCurve_* / SCurve_*: one axis, registers' curve."""
        if self.crd_of(axis) is not None:
            raise CommandError(f"axis {axis} moves in an interpolation; stop it first")
        r = self.res(axis)
        regs = self.regs[axis]
        prof = r.profile
        if prof.mode != PrfMode.CARD_DRIVE:
            if not prof.planner.done:
                prof.stop(abrupt=True)
                raise CommandError(f"axis {axis} moves in another mode; it is being stopped")
            prof.enter(PrfMode.CARD_DRIVE, factory=lambda: SCurvePlanner(self.cycle_ms))
        regs.stopdata = 0
        regs.stopped_by_user = False
        blocked = self._blocked(axis, direction)
        if blocked:
            regs.stopdata = blocked  # the chip takes the command and ends it at once
            return
        r.clear_flags()
        r.check_motion(f"{self.name} drive", float(direction))
        regs.await_inpos = True
        self._limit_mode(axis)
        planner = prof.planner
        assert isinstance(planner, SCurvePlanner)
        prm = regs.params(triangle=distance is not None and not regs.s_curve)
        planner.start(
            planner.pos,
            None if distance is None else float(distance),
            prm,
            direction,
            decel="manual" if regs.manual else "auto",
            manual_dec=float(regs.dec_pos),
        )

    def _blocked(self, axis: int, direction: int) -> int:
        """The error bits (get_stopdata D3/D4 limits, D5 alarm, D6/D7 COMP registers) of a
        drive that cannot start: toward an active limit, with the alarm input on and
        active, or past a soft limit in its direction.

        Decision (ADT850 manual 5.x and chapter 8 say a drive "stops" at a limit; 1 is kept for
        a wrong card or axis): the command is accepted (0) and the drive ends at once with
        its stop bit, as the chip does; ``get_status`` reads 0, ``get_stopdata`` why."""
        regs = self.regs[axis]
        if direction > 0 and self.limit(axis, True):
            return 0x08
        if direction < 0 and self.limit(axis, False):
            return 0x10
        if regs.alarm_on and self.alarm(axis):
            return 0x20
        if regs.ring:
            return 0  # the ring uses COMP+/COMP- as its tops: no soft limits (4.3)
        src = self.ep(axis) if regs.soft_ep else self.lp(axis)
        if direction > 0 and regs.soft[0] and src >= regs.comp[0]:
            return 0x40
        if direction < 0 and regs.soft[1] and src < regs.comp[1]:
            return 0x80
        return 0

    def decel_stop(self, axis: int) -> None:
        c = self.crd_of(axis)
        if c is not None:
            c.stop(False)
            return
        p = self.planner(axis)
        self.regs[axis].stopped_by_user = True
        if p is not None:
            p.decelerate()
        else:
            self.res(axis).stop(False)

    def sudden_stop(self, axis: int) -> None:
        c = self.crd_of(axis)
        if c is not None:
            c.stop_dec = StopDecel(c.stop_dec.smooth, IMMEDIATE)
            c.stop(True)
            return
        self.regs[axis].stopped_by_user = True
        p = self.planner(axis)
        if p is not None and not p.done:
            p.hold(p.pos)  # the pulses stop at once
        else:
            self.res(axis).stop(True)

    def change_speed(self, axis: int) -> None:
        p = self.planner(axis)
        if p is not None and not p.done:
            p.change_speed(self.regs[axis].vel())

    # --- interpolation ------------------------------------------------------------------
    def system(self, axes: list[int], master: int) -> CoordSystem:
        """The coordinate system for ``axes`` (1 unless Z-W), configured when needed."""
        crd = 2 if axes == [3, 4] else 1
        c = bank(self.ctl).get(crd)
        same = c.prm is not None and c.prm.axes() == axes
        slots = c.slots if same else []
        if same and all(self.res(n).profile.planner is s for n, s in zip(axes, slots, strict=True)):
            return c
        if c.running:
            raise CommandError(f"an interpolation of axes {c.prm.axes()} is running")
        for other in bank(self.ctl).systems.values():
            if other is not c and other.running and set(other.prm.axes()) & set(axes):
                raise CommandError(f"axes {other.prm.axes()} move in another interpolation")
        prof = [0] * 8
        for coord, n in enumerate(axes, 1):
            prof[n - 1] = coord
            r = self.res(n)
            if not r.profile.planner.done:
                raise CommandError(f"axis {n} is driving: interpolation needs it standing")
            r.clear_flags()
        prm = CrdParams(len(axes), tuple(prof), 1e9, 1e9)
        c.configure(prm, {n: self.res(n).profile for n in axes})
        regs = self.regs[master]
        c.stop_dec = StopDecel(min(max(regs.params().dec, 1e-9), IMMEDIATE), IMMEDIATE)
        return c

    def interpolate(
        self,
        axes: list[int],
        master: int,
        make: Callable[[tuple[float, ...]], Segment],
        prm: SCurveParams,
        decel: str,
        manual_dec: float = 0.0,
    ) -> CoordSystem:
        """Push one node (relative geometry from the FIFO's tail) and start if standing."""
        c = self.system(axes, master)
        geom = make(c.tail(0))

        def plan(g: Segment, v0: float, prev: Any) -> BaseSpeed:
            vb = prev.base_v_end if isinstance(prev, BaseSpeed) and v0 > 0.0 else None
            return BaseSpeed(
                g, plan_drive(base_length(g), prm, vb, decel=decel, manual_dec=manual_dec)
            )

        c.push(Motion(geom, 1.0, 1.0, 0.0, speed_plan=plan), 0)
        if not c.running:
            t0 = geom.tangent(False) if geom.length else None
            for coord, n in enumerate(axes):
                r = self.res(n)
                r.check_motion(f"{self.name} interpolation", t0[coord] if t0 else 0.0)
                self.regs[n].stopdata = 0
                self.regs[n].stopped_by_user = False
                self.regs[n].await_inpos = True
            c.start(0)
        return c

    @staticmethod
    def line(delta: tuple[int, ...]) -> Callable[[tuple[float, ...]], Segment]:
        def make(start: tuple[float, ...]) -> Segment:
            return Line(start, tuple(a + b for a, b in zip(start, delta, strict=True)))

        return make

    @staticmethod
    def arc(end: tuple[int, int], center: tuple[int, int], ccw: bool) -> Callable:
        """An arc (end and centre relative to the start); an end off the circle ends on the
        circle at the end's angle (the chips end an arc on their circle, ADT850 manual 5.2),
        rounded to whole pulses."""

        def make(start: tuple[float, ...]) -> Segment:
            cx, cy = start[0] + center[0], start[1] + center[1]
            r = math.hypot(center[0], center[1])
            if r == 0.0:
                raise CompatError("the arc's centre lies on its start point (radius 0)")
            ex, ey = start[0] + end[0], start[1] + end[1]
            if (end[0], end[1]) != (0, 0):
                d = math.hypot(ex - cx, ey - cy)
                if d == 0.0:
                    raise CompatError("the arc's end lies on its centre")
                if abs(d - r) > 0.5:
                    ex = round(cx + (ex - cx) * r / d)
                    ey = round(cy + (ey - cy) * r / d)
            return make_arc(start, (ex, ey), (cx, cy), (0, 1), CCW if ccw else CW)

        return make

    # --- the cycle: stop signals, COMP registers, why a drive stopped --------------------
    def _post(self, t_ns: int, dt_ns: int) -> None:
        edges = getattr(self.ctl.backend, "edges", {})
        for n in AXES:
            self._index_seen[n] = any(e.signal == "index" for e in edges.get(n, ()))
        for n in AXES:
            was, self._was_pulsing[n] = self._was_pulsing[n], self.pulsing(n)
            if not self._was_pulsing[n]:
                if was and self.regs[n].alarm_on and self.alarm(n):
                    self.regs[n].stopdata |= 0x20  # the amplifier's fault ended the pulses
                if self.regs[n].await_inpos:
                    self.driving(n)  # the drive ends in the cycle INPOS is seen
                continue
            regs = self.regs[n]
            r = self.res(n)
            v = r.prf_vel
            if r.prf_acc:
                regs.last_acc = abs(r.prf_acc)  # the CA register holds it at constant speed
            bits = 0
            for k in range(3):
                if regs.stop_on[k] and self.stop_input(n, k):
                    bits |= 1 << k
            if v > 0 and self.limit(n, True):
                bits |= 0x08
            if v < 0 and self.limit(n, False):
                bits |= 0x10
            if regs.alarm_on and self.alarm(n):
                bits |= 0x20
            src = self.ep(n) if regs.soft_ep else self.lp(n)
            if not regs.ring and regs.soft[0] and v > 0 and src >= regs.comp[0]:
                bits |= 0x40
            if not regs.ring and regs.soft[1] and v < 0 and src < regs.comp[1]:
                bits |= 0x80
            if not bits:
                continue
            if bits & 0x04 and self.stop2_clears_ep and not regs.stopdata & 0x04:
                self.set_ep(n, 0)  # the counter clears at the signal; the stop comes after
            regs.stopdata |= bits
            if bits & 0x20 or (bits & 0x18 and not regs.limit_decel):
                self._halt(n)  # ALARM, and limits in their "immediate" mode: at once
            else:
                self._signal_stop(n)
        for f in self.followers:
            f.ctl.clock.cycle()  # the other cards of the PC keep this card's time

    def _halt(self, axis: int) -> None:
        """The card's immediate stop of a drive (an interpolation: at once on its path)."""
        c = self.crd_of(axis)
        if c is not None:
            c.stop_dec = StopDecel(c.stop_dec.smooth, IMMEDIATE)
            c.stop(True)
            return
        p = self.planner(axis)
        if p is not None and not p.done:
            p.hold(p.pos)
        else:
            self.res(axis).stop(True)

    def _signal_stop(self, axis: int) -> None:
        c = self.crd_of(axis)
        if c is not None:
            if not c.stopping:
                c.stop(False)
            return
        p = self.planner(axis)
        if p is None or p.done:
            return
        if p.prm is not None and p.prm.constant:
            p.hold(p.pos)
        else:
            p.decelerate()


def open_card(name: str, **options: Any) -> PulseCard:
    """The controller's card (module docstring, "Opening"); raises what GT_Open reports."""
    from ..gt import (
        _core,
        bus_calls,  # noqa: F401  (registers GT_Open)
    )

    ctl = _core.SESSION.controllers.get(1)
    if ctl is None:
        options.setdefault("card", "gts:4")
        options.setdefault("log", "")
        rc = _core.REGISTRY["GT_Open"](**options)
        if rc != 0:
            why = _core.last_error()
            raise CommandError(f"GT_Open returned {rc}: {why.reason if why else ''}")
        ctl = _core.SESSION.controller(1)
    if ctl.card is None:
        raise CommandError("the open controller is an EtherCAT master, not a pulse card")
    if len(ctl.axes) < 4:
        raise CommandError(f"{name} needs a 4-axis card; the open card has {len(ctl.axes)}")
    for n in AXES:
        if not ctl.axes[n].servo_on:
            rc = _core.REGISTRY["GT_AxisOn"](n)
            if rc != 0:
                why = _core.last_error()
                raise CommandError(
                    f"axis {n}: GT_AxisOn returned {rc}: {why.reason if why else ''}"
                )
    return PulseCard(ctl, name)


def open_follower(base: PulseCard, name: str, machine: Any = None) -> PulseCard:
    """Another card in the same PC (multi-card): a controller of its own, a ``gts:4`` card
    with ``machine`` (None: no switches, whatever ``GTECAT_MACHINE`` says), whose cycles
    run with ``base``'s, one after each of its cycles, so the cards share one time.
    ``base.close()`` closes it."""
    from ..controller.core import Controller, Options
    from ..drives.machine import MachineDescription
    from ..gt.axis_calls import axis_on

    ctl = Controller(
        Options(
            card="gts:4",
            machine=MachineDescription() if machine is None else machine,  # not GTECAT_MACHINE
            clock="lockstep",
            backend="emulated",
            log="",
            cycle_ms=base.cycle_ms,
        )
    )
    try:
        for n in AXES:
            axis_on(ctl, ctl.axis(n))
        card = PulseCard(ctl, name)
    except Exception:
        ctl.close()
        raise
    base.followers.append(card)
    return card


__all__ = [
    "AXES",
    "AxisRegs",
    "CompatError",
    "PulseCard",
    "last_error",
    "open_card",
    "out",
]
