"""Buffered commands of the interpolation FIFO and the G0 lines of three and four axes.

Each buffered command is a FIFO entry like ``GT_BufIO``: it acts when the path reaches it
(the segment before it ends there at speed 0, as ``GT_BufIO`` does here) and counts as one
entry in ``GT_CrdStatus``'s segment number.  Decisions:

* ``GT_BufDoBit(crd, doType, index, value)``: output ``index`` (from 1) of ``MC_GPO``
  (1..16) to ``value``; ``MC_ENABLE`` / ``MC_CLEAR`` are refused (7): switching a drive
  from the path is not a buffered IO.
* ``GT_BufDA(crd, chn, daValue)``: the free analog output ``chn`` (a DAC of a pulse axis,
  or of an analog axis that is off; :mod:`gtecat.controller.servo_loop`) takes
  ``daValue``; a channel that the control loop drives when the entry is reached keeps it,
  with a master-log line.
* ``GT_BufLmtsOn/Off(crd, axis, limitType)``: ``GT_LmtsOn/Off`` of that axis there.
* ``GT_LnXYZG0`` / ``GT_LnXYZAG0``: rapid lines, like ``GT_LnXYG0``: they stop at their end.
* ``GT_CrdData(crd, NULL, fifo)``: what applications call after their last segment to push
  the look-ahead buffer into the FIFO.  The emulator's look-ahead (``GT_InitLookAhead``)
  plans the corner speeds over the FIFO itself, so every segment is in the FIFO already and
  the call only checks its arguments.  A segment given as a ``TCrdData`` (three layouts in
  the vendor's headers) returns 1: push segments with ``GT_LnXY`` ... ``GT_ArcXYC``.
* ``GT_GetRemainderSegNum``: the entries of the FIFO not finished yet (the one running
  included), in ``GT_CrdStatus``'s unit.
* ``GT_SetCrdMapBase(crd, base)``: base 0 (``TCrdPrm.profile[k]`` is profile ``k + 1``) is
  the emulated map; another base returns 1, saying it is not emulated.
"""

from __future__ import annotations

from typing import Any

from ..controller.core import Controller
from ..controller.crd.system import BufIO
from ..controller.digital_io import GPIO_COUNT
from ..controller.servo_loop import servo_loop
from ..errors import CommandError, ParameterError
from ._core import check_range, gt_function, store
from .constants import MC_DAC, MC_GPO
from .crd_calls import _crd, _push_line
from .status_calls import GT_LmtsOff, GT_LmtsOn

#: a tag for entries that are not outputs (GT_CrdStatus counts them all the same)
_LIMITS = -1


@gt_function
def GT_BufDoBit(
    ctl: Controller, crd: int, doType: int, index: int, value: int, fifo: int = 0
) -> int:
    """Output ``index`` of ``doType`` to ``value`` where the path reaches this entry."""
    c = _crd(ctl, crd)
    c.require_prm("GT_BufDoBit")
    if int(doType) != MC_GPO:
        raise ParameterError(f"doType={doType}: MC_GPO 12 (buffered general-purpose outputs)")
    bit = 1 << (check_range("index", index, 1, GPIO_COUNT) - 1)

    def apply(m: int, v: int) -> None:
        from .io_calls import read_do, write_do

        write_do(ctl, MC_GPO, (read_do(ctl, MC_GPO) & ~m) | (v & m))

    c.push(BufIO(MC_GPO, bit, bit if value else 0, apply=apply), int(fifo))
    return 0


@gt_function
def GT_BufDA(ctl: Controller, crd: int, chn: int, daValue: int, fifo: int = 0) -> int:
    """Analog output ``chn`` to ``daValue`` (-32768..32767 = +-10 V) at this point."""
    c = _crd(ctl, crd)
    c.require_prm("GT_BufDA")
    n = check_range("chn", chn, 1, 0x7FFF)
    if n not in ctl.axes:
        raise ParameterError(f"chn={n}: the analog outputs are 1..{max(ctl.axes, default=0)}")
    value = int(daValue)

    def apply(m: int, v: int) -> None:
        loop = servo_loop(ctl)
        if loop.analog(n) and ctl.axes[n].servo_on:
            ctl.log(
                f"GT_BufDA (coordinate system {c.number}): dac {n} carries the control loop; kept"
            )
            return
        loop.dac[n] = value

    c.push(BufIO(MC_DAC, 0, value, apply=apply), int(fifo))
    return 0


