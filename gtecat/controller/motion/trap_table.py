"""The next samples of a Trap move at once: :meth:`TrapPlanner.step` vectorised over time.

A Trap move is fixed from its ``GT_Update`` on (a new update, a stop or a limit hands
the axis back to the planner itself), so its next ``n`` samples can be computed in one
numpy evaluation instead of ``n`` calls.  The axis bank (:mod:`gtecat.controller.bank`)
reads one sample per cycle from such a table.  The arithmetic is the planner's
``_sample`` transcribed operation by operation (the same pieces, the same order of
additions in the smoothing integral, the same end test and final clamp), so every
sample is bit-identical to what ``step()`` returns; ``tests/gtecat/controller/motion/
test_trap_table.py`` holds both to that.
"""

from __future__ import annotations

import numpy as np

from .trap import _EPS_T, _MOVE, TrapPlanner


def trap_table(
    pl: TrapPlanner, n: int, k0: int | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    """Samples ``k0+1 .. k0+n`` of ``pl`` (which must be moving: ``pl._mode == _MOVE``;
    ``k0`` defaults to the planner's own sample count).

    Returns ``(pos, vel, acc, end)``: ``end`` is the index of the end sample
    (``(target, 0, 0)``, after which the planner is done), or ``n`` when the move goes on.
    """
    assert pl._mode == _MOVE
    cyc = pl._T
    k0 = pl._k if k0 is None else k0
    t = np.arange(k0 + 1, k0 + n + 1, dtype=np.int64) * cyc
    t_done = pl._t_done
    thr = t_done - _EPS_T * (1.0 + t_done * 1e-3)
    past = np.nonzero(t >= thr)[0]
    end = int(past[0]) if len(past) else n
    t = t[:end]
    segs = np.array(pl._segs, dtype=np.float64).reshape(-1, 4)
    st, p0s, v0s, acs = segs[:, 0], segs[:, 1], segs[:, 2], segs[:, 3]
    m = len(st)
    i = np.maximum(np.searchsorted(st, t, side="right") - 1, 0)
    tau = t - st[i]
    p = p0s[i] + tau * (v0s[i] + 0.5 * acs[i] * tau)
    v = v0s[i] + acs[i] * tau
    a = acs[i]
    ts = pl._ts
    if ts > 0.0:
        ta = t - ts
        j = np.maximum(np.searchsorted(st, ta, side="right") - 1, 0)
        tau = ta - st[j]
        ak = acs[j]
        vk = v0s[j] + ak * tau
        pk = p0s[j] + tau * (v0s[j] + 0.5 * ak * tau) - p
        va = vk
        lo = ta
        total = np.zeros(len(t))
        dist = np.zeros(len(t))
        span_max = int((i - j).max()) if len(t) else 0
        # lanes past their own piece i are computed and discarded (np.where): with extreme
        # parameters (dec = 1e-172) they may overflow, which must not warn
        with np.errstate(over="ignore", invalid="ignore"):
            for d in range(span_max + 1):
                k = j + d
                live = k <= i
                kc = np.minimum(k, m - 1)
                if d:
                    lo = st[kc]
                    pk = p0s[kc] - p
                    vk = v0s[kc]
                    ak = acs[kc]
                hi = np.where(k == i, t, st[np.minimum(kc + 1, m - 1)])
                span = hi - lo
                add = live & (span > 0.0)
                total = np.where(
                    add, total + span * (pk + span * (0.5 * vk + ak * span / 6.0)), total
                )
                dist = np.where(add, dist + span * (vk + 0.5 * ak * span), dist)
        p = p + total / ts
        v, a = dist / ts, (v - va) / ts
    final = (t - ts) >= pl._t_final
    if final.any():
        tgt = float(pl._target)
        clamped = np.minimum(p, tgt) if pl._dir > 0.0 else np.maximum(p, tgt)
        p = np.where(final, clamped, p)
    if end < n:
        p = np.append(p, float(pl._target))
        v = np.append(v, 0.0)
        a = np.append(a, 0.0)
    return p, v, a, end


def advance(pl: TrapPlanner, samples: int, last: tuple[float, float, float], done: bool) -> None:
    """Put ``pl`` where ``samples`` calls of ``step()`` would have left it (``last`` = the
    last sample taken; ``done``: that was the end sample)."""
    if not samples:
        return
    if done:
        pl._finish(float(pl._target))
        return
    pl._k += samples
    pl._pos, pl._vel, pl._acc = last
