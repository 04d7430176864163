"""The axis bank's Gear and Follow slaves compiled: a cluster's slaves filled in one C call.

:mod:`~gtecat.controller.bank_modes` steps a cluster's planners a table ahead.  A Gear or
Follow slave of a master that reads nobody itself (a Trap or PT axis) is the common case of
those modes - many slaves on one master, a gearbox or a cam line - and Python's steps of
every slave cost more than everything else of the cycle.  ``csrc/bank_slaves.c`` transcribes
``GearPlanner.step`` and ``FollowPlanner.step`` (the clutch; the cam's segments, passes and
end) with the same IEEE operations in the same order, built like the bank's kernel
(``-ffp-contract=off``, no fast-math), so its samples are the planners', bit for bit.

While such a slave's cluster is claimed its planner's state lives here (:class:`SlaveFill`:
``st``, and ``before``: the state when the row's current table began); a release hands the
planner ``before`` (:meth:`SlaveFill.put_back`) and the cluster steps it on to the
controller's time as it steps the others.  Without a C compiler (or with
``GTECAT_BANK_KERNEL=numpy``) the planners' own ``run`` fills the tables, as before.
"""

from __future__ import annotations

import ctypes
import logging
from operator import is_
from typing import Any

import numpy as np

from .bank_kernel import Unit
from .motion.follow import FollowPlanner
from .motion.gear import GearPlanner

log = logging.getLogger(__name__)

#: a row's state, in the C side's SL_* order: what both modes share, then Gear's slots, then
#: Follow's (``_nseg`` is ``len(_segs)``, ``_m`` the points in the running FIFO)
STATE = (
    "_kind _state _T _dir _m_prev _pos _vel _acc "
    "_cl _gx _r0 _r1 "
    "_x _i _nseg _loops_done _x0 _s0 _carry _sd _origin _loop _m"
).split()
_AT = {name: k for k, name in enumerate(STATE)}
#: the slots written back as they are (the others: ``_kind``, ``_nseg``, ``_m``, the Gear's
#: ``_x`` kept in ``_gx``, integers)
GEAR_SLOTS = ("_state", "_m_prev", "_pos", "_vel", "_acc", "_cl", "_r0", "_r1")
FOLLOW_SLOTS = (
    "_state _m_prev _pos _vel _acc _x _i _loops_done _x0 _s0 _carry _sd _origin _loop".split()
)
_INTS = frozenset({"_state", "_i", "_loops_done", "_loop"})
GEAR, FOLLOW = 1.0, 2.0
#: bank_slaves_fill's argument slots (the C side's SF_* order)
FILL_ARGS = "nr n table rows st before pts segs mp moving t_p t_v t_a base t_idx t_len t_cur t_end"
FILL_ARGS = FILL_ARGS.split()  # type: ignore[assignment]
_SEG_FIELDS = ("x0", "x1", "s0", "s1", "rs", "re", "k")


def _bind(lib: Any) -> None:
    lib.bank_slaves_state_size.restype = ctypes.c_int
    lib.bank_slaves_fill_args.restype = ctypes.c_int
    lib.bank_slaves_fill.restype = ctypes.c_int64
    lib.bank_slaves_fill.argtypes = (ctypes.c_void_p,)
    if lib.bank_slaves_state_size() != len(STATE):
        raise RuntimeError("the compiled slaves' state is not the one this module packs")
    if lib.bank_slaves_fill_args() != len(FILL_ARGS):
        raise RuntimeError("the compiled slaves' fill arguments are not the ones packed here")


#: () -> (the loaded library or None, why not); built and loaded once per process (without
#: it, the planners' own run)
library = Unit("bank_slaves", _bind, ())


def compiled_kind(pl: Any) -> bool:
    """``pl`` is a slave :class:`SlaveFill` runs: a Gear in motion, or a Follow in motion
    without a FIFO switch pending (its pass event met: not waiting for it); read unguarded."""
    get = object.__getattribute__
    t = type(pl).__mro__
    if GearPlanner in t:
        return get(pl, "_state") == 1
    if FollowPlanner in t:
        return get(pl, "_state") == 2 and not get(pl, "_switch")
    return False


