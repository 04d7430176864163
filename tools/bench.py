"""gtecat benchmarks: prints one JSON object with every figure and its target.

    python3 tools/bench.py                  # all
    python3 tools/bench.py --quick          # fewer repetitions
    python3 tools/bench.py --targets        # only the many-axes figures and their targets
    python3 tools/bench.py --wait           # only GTE_Wait's cost (fast against general)

Figures: ENI read of a 64-slave file; emulated bus cycles per wall second on the
manual's figure 5-2 topology (bus only: drives replaced by plain PDO slaves;
and with full CiA-402 drives) and on the 12-axis example; the cost of one
``GT_GetEcatRawData`` call; plus what each part's own bench module reports.

``targets`` holds the many-axes figures and their targets, measured side by side in this run on
generated buses of single-axis CSP drives (:mod:`tools.bench_scaling`, lockstep
clock, public GT API, axes beyond 32 on cores 2-4), each with its target and
``ok``: real-time factors of 12 axes moving in Trap, 64 axes (odd axes moving, even
ones holding), 128 axes moving, 12 axes in Trap on the scalar path (bank off: what the modes
outside the bank compare with); 64 axes homing (method 17); 64 axes in smart homing
(``GT_GoHome`` modes 20 and 11, each homing timed from start to end with the axes' statuses
polled every 100 ms; every other mode likewise); the manual's figure 5-2 bus and one axis
moving in Trap; 64 axes homed and left in homing mode 6 (all holding, and half of them
with the other half moving in Trap); 12 axes homing (reported); PT,
Gear, Follow and coordinated motion (crd) at 12 axes (reported) and 64 axes (target 10:
every motion mode); two coordinate systems polled every cycle (GT_CrdStatus, GT_GetPrfPos),
and the same with a segment streamed onto each every 10 cycles, bank against scalar path in
pairs (target: the bank no slower); ``GT_GetSts`` against building its argument,
interleaved, and every call shape of the fast path likewise (the worst ratio is held to 4),
and every function with a fast path in every way a client passes its value's pointer
(``every_call_shape_vs_arguments``, the same bar), that walk and the call shapes again with
the controller on the auto clock (``every_call_shape_vs_arguments_auto``: each poll carries
its share of the cycles, the bar on the whole call; each shape also with the share the
controller's cycles took, timed where they run, and its ratio without it), both walks with
the spans of a 16-axis controller;
the RSS of a fresh process with a 128-axis controller open and moving.  A figure that cannot be
measured (for example core 2 missing) has ``error`` and ``ok: false``.
"""

from __future__ import annotations

import argparse
import importlib
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Mapping, Sequence
from ctypes import (
    POINTER,
    byref,
    c_double,
    c_long,
    c_short,
    c_ubyte,
    c_uint32,
    c_ulong,
    c_ushort,
    c_void_p,
    pointer,
    sizeof,
)
from dataclasses import replace
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
EXAMPLES = ROOT / "examples"
#: the manual's figure 5-2 bus: 2 CSP drives and 2 IO slaves
FIG5_2 = EXAMPLES / "manual_fig5_2.eni"
FIG5_TEXT = "the manual's figure 5-2 bus (2 drives, 2 IO slaves), both moving"


def _bus(eni: Path, *, plain: bool):
    from gtecat.drives.io_slaves import IoSlave
    from gtecat.eni.layout import build_layout
    from gtecat.eni.reader import read_eni
    from gtecat.master.backends.emulated import EmulatedBackend
    from gtecat.master.bus import Master

    cfg = read_eni(eni)
    if plain:  # plain PDO slaves have no mailbox: drop the CoE InitCmds
        cfg = replace(cfg, slaves=tuple(replace(s, init_cmds=()) for s in cfg.slaves))
    layout = build_layout(cfg)
    slaves = None
    if plain:
        slaves = [
            IoSlave(s.position, s.name, s.identity, rx_pdos=s.rx_pdos, tx_pdos=s.tx_pdos)
            for s in layout.config.slaves
        ]
    master = Master(layout, EmulatedBackend(slaves=slaves), op_delay_cycles=0)
    master.open()
    master.cycle(0, 1_000_000)
    return master


def bench_cycles(eni: Path, *, plain: bool, seconds: float) -> float:
    """Bus cycles (master exchange + every slave's step) per wall second."""
    master = _bus(eni, plain=plain)
    n = 0
    t0 = time.perf_counter()
    t = 0
    while True:
        for _ in range(200):
            master.cycle(t, 1_000_000)
            t += 1_000_000
        n += 200
        el = time.perf_counter() - t0
        if el >= seconds:
            return n / el


def bench_raw_call(reps: int) -> float:
    """µs per GT_GetEcatRawData(0, 8) through the GT layer (lockstep clock)."""
    from gtecat import gt

    gt.GT_Close()
    gt.GT_Open(eni=str(EXAMPLES / "manual_fig5_2.eni"), clock="lockstep", log="")
    gt.GT_InitEcatComm()
    gt.GTE_Wait(20)
    buf = (c_ubyte * 8)()
    t0 = time.perf_counter()
    for _ in range(reps):
        gt.GT_GetEcatRawData(0, 8, buf)
    el = time.perf_counter() - t0
    gt.GT_Close()
    return el / reps * 1e6


def bench_controller_12_axes(seconds: float) -> float | None:
    """Controller + drives cycles per wall second with all 12 axes moving (issue 5)."""
    try:
        mod = importlib.import_module("tools.bench_motion_bus")
    except ModuleNotFoundError:
        return None
    return mod.cycles_per_second(seconds)


def _figure(
    r: Mapping[str, object], key: str, target: float, *, at_most: bool = False
) -> dict[str, object]:
    """``r`` with its target and pass/fail on ``r[key]`` (an ``error``: not ok)."""
    v = r.get(key)
    ok = isinstance(v, int | float) and (v <= target if at_most else v >= target)
    return {**r, "target": target, "ok": ok}


def bench_get_sts(seconds: float = 1.0, block: int = 200) -> dict[str, object]:
    """µs per ``GT_GetSts(1, p)`` and per ``p = byref(c_long())``, in alternating blocks
    of ``block`` of each on an open 12-axis controller; ratio of the medians."""
    from gtecat import gt
    from tools.bench_scaling import BenchError, bring_up, gtn
    from tools.gen_axes_eni import write_axes_eni

    with tempfile.TemporaryDirectory() as tmp:
        try:
            bring_up(write_axes_eni(12, Path(tmp) / "axes12.eni"), 12)
            for a in range(1, 13):
                gtn("AxisOn", a)
        except BenchError as exc:
            gt.GT_Close()
            return {"error": str(exc)}
        get_sts, clock = gt.GT_GetSts, time.perf_counter
        held = c_long()
        p = byref(held)
        args, calls = [], []
        t_end = clock() + seconds
        rng = range(block)
        while clock() < t_end:
            t0 = clock()
            for _ in rng:
                s = c_long()
                p = byref(s)
            t1 = clock()
            for _ in rng:
                get_sts(1, p)
            t2 = clock()
            args.append((t1 - t0) / block)
            calls.append((t2 - t1) / block)
        gt.GT_Close()
    arg_us, call_us = statistics.median(args) * 1e6, statistics.median(calls) * 1e6
    return {
        "gt_get_sts_us": round(call_us, 3),
        "argument_us": round(arg_us, 3),
        "ratio": round(call_us / arg_us, 2),
        "blocks": len(args),
    }


