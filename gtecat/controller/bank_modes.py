"""The axis bank's other motion modes: PT, Gear, Follow and coordinated motion (crd).

A Trap move's samples have a closed form, so the bank computes them in tables
(:func:`~gtecat.controller.motion.trap_table.trap_table`, or the compiled kernel).  The
planners of the other modes are stepped cycle by cycle, and some read other axes: a Gear or
Follow slave reads its master's planned position every cycle, a coordinate system moves
its axes together.  The bank runs them so:

* **Clusters.**  The axes whose planners depend on each other form one cluster: a moving
  Gear/Follow slave with its master (reading the master's *profile*, ``GT_Set*Master`` type 2),
  the axes of one running coordinate system, chains of those; a PT axis is a cluster of its
  own.  A cluster is claimed whole or not at all, and given back whole.  A slave that reads
  its master some other way (the encoder, the axis's planned position), or a master or a
  system the bank cannot run, keeps the whole cluster on the scalar path, and nothing else.
* **Tables stepped ahead.**  When a cluster's tables run out, its real planner objects are
  stepped :data:`SAMPLED_TABLE` cycles ahead, all in the controller's order (coordinate
  systems first, as their ``pre_cycle`` hook runs before the axes; then the axes in number
  order, so a slave reads the sample its master has in that cycle, exactly as in the scalar
  cycle), and the samples go into the rows' tables; the compiled kernel takes them one a
  cycle as it takes a Trap table's.
* **Compiled slaves.**  A Gear or Follow slave in motion whose master reads nobody, and which
  no slave reads, is not stepped in Python: :mod:`~gtecat.controller.bank_slaves` holds its
  state while the cluster is claimed and fills the tables of all such slaves of the cluster
  in one C call, from the positions its master holds in those cycles (the same operations as
  its planner's ``step``).
* **Given back exactly.**  Before the steps, the state of every planner (and coordinate
  system) of the cluster is kept.  A release puts it back and steps the planners again as
  many cycles as the bank ran since (never more than one table), so they stand where the
  scalar path would have them.  That needs the steps to be repeatable and to touch nothing
  outside the planner: a static PT FIFO (a dynamic one empties its FIFOs: its own tables,
  :mod:`~gtecat.controller.bank_pt_stream`), a Follow without
  a pending FIFO switch, a coordinate system whose FIFO holds only lines, arcs and delays
  (no GT_BufIO, GT_BufMove, GT_BufGear, no segment with its own speed plan); anything else
  stays scalar.
"""

from __future__ import annotations

from collections import deque
from operator import attrgetter
from typing import TYPE_CHECKING, Any

import numpy as np

from .bank_crd import crd_fill
from .bank_kernel import MAXSEG, PT_STATE
from .bank_pt_stream import stream_kind, stream_of
from .bank_pvt import compiled_kind as pvt_compiled_kind
from .bank_pvt import fill_row as pvt_fill_row
from .bank_pvt import pvt_fill
from .bank_slaves import compiled_kind, slave_fill
from .crd.system import AxisSlot, CoordSystem, CrdNow, Delay, Motion
from .motion.follow import FollowPlanner
from .motion.gear import GearPlanner
from .motion.master import SlavePlanner
from .motion.pt import PtMode, PtPlanner
from .motion.pvt import PvtPlanner
from .motion.stop import StopKind
from .motion.trap import _IDLE as _TRAP_IDLE
from .motion.trap import _MOVE as _TRAP_MOVE
from .motion.trap import TrapPlanner
from .motion.trap_table import advance, trap_table

if TYPE_CHECKING:
    from .bank import AxisBank

#: the state in which a slave's table may be filled with the others of its master (moving)
_FAST = {GearPlanner: 1, FollowPlanner: 2}
#: samples a cluster's planners are stepped ahead at once (the rewind at a release is at
#: most this many steps)
SAMPLED_TABLE = 32
#: master type of GT_SetGearMaster / GT_SetFollowMaster the bank follows: the profile
_MASTER_PROFILE = 2

_get = object.__getattribute__
_set = object.__setattr__
#: the attribute that is 0 when a planner of this type stands (``done``), where it has one
_REST: dict[type, str] = {
    PtPlanner: "_state",
    PvtPlanner: "_state",
    GearPlanner: "_state",
    FollowPlanner: "_state",
    TrapPlanner: "_mode",
}


# --- which planners a cluster may hold -----------------------------------------------------
def sampled_kind(pl: Any) -> bool:
    """``pl`` is a planner of a mode the bank steps ahead (PT, Gear, Follow, crd), in a state
    it can step ahead and rewind (module docstring); False for Trap and Jog (their own paths)
    and anything else."""
    if pl.stopping != StopKind.NONE:
        return False
    t = type(pl).__mro__
    if PtPlanner in t:
        return True  # (a dynamic FIFO in motion: bank_pt_stream)
    if PvtPlanner in t:  # (a table's run changes the planner alone: bank_pvt)
        return True
    if GearPlanner in t:
        return True
    if FollowPlanner in t:
        return not _get(pl, "_switch")
    if AxisSlot in t:
        return not _get(pl, "_fresh") and (not pl.crd.running or system_plain(pl.crd))
    return False


def trap_steppable(pl: Any) -> bool:
    """A Trap planner a cluster may step (a master of a Gear/Follow slave): at rest or moving."""
    return TrapPlanner in type(pl).__mro__ and _get(pl, "_mode") in (_TRAP_IDLE, _TRAP_MOVE)


def system_plain(c: CoordSystem) -> bool:
    """A running coordinate system whose steps are repeatable and touch nothing else."""
    if c.stopping != StopKind.NONE or c.waiting is not None or c.gears or c.gears_next:
        return False
    e = c.entry
    if e is not None and not (type(e) is Delay or (type(e) is Motion and e.speed_plan is None)):
        return False
    q = c.fifos[c.fifo]
    if not q:
        return True
    # a FIFO seen plain stays plain while it only loses entries at its head and gains plain
    # ones at its tail: only those after the last entry seen are looked at (a segment pushed
    # every cycle while the path runs costs one look, not one over the whole FIFO)
    last = q[-1]
    seen = _PLAIN.get(id(c))
    old = seen[1] if seen is not None and seen[0] == c.fifo else None
    if last is old and len(q) <= seen[2]:  # type: ignore[index]
        return True
    for e in reversed(q):
        if e is old:
            break
        t = type(e)
        if t is Delay:
            continue
        if t is not Motion or e.speed_plan is not None:
            return False
    _PLAIN[id(c)] = (c.fifo, last, len(q))
    return True


