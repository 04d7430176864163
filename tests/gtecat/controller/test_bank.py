"""The axis bank against the scalar reference (issue 17 item 1): the same GT program, cycle by
cycle, with ``bank="on"`` and ``bank="off"``, the bank's plain cycle compiled
(``GTECAT_BANK_KERNEL=c``, gtecat/controller/csrc/bank_kernel.c) and in numpy alone.

Compared exactly (``==`` on floats: the bank does the scalar code's float operations in the
same order, so no tolerance is needed): every axis's GT_GetSts word, planned position
(GT_GetPrfPos, GT_GetAxisPrfPos), encoder position (GT_GetEncPos), the whole GT raw image
(outputs 607Ah/6040h and inputs 6041h/6064h/60FDh... of every slave) and, at the end, the
drives' mechanics.  The scenarios move axes in Trap with smoothing, change targets while
moving, stop smoothly and abruptly, run into limit switches and soft limits, set bands and
following-error limits and write raw output bytes: each forces axes out of the bank and
back, which is where a difference would show.
"""

from __future__ import annotations

import os
import shutil
from ctypes import byref, c_double, c_long, c_short, c_ubyte, c_ulong
from pathlib import Path

import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from gtecat import faults, gt
from gtecat.controller.bank import AxisBank
from gtecat.controller.motion.jog import JogPlanner
from tests.conftest import examples

ROOT = Path(__file__).resolve().parents[3]
ENI = ROOT / "examples" / "twelve_axes.eni"
AXES = 12

MACHINE = {
    "axis": {
        "2": {"positive_limit": 60_000, "negative_limit": -60_000},
        "5": {"home_switch": [[2000, 4000], [9000, 9500]]},
        "7": {"following_error_window": 50},
        "10": {"positive_limit": 25_000},
        # touch probe edges (GT_SetTouchProbeFunction): probe inputs and index pulses
        "3": {"probe1": [[1000, 1500], [6000, 6040]], "index_offset": 250},
        "8": {"probe2": [[-3000, 3000]], "index_offset": -75, "counts_per_rev": 1000},
    }
}


def _machine_file(tmp: Path) -> str:
    lines = []
    for axis, keys in MACHINE["axis"].items():
        lines.append(f"[axis.{axis}]")
        for k, v in keys.items():
            lines.append(f"{k} = {v}")
    path = tmp / "machine.toml"
    path.write_text("\n".join(lines) + "\n")
    return str(path)


def _ok(rc: int, what: str) -> None:
    assert rc == 0, f"{what}: {rc} {gt.GTE_GetLastError()}"


def open_bus(eni: str, machine: str, bank: str) -> None:
    """The bank tests' bus: GT_Open in lockstep with ``bank``, brought to OP and started."""
    gt.GT_Close()
    _ok(gt.GT_Open(eni=eni, machine=machine, clock="lockstep", log="", bank=bank), "open")
    _ok(gt.GT_InitEcatComm(), "init")
    ready = c_short()
    for _ in range(200):
        gt.GT_IsEcatReady(byref(ready))
        if ready.value:
            break
        gt.GTE_Wait(1)
    _ok(gt.GT_StartEcatComm(), "start")


def _bring_up(machine: str, bank: str) -> None:
    open_bus(str(ENI), machine, bank)
    for a in range(1, AXES + 1):
        _ok(gt.GT_AxisOn(a), f"axis on {a}")
        _ok(gt.GT_PrfTrap(a), "trap")


def _sample(raw_size: int) -> tuple:
    sts = (c_long * AXES)()
    prf = (c_double * AXES)()
    axp = (c_double * AXES)()
    enc = (c_double * 8)()
    enc2 = (c_double * 4)()
    gt.GT_GetSts(1, sts, AXES)
    gt.GT_GetPrfPos(1, prf, AXES)
    gt.GT_GetAxisPrfPos(1, axp, AXES)
    gt.GT_GetEncPos(1, enc, 8)
    gt.GT_GetEncPos(9, enc2, 4)
    pv = (c_double * AXES)()
    gt.GT_GetPrfVel(1, pv, AXES)
    ev = (c_double * 8)()
    gt.GT_GetEncVel(1, ev, 8)
    # (the encoder's acceleration and the axis's encoder position through its link)
    ea, ae = (c_double * AXES)(), (c_double * AXES)()
    gt.GT_GetAxisEncAcc(1, ea, AXES)
    gt.GT_GetAxisEncPos(1, ae, AXES)
    raw = (c_ubyte * raw_size)()
    gt.GT_GetEcatRawData(0, raw_size, raw)
    one = c_long()
    gt.GT_GetSts(3, byref(one))  # the byref form too
    vel = (tuple(pv), tuple(ev), tuple(ea), tuple(ae))
    return (tuple(sts), tuple(prf), tuple(axp), tuple(enc), tuple(enc2), vel, bytes(raw), one.value)


