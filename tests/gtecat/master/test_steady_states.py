"""The emulated bus's steadiness check keeps its "every slave in OP" answer only while no
slave changes AL state: every way a slave's state changes counts the change, and the check
then answers False at once (before the master's cycle has seen anything)."""

from __future__ import annotations

import re
from collections.abc import Callable, Iterator
from ctypes import byref, c_short
from pathlib import Path
from typing import Any

import pytest

from gtecat import gt
from gtecat.controller.inspect import BusView
from gtecat.drives.slave import AlState, VirtualSlave
from gtecat.faults.bus import EmulatedBus
from tests.conftest import EXAMPLES

ROOT = Path(__file__).resolve().parents[3]
DRIVE, DIO = 0, 6  # a drive the axis bank runs and the IO slave the bus steps


@pytest.fixture(scope="module")
def ctl() -> Iterator[Any]:
    assert gt.GT_Open(eni=str(EXAMPLES / "twelve_axes.eni"), clock="lockstep", log="") == 0
    c = gt.GTE_Controller()
    gt.GT_InitEcatComm()
    st = c_short()
    for _ in range(200):
        c.clock.advance(1)
        if gt.GT_IsEcatReady(byref(st)) == 0 and st.value == 1:
            break
    gt.GT_StartEcatComm()
    for a in range(1, 13):
        gt.GT_AxisOn(a)
    c.clock.advance(50)
    yield c
    gt.GT_Close()


def _back_to_steady(ctl: Any, position: int) -> None:
    """The slave asked back to OP (as ``gtecat states -p N OP`` does), the axes on again."""
    BusView(ctl).states(position, "OP")
    for _ in range(20):
        ctl.clock.advance(10)
        if ctl.backend.steady():
            return
        gt.GT_ClrSts(1, 12)
        for a in range(1, 13):
            gt.GT_AxisOn(a)
    raise AssertionError("the bus does not come back to steady")


def _request(ctl: Any, pos: int) -> None:
    ctl.backend.request_state(pos, AlState.SAFEOP)  # an AL control request


def _states_verb(ctl: Any, pos: int) -> None:
    BusView(ctl).states(pos, "PREOP")  # gtecat states -p N PREOP


def _watchdog(ctl: Any, pos: int) -> None:
    ctl.backend.slaves[pos].watchdog_expired()


def _power_cycle(ctl: Any, pos: int) -> None:
    EmulatedBus(ctl).power_cycle(pos)


def _retreat(ctl: Any, pos: int) -> None:
    EmulatedBus(ctl).fall(pos, AlState.SAFEOP, 0x001B)


WAYS: dict[str, Callable[[Any, int], None]] = {
    "AL control request": _request,
    "gtecat states": _states_verb,
    "watchdog": _watchdog,
    "fault retreat": _retreat,
    "fault power cycle": _power_cycle,
}


#: each way on a drive the bank runs and on the IO slave the bus steps (a drive's power cycle
#: forgets its settings, so only the IO slave's is taken: the same write)
CASES = [(w, p) for p in (DRIVE, DIO) for w in WAYS if (w, p) != ("fault power cycle", DRIVE)]


@pytest.mark.parametrize(("way", "position"), CASES)
def test_every_state_change_makes_the_bus_unsteady(ctl: Any, way: str, position: int) -> None:
    _back_to_steady(ctl, position)
    assert ctl.backend.steady()
    before = VirtualSlave.al_changes
    WAYS[way](ctl, position)
    assert VirtualSlave.al_changes > before
    assert ctl.backend.slaves[position].al_state != AlState.OP
    assert not ctl.backend.steady()
    _back_to_steady(ctl, position)


def test_al_state_is_written_only_through_enter_state() -> None:
    """A write of ``al_state`` that bypasses the count would leave the check's answer stale."""
    write = re.compile(r"\.al_state\s*=(?!=)")
    found = [
        f"{path.relative_to(ROOT)}:{n}"
        for path in sorted((ROOT / "gtecat").rglob("*.py"))
        for n, line in enumerate(path.read_text().splitlines(), 1)
        if write.search(line)
    ]
    assert found == ["gtecat/drives/slave.py:" + str(_enter_state_line())], found


def _enter_state_line() -> int:
    lines = (ROOT / "gtecat/drives/slave.py").read_text().splitlines()
    start = next(i for i, s in enumerate(lines) if "def enter_state" in s)
    return next(i for i in range(start, len(lines)) if "self.al_state = " in lines[i]) + 1
