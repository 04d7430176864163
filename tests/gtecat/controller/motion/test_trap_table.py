"""trap_table (the axis bank's Trap samples, vectorised over time) against TrapPlanner.step:
the same samples, bit for bit, and the same end (gtecat/controller/motion/trap_table.py)."""

from __future__ import annotations

import copy

from hypothesis import given, settings
from hypothesis import strategies as st

from gtecat.controller.motion.trap import TrapParams, TrapPlanner
from gtecat.controller.motion.trap_table import advance, trap_table
from tests.conftest import examples


@settings(max_examples=examples(150, 19), deadline=None, derandomize=True)
@given(
    start=st.floats(-1e5, 1e5),
    target=st.integers(-200_000, 200_000),
    vel=st.floats(0.1, 50.0),
    acc=st.floats(0.01, 5.0),
    dec=st.floats(0.0, 5.0),
    vs=st.sampled_from([0.0, 0.0, 1.5]),
    smooth=st.sampled_from([0, 1, 5, 25, 50]),
    before=st.integers(0, 50),
    retarget=st.one_of(st.none(), st.tuples(st.integers(-200_000, 200_000), st.floats(0.1, 50.0))),
    n=st.sampled_from([1, 7, 256, 4096]),
)
def test_table_is_the_planner_sample_by_sample(
    start, target, vel, acc, dec, vs, smooth, before, retarget, n
) -> None:
    pl = TrapPlanner(1.0, start)
    pl.start(pl.pos, target, vel, TrapParams(acc=acc, dec=dec, vel_start=vs, smooth_time=smooth))
    for _ in range(before):
        pl.step()
    if retarget is not None and not pl.done:
        pl.update(*retarget)
    if pl.done:
        return
    ref = copy.deepcopy(pl)
    taken, ended = 0, False
    for _ in range(4):  # table after table, as the bank refills them
        p, v, a, end = trap_table(pl, n, pl._k + taken)
        for k in range(len(p)):
            assert ref.step() == (p[k], v[k], a[k]), f"sample {taken + k + 1}"
        taken += len(p)
        ended = end < n
        assert ref.done == ended
        if ended:
            break
    # the planner put where the table left it is the planner that stepped itself
    advance(pl, taken, (float(p[-1]), float(v[-1]), float(a[-1])), ended)
    assert (pl.done, pl.pos, pl.vel, pl.acc) == (ref.done, ref.pos, ref.vel, ref.acc)
    if not ended:
        assert pl.step() == ref.step()


@settings(max_examples=examples(60, 15), deadline=None, derandomize=True)
@given(
    start=st.floats(-1e5, 1e5),
    target=st.integers(-200_000, 200_000),
    vel=st.floats(0.1, 50.0),
    acc=st.floats(0.01, 5.0),
    dec=st.floats(0.0, 5.0),
    vs=st.sampled_from([0.0, 0.0, 1.5]),
    smooth=st.sampled_from([0, 1, 5, 25, 50]),
    before=st.integers(0, 50),
    retarget=st.one_of(st.none(), st.tuples(st.integers(-200_000, 200_000), st.floats(0.1, 50.0))),
    n=st.sampled_from([1, 7, 64, 1000]),
)
def test_the_compiled_table_is_the_planner_sample_by_sample(
    start, target, vel, acc, dec, vs, smooth, before, retarget, n
) -> None:
    """The axis bank's kernel fills its tables with a C transcription of trap_table."""
    import numpy as np
    import pytest

    from gtecat.controller import bank_kernel

    lib, reason = bank_kernel.library()
    if lib is None:
        pytest.skip(f"the kernel did not build here: {reason}")
    pl = TrapPlanner(1.0, start)
    pl.start(pl.pos, target, vel, TrapParams(acc=acc, dec=dec, vel_start=vs, smooth_time=smooth))
    for _ in range(before):
        pl.step()
    if retarget is not None and not pl.done:
        pl.update(*retarget)
    if pl.done:
        return
    ref = copy.deepcopy(pl)
    segs = np.array(pl._segs, np.float64).reshape(-1, 4)
    prm = np.array([pl._t_done, pl._ts, pl._t_final, float(pl._target), pl._dir])
    out = np.zeros((3, n + 1))
    taken = 0
    for _ in range(4):
        end = bank_kernel.trap_fill(lib, segs, pl._T, prm, pl._k + taken, n, out)
        got = end + 1 if end < n else n
        for k in range(got):
            assert ref.step() == (out[0, k], out[1, k], out[2, k]), f"sample {taken + k + 1}"
        taken += got
        assert ref.done == (end < n)
        if ref.done:
            break
