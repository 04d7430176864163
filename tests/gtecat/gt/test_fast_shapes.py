"""Every call shape of the fast path answers as the table path does, and takes the fast path.

The shapes a client uses for the polled readers (``GT_GetSts(1, byref(s), 1, 0)`` with 0 or
None as NULL, a reused or a fresh ``byref``, the ctypes object itself, a ctypes or numpy
array, ``GTN_`` with core 1) and for the raw image (``GT_Get/SetEcatRawData``,
``GT_EcatIOReadInput/WriteOutput`` with ctypes arrays, bytearrays, numpy byte arrays,
memoryviews, bytes) are called through the public function and through its table path
(``.slow``): return code, the memory written and GTE_GetLastError agree.  A profiler (not a
clock) shows that neither the table path nor the fast path's general way (the shapes it
checks one by one) ran for them: each is answered by its compiled common path.  The
homing status, the Trap parameters and the core reader are held to their table paths the
same way, in each state that changes their answer.  Every function of the table that takes a
pointer is on the fast path, declared only, or has a recorded reason.  The default run
samples the shapes; GTECAT_LONG=1 runs them all.
"""

from __future__ import annotations

import copy
import cProfile
import ctypes
import pstats
import random
from ctypes import byref
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from gtecat import gt
from gtecat.controller.axis import Axis
from gtecat.controller.axis_status import AxisStatus
from gtecat.controller.epoch import changed
from gtecat.controller.motion.trap import TrapPlanner
from gtecat.gt import fast
from gtecat.gt.table import FUNCTIONS, declared_only
from tests.conftest import EXAMPLES, LONG

from .profiled import table_calls

ENI = Path(__file__).resolve().parents[3] / "examples" / "manual_fig5_2.eni"


def _open(**options: str) -> object:
    """Figure 5-2's bus in OP with axis 1 on (the directory's fixture closes it after)."""
    assert gt.GT_Open(eni=str(ENI), clock="lockstep", log="", **options) == 0
    assert gt.GT_InitEcatComm() == 0
    gt.GTE_Wait(60)
    assert gt.GT_StartEcatComm() == 0
    assert gt.GT_AxisOn(1) == 0
    gt.GTE_Wait(5)
    return gt.GTE_Controller()


_HELD = ctypes.c_long()
_HELD_REF = byref(_HELD)
READER_SHAPES = {
    "byref": lambda t: (o := t(), (byref(o),), o),
    "same_byref": lambda t: ((_HELD_REF,), _HELD),
    "count_null0": lambda t: (o := t(), (byref(o), 1, 0), o),
    "count_none": lambda t: (o := t(), (byref(o), 1, None), o),
    "obj": lambda t: (o := t(), (o,), o),
    "array": lambda t: (o := (t * 2)(), (o,), o),
    "numpy": lambda t: (
        o := np.zeros(2, np.float64 if t is ctypes.c_double else np.int32),
        (o,),
        o,
    ),
}
RAW_SHAPES = {
    "ctypes": lambda n: (o := (ctypes.c_ubyte * n)(), o),
    "bytearray": lambda n: (o := bytearray(n), o),
    "numpy": lambda n: (o := np.zeros(n, np.uint8), o),
    "memoryview": lambda n: (o := bytearray(n), memoryview(o)),
    "byref_ctypes": lambda n: (o := (ctypes.c_ubyte * n)(), byref(o)),
}


def _value(o):
    if isinstance(o, ctypes.Array):
        return list(o)
    if isinstance(o, np.ndarray | bytearray):
        return bytes(o) if isinstance(o, bytearray) else o.tolist()
    return o.value


def _cases() -> list[tuple[str, str]]:
    cases = [(n, s) for n in sorted(fast.READERS) for s in READER_SHAPES]
    cases += [(n, s) for n in sorted(fast.RAW) for s in RAW_SHAPES]
    cases += [(n, "gtn") for n in sorted(fast.READERS)]
    if LONG:
        return cases
    rnd = random.Random(30)
    return sorted(rnd.sample(cases, 24))


def _call(name: str, shape: str, which: str) -> tuple:
    """One call of ``name`` in ``shape`` through the public function (``fast``) or its table
    path (``slow``): (return code, what it wrote, last error, calls of the table path)."""
    fn = getattr(gt, name)
    call = fn if which == "fast" else fn.slow
    if name in fast.READERS:
        t = ctypes.c_double if ctypes.c_double in fast.READERS[name][1] else ctypes.c_long
        if shape == "gtn":
            o = t()
            if which == "fast":
                call, args = getattr(gt, "GTN_" + name[3:]), (1, 1, byref(o))
            else:
                args = (1, byref(o))
        else:
            made = READER_SHAPES[shape](t)
            if len(made) == 2:
                extra, o = made
            else:
                _, extra, o = made
            args = (1, *extra)
    else:
        o, buf = RAW_SHAPES[shape](4)
        if "Set" in name or "Write" in name:
            o[0], o[1] = 0x0F, 0x01
        io = name in ("GT_EcatIOReadInput", "GT_EcatIOWriteOutput")
        args = (2, 0, 2 if "Write" in name else 4, buf) if io else (0, 4, buf)
    pr = cProfile.Profile()
    pr.enable()
    rc = call(*args)
    pr.disable()
    # the table path, or the fast path's own second way (the shapes it checks one by one)
    table = table_calls(pr, ("general", "gtn_general", "run"))
    return rc, _value(o), gt.GTE_GetLastError() if rc else "", table


