"""The axis bank's dynamic PT rows: a stream of points (manual 7.4.2 (4)) run in the bank.

A dynamic PT FIFO is emptied as the motion goes: when the running FIFO is used up the planner
clears it and runs on in the other one, or ends the motion when that one is empty
(:meth:`PtPlanner._next`).  The bank steps its planners a table ahead of the controller's
time (:mod:`~gtecat.controller.bank_modes`), and the application fills the FIFOs meanwhile
(``GT_PtSpace``, ``GT_PtData``): a table crossing the end of the running FIFO would clear it
(or end the stream) before its time, and miss the points pushed in the cycles before.  So a
dynamic PT row's table ends just before the sample that runs the FIFO out (from the end time
of its last point, with the planner's own end test); the table that sample begins is that
one sample, stepped by the planner itself on its FIFOs at the cycle it is taken.  Between
two such samples the steps touch no FIFO: the FIFOs are at every call what the scalar
path's are, a point appended reaches no sample computed already
(:mod:`~gtecat.controller.bank_stream` runs ``GT_PtData`` / ``GT_PtSpace`` on the row), and
the samples inside the running FIFO are the static ones (``bank_pt_fill``, the compiled PT
fill, where the kernel is; the planner's ``run`` else).

At a release the planner is put back where the table began and stepped to the controller's
time; a table that began with the FIFO's end, none of whose samples was taken, puts back the
planner and its FIFOs as they were before it.
"""

from __future__ import annotations

import math
from operator import attrgetter
from typing import TYPE_CHECKING, Any

import numpy as np

from .bank_kernel import PT_STATE
from .motion.pt import _EPS_T, PtMode, PtPlanner

if TYPE_CHECKING:
    from .bank import AxisBank
    from .bank_modes import Cluster

_get, _set = object.__getattribute__, object.__setattr__
_K, _T, _TOFF = PT_STATE.index("_k"), PT_STATE.index("_T"), PT_STATE.index("_toff")
_WHOLE = tuple(name in ("_k", "_i", "_loop", "_loops_done", "_state") for name in PT_STATE)
#: what a release puts back of a table that began with the FIFO's end (none of it taken)
_STREAM = ("_r", "_w", "_stream_t")
_state_of = attrgetter(*PT_STATE)


def stream_kind(pl: Any) -> bool:
    """``pl`` is a PT planner running a dynamic FIFO (read unguarded)."""
    return (
        PtPlanner in type(pl).__mro__
        and _get(pl, "_state") == 1
        and _get(pl, "_mode") == PtMode.DYNAMIC
    )