#: id(system) -> (fifo, its last entry, length) of the last FIFO seen plain (the entry itself
#: kept: its id cannot be taken by a new one)
_PLAIN: dict[int, tuple[int, Any, int]] = {}


#: per planner class: 1 when :func:`links` looks at its planners (a slave, a coordinate
#: system's axis, PT), 0 when they read nobody
_LINK_KIND: dict[type, int] = {}


def _link_kind(cls: type) -> int:
    t = cls.__mro__
    kind = int(SlavePlanner in t or AxisSlot in t or PtPlanner in t or PvtPlanner in t)
    _LINK_KIND[cls] = kind
    return kind


def links(bank: AxisBank) -> tuple[list[tuple[int, int]], set[int], set[int]]:
    """(pairs of rows that must stay together, rows stepped ahead in the bank, rows that must
    stay scalar because of a dependency the bank cannot follow); read with the guards off."""
    pairs: list[tuple[int, int]] = []
    sampled: set[int] = set()
    bad: set[int] = set()
    row_of_ax = bank._row_of
    row_of_pl: dict[int, int] | None = None
    kinds = _LINK_KIND
    # the rows to look at: every row out of the bank, and the claimed rows whose planner was
    # of a kind that reads or is read when last looked at (a claimed row's planner is the one
    # it had at its claim: anything that could change it gives the row back first)
    seen = bank._row_link
    if seen is None or len(seen) != len(bank.res):
        seen = bank._row_link = np.full(len(bank.res), -1, np.int8)
    res_of = bank.res
    # (np.flatnonzero and ndarray.any cost several times the ufuncs underneath on a bank's
    # few rows: this runs at every look of the bank)
    out = ~bank.alive
    if np.count_nonzero(seen):
        out |= seen != 0
    for r in out.nonzero()[0].tolist():
        res = res_of[r]
        if res is None:
            continue
        pl = res.profile.planner
        kind = kinds.get(type(pl))
        if kind is None:
            kind = _link_kind(type(pl))
        seen[r] = kind
        if not kind:
            continue  # a Trap, a Jog, a homing: reads nobody
        t = type(pl).__mro__
        if SlavePlanner in t:
            if _get(pl, "_state") == 0:
                continue  # a slave at rest reads nobody
            sampled.add(r)
            src = _get(pl, "_source")
            master = getattr(src, "master", None)
            mr = row_of_ax.get(id(master[0].ax)) if master is not None else None
            if mr is None:
                bad.add(r)
                continue
            mres = res_of[mr]
            if master[1] != _MASTER_PROFILE or (
                mres is not None and stream_kind(mres.profile.planner)
            ):
                # (a dynamic PT master's stream runs alone: bank_pt_stream)
                bad.update((r, mr))
                continue
            pairs.append((r, mr))
            sampled.add(mr)
        elif AxisSlot in t:
            c = pl.crd
            if not c.running:
                continue
            if row_of_pl is None:
                row_of_pl = {
                    id(x.profile.planner): k for k, x in enumerate(bank.res) if x is not None
                }
            sampled.add(r)
            for s in c.slots:
                k = row_of_pl.get(id(s))
                if k is None:
                    bad.add(r)
                else:
                    pairs.append((r, k))
        elif (PtPlanner in t or PvtPlanner in t) and _get(pl, "_state") != 0:
            sampled.add(r)
    return pairs, sampled, bad


# --- keeping and putting back a planner's state ----------------------------------------------
_NAMES: dict[type, tuple[tuple[str, ...], bool, Any]] = {}
_UNSET = object()
_CONTAINERS = (list, deque, dict)


def _names(cls: type) -> tuple[tuple[str, ...], bool, Any]:
    """(the slots of ``cls``, whether it has a ``__dict__``, a getter of all slots at once)."""
    got = _NAMES.get(cls)
    if got is None:
        slots: list[str] = []
        has_dict = False
        for k in cls.__mro__:
            if k is object:
                continue
            s = k.__dict__.get("__slots__")
            if s is None:
                has_dict = True
                continue
            for name in (s,) if isinstance(s, str) else s:
                if name == "__dict__":
                    has_dict = True
                elif name != "__weakref__" and name not in slots:
                    slots.append(name)
        getter = attrgetter(*slots) if len(slots) > 1 else None
        got = _NAMES[cls] = (tuple(slots), has_dict, getter)
    return got


def _keep(v: Any) -> Any:
    t = type(v)
    if t is list or t is deque:
        return (v, list(v))
    if t is dict:
        return (v, dict(v))
    if t is tuple and any(type(x) in _CONTAINERS for x in v):
        return (v, tuple(_keep(x) for x in v))
    return (v, None)


def _put(kept: Any) -> Any:
    v, c = kept
    if c is not None:
        t = type(v)
        if t is list:
            v[:] = c
        elif t is deque:
            v.clear()
            v.extend(c)
        elif t is dict:
            v.clear()
            v.update(c)
        else:  # a tuple of containers
            for x in c:
                _put(x)
    return v


def snapshot(obj: Any) -> tuple:
    """Everything ``obj`` holds (its slots and its ``__dict__``; lists, deques and dicts by
    content): :func:`restore` puts it back.  ``obj`` must not be guarded by the bank."""
    slots, has_dict, getter = _names(type(obj))
    vals: Any = None
    if getter is not None:
        try:
            vals = getter(obj)  # every slot in one call
        except AttributeError:
            vals = None
    if vals is None:
        vals = []
        for name in slots:
            try:
                vals.append(_get(obj, name))
            except AttributeError:
                vals.append(_UNSET)
    kept = [(i, _keep(v)) for i, v in enumerate(vals) if type(v) in _KEEP]
    d = None
    if has_dict:
        d = {k: _keep(v) for k, v in _get(obj, "__dict__").items()}
    return (tuple(vals), kept, d)


