"""GT_SetHomingMode(axis, 6) of a CSP row at rest run on the bank's row, against the scalar path.

The switch's cycles run as the row's CSP cycles in the bank, and its objects are brought to
what the scalar drive and axis leave (gtecat.controller.bank_home_rows).  Compared exactly
with the bank off, on both clocks: every call's return code, every axis's GT_GetSts word,
planned and encoder positions, GT_GetEcatHomingStatus and the whole GT raw image (6041h,
6061h, 6064h among it) after every cycle, and at the end every attribute of the switched
axes' objects (axis, resources, planner, encoder, band, drive channel, mechanics) and their
drives' process data buffers.  The calls: switched and left there, switched then a call that
gives the row back right after, switched and at once back to CSP, switched and homed
(35 and 37), switched again after a homing, switched after a Trap move, switched while a
drive fault is armed to come in the middle and while the drive's quick-stop input is held,
and a row given back in the middle of its switch (before its first cycle, after it).  More:
switched after its encoder was redefined (the switch drops the link's offset), after a Trap
move that ended in the bank, after a raw write of its outputs (the same value, another one),
with a touch probe armed, from CSV, back to CSP and at once to homing mode again, and homed
on the row.  A switched row stays in the bank with its objects guarded, and its cycles ran
in one run of the compiled kernel.
"""

from __future__ import annotations

import math
from ctypes import byref, c_double, c_long, c_short, c_ubyte
from typing import Any

import numpy as np
import pytest

from gtecat import faults, gt
from gtecat.controller import bank_home_rows, bank_kernel
from gtecat.controller.bank import _GUARD_SET, AxisBank
from tests.conftest import LONG, LONG_REASON
from tests.gtecat.controller.test_bank import ENI, HAS_CC, _ok, open_bus
from tests.gtecat.controller.test_bank_homing import _machine, _sample
from tests.gtecat.controller.test_bank_homing_calls import _prm, _trap

AXES = 12
SETUP: dict[int, tuple[int, dict[str, object]]] = {
    a: (0, {"home_switch": [[2_000 + 10 * a, 3_000]]}) for a in range(1, AXES + 1)
}
CYCLES = 146

#: cycle -> the calls made before it (each one's return code goes into the trace); axes 1-4
#: are drives of one channel (the rows switched on the bank's row), 5-12 channels of drives
#: with several (their rows go back for a call)
CALLS: dict[int, list[Any]] = {
    3: [lambda: gt.GT_SetHomingMode(1, 6)],
    4: [lambda: gt.GT_SetHomingMode(2, 6), lambda: gt.GT_ClrSts(2)],  # given back right after
    5: [lambda: gt.GT_SetHomingMode(3, 6), lambda: gt.GT_SetHomingMode(3, 8)],
    6: [lambda: gt.GT_SetHomingMode(4, 6), lambda: _prm(4, 35), lambda: gt.GT_StartEcatHoming(4)],
    8: [lambda: gt.GTN_SetHomingMode(1, 5, 6), lambda: _prm(5, 37)],
    9: [lambda: gt.GT_StartEcatHoming(5)],
    10: [lambda: _prm(1, 37), lambda: gt.GT_StartEcatHoming(1)],
    12: [lambda: _trap(3)],
    14: [lambda: gt.GT_SetHomingMode(2, 8)],
    20: [lambda: gt.GT_SetHomingMode(2, 6)],  # switched again
    30: [lambda: gt.GT_SetHomingMode(1, 8)],  # back to CSP after its homing
    40: [lambda: gt.GT_SetHomingMode(1, 6), lambda: _prm(1, 35, speed1=0)],
    41: [lambda: gt.GT_StartEcatHoming(1)],  # switched and homed again
    52: [lambda: gt.GT_SetHomingMode(4, 8)],
    53: [lambda: gt.GT_SetHomingMode(4, 6), lambda: gt.GT_GetSts(4, byref(c_long()), 1)],
    54: [lambda: gt.GT_SetHomingMode(4, 6), lambda: gt.GT_SetHomingMode(4, 8)],
    100: [lambda: gt.GT_SetHomingMode(3, 6)],  # refused: its Trap move still runs
    130: [lambda: gt.GT_SetHomingMode(3, 6)],  # after its Trap move, the motor settling
    132: [lambda: gt.GTN_SetHomingMode(1, 7, 6), lambda: gt.GT_SetHomingMode(12, 6)],
    # faults on switched drives (an injector hooks every cycle from now on: the calls' rows
    # go back for them)
    134: [lambda: faults.inject("quick_stop", axis=2)],
    135: [
        lambda: faults.inject("drive_fault", axis=3, code=0x2310, after_cycles=1),
        lambda: gt.GT_SetHomingMode(3, 8),  # the fault comes while the call waits
        lambda: gt.GT_SetHomingMode(4, 6),
    ],
    140: [
        faults.clear,
        lambda: gt.GT_ClrSts(2, 2),
        lambda: gt.GT_AxisOn(2),
        lambda: gt.GT_AxisOn(3),
    ],
}
#: the axes whose objects are compared at the end
DEEP = (1, 2, 3, 4, 5, 7, 12)


