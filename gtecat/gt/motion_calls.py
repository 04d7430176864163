"""GT motion calls: Trap and Jog modes, GT_Update, GT_Stop, planned and encoder positions.

Manual 6.3.2, 7.1-7.3, 8.2, 11.6 and chapter 13 entries 26-32, 46-47, 55, 59,
62-65, 74, 77, 88, 90, 105, 113, 115, 118, 125, 127, 131, 135, 137, 138.  The
work is done by :mod:`gtecat.controller.resources`; these wrappers check arguments and turn
the manual's pointer and ``count`` forms into Python.

Return 1 (with a reason), as chapter 13 lists, when:

* GT_PrfTrap / GT_PrfJog / GT_SetTrapPrm / GT_SetJogPrm / GT_GetJogPrm /
  GT_ZeroPos / GT_SetPrfPos: the profile is moving (call GT_Stop, wait for bit 10 = 0);
* GT_SetTrapPrm / GT_GetTrapPrm / GT_SetPos / GT_GetPos: the axis is not in
  Trap mode; GT_SetJogPrm / GT_GetJogPrm: not in Jog mode; GT_SetVel /
  GT_GetVel: in neither (the manual names Trap only, but Jog uses the same call, 7.3.1);
* GT_Update: for any axis of the mask, Trap/Jog mode, servo on (bit 9), the
  drive in CSP, no latched alarm / following error / stop-input flag, no
  motion toward a triggered limit (bits 5/6), a Trap speed set with GT_SetVel.
  GT_Update is all or nothing: when one axis fails none starts;
* GT_SynchAxisPos: ``mask`` is 0.

Other decisions: GT_GetJogPrm refuses while moving, as entry 55 says (GT_GetTrapPrm
does not, as entry 74 says).  GT_SetVel in Trap mode needs a speed > 0 (7).
Mask bits of GT_Update and GT_SynchAxisPos for axes that do not exist return 7;
GT_Stop ignores them (``GT_Stop(0xFFF, 0)`` stops "everything"), and bits 12/13
(coordinate systems, not on this controller).  ``count`` readers take up to the
number of axes from ``axis`` on (GT_GetEncPos / GT_GetEncVel: at most 8, entry
46), write a ctypes array / numpy array / list (one value may go to ``byref(c_double())``),
and store the controller clock (ms since GT_Reset) in ``pClock`` when given.
GT_Update starts at the current cycle: after GT_Update, the k-th cycle's sample is
the profile at ``k · cycle``.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

from ..controller import motion
from ..controller.core import Controller
from ..controller.profile import PrfMode
from ..controller.resources import AxisResources, axes_in_mask, axis_resources, axis_span
from ..errors import CommandError, ParameterError
from ._core import check_range, gt_function, store, store_array, struct_arg
from .fast import attr_getter, prf_mode_value, trap_prm_into
from .structs import TJogPrm, TTrapPrm

#: GT_Stop mask/option bit of coordinate system 1 (entry 131: bit 12 crd 1, bit 13 crd 2)
CRD_STOP_BIT = 12
_MAX_ENCODERS_PER_CALL = 8


# --- argument helpers ---------------------------------------------------------------------
def real_arg(name: str, value: Any) -> float:
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise ParameterError(f"{name}={value!r} is not a number") from None
    if not math.isfinite(x):
        raise ParameterError(f"{name}={value!r} must be finite")
    return x


def long_arg(name: str, value: Any) -> int:
    return check_range(name, value, -(1 << 31), (1 << 31) - 1)


def mask_arg(name: str, value: Any) -> int:
    """A ``long`` bit mask as its 32-bit word: bit 31 comes as the C ``long`` -2^31 or as
    the unsigned word (the table's ``mask``: -2^31 .. 2^32-1, as the argument layer takes
    every mask); a refusal quotes the value as given."""
    return check_range(name, value, -(1 << 31), (1 << 32) - 1) & 0xFFFFFFFF


def _read_many(
    ctl: Controller,
    first: int,
    pValue: Any,
    count: int,
    pClock: Any,
    get: Callable[[AxisResources], float],
    limit: int | None = None,
) -> int:
    axes = axis_span(ctl, first, count, limit)
    store_array(pValue, [get(r) if r is not None else 0 for r in axes])
    store(pClock, ctl.clock_ms() & 0xFFFFFFFF)
    return 0


# --- modes -----------------------------------------------------------------------------------
@gt_function
def GT_PrfTrap(ctl: Controller, profile: int) -> int:
    """Put the axis in point-to-point (Trap) mode (entry 90; 1 while it moves)."""
    axis_resources(ctl, profile).prf_trap()
    return 0


@gt_function
def GT_PrfJog(ctl: Controller, profile: int) -> int:
    """Put the axis in Jog mode (entry 88; 1 while it moves)."""
    axis_resources(ctl, profile).prf_jog()
    return 0


@gt_function
def GT_GetPrfMode(
    ctl: Controller, profile: int, pValue: Any, count: int = 1, pClock: Any = None
) -> int:
    """Motion mode: 0 Trap, 1 Jog, 2 PT, 3 Gear, 4 Follow, 5 interpolation, 6 PVT (entry 63)."""
    return _read_many(ctl, profile, pValue, count, pClock, prf_mode_value)


# --- Trap ------------------------------------------------------------------------------------
@gt_function
def GT_SetTrapPrm(ctl: Controller, profile: int, pPrm: Any) -> int:
    """acc, dec (0 = acc), velStart, smoothTime [0, 50] ms (entry 125)."""
    res = axis_resources(ctl, profile)
    res.profile.require_mode("GT_SetTrapPrm", PrfMode.TRAP)
    res.profile.require_idle("GT_SetTrapPrm")
    s = struct_arg(pPrm, TTrapPrm, "pPrm")
    prm = motion.TrapParams(acc=s.acc, dec=s.dec, vel_start=s.velStart, smooth_time=s.smoothTime)  # type: ignore[attr-defined]
    res.set_trap_prm(prm)
    return 0


@gt_function
def GT_GetTrapPrm(ctl: Controller, profile: int, pPrm: Any) -> int:
    res = axis_resources(ctl, profile)
    res.profile.require_mode("GT_GetTrapPrm", PrfMode.TRAP)
    trap_prm_into(res, struct_arg(pPrm, TTrapPrm, "pPrm"))
    return 0


@gt_function
def GT_SetPos(ctl: Controller, profile: int, pos: int) -> int:
    """Trap target, pulse, [-1073741823, 1073741823] (entry 115)."""
    axis_resources(ctl, profile).set_target(long_arg("pos", pos))
    return 0


@gt_function
def GT_GetPos(ctl: Controller, profile: int, pPos: Any) -> int:
    res = axis_resources(ctl, profile)
    res.profile.require_mode("GT_GetPos", PrfMode.TRAP)
    store(pPos, res.profile.trap_target)
    return 0


@gt_function
def GT_SetVel(ctl: Controller, profile: int, vel: float) -> int:
    """Trap speed (> 0) or signed Jog speed, pulse/ms, for the next GT_Update (entry 127)."""
    axis_resources(ctl, profile).set_vel(real_arg("vel", vel))
    return 0


@gt_function
def GT_GetVel(ctl: Controller, profile: int, pVel: Any) -> int:
    store(pVel, axis_resources(ctl, profile).get_vel())
    return 0


# --- Jog -------------------------------------------------------------------------------------
@gt_function
def GT_SetJogPrm(ctl: Controller, profile: int, pPrm: Any) -> int:
    """acc, dec (0 = acc), smooth in [0, 1) (entry 113)."""
    res = axis_resources(ctl, profile)
    res.profile.require_mode("GT_SetJogPrm", PrfMode.JOG)
    res.profile.require_idle("GT_SetJogPrm")
    s = struct_arg(pPrm, TJogPrm, "pPrm")
    res.set_jog_prm(motion.JogParams(acc=s.acc, dec=s.dec, smooth=s.smooth))  # type: ignore[attr-defined]
    return 0


@gt_function
def GT_GetJogPrm(ctl: Controller, profile: int, pPrm: Any) -> int:
    res = axis_resources(ctl, profile)
    res.profile.require_mode("GT_GetJogPrm", PrfMode.JOG)
    res.profile.require_idle("GT_GetJogPrm (entry 55)")
    s = struct_arg(pPrm, TJogPrm, "pPrm")
    prm = res.profile.jog_prm
    s.acc, s.dec, s.smooth = prm.acc, prm.dec, prm.smooth  # type: ignore[attr-defined]
    return 0


# --- start and stop ---------------------------------------------------------------------------
@gt_function
def GT_Update(ctl: Controller, mask: int) -> int:
    """Start (or change on the fly) the Trap / Jog motion of every axis in ``mask`` (entry 137)."""
    axes = axes_in_mask(ctl, mask, strict=True)
    if not axes:
        raise ParameterError("mask=0: no axis to start")
    for r in axes:
        r.check_update()
    for r in axes:
        r.start()
    return 0


@gt_function
def GT_Stop(ctl: Controller, mask: int, option: int) -> int:
    """Stop the axes and coordinate systems in ``mask`` (entry 131).

    Bits 0-11 are axes 1-12, bits 12 and 13 coordinate systems 1 and 2 (the entry's
    table); the same ``option`` bit set is an abrupt stop (decAbruptStop, or the
    system's GT_SetCrdStopDec abrupt deceleration), clear a smooth one.  A stopped
    system brakes along its path and drops the rest of its FIFO.
    """
    m = mask_arg("mask", mask)
    opt = mask_arg("option", option)
    for r in axes_in_mask(ctl, m & 0xFFF, strict=False):
        r.stop(bool(opt >> (r.number - 1) & 1))
    crds = vars(ctl).get("crd_bank")  # this core's own systems (gtecat.controller.crd.bank)
    if crds is not None:
        for n, c in crds.systems.items():
            bit = CRD_STOP_BIT + n - 1
            if m >> bit & 1:
                c.stop(bool(opt >> bit & 1))
    return 0


# --- positions ----------------------------------------------------------------------------------
def _define_reader(name: str, attr: str, doc: str, limit: int | None = None) -> None:
    getter = attr_getter(attr)

    def read(ctl: Controller, axis: int, pValue: Any, count: int = 1, pClock: Any = None) -> int:
        return _read_many(ctl, axis, pValue, count, pClock, getter, limit)

    read.__name__ = read.__qualname__ = name
    read.__doc__ = doc
    globals()[name] = gt_function(read)


_define_reader("GT_GetPrfPos", "prf_pos", "Planned position of the profile, pulse (entry 64).")
_define_reader("GT_GetPrfVel", "prf_vel", "Planned velocity, pulse/ms (entry 65).")
_define_reader("GT_GetPrfAcc", "prf_acc", "Planned acceleration, pulse/ms² (entry 62).")
_define_reader(
    "GT_GetAxisPrfPos", "axis_prf_pos", "Axis planned position (after GT_ProfileScale) (entry 31)."
)
_define_reader("GT_GetAxisPrfVel", "axis_prf_vel", "Axis planned velocity, pulse/ms (entry 32).")
_define_reader("GT_GetAxisPrfAcc", "axis_prf_acc", "Axis planned acceleration (entry 30).")
_define_reader(
    "GT_GetAxisEncPos", "axis_enc_pos", "Axis encoder position (after GT_EncScale) (entry 27)."
)
_define_reader("GT_GetAxisEncVel", "axis_enc_vel", "Axis encoder velocity, pulse/ms (entry 28).")
_define_reader("GT_GetAxisEncAcc", "axis_enc_acc", "Axis encoder acceleration (entry 26).")
_define_reader(
    "GT_GetAxisError", "axis_error", "Axis planned minus axis encoder position (entry 29)."
)
_define_reader(
    "GT_GetEncPos",
    "enc_pos",
    "Encoder position, pulse: 6064h / 2**PosScale (entry 46, 8.2; at most 8 at once).",
    _MAX_ENCODERS_PER_CALL,
)


@gt_function
def GT_GetEncVel(
    ctl: Controller, encoder: int, pValue: Any, count: int = 1, pClock: Any = None
) -> int:
    """Encoder velocity, pulse/ms (entry 47; at most 8 at once)."""
    return _read_many(
        ctl, encoder, pValue, count, pClock, attr_getter("enc_vel"), _MAX_ENCODERS_PER_CALL
    )


@gt_function
def GT_SetEncPos(ctl: Controller, encoder: int, encPos: int) -> int:
    """The encoder reading becomes ``encPos``; counting goes on from there (entry 105, 8.2)."""
    axis_resources(ctl, encoder).set_enc_pos(long_arg("encPos", encPos))
    return 0


@gt_function
def GT_SetPrfPos(ctl: Controller, profile: int, prfPos: int) -> int:
    """Redefine the planned position (not while moving); GT_SynchAxisPos syncs the axis (11.6)."""
    axis_resources(ctl, profile).set_prf_pos(long_arg("prfPos", prfPos))
    return 0


@gt_function
def GT_ZeroPos(ctl: Controller, axis: int, count: int = 1) -> int:
    """Planned and actual positions of ``count`` axes to 0 (entry 138; 1 while one moves)."""
    axes = [r for r in axis_span(ctl, axis, count) if r is not None]
    for r in axes:
        r.profile.require_idle(f"GT_ZeroPos (axis {r.number})")
    for r in axes:
        r.zero_pos()
    return 0


@gt_function
def GT_SynchAxisPos(ctl: Controller, mask: int) -> int:
    """Axis planned := scaled profile, axis encoder := scaled encoder for the mask (entry 135)."""
    try:
        m = int(mask)
    except (TypeError, ValueError):
        raise ParameterError(f"mask={mask!r} is not an integer") from None
    if m == 0:
        raise CommandError("GT_SynchAxisPos: mask is 0, no axis to synchronise (entry 135)")
    for r in axes_in_mask(ctl, m, strict=True):
        r.synch_axis_pos()
    return 0