def test_every_shape_answers_as_the_table_and_takes_the_fast_path() -> None:
    ctl = _open()
    bad = []
    for name, shape in _cases():
        if shape == "same_byref" and ctypes.c_double in fast.READERS.get(name, ((), ()))[1]:
            continue  # the held pointer object is a c_long
        rc, value, error, table = _call(name, shape, "fast")
        image = bytes(ctl.master.image.buffer)
        slow = _call(name, shape, "slow")
        if (rc, value, error) != slow[:3] or image != bytes(ctl.master.image.buffer):
            bad.append(f"{name} {shape}: {(rc, value, error)} != {slow[:3]}")
        elif rc != 0 or table:
            bad.append(f"{name} {shape}: rc {rc}, the table or general path ran {table} time(s)")
    assert not bad, "\n".join(bad)


@pytest.mark.parametrize(
    "args",
    [(-1, 4), (0, 0), (0, 10_000), (38, 4)],
    ids=["negative", "empty", "past the end", "into inputs"],
)
def test_raw_edges_answer_as_the_table(args: tuple[int, int]) -> None:
    _open()
    for name in ("GT_GetEcatRawData", "GT_SetEcatRawData"):
        fn = getattr(gt, name)
        got = []
        for call in (fn, fn.slow):
            buf = bytearray(8)
            rc = call(*args, buf)
            got.append((rc, bytes(buf), gt.GTE_GetLastError() if rc else ""))
        assert got[0] == got[1], name


def test_byref_of_a_raw_array_answers_as_the_table_on_the_fast_path() -> None:
    """``GT_GetEcatRawData(0, 4, byref(arr))``: the array's own fast path; ``byref(arr, 1)``
    and a too small array: the table path, with its answer."""
    ctl = _open()
    bad = []
    for name in sorted(fast.RAW):
        rc, value, error, table = _call(name, "byref_ctypes", "fast")
        image = bytes(ctl.master.image.buffer)
        slow = _call(name, "byref_ctypes", "slow")
        if (rc, value, error) != slow[:3] or image != bytes(ctl.master.image.buffer):
            bad.append(f"{name}: {(rc, value, error)} != {slow[:3]}")
        elif rc != 0 or table:
            bad.append(f"{name}: rc {rc}, the table or general path ran {table} time(s)")
    for make in (lambda: byref((ctypes.c_ubyte * 8)(), 1), lambda: byref((ctypes.c_ubyte * 2)())):
        got = []
        for call in (gt.GT_GetEcatRawData, gt.GT_GetEcatRawData.slow):
            p = make()
            got.append((call(0, 4, p), bytes(p._obj), gt.GTE_GetLastError()))
        if got[0] != got[1]:
            bad.append(f"{got[0]} != {got[1]}")
    assert not bad, "\n".join(bad)


def test_too_small_buffers_take_the_table_path() -> None:
    _open()
    for buf in (bytearray(2), (ctypes.c_ubyte * 2)(), np.zeros(2, np.uint8)):
        got = [
            (call(0, 4, buf), gt.GTE_GetLastError())
            for call in (gt.GT_GetEcatRawData, gt.GT_GetEcatRawData.slow)
        ]
        assert got[0] == got[1] and got[0][0] != 0


def test_every_pointer_function_is_fast_declared_or_has_a_reason() -> None:
    declared = set(declared_only())
    quick = fast.fast_functions()
    missing = []
    for name, proto in FUNCTIONS.items():
        if not any(p.pointer for p in proto.params) or name in quick or name in declared:
            continue
        if not fast.SLOW_REASONS.get(proto.group, "").strip():
            missing.append(f"{name} ({proto.group})")
    assert not missing, "on the table path without a recorded reason: " + ", ".join(missing)
    assert quick <= set(FUNCTIONS)


def test_every_raw_range_reads_as_the_table() -> None:
    """Each copier (one slice, a slice per run, one gather) against the table path: every
    offset and size of figure 5-2's image (and past it), into each kind of buffer."""
    _open()
    makers = (
        bytearray,
        lambda n: (ctypes.c_ubyte * n)(),
        lambda n: np.zeros(n, np.uint8),
        lambda n: memoryview(bytearray(n)),
    )
    bad = []
    for offset in range(0, 42, 3):
        for size in range(1, 12):
            for make in makers:
                got = []
                for call in (gt.GT_GetEcatRawData, gt.GT_GetEcatRawData.slow):
                    buf = make(size)
                    rc = call(offset, size, buf)
                    got.append((rc, bytes(buf), gt.GTE_GetLastError() if rc else ""))
                if got[0] != got[1]:
                    bad.append(f"{offset} {size} {type(buf).__name__}: {got}")
    assert not bad, "\n".join(bad[:10])


def test_the_inline_status_word_is_the_resources_word() -> None:
    """GT_GetSts's word of an axis the bank does not run, read inline by the fast path, is
    :meth:`AxisResources.status`'s in every combination of what makes it."""
    ctl = _open(bank="off")  # (an axis at rest in OP goes into the bank otherwise)
    res = ctl.resources[1]
    assert res.bank is None
    kept = (res.latched, res.ax.servo_on, res.profile.planner, res.band.arrived)
    trap = res.profile.planner
    assert type(trap) is TrapPlanner and trap.done
    moving_trap = copy.copy(trap)
    moving_trap._mode = 1  # (its state moving: done is False)
    assert not moving_trap.done
    planners = [SimpleNamespace(done=False), SimpleNamespace(done=True), trap, moving_trap]
    s = ctypes.c_long()
    bad = []
    try:
        for latched in (0, 0x2, int(AxisStatus.POSITIVE_LIMIT), AxisStatus.ALARM):
            for servo in (False, True):
                for planner in planners:
                    for arrived in (False, True):
                        res.latched, res.ax.servo_on = latched, servo
                        res.profile.planner = planner
                        res.band.arrived = arrived
                        changed()  # (the state changed by hand: the kept values ask again)
                        rc = gt.GT_GetSts(1, s)
                        if rc != 0 or s.value != res.status():
                            bad.append(f"{latched, servo, planner, arrived}: {s.value}")
    finally:
        res.latched, res.ax.servo_on, res.profile.planner, res.band.arrived = kept
    assert not bad, "\n".join(bad)


