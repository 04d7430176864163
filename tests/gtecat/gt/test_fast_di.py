"""GT_GetDi / GT_GetDiRaw / GT_GetDo on the fast path answer as their table path in every state.

The fast path keeps each input type's combination of axis bits and sense until the next
change of the inputs' sense (:func:`gtecat.controller.input_sense.changed`, counted in its
``EPOCH``).  Each test reads every type through both paths first (so a combination is kept),
then changes one thing that makes the value - a configuration's ``reverse`` (a vendor file,
``GT_SetSense``, ``GT_LmtSns``, ``GT_Reset``, gtecat's earlier format), the machine's switch
wiring, the bus brought up again, a switch moved onto, stuck or chattering, an EtherCAT IO
slave's input stuck, a drive in fault, a GPI, an axis arrived, the axis bank holding the
axes, the outputs GT_GetDo reads, a pulse card's terminals - and compares again: code, value
and reason for every type and every shape a client passes.  A writer that forgot the counter
would leave the fast path answering from a stale combination, which a test shows.
"""

from __future__ import annotations

import cProfile
import ctypes
from ctypes import byref
from pathlib import Path

import numpy as np

from gtecat import faults, gt
from gtecat.controller import config_file, input_sense
from gtecat.drives.machine import AxisMachine, MachineDescription

from .conftest import bring_up
from .profiled import table_calls

_HELD = ctypes.c_long()
_HELD_REF = byref(_HELD)
#: shape -> a maker of (the argument, what shows what was written)
SHAPES = {
    "byref": lambda: (o := ctypes.c_long(), byref(o), o),
    "same byref": lambda: (_HELD_REF, _HELD),
    "object": lambda: (o := ctypes.c_long(), o, o),
    "int32": lambda: (o := ctypes.c_int32(), byref(o), o),
    "unsigned": lambda: (o := ctypes.c_uint32(), byref(o), o),
    "narrow": lambda: (o := ctypes.c_int8(), byref(o), o),
    "double": lambda: (o := ctypes.c_double(), byref(o), o),
    "array": lambda: (o := (ctypes.c_long * 2)(), o, o),
    "uint array": lambda: (o := (ctypes.c_uint * 2)(), o, o),
    "numpy int32": lambda: (o := np.zeros(2, np.int32), o, o),
    "numpy int64": lambda: (o := np.zeros(1, np.int64), o, o),
    "numpy float": lambda: (o := np.zeros(1, np.float64), o, o),
    "offset": lambda: (o := (ctypes.c_long * 2)(), byref(o, 8), o),
    "null": lambda: (o := ctypes.c_long(), None, o),
}
#: the shapes the fast path answers without the table
FAST_SHAPES = ("byref", "same byref", "object", "int32", "array", "numpy int32")
#: every type each function reads, and the neighbours it refuses
TYPES = {"GT_GetDi": range(-1, 8), "GT_GetDiRaw": range(-1, 8), "GT_GetDo": range(9, 14)}


def _made(shape: str) -> tuple:
    m = SHAPES[shape]()
    return (m[0], m[1]) if len(m) == 2 else (m[1], m[2])


def _written(o) -> object:
    if isinstance(o, ctypes.Array | np.ndarray):
        return list(o)
    return o.value


def _table_calls(pr: cProfile.Profile) -> int:
    return table_calls(pr)


def compare(when: str, *, shapes=tuple(SHAPES), profile: bool = False) -> list[str]:
    """Every type through the fast path and the table path: the differences (and, with
    ``profile``, a fast shape that reached the table)."""
    bad = []
    for name, types in TYPES.items():
        fn = getattr(gt, name)
        for t in types:
            for shape in shapes:
                got = []
                for call in (fn, fn.slow):
                    arg, o = _made(shape)
                    pr = cProfile.Profile() if profile and call is fn else None
                    if pr is not None:
                        pr.enable()
                    rc = call(t, arg) if arg is not None else call(t, None)
                    if pr is not None:
                        pr.disable()
                    got.append((rc, _written(o), gt.GTE_GetLastError() if rc else ""))
                    if pr is not None and t in types[1:-1] and shape in FAST_SHAPES and rc == 0:
                        if _table_calls(pr):
                            bad.append(f"{when}: {name}({t}) {shape} took the table path")
                if got[0] != got[1]:
                    bad.append(f"{when}: {name}({t}) {shape}: {got[0]} != {got[1]}")
    return bad