def _raw_controlword(a: int, value: int) -> int:
    """A raw write of axis ``a``'s 6040h low byte (the bank sees its outputs written)."""
    e = gt.GTE_Controller().layout.axis_entry(a, 0x6040)
    assert e is not None
    return gt.GT_SetEcatRawData(e.gt_bit >> 3, 1, (c_ubyte * 1)(value))


def _axis_enc() -> tuple[float, ...]:
    """GT_GetAxisEncPos of every axis (through their encoders' links: an offset shows)."""
    values = (c_double * AXES)()
    _ok(gt.GT_GetAxisEncPos(1, values, AXES), "axis encoders")
    return tuple(values)


#: more switches (single-channel axes 1-4): from a row whose encoder was redefined (its link
#: offset dropped by the switch), from a row whose Trap move ended in the bank, with the
#: drive's outputs written raw just before, with a touch probe armed, from CSV, and to CSP
#: again and back from a switched row
MORE: dict[int, list[Any]] = {
    3: [lambda: gt.GT_SetEncPos(1, 7_000), lambda: _trap(2)],
    6: [lambda: gt.GT_SetHomingMode(1, 6)],
    7: [_axis_enc],
    8: [lambda: gt.GT_SetEncPos(1, 5_000)],  # its objects guarded again: the row goes back
    10: [lambda: _raw_controlword(3, 0x0F), lambda: gt.GT_SetHomingMode(3, 6)],  # the same
    12: [lambda: gt.GT_SetTouchProbeFunction(4, 0x0011)],
    15: [lambda: gt.GT_SetHomingMode(4, 6)],  # a probe armed
    20: [lambda: gt.GT_SetHomingMode(1, 8), lambda: gt.GT_SetHomingMode(3, 8)],
    22: [lambda: _raw_controlword(3, 0x07), lambda: gt.GT_SetHomingMode(3, 6)],  # another
    24: [lambda: gt.GT_SetHomingMode(1, 9)],
    27: [lambda: gt.GT_SetHomingMode(1, 6)],  # from CSV
    30: [lambda: gt.GT_SetHomingMode(1, 8), lambda: gt.GT_ClrSts(3), lambda: gt.GT_AxisOn(3)],
    33: [lambda: gt.GT_SetHomingMode(1, 6), lambda: gt.GT_SetHomingMode(1, 8)],
    36: [lambda: gt.GT_SetHomingMode(1, 6), lambda: _prm(1, 37)],
    37: [lambda: gt.GT_StartEcatHoming(1)],
    150: [lambda: gt.GT_SetHomingMode(1, 8)],
    153: [lambda: gt.GT_SetEncPos(1, 3_000)],
    156: [lambda: gt.GT_SetHomingMode(1, 6), lambda: _prm(1, 35)],
    157: [lambda: gt.GT_StartEcatHoming(1)],  # homed on the row after its encoder's offset
    158: [_axis_enc],
    160: [lambda: gt.GT_SetHomingMode(3, 8)],
    170: [lambda: gt.GT_SetHomingMode(2, 6)],  # its Trap move ended in the bank
    172: [lambda: gt.GT_SetHomingMode(3, 6), lambda: _prm(2, 35)],
    173: [lambda: gt.GT_StartEcatHoming(2)],
}
MORE_CYCLES = 180


