"""The older homing calls of GTS cards: GT_HomeInit, GT_Home, GT_Index, GT_HomeStop, GT_HomeSts.

Before ``GT_GoHome`` and THomePrm, a GTS card homed with a search that has the home capture
armed: the vendor's demos call ``GT_ClrSts``, ``GT_HomeInit``, ``GT_AxisOn``, then
``GT_Index(1, 20000, 2000)`` ("axis 1 homes on Home + Index") and
``GT_Home(axis, 200000, 50, 0.5, offset)`` per axis, and poll ``GT_HomeSts(axis, &sts)``
until ``sts`` is 1.  Each call runs on the smart homing of the axis
(:mod:`gtecat.controller.smart_home`), so the search, the capture and every error are
those of ``GT_GoHome`` (mode 20 home, 22 home + index); units are the Trap mode's
(pulse, pulse/ms, pulse/ms²).

Decisions where the header says no more than the prototypes:

* ``GT_Home(axis, pos, vel, acc, offset)``: a search from where the axis stands towards the
  profile position ``pos`` at ``vel`` with ``acc`` (acceleration and deceleration), the home
  capture armed for the edge where the switch is reached; once the home is captured the
  axis stops, goes back and stands at ``captured home + offset``.  ``pos`` is the end of
  the search: no home before it is an error.  Positions are not zeroed (``GT_ZeroPos``
  after, as with ``GT_GoHome``).  A standing axis in another profile mode is put in Trap
  mode first, a jogging one is taken over as ``GT_GoHome`` does.  ``pos`` equal to where
  the axis stands, or ``vel``/``acc`` not above 0, is 7.
* ``GT_Index(axis, pos, offset)`` arms the index stage of the *next* ``GT_Home`` (or
  ``GT_HomeStop``) of ``axis`` (the demos call it first): after the home is captured the
  axis searches the first index (Z) pulse beyond the home, in the direction of ``pos``'s
  sign (0: the home search's direction) and within ``|pos|`` pulses of the home (0: no
  limit), and stands at ``captured index + offset`` (the Index call's offset; the Home
  call's is then not used).  It returns 0 without moving; an axis that cannot capture an
  index (an EtherCAT drive without touch probe) makes the ``GT_Home`` return 1.
* ``GT_HomeStop(axis, pos, vel, acc)`` is ``GT_Home`` with ``offset`` 0: the axis stands
  on the captured home.
* ``GT_HomeInit()`` forgets every armed ``GT_Index`` of the card.  A homing works without
  it too (a master-log line says it was not called).  ``GT_Reset`` forgets them as well.
* ``GT_HomeSts(axis, &status)``: ``status`` 1 once the last homing of the axis (these calls
  or ``GT_GoHome``) has ended standing at its target, 0 while it runs or when none ran.  A
  homing that failed gives ``status`` 0 and returns 1 with the reason (the smart home's
  error: no home within the distance, a limit, the axis switched off, ...), so a loop that
  waits for 1 can end.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from .._attrs import PerObject
from ..controller.core import Controller
from ..controller.profile import PrfMode
from ..controller.resources import axis_resources
from ..controller.smart_home import HomeError, HomeMode, HomeParams, Stage, smart_home
from ..errors import CommandError, ParameterError
from ._core import gt_function, store
from .crd_calls import _real


@dataclass(frozen=True, slots=True)
class _Index:
    pos: int
    offset: int


class _State:
    def __init__(self) -> None:
        self.index: dict[int, _Index] = {}
        self.init = False


_STATES: PerObject[_State] = PerObject("legacy_home")


def _state(ctl: Controller) -> _State:
    """The card's homing state: the bus controller's, whichever core the call names (the
    armed indexes are kept by bus axis number)."""
    base = getattr(ctl, "_base", ctl)
    st = _STATES.get(base)
    if st is None:
        st = _STATES[base] = _State()
        base.on_reset.append(_reset)
    return st


def _reset(ctl: Controller) -> None:
    st = _STATES.get(ctl)
    if st is not None:
        st.index.clear()
        st.init = False


@gt_function
def GT_HomeInit(ctl: Controller) -> int:
    """Start the card's homing afresh: every armed GT_Index is forgotten."""
    st = _state(ctl)
    st.index.clear()
    st.init = True
    return 0


@gt_function
def GT_Index(ctl: Controller, axis: int, pos: int, offset: int) -> int:
    """Arm the index stage of the next GT_Home of ``axis`` (the module docstring)."""
    res = axis_resources(ctl, axis)  # a bad axis is 7 now, not at GT_Home
    _state(ctl).index[res.number] = _Index(int(pos), int(offset))
    return 0


def _home(ctl: Controller, axis: int, pos: int, vel: Any, acc: Any, offset: int, what: str) -> int:
    res = axis_resources(ctl, axis)
    v, a = _real("vel", vel), _real("acc", acc)
    if v <= 0.0 or a <= 0.0:
        raise ParameterError(f"vel={v}, acc={a}: both must be > 0")
    home = smart_home(ctl, axis)
    if home.running:
        raise CommandError(f"axis {axis} is homing already; wait until GT_HomeSts gives 1")
    if res.profile.mode not in (PrfMode.TRAP, PrfMode.JOG) and not res.moving:
        res.prf_trap()  # the card's homing takes a standing axis over
    here = round(res.profile.planner.pos)
    if int(pos) == here:
        raise ParameterError(f"pos={pos}: the axis stands there; the search needs a direction")
    state = _state(ctl)
    if not state.init:
        ctl.log(f"{what}: axis {axis} homes without GT_HomeInit having been called")
    d = 1 if int(pos) > here else -1
    idx = state.index.pop(res.number, None)
    prm = HomeParams(
        mode=HomeMode.HOME if idx is None else HomeMode.HOME_INDEX,
        moveDir=d,
        indexDir=d if idx is None or idx.pos == 0 else (1 if idx.pos > 0 else -1),
        velHigh=v,
        velLow=v,
        acc=a,
        dec=a,
        homeOffset=int(offset) if idx is None else idx.offset,
        searchHomeDistance=abs(int(pos) - here),
        searchIndexDistance=0 if idx is None else abs(idx.pos),
    )
    home.start(prm)
    if not home.running:  # refused: the status says why
        raise CommandError(home.reason or f"{what}: axis {axis} cannot home")
    return 0


@gt_function
def GT_Home(ctl: Controller, axis: int, pos: int, vel: float, acc: float, offset: int) -> int:
    """Search the home towards ``pos``; stand at home + ``offset`` (or at the index)."""
    return _home(ctl, axis, pos, vel, acc, offset, "GT_Home")


@gt_function
def GT_HomeStop(ctl: Controller, axis: int, pos: int, vel: float, acc: float) -> int:
    """GT_Home with offset 0: stand on the captured home."""
    return _home(ctl, axis, pos, vel, acc, 0, "GT_HomeStop")


@gt_function
def GT_HomeSts(ctl: Controller, axis: int, pStatus: Any) -> int:
    """1 when the axis's last homing ended at its target; 0 while running or none ran."""
    home = smart_home(ctl, axis)
    s = home.status
    failed = not s.run and s.error != HomeError.NONE
    store(pStatus, int(not s.run and s.stage == Stage.END and not failed))
    if failed:
        why = home.reason or f"error {int(s.error)}"
        raise CommandError(f"the homing of axis {axis} failed in stage {int(s.stage)}: {why}")
    return 0
