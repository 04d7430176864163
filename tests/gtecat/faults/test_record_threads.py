"""A program with a motion thread and an HMI thread (a field application's shape): the
recording holds both threads' calls in the order they ran, and the replay, in one thread,
gives every result again.  Neither thread sleeps on the wall clock: the interleaving is the
scheduler's, different in every run, which is what the recording must capture."""

from __future__ import annotations

import threading
from ctypes import byref, c_double, c_long
from pathlib import Path

from gtecat import gt
from gtecat.faults.record import replay

from .conftest import fig5_2_up, recorded


def _session() -> int:
    fig5_2_up()
    gt.GT_AxisOn(1)
    gt.GT_AxisOn(2)
    stop = threading.Event()
    polls = [0]

    def hmi() -> None:
        s = (c_long * 2)()
        p = (c_double * 2)()
        clk = c_long()
        while not stop.is_set():
            gt.GT_GetSts(1, s, 2, None)
            gt.GT_GetPrfPos(1, p, 2, byref(clk))
            polls[0] += 1

    th = threading.Thread(target=hmi)
    th.start()
    try:
        gt.GT_PrfTrap(1)
        for leg in range(6):
            gt.GT_SetPos(1, 3000 * (leg % 2))
            gt.GT_SetVel(1, 20.0)
            gt.GT_Update(1)
            for _ in range(40):
                gt.GTE_Wait(2)
    finally:
        stop.set()
        th.join(timeout=60)
    gt.GT_Close()
    return polls[0]


def test_both_threads_are_recorded_in_order_and_replay(tmp_path: Path) -> None:
    path = tmp_path / "threads.gtrec"
    polls = []
    recorded(path, lambda: polls.append(_session()), any_thread=True)
    text = path.read_text()
    assert polls[0] > 0
    assert text.count('"c":"GT_GetPrfPos"') == polls[0]  # every HMI call, none left out
    n, div = replay(path)
    assert div is None, str(div)
    assert n == sum(line.startswith('{"t":') for line in text.splitlines())