def _act(action: tuple) -> int:
    kind = action[0]
    if kind == "move":
        _, axis, target, vel, acc, dec, vs, smooth = action
        prm = gt.TTrapPrm()
        prm.acc, prm.dec, prm.velStart, prm.smoothTime = acc, dec, vs, smooth
        gt.GT_SetTrapPrm(axis, byref(prm))
        gt.GT_SetPos(axis, target)
        gt.GT_SetVel(axis, vel)
        return gt.GT_Update(1 << (axis - 1))
    if kind == "jog":
        _, axis, vel, acc, dec, smooth = action
        gt.GT_PrfJog(axis)
        prm = gt.TJogPrm()
        prm.acc, prm.dec, prm.smooth = acc, dec, smooth
        gt.GT_SetJogPrm(axis, byref(prm))
        gt.GT_SetVel(axis, vel)
        return gt.GT_Update(1 << (axis - 1))
    if kind == "trap":
        return gt.GT_PrfTrap(action[1])
    if kind == "retarget":
        _, axis, target, vel = action
        gt.GT_SetPos(axis, target)
        gt.GT_SetVel(axis, vel)
        return gt.GT_Update(1 << (axis - 1))
    if kind == "stop":
        _, mask, option = action
        return gt.GT_Stop(mask, option)
    if kind == "soft":
        _, axis, pos, neg = action
        return gt.GT_SetSoftLimit(axis, pos, neg)
    if kind == "band":
        _, axis, band, time = action
        return gt.GT_SetAxisBand(axis, band, time)
    if kind == "poserr":
        _, axis, err = action
        return gt.GT_SetPosErr(axis, err)
    if kind == "clear":
        return gt.GT_ClrSts(1, AXES)
    if kind == "clear_span":  # the axes of the span go back, the others stay in the bank
        _, first, count = action
        return gt.GT_ClrSts(first, min(count, AXES + 1 - first))
    if kind == "sdo":  # an SDO to one slave: its axes go back, the others stay
        _, slave, index = action
        data, size, abort = (c_ubyte * 8)(), c_ulong(), c_ulong()
        rc = gt.GT_EcatSDOUpload(slave, index, 0, data, 8, byref(size), byref(abort))
        return hash((rc, bytes(data)[: size.value], abort.value))
    if kind == "on":
        return gt.GT_AxisOn(action[1])
    if kind == "off":
        return gt.GT_AxisOff(action[1])
    if kind == "probe":  # the drive latches in the bank's cycles? it gives the axis back first
        return gt.GT_SetTouchProbeFunction(action[1], action[2])
    if kind == "kernel":  # the compiled cycle's build ends now (no GT call)
        KERNEL_BUILT[0] = True
        bank = gt.GTE_Controller().bank
        KERNEL_BUILT.append(bank.rows_run if bank is not None else 0)
        return 0
    if kind == "raw":
        _, offset, value = action
        return gt.GT_SetEcatRawData(offset, 1, (c_ubyte * 1)(value))
    if kind == "raw4":  # a 32-bit value (607Ah's size) little-endian
        _, offset, value = action
        return gt.GT_SetEcatRawData(
            offset, 4, (c_ubyte * 4)(*(value & 0xFFFFFFFF).to_bytes(4, "little"))
        )
    if kind == "unplug":  # the cable in front of a slave pulled (GTE_UnplugSlave)
        return gt.GTE_UnplugSlave(action[1])
    if kind == "quick_stop":  # the drive's quick-stop input (a fault), or all faults cleared
        if action[1]:
            return faults.inject("quick_stop", axis=action[1])
        return faults.clear()
    raise AssertionError(kind)


