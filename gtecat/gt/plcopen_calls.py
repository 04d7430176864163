"""Single-call moves of the GTN header: a velocity move and an absolute move, started at once.

* ``GT_MoveVelocity(profile, &prm)``: the profile becomes a Jog profile (``acc``, ``dec``
  of ``prm``) and runs at ``vel`` (pulse/ms, > 0) in ``direction`` 0 (positive) or 1
  (negative), as the vendor's EtherCAT demo's jog buttons use it; no ``GT_Update``.  It
  runs until ``GT_Stop``.  On a profile already in a velocity move the speed and
  direction change on the fly (the ramps stay the first call's: a running Jog keeps its
  parameters).  ``jerkBegin`` / ``jerkEnd`` are kept and read back; the ramps are linear
  (constant acceleration).
* ``GT_MoveAbsolute(profile, &prm)``: a Trap move to ``pos`` at ``vel`` with ``acc`` /
  ``dec``, started at once (``GT_PrfTrap`` + ``GT_SetTrapPrm`` + ``GT_SetPos`` +
  ``GT_SetVel`` + ``GT_Update`` in one call).  ``percent`` (the S-curve share, 0..100) is
  kept and read back; the ramps are linear.
* A profile moving in another mode returns 1 (as ``GT_PrfJog`` / ``GT_PrfTrap`` do on a
  moving profile); every condition of ``GT_Update`` (servo on, limits, ...) applies.
* ``GT_GetMoveVelocity`` / ``GT_GetMoveAbsolute``: the last parameters given for that
  profile (zeros before any).
"""

from __future__ import annotations

import ctypes
import math
from typing import Any

from .._attrs import PerObject
from ..controller.core import Controller
from ..controller.motion import TrapParams
from ..controller.motion.jog import JogParams
from ..controller.profile import PrfMode
from ..controller.resources import axis_resources
from ..errors import ParameterError
from ._core import gt_function, struct_arg


class TMoveVelocityPrm(ctypes.Structure):
    """GT_MoveVelocity: vel pulse/ms (> 0), acc / dec pulse/ms², jerkBegin / jerkEnd
    pulse/ms³, direction 0 positive / 1 negative (vendor GTN header)."""

    _fields_ = (
        ("vel", ctypes.c_double),
        ("acc", ctypes.c_double),
        ("dec", ctypes.c_double),
        ("jerkBegin", ctypes.c_double),
        ("jerkEnd", ctypes.c_double),
        ("direction", ctypes.c_int16),
    )


class TMoveAbsolutePrm(ctypes.Structure):
    """GT_MoveAbsolute: pos pulse, vel pulse/ms, acc / dec pulse/ms², percent (S-curve share)."""

    _fields_ = (
        ("pos", ctypes.c_int32),
        ("vel", ctypes.c_double),
        ("acc", ctypes.c_double),
        ("dec", ctypes.c_double),
        ("percent", ctypes.c_int16),
    )


_KEPT: PerObject[dict[tuple[str, int], bytes]] = PerObject("plcopen_kept")


def _kept(ctl: Controller) -> dict[tuple[str, int], bytes]:
    return _KEPT.setdefault(getattr(ctl, "_base", ctl), {})


def _copy(prm: Any, data: bytes | None, cls: type[ctypes.Structure]) -> None:
    """Fill ``prm`` with the kept parameters (zeros when there are none)."""
    src = cls.from_buffer_copy(data) if data is not None else cls()
    for name, _ in cls._fields_:
        setattr(prm, name, getattr(src, name))


def _positive(name: str, v: float) -> float:
    if not (math.isfinite(v) and v > 0.0):
        raise ParameterError(f"{name}={v!r}: must be > 0")
    return float(v)


@gt_function
def GT_MoveVelocity(ctl: Controller, profile: int, pPrm: Any) -> int:
    """Run profile ``profile`` at ``vel`` in ``direction`` now (the module docstring)."""
    prm = struct_arg(pPrm, TMoveVelocityPrm, "pPrm")
    vel, acc = _positive("vel", prm.vel), _positive("acc", prm.acc)
    dec = _positive("dec", prm.dec) if prm.dec != 0 else acc
    if prm.direction not in (0, 1):
        raise ParameterError(f"direction={prm.direction}: 0 positive, 1 negative")
    res = axis_resources(ctl, profile)
    p = res.profile
    if p.mode != PrfMode.JOG:
        res.prf_jog()  # refused (1) while the profile moves in another mode
    if p.jog.done:  # a running Jog keeps its ramps: only the speed changes
        res.set_jog_prm(JogParams(acc=acc, dec=dec, smooth=0.0))
    res.set_vel(-vel if prm.direction else vel)
    res.check_update()
    res.start()
    _kept(ctl)[("vel", res.number)] = bytes(prm)
    return 0


@gt_function
def GT_GetMoveVelocity(ctl: Controller, profile: int, pPrm: Any) -> int:
    res = axis_resources(ctl, profile)
    prm = struct_arg(pPrm, TMoveVelocityPrm, "pPrm")
    _copy(prm, _kept(ctl).get(("vel", res.number)), TMoveVelocityPrm)
    return 0


def move_absolute(ctl: Controller, profile: int, prm: Any) -> int:
    """GT_MoveAbsolute with its parameters ``prm`` (a TMoveAbsolutePrm, or a view of one):
    also what its fast path calls (gtecat.gt.fast_stream)."""
    vel, acc = _positive("vel", prm.vel), _positive("acc", prm.acc)
    dec = _positive("dec", prm.dec) if prm.dec != 0 else acc
    if not 0 <= prm.percent <= 100:
        raise ParameterError(f"percent={prm.percent}: 0..100")
    res = axis_resources(ctl, profile)
    p = res.profile
    if p.mode != PrfMode.TRAP:
        res.prf_trap()
    if p.trap.done:
        res.set_trap_prm(TrapParams(acc=acc, dec=dec, vel_start=0.0, smooth_time=0))
    res.set_target(int(prm.pos))
    res.set_vel(vel)
    res.check_update()
    res.start()
    _kept(ctl)[("abs", res.number)] = bytes(prm)
    return 0


@gt_function
def GT_MoveAbsolute(ctl: Controller, profile: int, pPrm: Any) -> int:
    """A Trap move to ``pos``, started now (the module docstring)."""
    return move_absolute(ctl, profile, struct_arg(pPrm, TMoveAbsolutePrm, "pPrm"))


@gt_function
def GT_GetMoveAbsolute(ctl: Controller, profile: int, pPrm: Any) -> int:
    res = axis_resources(ctl, profile)
    prm = struct_arg(pPrm, TMoveAbsolutePrm, "pPrm")
    _copy(prm, _kept(ctl).get(("abs", res.number)), TMoveAbsolutePrm)
    return 0


__all__ = ["TMoveAbsolutePrm", "TMoveVelocityPrm"]
