"""GT_HomeSts's fast path held to its table path: every shape a client passes, through a
homing's states (none made yet, running, ended at its target, failed), in lockstep and on
the auto clock; the common shapes answered without the table path."""

from __future__ import annotations

import sys
from ctypes import byref, c_double, c_int, c_short, c_ubyte, c_ushort
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from gtecat import gt
from tests.gtecat.controller.test_bank import ENI, _ok, open_bus
from tests.gtecat.controller.test_bank_smart_home import _machine

#: axis -> GT_Home's (pos, vel, acc, offset) or None (never homed), machine keys
SETUP: dict[int, tuple[tuple | None, dict[str, object]]] = {
    1: ((60_000, 20.0, 0.5, 100), {"home_switch": [[1_037, 8_000]]}),
    2: ((1_000, 20.0, 0.5, 0), {"home_switch": [[5_000, 6_000]]}),  # none before 1000
    3: ((-60_000, 10.0, 0.5, -40), {"home_switch": [[-3_000, -2_000]]}),  # still running
    4: (None, {}),
}

#: the shapes: a name, a maker of (pointer argument, reader of the value written)
SHAPES: dict[str, Any] = {
    "byref ushort": lambda: (lambda x: (byref(x), lambda: x.value))(c_ushort(9)),
    "byref short": lambda: (lambda x: (byref(x), lambda: x.value))(c_short(9)),
    "byref int": lambda: (lambda x: (byref(x), lambda: x.value))(c_int(9)),
    "byref ubyte": lambda: (lambda x: (byref(x), lambda: x.value))(c_ubyte(9)),
    "object": lambda: (lambda x: (x, lambda: x.value))(c_ushort(9)),
    "array": lambda: (lambda x: (x, lambda: list(x)))((c_ushort * 2)(9, 9)),
    "byref array": lambda: (lambda x: (byref(x), lambda: list(x)))((c_ushort * 2)(9, 9)),
    "byref array offset": lambda: (lambda x: (byref(x, 2), lambda: list(x)))((c_ushort * 2)(9, 9)),
    "numpy": lambda: (lambda x: (x, lambda: x.tolist()))(np.full(2, 9, np.uint16)),
    "numpy int32": lambda: (lambda x: (x, lambda: x.tolist()))(np.full(2, 9, np.int32)),
    "byref double": lambda: (lambda x: (byref(x), lambda: x.value))(c_double(9.0)),
    "None": lambda: (None, lambda: None),
}


def _both(axis: int, shape: str, twin: bool) -> tuple:
    """(rc, value, last error) of the fast function (or its GTN_ twin with core 1) and of
    the table path.  On the auto clock a call may run a cycle that changes the status: the
    fast function is asked before and after the table, and where the two differ the table's
    answer is either of them."""

    def one(call: Any) -> tuple:
        p, value = SHAPES[shape]()
        rc = call(p)
        return rc, value(), gt.GTE_GetLastError()

    fast = (lambda p: gt.GTN_HomeSts(1, axis, p)) if twin else (lambda p: gt.GT_HomeSts(axis, p))
    got = one(fast)
    table = one(lambda p: gt.GT_HomeSts.slow(axis, p))
    again = one(fast)
    return (got if table != again else again), table


def _cycles_of(call: Any, n: int = 400) -> int:
    """The controller's cycles that ``n`` calls let pass (the auto clock: 50 µs a call)."""
    clock = gt.GTE_Controller().clock
    before = clock.cycles
    for _ in range(n):
        call()
    return clock.cycles - before


@pytest.fixture(scope="module")
def machine(tmp_path_factory: pytest.TempPathFactory) -> str:
    setup = {a: (None, keys) for a, (_, keys) in SETUP.items()}
    return _machine(tmp_path_factory.mktemp("fast_legacy_home"), setup)


@pytest.mark.parametrize("clock", ["lockstep", "auto"])
def test_the_fast_path_answers_as_the_table_path(machine: str, clock: str) -> None:
    seen = set()
    try:
        open_bus(str(ENI), machine, "on")
        if clock == "auto":  # (the same bus on the auto clock)
            gt.GT_Close()
            _ok(gt.GT_Open(eni=str(ENI), machine=machine, log=""), "open auto")
            _ok(gt.GT_InitEcatComm(), "init")
            ready = c_short()
            while not (gt.GT_IsEcatReady(byref(ready)) == 0 and ready.value):
                gt.GTE_Wait(1)
            _ok(gt.GT_StartEcatComm(), "start")
        for a in SETUP:
            _ok(gt.GT_AxisOn(a), f"axis on {a}")
        _ok(gt.GT_HomeInit(), "home init")
        for a, (args, _) in SETUP.items():
            if args is not None:
                _ok(gt.GT_Home(a, *args), f"home {a}")
        for _ in range(16):
            for a in SETUP:
                for shape in SHAPES:
                    fast, table = _both(a, shape, twin=False)
                    assert fast == table, (a, shape)
                    twin, table = _both(a, shape, twin=True)
                    assert twin == table, (a, shape, "GTN_")
                    if shape == "byref ushort":
                        seen.add(table[:2])
            gt.GTE_Wait(13)
        if clock == "auto":  # each call costs the controller the time the table's does
            s = c_ushort()
            fast = _cycles_of(lambda: gt.GT_HomeSts(1, byref(s)))
            table = _cycles_of(lambda: gt.GT_HomeSts.slow(1, byref(s)))
            assert abs(fast - table) <= 1 and fast >= 10, (fast, table)
    finally:
        gt.GT_Close()
    # running (0, 0), ended (0, 1) and failed (1, 0) were all compared
    assert {(0, 0), (0, 1), (1, 0)} <= seen, seen


def test_the_common_shapes_never_reach_the_table(machine: str) -> None:
    calls: list[str] = []
    table = sys.modules["gtecat.gt.legacy_home_calls"].__file__

    def profile(frame: Any, event: str, arg: Any) -> None:
        if event == "call" and frame.f_code.co_filename == table:
            calls.append(frame.f_code.co_name)

    try:
        open_bus(str(ENI), machine, "on")
        for a in SETUP:
            _ok(gt.GT_AxisOn(a), f"axis on {a}")
        _ok(gt.GT_Home(1, *SETUP[1][0]), "home 1")
        gt.GTE_Wait(5)
        shapes = ("byref ushort", "byref short", "object", "array", "byref array", "numpy")
        args = [SHAPES[s]()[0] for s in shapes]
        sys.setprofile(profile)
        try:
            for p in args:
                assert gt.GT_HomeSts(1, p) == 0
                assert gt.GTN_HomeSts(1, 1, p) == 0
        finally:
            sys.setprofile(None)
    finally:
        gt.GT_Close()
    assert calls == []


def test_an_axis_the_fast_path_has_not_seen_goes_to_the_table(tmp_path: Path) -> None:
    """No homing made yet for the axis: the table path makes it (status 0)."""
    machine = _machine(tmp_path, {1: (None, {})})
    try:
        open_bus(str(ENI), machine, "on")
        s = c_ushort(5)
        assert gt.GT_HomeSts(1, byref(s)) == 0 and s.value == 0
        assert gt.GT_HomeSts(99, byref(s)) == 7
    finally:
        gt.GT_Close()
