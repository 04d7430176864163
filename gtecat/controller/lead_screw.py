"""Lead-screw (pitch error) compensation of one axis (GT_SetLeadScrewComp).

A table of ``n`` points spaced evenly from ``start`` over ``length`` pulses of the axis's
planned position holds the error to correct at each point, one list for each direction of
travel (the difference between them is the backlash).  While it is on, every cycle the
value for the planned position (linear between points, the end values beyond them) of
the direction the axis last moved in (positive until it has moved) is added to the
command on its way to the drive: the planned position (GT_GetPrfPos, GT_GetAxisPrfPos)
stays as planned, the drive and so the encoder go to the compensated place.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from .._attrs import PerObject


@dataclass(slots=True)
class LeadScrew:
    start: float
    length: float
    positive: tuple[float, ...]
    negative: tuple[float, ...]
    enabled: bool = False
    direction: int = 1
    last: float | None = None

    def value(self, pos: float, direction: int) -> float:
        table = self.positive if direction >= 0 else self.negative
        n = len(table)
        step = self.length / (n - 1)
        x = (pos - self.start) / step
        if x <= 0:
            return table[0]
        if x >= n - 1:
            return table[-1]
        k = int(x)
        f = x - k
        return table[k] + f * (table[k + 1] - table[k])

    def hook(self, ax: Any, t_ns: int, dt_ns: int) -> None:
        p = ax.prf_pos
        if self.last is not None and p != self.last:
            self.direction = 1 if p > self.last else -1
        self.last = p
        ax.compensation = self.value(p, self.direction) if self.enabled else 0.0


_SCREWS: PerObject[LeadScrew] = PerObject("lead_screw")


def lead_screw(ax: Any) -> LeadScrew | None:
    return _SCREWS.get(ax)


def set_lead_screw(ax: Any, screw: LeadScrew) -> None:
    old = _SCREWS.get(ax)
    if old is not None:
        screw.enabled, screw.direction, screw.last = old.enabled, old.direction, old.last
        if old.hook in ax.pre_hooks:
            ax.pre_hooks.remove(old.hook)
    _SCREWS[ax] = screw
    ax.pre_hooks.append(screw.hook)


__all__ = ["LeadScrew", "lead_screw", "set_lead_screw"]
