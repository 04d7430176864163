"""The axes part of ``gtecat demo``: enable, home, probe during a Trap move, IO; CSV and PNG.

Runs after the bus part of :mod:`gtecat.cli.demo_cmd` on the manual's figure 5-2
bus (two GTHD drives, two IO slaves) with ``gtecat/data/demo_machine.toml``:

1. ``GT_AxisOn`` on both axes (CiA-402 walk to *operation enabled*).
2. Homing both axes at once, manual example 5-2: ``GT_SetHomingMode(axis, 6)``,
   ``GT_SetEcatHomingPrm``, ``GT_StartEcatHoming``, poll ``GT_GetEcatHomingStatus``
   until bit 0 (done), ``GT_SetHomingMode(axis, 8)``.  Axis 1 uses method 3 (home
   switch + index pulse, the manual's example), axis 2 method 19 (the same switch
   edge without the index).  Figure 5-2 maps no 6060h/6061h, so the mode goes by SDO
   (manual 5.2.2.2).
3. Probe 1 armed (``GT_SetTouchProbeFunction``, manual example 5-3) and a Trap
   move of both axes started by one ``GT_Update``; axis 1 crosses the probe mark and
   ``GT_GetTouchProbeStatus`` reports the captured position, checked against the
   mark's position in the homed coordinates.
4. IO: "homed" and "probe captured" lamps on IO slave 3 through
   ``GT_EcatIOBitWriteOutput``, wired back to its inputs and read with
   ``GT_EcatIOReadInput``; the axis 1 statusword read through ``GT_GetEcatRawData``
   at the manual's offset 6.

A step whose ``GT_*`` functions this build lacks is skipped with a line saying so.
Everything is recorded every cycle (:class:`gtecat.controller.recorder.Recorder`) and written to
``demo.csv`` and ``demo.png``.
"""

from __future__ import annotations

from collections.abc import Callable
from ctypes import byref, c_double, c_long, c_short, c_ubyte, c_ushort
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..controller.recorder import Recorder, signal
from ..controller.trace_plot import plot_noisy

Say = Callable[[Any, str], None]

HOMING_CALLS = (
    "GT_SetHomingMode",
    "GT_SetEcatHomingPrm",
    "GT_StartEcatHoming",
    "GT_GetEcatHomingStatus",
)
PROBE_CALLS = ("GT_SetTouchProbeFunction", "GT_GetTouchProbeStatus")
TRAP_CALLS = (
    "GT_PrfTrap",
    "GT_SetTrapPrm",
    "GT_SetPos",
    "GT_SetVel",
    "GT_Update",
    "GT_GetSts",
    "TTrapPrm",
)


@dataclass(frozen=True)
class HomingPlan:
    """One axis's GT_SetEcatHomingPrm arguments (speeds counts/s, acc counts/s²)."""

    axis: int
    method: int
    speed1: float  # 6099h:01, search for the switch
    speed2: float  # 6099h:02, final approach and index search
    acc: float  # 609Ah
    what: str


# The scenario, matched to gtecat/data/demo_machine.toml (machine positions, counts).
HOMING = (
    HomingPlan(1, 3, 40000, 4000, 400000, "home switch + index pulse"),
    HomingPlan(2, 19, 30000, 3000, 300000, "home switch edge, no index"),
)
PROBE_FUNCTION = 0x0011  # probe 1 on, first event, rising edge (GT_SetTouchProbeFunction)
PROBE_MARK = 150000.0  # axis 1's probe 1 mark (machine position) in demo_machine.toml
TRAP_TARGETS = {1: 80000, 2: 30000}  # pulses after homing
TRAP_VEL = 60.0  # pulse/ms
TRAP_ACC = 0.6  # pulse/ms²
TRAP_SMOOTH = 20  # ms
LAMP_SLAVE = 3  # IO slave 3: DO bit 0 "homed", bit 1 "probe captured", wired to its DI
WAIT_STEP_MS = 2
HOLD_MS = 150
SETTLE_MS = 20_000

TRACE = (
    "axis1.prf",
    "axis1.enc",
    "axis1.sw",
    "axis1.machine",
    "0:0x60FD:0",
    "axis2.prf",
    "axis2.enc",
    "axis2.sw",
    "axis2.machine",
    "1:0x60FD:0",
    "3:0x7000:1",
    "axis1.mode",  # 6061h: from the drive (figure 5-2 does not map it)
    "axis2.mode",
)