def _levels() -> dict[str, int]:
    """Each function's value of each type (the table path), for the tests' own checks."""
    out = {}
    for name, types in TYPES.items():
        for t in types[1:-1]:
            v = ctypes.c_long()
            assert getattr(gt, name).slow(t, byref(v)) == 0
            out[f"{name}({t})"] = v.value
    return out


def _machine(**axis2: object) -> MachineDescription:
    """Axis 1 on its negative limit and its home switch, axis 2 short of its positive limit."""
    return MachineDescription(
        {
            1: AxisMachine(negative_limit=0, positive_limit=50_000, home_switch=((-10, 10),)),
            2: AxisMachine(negative_limit=-50_000, positive_limit=2_000, **axis2),  # type: ignore[arg-type]
        }
    )


def _cfg(tmp_path: Path, text: str, name: str = "test.cfg") -> str:
    path = tmp_path / name
    path.write_text(text)
    return str(path)


def _move(axis: int, pos: int) -> None:
    assert gt.GT_AxisOn(axis) == 0 and gt.GT_PrfTrap(axis) == 0, gt.GTE_GetLastError()
    prm = gt.TTrapPrm(acc=1, dec=1, velStart=0, smoothTime=0)
    assert gt.GT_SetTrapPrm(axis, byref(prm)) == 0
    assert gt.GT_SetPos(axis, pos) == 0 and gt.GT_SetVel(axis, 100) == 0
    assert gt.GT_Update(1 << (axis - 1)) == 0, gt.GTE_GetLastError()


def test_every_type_and_shape_answers_as_the_table_in_every_state(tmp_path: Path) -> None:
    """Each writer of the inputs' sense and each thing that moves a level, one after the
    other on one bus; after each, every type and shape through both paths."""
    bring_up(clock="lockstep", machine=_machine(), bank="off")
    bad = compare("at start", profile=True)
    seen = [_levels()]
    quick = ("byref", "same byref", "object", "numpy int32")

    def step(when: str, shapes=quick) -> None:
        before = input_sense.EPOCH[0]
        bad.extend(compare(when, shapes=shapes))
        seen.append(_levels())
        steps.append((when, before))

    steps: list[tuple[str, int]] = []
    epoch = input_sense.EPOCH[0]
    cfg = (
        "[limitPositive1]\nreverse=1\n[home2]\nreverse=1\n[alarm1]\nreverse=1\n[gpi3]\nreverse=1\n"
    )
    assert gt.GT_LoadConfig(_cfg(tmp_path, cfg)) == 0, gt.GTE_GetLastError()
    assert input_sense.EPOCH[0] != epoch, "a vendor file's reverse moves the counter"
    step("a vendor file")
    assert gt.GT_SetSense(gt.MC_HOME, 1, 1) == 0, gt.GTE_GetLastError()
    step("GT_SetSense home 1")
    assert gt.GT_SetSense(gt.MC_ARRIVE, 2, 1) == 0 and gt.GT_SetSense(gt.MC_GPI, 16, 1) == 0
    step("GT_SetSense arrive 2, gpi 16")
    assert gt.GT_LmtSns(0b0110) == 0, gt.GTE_GetLastError()
    step("GT_LmtSns")
    assert gt.GTE_SetGpi(3, 1) == 0 and gt.GTE_SetGpi(5, 1) == 0
    step("a GPI")
    assert gt.GT_SetDo(gt.MC_GPO, 0x8421) == 0 and gt.GT_SetDoBit(gt.MC_GPO, 16, 1) == 0
    step("the outputs")
    assert gt.GT_AxisOn(1) == 0 and gt.GT_SetDo(gt.MC_CLEAR, 0b10) == 0
    gt.GTE_Wait(5)
    step("an axis enabled, an alarm-clear output")
    _move(2, 3_000)  # onto axis 2's positive limit
    gt.GTE_Wait(200)
    step("a limit switch reached", shapes=tuple(SHAPES))
    faults.inject("switch_stuck", axis=1, switch="positive", value=1)
    gt.GTE_Wait(3)
    step("a switch stuck on")
    faults.inject("switch_stuck", axis=1, switch="home", value=0)
    gt.GTE_Wait(3)
    step("a switch stuck off")
    faults.inject("switch_chatter", axis=2, switch="home", period_cycles=1)
    for k in range(3):
        gt.GTE_Wait(1)
        step(f"a chattering switch, cycle {k}")
    faults.inject("io_stuck", slave=2, bit=0, value=1)  # (an EtherCAT IO slave's input)
    gt.GTE_Wait(2)
    step("an IO slave's input stuck")
    faults.inject("drive_fault", axis=1)
    gt.GTE_Wait(5)
    step("a drive in fault")
    assert gt.GT_Reset() == 0
    gt.GTE_Wait(3)
    step("GT_Reset", shapes=tuple(SHAPES))
    assert gt.GT_LoadConfig(_cfg(tmp_path, "[axis 1]\nactive = 1\n", "legacy.cfg")) == 0
    step("gtecat's earlier format")
    assert gt.GT_InitEcatComm() == 0, gt.GTE_GetLastError()  # the bus brought up again
    gt.GTE_Wait(60)
    step("the bus brought up again")
    assert not bad, "\n".join(bad[:20])
    # the states differ (the steps change what is read)
    assert len({tuple(s.values()) for s in seen}) >= 8, seen