#: the call shapes of the fast path and what building their arguments costs, as a client
#: writes both: (the call statement, the statement that builds the same arguments); the names
#: are those of :func:`_shape_env`
CALL_SHAPES: dict[str, tuple[str, str]] = {
    "GT_GetSts(1, byref(c_long()))": ("gt.GT_GetSts(1, byref(c_long()))", "byref(c_long())"),
    "GT_GetSts(1, byref(s))": ("gt.GT_GetSts(1, byref(s))", "byref(s)"),
    "GT_GetSts(1, ps), ps = byref(s) held": ("gt.GT_GetSts(1, ps)", "byref(c_long())"),
    "GT_GetSts(1, s)": ("gt.GT_GetSts(1, s)", "c_long()"),
    "GT_GetSts(1, byref(s), 1, 0)": ("gt.GT_GetSts(1, byref(s), 1, 0)", "byref(s)"),
    "GT_GetSts(1, byref(s), 1, None)": ("gt.GT_GetSts(1, byref(s), 1, None)", "byref(s)"),
    "GT_GetSts(1, byref(c_long()), 1, 0)": (
        "gt.GT_GetSts(1, byref(c_long()), 1, 0)",
        "byref(c_long())",
    ),
    "GTN_GetSts(1, 1, byref(s))": ("gt.GTN_GetSts(1, 1, byref(s))", "byref(s)"),
    "GT_GetSts(1, pointer(s))": ("gt.GT_GetSts(1, pointer(s))", "pointer(s)"),
    "GT_GetSts(1, c_long[1])": ("gt.GT_GetSts(1, arr1)", "(c_long * 1)()"),
    "GT_GetSts(1, c_long[2], 2)": ("gt.GT_GetSts(1, sts2, 2)", "(c_long * 2)()"),
    "GT_GetSts(1, c_long[12], 12, byref(clk))": (
        "gt.GT_GetSts(1, sts12, 12, byref(clk))",
        "byref(clk)",
    ),
    "GT_GetSts(1, numpy int32[1])": ("gt.GT_GetSts(1, np1)", "np.zeros(1, np.int32)"),
    "GT_GetPrfPos(1, byref(c_double()))": (
        "gt.GT_GetPrfPos(1, byref(c_double()))",
        "byref(c_double())",
    ),
    "GT_GetEncPos(1, byref(d))": ("gt.GT_GetEncPos(1, byref(d))", "byref(d)"),
    # a pointer into an array (C's &d12[k]): byref of the array, with and without an offset
    "GT_GetEncPos(9, byref(d12, 64), 4, None)": (
        "gt.GT_GetEncPos(9, byref(d12, 64), 4, None)",
        "byref(d12, 64)",
    ),
    "GT_GetPrfPos(2, byref(d12, 8), 1, None)": (
        "gt.GT_GetPrfPos(2, byref(d12, 8), 1, None)",
        "byref(d12, 8)",
    ),
    "GT_GetPrfPos(1, byref(d12), 1, None)": (
        "gt.GT_GetPrfPos(1, byref(d12), 1, None)",
        "byref(d12)",
    ),
    "GT_GetSts(1, byref(sts12, 8), 2)": ("gt.GT_GetSts(1, byref(sts12, 8), 2)", "byref(sts12, 8)"),
    "GT_GetPrfMode(1, byref(s))": ("gt.GT_GetPrfMode(1, byref(s))", "byref(s)"),
    "GT_GetClock(byref(clk))": ("gt.GT_GetClock(byref(clk))", "byref(clk)"),
    "GT_GetEcatEncPos(1, byref(s))": ("gt.GT_GetEcatEncPos(1, byref(s))", "byref(s)"),
    "GT_GetEcatRawData(0, 8, buf) c_ubyte[8]": ("gt.GT_GetEcatRawData(0, 8, buf)", "U8()"),
    "GT_GetEcatRawData(0, 8, byref(buf))": ("gt.GT_GetEcatRawData(0, 8, byref(buf))", "byref(buf)"),
    "GT_GetEcatRawData(0, 4, byref(buf, 3))": (
        "gt.GT_GetEcatRawData(0, 4, byref(buf, 3))",
        "byref(buf, 3)",
    ),
    "GT_SetEcatRawData(32, 2, byref(buf, 2))": (
        "gt.GT_SetEcatRawData(32, 2, byref(buf, 2))",
        "byref(buf, 2)",
    ),
    "GT_EcatIOReadInput(2, 0, 2, byref(buf, 1))": (
        "gt.GT_EcatIOReadInput(2, 0, 2, byref(buf, 1))",
        "byref(buf, 1)",
    ),
    "GT_GetEcatRawData(0, 8, c_ubyte[8]()) fresh": ("gt.GT_GetEcatRawData(0, 8, U8())", "U8()"),
    "GT_GetEcatRawData(0, 8, bytearray)": ("gt.GT_GetEcatRawData(0, 8, ba)", "bytearray(8)"),
    "GT_GetEcatRawData(0, 8, numpy uint8)": (
        "gt.GT_GetEcatRawData(0, 8, npu8)",
        "np.zeros(8, np.uint8)",
    ),
    "GT_GetEcatRawData(0, 8, memoryview)": (
        "gt.GT_GetEcatRawData(0, 8, mv8)",
        "memoryview(bytearray(8))",
    ),
    "GT_SetEcatRawData(32, 2, bytes)": ("gt.GT_SetEcatRawData(32, 2, out2)", "bytes([15, 0])"),
    "GT_SetEcatRawData(32, 2, c_ubyte[2](..)) fresh": (
        "gt.GT_SetEcatRawData(32, 2, (c_ubyte * 2)(0x55, 0xAA))",
        "(c_ubyte * 2)(0x55, 0xAA)",
    ),
    "GT_SetEcatRawData(32, 2, buf) c_ubyte[8]": ("gt.GT_SetEcatRawData(32, 2, buf)", "U8()"),
    "GT_EcatIOReadInput(2, 0, 4, buf)": ("gt.GT_EcatIOReadInput(2, 0, 4, buf)", "U8()"),
    "GT_EcatIOReadInput(2, 0, 4, bytearray)": (
        "gt.GT_EcatIOReadInput(2, 0, 4, ba)",
        "bytearray(8)",
    ),
    "GT_EcatIOWriteOutput(2, 0, 2, bytes)": (
        "gt.GT_EcatIOWriteOutput(2, 0, 2, out2)",
        "bytes([15, 0])",
    ),
    "GT_GetDi(MC_LIMIT_POSITIVE, byref(s))": ("gt.GT_GetDi(0, byref(s))", "byref(s)"),
    "GT_GetDi(MC_HOME, byref(c_long()))": ("gt.GT_GetDi(3, byref(c_long()))", "byref(c_long())"),
    "GT_GetDi(MC_GPI, s)": ("gt.GT_GetDi(4, s)", "c_long()"),
    "GT_GetDiRaw(MC_LIMIT_NEGATIVE, byref(s))": ("gt.GT_GetDiRaw(1, byref(s))", "byref(s)"),
    "GT_GetDo(MC_GPO, byref(s))": ("gt.GT_GetDo(12, byref(s))", "byref(s)"),
    "GT_GetTrapPrm(1, byref(tp))": ("gt.GT_GetTrapPrm(1, byref(tp))", "byref(tp)"),
    "GT_GetTrapPrm(1, byref(TTrapPrm()))": (
        "gt.GT_GetTrapPrm(1, byref(gt.TTrapPrm()))",
        "byref(gt.TTrapPrm())",
    ),
    "GT_GetEcatHomingStatus(1, byref(h))": ("gt.GT_GetEcatHomingStatus(1, byref(h))", "byref(h)"),
    "GT_GetEcatHomingStatus(1, byref(c_short()))": (
        "gt.GT_GetEcatHomingStatus(1, byref(c_short()))",
        "byref(c_short())",
    ),
    # an outside check's shapes: NULL of a pointer type, named arguments, two ranges in turn,
    # a word of IO in a c_ushort or a numpy array, the IO slaves in turn, an output bit
    "GT_GetSts(1, byref(s), 1, POINTER(c_uint32)())": (
        "gt.GT_GetSts(1, byref(s), 1, nullp)",
        "byref(s)",
    ),
    "GT_GetSts(1, byref(s), 1, c_void_p())": ("gt.GT_GetSts(1, byref(s), 1, vnull)", "byref(s)"),
    "GT_GetSts(axis=1, pSts=byref(s))": ("gt.GT_GetSts(axis=1, pSts=byref(s))", "byref(s)"),
    "GT_GetEcatRawData (0, 8, buf) and (8, 4, buf4) in turn": (
        "gt.GT_GetEcatRawData(0, 8, buf); gt.GT_GetEcatRawData(8, 4, buf4)",
        "U8(); U4()",
    ),
    "GT_SetEcatRawData(32, 2, byref(w)) c_ushort": (
        "gt.GT_SetEcatRawData(32, 2, byref(w))",
        "byref(w)",
    ),
    "GT_SetEcatRawData(32, 2, numpy uint16[1])": (
        "gt.GT_SetEcatRawData(32, 2, npu16)",
        "np.zeros(1, np.uint16)",
    ),
    "GT_EcatIOReadInput(2, 0, 2, byref(w)) c_ushort": (
        "gt.GT_EcatIOReadInput(2, 0, 2, byref(w))",
        "byref(w)",
    ),
    "GT_EcatIOReadInput(2, 0, 2, w)": ("gt.GT_EcatIOReadInput(2, 0, 2, w)", "c_ushort()"),
    "GT_EcatIOReadInput(2, 0, 2, numpy uint16[1])": (
        "gt.GT_EcatIOReadInput(2, 0, 2, npu16)",
        "np.zeros(1, np.uint16)",
    ),
    "GT_EcatIOReadInput slaves 2 and 3 in turn": (
        "gt.GT_EcatIOReadInput(2, 0, 2, byref(w)); gt.GT_EcatIOReadInput(3, 0, 2, byref(w))",
        "byref(w); byref(w)",
    ),
    "GT_EcatIOWriteOutput(2, 0, 2, byref(w)) c_ushort": (
        "gt.GT_EcatIOWriteOutput(2, 0, 2, byref(w))",
        "byref(w)",
    ),
    "GT_EcatIOWriteOutput(2, 0, 2, byref(c_ushort(5))) fresh": (
        "gt.GT_EcatIOWriteOutput(2, 0, 2, byref(c_ushort(5)))",
        "byref(c_ushort(5))",
    ),
    "GT_EcatIOWriteOutput slaves 2 and 3 in turn": (
        "gt.GT_EcatIOWriteOutput(2, 0, 2, byref(w)); gt.GT_EcatIOWriteOutput(3, 0, 2, byref(w))",
        "byref(w); byref(w)",
    ),
    "GT_EcatIOBitWriteOutput(2, 0, 3, 1)": ("gt.GT_EcatIOBitWriteOutput(2, 0, 3, 1)", "byref(w)"),
}
#: the table path (every other function: its checks compiled, then the emulated function's
#: own work, which these figures include): reported beside the fast path's, not in `worst`
TABLE_SHAPES: dict[str, tuple[str, str]] = {
    "GT_GetCore(byref(h))": ("gt.GT_GetCore(byref(h))", "byref(h)"),
    "GT_GetDiReverseCount(MC_HOME, 1, c_ulong[2], 2)": (
        "gt.GT_GetDiReverseCount(3, 1, counts, 2)",
        "(c_ulong * 2)()",
    ),
}