@dataclass
class DemoRun:
    """What happened, for the figure and for tests."""

    recorder: Recorder | None = None
    skipped: list[str] = field(default_factory=list)
    rc: dict[str, int] = field(default_factory=dict)
    homing: dict[int, tuple[float, float]] = field(default_factory=dict)  # axis: (t0, t1) ms
    home_status: dict[int, int] = field(default_factory=dict)
    home_machine: dict[int, float] = field(default_factory=dict)
    probe_value: int | None = None
    probe_expected: float | None = None
    moved: dict[int, int] = field(default_factory=dict)
    lamps: int | None = None
    files: list[Path] = field(default_factory=list)

    def problems(self) -> list[str]:
        """What did not go as the demo tells it (skipped steps are not problems)."""
        out = [f"{step} returned {rc}" for step, rc in self.rc.items() if rc != 0]
        out += [f"axis {a} homing status {st}" for a, st in self.home_status.items() if st != 3]
        if self.probe_expected is not None and self.probe_value != round(self.probe_expected):
            out.append(f"probe captured {self.probe_value}, expected {self.probe_expected:.0f}")
        return out


def _missing(gt: Any, names: tuple[str, ...]) -> list[str]:
    return [n for n in names if not hasattr(gt, n)]


def _skip(gt: Any, say: Say, run: DemoRun, step: str, names: tuple[str, ...]) -> bool:
    miss = _missing(gt, names)
    if miss:
        say(gt, f"{step}: skipped, this build lacks {', '.join(miss)}")
        run.skipped.append(step)
    return bool(miss)


def _wait(gt: Any, pred: Callable[[], bool], ms: int = SETTLE_MS) -> bool:
    """Poll ``pred`` while controller time passes (GTE_Wait works in every clock mode)."""
    waited = 0
    while not pred():
        if waited >= ms:
            return False
        gt.GTE_Wait(WAIT_STEP_MS)
        waited += WAIT_STEP_MS
    return True


def _why(gt: Any, rc: int) -> str:
    return "" if rc == 0 else f" ({gt.GTE_GetLastError()})"


def _enc(gt: Any, axis: int) -> int:
    pos = c_long()
    gt.GT_GetEcatEncPos(axis, byref(pos))
    return pos.value


def _sw(gt: Any, axis: int) -> int:
    buf = (c_ubyte * 2)()
    gt.GT_GetEcatAxisPdoData(axis, 0x6041, buf)
    return int.from_bytes(bytes(buf), "little")


def _now(gt: Any) -> float:
    return gt.GTE_Controller().clock.now_ns / 1e6


def _machine(gt: Any, axis: int) -> float:
    """Where the mechanics stand (GTE_GetMachinePos if present, else the recorder's view)."""
    if hasattr(gt, "GTE_GetMachinePos"):
        pos = c_double()
        if gt.GTE_GetMachinePos(axis, byref(pos)) == 0:
            return float(pos.value)
    return signal(gt.GTE_Controller(), f"axis{axis}.machine")()


# --- steps ---------------------------------------------------------------------------------------
INDENT = " " * 12  # under the "[  1234 ms] " stamp of demo_cmd.say


def _say(gt: Any, say: Say, first: str, *more: str) -> None:
    """One log entry: a headline, then the calls and values on indented lines."""
    say(gt, "\n".join([first, *(INDENT + m for m in more if m)]))


def enable(gt: Any, say: Say, run: DemoRun) -> bool:
    rcs = [gt.GT_AxisOn(a) for a in (1, 2)]
    run.rc["GT_AxisOn"] = max(rcs, key=abs)
    ok = rcs == [0, 0]
    sws = ", ".join(f"0x{_sw(gt, a):04X}" for a in (1, 2))
    _say(
        gt,
        say,
        "servo on: both drives in operation enabled" if ok else "servo on failed",
        f"GT_AxisOn(1) = {rcs[0]}, GT_AxisOn(2) = {rcs[1]}; statusword 6041h = {sws}"
        + _why(gt, run.rc["GT_AxisOn"]),
    )
    if run.recorder is not None:
        run.recorder.mark("servo on")
    return ok