def test_the_specialised_raw_entry_answers_as_the_table() -> None:
    """The raw functions specialise themselves for the latest call's shape: shapes that
    alternate, a buffer of that shape's type that cannot take the bytes (too small, read
    only, another dtype), and a bus brought up again all answer as the table path does."""
    calls = [
        (0, 8, lambda: bytearray(8)),
        (0, 8, lambda: bytearray(2)),
        (6, 4, lambda: bytearray(8)),
        (0, 8, lambda: memoryview(bytes(8))),
        (0, 8, lambda: memoryview(bytearray(8))),
        (0, 8, lambda: np.zeros(8, np.int32)),
        (0, 8, lambda: np.zeros(8, np.uint8)),
        (0, 8, lambda: np.zeros(8, np.uint8)[::2]),
        (0, 8, lambda: (ctypes.c_ubyte * 8)()),
        (0, 8, lambda: byref((ctypes.c_ubyte * 8)())),
        (0, 8, lambda: byref((ctypes.c_ubyte * 8)())),
        (0, 8, lambda: (ctypes.c_ubyte * 8)()),
        (0, 8, lambda: byref((ctypes.c_ubyte * 9)(), 1)),
        (0, 8, lambda: byref((ctypes.c_ubyte * 2)())),
        (0, 8, lambda: byref(ctypes.c_uint64())),
        (0, 8, lambda: bytearray(8)),
    ]
    carg = type(byref(ctypes.c_int()))
    bad = []
    for _ in range(2):  # the second time on a bus brought up again (another image)
        gt.GT_Close()
        _open()
        for offset, size, make in calls * 2:
            got = []
            for call in (gt.GT_GetEcatRawData, gt.GT_GetEcatRawData.slow):
                buf = make()
                rc = call(offset, size, buf)
                held = buf._obj if type(buf) is carg else buf
                got.append((rc, bytes(held), gt.GTE_GetLastError() if rc else ""))
            if got[0] != got[1]:
                bad.append(f"{offset} {size} {type(buf).__name__}: {got}")
        for data in (bytes([0x0F, 0]), bytearray([0x0F, 0]), bytes([1])):
            rcs = []
            for call in (gt.GT_SetEcatRawData, gt.GT_SetEcatRawData.slow):
                rcs.append((call(0, 2, data), gt.GTE_GetLastError() if rcs else ""))
            if rcs[0][0] != rcs[1][0]:
                bad.append(f"set {data!r}: {rcs}")
    assert not bad, "\n".join(bad)


def test_the_pdo_readers_answer_as_the_table() -> None:
    """GT_GetEcatEncPos and the other per-axis PDO readers: each shape, fast and table path
    agree (code, value, reason); a shape the fast path answers never reaches the table (on
    an axis the bank does not run at that moment: the bank's axes are the table's)."""
    ctl = _open()
    makers = {
        "byref": lambda t: (o := t(), byref(o), o),
        "same byref": lambda t: (_HELD, _HELD_REF, _HELD) if t is ctypes.c_long else None,
        "object": lambda t: (o := t(), o, o),
        "array": lambda t: (o := (t * 2)(), o, o),
        "narrow": lambda t: (o := ctypes.c_int8(), byref(o), o),
        "double": lambda t: (o := ctypes.c_double(), byref(o), o),
        "omitted": lambda t: (o := t(), None, o),
    }
    bad = []
    names = sorted(fast.ECAT_READERS)
    if not LONG:  # two mapped objects and one the figure's drives do not map
        names = ["GT_GetEcatAxisDI", "GT_GetEcatAxisPE", "GT_GetEcatEncPos"]
    for name in names:
        for axis in (1, 2, 9):
            for shape, make in makers.items():
                for t in (ctypes.c_long, ctypes.c_int32, ctypes.c_uint32):
                    got = []
                    own = type(ctl.axes.get(axis)) is Axis  # (not guarded by the bank)
                    for which in ("fast", "slow"):
                        made = make(t)
                        if made is None:
                            break
                        _, arg, o = made
                        fn = getattr(gt, name)
                        call = fn if which == "fast" else fn.slow
                        args = (axis,) if arg is None else (axis, arg)
                        pr = cProfile.Profile()
                        pr.enable()
                        rc = call(*args)
                        pr.disable()
                        table = table_calls(pr)
                        value = list(o) if isinstance(o, ctypes.Array) else o.value
                        got.append((rc, value, gt.GTE_GetLastError() if rc else "", table))
                    if got and got[0][:3] != got[1][:3]:
                        bad.append(f"{name}({axis}) {shape} {t.__name__}: {got}")
                    elif got and got[0][0] == 0 and shape in ("byref", "object") and got[0][3]:
                        if not own:
                            continue
                        bad.append(f"{name}({axis}) {shape} {t.__name__}: took the table path")
    assert not bad, "\n".join(bad[:10])


def _poll_pdo_while_moving(read: str, clock: str) -> tuple[list[tuple[int, ...]], int]:
    """A drive mapping every object the per-axis PDO readers read (6064h, 606Ch, 60F4h,
    60FDh, 60FEh, 6077h, 6078h, 603Fh) in a Trap move, each read every cycle (``read``:
    "fast", the functions, or "slow", their table path, which gives a banked axis back): the
    values, and at how many polls the axis was still banked after them."""
    assert gt.GT_Open(eni=str(EXAMPLES / "full_servo.eni"), clock=clock, log="") == 0
    assert gt.GT_InitEcatComm() == 0
    gt.GTE_Wait(200)
    assert gt.GT_StartEcatComm() == 0
    assert gt.GT_AxisOn(1) == 0
    ctl = gt.GTE_Controller()
    assert gt.GT_PrfTrap(1) == 0
    prm = gt.TTrapPrm(acc=0.5, dec=0.5, velStart=0, smoothTime=0)
    assert gt.GT_SetTrapPrm(1, byref(prm)) == 0
    assert gt.GT_SetVel(1, 40) == 0
    assert gt.GT_SetPos(1, 30_000) == 0
    assert gt.GT_Update(1) == 0
    names = sorted(fast.ECAT_READERS)
    calls = [getattr(gt, n) if read == "fast" else getattr(gt, n).slow for n in names]
    out, banked = [], 0
    v, u = ctypes.c_long(), ctypes.c_uint32()
    for _ in range(400):
        gt.GTE_Wait(1)
        row = []
        for name, call in zip(names, calls, strict=True):
            target = u if name in ("GT_GetEcatAxisDI", "GT_GetEcatAxisDO") else v
            assert call(1, byref(target)) == 0, gt.GTE_GetLastError()
            row.append(target.value)
        out.append(tuple(row))
        banked += type(ctl.axes[1]) is not Axis
    gt.GT_Close()
    return out, banked


