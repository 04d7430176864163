"""The planners' many-steps-at-once forms (the axis bank's tables) against their own step():
PtPlanner.run (and its compiled twin, bank_kernel.PtRun), GearPlanner.run and
FollowPlanner.run give the same samples, bit for bit, and leave the planner where the same
number of steps leaves it."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gtecat.controller.bank_kernel import PtRun
from gtecat.controller.bank_kernel import library as kernel_library
from gtecat.controller.motion.follow import FollowPlanner
from gtecat.controller.motion.gear import GearPlanner
from gtecat.controller.motion.pt import PtPlanner

_STATE = ("_pos", "_vel", "_acc", "_state")


def _pt(loop: int, cycle: float = 1.0) -> PtPlanner:
    pl = PtPlanner(0, cycle, pos=123.25)
    t = 0.0
    for k in range(1, 12):
        t += (3.7, 0.4, 9.0, 12.5)[k % 4]  # segments shorter than a cycle too
        pl.data(50.0 * math.sin(k) * k, t, (0, 1, 2, 0, 0)[k % 5], 0)
    pl.set_loop(loop)
    pl.start(0)
    return pl


def _state(pl: object) -> tuple:
    extra = ("_k", "_i", "_loops_done") if isinstance(pl, PtPlanner) else ("_m_prev",)
    return tuple(getattr(pl, name) for name in (*_STATE, *extra))


@pytest.mark.parametrize(("loop", "cycle"), [(0, 1.0), (3, 1.0), (1, 0.25), (2, 2.0)])
def test_pt_run_is_its_steps(loop: int, cycle: float) -> None:
    ref, got = _pt(loop, cycle), _pt(loop, cycle)
    lib, _ = kernel_library()
    compiled = _pt(loop, cycle) if lib is not None else None
    runner = PtRun(lib) if lib is not None else None
    pts = np.array([(p.pos, p.time, float(int(p.type))) for p in got.points(0)])
    out = np.zeros((3, 40))
    for chunk in (32, 7, 1, 5, *[32] * 60):
        want, end_want = [], -1
        for j in range(chunk):
            want.append(ref.step())
            if ref.done:
                end_want = j
                break
        ps, vs, as_, end = got.run(chunk)
        assert list(zip(ps, vs, as_, strict=True)) == want
        assert end == end_want
        assert _state(got) == _state(ref)
        if compiled is not None and runner is not None:
            c_end = runner(compiled, (pts.ctypes.data, len(pts)), chunk, tuple(out), 0)
            m = c_end + 1 if c_end >= 0 else chunk
            assert list(zip(*(out[:, :m].tolist()), strict=True)) == want
            assert c_end == end_want
            assert _state(compiled) == _state(ref)
        if ref.done:
            break
    assert loop == 0 or ref.done


def _masters() -> list[float]:
    """A master moving on, reversing and standing, in uneven steps."""
    out, m = [], 10.0
    for k in range(400):
        m += 37.5 * math.sin(k / 23.0) + (3.0 if k % 7 else 0.0)
        out.append(m)
    return out


@pytest.mark.parametrize(("d", "cycle"), [(0, 1.0), (1, 0.3), (-1, 1.0)])
def test_gear_run_is_its_steps(d: int, cycle: float) -> None:
    ms = _masters()
    feed = iter([ms[0], *ms])
    ref = GearPlanner(2, d, cycle, pos=5.0, source=lambda: next(feed))
    got = GearPlanner(2, d, cycle, pos=5.0, source=lambda: ms[0])
    for pl in (ref, got):
        pl.set_master(1)
        pl.set_ratio(3, 2, 500)
        pl.start()
    want = [ref.step() for _ in ms[:150]]
    ps, vs, as_, end = got.run(ms[:150])
    ref.set_ratio(1, 4, 0)  # a new ratio while geared (a clutch from where it stands)
    got.set_ratio(1, 4, 0)
    want += [ref.step() for _ in ms[150:]]
    p2, v2, a2, _ = got.run(ms[150:])
    assert list(zip(ps + p2, vs + v2, as_ + a2, strict=True)) == want
    assert end == -1
    assert _state(got) == _state(ref)


@pytest.mark.parametrize(("loop", "d", "cycle"), [(0, 0, 1.0), (2, 0, 0.3), (1, 1, 1.0)])
def test_follow_run_is_its_steps(loop: int, d: int, cycle: float) -> None:
    ms = _masters()
    feed = iter([ms[0], *ms])
    ref = FollowPlanner(2, d, cycle, pos=-7.0, source=lambda: next(feed))
    got = FollowPlanner(2, d, cycle, pos=-7.0, source=lambda: ms[0])
    for pl in (ref, got):
        pl.set_master(1)
        for k in range(1, 9):
            pl.data(200 * k, 90.0 * math.cos(k) * k, (0, 1, 2, 3)[k % 4], 0)
        pl.set_loop(loop)
        pl.start(0)
    want, end_want = [], -1
    for j in range(len(ms)):
        want.append(ref.step())
        if ref.done:
            end_want = j
            break
    got_all: list[tuple[float, float, float]] = []
    end, at = -1, 0
    for chunk in (32, 1, 32, 17, 400):
        ps, vs, as_, e = got.run(ms[at : at + chunk])
        got_all += list(zip(ps, vs, as_, strict=True))
        if e >= 0:
            end = at + e
            break
        at += chunk
    assert got_all == want
    assert end == end_want
    assert _state(got) == _state(ref)