def home(gt: Any, say: Say, run: DemoRun) -> bool:
    if _skip(gt, say, run, "homing", HOMING_CALLS):
        return False
    ctl = gt.GTE_Controller()
    for p in HOMING:
        by_sdo = ctl.layout.axis_entry(p.axis, 0x6060, 0) is None
        rcs = [
            gt.GT_SetHomingMode(p.axis, 6),
            gt.GT_SetEcatHomingPrm(p.axis, p.method, p.speed1, p.speed2, p.acc, 0, 0),
            gt.GT_StartEcatHoming(p.axis),
        ]
        run.rc[f"home{p.axis}"] = max(rcs, key=abs)
        run.homing[p.axis] = (_now(gt), _now(gt))
        _say(
            gt,
            say,
            f"axis {p.axis}: homing started, method {p.method} ({p.what})",
            f"GT_SetHomingMode({p.axis}, 6) = {rcs[0]}"
            + (" (6060h not in the PDO map: by SDO, manual 5.2.2.2)" if by_sdo else ""),
            f"GT_SetEcatHomingPrm({p.axis}, {p.method}, {p.speed1:g}, {p.speed2:g}, {p.acc:g}, "
            f"0, 0) = {rcs[1]}; GT_StartEcatHoming({p.axis}) = {rcs[2]}"
            + _why(gt, run.rc[f"home{p.axis}"]),
        )
    pending = {p.axis: p for p in HOMING if run.rc[f"home{p.axis}"] == 0}
    status = c_short()

    def poll() -> bool:
        for a in list(pending):
            rc = gt.GT_GetEcatHomingStatus(a, byref(status))
            if rc != 0 or status.value & 1:
                finish(pending.pop(a), rc, status.value)
        return not pending

    def finish(p: HomingPlan, rc: int, st: int) -> None:
        t0 = run.homing[p.axis][0]
        run.homing[p.axis] = (t0, _now(gt))
        run.home_status[p.axis] = st if rc == 0 else -1
        rc8 = gt.GT_SetHomingMode(p.axis, 8)
        if rc == 0 and st & 2:
            run.home_machine[p.axis] = _machine(gt, p.axis)
            _say(
                gt,
                say,
                f"axis {p.axis}: homed in {(run.homing[p.axis][1] - t0) / 1000:.2f} s; the home "
                f"point, machine position {run.home_machine[p.axis]:.0f}, now reads "
                f"{_enc(gt, p.axis)}",
                f"GT_GetEcatHomingStatus({p.axis}) = {rc}: status {st} (done, success); "
                f"GT_SetHomingMode({p.axis}, 8) = {rc8}: CSP",
            )
            if run.recorder is not None:
                run.recorder.mark(f"axis {p.axis} homed")
        else:
            _say(
                gt,
                say,
                f"axis {p.axis}: homing failed",
                f"GT_GetEcatHomingStatus({p.axis}) = {rc}, status {st} (bit 2 = error)"
                + _why(gt, rc),
            )

    if not _wait(gt, poll):
        say(gt, f"homing did not finish within {SETTLE_MS / 1000:g} s on axes {sorted(pending)}")
        return False
    ok = all(run.home_status.get(p.axis, 0) & 2 for p in HOMING)
    if ok:
        rc = gt.GT_EcatIOBitWriteOutput(LAMP_SLAVE, 0, 0, 1)
        _say(
            gt,
            say,
            f"'homed' lamp on: IO slave {LAMP_SLAVE} output bit 0",
            f"GT_EcatIOBitWriteOutput({LAMP_SLAVE}, 0, 0, 1) = {rc}" + _why(gt, rc),
        )
    return ok


