"""Position triggers (GT_SetTrigger / GT_SetTriggerEx): latch a position at an input's edge.

A trigger watches one input (the home switch of an axis, a general-purpose input) and,
at each edge of the wanted sense, latches the position of one resource (an encoder, an
axis, a profile) plus the trigger's ``offset``.  It latches ``loop`` times (0 and 1:
once) and is then done; with ``windowOnly`` an edge counts only where the latched
position lies in ``[firstPosition, lastPosition]``.  The GT layer
(:mod:`gtecat.gt.compare_calls`) says where the edges and positions come from.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from .._attrs import PerObject


@dataclass(slots=True)
class Edge:
    active: bool  #: the input became active (else inactive)
    pos: float  #: the latched resource's position at the edge


@dataclass(slots=True)
class Trigger:
    edges: Callable[[], list[Edge]]
    sense: int  #: 0 the input becomes active, 1 it becomes inactive
    offset: int
    loop: int
    window: tuple[int, int] | None
    settings: Any  #: the structure's values as given, read back by GT_GetTrigger(Ex)
    execute: bool = True
    done: bool = False
    position: int = 0
    clock: int = 0
    loops: int = 0

    def clear(self) -> None:
        self.execute, self.done, self.loops = True, False, 0

    def step(self, clock_ms: int) -> None:
        if not self.execute:
            return
        for e in self.edges():
            if e.active != (self.sense == 0):
                continue
            pos = round(e.pos) + self.offset
            if self.window is not None and not self.window[0] <= pos <= self.window[1]:
                continue
            self.position, self.clock = pos, clock_ms
            self.loops += 1
            if self.loops >= max(self.loop, 1):
                self.execute, self.done = False, True
                return


class Triggers:
    """The triggers of one controller, stepped after every cycle."""

    def __init__(self, ctl: Any) -> None:
        self.ctl = ctl
        self.by_index: dict[int, Trigger] = {}
        ctl.post_cycle.append(self._post)
        ctl.on_reset.append(lambda c: self.by_index.clear())

    def _post(self, t_ns: int, dt_ns: int) -> None:
        if self.by_index:
            ms = self.ctl.clock_ms()
            for t in self.by_index.values():
                t.step(ms)


_TRIGGERS: PerObject[Triggers] = PerObject("triggers")


def triggers(ctl: Any) -> Triggers:
    base = getattr(ctl, "_base", ctl)
    t = _TRIGGERS.get(base)
    if t is None:
        t = _TRIGGERS[base] = Triggers(base)
    return t


__all__ = ["Edge", "Trigger", "Triggers", "triggers"]