@pytest.mark.parametrize("clock", ["lockstep", "auto"])
def test_the_pdo_readers_read_a_banked_axis_where_it_is(clock: str) -> None:
    """The per-axis PDO readers answer an axis the bank runs without giving it back (the
    table path gives it back and the bank claims it again at its next cycle: a poll loop
    then paid that at every call on the auto clock), with the values of a session whose
    every read goes through the table path (so whose axes ran on their scalar drives)."""
    fast_values, fast_banked = _poll_pdo_while_moving("fast", clock)
    slow_values, slow_banked = _poll_pdo_while_moving("slow", clock)
    assert fast_banked > 350, "the moving axis stays in the bank while polled"
    assert slow_banked < 50  # (the auto clock: a call may make a cycle due that claims it)
    assert fast_values == slow_values
    assert len(set(fast_values)) > 300  # (the axes moved: the values changed every cycle)


#: bus axes on the bus beyond 32 axes: core 2 holds bus axes 33 and 34 as its axes 1 and 2
_BEYOND = 34


def _open_beyond_32(tmp_path: Path) -> object:
    """A 34-axis bus in OP, bus axes 2, 33 and 34 moving in Trap (so the bank holds them)."""
    from tools.gen_axes_eni import write_axes_eni

    eni = write_axes_eni(_BEYOND, tmp_path / "axes34.eni")
    assert gt.GT_Open(eni=str(eni), clock="lockstep", log="") == 0, gt.GTE_GetLastError()
    assert gt.GT_InitEcatComm() == 0, gt.GTE_GetLastError()
    ready = ctypes.c_short()
    for _ in range(1000):
        if gt.GT_IsEcatReady(byref(ready)) == 0 and ready.value == 1:
            break
        gt.GTE_Wait(1)
    assert gt.GT_StartEcatComm() == 0, gt.GTE_GetLastError()
    for core, local in ((1, 2), (2, 1), (2, 2)):
        assert gt.GTN_AxisOn(core, local) == 0, gt.GTE_GetLastError()
    gt.GTE_Wait(5)
    for core, local in ((1, 2), (2, 1), (2, 2)):
        prm = gt.TTrapPrm()
        prm.acc = prm.dec = 0.5
        assert gt.GTN_PrfTrap(core, local) == 0
        assert gt.GTN_SetTrapPrm(core, local, byref(prm)) == 0
        assert gt.GTN_SetPos(core, local, 50_000_000) == 0
        assert gt.GTN_SetVel(core, local, 20) == 0
        assert gt.GTN_Update(core, 1 << (local - 1)) == 0, gt.GTE_GetLastError()
    gt.GTE_Wait(30)
    return gt.GTE_Controller()


def _gtn(name: str, shape: str, core: int, axis: int, which: str) -> tuple:
    """``GTN_x(core, axis, ...)`` in ``shape`` through the public function (``fast``) or the
    table path of the GTN_ twin (``slow``): (code, what it wrote, last error, table calls)."""
    fn = getattr(gt, "GTN_" + name[3:])
    call = fn if which == "fast" else getattr(gt, name).gtn_slow
    t = ctypes.c_double if ctypes.c_double in fast.READERS[name][1] else ctypes.c_long
    made = READER_SHAPES[shape](t)
    extra, o = made if len(made) == 2 else made[1:]
    pr = cProfile.Profile()
    pr.enable()
    rc = call(core, axis, *extra)
    pr.disable()
    table = table_calls(pr, ("gtn_general",))
    return rc, _value(o), gt.GTE_GetLastError() if rc else "", table