def probe_and_move(gt: Any, say: Say, run: DemoRun, homed: bool) -> None:
    probe = not _skip(gt, say, run, "touch probe", PROBE_CALLS)
    if _skip(gt, say, run, "Trap move", TRAP_CALLS):
        return
    if probe:
        rc = gt.GT_SetTouchProbeFunction(1, PROBE_FUNCTION)
        run.rc["probe_arm"] = rc
        by_sdo = gt.GTE_Controller().layout.axis_entry(1, 0x60B8, 0) is None
        _say(
            gt,
            say,
            "axis 1: probe 1 armed for the first rising edge (manual example 5-3)",
            f"GT_SetTouchProbeFunction(1, 0x{PROBE_FUNCTION:04X}) = {rc}"
            + (" (60B8h is not in the PDO map: sent by SDO)" if by_sdo else "")
            + _why(gt, rc),
        )
    starts = {a: _enc(gt, a) for a in TRAP_TARGETS}
    rcs: list[int] = []
    mask = 0
    for a, target in TRAP_TARGETS.items():
        prm = gt.TTrapPrm()
        prm.acc, prm.dec, prm.velStart, prm.smoothTime = TRAP_ACC, TRAP_ACC, 0, TRAP_SMOOTH
        rcs += [
            gt.GT_PrfTrap(a),
            gt.GT_SetTrapPrm(a, byref(prm)),
            gt.GT_SetPos(a, target),
            gt.GT_SetVel(a, TRAP_VEL),
        ]
        mask |= 1 << (a - 1)
    rcs.append(gt.GT_Update(mask))
    run.rc["trap"] = max(rcs, key=abs)
    _say(
        gt,
        say,
        "Trap move of both axes, started together by one GT_Update",
        f"GT_PrfTrap, GT_SetTrapPrm(acc=dec={TRAP_ACC:g}, smoothTime={TRAP_SMOOTH}), "
        f"GT_SetVel({TRAP_VEL:g}) on axes 1, 2: "
        + ("all 0" if max(rcs[:-1], key=abs) == 0 else str(rcs[:-1])),
        ", ".join(f"GT_SetPos({a}, {t})" for a, t in TRAP_TARGETS.items())
        + f"; GT_Update(0x{mask:X}) = {rcs[-1]}"
        + _why(gt, run.rc["trap"]),
    )
    if run.recorder is not None:
        run.recorder.mark("Trap start")
    sts = c_long()

    def moving() -> bool:
        return any(gt.GT_GetSts(a, byref(sts)) == 0 and sts.value & 0x400 for a in TRAP_TARGETS)

    if not _wait(gt, lambda: not moving()):
        run.rc["trap_end"] = 1
        say(gt, f"Trap move still planning after {SETTLE_MS / 1000:g} s")
    gt.GTE_Wait(30)  # the drives settle on the last set-point
    run.moved = {a: _enc(gt, a) - starts[a] for a in TRAP_TARGETS}
    err = _max_following_error(run.recorder)
    _say(
        gt,
        say,
        "Trap move done: "
        + ", ".join(f"axis {a} at {_enc(gt, a)} (moved {run.moved[a]:+d})" for a in TRAP_TARGETS),
        "GT_GetSts bit 10 (planning) cleared; largest following error "
        + ", ".join(f"axis {a} {e:.0f}" for a, e in err.items())
        + " counts",
    )
    if probe:
        _probe_result(gt, say, run, homed)


def _max_following_error(rec: Recorder | None) -> dict[int, float]:
    if rec is None or rec.n == 0:
        return {}
    t0 = max((ms for ms, text in rec.events if text == "Trap start"), default=0.0)
    sel = rec.data[:, 0] >= t0
    return {
        a: float(np.max(np.abs(rec.column(f"axis{a}.prf")[sel] - rec.column(f"axis{a}.enc")[sel])))
        for a in TRAP_TARGETS
    }


def _probe_result(gt: Any, say: Say, run: DemoRun, homed: bool) -> None:
    st = c_ushort()
    v = [c_long() for _ in range(4)]
    rc = gt.GT_GetTouchProbeStatus(1, byref(st), *(byref(x) for x in v))
    run.rc["probe_status"] = rc
    call = f"GT_GetTouchProbeStatus(1, ...) = {rc}: 60B9h 0x{st.value:04X}"
    if rc != 0 or not st.value & 0x2:
        _say(gt, say, "axis 1: the probe captured nothing", call + _why(gt, rc))
        return
    run.probe_value = v[0].value
    check = ""
    if homed and 1 in run.home_machine:
        run.probe_expected = PROBE_MARK - run.home_machine[1]
        diff = v[0].value - run.probe_expected
        check = (
            f"the mark at machine position {PROBE_MARK:.0f} is {run.probe_expected:.0f} in "
            f"the homed coordinates: {'exact' if abs(diff) < 1 else f'off by {diff:+.0f}'}"
        )
    _say(
        gt,
        say,
        f"axis 1: probe 1 captured position {v[0].value} on the rising edge of the mark",
        call + f" (bit 1: rising edge latched), 60BAh = {v[0].value}",
        check,
    )
    if run.recorder is not None:
        _mark_probe_edge(run.recorder)
    rc = gt.GT_EcatIOBitWriteOutput(LAMP_SLAVE, 0, 1, 1)
    _say(
        gt,
        say,
        f"'probe' lamp on: IO slave {LAMP_SLAVE} output bit 1",
        f"GT_EcatIOBitWriteOutput({LAMP_SLAVE}, 0, 1, 1) = {rc}" + _why(gt, rc),
    )