#: values kept by content (a tuple: when it holds containers)
_KEEP = (list, deque, dict, tuple)


def restore(obj: Any, snap: tuple) -> None:
    slots, _, _ = _names(type(obj))
    vals, kept, d = snap
    for name, v in zip(slots, vals, strict=True):
        if v is not _UNSET:
            _set(obj, name, v)
    for _, k in kept:
        _put(k)
    if d is not None:
        od = _get(obj, "__dict__")
        od.clear()
        for k, kv in d.items():
            od[k] = _put(kv)


#: a PT planner's steps through a static FIFO change only these slots (bank_kernel.PT_STATE)
_PT_MOVING = object()
_PT_STATE_OF = attrgetter(*PT_STATE)


#: ... and a geared planner's (GearPlanner.step and _through_clutch)
_GEAR_MOVING = object()
_GEAR_STATE = ("_m_prev", "_pos", "_vel", "_acc", "_cl", "_x", "_state")
_GEAR_STATE_OF = attrgetter(*_GEAR_STATE)


#: ... and a following planner's (FollowPlanner.step, _follow, _advance, _begin_pass; its
#: cam segment list only grows, or is replaced, within a pass: kept with its length)
_FOLLOW_MOVING = object()
_FOLLOW_STATE = ("_x _m_prev _pos _vel _acc _i _segs _loops_done _x0 _s0 _carry _sd _state").split()
_FOLLOW_STATE_OF = attrgetter(*_FOLLOW_STATE)


#: ... and a Trap planner's in motion (TrapPlanner.step, _sample, _finish: its pieces are
#: replaced by a new list, never changed in place)
_TRAP_MOVING = object()
_TRAP_STATE = ("_k", "_pos", "_vel", "_acc", "_mode", "_segs", "_i", "_j")
_TRAP_STATE_OF = attrgetter(*_TRAP_STATE)
#: ... and an axis slot's (the planner of a coordinate system's axis)
_SLOT_MOVING = object()
_SLOT_STATE = ("_pos", "_vel", "_acc", "_fresh", "stopping")
_SLOT_STATE_OF = attrgetter(*_SLOT_STATE)
_MOVING = {
    _PT_MOVING: PT_STATE,
    _GEAR_MOVING: _GEAR_STATE,
    _FOLLOW_MOVING: _FOLLOW_STATE,
    _TRAP_MOVING: _TRAP_STATE,
    _SLOT_MOVING: _SLOT_STATE,
}

#: ... and a running coordinate system's (step, _next, _finish, _idle; its count of segments
#: done changes in place, its FIFO loses entries at its head: CoordSystem.popped records them)
_CRD_MOVING = object()
_CRD_STATE = (
    "running fifo stopping entry plan t s speed stop_acc waiting gears gears_next gear_entry"
).split()
_CRD_STATE_OF = attrgetter(*_CRD_STATE)


def _keep_system(c: CoordSystem) -> tuple:
    """What a running system's steps change (:func:`keep`); from now on it records the
    entries it takes off its FIFOs."""
    popped: list = []
    c.popped = popped
    return (_CRD_MOVING, _CRD_STATE_OF(c), c.segments_done, list(c.segments_done), list(c.tails))


def kept_push(c: CoordSystem, snap: tuple, entry: Any, fifo: int) -> None:
    """``entry`` was pushed onto ``fifo`` of ``c`` after its state was kept (``snap``, of
    :func:`keep`): the state put back holds it too."""
    if snap[0] is _CRD_MOVING:  # the entry stays on the FIFO: only its head is put back
        snap[4][fifo] = c.tails[fifo]
        return
    kept = snap[2]  # snapshot: the __dict__, containers by content
    kept["fifos"][1][fifo][1].append(entry)
    kept["tails"][1][fifo] = c.tails[fifo]


def _put_back_system(c: CoordSystem, snap: tuple) -> None:
    """:func:`_keep_system`'s state back: the entries taken off the running FIFO since go back
    to its head (those pushed since stay at its tail)."""
    _, values, done, counts, tails = snap
    popped = c.popped
    for name, value in zip(_CRD_STATE, values, strict=True):
        _set(c, name, value)
    done[:] = counts
    c.segments_done = done
    c.tails[:] = tails
    if popped:
        q = c.fifos[c.fifo]
        q.extendleft(reversed(popped))
    c.popped = None


def keep(obj: Any) -> tuple:
    """:func:`snapshot`, or for a PT planner moving through a static FIFO, a geared planner,
    a following one or a Trap master in motion only the slots its steps change."""
    t = type(obj).__mro__
    if TrapPlanner in t and _get(obj, "_mode") == _TRAP_MOVE and obj.stopping == StopKind.NONE:
        return (_TRAP_MOVING, _TRAP_STATE_OF(obj))
    if PtPlanner in t and _get(obj, "_state") == 1 and _get(obj, "_mode") == PtMode.STATIC:
        return (_PT_MOVING, _PT_STATE_OF(obj))
    if GearPlanner in t and _get(obj, "_state") == 1:
        return (_GEAR_MOVING, _GEAR_STATE_OF(obj))
    if FollowPlanner in t and _get(obj, "_state") == 2 and not _get(obj, "_switch"):
        return (_FOLLOW_MOVING, _FOLLOW_STATE_OF(obj), len(_get(obj, "_segs")))
    if AxisSlot in t:
        return (_SLOT_MOVING, _SLOT_STATE_OF(obj))
    if CoordSystem in t:
        if obj.running and not obj.stopping:
            return _keep_system(obj)
        obj.popped = None
    return snapshot(obj)


