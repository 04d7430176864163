"""The axis bank's PVT rows compiled: every PVT axis's table filled in one C call.

:mod:`~gtecat.controller.bank_modes` steps a cluster's planners a table ahead.  A PVT axis
in motion (``GT_PvtStart``) reads nobody and its planner changes nothing but itself; the
table it runs is its own copy of the segments (a table written while it runs takes effect
at the next start), so nothing but a call on its axis - which gives the row back through
the planner's guard - changes what it does.  ``csrc/bank_pvt.c`` transcribes
``PvtPlanner.step`` and ``PvtSegment.at`` (the passes, ``GT_SetPvtLoop``'s count, the end
of the last pass) with the same IEEE operations in the same order, built like the bank's
kernel (``-ffp-contract=off``, no fast-math), so its samples are the planner's, bit for bit.

The rows of PVT axes alone are filled together by the kernel's ``bank_pt_fill`` with this
run in place of PT's (:class:`PvtFill`, a :class:`~gtecat.controller.bank_kernel.PtFill`):
while such a row is claimed its planner's state lives there (``st``, and ``before``: the
state when the row's current table began); a release hands the planner ``before``
(:meth:`PvtFill.put_back`) and the cluster steps it on to the controller's time.
``GT_PvtStatus`` and ``GT_GetPvtLoop`` read such an axis without giving it back (:func:`now`).
A stop (the planner's stop ramp) or anything else the bank does not model gives the row back
before it changes the planner.  Without a C compiler (or with ``GTECAT_BANK_KERNEL=numpy``)
the planner's own ``step`` fills the tables, as for any planner the bank steps ahead.
"""

from __future__ import annotations

import ctypes
import logging
from typing import Any

import numpy as np

from .bank_kernel import PtFill, Unit
from .motion.pvt import _MOVE, PvtPlanner

log = logging.getLogger(__name__)

#: the PvtPlanner attributes a run reads and writes, in the C side's PV_* order
STATE = ("_k _T _i loop loops_done _origin _pos _vel _acc _state").split()
_INTS = frozenset({"_k", "_i", "loop", "loops_done", "_state"})


def _bind(lib: Any) -> None:
    lib.bank_pvt_state_size.restype = ctypes.c_int
    lib.bank_pvt_run.restype = ctypes.c_int64
    lib.bank_pvt_run.argtypes = (
        (ctypes.c_void_p,) * 2 + (ctypes.c_int64,) * 2 + (ctypes.c_void_p,) * 3
    )
    if lib.bank_pvt_state_size() != len(STATE):
        raise RuntimeError("the compiled PVT state is not the one this module packs")


#: () -> (the loaded library or None, why not); built and loaded once per process (without
#: it, the planners' own steps)
library = Unit("bank_pvt", _bind)


def compiled_kind(pl: Any) -> bool:
    """``pl`` is a PVT planner in motion (not stopping) :class:`PvtFill` runs; read
    unguarded."""
    get = object.__getattribute__
    return PvtPlanner in type(pl).__mro__ and get(pl, "_state") == _MOVE


def segments(held: dict[int, tuple[tuple, np.ndarray, int]], segs: tuple) -> tuple[Any, int]:
    """(the planner's segments as the C side reads them: t0, t1, p0, p1, v0, v1 per row; its
    address), made once per table (``held``: id(segments) -> (segments, array, address))."""
    got = held.get(id(segs))
    if got is None or got[0] is not segs:
        arr = np.array([(g.t0, g.t1, g.p0, g.p1, g.v0, g.v1) for g in segs], np.float64)
        got = held[id(segs)] = (segs, arr, arr.ctypes.data)
    return got[1], got[2]