def _mark_probe_edge(rec: Recorder) -> None:
    """Mark the cycle where 60FDh bit 16 (probe input 1) rose: the capture moment."""
    din = rec.column("0:0x60FD:0").astype(np.int64)
    rises = np.flatnonzero((din[1:] >> 16 & 1) > (din[:-1] >> 16 & 1))
    if rises.size:
        rec.events.append((float(rec.data[rises[-1] + 1, 0]), "probe 1 capture"))
        rec.events.sort()


def io(gt: Any, say: Say, run: DemoRun) -> None:
    gt.GT_EcatIOSynch()  # the lamp outputs go out; the wired inputs come back next cycle
    gt.GTE_Wait(2)
    buf = (c_ubyte * 4)()
    rc = gt.GT_EcatIOReadInput(LAMP_SLAVE, 0, 4, buf)
    run.lamps = buf[2]
    raw = c_ushort()
    rc_raw = gt.GT_GetEcatRawData(6, 2, byref(raw))
    _say(
        gt,
        say,
        f"IO slave {LAMP_SLAVE}: lamps {buf[0]:08b} wired back to its inputs {buf[2]:08b}",
        f"GT_EcatIOReadInput({LAMP_SLAVE}, 0, 4) = {rc}: [{buf[0]:02X} {buf[1]:02X} | "
        f"{buf[2]:02X} {buf[3]:02X}] (outputs | inputs, 5.2.2.5)",
        f"GT_GetEcatRawData(6, 2) = {rc_raw}: 0x{raw.value:04X}, axis 1's statusword (5.2.2.4)",
    )


def disable(gt: Any, say: Say) -> None:
    rcs = [gt.GT_AxisOff(a) for a in (1, 2)]
    _say(gt, say, "servo off", f"GT_AxisOff(1) = {rcs[0]}, GT_AxisOff(2) = {rcs[1]}")


# --- the whole part --------------------------------------------------------------------------
def run(gt: Any, say: Say, out: Path, plot: bool = True) -> DemoRun:
    """The axes part of the demo; writes ``demo.csv`` (and ``demo.png`` unless ``plot``)."""
    result = DemoRun()
    ctl = gt.GTE_Controller()
    for bit in range(8):
        gt.GTE_Slave(LAMP_SLAVE).wire(bit, bit)
    result.recorder = Recorder(ctl, TRACE, capacity=16384).start()
    try:
        if enable(gt, say, result):
            homed = home(gt, say, result)
            probe_and_move(gt, say, result, homed)
        io(gt, say, result)
        gt.GTE_Wait(HOLD_MS)  # a moment at rest before servo off (visible in the figure)
        disable(gt, say)
    finally:
        result.recorder.stop()
    rec = result.recorder
    result.files.append(rec.to_csv(out / "demo.csv"))
    if plot:
        result.files.append(plot_demo(rec, out / "demo.png", result))
    say(gt, f"trace: {rec.n} cycles -> " + ", ".join(str(f) for f in result.files))
    return result


# --- the figure ------------------------------------------------------------------------------
_COLORS = {1: "tab:blue", 2: "tab:orange"}
_LEGEND: dict[str, Any] = {"loc": "upper left", "bbox_to_anchor": (1.005, 1.0), "fontsize": 8}


def _masked_planned(rec: Recorder, axis: int, run: DemoRun) -> np.ndarray:
    """Planned position, blank where the controller does not plan (before enable, homing)."""
    t = rec.data[:, 0]
    prf = rec.column(f"axis{axis}.prf").copy()
    sw = rec.column(f"axis{axis}.sw").astype(np.int64)
    prf[(sw & 0x6F) != 0x27] = np.nan
    t0, t1 = run.homing.get(axis, (np.inf, np.inf))
    prf[(t >= t0) & (t <= t1 + 2 * WAIT_STEP_MS)] = np.nan
    return prf