def test_core_2_answers_as_the_table_fast_and_leaves_the_bank(tmp_path: Path) -> None:
    """``GTN_x(2, axis, ...)`` on a bus beyond 32 axes: every shape answers as the table path
    of core 2 (and as core 1 naming the bus axis), on the fast path; an axis core 2 does not
    have answers as the table (7 and its reason); polling the axes the bank holds leaves them
    there."""
    ctl = _open_beyond_32(tmp_path)
    banked = [ctl.resources[n] for n in (2, 33, 34)]
    assert all(r.bank is not None for r in banked), "the bank holds the moving axes"
    shapes = [s for s in READER_SHAPES if s != "same_byref"]
    bad = []
    for name in sorted(fast.READERS):
        for shape in shapes:
            for axis in (1, 2):
                got = _gtn(name, shape, 2, axis, "fast")
                want = _gtn(name, shape, 2, axis, "slow")
                bus = _gtn(name, shape, 1, 32 + axis, "slow")
                if got[:3] != want[:3] or got[:3] != bus[:3]:
                    bad.append(f"{name} {shape} (2, {axis}): {got[:3]} != {want[:3]} / {bus[:3]}")
                elif got[0] != 0 or got[3]:
                    bad.append(f"{name} {shape} (2, {axis}): rc {got[0]}, table ran {got[3]}")
        # not an axis of core 2: 7 with the table's reason; 3 (bus axis 35, which no drive
        # backs) lies inside the controller's axes: the table's 0 (axis_span's rule)
        for axis in (0, 3, 33, -1):
            got, want = _gtn(name, "byref", 2, axis, "fast"), _gtn(name, "byref", 2, axis, "slow")
            if got[:3] != want[:3] or got[0] != (0 if axis == 3 else 7):
                bad.append(f"{name} (2, {axis}): {got[:3]} != {want[:3]}")
        # count axes in one call (the polling loop's array form)
        for axis, count, clock in ((1, 2, ()), (1, 2, (0,)), (2, 2, ()), (1, 40, ())):
            got, want = [], []
            for which, out in (("fast", got), ("slow", want)):
                t = ctypes.c_double if ctypes.c_double in fast.READERS[name][1] else ctypes.c_long
                arr = (t * 40)()
                fn = (
                    getattr(gt, "GTN_" + name[3:])
                    if which == "fast"
                    else getattr(gt, name).gtn_slow
                )
                pr = cProfile.Profile()
                pr.enable()
                rc = fn(2, axis, arr, count, *clock)
                pr.disable()
                stats = pstats.Stats(pr).stats.items()  # type: ignore[attr-defined]
                table = sum(v[1] for (f, _, func), v in stats if func == "call" and "_core" in f)
                out += [rc, list(arr), gt.GTE_GetLastError() if rc else "", table]
            if got[:3] != want[:3] or (axis == 1 and count == 2 and (got[0] or got[3])):
                bad.append(f"{name} (2, {axis}, arr, {count}): {got} != {want}")
    assert not bad, "\n".join(bad[:20])
    # polling, on the fast path and the table's (count, pClock), keeps them in the bank
    s = (ctypes.c_long * 2)()
    clock = ctypes.c_ulong()
    for _ in range(3):
        for local in (1, 2):
            assert gt.GTN_GetSts(2, local, byref(s)) == 0
            assert gt.GTN_GetPrfPos(2, local, byref(ctypes.c_double())) == 0
            assert gt.GTN_GetEncPos(2, local, ctypes.c_double()) == 0
        assert gt.GTN_GetSts(2, 1, s, 2, byref(clock)) == 0
        assert gt.GTN_GetSts(1, 2, byref(s)) == 0
        gt.GTE_Wait(3)
    assert all(r.bank is not None for r in banked), "polling gave an axis back"
    assert all(v & (1 << 10) for v in s)  # both still moving


def test_the_homing_status_answers_as_the_table() -> None:
    """GT_GetEcatHomingStatus on its fast path (a byref or the object, no offset, an integer
    type the pointer takes): the table path's code, value and reason before any run, while
    a run that cannot end is polled (its reason beside the 0: the table path answers), when
    a run has ended, and for an axis that does not exist; its common shapes never reach
    the table."""
    from gtecat.drives.machine import AxisMachine, MachineDescription

    from .conftest import bring_up

    bring_up(machine=MachineDescription({1: AxisMachine(), 2: AxisMachine()}), log="")
    makers = {
        "byref": lambda: (o := ctypes.c_short(), byref(o), o),
        "object": lambda: (o := ctypes.c_short(), o, o),
        "long": lambda: (o := ctypes.c_long(), byref(o), o),
        "offset": lambda: (o := (ctypes.c_short * 2)(), byref(o, 2), o),
        "narrow": lambda: (o := ctypes.c_int8(), byref(o), o),
        "unsigned": lambda: (o := ctypes.c_ushort(), byref(o), o),
    }
    fn = gt.GT_GetEcatHomingStatus
    bad = []

    def compare(when: str) -> None:
        for axis in (1, 2, 3):
            for shape, make in makers.items():
                got = []
                for call in (fn, fn.slow):
                    _, p, o = make()
                    pr = cProfile.Profile()
                    pr.enable()
                    rc = call(axis, p)
                    pr.disable()
                    table = table_calls(pr)
                    got.append((rc, _value(o), gt.GTE_GetLastError(), table))
                if got[0][:3] != got[1][:3]:
                    bad.append(f"{when} axis {axis} {shape}: {got[0][:3]} != {got[1][:3]}")
                elif axis == 2 and shape in ("byref", "object", "long") and got[0][3]:
                    bad.append(f"{when} axis {axis} {shape}: took the table path")

    compare("before any run")
    assert gt.GT_AxisOn(1) == 0 and gt.GT_SetHomingMode(1, 6) == 0
    assert gt.GT_SetEcatHomingPrm(1, 24, 50_000, 5_000, 1_000_000, 0, 0) == 0
    assert gt.GT_StartEcatHoming(1) == 0  # (a home switch the machine lacks: never ends)
    assert gt.GT_AxisOn(2) == 0 and gt.GT_SetHomingMode(2, 6) == 0
    assert gt.GT_SetEcatHomingPrm(2, 35, 50_000, 5_000, 1_000_000, 0, 0) == 0
    assert gt.GT_StartEcatHoming(2) == 0  # (the current position: ends at once)
    compare("started")
    gt.GTE_Wait(20)
    compare("later")
    assert not bad, "\n".join(bad[:10])