class PvtFill(PtFill):
    """The state of a bank's PVT rows in motion (one cluster each) and the kernel's call that
    fills their tables (``bank_pt_fill`` running ``bank_pvt_run``)."""

    def __init__(self, kernel: Any, lib: Any, n: int) -> None:
        run = ctypes.cast(lib.bank_pvt_run, ctypes.c_void_p).value or 0
        super().__init__(kernel, n, STATE, _INTS, run)
        self.n = n
        self.run = lib.bank_pvt_run
        #: samples written (statistics: the tests check the compiled fill ran)
        self.samples = 0
        #: id(segments tuple) -> (the tuple, its array): rows running one table share it
        self._tables: dict[int, tuple[tuple, np.ndarray, int]] = {}
        #: run_row's state and tables (planners whose state is their own)
        self.one = np.zeros(len(STATE))
        self._one_ptr = self.one.ctypes.data
        self._row_tables: dict[int, tuple[tuple, np.ndarray, int]] = {}
        #: stepped's samples (not kept)
        self._scratch = np.empty((3, 0))
        self._scratch_ptrs = (0, 0, 0)

    def load(self, r: int, pl: Any) -> None:
        """Row ``r`` runs PVT planner ``pl`` (:func:`compiled_kind`, unguarded) from now on."""
        self.st[r] = self._state(pl)
        arr, ptr = segments(self._tables, object.__getattribute__(pl, "_segs"))
        self._points[r] = arr
        self.pts[r], self.m[r] = ptr, len(arr)

    def fill(self, bank: Any, rows: list[int], n: int) -> int:
        got = super().fill(bank, rows, n)
        self.samples += got
        return got

    def run_row(self, bank: Any, r: int, pl: Any, n: int) -> None:
        """Row ``r``'s next table from planner ``pl`` (unguarded; its state not held here),
        which moves on as ``n`` steps move it (``bank_pvt_run``)."""
        held = self._row_tables
        if len(held) > 64:  # (tables of planners long gone)
            held.clear()
        arr, ptr = segments(held, object.__getattribute__(pl, "_segs"))
        st = self.one
        st[:] = self._state(pl)
        bank.keep_last_sample(r)
        off = 8 * int(bank.base[r])
        p, v, a = (t.ctypes.data + off for t in (bank.t_p, bank.t_v, bank.t_a))
        end = int(self.run(self._one_ptr, ptr, len(arr), n, p, v, a))
        put = object.__setattr__
        for name, value, whole in zip(STATE, st.tolist(), self._whole, strict=True):
            put(pl, name, int(value) if whole else value)
        m = end + 1 if end >= 0 else n
        self.samples += m
        bank.sampled_samples += m
        bank.t_len[r] = m
        bank.t_cur[r] = 0
        bank.t_end[r] = end

    def stepped(self, vals: list[Any], segs: tuple, m: int) -> list[float]:
        """A planner's state ``vals`` (STATE order) after ``m`` steps over ``segs``."""
        held = self._row_tables
        if len(held) > 64:
            held.clear()
        arr, ptr = segments(held, segs)
        if self._scratch.shape[1] < m:
            self._scratch = np.empty((3, m))
            self._scratch_ptrs = tuple(self._scratch[j].ctypes.data for j in range(3))
        st = self.one
        st[:] = vals
        self.run(self._one_ptr, ptr, len(arr), m, *self._scratch_ptrs)
        return st.tolist()  # type: ignore[no-any-return]

    def drop(self, r: int) -> None:
        """Row ``r`` leaves: its table's array goes (the last row of a table takes it along)."""
        arr = self._points.pop(r, None)
        if arr is not None and not any(x is arr for x in self._points.values()):
            for key, (_, held, _) in list(self._tables.items()):
                if held is arr:
                    del self._tables[key]


def now(res: Any, pl: Any) -> tuple[int, float, int, int] | None:
    """(table selected, table time of the pass, passes done, loop setting) of PVT planner
    ``pl`` of axis ``res`` as the scalar path has them now, where the bank runs the axis
    (``GT_PvtStatus``, ``GT_GetPvtLoop`` read it so, without giving it back); None where
    it does not (the planner holds them).  The planner's state when the row's current
    table began (:class:`PvtFill`'s, or the one its cluster kept for a rewind), stepped as
    many cycles as the bank ran since, on a copy."""
    bank = res.bank
    if bank is None:
        return None
    get = object.__getattribute__
    r = res.bank_row
    cl = bank.__dict__.get("_cluster_of", {}).get(bank.group_of[r])
    vals: list[Any] | None = None
    if cl is not None and cl.snaps is not None:  # stepped ahead since the claim
        if isinstance(cl.compiled_pt, PvtFill):
            vals = cl.compiled_pt.before[r].tolist()
        else:
            for obj, snap in cl.snaps:
                if obj is pl:  # (bank_modes.snapshot: the planner's __dict__ by name)
                    vals = [snap[2][name][0] for name in STATE]
                    break
    if vals is None:  # not stepped ahead: the planner stands where the scalar path has it
        vals = [get(pl, name) for name in STATE]
        m = 0
    else:
        m = bank.taken.item(r) - bank.fill_taken.item(r)
    segs = get(pl, "_segs")
    if m and int(vals[-1]) == _MOVE:
        pf = pvt_fill(bank)
        if pf is not None:
            vals = pf.stepped(vals, segs, m)
        else:
            copy = PvtPlanner.__new__(PvtPlanner)
            copy.__dict__.update(get(pl, "__dict__"))
            for name, value in zip(STATE, vals, strict=True):
                setattr(copy, name, value)
            for _ in range(m):
                copy.step()
            vals = [getattr(copy, name) for name in STATE]
    k, cyc, state = int(vals[0]), vals[1], int(vals[-1])
    t = segs[0].t0 + k * cyc if state == _MOVE and segs else 0.0
    return get(pl, "table_id"), t, int(vals[4]), int(vals[3])


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
    kernel = bank._kernel_lib
    if kernel is None:
        return None
    pf = bank.__dict__.get("_pvt_fill")
    if pf is False:
        return None
    n = len(bank.t_len)
    if pf is None or pf.n != n or pf.fn is not kernel.bank_pt_fill:
        lib, reason = library()
        if lib is None:
            log.info("bank PVT: the planners' own steps fill their tables (%s)", reason)
            bank._pvt_fill = False
            return None
        pf = bank._pvt_fill = PvtFill(kernel, lib, n)
    return pf


__all__ = ["PvtFill", "compiled_kind", "fill_row", "library", "now", "pvt_fill"]