def _shape_env() -> dict[str, object]:
    """The names :data:`CALL_SHAPES` uses (the controller open)."""
    import numpy as np

    from gtecat import gt

    return {
        "gt": gt,
        "np": np,
        "byref": byref,
        "pointer": pointer,
        "c_long": c_long,
        "c_short": c_short,
        "c_double": c_double,
        "c_ubyte": c_ubyte,
        "c_ulong": c_ulong,
        "s": c_long(),
        "ps": byref(c_long()),
        "d": c_double(),
        "h": c_short(),
        "clk": c_ulong(),
        "U8": c_ubyte * 8,
        "buf": (c_ubyte * 8)(),
        "ba": bytearray(8),
        "npu8": np.zeros(8, np.uint8),
        "mv8": memoryview(bytearray(8)),
        "np1": np.zeros(1, np.int32),
        "arr1": (c_long * 1)(),
        "sts2": (c_long * 2)(),
        "sts12": (c_long * 12)(),
        "d12": (c_double * 12)(),
        "out2": bytes([0x0F, 0x00]),
        "tp": gt.TTrapPrm(),
        "counts": (c_ulong * 2)(),
        "c_ushort": c_ushort,
        "w": c_ushort(5),
        "npu16": np.zeros(1, np.uint16),
        "U4": c_ubyte * 4,
        "buf4": (c_ubyte * 4)(),
        "nullp": POINTER(c_uint32)(),
        "vnull": c_void_p(),
    }


def bench_call_shapes(seconds: float = 1.0, block: int = 200) -> dict[str, object]:
    """Each call shape of the fast path (:data:`CALL_SHAPES`) against the statement that
    builds the same arguments, each timed as a loop of its statement (no wrapper around
    either), in alternating blocks on figure 5-2's bus (lockstep, axis 1 on and in Trap):
    µs per call, µs per argument build, their ratio (medians); ``worst`` is the largest
    ratio."""
    from gtecat import gt

    gt.GT_Close()
    gt.GT_Open(eni=str(EXAMPLES / "manual_fig5_2.eni"), clock="lockstep", log="")
    gt.GT_InitEcatComm()
    gt.GTE_Wait(60)
    gt.GT_StartEcatComm()
    gt.GT_AxisOn(1)
    gt.GT_PrfTrap(1)
    gt.GTE_Wait(20)
    env = _shape_env()
    per = seconds / (len(CALL_SHAPES) + len(TABLE_SHAPES))
    try:
        out = _time_pairs(
            {k: (*v, env) for k, v in CALL_SHAPES.items()}, per * len(CALL_SHAPES), block
        )
        table_out = _time_pairs(
            {k: (*v, env) for k, v in TABLE_SHAPES.items()}, per * len(TABLE_SHAPES), block
        )
    finally:
        gt.GT_Close()
    worst = max((row["ratio"] for row in out.values()), default=0.0)
    table_worst = max((row["ratio"] for row in table_out.values()), default=0.0)
    return {"shapes": out, "worst": worst, "table_path": table_out, "table_worst": table_worst}


def _loop(stmt: str, env: dict[str, object]) -> Callable[[int], None]:
    """``f(n)``: ``stmt`` run ``n`` times, its names ``env``'s globals (as timeit runs it)."""
    ns = dict(env)
    exec(compile(f"def _run(_n):\n    for _ in range(_n):\n        {stmt}\n", stmt, "exec"), ns)
    return ns["_run"]  # type: ignore[return-value]


def _time_pairs(
    pairs: Mapping[str, tuple[str, str, dict[str, object]]],
    seconds: float,
    block: int,
    cycles: Sequence[int] | None = None,
) -> dict[str, dict[str, float]]:
    """Per name, (the call statement, the statement building its arguments, their names)
    timed as loops of ``block`` runs, alternating, for ``seconds`` in all: µs per call, µs
    per argument build, the ratio of the medians.  ``cycles``: the quick cycles' timer
    (``centry.CYCLE_TIMER``, on): also the µs per call the controller's cycles took inside
    the calls (``cycle_us``: the kernel's cycle and its book, which the call's host latency
    runs on the auto clock), the call less them (``less_cycles_us``, median of each block's
    difference: the call's own work, the values it makes again after a cycle included) and
    that against the arguments (``ratio_less_cycles``)."""
    clock = time.perf_counter
    per = seconds / max(1, len(pairs))
    out: dict[str, dict[str, float]] = {}
    for name, (call_src, build_src, env) in pairs.items():
        call, build = _loop(call_src, env), _loop(build_src, env)
        calls, args, cyc = [], [], []
        t_end = clock() + per
        while clock() < t_end or len(calls) < 3:
            t0 = clock()
            build(block)
            t1 = clock()
            ns0 = cycles[1] if cycles is not None else 0
            call(block)
            t2 = clock()
            args.append((t1 - t0) / block)
            calls.append((t2 - t1) / block)
            if cycles is not None:
                cyc.append((cycles[1] - ns0) * 1e-9 / block)
        c_us, a_us = statistics.median(calls) * 1e6, statistics.median(args) * 1e6
        out[name] = {
            "call_us": round(c_us, 3),
            "argument_us": round(a_us, 3),
            "ratio": round(c_us / a_us, 2),
        }
        if cycles is not None:
            own = statistics.median(c - y for c, y in zip(calls, cyc, strict=True)) * 1e6
            out[name] |= {
                "cycle_us": round(statistics.median(cyc) * 1e6, 3),
                "less_cycles_us": round(own, 3),
                "ratio_less_cycles": round(own / a_us, 2),
            }
    return out


def every_shape(
    names: Sequence[str] | None = None,
) -> tuple[dict[str, tuple[str, str, dict[str, object]]], dict[str, str]]:
    """Every function with a fast path (the raw image functions: :func:`bench_call_shapes`)
    in every way a client passes its value's pointer, with what building that argument
    costs: ``byref`` of a reused and of a fresh object, the ctypes object itself, a ctypes
    and a numpy array of one element, and NULL (0, None) for the optional pointer after it
    (``count`` 1 first for the readers of a span), a pointer into an array (``byref(arr)``,
    ``byref(arr, k * sizeof(elem))``: C's ``&arr[k]``; for the readers of a span, two values
    there too; ``pointer(s)``; a numpy array of several values), and for the readers that
    take ``pClock`` their shapes with a clock pointer (``byref`` of it, the object itself,
    ``pointer`` of it, with one value and with a span), GT_GetClock's two pointers (pClock
    and pLoop, the vendor's form); each call written
    out as a client writes
    it (no ``*args``), with the statement that builds the same arguments and their names.
    ``names``: these functions instead (a comparison with another version).  The controller
    must be open.  Also the shapes not measured and why: a call
    that does not return 0 on this bus (an object its drives do not map), a shape the table
    path answers (``fast.SLOW_SHAPES``)."""
    import numpy as np

    from gtecat import gt
    from gtecat.gt import fast
    from gtecat.gt.args import _scalar_types
    from gtecat.gt.table import FUNCTIONS

    first = {"GT_GetDi": 3, "GT_GetDiRaw": 0, "GT_GetDo": 10}  # (a type; else axis 1)
    dtypes = {c_double: np.float64, c_long: np.int64, c_short: np.int16}
    out: dict[str, tuple[str, str, dict[str, object]]] = {}
    skipped: dict[str, str] = {}
    slow = getattr(fast, "SLOW_SHAPES", {})  # (an earlier version has none)
    for name in names if names is not None else sorted(fast.fast_functions() - fast.RAW):
        params = FUNCTIONS[name].params
        i = next(k for k, q in enumerate(params) if q.pointer)
        if name in fast.STRUCT_READERS:
            t: type = fast.STRUCT_READERS[name][0]
        else:
            ok = _scalar_types(params[i])
            t = next(x for x in (c_double, c_long, c_short) if x in ok)
        held = t()
        rest = params[i + 1 :]
        null = bool(rest) and rest[-1].pointer and rest[-1].default is not None
        count = "1, " if len(rest) == 2 else ""
        env = {
            "fn": getattr(gt, name),
            "t": t,
            "held": held,
            "ref": byref(held),
            "arr": (t * 1)(),
            "arr4": (t * 4)(),
            "k": sizeof(t),
            "byref": byref,
            "pointer": pointer,
            "np": np,
            "c_ulong": c_ulong,
        }
        x = f"{first.get(name, 1)}, " if i else ""
        # shape: (its kind, as fast.SLOW_SHAPES names it; the call's source; building its
        # arguments' source)
        shapes = {
            "byref(s)": ("byref reused", f"fn({x}byref(held))", "byref(held)"),
            "ps (byref(s) held)": ("byref reused", f"fn({x}ref)", "byref(t())"),
            f"byref({t.__name__}())": ("byref fresh", f"fn({x}byref(t()))", "byref(t())"),
            "s": ("object", f"fn({x}held)", "t()"),
            f"{t.__name__}[1]": ("array[1]", f"fn({x}arr)", "(t * 1)()"),
            "byref(arr)": ("byref array", f"fn({x}byref(arr4))", "byref(arr4)"),
            "byref(arr, k)": ("byref array offset", f"fn({x}byref(arr4, k))", "byref(arr4, k)"),
        }
        if name in fast.READERS:
            shapes["byref(arr, k), 2, None"] = (
                "byref array span",
                f"fn({x}byref(arr4, k), 2, None)",
                "byref(arr4, k)",
            )
            shapes["pointer(s)"] = ("pointer", f"fn({x}pointer(held))", "pointer(held)")
        env["mv"] = memoryview(env["arr"])  # (memoryview(arr): the array's own, or apart)
        shapes["memoryview(arr)"] = ("memoryview", f"fn({x}mv)", "memoryview(arr)")
        if name == fast.CLOCK:
            # the vendor's two-pointer form GT_GetClock(&clk, &loop), as clients pass it
            env["loop"] = c_ulong()
            shapes |= {
                "byref(s), byref(loop)": (
                    "loop byref",
                    "fn(byref(held), byref(loop))",
                    "byref(held); byref(loop)",
                ),
                "s, loop": ("loop object", "fn(held, loop)", "t(); c_ulong()"),
                "pointer(s), pointer(loop)": (
                    "loop pointer",
                    "fn(pointer(held), pointer(loop))",
                    "pointer(held); pointer(loop)",
                ),
            }
        if [q.name for q in rest] == ["count", "pClock"]:
            # the clock pointer too (the vendor's form of a loop that timestamps its reads)
            env["clk"] = c_ulong()
            shapes |= {
                "byref(s), 1, byref(clk)": (
                    "clock byref",
                    f"fn({x}byref(held), 1, byref(clk))",
                    "byref(held); byref(clk)",
                ),
                "s, 1, clk": ("clock object", f"fn({x}held, 1, clk)", "t(); c_ulong()"),
                f"{t.__name__}[4], 2, byref(clk)": (
                    "clock span",
                    f"fn({x}arr4, 2, byref(clk))",
                    "byref(clk)",
                ),
                "byref(arr, k), 2, clk": (
                    "clock byref array span",
                    f"fn({x}byref(arr4, k), 2, clk)",
                    "byref(arr4, k)",
                ),
                # the clock as pointer(x)
                "byref(s), 1, pointer(clk)": (
                    "clock pointer",
                    f"fn({x}byref(held), 1, pointer(clk))",
                    "byref(held); pointer(clk)",
                ),
            }
        if t in dtypes:
            env["npa"], env["dt"] = np.zeros(1, dtypes[t]), dtypes[t]
            dn = np.dtype(dtypes[t]).name
            shapes[f"numpy {dn}[1]"] = ("numpy[1]", f"fn({x}npa)", "np.zeros(1, dt)")
            if name in fast.READERS:  # (numpy arrays of several values)
                env["npa4"] = np.zeros(4, dtypes[t])
                shapes[f"numpy {dn}[4], 2"] = ("numpy span", f"fn({x}npa4, 2)", "np.zeros(4, dt)")
                if "clk" in env:
                    shapes[f"numpy {dn}[4], 2, byref(clk)"] = (
                        "numpy span clock",
                        f"fn({x}npa4, 2, byref(clk))",
                        "byref(clk)",
                    )
        if null:
            env["nullp"], env["vnull"] = POINTER(c_uint32)(), c_void_p()
            for z, kind in (
                ("0", "null 0"),
                ("None", "null None"),
                ("nullp", "null pointer"),  # (NULL of a pointer type: POINTER(c_uint32)())
                ("vnull", "null c_void_p"),
            ):
                shapes[f"byref(s), {count}{z}"] = (
                    kind,
                    f"fn({x}byref(held), {count}{z})",
                    "byref(held)",
                )
        # the arguments named as the table names them (GT_GetSts(axis=1, pSts=byref(s)))
        named = [q.name for q in params[: i + 1]]
        values = [*([str(first.get(name, 1))] if i else []), "byref(held)"]
        shapes["keywords"] = (
            "keywords",
            f"fn({', '.join(f'{n}={v}' for n, v in zip(named, values, strict=True))})",
            "byref(held)",
        )
        for shape, (kind, call, build) in shapes.items():
            label = f"{name}({'x, ' if i else ''}{shape})"
            if kind in slow.get(name, {}):  # (whatever it returns on this bus)
                skipped[label] = "on the table path: " + slow[name][kind]
                continue
            rc = eval(call, env)
            if rc != 0:
                skipped[label] = f"returns {rc} on this bus"
            else:
                out[label] = (call, build, env)
    return out, skipped


