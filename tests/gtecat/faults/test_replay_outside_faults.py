"""Faults injected from outside the session (``gtecat fault inject --attach``, the panel: another
thread) replay where they were armed: between two calls at once, with their own trigger
counted from there; while a call ran, at the cycle of that call they were armed in."""

from __future__ import annotations

import threading
from ctypes import byref, c_ubyte, c_ulong
from pathlib import Path

from gtecat import faults, gt
from gtecat.faults.record import Recorder, replay
from gtecat.gt._core import SESSION
from tests.conftest import EXAMPLES


def _sdo() -> int:
    buf, n, ab = (c_ubyte * 4)(), c_ulong(), c_ulong()
    return gt.GT_EcatSDOUpload(0, 0x6065, 0, buf, 4, byref(n), byref(ab))


def _elsewhere(kind: str, **values: object) -> None:
    """Injected by another thread, as the endpoint serving ``gtecat fault`` does."""
    th = threading.Thread(target=faults.inject, args=(kind,), kwargs=values)
    th.start()
    th.join()


def test_faults_armed_from_outside_replay_where_they_were_armed(tmp_path: Path) -> None:
    out = tmp_path / "outside.gtrec"
    rec = Recorder(out).start()
    codes = []
    try:
        gt.GT_Open(eni=str(EXAMPLES / "full_servo.eni"), log="")
        gt.GT_InitEcatComm()
        gt.GTE_Wait(20)
        codes.append(_sdo())
        # between two calls, at once: the very next SDO meets it (no cycle runs before it)
        _elsewhere("mailbox_abort", slave=0, index=0x6065, code=0x06020000)
        codes += [_sdo(), _sdo()]
        # with its own trigger, counted from where it was armed: the 2nd SDO after it
        _elsewhere("mailbox_lost", slave=0, index=0x6065, on_sdo=[0, 0x6065, 2])
        codes += [_sdo(), _sdo(), _sdo()]
        # while a call runs (a request served in a cycle of a long wait): 40 ms after the
        # cycle it was armed in, so after the wait ends, before the SDO 20 ms later
        ctl = SESSION.controller(1)
        t_arm = ctl.clock.now_ns + 20_000_000

        def in_cycle() -> None:
            if ctl.clock.now_ns >= t_arm:
                ctl.before_cycle = [g for g in ctl.before_cycle if g is not in_cycle]
                faults.inject("mailbox_abort", slave=0, index=0x6065, code=0x06090011, after_ms=40)

        ctl.before_cycle.append(in_cycle)
        gt.GTE_Wait(50)
        codes.append(_sdo())
        gt.GTE_Wait(20)
        codes.append(_sdo())
        gt.GT_Close()
    finally:
        rec.stop()
    rec.write()
    assert codes[:3] == [0, 1, 0] and codes[3] == 0 and codes[4] != 0 and codes[5] == 0, codes
    assert codes[6:] == [0, 1], codes
    text = out.read_text()
    assert text.count('"sync":false') == 2 and text.count('"f":"inject"') == 3
    n, div = replay(out)
    assert div is None, str(div)
    assert n == rec.calls