def _rate(t_ms: np.ndarray, x: np.ndarray, limit: float) -> np.ndarray:
    """d x / dt in units per second; steps larger than ``limit`` per ms are redefinitions."""
    v = np.full_like(x, np.nan)
    if len(x) < 2:
        return v
    dt = np.diff(t_ms)
    dx = np.diff(x)
    with np.errstate(invalid="ignore", divide="ignore"):
        r = dx / dt
    r[np.abs(r) > limit] = np.nan
    v[1:] = r * 1000.0
    return v


def _bit_rows(rec: Recorder) -> list[tuple[str, np.ndarray, str]]:
    rows: list[tuple[str, np.ndarray, str]] = []
    for a in (1, 2):
        sw = rec.column(f"axis{a}.sw").astype(np.int64)
        din = rec.column(f"{a - 1}:0x60FD:0").astype(np.int64)
        c = _COLORS[a]
        rows += [
            (f"ax{a} operation enabled", (sw & 0x6F) == 0x27, c),
            (f"ax{a} SW10 target reached", (sw >> 10 & 1) == 1, c),
            (f"ax{a} SW12 homing attained / CSP following", (sw >> 12 & 1) == 1, c),
        ]
        if np.any(sw >> 13 & 1):
            rows.append((f"ax{a} SW13 error", (sw >> 13 & 1) == 1, "tab:red"))
        rows.append((f"ax{a} 60FDh.2 home switch", (din >> 2 & 1) == 1, c))
        if np.any(din >> 16 & 1):
            rows.append((f"ax{a} 60FDh.16 probe 1 input", (din >> 16 & 1) == 1, c))
    do = rec.column(f"{LAMP_SLAVE}:0x7000:1").astype(np.int64)
    rows += [
        (f"IO {LAMP_SLAVE} DO0 'homed' lamp", (do & 1) == 1, "tab:green"),
        (f"IO {LAMP_SLAVE} DO1 'probe' lamp", (do >> 1 & 1) == 1, "tab:green"),
    ]
    return rows


def _bands(ax: Any, rec: Recorder, t: np.ndarray) -> None:
    """Per axis: the CiA-402 state (from 6041h) and the mode (6061h) as labelled bands."""
    from ..controller.recorder import MODE_NAMES, STATE_NAMES, state_of
    from ..controller.trace_plot import STATE_COLORS, _segments

    lanes = []
    for a in (1, 2):
        sw = rec.column(f"axis{a}.sw").astype(np.int64)
        lanes.append((f"axis {a} CiA-402 state", np.array([state_of(int(w)) for w in sw]),
                      STATE_NAMES, STATE_COLORS))  # fmt: skip
        mode_colors = {"CSP": "#c7e9c0", "homing": "#fdd0a2", "no mode": "0.9"}
        lanes.append((f"axis {a} mode (6061h)", rec.column(f"axis{a}.mode").astype(np.int64),
                      MODE_NAMES, mode_colors))  # fmt: skip
    span = max(float(t[-1] - t[0]), 1e-9) if len(t) else 1.0
    n = len(lanes)
    for j, (_label, values, names, colors) in enumerate(lanes):
        y = n - 1 - j
        for a, b, v in _segments(values):
            text = names.get(v, str(v))
            x0, x1 = t[a], t[min(b, len(t) - 1)]
            ax.axvspan(x0, x1, ymin=(y + 0.12) / n, ymax=(y + 0.88) / n,
                       color=colors.get(text, "0.8"), lw=0)  # fmt: skip
            if x1 - x0 > 0.07 * span:
                ax.text((x0 + x1) / 2, y + 0.5, text, ha="center", va="center", fontsize=7)
    ax.set_ylim(0, n)
    ax.set_yticks([n - 1 - j + 0.5 for j in range(n)])
    ax.set_yticklabels([lane[0] for lane in lanes], fontsize=8)