def _run(
    actions: list[tuple[int, tuple]],
    machine: str,
    bank: str,
    kernel: str = "c",
    chunked: bool = False,
) -> tuple[list, list, int]:
    """The program's trace; ``kernel``: the bank's plain cycle compiled ("c") or numpy;
    ``chunked``: each wait in one GTE_Wait, sampled at its end only (the clock may run
    its cycles many at a time)."""
    old = os.environ.get("GTECAT_BANK_KERNEL")
    os.environ["GTECAT_BANK_KERNEL"] = kernel
    try:
        _bring_up(machine, bank)
    finally:
        if old is None:
            del os.environ["GTECAT_BANK_KERNEL"]
        else:
            os.environ["GTECAT_BANK_KERNEL"] = old
    ctl = gt.GTE_Controller()
    size = ctl.layout.gt_raw_bytes
    trace, codes = [], []
    try:
        for wait, action in actions:
            codes.append(_act(action))
            if chunked:
                gt.GTE_Wait(wait)
                trace.append(_sample(size))
                continue
            for _ in range(wait):
                gt.GTE_Wait(1)
                trace.append(_sample(size))
        rows = ctl.bank.rows_run if ctl.bank is not None else 0
        MANY_CYCLES.append(ctl.bank.many_cycles if ctl.bank is not None else 0)
        if ctl.bank is not None and kernel == "c":
            if ctl.bank.kernel is None and not HAS_CC:
                KERNEL_CYCLES.append(-1)  # numpy alone ran: the callers skip their C check
            else:
                assert ctl.bank.kernel is not None, ctl.bank.kernel_reason
                KERNEL_CYCLES.append(ctl.bank.kernel_cycles)
        elif ctl.bank is not None and kernel == "numpy":
            assert ctl.bank.kernel_cycles == 0
        elif ctl.bank is not None:
            KERNEL_CYCLES.append(ctl.bank.kernel_cycles)
        mech = [
            (ch.mech.pos, ch.mech.vel, ch.statusword)
            for s in ctl.backend.slaves
            for ch in getattr(s, "channels", [])
        ]
        trace.append(tuple(mech))
    finally:
        gt.GT_Close()
    return trace, codes, rows


KERNEL_CYCLES: list[int] = []  # cycles the compiled kernel ran, per "c" run
#: the "kernel" action: the build the bank waits for has ended; the bank's rows run by then
KERNEL_BUILT: list = [False]
MANY_CYCLES: list[int] = []  # cycles the kernel ran many at a time, per run
HAS_CC = bool(os.environ.get("CC") or any(shutil.which(c) for c in ("cc", "gcc", "clang")))


def _kernel_ran(cycles: int) -> None:
    if cycles < 0:
        pytest.skip("no C compiler: the bank's compiled cycle was not built (numpy checked)")
    assert cycles > 300  # most of the bank's cycles were the compiled one


axis = st.integers(1, AXES)
move = st.tuples(
    st.just("move"),
    axis,
    st.integers(-80_000, 80_000),
    st.floats(0.5, 80.0),
    st.floats(0.05, 5.0),
    st.floats(0.0, 5.0),
    st.sampled_from([0.0, 0.0, 1.0, 3.0]),
    st.sampled_from([0, 0, 5, 25, 50]),
)
jog = st.tuples(
    st.just("jog"),
    axis,
    st.floats(-40.0, 40.0),
    st.floats(0.05, 5.0),
    st.floats(0.0, 5.0),
    st.sampled_from([0.0, 0.0, 0.5, 0.9]),
)
#: 60B8h patterns: probe 1 on its input (rising and falling, continuous), on the index pulse,
#: both probes (probe 2 on its input, first event only), off
PROBES = [0x33, 0x17, 0x3117, 0]
action = st.one_of(
    move,
    move,
    move,
    jog,
    st.tuples(st.just("trap"), axis),
    st.tuples(st.just("retarget"), axis, st.integers(-80_000, 80_000), st.floats(0.5, 80.0)),
    st.tuples(st.just("stop"), st.integers(1, (1 << AXES) - 1), st.integers(0, (1 << AXES) - 1)),
    st.tuples(st.just("soft"), axis, st.integers(0, 60_000), st.integers(-60_000, -1)),
    st.tuples(st.just("band"), axis, st.integers(0, 50), st.integers(0, 20)),
    st.tuples(st.just("poserr"), axis, st.integers(1, 200)),
    st.tuples(st.just("clear")),
    st.tuples(st.just("clear_span"), axis, st.integers(1, 3)),
    st.tuples(st.just("sdo"), st.integers(0, 7), st.sampled_from([0x6064, 0x6041, 0x603F, 0x1001])),
    st.tuples(st.just("on"), axis),
    st.tuples(st.just("raw"), st.integers(0, 40), st.integers(0, 255)),
    # 60B8h: probe 1 on its input (both edges, continuous), on the index, probe 2 too, off
    st.tuples(st.just("probe"), st.sampled_from([3, 8, 3, 8, 5]), st.sampled_from(PROBES)),
)
program = st.lists(st.tuples(st.integers(0, 80), action), min_size=1, max_size=10)