def _buf_limits(
    ctl: Controller, name: str, crd: int, axis: int, limit_type: int, fifo: int, on: bool
) -> int:
    c = _crd(ctl, crd)
    c.require_prm(name)
    ctl.axis(axis)  # 7 now for an axis that does not exist
    t = int(limit_type)
    if t not in (-1, 0, 1):
        raise ParameterError(f"limitType={t}: MC_LIMIT_POSITIVE 0, MC_LIMIT_NEGATIVE 1 or -1")
    fn = (GT_LmtsOn if on else GT_LmtsOff).__wrapped__

    def apply(m: int, v: int) -> None:
        try:
            fn(ctl, axis, t)
        except (CommandError, ParameterError) as e:
            ctl.log(f"{name} (coordinate system {c.number}, axis {axis}): {e}")

    c.push(BufIO(_LIMITS, 0, int(on), apply=apply), int(fifo))
    return 0


@gt_function
def GT_BufLmtsOn(ctl: Controller, crd: int, axis: int, limitType: int, fifo: int = 0) -> int:
    """The limit switches of ``axis`` watched again from this point of the path."""
    return _buf_limits(ctl, "GT_BufLmtsOn", crd, axis, limitType, fifo, True)


@gt_function
def GT_BufLmtsOff(ctl: Controller, crd: int, axis: int, limitType: int, fifo: int = 0) -> int:
    """The limit switches of ``axis`` ignored from this point (a path onto a switch)."""
    return _buf_limits(ctl, "GT_BufLmtsOff", crd, axis, limitType, fifo, False)


@gt_function
def GT_LnXYZG0(
    ctl: Controller, crd: int, x: int, y: int, z: int, synVel: float, synAcc: float, fifo: int = 0
) -> int:
    """Rapid line to (x, y, z): a line that stops at its end."""
    return _push_line(_crd(ctl, crd), "GT_LnXYZG0", fifo, {0: x, 1: y, 2: z}, synVel, synAcc, 0.0)


@gt_function
def GT_LnXYZAG0(
    ctl: Controller,
    crd: int,
    x: int,
    y: int,
    z: int,
    aPos: int,
    synVel: float,
    synAcc: float,
    fifo: int = 0,
) -> int:
    """Rapid line to (x, y, z, a): a line that stops at its end."""
    values = {0: x, 1: y, 2: z, 3: aPos}
    return _push_line(_crd(ctl, crd), "GT_LnXYZAG0", fifo, values, synVel, synAcc, 0.0)


@gt_function
def GT_CrdData(ctl: Controller, crd: int, pCrdData: Any = None, fifo: int = 0) -> int:
    """NULL: flush the look-ahead buffer into the FIFO (nothing is held back here)."""
    c = _crd(ctl, crd)
    c.require_prm("GT_CrdData")
    if pCrdData is not None:
        raise CommandError(
            "GT_CrdData: a segment given as TCrdData is not emulated (its layout differs "
            "between the vendor's headers); push it with GT_LnXY ... GT_ArcXYC"
        )
    c.space(int(fifo))  # 7 for a FIFO other than 0 and 1
    return 0


@gt_function
def GT_GetRemainderSegNum(ctl: Controller, crd: int, pSegment: Any, fifo: int = 0) -> int:
    """Entries of ``fifo`` not finished yet (the running one included)."""
    c = _crd(ctl, crd)
    c.require_prm("GT_GetRemainderSegNum")
    store(pSegment, c.now().remainder(int(fifo)))
    return 0


@gt_function
def GT_SetCrdMapBase(ctl: Controller, crd: int, base: int) -> int:
    _crd(ctl, crd)
    b = int(base)
    if b != 0:
        raise CommandError(
            f"GT_SetCrdMapBase: base {b} is not emulated; base 0 (TCrdPrm.profile[k] is "
            "profile k + 1) is"
        )
    return 0


@gt_function
def GT_GetCrdMapBase(ctl: Controller, crd: int, pBase: Any) -> int:
    _crd(ctl, crd)
    store(pBase, 0)  # the only base emulated (GT_SetCrdMapBase)
    return 0
