"""The axis bank's PVT rows compiled: every PVT axis's table filled in one C call.

:mod:`~gtecat.controller.bank_modes` steps a cluster's planners a table ahead.  A PVT axis
in motion (``GT_PvtStart``) reads nobody and its planner changes nothing but itself; the
table it runs is its own copy of the segments (a table written while it runs takes effect
at the next start), so nothing but a call on its axis - which gives the row back through
the planner's guard - changes what it does.  ``csrc/bank_pvt.c`` transcribes
``PvtPlanner.step`` and ``PvtSegment.at`` (the passes, ``GT_SetPvtLoop``'s count, the end
of the last pass) with the same IEEE operations in the same order, built like the bank's
kernel (``-ffp-contract=off``, no fast-math), so its samples are the planner's, bit for bit.

While such a row is claimed its planner's state lives here (:class:`PvtFill`: ``st``, and
``before``: the state when the row's current table began); a release hands the planner
``before`` (:meth:`PvtFill.put_back`) and the cluster steps it on to the controller's time.
A stop (the planner's stop ramp) or anything else the bank does not model gives the row back
before it changes the planner.  Without a C compiler (or with ``GTECAT_BANK_KERNEL=numpy``)
the planner's own ``step`` fills the tables, as for any planner the bank steps ahead.
"""

from __future__ import annotations

import ctypes
import logging
from operator import attrgetter, is_
from typing import Any

import numpy as np

from .bank_kernel import CFLAGS, build
from .motion.pvt import _MOVE, PvtPlanner

log = logging.getLogger(__name__)

#: the PvtPlanner attributes a run reads and writes, in the C side's PV_* order
STATE = ("_k _T _i loop loops_done _origin _pos _vel _acc _state").split()
_INTS = frozenset({"_k", "_i", "loop", "loops_done", "_state"})
_WHOLE = tuple(name in _INTS for name in STATE)
#: bank_pvt_fill's argument slots (the C side's PF_* order): counts, then addresses
FILL_ARGS = (
    "nr n table rows st before segs m t_p t_v t_a base t_idx t_len t_cur t_end taken fill_taken"
).split()
#: the bank's arrays bound to FILL_ARGS from ``t_p`` on, and their types
_BANK = ("t_p", "t_v", "t_a", "base", "t_idx", "t_len", "t_cur", "t_end", "taken", "fill_taken")

_LIB: Any = None
_LIB_REASON = ""


def library() -> tuple[Any, str]:
    """(the loaded library or None, why not); built and loaded once per process."""
    global _LIB, _LIB_REASON
    if _LIB is not None or _LIB_REASON:
        return _LIB, _LIB_REASON
    try:
        lib = ctypes.CDLL(str(build(CFLAGS, "bank_pvt")))
        lib.bank_pvt_state_size.restype = ctypes.c_int
        lib.bank_pvt_fill_args.restype = ctypes.c_int
        lib.bank_pvt_fill.restype = ctypes.c_int64
        lib.bank_pvt_fill.argtypes = (ctypes.c_void_p,)
        lib.bank_pvt_run.restype = ctypes.c_int64
        lib.bank_pvt_run.argtypes = (
            (ctypes.c_void_p,) * 2 + (ctypes.c_int64,) * 2 + (ctypes.c_void_p,) * 3
        )
        if lib.bank_pvt_state_size() != len(STATE):
            raise RuntimeError("the compiled PVT state is not the one this module packs")
        if lib.bank_pvt_fill_args() != len(FILL_ARGS):
            raise RuntimeError("the compiled PVT fill arguments are not the ones packed here")
        _LIB = lib
    except Exception as e:  # no compiler, a failed build: the planner's own steps
        _LIB_REASON = f"{type(e).__name__}: {e}"
    return _LIB, _LIB_REASON


def compiled_kind(pl: Any) -> bool:
    """``pl`` is a PVT planner in motion (not stopping) :class:`PvtFill` runs; read
    unguarded."""
    get = object.__getattribute__
    return PvtPlanner in type(pl).__mro__ and get(pl, "_state") == _MOVE