#: spans of a controller of 16 axes (more than chapter 13's 12), every axis moving in Trap:
#: a poll of every axis in one call, into ctypes and numpy arrays (:func:`bench_every_shape`)
WIDE_SHAPES: dict[str, tuple[str, str]] = {
    "GT_GetSts(1, c_long[16], 16, byref(clk))": (
        "gt.GT_GetSts(1, sts16, 16, byref(clk))",
        "byref(clk)",
    ),
    "GT_GetSts(1, c_long[16], 16)": ("gt.GT_GetSts(1, sts16, 16)", "(c_long * 16)()"),
    "GT_GetSts(1, numpy int32[16], 16)": ("gt.GT_GetSts(1, np16, 16)", "np.zeros(16, np.int32)"),
    "GT_GetPrfPos(1, c_double[16], 16, None)": (
        "gt.GT_GetPrfPos(1, d16, 16, None)",
        "(c_double * 16)()",
    ),
    "GT_GetPrfPos(1, numpy float64[16], 16, byref(clk))": (
        "gt.GT_GetPrfPos(1, npd16, 16, byref(clk))",
        "byref(clk)",
    ),
    "GT_GetSts(5, byref(sts16, 8), 12, pointer(clk))": (
        "gt.GT_GetSts(5, byref(sts16, 8), 12, pointer(clk))",
        "byref(sts16, 8); pointer(clk)",
    ),
}


def _wide_pairs(clock: str) -> dict[str, tuple[str, str, dict[str, object]]]:
    """:data:`WIDE_SHAPES` with their names, on a 16-axis bus opened on ``clock`` (every axis
    on and moving in Trap; a shape that does not return 0: left out); the caller closes
    it."""
    import numpy as np

    from gtecat import gt
    from tools.gen_axes_eni import write_axes_eni

    with tempfile.TemporaryDirectory() as tmp:  # (GT_InitEcatComm reads the ENI too)
        eni = write_axes_eni(16, Path(tmp) / "axes16.eni")
        gt.GT_Open(eni=str(eni), clock=clock, log="")
        gt.GT_InitEcatComm()
        ready = c_short()
        for _ in range(10_000):
            if gt.GT_IsEcatReady(byref(ready)) == 0 and ready.value == 1:
                break
            gt.GTE_Wait(1)
        gt.GT_StartEcatComm()
    for a in range(1, 17):
        gt.GT_AxisOn(a)
    gt.GTE_Wait(20)
    for a in range(1, 17):
        prm = gt.TTrapPrm()
        prm.acc = prm.dec = 0.3
        gt.GT_PrfTrap(a)
        gt.GT_SetTrapPrm(a, byref(prm))
        gt.GT_SetPos(a, 80_000_000 * (-1) ** a)
        gt.GT_SetVel(a, 15 + a)
    gt.GT_Update(0xFFFF)
    gt.GTE_Wait(30)
    env = _shape_env() | {
        "sts16": (c_long * 16)(),
        "d16": (c_double * 16)(),
        "np16": np.zeros(16, np.int32),
        "npd16": np.zeros(16, np.float64),
    }
    return {f"{k} (16 axes)": (*v, env) for k, v in WIDE_SHAPES.items() if eval(v[0], env) == 0}


def bench_every_shape(
    seconds: float = 20.0,
    block: int = 200,
    names: Sequence[str] | None = None,
    *,
    clock: str = "lockstep",
    raw: bool = False,
) -> dict[str, object]:
    """:func:`every_shape` on figure 5-2's bus (axis 1 on; ``clock``: the controller's clock,
    ``raw``: with :data:`CALL_SHAPES` too - the raw image functions' shapes among them),
    each against building its arguments in alternating blocks, then (the whole walk, no
    ``names``) :data:`WIDE_SHAPES` on a 16-axis bus on the same clock; ``worst`` the largest
    ratio, ``above_4`` the shapes above the bar.  On the auto clock every call costs its host
    latency of controller time, so a call's figure carries its share of the cycles that run
    (one 1 ms cycle every 20 calls): each shape says how much of it the controller's cycles
    took (``cycle_us``, the readers' C entries' quick cycles timed where they run: the
    kernel's cycle and its book) and its ratio without them (``ratio_less_cycles``: the call's
    own work, the values it makes again after a cycle included); ``worst_less_cycles`` the
    largest of those (``worst`` stays the whole call's)."""
    from gtecat import gt
    from gtecat.gt import centry

    timer = centry.CYCLE_TIMER if clock == "auto" and centry.CYCLE_TIMED else None

    gt.GT_Close()
    gt.GT_Open(eni=str(EXAMPLES / "manual_fig5_2.eni"), clock=clock, log="")
    gt.GT_InitEcatComm()
    gt.GTE_Wait(60)
    gt.GT_StartEcatComm()
    gt.GT_AxisOn(1)
    gt.GTE_Wait(20)
    try:
        pairs, skipped = every_shape(names)
        if raw:
            env = _shape_env()
            pairs |= {k: (*v, env) for k, v in CALL_SHAPES.items()}
        if timer is not None:
            timer[0] = 1
        shapes = _time_pairs(pairs, seconds, block, timer)
        if names is None:  # (the spans of a controller of more than 12 axes)
            gt.GT_Close()
            wide = _wide_pairs(clock)
            shapes |= _time_pairs(wide, seconds * len(wide) / max(1, len(pairs)), block, timer)
            for k in WIDE_SHAPES:
                if f"{k} (16 axes)" not in wide:
                    skipped[f"{k} (16 axes)"] = "does not return 0 on the 16-axis bus"
    finally:
        if timer is not None:
            timer[0] = 0
        gt.GT_Close()
    worst = max((r["ratio"] for r in shapes.values()), default=0.0)
    above = {k: r["ratio"] for k, r in shapes.items() if r["ratio"] > 4}
    out: dict[str, object] = {
        "shapes": shapes,
        "count": len(shapes),
        "worst": worst,
        "above_4": above,
    }
    if timer is not None:
        less = {k: r["ratio_less_cycles"] for k, r in shapes.items()}
        top = max(less, key=less.__getitem__, default=None)
        out |= {
            "worst_less_cycles": less[top] if top is not None else 0.0,
            "worst_less_cycles_shape": top,
            "worst_shape": max(shapes, key=lambda k: shapes[k]["ratio"], default=None),
        }
    return out | {"not_measured": skipped}