class PtStream:
    """The dynamic PT rows of one bank: their points for the compiled fill, and per row the
    planner as it stood before a table that began with the FIFO's end (``ev``)."""

    def __init__(self, bank: AxisBank) -> None:
        self.bank = bank
        #: row -> its running FIFO's points (position, time, type), room for the whole FIFO
        self.points: dict[int, np.ndarray] = {}
        #: row -> the planner's state before (kept while the row's table began with an event)
        self.ev: dict[int, tuple] = {}
        #: row -> the planner's PT_STATE when its table began (no compiled fill)
        self.before: dict[int, tuple] = {}
        #: samples stepped by the planner itself at a FIFO's end (statistics)
        self.events = 0
        #: row -> the running FIFO's list of points and how many of them ``points`` holds
        self.items: dict[int, list] = {}
        self.count: dict[int, int] = {}
        #: per row, the end time of the running FIFO's last point (the compiled fill's cut)
        self.t_last = np.zeros(len(bank.res))

    # --- a row claimed --------------------------------------------------------------------
    def load(self, r: int, pl: PtPlanner) -> None:
        """Row ``r`` runs dynamic PT planner ``pl`` (unguarded) from now on."""
        self.ev.pop(r, None)
        self.before.pop(r, None)
        pf = self.bank.pt_fill
        if pf is None:
            return
        pf.st[r] = [float(v) for v in pf._state(pl)]
        self._points(r, pl, reset=True)

    def _points(self, r: int, pl: PtPlanner, reset: bool = False) -> None:
        """The compiled fill's copy of the running FIFO's points follows the FIFO (points
        are only appended while it runs; ``reset``: another FIFO runs)."""
        pf = self.bank.pt_fill
        assert pf is not None
        q = _get(pl, "_fifos")[_get(pl, "_r")]
        items = q._items
        buf = self.points.get(r)
        if buf is None or len(buf) < q.capacity:
            buf = self.points[r] = np.zeros((q.capacity, 3))
            pf._points[r] = buf
            pf.pts[r] = buf.ctypes.data
            reset = True
        m = 0 if reset else int(pf.m[r])
        n = len(items)
        if n > m:
            buf[m:n] = [(p.pos, p.time, float(int(p.type))) for p in items[m:n]]
        pf.m[r] = n
        self.items[r], self.count[r] = items, n
        if r >= len(self.t_last):  # (a bank of more rows since)
            self.t_last = np.concatenate((self.t_last, np.zeros(r + 1 - len(self.t_last))))
        if n:
            self.t_last[r] = items[-1].time

    # --- tables -----------------------------------------------------------------------------
    def fill(self, rows: list[int], n: int) -> int:
        """New tables (at most ``n`` samples) for dynamic PT rows ``rows``; the samples."""
        from .bank import _Bypass

        bank = self.bank
        total = 0
        _Bypass.on = True
        try:
            if bank.pt_fill is not None:
                return self._fill_compiled(rows, n)
            for r in rows:
                pl = bank.res[r].profile.planner
                bank.fill_taken[r] = bank.taken[r]
                k, cyc, toff = _get(pl, "_k"), _get(pl, "_T"), _get(pl, "_toff")
                q = _get(pl, "_fifos")[_get(pl, "_r")]
                c = _before_end(k, cyc, q._items[-1].time + toff)
                if c == 0:
                    total += self._event(r, pl)
                    continue
                self.ev.pop(r, None)
                self.before[r] = tuple(_get(pl, name) for name in PT_STATE)
                ps, vs, as_, end = pl.run(min(c, n))
                total += _put(bank, r, ps, vs, as_, end)
        finally:
            _Bypass.on = False
        return total

    def _fill_compiled(self, rows: list[int], n: int) -> int:
        """:meth:`fill` by the compiled PT fill: every row's cut at once (``_before_end``'s
        operations on arrays), the rows of one cut in one call."""
        bank = self.bank
        pf = bank.pt_fill
        assert pf is not None
        res, items, count = bank.res, self.items, self.count
        for r in rows:  # (the running FIFO grew: its new points for the compiled fill)
            q = items.get(r)
            if q is None or len(q) != count[r]:
                self._points(r, res[r].profile.planner)
        ra = np.array(rows, np.intp)
        bank.fill_taken[ra] = bank.taken[ra]
        st = pf.st[ra]
        c = _before_end_rows(st[:, _K], st[:, _T], self.t_last[ra] + st[:, _TOFF])
        total = 0
        at_end = c == 0
        if np.count_nonzero(at_end):
            for r in ra[at_end].tolist():
                total += self._event(r, res[r].profile.planner)
            ra, c = ra[~at_end], c[~at_end]
        if self.ev:
            for r in ra.tolist():
                self.ev.pop(r, None)
        c = np.minimum(c, n)
        if len(c) and (c == c[0]).all():
            return total + pf.fill(bank, ra.tolist(), int(c[0]))
        for v in np.unique(c).tolist():
            total += pf.fill(bank, ra[c == v].tolist(), v)
        return total

    def _event(self, r: int, pl: PtPlanner) -> int:
        """Row ``r``'s next sample runs its FIFO out: a table of that one sample, stepped by
        the planner on its FIFOs (the state before kept for a release before it is taken)."""
        from .bank import _GUARD_SET

        cls = type(pl)
        if cls in _GUARD_SET:  # (its steps read it as it is: out of its guard class meanwhile)
            _set(pl, "__class__", cls.__base__)
        try:
            return self._step_event(r, pl)
        finally:
            _set(pl, "__class__", cls)

    def _step_event(self, r: int, pl: PtPlanner) -> int:
        bank = self.bank
        pf = bank.pt_fill
        if pf is not None:  # the compiled state into the planner
            _put_state(pl, pf.st[r].tolist())
        fifos = pl._fifos
        self.ev[r] = (
            _state_of(pl),
            (pl._r, pl._w, pl._stream_t),
            (list(fifos[0]._items), list(fifos[1]._items)),
        )
        p, v, a = pl.step()
        self.events += 1
        after = _state_of(pl)
        if pf is not None:
            pf.st[r] = after
            pf.before[r] = after
            if _get(pl, "_state") == 1:
                self._points(r, pl, reset=True)
        else:
            self.before[r] = after
        return _put(bank, r, [p], [v], [a], 0 if _get(pl, "_state") == 0 else -1)

    # --- calls and releases ---------------------------------------------------------------------
    def current(self, r: int) -> bool:
        """Row ``r``'s FIFOs are the scalar path's now: its table did not begin with the
        FIFO's end, or that sample was taken."""
        return r not in self.ev or int(self.bank.taken[r]) != int(self.bank.fill_taken[r])

    def rewind(self, cl: Cluster) -> None:
        """Put the row's planner where the scalar path has it (a release)."""
        bank = self.bank
        r = cl.rows[0]
        pl = cl.planners[0]
        pf = bank.pt_fill
        ev = self.ev.pop(r, None)
        before = self.before.pop(r, None)
        buf = self.points.pop(r, None)
        self.items.pop(r, None)
        self.count.pop(r, None)
        if pf is not None:
            pf._points.pop(r, None)
        if cl.snaps is None:  # never filled: the planner never left its state
            return
        cl.snaps = None
        m = int(bank.taken[r] - bank.fill_taken[r])
        if ev is not None and m == 0:  # the FIFO's end not reached yet
            _put_state(pl, ev[0])
            for name, value in zip(_STREAM, ev[1], strict=True):
                _set(pl, name, value)
            fifos = _get(pl, "_fifos")
            for q, items in zip((fifos[0], fifos[1]), ev[2], strict=True):
                q._items[:] = items
            return
        if pf is not None:
            _put_state(pl, pf.before[r].tolist())
        elif before is not None:
            _put_state(pl, before)
        if ev is not None:
            m -= 1  # (the state after the FIFO's end)
        del buf
        for _ in range(m):
            pl.step()