class SlaveFill:
    """The state of the compiled slaves of a bank's clusters (one row each) and the call
    that fills their tables."""

    def __init__(self, lib: Any, n: int) -> None:
        self.fn = lib.bank_slaves_fill
        self.n = n
        self.st = np.zeros((n, len(STATE)))
        self.before = np.zeros((n, len(STATE)))
        self.pts = np.zeros(n, np.int64)
        self.segs = np.zeros(n, np.int64)
        #: per row, the address of the master positions it reads in the cycles of a fill
        self.mp = np.zeros(n, np.int64)
        self.args = np.zeros(len(FILL_ARGS), np.int64)
        self._args_ptr = self.args.ctypes.data
        #: samples written (statistics: the tests check the compiled fill ran)
        self.samples = 0
        #: row -> its Follow FIFO's points and segments (the arrays the addresses point into)
        self._arrays: dict[int, tuple[np.ndarray, np.ndarray]] = {}
        #: the bank's arrays whose addresses ``args`` holds
        self._bound: tuple | None = None
        a = self.args
        a[4], a[5] = self.st.ctypes.data, self.before.ctypes.data
        a[6], a[7], a[8] = self.pts.ctypes.data, self.segs.ctypes.data, self.mp.ctypes.data

    def load(self, r: int, pl: Any) -> None:
        """Row ``r`` runs slave ``pl`` (:func:`compiled_kind`, unguarded) from now on."""
        get = object.__getattribute__
        row = [0.0] * len(STATE)
        at = _AT
        row[at["_T"]] = get(pl, "_T")
        row[at["_dir"]] = float(get(pl, "_dir"))
        if GearPlanner in type(pl).__mro__:
            row[at["_kind"]] = GEAR
            for name in GEAR_SLOTS:
                row[at[name]] = float(get(pl, name))
            row[at["_gx"]] = get(pl, "_x")
        else:
            row[at["_kind"]] = FOLLOW
            for name in FOLLOW_SLOTS:
                row[at[name]] = float(get(pl, name))
            q = get(pl, "_fifos")[get(pl, "_r")]
            pts = np.array([(float(p.master), p.slave, float(int(p.type))) for p in q])
            segs = np.zeros((len(pts), len(_SEG_FIELDS)))
            had = get(pl, "_segs")
            for k, g in enumerate(had):
                segs[k] = (g.x0, g.x1, g.s0, g.s1, g.rs, g.re, g.k)
            row[at["_nseg"]] = float(len(had))
            row[at["_m"]] = float(len(pts))
            self._arrays[r] = (pts, segs)
            self.pts[r], self.segs[r] = pts.ctypes.data, segs.ctypes.data
        self.st[r] = row

    def fill(self, bank: Any, rows: np.ndarray, n: int, rows_ptr: int = 0) -> int:
        """New tables of ``n`` samples for the moving ``rows`` (int64; ``rows_ptr``: their
        address, when the caller holds it), each reading the master positions at its
        :attr:`mp`; every row's state kept in :attr:`before` first.  Returns the samples
        written."""
        arrays = (
            bank.moving,
            bank.t_p,
            bank.t_v,
            bank.t_a,
            bank.base,
            bank.t_idx,
            bank.t_len,
            bank.t_cur,
            bank.t_end,
        )
        a = self.args
        if self._bound is None or not all(map(is_, arrays, self._bound)):
            for slot, arr in enumerate(arrays, 9):
                want = np.bool_ if slot == 9 else np.float64 if slot < 13 else np.int64
                if arr.dtype != want or not arr.flags.c_contiguous:
                    raise TypeError(f"slave fill: {FILL_ARGS[slot]} is {arr.dtype}")
                a[slot] = arr.ctypes.data
            self._bound = arrays
        a[0], a[1], a[2], a[3] = len(rows), n, bank.table, rows_ptr or rows.ctypes.data
        got = int(self.fn(self._args_ptr))
        self.samples += got
        return got

    def put_back(self, r: int, pl: Any) -> None:
        """The planner of row ``r`` as it stood when the row's current table began (its
        Follow segments computed again as they were: each is a function of the pass and the
        one before); the row leaves."""
        put = object.__setattr__
        before = self.before[r].tolist()
        at = _AT
        if before[at["_kind"]] == GEAR:
            for name in GEAR_SLOTS:
                v = before[at[name]]
                put(pl, name, int(v) if name in _INTS else v)
            put(pl, "_x", before[at["_gx"]])
        else:
            for name in FOLLOW_SLOTS:
                v = before[at[name]]
                put(pl, name, int(v) if name in _INTS else v)
            segs: list[Any] = []
            put(pl, "_segs", segs)
            for k in range(int(before[at["_nseg"]])):
                segs.append(pl._segment(k))
        self.drop(r)

    def drop(self, r: int) -> None:
        """Row ``r`` leaves: the compiled fill skips it from now on (no planner kind), its
        arrays go."""
        self.st[r, 0] = 0.0
        self.pts[r] = self.segs[r] = 0
        self._arrays.pop(r, None)


def slave_fill(bank: Any) -> SlaveFill | None:
    """The bank's :class:`SlaveFill` (made on first use, again when its rows were rebuilt),
    or None where the bank's cycle is not compiled or this library does not build."""
    if bank._kernel_lib is None:
        return None
    sf = bank.__dict__.get("_slave_fill")
    if sf is False:
        return None
    n = len(bank.t_len)
    if sf is None or sf.n != n:
        lib, reason = library()
        if lib is None:
            log.info("bank slaves: the planners' own run fills their tables (%s)", reason)
            bank._slave_fill = False
            return None
        sf = bank._slave_fill = SlaveFill(lib, n)
    return sf