def _rss() -> dict[str, float]:
    """VmRSS and VmHWM of this process in MB (``ru_maxrss`` where /proc is absent)."""
    out: dict[str, float] = {}
    try:
        for line in Path("/proc/self/status").read_text().splitlines():
            key, _, value = line.partition(":")
            if key in ("VmRSS", "VmHWM"):
                out[f"{key}_mb"] = round(int(value.split()[0]) / 1024, 1)
    except OSError:
        import resource

        out["VmHWM_mb"] = round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024, 1)
    out.setdefault("VmRSS_mb", out.get("VmHWM_mb", 0.0))
    return out


def rss_child(n: int, seconds: float, eni: str = "") -> int:
    """In this (fresh) process: ``n`` axes open and moving in Trap (on ``eni``, the bus
    the parent wrote); print the RSS.  ``n`` 0: the modules imported, nothing open."""
    from tools.bench_scaling import run_bus

    if not n:
        from gtecat import gt  # noqa: F401  (what every process holds before its bus)

        print(json.dumps(_rss()))
        return 0
    plan = dict.fromkeys(range(1, n + 1), "moving")
    r = run_bus(n, plan, seconds=seconds, repeat=1, after=_rss, eni_file=eni or None)
    print(json.dumps(r))
    return 0


def _subreaper() -> bool:
    """Linux: the processes a child leaves running when it ends (the bank kernel's build,
    which goes on by itself) become this process's children, to be waited for and counted."""
    if not sys.platform.startswith("linux"):
        return False
    try:
        import ctypes

        return ctypes.CDLL(None).prctl(36, 1, 0, 0, 0) == 0  # PR_SET_CHILD_SUBREAPER
    except (OSError, AttributeError):
        return False


def _reap(limit_s: float = 120.0) -> None:
    """Wait for every child left (the orphans :func:`_subreaper` gave this process)."""
    end = time.monotonic() + limit_s
    while time.monotonic() < end:
        try:
            pid, _ = os.waitpid(-1, os.WNOHANG)
        except ChildProcessError:
            return
        if pid == 0:
            time.sleep(0.01)


def _child(args: list[str], env: Mapping[str, str] | None = None) -> dict[str, object]:
    """Run this script with ``args`` in a fresh process (``env``: its environment): its last
    JSON line, with the process's wall and CPU seconds from spawn to exit.  The CPU counts
    every process it started, also one that went on after it ended (the kernel's build on a
    first run: ``background_s`` is how much longer that ran, on Linux)."""
    import resource

    cmd = [sys.executable, __file__, *args]
    reaper = _subreaper()
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    p = subprocess.run(cmd, capture_output=True, text=True, cwd=ROOT, timeout=600, env=env)
    wall = time.perf_counter() - t0
    if reaper:
        _reap()
    left = time.perf_counter() - t0 - wall
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if p.returncode != 0:
        return {"error": (p.stderr.strip().splitlines() or ["child failed"])[-1]}
    r = json.loads(p.stdout.strip().splitlines()[-1])
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    out = {**r, "process_wall_s": round(wall, 3), "process_cpu_s": round(cpu, 3)}
    if left > 0.05:
        out["background_s"] = round(left, 3)
    return out


def bench_rss(n: int = 128, seconds: float = 0.5) -> dict[str, object]:
    """The RSS of a fresh Python process with an ``n``-axis controller open and moving
    (the ENI written beforehand, by this process), and the memory per axis: its peak RSS
    less that of a process that only imported gtecat, per axis."""
    from tools.gen_axes_eni import write_axes_eni

    with tempfile.TemporaryDirectory() as tmp:
        eni = write_axes_eni(n, Path(tmp) / f"axes{n}.eni")
        r = _child(["--rss-child", str(n), "--seconds", str(seconds), "--eni", str(eni)])
    base = _child(["--rss-child", "0"])
    if "error" in r or "error" in base:
        return {"error": str(r.get("error") or base.get("error"))}
    per_axis = (float(r["VmHWM_mb"]) - float(base["VmHWM_mb"])) / n  # type: ignore[arg-type]
    return {
        "axes": n,
        "state": "moving",
        **r,
        "import_only_VmHWM_mb": base["VmHWM_mb"],
        "mb_per_axis": round(per_axis, 4),
    }


def bringup_child(eni: str) -> int:
    """In this (fresh) process: import gtecat, open ``eni`` (lockstep), GT_InitEcatComm,
    GT_IsEcatReady until ready, GT_StartEcatComm: every slave in OP.  Prints the phases'
    wall and CPU seconds."""
    from ctypes import c_short

    t0 = time.perf_counter()
    from gtecat import gt

    t1, c1 = time.perf_counter(), time.process_time()
    ok = gt.GT_Open(eni=eni, clock="lockstep", log="") == 0 and gt.GT_InitEcatComm() == 0
    ready = c_short()
    for _ in range(10_000):
        if not ok or (gt.GT_IsEcatReady(byref(ready)) == 0 and ready.value == 1):
            break
        gt.GTE_Wait(1)
    ok = ok and ready.value == 1 and gt.GT_StartEcatComm() == 0
    if not ok:
        print(json.dumps({"error": gt.GTE_GetLastError() or "the bus did not reach OP"}))
        return 1
    t2, c2 = time.perf_counter(), time.process_time()
    print(
        json.dumps(
            {
                "import_s": round(t1 - t0, 3),
                "import_cpu_s": round(c1, 3),
                "to_op_s": round(t2 - t1, 3),
                "to_op_cpu_s": round(c2 - c1, 3),
                **_rss(),
            }
        )
    )
    gt.GT_Close()
    return 0


COLD = (
    "cold: a new, empty gtecat cache folder (GTECAT_CACHE_DIR) and no bytecode written by Python"
    " (PYTHONDONTWRITEBYTECODE=1), as the first run on a fresh machine: the ENI parsed, gtecat's"
    " modules compiled from source, the bank's C kernel built in a process of its own once the"
    " bus is in OP (its compiler's CPU counted; background_s: how long it went on after the exit)"
)
WARM = "warm: the same cache folder after one such run (the ENI's model, modules, kernel kept)"


def bench_bringup(n: int, warm: bool = True) -> dict[str, object]:
    """A fresh process taking an ``n``-axis bus (written beforehand) to OP: the process's
    wall and CPU seconds from spawn to exit (Python start and imports included), on a cold
    cache (the figure); ``warm``: then again on the cache that run left, reported beside."""
    from tools.gen_axes_eni import write_axes_eni

    with tempfile.TemporaryDirectory() as tmp:
        eni = write_axes_eni(n, Path(tmp) / f"axes{n}.eni")
        env = {**os.environ, "GTECAT_CACHE_DIR": str(Path(tmp) / "cache")}
        env["PYTHONDONTWRITEBYTECODE"] = "1"
        env.pop("GTECAT_ENI_CACHE", None)
        env.pop("GTECAT_PYC_CACHE", None)
        r = _child(["--bringup-child", str(eni)], env)
        out: dict[str, object] = {"axes": n, "cache": COLD, **r}
        if warm and "error" not in r:
            w = _child(["--bringup-child", str(eni)], env)
            keep = ("process_wall_s", "process_cpu_s", "to_op_s", "import_s", "error")
            out["warm"] = {"cache": WARM, **{k: v for k, v in w.items() if k in keep}}
    return out


def bench_bringup_growth(counts: Sequence[int] = (256, 512, 1024, 2048)) -> dict[str, object]:
    """Bring-up on a cold cache at each axis count (:func:`bench_bringup`, ``counts``
    doubling): whole-process CPU seconds, the CPU each step adds per axis it adds
    (``ms_cpu_per_added_axis``: what is paid once, such as Python's start and the kernel's
    build, drops out), and ``growth``: the last step's over that of the span before it, from
    the first count to the last but one (1.0: linear).  The span, not the first doubling
    alone: 256 axes more cost a few tenths of a second of CPU, as much as the compiler's
    build moves from run to run, and a first step measured as nothing made the figure
    meaningless."""
    rows: dict[str, object] = {}
    cpus: list[float] = []
    steps: list[float] = []
    for k, n in enumerate(counts):
        r = bench_bringup(n, warm=False)
        if "error" in r:
            return {"error": f"{n} axes: {r['error']}"}
        cpus.append(float(r["process_cpu_s"]))  # type: ignore[arg-type]
        row = {"process_wall_s": r["process_wall_s"], "process_cpu_s": r["process_cpu_s"]}
        if k:
            steps.append((cpus[k] - cpus[k - 1]) / (n - counts[k - 1]))
            row["ms_cpu_per_added_axis"] = round(1000 * steps[-1], 3)
        rows[str(n)] = row
    before = (cpus[-2] - cpus[0]) / (counts[-2] - counts[0]) if len(counts) > 2 else 0.0
    return {
        "cache": COLD,
        "axes": rows,
        "ms_cpu_per_axis_before_last": round(1000 * before, 3),
        "growth": round(steps[-1] / before, 2) if before > 0 else None,
    }


#: the streaming figures (tools/bench_stream.py)
PT_DYNAMIC = "PT, dynamic FIFOs refilled every 20 ms (GT_PtSpace, GT_PtData per free slot)"
MOVE_ABSOLUTE = "a GT_MoveAbsolute to a new target on every axis every 20 ms"
GEAR = "per core: the first axis in Trap, the others in Gear on it (1:2)"
FOLLOW = "per core: the first axis in Trap, the others in Follow on it (a 16-point cam, endless)"
CRD = "per core: 2 XY coordinate systems (4 axes) on a path of lines and arcs, the others holding"
PVT = "PVT, a 3-point table per core (GT_PvtTable), GT_SetPvtLoop(a, 0): endless"


