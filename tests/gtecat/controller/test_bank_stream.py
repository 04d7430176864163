"""Calls that stream into axes the bank runs (gtecat/controller/bank_stream.py and
bank_pt_stream.py) against the scalar reference: the same GT program, cycle by cycle, with
``bank="on"`` and ``bank="off"`` (test_bank_modes' sample of every axis: status words, planned
and encoder positions and speeds, the GT raw image), every call's return code and every
value it reads compared with ``==``.

* Dynamic PT streams (``GT_PtSpace``, ``GT_PtData`` per free slot, as an application refills
  its FIFOs): kept full (the FIFOs switch), run dry (the stream ends, then starts again),
  refilled point by point at many offsets from the FIFO's end, pushed into when full (1),
  with a time going backwards (7), segments of every type and of one cycle; a static PT
  motion whose other FIFO is filled while it runs.
* ``GT_MoveAbsolute`` retargets while accelerating, cruising, decelerating and reversing,
  onto the same target, from rest, with smoothing (a Trap move started before), toward a
  limit switch (refused once its flag is latched) and out of range (7).
"""

from __future__ import annotations

import os
from collections.abc import Callable
from ctypes import byref, c_long, c_short
from pathlib import Path

import pytest

from gtecat import gt
from tests.gtecat.controller.test_bank import _bring_up, _machine_file, _ok
from tests.gtecat.controller.test_bank_modes import _look, _play, reference

Script = list[tuple[int, Callable[[], object]]]
#: the dynamic PT axes and the Trap axes of the programs
PT_AXES = (1, 3, 4, 5, 6)
MOVE_AXES = (7, 8, 9, 10, 11, 12)


def _bit(*axes: int) -> int:
    return sum(1 << (a - 1) for a in axes)


class _Stream:
    """Per axis the points pushed so far (times in ms from the PT start)."""

    def __init__(self) -> None:
        self.k = dict.fromkeys(PT_AXES, 0)
        self.t = dict.fromkeys(PT_AXES, 0)

    def push(self, a: int, n: int | None = None, seg: int = 10) -> tuple:
        """GT_PtSpace, then a GT_PtData per free slot (at most ``n``); every code and value."""
        sp = c_short()
        out: list = [gt.GT_PtSpace(a, byref(sp), 0), sp.value]
        free = sp.value if n is None else min(n, sp.value + 1)  # (one too many: code 1)
        for _ in range(free):
            self.k[a] += 1
            k = self.k[a]
            step = seg if seg else 1 + k % 7
            kind = (gt.PT_SEGMENT_NORMAL, gt.PT_SEGMENT_EVEN, gt.PT_SEGMENT_STOP)[k % 5 % 3]
            pos = 900.0 * ((k % 40) if k % 80 < 40 else 80 - k % 80) + 3.5 * a
            rc = gt.GT_PtData(a, pos, self.t[a] + step, kind, 0)
            if rc == 0:
                self.t[a] += step
            out.append(rc)
        return tuple(out)


def _pt_program() -> Script:
    s = _Stream()

    def setup() -> object:
        out = []
        for a in PT_AXES:
            out.append(gt.GT_PrfPt(a, gt.PT_MODE_DYNAMIC))
            out.append(s.push(a, 40 if a != 6 else 5, seg=0 if a in (4, 5) else 10))
        # axis 2: static PT, endless, its other FIFO filled while it runs
        _ok(gt.GT_PrfPt(2, gt.PT_MODE_STATIC), "PrfPt")
        for k in range(1, 7):
            _ok(gt.GT_PtData(2, 300.0 * k, 9 * k, gt.PT_SEGMENT_NORMAL, 0), "PtData")
        _ok(gt.GT_SetPtLoop(2, 0), "SetPtLoop")
        out.append(gt.GT_PtStart(_bit(*PT_AXES, 2), 0))
        return tuple(out)

    def poll(cycle: int) -> Callable[[], object]:
        def act() -> object:
            out = [s.push(1, seg=10)]  # kept full: the FIFOs switch
            if cycle % 3 == 0:
                out.append(s.push(3, 1, seg=10))  # one point at a time: near the FIFO's end
            out.append(s.push(4, 2, seg=0))  # short segments of varied length
            if cycle % 50 == 0:
                out.append(s.push(5, 60, seg=0))  # pushed into when full: 1
            if cycle in (120, 320):
                # axis 6 ran dry (its stream ended): a new stream, started again
                out.append(s.push(6, 12, seg=10))
                s.t[6] = 0
                out.append(gt.GT_PtClear(6, 0))
                sp = c_short()
                out.append((gt.GT_PtSpace(6, byref(sp), 0), sp.value))
                out.append(s.push(6, 8, seg=10))
                out.append(gt.GT_PtStart(_bit(6), 0))
            if cycle == 200:
                out.append(gt.GT_PtData(1, 0.0, 5, gt.PT_SEGMENT_NORMAL, 0))  # time back: 7
                out.append(gt.GT_PtData(1, 0.0, s.t[1] + 10, 7, 0))  # no such type: 7
                out.append(gt.GT_PtData(2, 99.0, 9, gt.PT_SEGMENT_NORMAL, 1))  # other FIFO
                sp = c_short()
                out.append((gt.GT_PtSpace(2, byref(sp), 1), sp.value))
            if cycle == 260:
                out.append(gt.GT_PtData(2, 99.0, 200, gt.PT_SEGMENT_NORMAL, 0))  # running: 1
            return tuple(out)

        return act

    script: Script = [(0, setup)]
    for c in range(1, 31):
        script.append((13 + c % 5, poll(15 * c)))
    return script