def _trap_samples(
    bank: AxisBank, pl: TrapPlanner, n: int, held: dict[int, tuple] | None = None
) -> tuple[Any, Any, Any, int]:
    """:func:`~gtecat.controller.motion.trap_table.trap_table` of a Trap master, compiled
    where the kernel is (bank_kernel.trap_fill: the same samples; the arrays returned are
    the bank's scratch, valid until the next call).  ``held``: the planner's pieces as the
    kernel reads them, kept from one call to the next while the plan stays (a new plan is a
    new list of pieces)."""
    lib = bank._kernel_lib
    k = len(pl._segs)
    if lib is None or k > MAXSEG:
        return trap_table(pl, n)
    sc = bank.__dict__.get("_trap_scratch")
    if sc is None or sc[0] is not lib or sc[1].shape[1] < n + 1:
        prm, out = np.zeros(5), np.zeros((3, n + 1))
        ptrs = (prm.ctypes.data, *(out[j].ctypes.data for j in range(3)))
        sc = bank._trap_scratch = (lib, out, prm, ptrs)
    _, out, prm, (p_prm, p0, p1, p2) = sc
    segs = pl._segs
    got = held.get(id(pl)) if held is not None else None
    if got is None or got[0] is not segs or got[1] != k:
        buf = np.array(segs, np.float64).reshape(-1, 4)
        got = (segs, k, buf, buf.ctypes.data)
        if held is not None:
            held[id(pl)] = got
    prm[:] = (pl._t_done, pl._ts, pl._t_final, float(pl._target), pl._dir)
    end = lib.bank_trap_fill(got[3], k, pl._T, p_prm, pl._k, n, p0, p1, p2)
    m = end + 1 if end < n else n
    return out[0, :m], out[1, :m], out[2, :m], end


def _master_travel(pl: Any, ms: list[float]) -> tuple[float, np.ndarray, np.ndarray]:
    """(cycle time, master positions, the master's travel each cycle as the slaves of ``pl``'s
    master take it: only in their follow direction), for the vectorised Gear/Follow rows;
    every slave of one master shares ``pl``'s cycle, direction and last master position."""
    cyc, dir_, m_prev = _get(pl, "_T"), _get(pl, "_dir"), _get(pl, "_m_prev")
    m = np.array(ms, np.float64)
    d = np.diff(m, prepend=m_prev)
    if dir_ > 0:
        d = np.where(d > 0.0, d, 0.0)
    elif dir_ < 0:
        d = np.where(d < 0.0, d, 0.0)
    return cyc, m, d


class SystemTrace:
    """A coordinate system's state in each cycle of a cluster's last fill: the read calls
    (GT_CrdStatus, GT_CrdSpace, GT_GetCrdPos, GT_GetCrdVel) answer from it while the bank
    holds the system a table ahead of the controller's time, without giving it back.

    ``start``: :meth:`CoordSystem.state` before the fill; ``speeds[j]``: the path speed after
    cycle ``j``; ``marks``: (cycle, state after it) of the cycles :meth:`CoordSystem.run` did
    not take as its common case (only the speed and the positions change in one of those:
    the positions are the slots' samples, ``cols``); every cycle is marked where ``cols`` is
    None."""

    __slots__ = ("bank", "cols", "marks", "memo", "pushed", "rows", "speeds", "start")

    def __init__(self, bank: AxisBank, rows: list[int], c: CoordSystem) -> None:
        self.bank = bank
        self.rows = rows
        #: (the bank's cycle count, the answer): the reads of one cycle share it
        self.memo: tuple[int, Any] | None = None
        self.start = c.state()
        self.speeds: list[float] = []
        self.marks: list[tuple[int, tuple]] = []
        #: the slots' positions in each cycle (``cols[k][j]``: slot ``k``, cycle ``j``)
        self.cols: Any = None
        #: entries pushed onto each FIFO since (AxisBank._pushed_ahead): not in the states
        self.pushed = [0, 0]

    def now(self, c: CoordSystem) -> Any:
        """``c`` as the scalar path has it now: the cluster's rows took ``m`` samples since the
        fill (as :meth:`Cluster.rewind` counts them); past the cycles stepped, ``c``'s own."""
        bank = self.bank
        memo = self.memo
        cycles = bank.bank_cycles
        if memo is not None and memo[0] == cycles:
            return memo[1]
        now = self._at(c)
        self.memo = (cycles, now)
        return now

    def _at(self, c: CoordSystem) -> Any:
        bank = self.bank
        taken, filled = bank.taken, bank.fill_taken
        m = max(int(taken[r]) - int(filled[r]) for r in self.rows)
        if m >= len(self.speeds):  # the objects stand where the scalar path has them
            return CrdNow(c, c.state())
        if m == 0:
            return CrdNow(c, self._pushed(self.start))
        marks = self.marks
        j = m - 1
        k = len(marks) - 1
        while k >= 0 and marks[k][0] > j:
            k -= 1
        if k >= 0 and marks[k][0] == j:
            return CrdNow(c, self._pushed(marks[k][1]))
        base = marks[k][1] if k >= 0 else self.start
        cols = self.cols
        assert cols is not None
        pos = tuple(float(col[j]) - o for col, o in zip(cols, c.origin, strict=True))
        return CrdNow(c, self._pushed((*base[:6], self.speeds[j], pos, base[8])))

    def _pushed(self, st: tuple) -> tuple:
        p0, p1 = self.pushed
        if not (p0 or p1):
            return st
        return (*st[:4], st[4] + p0, st[5] + p1, *st[6:])