_PLAIN = (int, float, str, bool, bytes, type(None))
#: what the bank keeps on the objects for itself, and a Trap planner's cursor into its
#: segments, which a move run in the bank's table leaves where the move's last cycle in the
#: bank found it (the same with or without the switch; nothing reads it once the move ended)
_BANK_OWN = frozenset(("bank", "bank_row", "_i"))


def _walk(obj: Any, path: str, out: dict[str, Any], seen: set[int]) -> None:
    """Every plain value reachable from ``obj`` through gtecat's objects, by path."""
    if isinstance(obj, _PLAIN):
        # (numbers by value: a drive's demand is the CSP target's int on the scalar path and
        # the float the bank's row keeps once it was claimed, on both sides of the switch)
        out[path] = "nan" if isinstance(obj, float) and math.isnan(obj) else obj
        return
    if isinstance(obj, (bytearray, memoryview)):
        out[path] = bytes(obj)
        return
    if isinstance(obj, np.ndarray):
        out[path] = obj.tobytes()
        return
    if id(obj) in seen:
        return
    seen.add(id(obj))
    if isinstance(obj, (list, tuple)):
        for i, x in enumerate(obj):
            _walk(x, f"{path}[{i}]", out, seen)
        return
    if isinstance(obj, dict):
        for k, x in obj.items():
            if isinstance(k, _PLAIN):
                _walk(x, f"{path}{{{k!r}}}", out, seen)
        return
    if not (type(obj).__module__ or "").startswith("gtecat.") or path.count(".") > 5:
        return
    if type(obj).__name__ in ("Controller", "AxisBank", "Cia402Drive", "ObjectDictionary"):
        return
    names = set(getattr(obj, "__dict__", {}))
    for cls in type(obj).__mro__:
        names.update(s for s in getattr(cls, "__slots__", ()) if s != "__dict__")
    out[path] = type(obj).__name__
    for n in sorted(names - _BANK_OWN):
        try:
            v = object.__getattribute__(obj, n)
        except AttributeError:
            continue
        if hasattr(v, "__self__") and callable(v):
            out[f"{path}.{n}"] = ("bound", type(v.__self__).__name__, v.__name__)
            continue
        _walk(v, f"{path}.{n}", out, seen)


def _objects(ctl: Any, deep: tuple[int, ...] = DEEP) -> dict[str, Any]:
    """Axes ``deep``'s objects and their drives' buffers, their values by path."""
    if ctl.bank is not None:
        ctl.bank.release_all()
    out: dict[str, Any] = {}
    for a in deep:
        ax = ctl.axes[a]
        slave = ctl.backend.slaves[ax.io.slave]
        _walk(ax, f"axis{a}", out, set())
        _walk(slave.channel(ax.io.channel), f"drive{a}", out, set())
        out[f"rx{a}"], out[f"tx{a}"] = bytes(slave.rx), bytes(slave.tx)
    return out