def test_the_trap_parameters_answer_as_the_table() -> None:
    """GT_GetTrapPrm on its fast path (``byref(s)`` or ``s`` of TTrapPrm): the table path's
    code, fields and reason for each shape, in Trap and in another mode, for an axis that
    does not exist; a banked axis stays in the bank (its Trap parameters and mode are set
    by GT calls only, which give it back first), and answers as the table path does."""
    ctl = _open()
    prm = gt.TTrapPrm(acc=0.25, dec=0.5, velStart=1.5, smoothTime=7)
    assert gt.GT_SetTrapPrm(1, byref(prm)) == 0, gt.GTE_GetLastError()
    makers = {
        "byref": lambda: (o := gt.TTrapPrm(), byref(o), o),
        "object": lambda: (o := gt.TTrapPrm(), o, o),
        "offset": lambda: (o := (gt.TTrapPrm * 2)(), byref(o, 8), o),
        "another structure": lambda: (o := gt.TJogPrm(), byref(o), o),
        "bytes": lambda: (o := (ctypes.c_ubyte * 64)(), byref(o), o),
        "too small": lambda: (o := (ctypes.c_ubyte * 8)(), byref(o), o),
        "null": lambda: (o := gt.TTrapPrm(), None, o),
    }
    fn = gt.GT_GetTrapPrm
    bad = []

    def compare(when: str) -> None:
        for axis in (1, 2, 9):
            for shape, make in makers.items():
                got = []
                for call in (fn, fn.slow):
                    _, p, o = make()
                    rc = call(axis, p)
                    got.append((rc, bytes(o), gt.GTE_GetLastError() if rc else ""))
                if got[0] != got[1]:
                    bad.append(f"{when} axis {axis} {shape}: {got[0]} != {got[1]}")

    banked = [n for n in (1, 2) if ctl.resources[n].bank is not None]
    assert banked, "an axis at rest is in the bank"
    for n in banked:  # (the fast path's call leaves it there)
        assert fn(n, gt.TTrapPrm()) == 0 and ctl.resources[n].bank is not None
    compare("trap")
    assert gt.GT_PrfJog(1) == 0, gt.GTE_GetLastError()
    compare("jog")
    s = gt.TTrapPrm()
    pr = cProfile.Profile()
    pr.enable()
    rc = fn(2, byref(s))
    pr.disable()
    table = table_calls(pr)
    assert rc == 0 and not table, "byref(TTrapPrm) took the table path"
    assert not bad, "\n".join(bad[:10])


def test_the_core_reader_answers_as_the_table() -> None:
    """GT_GetCore on its fast path: the table path's code, value and reason in each shape,
    with no controller open, on an open one, and after GT_SetCore(2)."""
    makers = {
        "byref": lambda: (o := ctypes.c_short(), byref(o), o),
        "object": lambda: (o := ctypes.c_short(), o, o),
        "long": lambda: (o := ctypes.c_long(), byref(o), o),
        "offset": lambda: (o := (ctypes.c_short * 2)(), byref(o, 2), o),
        "narrow": lambda: (o := ctypes.c_int8(), byref(o), o),
        "null": lambda: (o := ctypes.c_short(), None, o),
    }
    fn = gt.GT_GetCore
    bad = []

    def compare(when: str) -> None:
        for shape, make in makers.items():
            got = []
            for call in (fn, fn.slow):
                _, p, o = make()
                rc = call(p)
                got.append((rc, _value(o), gt.GTE_GetLastError() if rc else ""))
            if got[0] != got[1]:
                bad.append(f"{when} {shape}: {got[0]} != {got[1]}")

    compare("closed")
    _open()
    compare("open")
    s = ctypes.c_short()
    pr = cProfile.Profile()
    pr.enable()
    rc = fn(byref(s))
    pr.disable()
    table = table_calls(pr)
    assert rc == 0 and s.value == 1 and not table
    try:
        if gt.GT_SetCore(2) == 0:
            compare("core 2")
    finally:
        gt.GT_SetCore(1)
    assert not bad, "\n".join(bad)


def test_a_span_over_axes_no_drive_backs_reads_as_the_table_on_the_fast_path() -> None:
    """``GT_GetSts(1, sts, 12, &clk)`` on figure 5-2's bus (2 drives): the controller's axes
    3..12 read as axes at rest (0) on the fast path, with the table path's values, clock and
    refusals (a span past the controller's axes, axis 0); with axis 1 in the bank, and out
    of it (a planner chosen: a span of a row, an axis the bank does not run and zeros)."""
    _open()
    bad = []
    for name in [*sorted(fast.READERS), "", *sorted(fast.READERS)]:
        if not name:
            gt.GT_PrfTrap(1)
            continue
        t = ctypes.c_double if ctypes.c_double in fast.READERS[name][1] else ctypes.c_long
        for first, count in ((1, 12), (2, 5), (3, 8), (11, 2), (1, 13), (0, 3), (12, 2)):
            got = []
            for which in ("fast", "slow"):
                fn = getattr(gt, name)
                call = fn if which == "fast" else fn.slow
                arr, clk = (t * 13)(), ctypes.c_ulong()
                pr = cProfile.Profile()
                pr.enable()
                rc = call(first, arr, count, byref(clk))
                pr.disable()
                table = table_calls(pr)
                got.append((rc, list(arr), clk.value, gt.GTE_GetLastError() if rc else "", table))
            if got[0][:4] != got[1][:4]:
                bad.append(f"{name}({first}, {count}): {got[0][:4]} != {got[1][:4]}")
            elif got[0][0] == 0 and (got[0][4] or count > fast.READ_LIMITS.get(name, 12)):
                bad.append(f"{name}({first}, {count}): the table path ran")
    assert not bad, "\n".join(bad[:5])


