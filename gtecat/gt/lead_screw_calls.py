"""Lead-screw compensation: ``GT_SetLeadScrewComp`` and ``GT_EnableLeadScrewComp``.

Decisions where the vendor header says no more:

* ``GT_SetLeadScrewComp(axis, n, startPos, lenPos, pPositive, pNegative)``: ``n`` points
  (2..1024) from ``startPos`` to ``startPos + lenPos`` (``lenPos`` > 0, pulses of the
  axis's planned position), evenly spaced; ``pPositive[k]`` / ``pNegative[k]`` the
  correction (pulses) at point ``k`` when the axis moves in the positive / negative
  direction.  Between points the value is linear, beyond the ends it is the end value
  (:mod:`gtecat.controller.lead_screw`).  The axis must stand still (1); a new table
  keeps the on/off state.
* ``GT_EnableLeadScrewComp(axis, mode)``: 1 on, 0 off; on needs a table (1).  Switching it
  on or off at a point where the correction is not 0 moves the drive by it in one cycle,
  as on the card.  GT_Reset switches it off (the table stays).
* The planned position stays as planned (GT_GetPrfPos); the drive's command and so the
  encoder (GT_GetEncPos) carry the correction.
"""

from __future__ import annotations

from typing import Any

from ..controller.core import Controller
from ..controller.lead_screw import LeadScrew, lead_screw, set_lead_screw
from ..controller.resources import axis_resources
from ..errors import CommandError, ParameterError
from ._core import gt_function


def _on_reset(ctl: Controller) -> None:
    for ax in ctl.axes.values():
        s = lead_screw(ax)
        if s is not None:
            s.enabled = False
            ax.compensation = 0.0


@gt_function
def GT_SetLeadScrewComp(
    ctl: Controller, axis: int, n: int, startPos: int, lenPos: int, pPositive: Any, pNegative: Any
) -> int:
    """The compensation table of ``axis`` (module docstring)."""
    res = axis_resources(ctl, axis)
    if int(lenPos) <= 0:
        raise ParameterError(f"lenPos={lenPos}: the table's length in pulses, > 0")
    if pPositive is None or pNegative is None:
        raise ParameterError("pPositive and pNegative must point to n values each")
    if res.moving:
        raise CommandError(f"GT_SetLeadScrewComp: axis {res.number} is moving")
    pos = tuple(float(v) for v in pPositive.load_values(int(n)))
    neg = tuple(float(v) for v in pNegative.load_values(int(n)))
    set_lead_screw(res.ax, LeadScrew(float(startPos), float(lenPos), pos, neg))
    base = getattr(ctl, "_base", ctl)
    if _on_reset not in base.on_reset:
        base.on_reset.append(_on_reset)
    return 0


@gt_function
def GT_EnableLeadScrewComp(ctl: Controller, axis: int, mode: int) -> int:
    """1 on, 0 off."""
    res = axis_resources(ctl, axis)
    s = lead_screw(res.ax)
    if s is None:
        if int(mode):
            raise CommandError(
                f"GT_EnableLeadScrewComp: axis {res.number} has no table (GT_SetLeadScrewComp)"
            )
        return 0
    s.enabled = bool(int(mode))
    return 0