def test_the_machine_wiring_and_the_bank(tmp_path: Path) -> None:
    """A machine stating its switch wiring against a file's reverse; the axis bank holding
    the axes (the inputs are read in the process image, which the bank writes: it keeps
    them, on both paths)."""
    bring_up(clock="lockstep", machine=_machine(switch_wiring="normally_closed"))
    bad = compare("wired", profile=True)
    cfg = "[limitPositive2]\nreverse=0\n[limitNegative2]\nreverse=1\n[home1]\nreverse=1\n"
    assert gt.GT_LoadConfig(_cfg(tmp_path, cfg)) == 0, gt.GTE_GetLastError()
    bad += compare("wired, a file")
    assert not bad, "\n".join(bad[:20])
    gt.GT_Close()
    bring_up(clock="lockstep", bank="on")  # (no switches: the axes at rest go into the bank)
    ctl = gt.GTE_Controller()
    assert gt.GT_AxisOn(1) == 0 and gt.GT_AxisOn(2) == 0
    gt.GTE_Wait(20)
    assert ctl.bank is not None and ctl.bank.n_alive, "axes at rest in OP are in the bank"
    image = bytes(ctl.master.image.buffer)
    v, want = ctypes.c_long(), ctypes.c_long()
    held = ctl.bank.n_alive
    assert gt.GT_GetDi(gt.MC_ARRIVE, byref(v)) == 0
    assert gt.GT_GetDi.slow(gt.MC_ARRIVE, byref(want)) == 0 and v.value == want.value
    assert ctl.bank.n_alive == held, "the inputs' readers keep the bank's axes"
    assert image == bytes(ctl.master.image.buffer)
    gt.GTE_Wait(20)
    assert ctl.bank.n_alive
    bad = compare("the bank")
    assert not bad, "\n".join(bad[:20])


def test_a_missing_counter_bump_is_seen(monkeypatch) -> None:
    """The comparison catches a writer that does not move the counter: with the counter
    silenced for configuration files, GT_SetSense leaves the fast path stale."""
    bring_up(clock="lockstep", machine=_machine(), bank="off")
    assert not compare("before", shapes=("byref",))
    monkeypatch.setattr(config_file, "sense_changed", lambda *_: None)
    assert gt.GT_SetSense(gt.MC_LIMIT_NEGATIVE, 1, 1) == 0
    assert compare("silenced", shapes=("byref",)), "a stale combination went unseen"


def test_level_changes_counted_every_cycle_leave_the_bank_its_axes() -> None:
    """GT_GetDiReverseCount samples GT_GetDi's view every cycle through the kept reader: a
    home switch crossed again and again counts the same with the axis bank as without it,
    and the bank keeps the moving axis (no look at its objects every cycle)."""
    counts = {}
    for bank in ("on", "off"):
        gt.GT_Close()
        windows = tuple((k * 500, k * 500 + 150) for k in range(1, 40))
        bring_up(
            clock="lockstep",
            bank=bank,
            machine=MachineDescription({1: AxisMachine(home_switch=windows)}),
        )
        ctl = gt.GTE_Controller()
        c = (ctypes.c_ulong * 2)()
        assert gt.GT_GetDiReverseCount(gt.MC_HOME, 1, c, 2) == 0  # (watched from here)
        _move(1, 15_000)
        held = []
        for _ in range(16):
            gt.GTE_Wait(25)
            held.append(ctl.bank.n_alive if ctl.bank is not None else None)
        assert gt.GT_GetDiReverseCount(gt.MC_HOME, 1, c, 2) == 0
        counts[bank] = list(c)
        if bank == "on":
            assert all(held[2:]), f"the bank gave the axes back: {held}"
    assert counts["on"] == counts["off"] and counts["on"][0] >= 20, counts


