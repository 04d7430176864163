"""Lead-screw compensation of the axes the bank runs (:mod:`gtecat.controller.lead_screw`).

An axis with a compensation table (``GT_SetLeadScrewComp``) has one more per-cycle hook:
after its profile's step it notes the direction the planned position moved in and, while
the compensation is on, adds the table's value for that position and direction to the
command 607Ah follows.  The bank runs such an axis as any other row and does the hook's
work per row, with the same floating-point operations in the same order
(:meth:`~gtecat.controller.lead_screw.LeadScrew.value`): in numpy here (the bank's numpy
cycle) and in the compiled cycle (``csrc/bank_kernel.c``, ``ls_*``), so positions,
encoder values and status stay bit-equal with the scalar path.

The hook's last position is the row's last planned position (``a_last``): a row in CSP is
taken only where the two are equal (the hook ran after the planned position last changed).
A drive homing (mode 6) has its plan follow the drive after the hook, so the hook sees the
planned position of the cycle before: such a row keeps the hook's last position itself
(``ls_last``, not a number for none), and the compiled cycle, which alone runs homing rows,
follows it.  Per row: ``ls`` 0 (no table), 1 (a table, the compensation off: only the
direction is followed) or 2 (on); ``ls_dir`` the direction; ``ls_prm`` the table's start
and point spacing; ``ls_ix`` where its positive table begins in ``ls_tab`` and its point
count (the negative table follows it).  A table changes only through a GT call on its axis,
which gives the row back first.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .lead_screw import LeadScrew, lead_screw


def screw_arrays(bank: Any, n: int) -> None:
    """The per-row arrays of a bank of ``n`` rows (read by the compiled cycle by name)."""
    bank.ls = np.zeros(n, np.uint8)
    bank.ls_dir = np.ones(n, np.int64)
    bank.ls_prm = np.zeros(2 * n)
    bank.ls_ix = np.zeros(2 * n, np.int64)
    bank.ls_tab = np.zeros(1)
    bank.ls_last = np.zeros(n)
    #: the screw whose tables ls_tab holds for each row (None: none)
    bank._ls_obj = [None] * n


def screw_claimable(ax: Any, res: Any, homing: bool = False) -> bool:
    """The axis's hooks are its resources' and its lead screw's, in that order (the screw
    set after the resources: it reads the planned position of this cycle), and (but in a
    drive homing: ``homing``) the screw has seen the planned position as it stands."""
    hooks = ax.pre_hooks
    if len(hooks) != 2 or hooks[0] != res._pre:
        return False
    s = lead_screw(ax)
    if s is None or hooks[1] != s.hook or (not homing and s.last != ax.prf_pos):
        return False
    return 2 <= len(s.positive) == len(s.negative)


def screw_load(bank: Any, r: int, ax: Any) -> None:
    """Row ``r`` takes its axis's lead screw (or none) as it stands."""
    s = lead_screw(ax)
    if s is None or not ax.pre_hooks or ax.pre_hooks[-1] != s.hook:
        bank.ls[r] = 0
        return
    if bank._ls_obj[r] is not s:
        bank._ls_obj[r] = s
        _tables(bank)
    bank.ls[r] = 2 if s.enabled else 1
    bank.ls_dir[r] = s.direction
    bank.ls_last[r] = math.nan if s.last is None else s.last


def _tables(bank: Any) -> None:
    """Every row's tables in one flat array again (a screw new to a row)."""
    parts: list[tuple[float, ...]] = []
    at = 0
    for r, s in enumerate(bank._ls_obj):
        if s is None:
            continue
        n = len(s.positive)
        bank.ls_ix[2 * r], bank.ls_ix[2 * r + 1] = at, n
        bank.ls_prm[2 * r] = s.start
        bank.ls_prm[2 * r + 1] = s.length / (n - 1)  # (LeadScrew.value's step)
        parts += [s.positive, s.negative]
        at += 2 * n
    bank.ls_tab = np.array([v for p in parts for v in p] or [0.0], np.float64)
    if bank.kernel is not None:
        bank.kernel.bound = False  # (a new array: bound again before the next cycle)


def screw_put_back(bank: Any, r: int, ax: Any) -> None:
    """Row ``r``'s screw state into its :class:`LeadScrew` as the hook leaves it (its last
    position the row's last planned position), as the row leaves the bank."""
    kind = int(bank.ls[r])
    if not kind:
        return
    bank.ls[r] = 0
    s: LeadScrew | None = bank._ls_obj[r]
    if s is None:
        return
    if bank.hm[r]:  # (ls_last: module docstring)
        last = float(bank.ls_last[r])
        s.last = None if math.isnan(last) else last
    else:
        s.last = float(bank.a_last[r])
    s.direction = int(bank.ls_dir[r])
    if bank.bank_cycles != bank.claim_cycle[r] and s.last is not None:
        # the hook's value of the last cycle
        ax.compensation = s.value(s.last, s.direction) if kind == 2 else 0.0


def screw_command(bank: Any, a: np.ndarray) -> tuple[np.ndarray, np.ndarray | None]:
    """The numpy cycle's part: (the position 607Ah follows, in pulses, for every row; the
    rows' directions after this cycle, None without a screw row).  LeadScrew.hook and
    LeadScrew.value per row, vectorised."""
    ls = bank.ls
    if not np.count_nonzero(ls):
        return a, None
    last, old = bank.a_last, bank.ls_dir
    with np.errstate(invalid="ignore"):
        moved = (ls != 0) & (a != last)
        d = np.where(moved, np.where(a > last, 1, -1), old)
    rows = np.flatnonzero(ls == 2)
    if not len(rows):
        return a, d
    ar = a[rows]
    comp = screw_values(bank, rows, ar, d[rows])
    cmd = a.copy()
    cmd[rows] = ar + comp
    return cmd, d


def screw_values(bank: Any, rows: np.ndarray, pos: np.ndarray, d: np.ndarray) -> np.ndarray:
    """LeadScrew.value of ``rows`` at ``pos`` in directions ``d`` (not a number where the
    position is none: such a row leaves before its cycle)."""
    off, n = bank.ls_ix[2 * rows], bank.ls_ix[2 * rows + 1]
    o = off + np.where(d >= 0, 0, n)
    tab = bank.ls_tab
    with np.errstate(invalid="ignore"):
        x = (pos - bank.ls_prm[2 * rows]) / bank.ls_prm[2 * rows + 1]
        lo = x <= 0
        hi = x >= n - 1
        inner = ~(lo | hi) & (x == x)
    xi = np.where(inner, x, 0.0)
    k = xi.astype(np.int64)
    f = xi - k
    t0 = tab[o + k]
    v = t0 + f * (tab[o + k + 1] - t0)
    v = np.where(lo, tab[o], np.where(hi, tab[o + n - 1], v))
    return np.where(x == x, v, np.nan)


def screw_commit(bank: Any, d: np.ndarray | None, keep: np.ndarray | None) -> None:
    """The numpy cycle commits the directions of :func:`screw_command` (``keep``: the rows
    that stay, None: all)."""
    if d is None:
        return
    if keep is None:
        bank.ls_dir[:] = d
    else:
        bank.ls_dir[keep] = d[keep]


__all__ = [
    "screw_arrays",
    "screw_claimable",
    "screw_command",
    "screw_commit",
    "screw_load",
    "screw_put_back",
    "screw_values",
]