@settings(
    max_examples=examples(12, 3),
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)
@given(actions=program)
# a raw write to a claimed drive's controlword just before the bank takes more rows: the new
# look at the rows' output bytes gives that drive back first (it decodes what the image holds)
@example(actions=[(1, ("raw", 0, 0)), (0, ("clear",)), (0, ("clear",))])
# a moving axis switched off: given back with its Trap table, it is none of the numpy cycle's
# tables to fill (an outside fuzz's -7 "internal error" with the numpy cycle)
# a raw write of a claimed drive's 607Ah, then its cable pulled: the drive given back runs
# on the 607Ah it last received (the bank's), not on the raw value it never received
@example(actions=[(2, ("soft", 11, 17649, -12482)), (0, ("raw4", 269, 30039)), (3, ("unplug", 2))])
# a raw 607Ah write to an axis switched off (a frozen row): the next cycle writes 607Ah over it,
# as the scalar axis does every cycle
@example(actions=[(0, ("off", 11)), (0, ("probe", 3, 12567)), (3, ("raw4", 269, 18101))])
# the quick-stop input of a moving drive: it ramps down in quick stop active while the
# controller sends "quick stop", then switch on disabled (controlword 0); input released, on
@example(
    actions=[
        (30, ("move", 4, 60_000, 40.0, 2.0, 2.0, 0.0, 0)),
        (20, ("quick_stop", 4)),
        (0, ("quick_stop", 0)),
        (0, ("on", 4)),
    ]
)
@example(
    actions=[
        (0, ("move", 7, 1725, 14.0, 2.42, 1.89, 1.0, 25)),
        (0, ("move", 5, -9529, 39.46, 2.86, 0.356, 0.0, 5)),
        (1, ("off", 5)),
    ]
)
def test_bank_matches_the_scalar_path_cycle_by_cycle(tmp_path: Path, actions) -> None:
    """The scalar reference, the bank with its compiled cycle and the bank with numpy alone."""
    machine = _machine_file(tmp_path)
    actions = [*actions, (150, ("clear",))]
    ref, ref_codes, ref_rows = _run(actions, machine, "off")
    assert ref_rows == 0
    for kernel in ("c", "numpy"):
        got, got_codes, _ = _run(actions, machine, "on", kernel)
        assert got_codes == ref_codes, kernel
        for k, (a, b) in enumerate(zip(ref, got, strict=True)):
            assert a == b, f"cycle {k}: the bank ({kernel}) and the scalar path differ"


@pytest.mark.long
def test_the_bank_runs_a_moving_twelve_axis_bus(tmp_path: Path) -> None:
    """Without this the differential test could pass with the bank never engaged."""
    machine = _machine_file(tmp_path)
    moves = [
        (0, ("move", a, (-1) ** a * 40_000, 20.0 + a, 0.5, 0.5, 0.0, 25)) for a in range(1, 13)
    ]
    actions = [*moves, (400, ("band", 1, 10, 4))]
    ref, _, _ = _run(actions, machine, "off")
    KERNEL_CYCLES.clear()
    got, _, rows = _run(actions, machine, "on")
    assert rows > 12 * 300  # most axis-cycles ran in the bank
    assert got == ref
    got, _, rows = _run(actions, machine, "on", "numpy")
    assert rows > 12 * 300
    assert got == ref
    _kernel_ran(KERNEL_CYCLES[0])