def test_a_pulse_card_answers_as_the_table(tmp_path: Path) -> None:
    """The same readers on a GTS card's axes (their terminals from the machine description),
    with a vendor file of normally-closed switches loaded."""
    m = MachineDescription(
        {
            n: AxisMachine(negative_limit=0, positive_limit=30_000, home_switch=((-5, 5),))
            for n in (1, 2, 3)
        }
    )
    assert gt.GT_Open(card="gts:4", machine=m, clock="lockstep", log="") == 0
    assert gt.GT_Reset() == 0
    gt.GTE_Wait(3)
    bad = compare("a card", shapes=("byref", "object", "array"), profile=True)
    cfg = "[limitNegative1]\nreverse=1\n[home3]\nreverse=1\n[limitPositive2]\nreverse=1\n"
    assert gt.GT_LoadConfig(_cfg(tmp_path, cfg)) == 0, gt.GTE_GetLastError()
    gt.GTE_Wait(3)
    bad += compare("a card, a file", shapes=("byref", "object", "array"))
    assert not bad, "\n".join(bad[:20])


def test_inputs_polled_every_cycle_read_the_same_with_the_bank_holding_the_axes() -> None:
    """GT_GetDi and GT_GetDiRaw polled between every two cycles while axes move over their
    limit and home switches: the same values with the axis bank as without it (the bank
    writes the drives' inputs into the image as the scalar drives do), and the bank keeps
    the axes all along (polling gave every axis back and took it again each cycle)."""
    windows = tuple((k * 400, k * 400 + 120) for k in range(1, 30))
    machine = MachineDescription(
        {
            1: AxisMachine(home_switch=windows, positive_limit=9_000, negative_limit=-9_000),
            2: AxisMachine(home_switch=windows[::2], positive_limit=6_000, negative_limit=-500),
        }
    )
    seen = {}
    for bank in ("on", "off"):
        gt.GT_Close()
        bring_up(clock="lockstep", bank=bank, machine=machine)
        ctl = gt.GTE_Controller()
        _move(1, 12_000)
        _move(2, -2_000)
        values, held = [], []
        v = ctypes.c_long()
        for _ in range(300):
            gt.GTE_Wait(1)
            row = []
            for fn in (gt.GT_GetDi, gt.GT_GetDiRaw):
                for t in (gt.MC_LIMIT_POSITIVE, gt.MC_LIMIT_NEGATIVE, gt.MC_HOME, gt.MC_ALARM):
                    assert fn(t, byref(v)) == 0
                    row.append(v.value)
            values.append(row)
            held.append(ctl.bank.n_alive if ctl.bank is not None else 0)
        seen[bank] = values
        if bank == "on":
            # the moving axes stayed in the bank while polled, up to the limit switch that
            # stops axis 2 (a stop on a limit is an event the scalar path takes)
            assert min(held[5:130]) >= 1, held
    assert seen["on"] == seen["off"]
    assert len({tuple(r) for r in seen["on"]}) >= 4  # the inputs did change on the way


def test_get_do_reads_the_banks_rows_and_keeps_them() -> None:
    """GT_GetDo on the auto clock while the bank runs the axes (one on, one off, then the
    other way round): MC_ENABLE's bits from the rows, MC_CLEAR and MC_GPO the controller's,
    each as the table path reads them, and the bank keeps its axes (the table path gives
    them back; its guarded axis objects would too)."""
    bring_up(clock="auto")
    ctl = gt.GTE_Controller()
    s = ctypes.c_long()
    assert gt.GT_AxisOn(1) == 0
    assert gt.GT_SetDo(12, 0x5A) == 0
    for on, off in ((1, 2), (2, 1)):
        assert gt.GT_AxisOn(on) == 0 and gt.GT_AxisOff(off) == 0
        for _ in range(800):  # (polls: the bank claims both axes)
            gt.GT_GetSts(1, byref(s))
        assert ctl.bank.n_alive == ctl.bank.n == 2
        fast = [(gt.GT_GetDo(t, byref(s)), s.value) for t in (10, 11, 12)]
        assert ctl.bank.n_alive == 2  # (kept)
        assert fast == [(gt.GT_GetDo.slow(t, byref(s)), s.value) for t in (10, 11, 12)]
        assert fast[0] == (0, 1 << (on - 1)) and fast[2] == (0, 0x5A)