def plot_demo(rec: Recorder, path: Path, run: DemoRun) -> Path:
    """demo.png: position, velocity, following error, drive and IO bits, events, vs time."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t_ms = rec.data[:, 0]
    t = t_ms / 1000.0
    rows = _bit_rows(rec)
    fig, axs = plt.subplots(
        5,
        1,
        figsize=(12, 15),
        sharex=True,
        gridspec_kw={"height_ratios": [3, 2, 2, 1.6, 0.32 * len(rows)]},
    )
    pos, vel, err, bands, bits = axs
    _bands(bands, rec, t)
    jump = 4 * max(TRAP_VEL, max(p.speed1 for p in HOMING) / 1000.0)
    for a in (1, 2):
        c = _COLORS[a]
        enc = rec.column(f"axis{a}.enc")
        prf = _masked_planned(rec, a, run)
        pos.plot(t, enc, color=c, lw=1.6, label=f"axis {a} actual (6064h)")
        pos.plot(
            t,
            prf,
            color="black",
            lw=0.9,
            ls="--",
            alpha=0.8,
            label="planned (607Ah set-point)" if a == 1 else None,
        )
        vel.plot(
            t,
            _rate(t_ms, rec.column(f"axis{a}.machine"), jump),
            color=c,
            lw=1.4,
            label=f"axis {a} actual",
        )
        vel.plot(
            t,
            _rate(t_ms, prf, jump),
            color="black",
            lw=0.9,
            ls="--",
            alpha=0.8,
            label="planned" if a == 1 else None,
        )
        plot_noisy(err, t, prf - enc, c, f"axis {a} (band: min-max, line: mean)")
        t0, t1 = run.homing.get(a, (None, None))
        if t0 is not None:
            for ax in (pos, vel, err):
                ax.axvspan(t0 / 1000, t1 / 1000, color=c, alpha=0.08, lw=0)
            pos.annotate(
                f"axis {a} homing (mode 6): {t0 / 1000:.2f}-{t1 / 1000:.2f} s",
                (t0 / 1000, 1.0),
                xycoords=("data", "axes fraction"),
                xytext=(4, -4 - 11 * (a - 1)),
                textcoords="offset points",
                ha="left",
                va="top",
                fontsize=8,
                color=c,
            )
    if run.probe_value is not None:
        tc = next((ms for ms, text in rec.events if text.startswith("probe")), None)
        if tc is not None:
            pos.plot(
                [tc / 1000],
                [run.probe_value],
                marker="o",
                ms=9,
                mfc="none",
                mec="tab:red",
                mew=2,
                ls="none",
                label=f"probe 1 capture 60BAh = {run.probe_value}",
            )
    pos.set_ylabel("position (counts)")
    pos.legend(**_LEGEND)
    if run.homing:
        pos.text(
            1.005,
            0.0,
            "shaded: homing.\nWhen it ends, the drive\nredefines 6064h: the\nhome point reads 0.",
            transform=pos.transAxes,
            fontsize=8,
            va="bottom",
            color="0.3",
        )
    vel.set_ylabel("velocity (counts/s)")
    vel.legend(**_LEGEND)
    err.set_ylabel("following error\nplanned − actual (counts)")
    err.legend(**_LEGEND)
    for i, (_name, on, c) in enumerate(rows):
        y = len(rows) - 1 - i
        bits.fill_between(t, y, y + 0.7 * on, step="post", color=c, alpha=0.75, lw=0)
        if 0 < on.sum() < 0.02 * len(on):  # a short pulse: mark where it rose
            rise = np.flatnonzero(np.diff(on.astype(np.int8)) > 0) + 1
            bits.plot(t[rise], np.full(len(rise), y + 0.35), "v", color=c, ms=7)
        bits.axhline(y, color="0.85", lw=0.5)
    bits.set_yticks([len(rows) - 1 - i + 0.35 for i in range(len(rows))])
    bits.set_yticklabels([r[0] for r in rows], fontsize=8)
    bits.set_ylim(-0.2, len(rows))
    bits.set_xlabel("controller time (s)")
    for ax in axs:
        ax.grid(alpha=0.3)
        for ms, _text in rec.events:
            ax.axvline(ms / 1000, color="tab:red", lw=0.7, alpha=0.5)
    span = max(float(t[-1] - t[0]), 1e-9) if len(t) else 1.0
    last_x, shift = -1e9, 0
    for ms, text in sorted(rec.events):
        x = ms / 1000
        shift = shift + 1 if (x - last_x) < 0.02 * span else 0  # events close together
        last_x = x
        bits.annotate(
            text,
            (x, 0),
            xycoords=("data", "axes fraction"),
            xytext=(2 + 9 * shift, 2),
            textcoords="offset points",
            rotation=90,
            fontsize=7,
            color="tab:red",
            ha="left",
            va="bottom",
        )
    fig.suptitle(
        "gtecat demo — manual figure 5-2 bus: enable, homing (axis 1 method "
        f"{HOMING[0].method}, axis 2 method {HOMING[1].method}), probe capture during a "
        "Trap move",
        fontsize=11,
    )
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path
