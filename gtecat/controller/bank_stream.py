"""GT calls that stream into an axis the bank runs, without giving it back.

A PLC-style program gives its axes a new target every few cycles (``GT_MoveAbsolute``), and a
PT application refills its dynamic FIFOs while they run (``GT_PtSpace``, then ``GT_PtData`` per
free slot).  Before, each such call gave its axis back to the scalar objects (a release:
the row's state written into them) and the bank took it again at the next cycle (a claim):
on 64 axes about 50 µs (a new target) and 90 µs (a PT point) per call.  Here those calls run
on the claimed row itself, exactly where the scalar path would run them from that state:

* ``GT_MoveAbsolute`` on a row standing or moving in Trap (:func:`retarget`): the planner
  is put where the scalar path has it now (``trap_table.advance``, as a release does), the
  function runs on it, and the row takes the new move up from the planner (its pieces, its
  constants, an empty table the next cycle fills) - a release and a claim put the same
  values into the objects and take the same ones back.  A call that fails leaves the
  planner as it was.  Anything else (another mode, a row a hook watches, a drive stepping
  in place) takes the ordinary way.
* ``GT_PtData`` / ``GT_PtSpace`` on a row in PT (:func:`pt_call`): they read and append to the
  FIFOs, which the bank's steps of the planner leave alone but at the sample that runs a
  FIFO out (the switch to the other one, or the end of the stream). The bank's tables of a
  dynamic PT row end before such a sample (:mod:`~gtecat.controller.bank_pt_stream`), so
  the FIFOs at any call hold what the scalar path's hold at that cycle, and a point appended
  at the tail reaches no sample already computed.

The differential tests (``tests/gtecat/controller/test_bank_stream.py``) run the same
programs with the bank and without it and compare every axis's positions and status.
"""

from __future__ import annotations

from collections.abc import Callable
from itertools import chain
from operator import attrgetter
from typing import TYPE_CHECKING, Any

from .bank import _GUARD_SET, _SEG_PACK, _TPRM_PACK, MAXSEG, NTPRM, _Bypass, _reguard, _unguard
from .bank_pt_stream import fifos_current
from .motion.pt import PtPlanner
from .motion.trap import _MOVE, TrapPlanner
from .motion.trap_table import advance
from .profile import PrfMode

if TYPE_CHECKING:
    from .bank import AxisBank

#: the GT functions :func:`call_streamed` runs on a claimed row
STREAMED = frozenset({"GT_MoveAbsolute", "GT_PtData", "GT_PtSpace"})

_get, _set = object.__getattribute__, object.__setattr__
#: what a Trap planner's advance and start change (restored when the call fails)
_TRAP_SLOTS = ("_k", "_pos", "_vel", "_acc", "_mode", "_segs", "_i", "_j", "_ts", "_t_done",
               "_t_final", "_dir", "_target", "_speed", "_prm", "stopping")  # fmt: skip
_trap_state = attrgetter(*_TRAP_SLOTS)
_chain = chain.from_iterable


def call_streamed(
    bank: AxisBank, ctl: Any, proto: Any, values: tuple, call: Callable[[], Any]
) -> Any:
    """``call()``'s result, a GT function of :data:`STREAMED` with ``values`` on ``ctl``: on
    its axis's claimed row where that row allows it (module docstring), else as any call
    (its axis given back first: :meth:`AxisBank.before_call`)."""
    r = stream_row(bank, ctl, proto.name, values)
    if r >= 0:
        if proto.name == "GT_MoveAbsolute":
            return retarget(bank, r, call)
        return pt_call(bank, r, call)
    bank.before_call(ctl, proto, values)
    return call()


def stream_row(bank: AxisBank, ctl: Any, name: str, values: tuple) -> int:
    """The claimed row GT function ``name`` of :data:`STREAMED` with ``values`` may run on,
    the row kept (module docstring), else -1."""
    r = _row(bank, ctl, values)
    if r < 0:
        return -1
    if name == "GT_MoveAbsolute":
        return r if _trap_row(bank, r) else -1
    return r if _pt_row(bank, r, name, values) else -1


def on_row(obj: Any, fn: Callable[[], Any]) -> Any:
    """``fn()`` with ``obj`` (a claimed row's planner) out of its guard class for the call:
    read and changed as it is, nothing given back (a guarded attribute costs a Python call)."""
    cls = type(obj)
    if cls not in _GUARD_SET:
        return fn()
    _set(obj, "__class__", cls.__base__)
    try:
        return fn()
    finally:
        _set(obj, "__class__", cls)