def test_a_kernel_built_meanwhile_is_taken_mid_move_bit_for_bit(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A first run on a machine does not wait for the compiled cycle's build: the bank runs
    numpy, then at the first cycle after the build ends gives every axis back and claims
    them again for the compiled cycle - mid-move, with no GT call - and the trace stays the
    scalar path's."""
    from gtecat.controller import bank as bank_mod
    from gtecat.controller import bank_kernel

    lib, reason = bank_kernel.library()
    if lib is None:
        pytest.skip(f"the compiled cycle did not build here: {reason}")
    machine = _machine_file(tmp_path)
    moves = [
        (0, ("move", a, (-1) ** a * 30_000, 15.0 + a, 0.5, 0.4, 0.0, (0, 5, 25)[a % 3]))
        for a in range(1, 13)
    ]
    actions = [*moves[:-1], (60, moves[-1][1]), (150, ("kernel",)), (60, ("stop", 0b11, 0))]
    ref, ref_codes, _ = _run(actions, machine, "off")
    KERNEL_BUILT[:] = [False]
    monkeypatch.setattr(
        bank_mod, "kernel_library", lambda wait=True: (lib, "") if KERNEL_BUILT[0] else (None, "")
    )
    monkeypatch.setattr(bank_mod, "kernel_settled", lambda: KERNEL_BUILT[0])
    KERNEL_CYCLES.clear()
    got, codes, rows = _run(actions, machine, "on", "auto")
    assert codes == ref_codes
    for k, (a, b) in enumerate(zip(ref, got, strict=True)):
        assert a == b, f"cycle {k}: the bank and the scalar path differ"
    assert KERNEL_BUILT[1] > 12 * 40  # numpy ran the moves before
    assert rows > 12 * 200 and 100 < KERNEL_CYCLES[0] < 210  # and the kernel after


@pytest.mark.long
def test_cycles_run_many_at_once_are_the_cycles_one_by_one(tmp_path: Path) -> None:
    """Long waits with nothing else to do run many cycles per call of the kernel, which fills
    its short Trap tables itself; moves that end, a stop, a new target, a band, a limit
    switch and a raw write interrupt them.  The results are the scalar path's."""
    machine = _machine_file(tmp_path)
    moves = [
        (0, ("move", a, (-1) ** a * 30_000, 15.0 + a, 0.5, 0.4, 0.0, (0, 5, 25)[a % 3]))
        for a in range(1, 13)
    ]
    actions = [
        *moves,
        (333, ("band", 4, 10, 4)),
        (101, ("retarget", 6, 2_000, 30.0)),
        (250, ("stop", 0b1001, 0b1000)),
        (97, ("move", 2, 70_000, 60.0, 2.0, 2.0, 0.0, 5)),  # runs into its +60000 limit
        (1200, ("raw", 3, 7)),
        (150, ("clear",)),
    ]
    ref, ref_codes, _ = _run(actions, machine, "off", chunked=True)
    KERNEL_CYCLES.clear()
    MANY_CYCLES.clear()
    got, codes, _ = _run(actions, machine, "on", chunked=True)
    assert codes == ref_codes
    for k, (a, b) in enumerate(zip(ref, got, strict=True)):
        assert a == b, f"sample {k}: the bank and the scalar path differ"
    _kernel_ran(KERNEL_CYCLES[0])
    assert MANY_CYCLES[0] > 300  # the waits before the limit ran many cycles at a time


@pytest.mark.long
def test_the_bank_runs_jogging_axes(tmp_path: Path) -> None:
    machine = _machine_file(tmp_path)
    jogs = [
        (0, ("jog", a, (-1) ** a * (3.0 + a), 0.2, 0.3, (0.0, 0.5, 0.9)[a % 3])) for a in (1, 3, 4)
    ]
    actions = [*jogs, (300, ("jog", 3, -2.0, 0.2, 0.3, 0.5)), (200, ("stop", 0b1101, 0))]
    actions.append((100, ("clear",)))
    ref, _, _ = _run(actions, machine, "off")
    KERNEL_CYCLES.clear()
    got, _, rows = _run(actions, machine, "on")
    assert rows > 3 * 300
    assert got == ref
    _kernel_ran(KERNEL_CYCLES[0])


def test_jog_ramps_and_reversals_run_in_the_bank(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Jogs that spend their time ramping (slow acceleration, a reversal, smoothing or not):
    the compiled cycle and numpy alone against the scalar path, cycle by cycle, and the
    bank's runs step the jogs themselves (the scalar planner only on the cycles of a call)."""
    machine = _machine_file(tmp_path)
    steps = [0]
    step = JogPlanner.step

    def counted(self: JogPlanner) -> tuple[float, float, float]:
        steps[0] += 1
        return step(self)

    monkeypatch.setattr(JogPlanner, "step", counted)
    actions = [
        (0, ("jog", 1, 3.0, 0.05, 0.08, 0.0)),
        (0, ("jog", 3, -2.5, 0.04, 0.1, 0.5)),
        (60, ("jog", 4, 1.5, 0.03, 0.03, 0.9)),
        (80, ("jog", 1, -2.0, 0.05, 0.08, 0.0)),  # a reversal: braking, then accelerating
        (90, ("jog", 3, -1.0, 0.04, 0.1, 0.5)),  # down to a lower speed
        (40, ("clear",)),
    ]
    ref, _, _ = _run(actions, machine, "off")
    scalar = steps[0]
    assert scalar > 600
    for kernel in ("c", "numpy"):
        steps[0] = 0
        got, _, _ = _run(actions, machine, "on", kernel)
        for k, (a, b) in enumerate(zip(ref, got, strict=True)):
            assert a == b, f"cycle {k}: the bank ({kernel}) and the scalar path differ"
        assert steps[0] < scalar // 10, kernel


def test_an_axis_standing_with_a_latched_flag_runs_in_the_bank(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """An axis stopped by its soft limit, the limit then moved away (the flag stays latched
    until GT_ClrSts): the bank runs it standing, its GT_GetSts word with the flag, cycle by
    cycle as the scalar path."""
    machine = _machine_file(tmp_path)
    taken = [0]
    standing = AxisBank._latched_standing

    def counted(ax: object, res: object) -> bool:
        ok = standing(ax, res)
        taken[0] += ok
        return ok

    monkeypatch.setattr(AxisBank, "_latched_standing", staticmethod(counted))
    actions = [
        (0, ("soft", 3, 2000, -60_000)),
        (200, ("move", 3, 20_000, 20.0, 1.0, 1.0, 0.0, 0)),
        (120, ("soft", 3, 60_000, -60_000)),  # the cause is gone, the flag stays
        (60, ("clear",)),
    ]
    ref, ref_codes, _ = _run(actions, machine, "off")
    assert any(sample[0][2] & 0x20 for sample in ref[200:320])  # bit 5 latched
    for kernel in ("c", "numpy"):
        taken[0] = 0
        got, codes, _ = _run(actions, machine, "on", kernel)
        assert codes == ref_codes
        for k, (a, b) in enumerate(zip(ref, got, strict=True)):
            assert a == b, f"cycle {k}: the bank ({kernel}) and the scalar path differ"
        assert taken[0] >= 1, kernel


def test_gt_calls_release_and_the_bank_claims_again(tmp_path: Path) -> None:
    machine = _machine_file(tmp_path)
    _bring_up(machine, "on")
    try:
        ctl = gt.GTE_Controller()
        gt.GTE_Wait(40)
        bank = ctl.bank
        assert bank.n_alive == AXES
        gt.GT_ClrSts(3)  # nothing to clear: the axis stays in the bank
        assert bank.n_alive == AXES
        lo, hi = c_long(), c_long()
        assert gt.GT_GetSoftLimit(3, byref(hi), byref(lo)) == 0
        assert bank.n_alive == AXES - 1  # names one axis: its slave's rows leave, the others stay
        gt.GTE_Wait(2)
        assert bank.n_alive == AXES
        # a Trap move's start runs on its axis's row in place: no drive leaves
        steps = bank.steps_in_place
        assert gt.GT_SetVel(3, 5.0) == 0  # (the profile's speed alone: the row as it stands)
        assert gt.GT_SetPos(3, 2000) == 0
        assert bank.n_alive == AXES and bank.steps_in_place == steps
        assert gt.GT_Update(1 << 2) == 0
        assert bank.n_alive == AXES and bank.steps_in_place == steps + 1
        assert bank.moving[bank._row_of[id(ctl.axes[3])]]
        # the field side touching a drive gives its slave back too
        ch = ctl.backend.slaves[0].channels[0]
        pos = ch.machine_position
        assert bank.n_alive == AXES - 1
        assert pos == ch.mech.pos
    finally:
        gt.GT_Close()


@pytest.mark.parametrize("mode", ["auto", "on", "off"])
def test_bank_modes_open(mode: str, tmp_path: Path) -> None:
    _bring_up(_machine_file(tmp_path), mode)
    try:
        bank = gt.GTE_Controller().bank
        assert (bank is None) == (mode == "off")
    finally:
        gt.GT_Close()


def test_unknown_bank_mode_is_refused() -> None:
    gt.GT_Close()
    assert gt.GT_Open(eni=str(ENI), clock="lockstep", log="", bank="fast") != 0
    assert "bank" in gt.GTE_GetLastError()
    gt.GT_Close()


def test_armed_touch_probes_run_in_the_bank(tmp_path: Path) -> None:
    """Axes 3 and 8 move with their drives' touch probes armed (GT_SetTouchProbeFunction) over
    probe windows and index pulses, both directions, continuous and first-event latches: the
    bank runs them between the edges and gives each back before a cycle that latches one
    (60B9h/60BAh are in the raw image compared every cycle), compiled and numpy (long waits
    with armed probes: test_bank_smart_home's index homings)."""
    machine = _machine_file(tmp_path)
    actions = [
        (1, ("probe", 3, 0x33)),
        (1, ("probe", 8, 0x3117)),
        (0, ("move", 3, 7_000, 40.0, 1.0, 1.0, 0.0, 0)),
        (120, ("move", 8, -4_000, 25.0, 1.0, 1.0, 0.0, 25)),
        (200, ("probe", 3, 0x17)),
        (0, ("move", 3, -500, 60.0, 2.0, 2.0, 0.0, 5)),
        (200, ("clear",)),
    ]
    ref, ref_codes, _ = _run(actions, machine, "off")
    cycles = len(ref) - 1
    for kernel in ("c", "numpy"):
        got, codes, rows = _run(actions, machine, "on", kernel)
        assert codes == ref_codes
        for k, (x, y) in enumerate(zip(ref, got, strict=True)):
            assert x == y, f"cycle {k}: the bank ({kernel}) and the scalar path differ"
        # the probe axes ran in the bank (axis 8 shares its drive with axes 5-7)
        assert rows > 0.9 * AXES * cycles, (kernel, rows, cycles)


def test_one_row_given_back_in_floats_is_the_numpy_one(tmp_path: Path) -> None:
    """A release of one row computes its drive's process values in Python floats
    (CspBank._one_row); the numpy operations of every other release (_row_outputs) give the
    same integers, halves, negative zeros and the switch windows included, and the values
    numpy converts otherwise (not a number, beyond 2**62) go to numpy."""
    import math
    import random

    import numpy as np

    _bring_up(_machine_file(tmp_path), "on")
    try:
        gt.GTE_Wait(5)
        csp = gt.GTE_Controller().bank.csp
        rnd = random.Random(7)
        values = [0.5, -0.5, 1.5, 2.5, -2.5, -0.0, 0.0, 1e6 + 0.5, 2999.5, 3000.0, 9000.0]
        checked = 0
        for k in range(400):
            r = rnd.randrange(csp.n)
            for name in ("pos", "dpos", "vel", "acc"):
                v = rnd.choice(values) if k % 2 else rnd.uniform(-1e5, 1e5)
                getattr(csp, name)[r] = v
            csp.limited[r], csp.sw_limited[r] = rnd.random() < 0.3, rnd.random() < 0.2
            one = csp._one_row(r)
            ref = csp._row_outputs(np.asarray([r], np.intp))
            assert one is not None
            assert one == {name: int(v[0]) for name, v in ref.items()}, (r, k)
            checked += 1
        for bad in (math.nan, math.inf, 2.0**63):
            csp.pos[0] = bad
            assert csp._one_row(0) is None
        csp.pos[0] = 0.0  # (the release at the close converts it)
        assert checked == 400
    finally:
        gt.GT_Close()
