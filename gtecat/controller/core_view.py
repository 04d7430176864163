"""Cores 2, 3, 4 ...: the axes beyond 32 of the one EtherCAT bus.

``GT_Update(long mask)``, ``GT_Stop(long mask, long option)`` and every ``short axis``
argument reach 32 axes per core, as on the real controller.  A bus with more CiA-402
axes is addressed the way Googol's multi-core controllers address theirs: through
``GTN_*(core, ...)`` with **core c addressing bus axes 32·(c-1)+1 .. 32·c** as its
local axes 1..32 (``GTN_AxisOn(2, 1)`` enables bus axis 33, ``GTN_Update(2, 0b11)``
starts bus axes 33 and 34).  Core 1 is the EtherCAT core itself.

Decisions: a core beyond 1 exists while the bus has an axis in its range (a 40-axis bus
has cores 1 and 2; ``GTN_x(3, ...)`` is refused with 7 naming the highest core).  It is a
*view* of the one controller: the same clock, bus, process image, log and settings;
only its axis numbering differs, so bus-level functions called through it (raw data,
SDO, bring-up) act on the shared bus.  Messages name the bus axis number.  Core 1 also
takes any bus axis number in a ``short axis`` argument (``GT_GetPrfPos(40, ...)``):
only its 32-bit masks stop at axis 32, so code written for one core keeps working.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from .._attrs import own_dict
from ..errors import ParameterError

if TYPE_CHECKING:
    from .axis import Axis
    from .core import Controller

#: axes one core addresses (the width of GT_Update's mask)
AXES_PER_CORE = 32


class _Shared:
    """The controller's attribute of this name, read through a view as :meth:`CoreView.__getattr__`
    reads it, without the failed lookup before it: each of those makes and drops an
    AttributeError, and every call through core 2 reads several of these (a drive homing's
    set-up on 64 axes: about 700 per pass).  A non-data descriptor: a value set on the view
    itself is found first, as before."""

    def __set_name__(self, owner: type, name: str) -> None:
        self.name = name

    def __get__(self, view: Any, owner: type | None = None) -> Any:
        if view is None:
            return self
        return getattr(view._base, self.name)


class CoreView:
    """Core ``core`` of ``base``: its local axes 1..32 are the bus axes of that range."""

    # the controller's parts a call reads on each axis (the rest through __getattr__)
    bank = _Shared()
    master = _Shared()
    backend = _Shared()
    card = _Shared()
    pre_cycle = _Shared()
    post_cycle = _Shared()

    def __init__(self, base: Controller, core: int) -> None:
        self._base = base
        self.core = core
        #: what other modules keep per core (its own: gtecat._attrs.PerObject)
        self.extensions: dict[str, Any] = {}
        #: the controller's clock, which is its own for its life (every call through a view
        #: reads it: its lock, its cycles), read here without __getattr__
        self.clock = base.clock
        self.first = AXES_PER_CORE * (core - 1) + 1
        self._source: dict[int, Axis] | None = None
        self.axes: dict[int, Axis] = {}
        self.resources: dict[int, Any] = {}
        self._sync()
        own_dict(self)  # (its own systems are found by vars(): gtecat._attrs)

    def _sync(self) -> None:
        """Renumber the bus axes of this core's range (again after a new bus bring-up)."""
        base = self._base
        if self._source is base.axes:
            return
        self._source = base.axes
        lo = self.first
        self.axes = {n - lo + 1: ax for n, ax in base.axes.items() if lo <= n < lo + AXES_PER_CORE}
        res = getattr(base, "resources", {})
        self.resources = {n - lo + 1: res[n] for n in range(lo, lo + AXES_PER_CORE) if n in res}

    @property
    def exists(self) -> bool:
        self._sync()
        return bool(self.axes)

    def axis(self, n: int) -> Axis:
        self._sync()
        try:
            n = int(n)
        except (TypeError, ValueError):
            raise ParameterError(f"axis={n!r} is not an integer") from None
        ax = self.axes.get(n)
        if ax is None:
            raise ParameterError(
                f"core {self.core}: axis {n} out of range 1..{max(self.axes)} "
                f"(bus axes {self.first}..{self.first + max(self.axes) - 1})"
            )
        return ax

    def __getattr__(self, name: str) -> Any:
        return getattr(self._base, name)