def _span_session(tmp_path: Path, clock: str, way: str) -> tuple[list, int]:
    """A 16-axis bus (a controller of more axes than the 12 of chapter 13), every axis moving
    in Trap; each reader's spans past the twelfth axis into a ctypes and a numpy array, step
    by step through the public function (``c``), its Python fast function (``python``) or
    its table path (``table``): what each wrote and returned, and how many reads took the
    Python fast path's general way or the table path."""
    from tools.gen_axes_eni import write_axes_eni

    eni = write_axes_eni(16, tmp_path / "axes16.eni")
    assert gt.GT_Open(eni=str(eni), clock=clock, log="") == 0, gt.GTE_GetLastError()
    try:
        assert gt.GT_InitEcatComm() == 0, gt.GTE_GetLastError()
        ready = ctypes.c_short()
        for _ in range(1000):
            if gt.GT_IsEcatReady(byref(ready)) == 0 and ready.value == 1:
                break
            gt.GTE_Wait(1)
        assert gt.GT_StartEcatComm() == 0, gt.GTE_GetLastError()
        for a in range(1, 17):
            assert gt.GT_AxisOn(a) == 0, gt.GTE_GetLastError()
        gt.GTE_Wait(5)
        for a in range(1, 17):
            prm = gt.TTrapPrm()
            prm.acc = prm.dec = 0.5
            assert gt.GT_PrfTrap(a) == 0
            assert gt.GT_SetTrapPrm(a, byref(prm)) == 0
            assert gt.GT_SetPos(a, 200 * a * (-1) ** a) == 0
            assert gt.GT_SetVel(a, 2 + a / 4) == 0
        assert gt.GT_Update(0xFFFF) == 0, gt.GTE_GetLastError()
        seen: list = []
        pr = cProfile.Profile()
        for step in range(12):
            if clock == "lockstep":
                gt.GTE_Wait(1 + step % 4)
            for name in sorted(fast.READERS):
                f = getattr(gt, name)
                fn = {"c": f, "python": getattr(f, "python", f), "table": f.slow}[way]
                # the GTN_ form with core 1 (its C entry; else its table path, which its Python
                # function's spans are)
                gtn = getattr(gt, "GTN_" + name[3:]) if way == "c" else f.gtn_slow
                t = ctypes.c_double if ctypes.c_double in fast.READERS[name][1] else ctypes.c_long
                dt = np.float64 if t is ctypes.c_double else np.int32
                most = fast.READ_LIMITS.get(name, 16)
                for first, count in ((1, 16), (3, 14), (5, 12), (1, 13), (16, 1), (2, 16), (0, 13)):
                    for kind in ("ctypes", "numpy"):
                        arr = (t * 16)() if kind == "ctypes" else np.zeros(16, dt)
                        clk = ctypes.c_ulong()
                        # (a span the function answers with 0: profiled, through the C entry)
                        span = 1 <= first and first + count <= 17 and count <= most
                        span = span and way == "c"
                        if span:
                            pr.enable()
                        rc = fn(first, arr, count, byref(clk))
                        pr.disable()
                        why = gt.GTE_GetLastError() if rc else ""
                        seen.append(
                            (step, name, first, count, kind, rc, bytes(arr), clk.value, why)
                        )
                        if kind == "numpy" and step % 3:
                            continue
                        arr = (t * 16)() if kind == "ctypes" else np.zeros(16, dt)
                        if span:
                            pr.enable()
                        rc = gtn(1, first, arr, count, ctypes.pointer(clk))
                        pr.disable()
                        why = gt.GTE_GetLastError() if rc else ""
                        seen.append((step, "GTN", name, first, count, kind, rc, bytes(arr), why))
                        seen.append(clk.value)
        if way != "c":
            return seen, 0
        python = table_calls(pr, ("general", "many"))
        return seen, python
    finally:
        gt.GT_Close()


@pytest.mark.parametrize(
    "clock",
    [
        # (the default run: the auto clock's; the lockstep clock's spans through the C
        # entries in test_the_pdo_readers_read_a_banked_axis_where_it_is and test_centry)
        pytest.param("lockstep", marks=pytest.mark.long("the same session on the lockstep clock")),
        "auto",
    ],
)
def test_spans_past_twelve_axes_read_as_the_table_on_the_fast_path(
    tmp_path: Path, clock: str
) -> None:
    """``GT_GetSts(1, sts, 16, &clk)`` on a controller of 16 axes (and every reader, from
    several axes, into ctypes and numpy arrays): the table path's values, clock, codes and
    refusals (a span past the controller's axes, axis 0, an encoder reader's more than 8),
    step by step while every axis moves, and the GTN_ form with core 1 (a ``pointer`` to the
    clock); the spans it answers with 0 never reach Python's general way nor the table (the
    C entry), on both clocks."""
    fast_seen, python = _span_session(tmp_path, clock, "c")
    table_seen, _ = _span_session(tmp_path, clock, "table")
    assert fast_seen == table_seen
    assert _span_session(tmp_path, clock, "python")[0] == table_seen
    codes = {(x[1], x[2], x[3], x[5]) for x in fast_seen if type(x) is tuple and x[1] != "GTN"}
    assert ("GT_GetSts", 1, 16, 0) in codes and ("GT_GetSts", 2, 16, 7) in codes
    assert ("GT_GetEncPos", 1, 16, 7) in codes
    assert python == 0


class _Word(ctypes.Structure):
    _fields_ = [("lo", ctypes.c_ubyte), ("hi", ctypes.c_ubyte)]


def _read_only() -> np.ndarray:
    a = np.zeros(2, np.uint8)
    a.flags.writeable = False
    return a