def _run(
    machine: str,
    bank: str,
    clock: str,
    calls: dict[int, list[Any]] = CALLS,
    cycles: int = CYCLES,
    deep: tuple[int, ...] = DEEP,
    count: str = "home_switches",
) -> tuple[list, dict[str, Any], int]:
    """``calls`` made over ``cycles`` cycles of the 12-axis bus with ``bank``: every call's
    return code and every cycle's sample, axes ``deep``'s objects at the end, and the bank's
    statistic ``count`` (0 without a bank)."""
    trace: list = []
    try:
        gt.GT_Close()
        _ok(gt.GT_Open(eni=str(ENI), machine=machine, clock=clock, log="", bank=bank), "open")
        _ok(gt.GT_InitEcatComm(), "init")
        ready = c_short()
        while not (gt.GT_IsEcatReady(byref(ready)) == 0 and ready.value == 1):
            gt.GTE_Wait(1)
        _ok(gt.GT_StartEcatComm(), "start")
        for a in range(1, AXES + 1):
            _ok(gt.GT_AxisOn(a), f"axis on {a}")
        gt.GTE_Wait(20)
        ctl = gt.GTE_Controller()
        size = ctl.layout.gt_raw_bytes
        for k in range(cycles):
            trace.append(tuple(call() for call in calls.get(k, ())))
            gt.GTE_Wait(1)
            trace.append(_sample(size))
        counted = getattr(ctl.bank, count) if ctl.bank is not None else 0
        return trace, _objects(ctl, deep), counted
    finally:
        faults.clear()
        gt.GT_Close()


def _same(ref: tuple, got: tuple) -> None:
    """Every step and every object of a run with the bank as the scalar drives' run."""
    for k, (a, b) in enumerate(zip(ref[0], got[0], strict=True)):
        assert a == b, f"step {k} (cycle {k // 2}): the bank and the scalar drives differ"
    diff = sorted(p for p in ref[1].keys() | got[1].keys() if ref[1].get(p) != got[1].get(p))
    assert not diff, f"objects differ: {[(p, ref[1].get(p), got[1].get(p)) for p in diff[:5]]}"


def _all_on(machine: str) -> None:
    """The 12-axis bus with the bank on (lockstep, :func:`open_bus`), every axis enabled."""
    open_bus(str(ENI), machine, "on")
    for a in range(1, AXES + 1):
        _ok(gt.GT_AxisOn(a), f"axis on {a}")


def _ran_on_rows(got: tuple, least: int) -> None:
    """Without this the comparison could pass with no switch ever run on a row."""
    if HAS_CC and bank_kernel.wanted() != "numpy":
        assert got[2] >= least


@pytest.fixture(scope="module")
def machine(tmp_path_factory: pytest.TempPathFactory) -> str:
    return _machine(tmp_path_factory.mktemp("home_rows"), SETUP)


@pytest.fixture(scope="module", params=["lockstep", "auto"])
def runs(request: pytest.FixtureRequest, machine: str) -> tuple:
    clock = request.param
    return clock, _run(machine, "off", clock), _run(machine, "on", clock)


def test_switches_on_rows_match_the_scalar_drives(runs: tuple) -> None:
    _, ref, got = runs
    _same(ref, got)
    _ran_on_rows(got, 7)
    codes = [c for step in ref[0][0::2] for c in step]
    assert codes.count(0) < len(codes)  # the fault's switch was refused
    assert ref[0][-1][3][3] == 3  # axis 4 homed again


@pytest.mark.parametrize("at", [0, 1])
def test_a_row_given_back_in_the_middle_of_its_switch(
    runs: tuple, machine: str, monkeypatch: pytest.MonkeyPatch, at: int
) -> None:
    """A row given back while its drive switches (at the cycle ``at`` cycles after 6060h
    was written, before the bank runs it): its objects go on from the cycles it ran in the
    bank on the scalar path exactly."""
    clock, ref, _ = runs
    if not LONG and (clock, at) not in (("lockstep", 0), ("auto", 1)):
        pytest.skip(f"{LONG_REASON} (the default run: lockstep at 0, auto at 1)")
    cycle = AxisBank._cycle
    given: list[int] = []

    def give_back_in_the_switch(bank: AxisBank, t_ns: int, dt_ns: int) -> None:
        r = bank.home_switch
        if r >= 0 and bank.bank_cycles - bank.home_switch_from == at and len(given) < 3:
            given.append(r)
            bank.release_all()
        cycle(bank, t_ns, dt_ns)

    many = AxisBank.run_cycles

    def one_by_one_in_the_switch(bank: AxisBank, t_ns: int, dt_ns: int, n: int) -> int:
        return 0 if bank.home_switch >= 0 else many(bank, t_ns, dt_ns, n)

    monkeypatch.setattr(AxisBank, "_cycle", give_back_in_the_switch)
    # (the switch's cycles one by one through the bank's cycle, not the quick run's kernel)
    monkeypatch.setattr(AxisBank, "run_cycles", one_by_one_in_the_switch)
    got = _run(machine, "on", clock)
    _same(ref, got)
    if HAS_CC and bank_kernel.wanted() != "numpy":
        assert len(given) == 3