def _row(bank: AxisBank, ctl: Any, values: tuple) -> int:
    """The claimed row of the call's axis, in a state no step is under way in, else -1."""
    if not (bank.n_alive and bank.built and values) or bank._stepping >= 0:
        return -1
    if bank._opened or bank._frozen_call >= 0:
        return -1
    n = values[0]
    if type(n) is not int:
        return -1
    ax = ctl.axes.get(n)
    r = bank._row_of.get(id(ax)) if ax is not None else None
    if r is None or not bank.alive[r] or r in bank._open or r in bank._aware:
        return -1
    if r in bank._post_next or r in bank._tp_apply:
        return -1
    return r  # type: ignore[no-any-return]


# --- GT_MoveAbsolute: a Trap row retargeted in place ------------------------------------------
def _trap_row(bank: AxisBank, r: int) -> bool:
    """Row ``r`` stands or moves in Trap (not jogging, homing, frozen, stepped by a cluster)."""
    if bank.sampled[r] or bank.jog[r] or bank.hm[r] or bank.frz[r]:
        return False
    prof = bank.res[r].profile
    if prof.mode != PrfMode.TRAP or not prof.active:
        return False
    pl = prof.planner
    return pl is prof.trap and TrapPlanner in type(pl).__mro__


def retarget(bank: AxisBank, r: int, call: Callable[[], Any]) -> Any:
    """``call()`` (GT_MoveAbsolute) on claimed Trap row ``r``: its planner put where the
    scalar path has it now, the call run on it, the row taking the new move up."""
    res = bank.res[r]
    pl = res.profile.planner
    was_moving = bool(bank.moving[r])
    # the row's objects read as they are, nothing given back: the planner and the axis the
    # call reads out of their guard classes (a guarded attribute costs a Python call)
    objs = (pl, bank.axes[r])
    _unguard(objs)
    _Bypass.on = True
    try:
        kept = _trap_state(pl)
        if _get(pl, "_mode") == _MOVE:
            advance(pl, int(bank.taken[r]), bank._planned_row(r), bool(bank.ended[r]))
        try:
            rc = call()
        except BaseException:
            for name, value in zip(_TRAP_SLOTS, kept, strict=True):
                _set(pl, name, value)
            raise
        claimed = bool(bank.alive[r])
        if claimed:
            load_trap(bank, r, pl)
    finally:
        _Bypass.on = False
        if bank.alive[r]:
            _reguard(objs)
    if not claimed:  # (given back meanwhile: its objects are the scalar path's)
        return rc
    bank._after_load(r, was_moving)
    bank.streamed_calls += 1
    return rc


def load_trap(bank: AxisBank, r: int, pl: TrapPlanner) -> None:
    """Row ``r``'s Trap move taken up from its planner, as :meth:`AxisBank._load` takes it
    (the row's other state - drive, encoder, band, flags - is what it was)."""
    moving = pl._mode == _MOVE
    bank.moving[r] = moving
    bank.taken[r] = 0
    bank.k0[r] = pl._k if moving else 0
    bank.ended[r] = False
    bank._kept.pop(r, None)
    segs = pl._segs
    if moving and len(segs) <= MAXSEG and bank._kernel_lib is not None:
        m = len(segs)
        _SEG_PACK[m].pack_into(bank.seg, r * MAXSEG * 32, *_chain(segs))
        _TPRM_PACK.pack_into(
            bank.tprm, r * NTPRM * 8,
            pl._t_done, pl._ts, pl._t_final, float(pl._target), pl._dir, pl._T,
        )  # fmt: skip
        bank.nseg[r] = m
    else:
        bank.nseg[r] = 0
    i = int(bank.base[r]) + (bank.table if moving else 0)
    bank._t_p1[i], bank._t_v1[i], bank._t_a1[i] = pl._pos, pl._vel, pl._acc
    bank.t_idx[r] = i
    if moving:
        bank.t_cur[r], bank.t_len[r], bank.t_end[r] = 0, 0, -1
    else:
        bank.t_cur[r], bank.t_len[r], bank.t_end[r] = 0, 1, 0


# --- GT_PtData / GT_PtSpace: the FIFOs of a PT row ---------------------------------------------
def _pt_row(bank: AxisBank, r: int, name: str, values: tuple) -> bool:
    """Row ``r`` is in PT and its FIFOs are now what the scalar path's are now."""
    prof = bank.res[r].profile
    if prof.mode != PrfMode.PT:
        return False
    pl = prof.planner
    if PtPlanner not in type(pl).__mro__:
        return False
    return fifos_current(bank, r, pl, name, values)


def pt_call(bank: AxisBank, r: int, call: Callable[[], Any]) -> Any:
    """``call()`` (GT_PtData, GT_PtSpace) on claimed PT row ``r``: the planner's FIFOs read
    and appended to as they stand (they are the scalar path's: :func:`_pt_row`)."""
    _Bypass.on = True
    try:
        rc = on_row(bank.res[r].profile.planner, call)
    finally:
        _Bypass.on = False
    bank.streamed_calls += 1
    return rc


__all__ = ["STREAMED", "call_streamed", "load_trap", "on_row", "pt_call", "retarget", "stream_row"]
