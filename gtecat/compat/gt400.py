"""The legacy GT-400 card (``gt400.dll``) over our axes: ``from gtecat.compat import gt400``.

The GT-400 library addresses a *current axis*: ``GT_Axis(n)`` selects it, then
``GT_PrflT`` / ``GT_PrflS`` / ``GT_PrflV`` choose its profile, ``GT_SetPos`` ``GT_SetVel``
``GT_SetAcc`` ``GT_SetMAcc`` ``GT_SetJerk`` set it and ``GT_Update`` starts it; the names
and argument lists are the vendor's ``gt400.h`` (``short __stdcall``, no ``cardNum``, no
axis argument).  Units are the controller's: pulse, pulse/ms, pulse/ms², pulse/ms³.  Calls
return 0, or 1 with a reason (:func:`gtecat.compat.last_error`) when the card cannot do it,
7 for a value outside the call's range; they never raise.

The card is the ``gts:4`` pulse-card personality (:mod:`gtecat.controller.card`): four
axes with the machine description's switches.  Decisions where the vendor is silent:

* **Opening.**  ``GT_Open()`` opens a ``gts:4`` card (``GT_Open(**options)`` takes the
  GT layer's keywords: ``machine=``, ``clock=``) or uses the pulse card already open;
  the current axis is 1.  Axes stay off until ``GT_AxisOn``.  ``GT_Close`` releases it.
* **Profiles.**  T: a trapezoid with ``GT_SetAcc``; S: a jerk-limited curve, acceleration
  up to ``GT_SetMAcc``, jerk ``GT_SetJerk`` (the controller's S-curve planner, exact to
  the target); V: a velocity move at ``GT_SetVel`` (its sign the direction) with
  ``GT_SetAcc``, until a stop.  A profile's parameters default to acc 0.01, MAcc 0.01,
  jerk 0.0001, vel 0 (``GT_Update`` with vel 0 returns 1).  ``GT_Update`` while the axis
  moves in the same profile re-plans from where it is (a new target or speed); in another
  profile it returns 1.  ``GT_MltiUpdt(mask)`` updates the axes of ``mask`` (bit 0 = 1).
* **Stops.**  ``GT_SmthStp``: down with the profile's own deceleration (T/V: acc; S: the
  S ramp); ``GT_AbptStp``: at once (the controller's abrupt stop).
* **Status** (``GT_GetSts``, 16 bits): bit 0 motion complete (set when a motion ends,
  cleared by ``GT_ClrSts`` and ``GT_Update``), bit 1 drive alarm, bit 4 following error,
  bits 5/6 positive/negative limit, bit 10 moving - the positions field applications
  test (``sts & 0x1``, ``sts & 0x400``) and the GTS table 6-2 kept the others.
* **General IO** are Googol's active-low terminals: ``GT_ExInpt`` bit i is 0 while input
  EXI i is active (``GTE_SetGpi(i + 1, 1)`` on the GT layer); ``GT_ExOpt`` / ``GT_ExOptBit``
  write levels, 0 switching the output on (``GT_GetDo(MC_GPO)`` of the GT layer shows the
  outputs that are on, bit i = EXO i).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from ..controller.digital_io import digital_io
from ..controller.epoch import changed as readers_changed
from ..controller.motion.scurve import SCurveParams, SCurvePlanner
from ..controller.profile import PrfMode
from ..controller.resources import AxisResources, axis_resources
from ..errors import CommandError, ParameterError
from ._card import CompatError, integer, out, real, set_last_error

AXES = (1, 2, 3, 4)
#: GT_GetSts bits (module docstring)
STS_DONE, STS_ALARM, STS_ERROR, STS_POS_LIMIT, STS_NEG_LIMIT, STS_MOVING = (
    0x1,
    0x2,
    0x10,
    0x20,
    0x40,
    0x400,
)
_FROM_GTS = STS_ALARM | STS_ERROR | STS_POS_LIMIT | STS_NEG_LIMIT


@dataclass(slots=True)
class _Axis:
    mode: str = "T"
    pos: int = 0
    vel: float = 0.0
    acc: float = 0.01
    macc: float = 0.01
    jerk: float = 0.0001
    done: bool = False
    was_moving: bool = False


class _Card:
    def __init__(self, ctl: Any) -> None:
        self.ctl = ctl
        self.axis = 1
        self.axes = {n: _Axis() for n in AXES}
        self.outputs = 0xFFFF  # levels: every output off
        self.cycle_ms = ctl.clock.cycle_ns / 1e6
        ctl.post_cycle.append(self._post)

    def res(self, n: int | None = None) -> AxisResources:
        return axis_resources(self.ctl, self.axis if n is None else n)

    def _post(self, t: int, dt: int) -> None:
        for n, a in self.axes.items():
            moving = self.res(n).moving
            if a.was_moving and not moving:
                a.done = True
            a.was_moving = moving

    def close(self) -> None:
        if self._post in self.ctl.post_cycle:
            self.ctl.post_cycle.remove(self._post)


_CARD: list[_Card | None] = [None]


def _api(fn: Callable[..., int | None]) -> Callable[..., int]:
    """The library's return codes: 0, 1 (cannot), 7 (a value out of range); never raises."""

    @functools.wraps(fn)
    def call(*args: Any, **kwargs: Any) -> int:
        try:
            rc = fn(*args, **kwargs)
        except (CompatError, ParameterError) as e:
            set_last_error(f"{fn.__name__}: {e}")
            rc = 7
        except Exception as e:  # the vendor's C API never raises
            set_last_error(f"{fn.__name__}: {e}")
            rc = 1
        readers_changed()  # (the card changed without a GT call: controller/epoch.py)
        card = _CARD[0]
        if card is not None:
            card.ctl.clock.on_call()
        return 0 if rc is None else rc

    return call