#: the cycle hooks :func:`bench_hooked_poll` compares with none: a ``[[fault]]`` table whose
#: trigger is far off (the fault injector waits for its time) and the same with smart homing
#: there too (a homing started and ended: its hook stays, with nothing to run)
HOOKED_CASES = ("none", "far_fault", "far_fault_smart_homing")
_FAR_FAULT = """
[[fault]]
kind = "drive_fault"
axis = 12
code = "overcurrent"
at_ms = 100000000
"""


def _hooked_session(case: str, machine: Path, moving: bool) -> None:
    """The 12-axis example bus in the auto clock, every axis on (``moving``: in long Trap
    moves), with the cycle hooks of ``case`` (:data:`HOOKED_CASES`)."""
    from gtecat import gt

    gt.GT_Close()
    mach = str(machine) if case != "none" else None
    ok = gt.GT_Open(eni=str(EXAMPLES / "twelve_axes.eni"), machine=mach, clock="auto", log="")
    assert ok == 0 and gt.GT_InitEcatComm() == 0
    ready = c_short()
    while gt.GT_IsEcatReady(byref(ready)) == 0 and ready.value != 1:
        gt.GTE_Wait(1)
    assert gt.GT_StartEcatComm() == 0 and gt.GT_Reset() == 0
    for a in range(1, 13):
        gt.GT_AxisOn(a)
    if case.endswith("smart_homing"):  # (a smart homing on axis 1, stopped: its hook stays)
        prm = gt.THomePrm()
        gt.GT_GetHomePrm(1, byref(prm))
        prm.mode = 20
        gt.GTE_Wait(20)
        assert gt.GT_GoHome(1, byref(prm)) == 0
        gt.GTE_Wait(20)
        assert gt.GT_Stop(1, 0) == 0
    gt.GTE_Wait(50)
    if moving:
        prm = gt.TTrapPrm()
        prm.acc, prm.dec = 0.5, 0.5
        for a in range(1, 13):
            gt.GT_PrfTrap(a)
            gt.GT_SetTrapPrm(a, byref(prm))
            gt.GT_SetVel(a, 20)
            gt.GT_SetPos(a, (-1) ** a * 50_000_000)
        gt.GT_Update(0xFFF)
    gt.GTE_Wait(20)


def bench_hooked_poll(
    seconds: float = 1.0, repeat: int = 3, block: int = 2000, moving: bool = False
) -> dict[str, object]:
    """µs per ``GT_GetSts(1, byref(s))`` on the auto clock (a cycle runs inside every
    20th call) with cycle hooks that stay quiet (:data:`HOOKED_CASES`) and with none: by
    the readers' C entry, and by its Python fast path (``.python``: what a replay calls);
    the cases in turn, ``repeat`` rounds of ``seconds`` each, best block of each; ratios
    to no hook."""
    from gtecat import gt

    clock = time.perf_counter
    best: dict[str, float] = {}
    with tempfile.TemporaryDirectory() as tmp:
        machine = Path(tmp) / "far_fault.toml"
        machine.write_text(_FAR_FAULT)
        for _ in range(repeat):
            for case in HOOKED_CASES:
                _hooked_session(case, machine, moving)
                s = c_long()
                p = byref(s)
                python = getattr(gt.GT_GetSts, "python", gt.GT_GetSts)  # (no C entry: itself)
                for way, fn in (("c_entry", gt.GT_GetSts), ("python", python)):
                    key = f"{case}_{way}_us"
                    rng = range(block)
                    t_end = clock() + seconds / 2
                    while clock() < t_end:
                        t0 = clock()
                        for _ in rng:
                            fn(1, p)
                        us = (clock() - t0) / block * 1e6
                        best[key] = min(best.get(key, us), us)
                gt.GT_Close()
    out: dict[str, object] = {k: round(v, 3) for k, v in best.items()}
    for case in HOOKED_CASES[1:]:
        for way in ("c_entry", "python"):
            out[f"{case}_{way}_ratio"] = round(best[f"{case}_{way}_us"] / best[f"none_{way}_us"], 3)
    out["moving"] = moving
    return out


def bench_fig5_2_io(seconds: float = 2.0, repeat: int = 3) -> dict[str, object]:
    """The manual's figure 5-2 application writing its IO outputs every millisecond (section
    5: 2 drives, 2 IO slaves): both axes in Trap (:func:`start_trap`), and every 1 ms
    ``GTE_Wait(1)``, each IO slave's input word read (``GT_EcatIOReadInput(slave, 0, 2,
    byref(w))``), its output word written with a new value (``GT_EcatIOWriteOutput``, the
    same shape), ``GT_GetSts(1, ...)``; lockstep clock.  ``rtf``: controller milliseconds
    per CPU millisecond, the best of ``repeat`` windows of ``seconds`` / ``repeat`` wall
    seconds."""
    from ctypes import c_ushort

    from gtecat import gt
    from tools.bench_scaling import BenchError, start_trap

    best = 0.0
    try:
        rc = gt.GT_Open(eni=str(FIG5_2), clock="lockstep", log="")
        ready = c_short()
        if rc or gt.GT_InitEcatComm():
            raise BenchError(f"GT_Open / GT_InitEcatComm: {gt.GTE_GetLastError()}")
        for _ in range(10_000):
            if gt.GT_IsEcatReady(byref(ready)) == 0 and ready.value == 1:
                break
            gt.GTE_Wait(1)
        if gt.GT_StartEcatComm() or gt.GT_AxisOn(1) or gt.GT_AxisOn(2):
            raise BenchError(f"start: {gt.GTE_GetLastError()}")
        gt.GTE_Wait(50)
        start_trap((1, 2))
        gt.GTE_Wait(100)
        w, s, k = c_ushort(), c_long(), 0
        wait, read, write, sts = (
            gt.GTE_Wait,
            gt.GT_EcatIOReadInput,
            gt.GT_EcatIOWriteOutput,
            gt.GT_GetSts,
        )
        for _ in range(repeat):
            ms = 0
            c0, t0 = time.process_time(), time.perf_counter()
            while time.perf_counter() - t0 < seconds / repeat:
                for _ in range(200):
                    wait(1)
                    k += 1
                    for sl in (2, 3):
                        read(sl, 0, 2, byref(w))
                        write(sl, 0, 2, byref(c_ushort(k & 0xFFFF)))
                    sts(1, byref(s), 1, None)
                ms += 200
            best = max(best, ms / max(time.process_time() - c0, 1e-9) / 1000)
        if sts(1, byref(s), 1, None) or not s.value & 0x400:  # (both still moving)
            raise BenchError(f"axis 1 stopped moving: status {s.value:#x}")
    except BenchError as exc:
        return {"error": str(exc)}
    finally:
        gt.GT_Close()
    return {
        "axes": 2,
        "what": "figure 5-2, both in Trap; every ms GTE_Wait(1), each IO slave's input word "
        "read and its output word written with a new value, GT_GetSts",
        "rtf": round(best, 1),
    }