def _put_state(pl: PtPlanner, values: Any) -> None:
    for name, value, whole in zip(PT_STATE, values, _WHOLE, strict=True):
        _set(pl, name, int(value) if whole else value)


def _before_end(k: int, cyc: float, t1: float) -> int:
    """The samples after sample ``k`` (at ``k·cyc`` ms) before the first one at or past the
    end of a segment ending at ``t1`` (PtPlanner.step's end test)."""
    lim = t1 - _EPS_T * (1.0 + abs(t1) * 1e-3)
    s = max(k + 1, math.ceil(lim / cyc)) if math.isfinite(lim) else k + 1
    while s > k + 1 and (s - 1) * cyc >= lim:
        s -= 1
    while s * cyc < lim:
        s += 1
    return s - (k + 1)


def _before_end_rows(k: np.ndarray, cyc: np.ndarray, t1: np.ndarray) -> np.ndarray:
    """:func:`_before_end` of many rows (float64 arrays; the same IEEE operations)."""
    lim = t1 - _EPS_T * (1.0 + np.abs(t1) * 1e-3)
    first = k + 1.0
    s = np.maximum(first, np.ceil(lim / cyc))
    while True:
        down = (s > first) & ((s - 1.0) * cyc >= lim)
        if not np.count_nonzero(down):
            break
        s -= down
    while True:
        up = s * cyc < lim
        if not np.count_nonzero(up):
            break
        s += up
    return (s - first).astype(np.int64)


def _put(bank: AxisBank, r: int, ps: Any, vs: Any, as_: Any, end: int) -> int:
    from .bank_modes import Cluster

    Cluster._put(bank, r, ps, vs, as_, end)
    return 0  # (Cluster._put counts its samples itself)


def stream_of(bank: AxisBank) -> PtStream:
    """The bank's :class:`PtStream`, made at its first dynamic PT row."""
    s = bank.__dict__.get("pt_stream")
    if s is None:
        s = bank.pt_stream = PtStream(bank)
    return s  # type: ignore[no-any-return]


def fifos_current(bank: AxisBank, r: int, pl: Any, name: str, values: tuple) -> bool:
    """A GT_PtSpace / GT_PtData (``name``, ``values``) may run on claimed PT row ``r``'s
    FIFOs as they stand: they are the scalar path's (nothing steps them ahead: a row at
    rest; a static FIFO, which no step changes, and a point going to the FIFO the motion
    does not read; a dynamic stream whose table does not begin with a FIFO's end not taken
    yet)."""
    if not bank.sampled[r]:
        return _get(pl, "_state") == 0
    cl = bank._cluster_of.get(bank.group_of[r])
    if cl is None:
        return False
    if getattr(cl, "pt_stream", False):
        s = bank.__dict__.get("pt_stream")
        return s is None or s.current(r)
    if len(cl.rows) != 1 or _get(pl, "_mode") != PtMode.STATIC:
        return False
    if name == "GT_PtSpace":
        return True
    fifo = values[4] if len(values) > 4 else 0
    if type(fifo) is not int or fifo not in (0, 1):
        return False
    return _get(pl, "_r") != fifo  # (a static motion reads the FIFO it started alone)


__all__ = ["PtStream", "fifos_current", "stream_kind", "stream_of"]