class PvtFill:
    """The state of a bank's PVT rows in motion (one cluster each) and the call that fills
    their tables (the interface of :class:`~gtecat.controller.bank_kernel.PtFill`)."""

    def __init__(self, lib: Any, n: int) -> None:
        self.fn = lib.bank_pvt_fill
        self.n = n
        self.st = np.zeros((n, len(STATE)))
        self.before = np.zeros((n, len(STATE)))
        self.segs = np.zeros(n, np.int64)
        self.m = np.zeros(n, np.int64)
        self.rows = np.zeros(n, np.int64)
        self.args = np.zeros(len(FILL_ARGS), np.int64)
        self._args_ptr = self.args.ctypes.data
        #: samples written (statistics: the tests check the compiled fill ran)
        self.samples = 0
        #: row -> its table's segments (the array its address points into)
        self._arrays: dict[int, np.ndarray] = {}
        #: id(segments tuple) -> (the tuple, its array): rows running one table share it
        self._tables: dict[int, tuple[tuple, np.ndarray]] = {}
        self._state = attrgetter(*STATE)
        self._bound: tuple | None = None
        #: run_row's state and tables (planners whose state is their own)
        self.run = lib.bank_pvt_run
        self.one = np.zeros(len(STATE))
        self._one_ptr = self.one.ctypes.data
        self._row_tables: dict[int, tuple[tuple, np.ndarray]] = {}
        a = self.args
        a[3], a[4], a[5] = self.rows.ctypes.data, self.st.ctypes.data, self.before.ctypes.data
        a[6], a[7] = self.segs.ctypes.data, self.m.ctypes.data

    def load(self, r: int, pl: Any) -> None:
        """Row ``r`` runs PVT planner ``pl`` (:func:`compiled_kind`, unguarded) from now on."""
        self.st[r] = self._state(pl)
        arr = segments(self._tables, object.__getattribute__(pl, "_segs"))
        self._arrays[r] = arr
        self.segs[r], self.m[r] = arr.ctypes.data, len(arr)

    def fill(self, bank: Any, rows: list[int], n: int) -> int:
        """New tables of ``n`` samples for ``rows``; the samples written."""
        k = len(rows)
        self.rows[:k] = rows
        a = self.args
        a[0], a[1], a[2] = k, n, bank.table
        arrays = tuple(getattr(bank, name) for name in _BANK)
        if self._bound is None or not all(map(is_, arrays, self._bound)):
            for slot, arr in enumerate(arrays, 8):
                want = np.float64 if slot < 11 else np.int64
                if arr.dtype != want or not arr.flags.c_contiguous:
                    raise TypeError(f"PVT fill: {FILL_ARGS[slot]} is {arr.dtype}")
                a[slot] = arr.ctypes.data
            self._bound = arrays
        got = int(self.fn(self._args_ptr))
        self.samples += got
        return got

    def run_row(self, bank: Any, r: int, pl: Any, n: int) -> None:
        """Row ``r``'s next table from planner ``pl`` (unguarded; its state not held here),
        which moves on as ``n`` steps move it (``bank_pvt_run``)."""
        held = self._row_tables
        if len(held) > 64:  # (tables of planners long gone)
            held.clear()
        arr = segments(held, object.__getattribute__(pl, "_segs"))
        st = self.one
        st[:] = self._state(pl)
        bank.keep_last_sample(r)
        off = 8 * int(bank.base[r])
        p, v, a = (t.ctypes.data + off for t in (bank.t_p, bank.t_v, bank.t_a))
        end = int(self.run(self._one_ptr, arr.ctypes.data, len(arr), n, p, v, a))
        put = object.__setattr__
        for name, value, whole in zip(STATE, st.tolist(), _WHOLE, strict=True):
            put(pl, name, int(value) if whole else value)
        m = end + 1 if end >= 0 else n
        self.samples += m
        bank.sampled_samples += m
        bank.t_len[r] = m
        bank.t_cur[r] = 0
        bank.t_end[r] = end

    def put_back(self, r: int, pl: Any) -> None:
        """The planner of row ``r`` as it stood when the row's current table began; the row
        leaves."""
        put = object.__setattr__
        for name, value, whole in zip(STATE, self.before[r].tolist(), _WHOLE, strict=True):
            put(pl, name, int(value) if whole else value)
        self.drop(r)

    def drop(self, r: int) -> None:
        """Row ``r`` leaves: its table's array goes (the last row of a table takes it along)."""
        arr = self._arrays.pop(r, None)
        if arr is not None and not any(x is arr for x in self._arrays.values()):
            for key, (_, held) in list(self._tables.items()):
                if held is arr:
                    del self._tables[key]


def segments(held: dict[int, tuple[tuple, np.ndarray]], segs: tuple) -> np.ndarray:
    """The planner's segments as the C side reads them (t0, t1, p0, p1, v0, v1 per row),
    made once per table (``held``: id(segments) -> (segments, array))."""
    got = held.get(id(segs))
    if got is None or got[0] is not segs:
        arr = np.array([(g.t0, g.t1, g.p0, g.p1, g.v0, g.v1) for g in segs], np.float64)
        got = held[id(segs)] = (segs, arr)
    return got[1]


def fill_row(bank: Any, r: int, pl: Any, n: int) -> bool:
    """Row ``r``'s next table of ``n`` samples from PVT planner ``pl`` (unguarded) in motion,
    compiled, for a PVT axis in a cluster of several rows (a drive of several channels, a
    Gear master): :meth:`PvtFill.run_row`; False where this is not such a planner or the
    library is not there (the planner's own run fills it)."""
    if not compiled_kind(pl):
        return False
    pf = pvt_fill(bank)
    if pf is None:
        return False
    pf.run_row(bank, r, pl, n)
    return True


def pvt_fill(bank: Any) -> PvtFill | None:
    """The bank's :class:`PvtFill` (made on first use, again when its rows were rebuilt),
    or None where the bank's cycle is not compiled or this library does not build."""
    if bank._kernel_lib is None:
        return None
    pf = bank.__dict__.get("_pvt_fill")
    if pf is False:
        return None
    n = len(bank.t_len)
    if pf is None or pf.n != n:
        lib, reason = library()
        if lib is None:
            log.info("bank PVT: the planners' own steps fill their tables (%s)", reason)
            bank._pvt_fill = False
            return None
        pf = bank._pvt_fill = PvtFill(lib, n)
    return pf


__all__ = ["PvtFill", "compiled_kind", "fill_row", "library", "pvt_fill"]