def bench_crd_poll(
    seconds: float = 1.0, pairs: int = 3, n: int = 12, push_every: int = 0
) -> dict[str, object]:
    """Coordinated motion polled every cycle, as field applications do: ``n`` axes, two XY
    systems (axes 1-2 and 3-4, the crd figure's path), and after each 1 ms cycle
    ``GT_CrdStatus`` of both systems and ``GT_GetPrfPos`` of their four axes (``push_every``:
    and every that many cycles ``GT_CrdSpace`` and a ``GT_LnXY`` onto each running path, a
    segment streamed).  Controller milliseconds per CPU second with the axis bank (``auto``)
    and on the scalar path (``off``), measured in pairs back to back (the best window of
    each); ``ratio``: bank / scalar."""
    from ctypes import c_double, c_int32, c_short

    from tools.bench_scaling import bring_up, check, crd_plan, gtn, start_crd
    from tools.gen_axes_eni import write_axes_eni

    gt = importlib.import_module("gtecat.gt")
    plan = crd_plan(n)
    crd_axes = [a for a, s in plan.items() if s == "crd"]
    best = {"auto": 0.0, "off": 0.0}
    run, seg, pos, space = c_short(), c_int32(), c_double(), c_int32()
    prun, pseg, ppos, pspace = byref(run), byref(seg), byref(pos), byref(space)
    with tempfile.TemporaryDirectory() as tmp:
        eni = write_axes_eni(n, Path(tmp) / f"axes{n}.eni")
        for _ in range(pairs):
            for bank in ("auto", "off"):
                bring_up(eni, n, bank)
                try:
                    for a in plan:
                        gtn("AxisOn", a)
                    start_crd(crd_axes)
                    gt.GTE_Wait(50)
                    check(plan)
                    ms = 0
                    c0, t0 = time.process_time(), time.perf_counter()
                    while time.perf_counter() - t0 < seconds / pairs:
                        for k in range(100):
                            gt.GTE_Wait(1)
                            for crd in (1, 2):
                                gt.GT_CrdStatus(crd, prun, pseg, 0)
                            for a in crd_axes:
                                gt.GT_GetPrfPos(a, ppos)
                            if push_every and k % push_every == 0:
                                for crd in (1, 2):
                                    gt.GT_CrdSpace(crd, pspace, 0)
                                    x = 10_000 * (k // push_every % 2)
                                    gt.GT_LnXY(crd, x, 0, 20.0, 0.5, 20.0, 0)
                        ms += 100
                    cpu = max(time.process_time() - c0, 1e-9)
                    check(plan)
                finally:
                    gt.GT_Close()
                best[bank] = max(best[bank], ms / 1000 / cpu)
    return {
        "axes": n,
        "what": "2 XY systems, GT_CrdStatus x2 + GT_GetPrfPos x4 after every cycle"
        + (f", a segment pushed onto each every {push_every} cycles" if push_every else ""),
        "rtf_cpu_bank": round(best["auto"], 2),
        "rtf_cpu_scalar": round(best["off"], 2),
        "ratio": round(best["auto"] / best["off"], 2) if best["off"] else None,
    }


WAIT_BUSES = ("fig5_2", "12_axes", "12_axes_far_fault")


def _wait_session(bus: str, eni_dir: Path) -> None:
    """A bus in the auto clock (GT_Open's default) brought up by GT_* calls, its axes on
    and moving in the bank: ``fig5_2`` (the manual's figure 5-2 bus, axis 1 jogging, axis 2
    on), ``12_axes`` (a generated 12-axis bus, odd axes in long Trap moves, even ones
    jogging), ``12_axes_far_fault`` (the same with a machine description's ``[[fault]]``
    far off: the fault injector's cycle hook, quiet)."""
    from gtecat import gt

    gt.GT_Close()
    machine = None
    if bus == "fig5_2":
        eni, n = FIG5_2, 2
    else:
        from tools.gen_axes_eni import write_axes_eni

        eni, n = write_axes_eni(12, eni_dir / "axes12.eni"), 12
        if bus.endswith("far_fault"):
            machine = eni_dir / "far_fault.toml"
            machine.write_text(_FAR_FAULT)
    opened = gt.GT_Open(eni=str(eni), machine=machine and str(machine), log="")
    assert opened == 0 and gt.GT_InitEcatComm() == 0
    ready = c_short()
    while gt.GT_IsEcatReady(byref(ready)) != 0 or ready.value != 1:
        gt.GTE_Wait(1)
    assert gt.GT_StartEcatComm() == 0
    for a in range(1, n + 1):
        assert gt.GT_AxisOn(a) == 0
    gt.GTE_Wait(20)
    jog = gt.TJogPrm()
    jog.acc, jog.dec = 0.1, 0.1
    trap = gt.TTrapPrm()
    trap.acc, trap.dec = 0.5, 0.5
    for a in (1,) if bus == "fig5_2" else range(1, n + 1):
        if a % 2 or bus == "fig5_2":
            assert gt.GT_PrfJog(a) == 0 and gt.GT_SetJogPrm(a, byref(jog)) == 0
            assert gt.GT_SetVel(a, 10.0) == 0
        else:
            assert gt.GT_PrfTrap(a) == 0 and gt.GT_SetTrapPrm(a, byref(trap)) == 0
            assert gt.GT_SetVel(a, 20.0) == 0 and gt.GT_SetPos(a, 50_000_000) == 0
    assert gt.GT_Update(1 if bus == "fig5_2" else (1 << n) - 1) == 0
    gt.GTE_Wait(200)  # (past the ramps: the moves' steady part)


def bench_gte_wait(seconds: float = 1.0, repeat: int = 3, block: int = 500) -> dict[str, object]:
    """µs per ``GTE_Wait(1)`` (and per ``GTE_Wait(10)``, whose difference is the cost of the
    nine cycles more) on the auto clock, the axes moving in the bank (:func:`_wait_session`):
    a wait's fixed cost, which a field application paced by waits pays every controller
    millisecond.  ``fast``: the public function (its C entry, where there is one);
    ``python``: the Python fast function behind that entry (what the public function is
    without one: ``GTECAT_CENTRY=0``); ``general``: the table path with the quick way off
    (``Controller.QUICK_WAIT``: what every wait took before it), in alternate blocks of the
    same session, the best block of each (its CPU time); ``ratio``: general / fast;
    ``cycles``: the controller cycles one wait ran (1 ms cycle time, the calls' latency
    included)."""
    from gtecat import gt
    from gtecat.controller.core import Controller

    clock = time.perf_counter
    cpu = time.process_time  # (the blocks' own CPU: on a shared machine the wall's is noisier)
    best: dict[str, float] = {}
    cycles: dict[str, float] = {}
    ways = [("fast", gt.GTE_Wait, True), ("general", gt.GTE_Wait.slow, False)]
    if hasattr(gt.GTE_Wait, "python"):
        ways.insert(1, ("python", gt.GTE_Wait.python, True))
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(repeat):
            for bus in WAIT_BUSES:
                _wait_session(bus, Path(tmp))
                ctl = gt.GTE_Controller()
                for ms in (1, 10):
                    t_end = clock() + seconds / 4
                    while clock() < t_end:
                        for way, wait, quick in ways:
                            key = f"gte_wait_{ms}ms_{bus}_{way}"
                            Controller.QUICK_WAIT = quick
                            try:
                                c0 = ctl.clock.cycles
                                t0 = cpu()
                                for _ in range(block):
                                    wait(ms)
                                us = (cpu() - t0) / block * 1e6
                            finally:
                                Controller.QUICK_WAIT = True
                            best[f"{key}_us"] = min(best.get(f"{key}_us", us), us)
                            cycles[f"{key}_cycles"] = (ctl.clock.cycles - c0) / block
                gt.GT_Close()
    out: dict[str, object] = {k: round(v, 3) for k, v in best.items()}
    out.update(cycles)
    for bus in WAIT_BUSES:
        for ms in (1, 10):
            key = f"gte_wait_{ms}ms_{bus}"
            out[f"{key}_ratio"] = round(best[f"{key}_general_us"] / best[f"{key}_fast_us"], 2)
        out[f"per_cycle_{bus}_fast_us"] = round(
            (best[f"gte_wait_10ms_{bus}_fast_us"] - best[f"gte_wait_1ms_{bus}_fast_us"]) / 9, 3
        )
    return out


def compiled_parts() -> dict[str, object]:
    """Build (or load) the bank's compiled parts before any figure is measured, and say how
    long that took: on a fresh machine or checkout the first controller would otherwise
    start their build in a process of its own and run the numpy cycle until it ends, so the
    first figures would measure the build beside numpy (128 axes in Trap: 7x instead of
    150x on an idle machine) rather than the steady state the figures are about."""
    from gtecat.controller import bank_crd, bank_kernel, bank_pvt, bank_slaves

    t0, c0 = time.perf_counter(), time.process_time()
    out: dict[str, object] = {}
    for name, lib in (
        ("bank_kernel", bank_kernel.library),
        ("bank_crd", bank_crd.library),
        ("bank_slaves", bank_slaves.library),
        ("bank_pvt", bank_pvt.library),
    ):
        if name == "bank_kernel" and bank_kernel.wanted() == "numpy":
            out[name] = "not built: GTECAT_BANK_KERNEL=numpy"
            continue
        why = lib()[1]
        if why:
            out[name] = why
    out["wall_s"] = round(time.perf_counter() - t0, 3)
    out["cpu_s"] = round(time.process_time() - c0, 3)  # (the compiler's own is not counted)
    return out


def issue17(seconds: float = 1.5, repeat: int = 3, only: Sequence[str] = ()) -> dict[str, object]:
    """The many-axes figures, measured one after the other in this run (``only``: those),
    after the compiled parts are there (:func:`compiled_parts`, reported as ``build``)."""
    from tools.bench_scaling import (
        crd_plan,
        run_bus,
        run_drive_homing,
        run_gohome,
        run_legacy_home,
    )

    build = compiled_parts()

    def rtf(
        n: int,
        plan: dict[int, str],
        target: float | None,
        what: str,
        bank: str | None = None,
        eni: Path | None = None,
    ) -> dict[str, object]:
        """``run_bus`` on ``n`` generated axes (``eni``: that bus instead)."""
        r = {
            "axes": n,
            "what": what,
            **run_bus(n, plan, seconds=seconds, repeat=repeat, bank=bank, eni_file=eni),
        }
        return r if target is None else _figure(r, "rtf", target)

    def every(n: int, state: str) -> dict[int, str]:
        return dict.fromkeys(range(1, n + 1), state)

    def stream(n: int, kind: str, target: float, what: str) -> dict[str, object]:
        """An application streaming calls into ``n`` moving axes (tools/bench_stream.py)."""
        from tools.bench_stream import run_stream

        r = {"axes": n, "what": what, **run_stream(n, kind, seconds, repeat)}
        return _figure(r, "rtf_cpu", target)  # (per CPU second: the calls are the load)

    half = {a: "moving" if a % 2 else "idle" for a in range(1, 65)}
    homed_half = {a: "moving" if a % 2 else "homed6" for a in range(1, 65)}

    def gohome(n: int, mode: int, target: float | None) -> dict[str, object]:
        r = {"axes": n, "what": f"smart homing (GT_GoHome) mode {mode}, start to end"}
        r |= run_gohome(n, mode, repeat=repeat)
        return r if target is None else _figure(r, "rtf", target)

    def legacy_home(n: int, target: float | None) -> dict[str, object]:
        r = {"axes": n, "what": "the older cards' homing (GT_HomeInit, GT_Home), start to end"}
        r |= run_legacy_home(n, repeat=repeat)
        return r if target is None else _figure(r, "rtf", target)

    def drive_home(
        n: int, method: int, target: float | None, setup: bool = False
    ) -> dict[str, object]:
        what = "set-up (homing mode, parameters) and start" if setup else "start"
        r = {"axes": n, "what": f"drive homing (mode 6) method {method}, {what} to end"}
        r |= run_drive_homing(n, method, repeat=repeat, setup=setup)
        return r if target is None else _figure(r, "rtf", target)

    figures: dict[str, Callable[[], dict[str, object]]] = {
        "rtf_fig5_2_trap": lambda: rtf(2, every(2, "moving"), 300, FIG5_TEXT, eni=FIG5_2),
        "rtf_fig5_2_trap_io_every_ms": lambda: _figure(
            bench_fig5_2_io(2 * seconds, repeat), "rtf", 300
        ),
        "rtf_1_axis_trap": lambda: rtf(1, every(1, "moving"), 500, "one axis moving in Trap"),
        "rtf_12_axes_trap": lambda: rtf(12, every(12, "moving"), 20, "all 12 moving in Trap"),
        "rtf_64_axes_32_trap_32_holding": lambda: rtf(
            64, half, 10, "odd axes moving in Trap, even axes enabled and holding"
        ),
        "rtf_64_axes_trap_lead_screw": lambda: rtf(
            64, every(64, "screw"), 10, "all 64 moving in Trap, lead-screw compensation on"
        ),
        "rtf_128_axes_trap": lambda: rtf(128, every(128, "moving"), 100, "all 128 moving in Trap"),
        "rtf_12_axes_homing_17": lambda: rtf(
            12, every(12, "homing"), None, "drive homing method 17"
        ),
        "rtf_64_axes_homing_17": lambda: rtf(64, every(64, "homing"), 10, "drive homing method 17"),
        **{
            f"rtf_64_axes_drive_home_{m}": (lambda m=m: drive_home(64, m, 10))
            for m in (1, 2, 17, 24, 27)
        },
        "rtf_64_axes_drive_home_35_setup": lambda: drive_home(64, 35, 10, setup=True),
        "rtf_64_axes_gohome_10": lambda: gohome(64, 10, 10),
        "rtf_64_axes_gohome_20": lambda: gohome(64, 20, 10),
        "rtf_64_axes_gohome_11": lambda: gohome(64, 11, 10),
        "rtf_64_axes_gohome_12": lambda: gohome(64, 12, 10),
        "rtf_64_axes_gohome_13": lambda: gohome(64, 13, 10),
        "rtf_64_axes_gohome_22": lambda: gohome(64, 22, 10),
        "rtf_64_axes_gohome_30": lambda: gohome(64, 30, 10),
        "rtf_64_axes_gohome_40": lambda: gohome(64, 40, 10),
        "rtf_64_axes_gohome_41": lambda: gohome(64, 41, 10),
        "rtf_64_axes_home_legacy": lambda: legacy_home(64, 10),
        "rtf_64_axes_homed_mode6": lambda: rtf(
            64, every(64, "homed6"), 10, "homed (method 35), left in homing mode 6, holding"
        ),
        "rtf_64_axes_homed_mode6_32_trap": lambda: rtf(
            64,
            homed_half,
            10,
            "even axes homed and left in homing mode 6, odd axes moving in Trap",
        ),
        "rtf_12_axes_trap_scalar": lambda: rtf(
            12, every(12, "moving"), None, "all 12 moving in Trap, scalar path (bank off)", "off"
        ),
        "rtf_12_axes_pt": lambda: rtf(12, every(12, "pt"), None, "PT, static FIFO, endless loop"),
        "rtf_64_axes_pt": lambda: rtf(64, every(64, "pt"), 10, "PT, static FIFO, endless loop"),
        "rtf_64_axes_pvt": lambda: rtf(64, every(64, "pvt"), 10, PVT),
        "rtf_64_axes_pt_dynamic": lambda: stream(64, "pt_dynamic", 10, PT_DYNAMIC),
        "rtf_64_axes_move_absolute": lambda: stream(64, "move_absolute", 10, MOVE_ABSOLUTE),
        "rtf_12_axes_gear": lambda: rtf(12, every(12, "gear"), None, GEAR),
        "rtf_64_axes_gear": lambda: rtf(64, every(64, "gear"), 10, GEAR),
        "rtf_12_axes_follow": lambda: rtf(12, every(12, "follow"), None, FOLLOW),
        "rtf_64_axes_follow": lambda: rtf(64, every(64, "follow"), 10, FOLLOW),
        "rtf_12_axes_crd": lambda: rtf(12, crd_plan(12), None, CRD),
        "rtf_64_axes_crd": lambda: rtf(64, crd_plan(64), 10, CRD),
        "crd_polled_12_axes_bank_vs_scalar": lambda: _figure(
            bench_crd_poll(2 * seconds), "ratio", 1.0
        ),
        "crd_streamed_12_axes_bank_vs_scalar": lambda: _figure(
            bench_crd_poll(2 * seconds, push_every=10), "ratio", 1.0
        ),
        "gt_get_sts_vs_argument": lambda: _figure(bench_get_sts(seconds), "ratio", 4, at_most=True),
        "call_shapes_vs_arguments": lambda: _figure(
            bench_call_shapes(2 * seconds), "worst", 4, at_most=True
        ),
        "every_call_shape_vs_arguments": lambda: _figure(
            bench_every_shape(10 * seconds), "worst", 4, at_most=True
        ),
        "every_call_shape_vs_arguments_auto": lambda: _figure(
            bench_every_shape(12 * seconds, clock="auto", raw=True), "worst", 4, at_most=True
        ),
        "rss_128_axes_moving": lambda: _figure(
            bench_rss(128, min(seconds, 1.0)), "mb_per_axis", 0.1, at_most=True
        ),
        "rss_1024_axes_moving": lambda: _figure(
            bench_rss(1024, min(seconds, 1.0)), "mb_per_axis", 0.1, at_most=True
        ),
        "bringup_512_axes_to_op": lambda: _figure(
            bench_bringup(512), "process_wall_s", 3.0, at_most=True
        ),
        "bringup_1024_axes_to_op": lambda: _figure(
            bench_bringup(1024), "process_wall_s", 6.0, at_most=True
        ),
        "bringup_growth": lambda: _figure(bench_bringup_growth(), "growth", 1.5, at_most=True),
    }
    unknown = sorted(set(only) - set(figures))
    if unknown:
        raise SystemExit(f"unknown figure(s): {', '.join(unknown)}; known: {', '.join(figures)}")
    out: dict[str, object] = {
        name: make() for name, make in figures.items() if not only or name in only
    }
    out["ok"] = all(isinstance(v, dict) and v.get("ok", True) for v in out.values())
    out["build"] = build
    return out


def main() -> int:
    ap = argparse.ArgumentParser(description="Every benchmark figure, as one JSON object.")
    ap.add_argument("--quick", action="store_true", help="shorter windows (noisier figures)")
    ap.add_argument(
        "--hooked",
        action="store_true",
        help="only a polling loop on the auto clock with quiet cycle hooks against none",
    )
    ap.add_argument("--targets", action="store_true", help="only the many-axes figures")
    ap.add_argument("--wait", action="store_true", help="only GTE_Wait's cost (auto clock)")
    ap.add_argument("--issue17", dest="targets", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--seconds", type=float, help="wall seconds per many-axes figure (1.5)")
    ap.add_argument("--repeat", type=int, default=3, help="windows per real-time factor")
    ap.add_argument("--rss-child", type=int, metavar="AXES", help=argparse.SUPPRESS)
    ap.add_argument("--eni", default="", help=argparse.SUPPRESS)
    ap.add_argument("--bringup-child", metavar="ENI", help=argparse.SUPPRESS)
    ap.add_argument(
        "--only",
        default="",
        help="comma-separated figure names of --targets to measure (e.g. rtf_128_axes_trap)",
    )
    args = ap.parse_args()
    if args.rss_child is not None:
        return rss_child(args.rss_child, args.seconds or 0.5, args.eni)
    if args.bringup_child:
        return bringup_child(args.bringup_child)
    secs = 0.5 if args.quick else 2.0
    secs17 = args.seconds or (0.6 if args.quick else 1.5)
    if args.hooked:
        hooked = {
            "idle": bench_hooked_poll(secs / 2, args.repeat),
            "moving": bench_hooked_poll(secs / 2, args.repeat, moving=True),
        }
        print(json.dumps({"hooked_poll": hooked}, indent=2))
        return 0
    if args.wait:
        print(json.dumps({"gte_wait": bench_gte_wait(secs / 2, args.repeat)}, indent=2))
        return 0
    only = [x for x in args.only.split(",") if x]
    if args.targets or only:
        print(json.dumps({"targets": issue17(secs17, args.repeat, only)}, indent=2))
        return 0
    out: dict[str, object] = {}
    try:
        from tools.bench_eni import bench_read

        out["eni_read_64_slaves"] = bench_read(64)
    except ModuleNotFoundError:
        pass
    fig = EXAMPLES / "manual_fig5_2.eni"
    twelve = EXAMPLES / "twelve_axes.eni"
    out["cycles_per_s_fig5_2_bus_only"] = round(bench_cycles(fig, plain=True, seconds=secs))
    out["cycles_per_s_fig5_2_drives"] = round(bench_cycles(fig, plain=False, seconds=secs))
    if twelve.exists():
        out["cycles_per_s_12_axes_bus_only"] = round(bench_cycles(twelve, plain=True, seconds=secs))
        out["cycles_per_s_12_axes_drives"] = round(bench_cycles(twelve, plain=False, seconds=secs))
    out["gt_get_ecat_raw_data_us"] = round(bench_raw_call(2000 if args.quick else 20000), 2)
    out["gte_wait"] = bench_gte_wait(secs / 2, args.repeat)
    ctl12 = bench_controller_12_axes(secs)
    if ctl12 is not None:
        out["cycles_per_s_12_axes_controller_moving"] = round(ctl12)
    for name in ("bench_drive", "bench_homing", "bench_homing_gt", "bench_motion"):
        try:
            mod = importlib.import_module(f"tools.{name}")
        except ModuleNotFoundError:
            continue
        fn = getattr(mod, "summary", None)
        if fn is not None:
            out[name.removeprefix("bench_")] = fn(quick=args.quick)
    out["targets"] = issue17(secs17, args.repeat)
    print(json.dumps(out, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
