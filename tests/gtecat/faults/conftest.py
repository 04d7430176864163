"""Every test of the fault vocabulary, recording and replay starts and ends with no GT
session open (a failed test leaves none behind for the next); :func:`record_one_by_one`
records a session the reference way the replays are compared with; :func:`fig5_2_up` brings
the manual's figure 5-2 bus up as an application does, :func:`recorded` records one and
:func:`changed` writes a tampered copy."""

from __future__ import annotations

import json
from collections.abc import Callable, Iterator
from ctypes import byref, c_short
from pathlib import Path

import pytest

from gtecat import gt
from gtecat.controller.bank import AxisBank
from gtecat.controller.core import Controller
from gtecat.faults.record import Recorder
from tests.conftest import EXAMPLES


def fig5_2_up() -> None:
    """The manual's figure 5-2 bus brought up on the default clock, as an application does
    (GT_Open, GT_InitEcatComm, GT_IsEcatReady until ready, GT_StartEcatComm)."""
    assert gt.GT_Open(eni=str(EXAMPLES / "manual_fig5_2.eni"), log="") == 0
    gt.GT_InitEcatComm()
    st = c_short()
    while not (gt.GT_IsEcatReady(byref(st)) == 0 and st.value == 1):
        gt.GTE_Wait(1)
    gt.GT_StartEcatComm()


def fig5_2_jogging(vel: float) -> None:
    """:func:`fig5_2_up`, and axis 1 on and jogging at ``vel`` pulse/ms (an encoder that moves:
    every poll reads new values)."""
    fig5_2_up()
    gt.GT_AxisOn(1)
    gt.GT_PrfJog(1)
    gt.GT_SetVel(1, vel)
    gt.GT_Update(1)


def recorded(path: Path, session: Callable[[], object], any_thread: bool = False) -> Path:
    """``session()`` recorded into ``path`` (the calls of every thread: ``any_thread``)."""
    rec = Recorder(path, any_thread=any_thread).start()
    try:
        session()
    finally:
        rec.stop()
        gt.GT_Close()
    return rec.write()


def record_one_by_one(out: Path, session: Callable[[], object], quick: bool = True) -> Path:
    """Record ``session()`` into ``out`` with every cycle run one by one (no run of cycles at
    once; ``quick=False``: no quick cycle a call's latency makes due either) and every Trap
    table computed afresh when an axis comes back to the bank: the reference a replay the
    quick ways must reproduce exactly."""
    mp = pytest.MonkeyPatch()
    mp.setattr(Controller, "run_cycles", lambda self, n: 0)
    if not quick:
        mp.setattr(Controller, "due_cycle", lambda self, pending: False)
    mp.setattr(AxisBank, "_keep_table", lambda self, r, pl: None)
    rec = Recorder(out).start()
    try:
        session()
    finally:
        rec.stop()
        mp.undo()
        gt.GT_Close()
    rec.write()
    return out


def changed(
    src: Path, dst: Path, picked: Callable[[str], bool], nth: int, change: Callable[[dict], object]
) -> int:
    """``src`` written to ``dst`` with the ``nth`` call whose line ``picked`` takes changed by
    ``change(entry)``, the line written as the recorder writes it; that call's number."""
    lines = src.read_text().splitlines()
    calls = seen = 0
    for i, line in enumerate(lines[1:], 1):
        if not line.startswith('{"t":'):
            continue
        calls += 1
        if picked(line):
            seen += 1
            if seen == nth:
                e = json.loads(line)
                change(e)
                lines[i] = json.dumps(e, separators=(",", ":"))
                dst.write_text("\n".join(lines) + "\n")
                return calls
    raise AssertionError(f"{src}: no call {nth} of those picked")


@pytest.fixture(autouse=True)
def _closed() -> Iterator[None]:
    gt.GT_Close()
    yield
    gt.GT_Close()
