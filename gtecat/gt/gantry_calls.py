"""Gantry pairs: ``GT_SetGantryMode(group, master, slave, mode, syncErrorLimit)``.

The vendor header's modes: ``GANTRY_MODE_NONE`` -1, ``GANTRY_MODE_OPEN_LOOP_GANTRY`` 1,
``GANTRY_MODE_DECOUPLE_POSITION_LOOP`` 2.  Decisions (the header says no more):

* A pair (modes 1 and 2 alike: the emulated drives close their own loops) makes the slave
  profile an electronic gear of the master profile, 1:1 with no clutch, engaged at once: every
  motion of the master (Trap, Jog, interpolation, homing) moves the slave by the same
  amount, and the slave keeps the offset it had.  Both axes must stand still (1 otherwise);
  master and slave differ and neither is in another group (7).
* ``GANTRY_MODE_NONE`` releases the slave (a Trap profile again, where it stands); the
  master must stand still (the call lets the slave take the master's last step: one
  cycle).  ``syncErrorLimit`` (pulses, > 0) is kept and read back: the emulated drives
  follow their command exactly, so the two encoders never drift apart.
* ``GT_GetGantryMode`` of a group never set reads master 0, slave 0, mode -1, limit 1000.
* Each core has its own groups and names their axes in its own numbering (``GTN_x(2, ...)``
  on a bus of more than 32 axes: core 2's axis 1 is bus axis 33); an axis is in one group
  of one core at most.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from .._attrs import PerObject
from ..controller.core import Controller
from ..controller.resources import axis_resources
from ..errors import CommandError, ParameterError
from ._core import gt_function, store
from .motion_calls import GT_PrfTrap
from .motion_ext_calls import GT_GearStart, GT_PrfGear, GT_SetGearMaster, GT_SetGearRatio

GANTRY_MODE_NONE = -1
GANTRY_MODE_OPEN_LOOP_GANTRY = 1
GANTRY_MODE_DECOUPLE_POSITION_LOOP = 2
_GEAR_MASTER_PROFILE = 2


@dataclass(slots=True)
class _Pair:
    master: int = 0
    slave: int = 0
    mode: int = GANTRY_MODE_NONE
    limit: int = 1000
    bus: tuple[int, int] = (0, 0)  #: master and slave as bus axis numbers


#: the bus controller -> its cores' groups (core 1: itself, a core beyond: its view)
_GROUPS: PerObject[dict[Any, dict[int, _Pair]]] = PerObject("gantry_groups")


def _groups(ctl: Controller) -> dict[int, _Pair]:
    """The groups of the core ``ctl`` (a core beyond 1 is a view of the bus controller)."""
    return _GROUPS.setdefault(getattr(ctl, "_base", ctl), {}).setdefault(ctl, {})


def _all_groups(ctl: Controller) -> list[tuple[str, int, _Pair]]:
    """(core, group, pair) of every core of ``ctl``'s bus."""
    base = getattr(ctl, "_base", ctl)
    out = []
    for owner, groups in list((_GROUPS.get(base) or {}).items()):
        core = f" of core {owner.core}" if owner is not base else ""
        out += [(core, n, p) for n, p in groups.items()]
    return out


def _release(ctl: Controller, pair: _Pair) -> None:
    """The slave out of its gear, where it stands (the master must stand still)."""
    _still(ctl, pair.master)
    res = axis_resources(ctl, pair.slave)
    for _ in range(2):  # the gear follows the master's last step one cycle later
        if res.profile.planner.vel == 0.0:
            break
        ctl.clock.advance_ns(ctl.clock.cycle_ns)
    if res.profile.planner.vel != 0.0:
        raise CommandError(f"GT_SetGantryMode: slave axis {pair.slave} is moving; stop it first")
    res.stop(True)  # the engaged gear (a motion that follows the master) ends here
    GT_PrfTrap.__wrapped__(ctl, pair.slave)


def _still(ctl: Controller, *axes: int) -> None:
    moving = [a for a in axes if axis_resources(ctl, a).moving]
    if moving:
        raise CommandError(f"GT_SetGantryMode: axes {moving} are moving; stop them first")


@gt_function
def GT_SetGantryMode(
    ctl: Controller, group: int, master: int, slave: int, mode: int, syncErrorLimit: int = 1000
) -> int:
    """Pair ``slave`` with ``master`` (modes 1, 2) or release the group (-1)."""
    g, m = int(group), int(mode)
    groups = _groups(ctl)
    old = groups.get(g)
    if m == GANTRY_MODE_NONE:
        if old is not None and old.mode != GANTRY_MODE_NONE:
            _release(ctl, old)
        groups[g] = _Pair(mode=GANTRY_MODE_NONE, limit=old.limit if old else 1000)
        return 0
    if m not in (GANTRY_MODE_OPEN_LOOP_GANTRY, GANTRY_MODE_DECOUPLE_POSITION_LOOP):
        raise ParameterError(f"mode={m}: -1 none, 1 open-loop gantry, 2 decoupled position loop")
    a, b = int(master), int(slave)  # the caller's numbering, as the calls below take it
    bus = (axis_resources(ctl, a).number, axis_resources(ctl, b).number)
    if a == b:
        raise ParameterError(f"master={a}, slave={b}: two different axes")
    if int(syncErrorLimit) <= 0:
        raise ParameterError(f"syncErrorLimit={syncErrorLimit}: pulses, > 0")
    for core, n, p in _all_groups(ctl):
        mine = p is groups.get(n)
        if not (mine and n == g) and p.mode != GANTRY_MODE_NONE and set(bus) & set(p.bus):
            raise ParameterError(
                f"axis in gantry group {n}{core} already (master {p.master}, slave {p.slave})"
            )
    if old is not None and old.mode != GANTRY_MODE_NONE:
        _release(ctl, old)
    _still(ctl, a, b)
    GT_PrfGear.__wrapped__(ctl, b, 0)
    GT_SetGearMaster.__wrapped__(ctl, b, a, _GEAR_MASTER_PROFILE, 0)
    GT_SetGearRatio.__wrapped__(ctl, b, 1, 1, 0)
    GT_GearStart.__wrapped__(ctl, 1 << (b - 1))
    groups[g] = _Pair(a, b, m, int(syncErrorLimit), bus)
    return 0


@gt_function
def GT_GetGantryMode(
    ctl: Controller, group: int, pMaster: Any, pSlave: Any, pMode: Any, pSyncErrorLimit: Any
) -> int:
    p = _groups(ctl).get(int(group), _Pair())
    store(pMaster, p.master)
    store(pSlave, p.slave)
    store(pMode, p.mode)
    store(pSyncErrorLimit, p.limit)
    return 0