def _card() -> _Card:
    card = _CARD[0]
    if card is None:
        raise CommandError("the card is not open: call GT_Open first")
    return card


# --- opening, axes --------------------------------------------------------------------------
@_api
def GT_Open(**options: Any) -> int:
    """Open the GT-400 card (a ``gts:4`` pulse card; the GT layer's keywords pass through)."""
    from ..gt import _core, bus_calls  # noqa: F401  (registers GT_Open)

    if _CARD[0] is not None:
        _CARD[0].close()
        _CARD[0] = None
    ctl = _core.SESSION.controllers.get(1)
    if ctl is None:
        options.setdefault("card", "gts:4")
        options.setdefault("log", "")
        rc = _core.REGISTRY["GT_Open"](**options)
        if rc != 0:
            why = _core.last_error()
            raise CommandError(f"GT_Open returned {rc}: {why.reason if why else ''}")
        ctl = _core.SESSION.controller(1)
    if ctl.card is None or len(ctl.axes) < 4:
        raise CommandError("the open controller is not a 4-axis pulse card (gts:4)")
    _CARD[0] = _Card(ctl)
    return 0


@_api
def GT_Close() -> int:
    _card().close()
    _CARD[0] = None
    return 0


@_api
def GT_Axis(axis: int) -> int:
    """The current axis (1..4)."""
    _card().axis = integer("axis", axis, 1, 4)
    return 0


def _gt(name: str, *args: Any) -> None:
    """A GT-layer call on the current card; CommandError with its reason when it fails."""
    from ..gt import _core

    rc = _core.REGISTRY[name](*args)
    if rc != 0:
        why = _core.last_error()
        raise CommandError(why.reason if why else f"{name} returned {rc}")


@_api
def GT_AxisOn() -> int:
    _gt("GT_AxisOn", _card().axis)
    return 0


@_api
def GT_AxisOff() -> int:
    _gt("GT_AxisOff", _card().axis)
    return 0


@_api
def GT_ClrSts() -> int:
    card = _card()
    _gt("GT_ClrSts", card.axis)
    card.axes[card.axis].done = False
    return 0


@_api
def GT_GetSts(status: Any) -> int:
    """The current axis's 16-bit status (module docstring)."""
    card = _card()
    r = card.res()
    s = r.status() & _FROM_GTS
    if r.moving:
        s |= STS_MOVING
    if card.axes[card.axis].done:
        s |= STS_DONE
    out(status, s)
    return 0


@_api
def GT_ZeroPos() -> int:
    _gt("GT_ZeroPos", _card().axis)
    return 0


# --- profiles ---------------------------------------------------------------------------------
def _mode(mode: str) -> Callable[[], int]:
    def prfl() -> int:
        card = _card()
        r = card.res()
        a = card.axes[card.axis]
        if r.moving and a.mode != mode:
            raise CommandError(f"axis {card.axis} is moving; stop it before changing its profile")
        a.mode = mode
        return 0

    prfl.__name__ = f"GT_Prfl{mode}"
    prfl.__doc__ = f"The current axis's profile: {mode} (module docstring)."
    return _api(prfl)


GT_PrflT = _mode("T")
GT_PrflS = _mode("S")
GT_PrflV = _mode("V")


def _set(name: str, value: Any, positive: bool) -> None:
    card = _card()
    v = real(name, value)
    if positive and not v > 0:
        raise CompatError(f"{name}={v}: must be > 0")
    setattr(card.axes[card.axis], name, v)


@_api
def GT_SetVel(vel: float) -> int:
    """Speed, pulse/ms (V profile: its sign is the direction)."""
    _set("vel", vel, False)
    return 0


@_api
def GT_SetAcc(acc: float) -> int:
    """Acceleration of the T and V profiles, pulse/ms²."""
    _set("acc", acc, True)
    return 0


@_api
def GT_SetMAcc(acc: float) -> int:
    """Largest acceleration of the S profile, pulse/ms²."""
    _set("macc", acc, True)
    return 0


@_api
def GT_SetJerk(jerk: float) -> int:
    """Jerk of the S profile, pulse/ms³."""
    _set("jerk", jerk, True)
    return 0


@_api
def GT_SetPos(pos: int) -> int:
    card = _card()
    card.axes[card.axis].pos = integer("pos", pos, -(2**31), 2**31 - 1)
    return 0


