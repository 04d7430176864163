"""An application that writes its IO outputs with a new value every millisecond (figure
5-2's bus, manual section 5: both axes in Trap, every ms ``GTE_Wait(1)``, each IO slave's
input word read with ``GT_EcatIOReadInput``, its output word written with
``GT_EcatIOWriteOutput``, ``GT_GetSts``): the compiled cycle takes a plain IO slave's new
outputs to the field itself, and every cycle leaves the slaves' outputs, field outputs,
field inputs and inputs, the process image and the answers as the general Python cycle
leaves them.  A wired IO slave (an output wired to one of its inputs) keeps its general
cycle and reads its own output back one cycle later, as before.  Lockstep and auto clocks."""

from __future__ import annotations

import ctypes
from ctypes import byref
from typing import Any

import pytest

from gtecat import gt
from gtecat.controller.core import Controller
from gtecat.controller.epoch import EPOCH
from gtecat.gt import centry

from .conftest import bring_up

pytestmark = pytest.mark.skipif(bool(centry.REASON), reason=f"no C entry: {centry.REASON}")

IO_SLAVES = (2, 3)  # (figure 5-2: slaves 0 and 1 the drives)


def _fn(name: str, general: bool) -> Any:
    fn = getattr(gt, name)
    return getattr(fn, "slow", fn) if general else fn


def _run(general: bool, wired: bool, clock: str, ms: int = 120) -> tuple[list[Any], int]:
    """Each ms's state after its calls, and how often a changing write left the armed quick
    cycle standing (the compiled way's own; 0 on the general way)."""
    bring_up("manual_fig5_2.eni", clock=clock)
    try:
        wait, read, write, sts = (
            _fn(n, general)
            for n in ("GTE_Wait", "GT_EcatIOReadInput", "GT_EcatIOWriteOutput", "GT_GetSts")
        )
        for axis in (1, 2):
            assert gt.GT_AxisOn(axis) == 0
        wait(20)
        for axis in (1, 2):
            prm = gt.TTrapPrm()
            prm.acc = prm.dec = 0.5
            prm.smoothTime = 25
            assert gt.GT_PrfTrap(axis) == 0
            assert gt.GT_SetTrapPrm(axis, byref(prm)) == 0
            assert gt.GT_SetPos(axis, 50_000_000) == 0
            assert gt.GT_SetVel(axis, 20) == 0
        assert gt.GT_Update(3) == 0
        if wired:
            gt.GTE_Slave(2).wire(3, 1)  # (output bit 3 onto input bit 1)
            gt.GTE_Slave(2).wire(8, 12)
        ctl = gt.GTE_Controller()
        slaves = [gt.GTE_Slave(s) for s in IO_SLAVES]
        v, s = ctypes.c_ushort(), ctypes.c_long()
        states, kept = [], 0
        for k in range(ms):
            assert wait(1) == 0
            got = []
            for sl in IO_SLAVES:
                assert read(sl, 0, 2, byref(v)) == 0
                got.append(v.value)
                assert write(sl, 0, 2, byref(ctypes.c_ushort((k * 0x0101 + sl) & 0xFFFF))) == 0
                kept += ctl.clock.quick[4] == EPOCH.n
            assert sts(1, byref(s), 1, None) == 0
            got.append(s.value)
            got.append(ctl.clock.cycles)
            got.append(ctl.master.image.buffer.tobytes())
            for io in slaves:
                got += [bytes(io.rx), bytes(io.field_outputs), bytes(io.field_inputs), bytes(io.tx)]
            states.append(got)
        return states, kept
    finally:
        gt.GT_Close()


@pytest.mark.parametrize("clock", ["lockstep", "auto"])
@pytest.mark.parametrize("wired", [False, True], ids=["plain", "wired"])
def test_changing_outputs_every_ms_as_the_general_cycle(
    wired: bool, clock: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    quick, kept = _run(False, wired, clock)
    with monkeypatch.context() as m:
        m.setattr(Controller, "QUICK_WAIT", False)
        general, none = _run(True, wired, clock)
    assert none == 0
    for k, (a, b) in enumerate(zip(quick, general, strict=True)):
        at = next((j for j, (x, y) in enumerate(zip(a, b, strict=True)) if x != y), None)
        assert at is None, f"ms {k}, item {at}: the compiled way {a[at]!r}, the general {b[at]!r}"
    if wired:
        # (slave 2 reads its own output bit 3 back on input bit 1 a cycle after the write)
        assert any(st[0] & 0x2 for st in general) and not all(st[0] & 0x2 for st in general)
    else:
        assert kept > len(quick)  # (most changing writes left the compiled cycle armed)