def test_a_switched_row_the_bank_would_not_take_goes_back(
    runs: tuple, machine: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A row whose switch ran on it but which the bank would not take again as it stands
    then (here: told so, the first three times) is given back with its objects as the
    switch left them."""
    clock, ref, _ = runs
    switched = bank_home_rows._switched
    frozen = AxisBank._eligible_frozen
    due: list[int] = []
    refused: list[int] = []

    def switched_then_refused(bank: AxisBank, r: int, g: Any) -> None:
        switched(bank, r, g)
        if len(refused) < 3:
            due.append(r)

    def refuse_once(bank: AxisBank, r: int, powered: bool = False) -> bool:
        if due and due[-1] == r:
            refused.append(due.pop())
            return False
        return frozen(bank, r, powered)

    monkeypatch.setattr(bank_home_rows, "_switched", switched_then_refused)
    monkeypatch.setattr(AxisBank, "_eligible_frozen", refuse_once)
    got = _run(machine, "on", clock)
    _same(ref, got)
    if HAS_CC and bank_kernel.wanted() != "numpy":
        assert len(refused) == 3


#: (the default run: :data:`MORE` on the auto clock; GTECAT_LONG=1 on both)
@pytest.fixture(
    scope="module",
    params=[pytest.param("lockstep", marks=pytest.mark.long("on the lockstep clock")), "auto"],
)
def more(request: pytest.FixtureRequest, machine: str) -> tuple:
    clock = request.param
    return tuple(
        _run(machine, bank, clock, MORE, MORE_CYCLES, (1, 2, 3, 4)) for bank in ("off", "on")
    )


def test_more_switches_on_rows_match_the_scalar_drives(more: tuple) -> None:
    ref, got = more
    _same(ref, got)
    _ran_on_rows(got, 6)
    assert ref[0][-1][3][0] == 3  # axis 1 homed


def test_a_switched_row_stays_in_the_bank_guarded(machine: str) -> None:
    """A switch on the row runs its cycles in one run of the compiled kernel, keeps the row
    (frozen in homing mode) and its objects' guards: touched from outside, it goes back."""
    if not HAS_CC or bank_kernel.wanted() == "numpy":
        pytest.skip("the switch runs on rows only with the compiled cycle")
    try:
        _all_on(machine)
        gt.GTE_Wait(20)  # (every axis in the bank: the controller runs cycles its quick way)
        bank = gt.GTE_Controller().bank
        r = bank._row_of[id(gt.GTE_Controller().axes[1])]
        runs: list[int] = []
        run = bank.kernel.run

        def counted(t_ns: int, dt: float, dt_ns: int, most: int) -> tuple[int, int]:
            runs.append(most)
            return run(t_ns, dt, dt_ns, most)

        bank.kernel.run = counted
        releases, switches = bank.releases, bank.home_switches
        _ok(gt.GT_SetHomingMode(1, 6), "mode")
        assert runs == [2]  # (6060h taken in the first cycle, shown after the second)
        assert bank.home_switches == switches + 1 and bank.releases == releases
        assert bank.alive[r] and bank.frz[r]
        g = bank.groups[bank.group_of[r]]
        assert all(type(obj) in _GUARD_SET for obj in bank._guarded_objects(g))
        bank.res[r].encoder.pos += 0.0  # (anything reaching an object gives the row back)
        assert not bank.alive[r]
    finally:
        gt.GT_Close()