def _move(a: int, pos: int, vel: float = 20.0, acc: float = 0.5, dec: float = 0.0) -> int:
    prm = gt.TMoveAbsolutePrm()
    prm.pos, prm.vel, prm.acc, prm.dec, prm.percent = pos, vel, acc, dec, 0
    return gt.GT_MoveAbsolute(a, byref(prm))


def _trap(a: int, target: int, vel: float, smooth: int) -> int:
    gt.GT_PrfTrap(a)
    prm = gt.TTrapPrm()
    prm.acc, prm.dec, prm.velStart, prm.smoothTime = 0.5, 0.5, 0.0, smooth
    gt.GT_SetTrapPrm(a, byref(prm))
    gt.GT_SetPos(a, target)
    gt.GT_SetVel(a, vel)
    return gt.GT_Update(_bit(a))


def _move_program() -> Script:
    def setup() -> object:
        # axis 8 moves with smoothing: the retargets keep its parameters
        return (_trap(8, 90_000, 15.0, 25), *(_move(a, 40_000 + 100 * a) for a in (7, 9, 11, 12)))

    script: Script = [(0, setup)]
    flip = [1]

    def every(a: int, pos: int, vel: float = 20.0) -> Callable[[], object]:
        return lambda: _move(a, pos, vel)

    # accelerating (7 at 10 ms), cruising, decelerating onto the target, reversing
    script += [
        (10, every(7, 60_000)),
        (5, every(9, -5_000)),  # reversing while accelerating
        (25, every(8, -20_000)),  # smoothing kept
        (30, every(11, 40_000 + 1100)),  # the same target again
        (10, every(12, 1_000, 5.0)),  # slower, then brakes onto a target behind
        (40, lambda: (_move(10, 30_000), _move(7, 10_000, 30.0))),  # 10 toward its limit
        (7, lambda: _move(11, 2_000_000_000)),  # out of range: 7
    ]
    for c in range(12):

        def all_axes(c: int = c) -> object:
            flip[0] = -flip[0]
            out = []
            for a in MOVE_AXES:
                out.append(_move(a, flip[0] * (20_000 + 900 * a + 37 * c), 10.0 + a + c % 3))
            sts = c_long()
            out.append((gt.GT_GetSts(10, byref(sts)), sts.value))
            return tuple(out)

        script.append((17 + 3 * (c % 4), all_axes))
    script += [
        (60, lambda: _move(10, 40_000)),  # toward the latched positive limit: 1
        (5, lambda: (gt.GT_ClrSts(10), _move(10, 0))),
        (40, lambda: _move(9, 12_345)),
    ]
    return script


#: the programs (made afresh for each run: a stream counts the points it pushed)
PT_STREAM = _pt_program
MOVES = _move_program


def _run(
    program: Callable[[], Script], machine: str, bank: str, chunked: bool
) -> tuple[list, tuple]:
    """The script's trace (every cycle, or the end of each wait when ``chunked``) and the
    bank's counts (calls streamed, FIFO ends stepped, samples stepped ahead)."""
    script = program()
    _bring_up(machine, bank)
    ctl = gt.GTE_Controller()
    size = ctl.layout.gt_raw_bytes
    trace: list = []
    try:
        _play(script, size, chunked, trace)
        gt.GTE_Wait(30)
        trace.append(_look(size))
        trace.append(
            tuple(
                (ch.mech.pos, ch.mech.vel, ch.statusword)
                for s in ctl.backend.slaves
                for ch in getattr(s, "channels", [])
            )
        )
        b = ctl.bank
        counts = (0, 0, 0)
        if b is not None:
            ps = b.__dict__.get("pt_stream")
            counts = (b.streamed_calls, ps.events if ps else 0, b.sampled_samples)
    finally:
        gt.GT_Close()
    return trace, counts


@pytest.fixture(scope="module")
def machine(tmp_path_factory: pytest.TempPathFactory) -> str:
    return _machine_file(Path(tmp_path_factory.mktemp("stream")))


@pytest.mark.parametrize(
    ("script", "chunked"),
    [
        (PT_STREAM, False),
        (PT_STREAM, True),
        (MOVES, False),
        pytest.param(MOVES, True, marks=pytest.mark.long("the moves again in long waits")),
    ],
    ids=["pt-stream", "pt-stream-chunked", "moves", "moves-chunked"],
)
def test_streamed_calls_in_the_bank_match_the_scalar_path(machine, script, chunked) -> None:
    ref, none = reference(_run, script, machine, chunked)
    assert none == (0, 0, 0)
    got, (streamed, events, samples) = _run(script, machine, "on", chunked)
    for k, (a, b) in enumerate(zip(ref, got, strict=True)):
        assert a == b, f"step {k}: the bank and the scalar path differ"
    assert streamed >= 60, "the calls hardly ran on claimed rows"
    if script is PT_STREAM:
        assert events >= 3, "no FIFO ran out in the bank"
        assert samples >= 1500, "the bank hardly ran the streams"


@pytest.mark.sample(1)
@pytest.mark.parametrize("script", [PT_STREAM, MOVES], ids=["pt-stream", "moves"])
def test_streamed_calls_in_the_numpy_bank_match_the_scalar_path(machine, script) -> None:
    """The same without the compiled cycle: the dynamic PT tables by the planners' run."""
    ref, _ = reference(_run, script, machine, True)
    old = os.environ.get("GTECAT_BANK_KERNEL")
    os.environ["GTECAT_BANK_KERNEL"] = "numpy"
    try:
        got, (streamed, _, _) = _run(script, machine, "on", True)
    finally:
        if old is None:
            del os.environ["GTECAT_BANK_KERNEL"]
        else:
            os.environ["GTECAT_BANK_KERNEL"] = old
    assert got == ref
    assert streamed >= 60