class Cluster:
    """Rows whose planners the bank steps ahead together (module docstring)."""

    __slots__ = (
        "alone",
        "before",
        "compiled",
        "compiled_pt",
        "compiled_ptr",
        "compiled_rows",
        "ext",
        "groups",
        "kept",
        "leads",
        "list_leads",
        "masters",
        "planners",
        "pt_stream",
        "pts",
        "rows",
        "rows_arr",
        "rows_sel",
        "slot_of",
        "snaps",
        "stepped",
        "systems",
        "topo",
        "trap_pieces",
    )

    def __init__(self, bank: AxisBank, rows: list[int], groups: list[int]) -> None:
        order = bank.order
        self.rows = sorted(rows, key=lambda r: order[r])
        self.groups = groups
        self.planners = [bank.res[r].profile.planner for r in self.rows]
        systems: list[CoordSystem] = []
        for pl in self.planners:
            if AxisSlot in type(pl).__mro__ and pl.crd.running and pl.crd not in systems:
                systems.append(pl.crd)
        self.systems = systems
        self.snaps: list[tuple[Any, tuple]] | None = None
        self.rows_arr = np.array(self.rows, np.intp)
        #: the rows as a slice where they follow each other (basic indexing, cheaper)
        r0 = self.rows[0]
        consecutive = self.rows == list(range(r0, r0 + len(self.rows)))
        self.rows_sel: Any = slice(r0, r0 + len(self.rows)) if consecutive else self.rows_arr
        #: a cluster of one coordinate system (``alone``): each row's slot in it
        self.slot_of: Any = None
        #: id(Trap master) -> its pieces as the compiled fill reads them (_trap_samples)
        self.trap_pieces: dict[int, tuple] = {}
        #: the objects a fill keeps for the rewind; the planners it steps in Python (the
        #: others: the compiled slaves, bank_slaves)
        self.kept: list[Any] = [*self.planners, *systems]
        self.stepped: list[Any] = list(self.planners)
        #: the indices of the slaves the compiled fill runs (bank_slaves.SlaveFill), their
        #: rows, and per master (index, rows reading its sample of the same cycle, rows
        #: reading the one before)
        self.compiled: list[int] = []
        self.compiled_rows = np.zeros(0, np.int64)
        self.compiled_ptr = 0  # (its address)
        #: per master of compiled slaves: its position before a fill and after each cycle
        #: of it (what the slaves read, at addresses SlaveFill.mp holds)
        self.ext: dict[int, np.ndarray] = {}
        #: the cluster is one coordinate system with its axes and nothing else
        self.alone = len(systems) == 1 and {id(pl) for pl in self.planners} == {
            id(slot) for slot in systems[0].slots
        }
        # a PT axis alone through a static FIFO: its tables filled by the compiled kernel for
        # all such rows at once (bank_kernel.PtFill holds its state meanwhile)
        # (a PVT axis alone in motion too: bank_pvt.PvtFill); ``compiled_pt`` is that fill
        pl = self.planners[0]
        self.compiled_pt: Any = None
        if len(self.rows) == 1:
            if (
                bank.pt_fill is not None
                and PtPlanner in type(pl).__mro__
                and _get(pl, "_state") == 1
                and _get(pl, "_mode") == PtMode.STATIC
            ):
                self.compiled_pt = bank.pt_fill
            elif pvt_compiled_kind(pl):
                self.compiled_pt = pvt_fill(bank)
            if self.compiled_pt is not None:
                self.compiled_pt.load(self.rows[0], pl)
        #: a PT axis alone running a dynamic FIFO (bank_pt_stream fills its tables)
        self.pt_stream = len(self.rows) == 1 and stream_kind(pl)
        if self.pt_stream:
            stream_of(bank).load(self.rows[0], pl)
        self.before: list[bool] = []
        #: a static PT FIFO's points for the compiled fill: (address, rows, the array)
        self.pts: dict[int, tuple[int, int, np.ndarray]] = {}
        # the planners one after the other (masters first) where no coordinate system is
        # in the cluster: :meth:`fill` by columns; else cycle by cycle, all together
        self.masters: list[int | None] = [None] * len(self.rows)
        self.topo: list[int] | None = None
        self.leads: set[int] = set()  # the planners some slave of the cluster reads
        self.list_leads: set[int] = set()  # ... some slave stepped in Python reads
        if systems:
            return
        at = {r: i for i, r in enumerate(self.rows)}
        for i, pl in enumerate(self.planners):
            t = type(pl).__mro__
            if not (PtPlanner in t or TrapPlanner in t or SlavePlanner in t or PvtPlanner in t):
                return
            if SlavePlanner in t and _get(pl, "_state") != 0:
                master = getattr(_get(pl, "_source"), "master", None)
                mi = at.get(bank._row_of.get(id(master[0].ax), -1)) if master else None
                if mi is None:
                    return
                self.masters[i] = mi
        topo: list[int] = []
        placed = [False] * len(self.rows)
        while len(topo) < len(self.rows):
            ready = [
                i
                for i in range(len(self.rows))
                if not placed[i] and (self.masters[i] is None or placed[self.masters[i]])
            ]
            if not ready:
                return  # slaves of each other: cycle by cycle
            for i in ready:
                placed[i] = True
            topo += ready
        self.topo = topo
        self.leads = {m for m in self.masters if m is not None}
        self.list_leads = set(self.leads)
        # a master read before its slave steps (numbered below it) gives the slave the sample
        # of the same cycle, else the one before (the controller steps axes in number order)
        self.before = [
            m is not None and order[self.rows[m]] < order[r]
            for m, r in zip(self.masters, self.rows, strict=True)
        ]
        self._compile(bank)

    def _compile(self, bank: AxisBank) -> None:
        """Hand the slaves in motion that read a master reading nobody, and that no slave
        reads, to the compiled fill (bank_slaves), where it runs; they are stepped there."""
        masters = self.masters
        cand = [
            i
            for i, mi in enumerate(masters)
            if mi is not None
            and masters[mi] is None
            and i not in self.leads
            and compiled_kind(self.planners[i])
        ]
        if not cand:
            return
        sf = slave_fill(bank)
        if sf is None:
            return
        rows = self.rows
        for i in cand:
            sf.load(rows[i], self.planners[i])
        self.compiled = cand
        self.compiled_rows = np.array([rows[i] for i in cand], np.int64)
        self.compiled_ptr = self.compiled_rows.ctypes.data
        for i in cand:
            mi = masters[i]
            ext = self.ext.get(mi)  # type: ignore[arg-type]
            if ext is None:
                ext = self.ext[mi] = np.zeros(SAMPLED_TABLE + 1)  # type: ignore[index]
            # the master's sample of the same cycle (it steps first), else the one before
            sf.mp[rows[i]] = ext.ctypes.data + (8 if self.before[i] else 0)
        out = set(cand)
        self.list_leads = {mi for i, mi in enumerate(masters) if mi is not None and i not in out}
        self.kept = [pl for i, pl in enumerate(self.planners) if i not in out]
        self.stepped = list(self.kept)
        self.topo = [i for i in self.topo if i not in out]  # type: ignore[union-attr]

    def step(self) -> None:
        """One scalar cycle of the cluster's planners: the systems (the controller's
        ``pre_cycle``), then each axis that moves (``AxisResources._pre``)."""
        for c in self.systems:
            if c.running:
                c.step()
        for pl in self.planners:
            if not pl.done:
                pl.step()

    def fill(self, bank: AxisBank) -> None:
        """The next :data:`SAMPLED_TABLE` samples of every moving row, its planners stepped
        (their state before kept for :meth:`rewind`)."""
        self.snaps = [(o, keep(o)) for o in self.kept]
        rows = self.rows
        moving = bank.moving
        ra = self.rows_sel
        bank.fill_taken[ra] = bank.taken[ra]
        if self.topo is not None:
            self._fill_columns(bank)
            return
        for c in self.systems:
            c.trace = None
        if self.alone:  # one coordinate system and its axes: its own run
            c = self.systems[0]
            if c.running:
                trace = SystemTrace(bank, rows, c)
                cf = crd_fill(bank)
                seg = cf.segment if cf is not None else None
                out, end = c.run(SAMPLED_TABLE, trace.speeds, trace.marks, seg)
                m = end + 1 if end >= 0 else SAMPLED_TABLE
                trace.cols = out[0]
                c.trace = trace
                slot_of = self.slot_of
                if slot_of is None:  # each row's slot (its coordinate) in the system
                    at = {id(slot): k for k, slot in enumerate(c.slots)}
                    slot_of = [at[id(pl)] for pl in self.planners]
                    # (a slice where they are in order: basic indexing, cheaper)
                    in_order = slot_of == list(range(len(slot_of)))
                    self.slot_of = slot_of = slice(None) if in_order else np.array(slot_of)
                if moving[ra].all():  # the rows' new tables in one assignment per table
                    bank.sampled_samples += m * len(rows)
                    bank.keep_last_sample(ra)
                    for t, q in zip((bank.t_p, bank.t_v, bank.t_a), out, strict=True):
                        t[ra, :m] = q[slot_of, :m]
                    bank.t_len[ra] = m
                    bank.t_cur[ra] = 0
                    bank.t_end[ra] = end
                    return
                for i, r in enumerate(rows):
                    if moving[r]:
                        k = i if type(slot_of) is slice else slot_of[i]
                        self._put(bank, r, out[0, k, :m], out[1, k, :m], out[2, k, :m], end)
                return
        pls = self.planners
        systems = self.systems
        # (index, step, the attribute that is 0 at rest or None: ``done``, its samples);
        # a row not moving has a planner at rest, which a cycle does not step
        live = [
            (i, pl.step, _REST.get(type(pl)), [])
            for i, pl in enumerate(pls)
            if moving[rows[i]] and not pl.done
        ]
        ends = [-1] * len(rows)
        cols: list[list[tuple[float, float, float]]] = [[] for _ in rows]
        for i, _, _, col in live:
            cols[i] = col
        table = SAMPLED_TABLE
        if len(live) == 1 and not systems:  # one planner (a PT axis): its steps alone
            i, step, rest, col = live[0]
            pl = pls[i]
            for j in range(table):
                col.append(step())
                if (_get(pl, rest) == 0) if rest else pl.done:
                    ends[i] = j
                    break
        else:
            traces = [SystemTrace(bank, rows, c) for c in systems]
            for j in range(table):
                for c in systems:
                    if c.running:
                        c.step()
                for c, trace in zip(systems, traces, strict=True):
                    trace.speeds.append(c.speed)
                    trace.marks.append((j, c.state()))
                ended = False
                for i, step, rest, col in live:
                    # the others of the cluster at rest: stepping them changes nothing
                    col.append(step())
                    pl = pls[i]
                    if (_get(pl, rest) == 0) if rest else pl.done:
                        ends[i] = j
                        ended = True
                if ended:
                    live = [x for x in live if ends[x[0]] < 0]
            for c, trace in zip(systems, traces, strict=True):
                c.trace = trace
        for i, r in enumerate(rows):
            if cols[i]:
                ps, vs, as_ = (list(x) for x in zip(*cols[i], strict=True))
                self._put(bank, r, ps, vs, as_, ends[i])

    def _fill_columns(self, bank: AxisBank) -> None:
        """:meth:`fill` one planner after the other, masters first: each planner's ``run``
        (its steps at once), a slave given the positions its master holds in those cycles."""
        n = SAMPLED_TABLE
        rows, pls = self.rows, self.planners
        moving = bank.moving
        compiled = bank.pt_run is not None
        seen: list[list[float] | None] = [None] * len(rows)  # positions after each cycle
        full: list[tuple[int, list[float], list[float], list[float]]] = []
        geared: dict[tuple, tuple[list[float], list[int]]] = {}
        starts = [0.0] * len(rows)  # positions before the first
        for i in self.topo:  # type: ignore[union-attr]
            pl = pls[i]
            r = rows[i]
            starts[i] = start = pl.pos
            if not moving[r] or pl.done:
                seen[i] = [start] * n
                if i in self.ext:
                    self.ext[i][:] = start
                continue
            mi = self.masters[i]
            if TrapPlanner in type(pl).__mro__:
                p, v, a, end = _trap_samples(bank, pl, n, self.trap_pieces)
                m = len(p)
                advance(pl, m, (float(p[-1]), float(v[-1]), float(a[-1])), end < n)
                self._put(bank, r, p, v, a, end if end < n else -1)
                if i in self.leads:
                    self._lead(i, start, p, seen)
                continue
            elif mi is None:
                if compiled and PtPlanner in type(pl).__mro__:
                    if _get(pl, "_mode") == PtMode.STATIC and _get(pl, "_state") == 1:
                        self._pt_compiled(bank, i, pl)
                        if i in self.leads:  # (a master of a slave: its positions)
                            self._lead(i, start, bank.t_p[r, : bank.t_len[r]], seen)
                        continue
                if pvt_fill_row(bank, r, pl, n):  # a PVT axis with others (bank_pvt)
                    if i in self.leads:
                        self._lead(i, start, bank.t_p[r, : bank.t_len[r]], seen)
                    continue
                ps, vs, as_, end = pl.run(n)
            else:
                ms = seen[mi]
                assert ms is not None
                if not self.before[i]:  # the master steps after this slave in a cycle
                    ms = [starts[mi], *ms[:-1]]
                if i not in self.leads and _get(pl, "_state") == _FAST.get(type(pl)):
                    # geared at a fixed ratio, or following inside a cam segment: with the
                    # others of its master at once
                    if GearPlanner in type(pl).__mro__ and _get(pl, "_cl") == 0.0:
                        key = (0, mi, self.before[i], _get(pl, "_dir"), _get(pl, "_m_prev"))
                        geared.setdefault(key, (ms, []))[1].append(i)
                        continue
                    if FollowPlanner in type(pl).__mro__:
                        key = (1, mi, self.before[i], _get(pl, "_dir"), _get(pl, "_m_prev"))
                        geared.setdefault(key, (ms, []))[1].append(i)
                        continue
                ps, vs, as_, end = pl.run(ms)
            if i in self.leads:
                self._lead(i, start, ps, seen)
            if end < 0 and len(ps) == n:
                full.append((r, ps, vs, as_))
            else:
                self._put(bank, r, ps, vs, as_, end)
        for key, (ms, slaves) in geared.items():
            if key[0] == 0:
                self._gear_rows(bank, ms, slaves)
                continue
            for r, ps, vs, as_, end in self._follow_rows(bank, ms, slaves):
                if end < 0 and len(ps) == n:
                    full.append((r, ps, vs, as_))
                else:
                    self._put(bank, r, ps, vs, as_, end)
        if full:  # the rows that go on, in one assignment per table
            rs = np.array([f[0] for f in full], np.intp)
            self._put_rows(bank, rs, tuple([f[k + 1] for f in full] for k in range(3)), n)
        if self.compiled:  # the compiled slaves, all at once (bank_slaves)
            sf = bank._slave_fill
            bank.sampled_samples += sf.fill(bank, self.compiled_rows, n, self.compiled_ptr)

    def _lead(self, i: int, start: float, ps: Any, seen: list[list[float] | None]) -> None:
        """Master ``i``'s positions in a fill (``ps``: its samples, a list or an array; it
        holds the last after its end) for the slaves that read them: :attr:`ext` for the
        compiled ones, ``seen`` for the others."""
        n = SAMPLED_TABLE
        ext = self.ext.get(i)
        if ext is not None:
            m = len(ps)
            ext[0] = start
            ext[1 : m + 1] = ps
            if m < n:
                ext[m + 1 :] = ps[-1]
        if i in self.list_leads:
            seen[i] = self._pad(ps if type(ps) is list else ps.tolist(), n)

    def _gear_rows(self, bank: AxisBank, ms: list[float], slaves: list[int]) -> None:
        """Geared slaves of one master at a fixed ratio (no clutch zone), one table each:
        GearPlanner.step's operations for all of them at once (``pos += ratio·d`` summed in
        order, speed ``ds/T``, acceleration the change of speed over ``T``)."""
        pls = [self.planners[i] for i in slaves]
        cyc, m, d = _master_travel(pls[0], ms)
        r1 = np.array([_get(pl, "_r1") for pl in pls])
        ds = r1[:, None] * d[None, :]
        pos0 = np.array([[_get(pl, "_pos")] for pl in pls])
        pos = np.add.accumulate(np.concatenate((pos0, ds), axis=1), axis=1)[:, 1:]
        v = ds / cyc
        vel0 = np.array([[_get(pl, "_vel")] for pl in pls])
        acc = (v - np.concatenate((vel0, v[:, :-1]), axis=1)) / cyc
        rs = np.array([self.rows[i] for i in slaves], np.intp)
        self._put_rows(bank, rs, (pos, v, acc), len(ms))
        m_last = float(m[-1])
        for pl, p, vv, a in zip(
            pls, pos[:, -1].tolist(), v[:, -1].tolist(), acc[:, -1].tolist(), strict=True
        ):
            _set(pl, "_m_prev", m_last)
            _set(pl, "_pos", p)
            _set(pl, "_vel", vv)
            _set(pl, "_acc", a)

    def _follow_rows(
        self, bank: AxisBank, ms: list[float], slaves: list[int]
    ) -> list[tuple[int, list[float], list[float], list[float], int]]:
        """Following slaves of one master, their cycles inside the current cam segment all at
        once: FollowPlanner.step's operations (travel summed in order, ``s = origin + s0 +
        u·(rs + k·u)``, speed and acceleration as differences over ``T``).  A slave whose
        travel leaves the segment within the table is stepped on from there by its ``run``;
        returns those rows' samples (row, positions, speeds, accelerations, end)."""
        pls = [self.planners[i] for i in slaves]
        cyc, m, d = _master_travel(pls[0], ms)
        # each planner's travel, direction, segment (x0, x1, origin + s0, rs, k), position and
        # speed: one row per planner, read in one pass
        cols = []
        for pl in pls:
            i = _get(pl, "_i")
            g = _get(pl, "_segs")[i]
            cols.append(
                (
                    _get(pl, "_x"),
                    _get(pl, "_sd"),
                    g.x0,
                    g.x1,
                    _get(pl, "_origin") + g.s0,
                    g.rs,
                    g.k,
                    _get(pl, "_pos"),
                    _get(pl, "_vel"),
                    i == 0,
                )
            )
        st = np.array(cols, np.float64)
        x0, sd, sx0, sx1, base, rs, k, pos0, vel0, first_seg = (st[:, c : c + 1] for c in range(10))
        first_seg = first_seg != 0.0
        x = np.add.accumulate(np.concatenate((x0, np.broadcast_to(d, (len(pls), len(d)))), 1), 1)
        x = x[:, 1:]
        # _follow's two loops do nothing in a cycle where x is before x1 and, past the
        # first segment of the pass, not behind x0
        inside = ((x - sx1) * sd < 0.0) & (first_seg | ((x - sx0) * sd >= 0.0))
        n = len(ms)
        stay = np.where(inside.all(axis=1), n, np.argmin(inside, axis=1)).tolist()
        u = x - sx0
        u = np.where(u * sd < 0.0, 0.0, u)  # behind the start of the pass: wait there
        pos = base + u * (rs + k * u)
        v = (pos - np.concatenate((pos0, pos[:, :-1]), 1)) / cyc
        acc = (v - np.concatenate((vel0, v[:, :-1]), 1)) / cyc
        whole = [j for j, c in enumerate(stay) if c == n]
        rest: list[tuple[int, list[float], list[float], list[float], int]] = []
        for j, c in enumerate(stay):
            if c == n:
                continue
            pl = pls[j]
            if c:  # the cycles inside the segment, then the planner's own steps
                _set(pl, "_x", float(x[j, c - 1]))
                _set(pl, "_m_prev", ms[c - 1])
                _set(pl, "_pos", float(pos[j, c - 1]))
                _set(pl, "_vel", float(v[j, c - 1]))
                _set(pl, "_acc", float(acc[j, c - 1]))
            ps, vs, as_, end = pl.run(ms[c:])
            if end >= 0:
                end += c
            head = (pos[j, :c].tolist(), v[j, :c].tolist(), acc[j, :c].tolist())
            rest.append((self.rows[slaves[j]], head[0] + ps, head[1] + vs, head[2] + as_, end))
        if not whole:
            return rest
        sel = np.array(whole, np.intp)
        rs_rows = np.array([self.rows[slaves[j]] for j in whole], np.intp)
        self._put_rows(bank, rs_rows, (pos[sel], v[sel], acc[sel]), n)
        m_last = float(m[-1])
        for j, xe, p, vv, a in zip(
            whole,
            x[sel, -1].tolist(),
            pos[sel, -1].tolist(),
            v[sel, -1].tolist(),
            acc[sel, -1].tolist(),
            strict=True,
        ):
            pl = pls[j]
            _set(pl, "_x", xe)
            _set(pl, "_m_prev", m_last)
            _set(pl, "_pos", p)
            _set(pl, "_vel", vv)
            _set(pl, "_acc", a)
        return rest

    @staticmethod
    def _pad(ps: list[float], n: int) -> list[float]:
        """A planner's positions in ``n`` cycles (it holds the last after its end)."""
        return ps + [ps[-1]] * (n - len(ps))

    def _pt_compiled(self, bank: AxisBank, i: int, pl: PtPlanner) -> None:
        """A static PT row's table by the compiled kernel (bank_kernel.PtRun)."""
        pts = self.pts.get(i)
        if pts is None:  # the FIFO cannot change while the cluster is claimed
            q = _get(pl, "_fifos")[_get(pl, "_r")]
            arr = np.array([(p.pos, p.time, float(int(p.type))) for p in q], np.float64)
            pts = self.pts[i] = (arr.ctypes.data, len(arr), arr)
        r = self.rows[i]
        bank.keep_last_sample(r)
        tables = (bank.t_p, bank.t_v, bank.t_a)
        end = bank.pt_run(pl, pts[:2], SAMPLED_TABLE, tables, int(bank.base[r]))
        m = end + 1 if end >= 0 else SAMPLED_TABLE
        bank.sampled_samples += m
        bank.t_len[r] = m
        bank.t_cur[r] = 0
        bank.t_end[r] = end

    @staticmethod
    def _put(
        bank: AxisBank, r: int, ps: list[float], vs: list[float], as_: list[float], end: int
    ) -> None:
        """A row's new table (AxisBank.keep_last_sample first, as for a Trap table)."""
        m = len(ps)
        if not m:
            return
        bank.sampled_samples += m
        bank.keep_last_sample(r)
        bank.t_p[r, :m], bank.t_v[r, :m], bank.t_a[r, :m] = ps, vs, as_
        bank.t_len[r] = m
        bank.t_cur[r] = 0
        bank.t_end[r] = end

    @staticmethod
    def _put_rows(bank: AxisBank, rs: np.ndarray, tables: tuple[Any, Any, Any], n: int) -> None:
        """Rows whose new tables are full and go on (positions, speeds, accelerations: one
        row of ``n`` samples each), in one assignment per table."""
        bank.keep_last_sample(rs)
        for t, values in zip((bank.t_p, bank.t_v, bank.t_a), tables, strict=True):
            t[rs, :n] = values
        bank.t_len[rs] = n
        bank.t_cur[rs] = 0
        bank.t_end[rs] = -1
        bank.sampled_samples += n * len(rs)

    def rewind(self, bank: AxisBank) -> None:
        """Put the planners where the scalar path has them: their state at the last fill,
        then as many steps as the bank ran since."""
        if self.pt_stream:
            stream_of(bank).rewind(self)
            return
        if self.compiled_pt is not None:
            if self.snaps is None:  # never filled: the planner never left its state
                self.compiled_pt.drop(self.rows[0])
                return
            self.compiled_pt.put_back(self.rows[0], self.planners[0])
            self.snaps = None
            for _ in range(int(bank.taken[self.rows[0]] - bank.fill_taken[self.rows[0]])):
                self.step()
            return
        if self.snaps is None:  # never stepped ahead
            for i in self.compiled:
                bank._slave_fill.drop(self.rows[i])
            return
        n = max(int(bank.taken[r] - bank.fill_taken[r]) for r in self.rows)
        for obj, snap in self.snaps:
            names = _MOVING.get(snap[0]) if type(snap[0]) is object else None
            if snap[0] is _CRD_MOVING:
                _put_back_system(obj, snap)
            elif names is not None:
                for name, value in zip(names, snap[1], strict=True):
                    _set(obj, name, value)
                if snap[0] is _FOLLOW_MOVING:
                    del _get(obj, "_segs")[snap[2] :]  # the segments added since
            else:
                restore(obj, snap)
        for i in self.compiled:
            bank._slave_fill.put_back(self.rows[i], self.planners[i])
        self.snaps = None
        for _ in range(n):
            self.step()


__all__ = [
    "SAMPLED_TABLE",
    "Cluster",
    "SystemTrace",
    "kept_push",
    "links",
    "restore",
    "sampled_kind",
    "snapshot",
]