#: a client's buffers of a 2-byte IO word besides the byte arrays: a ctypes number or
#: structure, byref of one (held or fresh), numpy arrays of other dtypes and shapes, a
#: memoryview of numbers (each the fast path's: its memory's bytes, as the table copies them)
WORD_SHAPES = {
    "c_ushort": lambda: (o := ctypes.c_ushort(0x0105), o),
    "byref(c_ushort)": lambda: (o := ctypes.c_ushort(0x0105), byref(o)),
    "byref(c_uint32)": lambda: (o := ctypes.c_uint32(0x0105), byref(o)),
    "structure": lambda: (o := _Word(5, 1), o),
    "byref(structure)": lambda: (o := _Word(5, 1), byref(o)),
    "c_double": lambda: (o := ctypes.c_double(2.5), o),
    "numpy uint16[1]": lambda: (o := np.array([0x0105], np.uint16), o),
    "numpy int32[2]": lambda: (o := np.array([0x0105, 7], np.int32), o),
    "numpy float64[1]": lambda: (o := np.array([2.5]), o),
    "numpy uint8[1, 2]": lambda: (o := np.array([[5, 1]], np.uint8), o),
    "memoryview H": lambda: (o := bytearray([5, 1, 0, 0]), memoryview(o).cast("H")),
    "memoryview c_ushort[1]": lambda: (o := (ctypes.c_ushort * 1)(0x0105), memoryview(o)),
}
#: shapes the table refuses (or that must not be answered by the copy): the same answer
WORD_REFUSED = {
    "byref(c_ushort, 1)": lambda: (o := ctypes.c_ushort(), byref(o, 1)),
    "c_ubyte": lambda: (o := ctypes.c_ubyte(), o),
    "c_void_p": lambda: (o := ctypes.c_void_p(5), o),
    "byref(c_void_p)": lambda: (o := ctypes.c_void_p(5), byref(o)),
    "numpy strided": lambda: (o := np.zeros(4, np.uint16), o[::2]),
    "numpy objects": lambda: (o := np.array([None, None], object), o),
    "numpy read-only": lambda: (o := _read_only(), o),
    "memoryview strided": lambda: (o := bytearray(8), memoryview(o)[::2]),
    "pointer(c_ushort)": lambda: (o := ctypes.c_ushort(0x0105), ctypes.pointer(o)),
}


def _bytes_of(o: object) -> bytes:
    if isinstance(o, np.ndarray):
        return o.tobytes() if not o.dtype.hasobject else repr(o.tolist()).encode()
    return bytes(o)  # type: ignore[call-overload]


def _word_call(fn: object, name: str, slave: int, make: object) -> tuple:
    """(code, the buffer's bytes after, reason, calls of the table or general path) of one
    call on the slave's first output word (the raw functions: where it lies in the image)."""
    o, p = make()  # type: ignore[operator]
    raw = gt.GTE_Controller().master.image.layout.slaves[slave].gt_offset
    args = (slave, 0, 2, p) if "EcatIO" in name else (raw, 2, p)
    pr = cProfile.Profile()
    pr.enable()
    rc = fn(*args)  # type: ignore[operator]
    pr.disable()
    table = table_calls(pr, ("general", "gtn_general", "run"))
    return rc, _bytes_of(o), gt.GTE_GetLastError() if rc else "", table


@pytest.mark.parametrize("name", sorted(fast.RAW))
def test_every_word_buffer_answers_as_the_table_on_the_fast_path(name: str) -> None:
    """``GT_EcatIOReadInput(2, 0, 2, byref(c_ushort()))`` and its kind (WORD_SHAPES), slaves
    2 and 3 in turn, through the C entry and its Python fast function: the table path's
    answer and image, and neither the table nor the general path runs; the shapes the table
    refuses (WORD_REFUSED) answer as it does."""
    ctl = _open()
    fn = getattr(gt, name)
    ways = [fn, *([fn.python] if hasattr(fn, "python") else [])]
    bad = []
    for shapes, fast_too in ((WORD_SHAPES, True), (WORD_REFUSED, False)):
        for shape, make in shapes.items():
            for way in ways:
                for slave in (2, 3, 2, 3):
                    got = _word_call(way, name, slave, make)
                    image = bytes(ctl.master.image.buffer)
                    want = _word_call(fn.slow, name, slave, make)
                    if got[:3] != want[:3] or image != bytes(ctl.master.image.buffer):
                        bad.append(f"{shape} {slave}: {got[:3]} != {want[:3]}")
                    elif fast_too and (got[0] != 0 or got[3]):
                        bad.append(f"{shape} {slave}: rc {got[0]}, table/general {got[3]}")
    assert not bad, "\n".join(bad)


def test_an_output_bit_is_written_as_the_table_writes_it_on_the_fast_path() -> None:
    """GT_EcatIOBitWriteOutput: every bit of each output byte of the IO slaves set and
    cleared, slaves in turn, on the fast path (no table call) with the table's image; its
    refusals (a bit, a value, an input byte, a slave out of range, a bool, a float) answer as
    the table does."""
    ctl = _open()
    bad = []
    for fn in (gt.GT_EcatIOBitWriteOutput, getattr(gt.GT_EcatIOBitWriteOutput, "python", None)):
        if fn is not None:  # (its C entry, then its Python fast function)
            bad += _bits(ctl, fn, gt.GT_EcatIOBitWriteOutput.slow)
    assert not bad, "\n".join(bad)


def _bits(ctl: object, fn: object, slow: object) -> list[str]:
    bad = []

    def both(args: tuple) -> tuple:
        out = []
        for way in (fn, slow):
            before = bytes(ctl.master.image.buffer)
            pr = cProfile.Profile()
            pr.enable()
            rc = way(*args)
            pr.disable()
            out.append((rc, bytes(ctl.master.image.buffer), gt.GTE_GetLastError() if rc else ""))
            out.append(table_calls(pr, ("general", "gtn_general")))
            ctl.master.image.buffer[:] = np.frombuffer(before, np.uint8)
        return out[0], out[1], out[2]

    for value in (1, 0, 1):
        for bit in range(8):
            for slave in (2, 3):
                for offset in (0, 1):
                    got, table, want = both((slave, offset, bit, value))
                    if got != want or got[0] != 0 or table:
                        bad.append(f"{slave} {offset} {bit} {value}: {got[0]} {table}")
                    fn(slave, offset, bit, value)  # (the image moves on)
    refused = [(2, 0, 8, 1), (2, 0, -1, 1), (2, 0, 3, 2), (2, 2, 0, 1), (2, 5, 0, 1)]
    refused += [(9, 0, 0, 1), (2, 0, 3, True), (2, 0, 3, 1.0), (2, 0), (2, 0, 3, 1, 1)]
    for args in refused:
        got, _, want = both(args)
        if got != want:
            bad.append(f"{args}: {got[0]} {got[2]!r} != {want[0]} {want[2]!r}")
    return bad