def _start(card: _Card, n: int) -> None:
    a = card.axes[n]
    r = card.res(n)
    prof = r.profile
    if a.mode == "V":
        if a.vel == 0:
            raise CommandError(f"axis {n}: GT_SetVel first (a velocity move needs a speed)")
        direction, distance = (1 if a.vel > 0 else -1), None
        prm = SCurveParams(0.0, abs(a.vel), a.acc)
    else:
        if not a.vel > 0:
            raise CommandError(f"axis {n}: GT_SetVel first (vel {a.vel} pulse/ms)")
        jerk = a.jerk if a.mode == "S" else math.inf
        prm = SCurveParams(0.0, a.vel, a.macc if a.mode == "S" else a.acc, jerk=jerk)
        here = prof.planner.pos if prof.mode == PrfMode.CARD_DRIVE else r.prf_pos
        direction = 1 if a.pos >= here else -1
        distance = abs(a.pos - here)
    if prof.mode != PrfMode.CARD_DRIVE:
        if r.moving:
            raise CommandError(f"axis {n} moves in another mode; stop it first")
        prof.enter(PrfMode.CARD_DRIVE, factory=lambda: SCurvePlanner(card.cycle_ms))
    planner = prof.planner
    assert isinstance(planner, SCurvePlanner)
    if not planner.done:  # moving: a V profile changes its speed, the others must stop first
        if a.mode != "V" or planner.vel * direction < 0 or not planner.change_speed(abs(a.vel)):
            raise CommandError(
                f"axis {n} is moving; GT_Update changes the speed of a V profile in its "
                "direction only (stop it first: GT_SmthStp)"
            )
        return
    r.check_motion(f"GT_Update (axis {n})", float(direction))
    a.done = False
    planner.start(planner.pos, distance, prm, direction)


@_api
def GT_Update() -> int:
    """Start (or re-plan) the current axis's motion."""
    card = _card()
    _start(card, card.axis)
    return 0


@_api
def GT_MltiUpdt(mask: int) -> int:
    """``GT_Update`` of every axis of ``mask`` (bit 0 = axis 1)."""
    card = _card()
    m = integer("mask", mask, 0, 0xF)
    for n in AXES:
        if m >> (n - 1) & 1:
            _start(card, n)
    return 0


@_api
def GT_SmthStp() -> int:
    """Stop the current axis with its profile's deceleration."""
    card = _card()
    r = card.res()
    p = r.profile.planner
    if isinstance(p, SCurvePlanner) and not p.done:
        p.decelerate()
    else:
        r.stop(False)
    return 0


@_api
def GT_AbptStp() -> int:
    """Stop the current axis at once."""
    _card().res().stop(True)
    return 0


# --- positions ---------------------------------------------------------------------------------
@_api
def GT_GetPrfPos(pos: Any) -> int:
    out(pos, round(_card().res().prf_pos))
    return 0


@_api
def GT_GetAtlPos(pos: Any) -> int:
    out(pos, round(_card().res().enc_pos))
    return 0


@_api
def GT_GetPrfVel(vel: Any) -> int:
    out(vel, _card().res().prf_vel)
    return 0


# --- general IO ---------------------------------------------------------------------------------
@_api
def GT_ExInpt(io_input: Any) -> int:
    """The 16 input levels, bit i = EXI i, 0 = active."""
    out(io_input, ~digital_io(_card().ctl).gpi & 0xFFFF)
    return 0


def _write_outputs(card: _Card, levels: int) -> None:
    card.outputs = levels & 0xFFFF
    digital_io(card.ctl).set_gpo(~levels & 0xFFFF)  # the outputs that are on


@_api
def GT_ExOpt(io_output: int) -> int:
    """The 16 output levels, bit i = EXO i, 0 = on."""
    card = _card()
    _write_outputs(card, integer("io_output", io_output, 0, 0xFFFF))
    return 0


@_api
def GT_ExOptBit(bit: int, value: int) -> int:
    """Output ``bit`` (0..15) to level ``value`` (0 = on)."""
    card = _card()
    b = integer("bit", bit, 0, 15)
    v = integer("value", value, 0, 1)
    levels = card.outputs & ~(1 << b) | (v << b)
    _write_outputs(card, levels)
    return 0


@_api
def GT_GetExOpt(value: Any) -> int:
    out(value, _card().outputs)
    return 0


__all__ = [
    "GT_AbptStp",
    "GT_Axis",
    "GT_AxisOff",
    "GT_AxisOn",
    "GT_Close",
    "GT_ClrSts",
    "GT_ExInpt",
    "GT_ExOpt",
    "GT_ExOptBit",
    "GT_GetAtlPos",
    "GT_GetExOpt",
    "GT_GetPrfPos",
    "GT_GetPrfVel",
    "GT_GetSts",
    "GT_MltiUpdt",
    "GT_Open",
    "GT_PrflS",
    "GT_PrflT",
    "GT_PrflV",
    "GT_SetAcc",
    "GT_SetJerk",
    "GT_SetMAcc",
    "GT_SetPos",
    "GT_SetVel",
    "GT_SmthStp",
    "GT_Update",
    "GT_ZeroPos",
]
