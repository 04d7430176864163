"""Position compare and triggers: the GTS 2D compare, the GTN position compare, triggers.

The units fire where the path of the watched positions passes their points
(:mod:`gtecat.controller.compare`: every point the cycle's straight path reaches within
the band fires, in order, however fast the motion).  The vendor's manual for these
functions is not public; the header's comments and the vendor's application notes say
what the arguments mean.  Decisions where they say no more:

**2D compare (GTS cards), ``chn`` 0 = HSIO0, 1 = HSIO1.**

* ``GT_2DCompareMode(chn, mode)``: 0 one dimension (the X coordinate alone), 1 two.
  The default is 1: a channel compares both coordinates until told otherwise.
* ``GT_2DCompareSetPrm``: ``encx``/``ency`` name the axes watched, ``source`` 0 their
  planned position (profile), 1 their encoder; ``outputType`` 0 pulse, 1 level (it
  toggles at each point); ``startLevel`` is the output level at the start;
  ``time`` the pulse length in µs (1..32767 accepted, shorter than a cycle: the output is
  seen only through the count); ``maxerr`` the band (pulses, on each coordinate, >= 0);
  ``threshold`` (the vendor's "optimal algorithm threshold") is kept and has no effect.
* ``GT_2DCompareData(chn, count, pBuf, fifo)`` appends ``count`` points (1..4096, the
  header's ``COMPARE_DATA_MAX`` per FIFO) to FIFO ``fifo``; 1 when they do not fit.
* ``GT_2DCompareStart`` needs parameters and points (1 otherwise) and reads FIFO 0 (or
  the one holding points), then the other when the first runs dry.
* ``GT_2DCompareStop`` stops comparing, the points left stay (a new start goes on
  with them).  ``GT_2DCompareClear`` stops, empties both FIFOs and sets the count to 0;
  ``GT_2DCompareClearData`` empties the FIFOs only.
* ``GT_2DCompareStatus``: ``pStatus`` 0 comparing, 1 finished (also before any start);
  ``pCount`` outputs so far (points reached, and ``GT_2DComparePulse`` calls);
  ``pFifo`` the FIFO to fill next (the one not being read), ``pFifoCount`` its room;
  ``pBufCount`` the room of the card's 512-point FPGA stage, which the emulation does
  not keep apart from the FIFOs: 512 minus the points left in the FIFO being read
  (never below 0).
* ``GT_2DComparePulse(chn, level, outputType, time)``: one output now: it counts; a level
  output (``outputType`` 1) takes ``level`` (0 the start level, 1 its opposite).
* ``GT_SetComparePort(channel, hsio0, hsio1)``: ``COMPARE_PORT_HSIO`` (0, the default) sends
  the two channels to the card's HSIO pins, which are not terminals of the emulated card;
  ``COMPARE_PORT_GPO`` (1) to general outputs ``hsio0 + 1`` and ``hsio1 + 1`` (``hsio``
  0..15 counts from 0).  There a level output is seen with ``GT_GetDo(MC_GPO)``: every
  toggle inverts that output (the vendor says to set it high, its idle state, first); a
  pulse is shorter than a cycle and leaves it as it is.

**Position compare (GTN header)**, ``index`` 1..8; the ``GT_`` form takes the core first
too, as the vendor's header declares it.

* ``TPosCompareMode``: ``mode`` 0 FIFO (points from ``GT_PosCompareData``), 1 linear
  (``GT_SetPosCompareLinear``); ``dimension`` 1 or 2; ``sourceMode`` 0 encoder, 1 the
  pulses sent out (the planned position); ``sourceX``/``sourceY`` the axes;
  ``outputMode`` 0 pulse, 1 level, 2 "auto" (a pulse); ``errorBand`` the band (pulses)
  on each coordinate; ``outputCounter`` and ``outputPulseWidth`` are kept and read back.
  Setting the mode stops the unit and empties it.
* Status: ``run`` 1 while comparing; ``space`` room in the FIFO; ``pulseCount``
  outputs so far; ``hso``, ``gpo``, ``segmentNumber`` those of the last point reached.
  Info: ``config`` 1 once a mode is set, ``fifoEmpty``, ``head``/``tail`` the points
  reached / pushed since the last clear (16 bits), ``commandReceive``/``commandSend``
  the same counts in full, ``posX``/``posY`` the watched positions now.
* The points' ``hso``/``gpo`` bits are reported back as they were given; they drive no
  output terminal of the emulated card.

**Triggers**, ``i`` 1..the controller's axis count.

* The input: ``probeType`` ``MC_HOME`` (3), the home switch of axis ``probeIndex``
  (the card's latch: exact to the count on a GTS card); ``MC_GPI`` (4), general input
  ``probeIndex`` (1..16), sampled every cycle.  ``sense`` 0 latches where the input becomes
  active, 1 where it becomes inactive (the capture's senses).
* The position: ``TTrigger.encoder`` is an encoder; ``TTriggerEx`` names it with
  ``latchType`` ``MC_ENCODER`` (23, the encoder), ``MC_PROFILE`` (31, the planned
  position) or ``MC_AXIS`` (30, the axis's encoder position) and ``latchIndex``.  A home
  edge latches the encoder of that axis where the switch was crossed; other positions
  are those of the cycle the edge is seen in.
* ``offset`` is added to the latched value; ``loop`` latches (0 or 1: one), the status
  keeps the last; ``windowOnly`` 1 ignores edges whose position lies outside
  ``[firstPosition, lastPosition]``.
* Status: ``execute`` 1 while armed, ``done`` 1 once the latches are made, ``position``,
  ``clock`` (GT_GetClock ms of the last latch) and ``loopCount``.
  ``GT_ClearTriggerStatus`` arms it again (status 0); a trigger never set reads 0s.
"""

from __future__ import annotations

import ctypes
import importlib
import inspect
from typing import Any

from ..controller.capture import CAPTURE_HOME, capture_unit
from ..controller.compare import FIFO_POINTS, CompareChannel, Point, compare_units
from ..controller.core import Controller
from ..controller.digital_io import GPIO_COUNT, digital_io
from ..controller.resources import axis_resources, position_source, resource_count
from ..controller.trigger import Edge, Trigger, triggers
from ..errors import CommandError, ParameterError
from ._core import SESSION, check_range, gt_function, store, struct_arg
from .constants import MC_GPI, MC_GPO, MC_HOME

MC_ENCODER, MC_AXIS, MC_PROFILE = 23, 30, 31
_FPGA_POINTS = 512


def _t(name: str) -> type[ctypes.Structure]:
    """A structure class of ``gtecat.gt`` (built from the table once the package is loaded)."""
    return vars(importlib.import_module("gtecat.gt"))[name]


def _core(ctl: Controller, core: int) -> Controller:
    """The controller of ``core`` (the vendor's GT_ form of these functions names it too)."""
    return ctl if int(core) == 1 else SESSION.controller(int(core))


def _source(ctl: Controller, axis: int, planned: bool):
    res = axis_resources(ctl, axis)
    if planned:
        return lambda: res.profile.planner.pos
    return lambda: res.encoder.pos


# --- 2D compare (GTS) ---------------------------------------------------------------------
class _TwoD:
    __slots__ = ("mode", "prm", "start_level")

    def __init__(self) -> None:
        self.mode = 1
        self.prm: tuple | None = None
        self.start_level = 0


def _unit2d(ctl: Controller, chn: int) -> tuple[CompareChannel, _TwoD]:
    units = compare_units(ctl)
    key = ("2d", int(chn))
    return units.get(key), units.settings.setdefault(key, _TwoD())


@gt_function
def GT_2DCompareMode(ctl: Controller, chn: int, mode: int) -> int:
    """0 one dimension (X), 1 two dimensions (the default)."""
    u, s = _unit2d(ctl, chn)
    if u.running:
        raise CommandError(f"GT_2DCompareMode: channel {chn} is comparing; stop it first")
    s.mode = int(mode)
    u.dims = 1 + s.mode
    return 0


@gt_function
def GT_2DCompareSetPrm(ctl: Controller, chn: int, pPrm: Any) -> int:
    prm = struct_arg(pPrm, _t("T2DComparePrm"), "pPrm")
    u, s = _unit2d(ctl, chn)
    if u.running:
        raise CommandError(f"GT_2DCompareSetPrm: channel {chn} is comparing; stop it first")
    if prm.source not in (0, 1):
        raise ParameterError(f"source={prm.source}: 0 planned position, 1 encoder")
    if prm.outputType not in (0, 1):
        raise ParameterError(f"outputType={prm.outputType}: 0 pulse, 1 level")
    if prm.startLevel not in (0, 1):
        raise ParameterError(f"startLevel={prm.startLevel}: 0 or 1")
    if prm.maxerr < 0 or prm.time < 1:
        raise ParameterError(f"maxerr={prm.maxerr} (>= 0), time={prm.time} (us, >= 1)")
    planned = prm.source == 0
    u.sources = (_source(ctl, prm.encx, planned), _source(ctl, prm.ency, planned))
    u.band = float(prm.maxerr)
    u.pulse = prm.outputType == 0
    u.level = s.start_level = int(prm.startLevel)
    u.dims = 1 + s.mode
    s.prm = tuple(getattr(prm, f) for f, _ in prm._fields_)
    return 0


@gt_function
def GT_2DCompareData(ctl: Controller, chn: int, count: int, pBuf: Any, fifo: int) -> int:
    """Append ``count`` points (px, py) to FIFO ``fifo`` of channel ``chn``."""
    n = check_range("count", count, 1, FIFO_POINTS)
    if pBuf is None:
        raise ParameterError("pBuf is NULL")
    buf = pBuf.struct(_t("T2DCompareData") * n)
    u, _ = _unit2d(ctl, chn)
    u.push(int(fifo), [Point(float(p.px), float(p.py)) for p in buf])
    return 0


@gt_function
def GT_2DCompareStart(ctl: Controller, chn: int) -> int:
    u, s = _unit2d(ctl, chn)
    if s.prm is None:
        raise CommandError(
            f"GT_2DCompareStart: channel {chn} has no parameters (GT_2DCompareSetPrm)"
        )
    _route(ctl, chn, u)
    u.start()
    return 0


@gt_function
def GT_2DCompareStop(ctl: Controller, chn: int) -> int:
    _unit2d(ctl, chn)[0].stop()
    return 0


@gt_function
def GT_2DCompareClear(ctl: Controller, chn: int) -> int:
    """Stop, empty both FIFOs, count 0."""
    u, s = _unit2d(ctl, chn)
    u.stop()
    u.clear_data()
    u.count = u.received = u.sent = 0
    u.level = s.start_level
    return 0


@gt_function
def GT_2DCompareClearData(ctl: Controller, chn: int) -> int:
    """Empty both FIFOs (the count stays)."""
    u, _ = _unit2d(ctl, chn)
    u.stop()
    u.clear_data()
    return 0


@gt_function
def GT_2DCompareStatus(
    ctl: Controller,
    chn: int,
    pStatus: Any,
    pCount: Any,
    pFifo: Any,
    pFifoCount: Any,
    pBufCount: Any = None,
) -> int:
    u, _ = _unit2d(ctl, chn)
    store(pStatus, 0 if u.running else 1)
    store(pCount, u.count & 0x7FFFFFFF)
    idle = u.idle_fifo
    store(pFifo, idle)
    store(pFifoCount, min(u.space(idle), 0x7FFF))
    left = len(u.fifos[u.active]) if u.running else 0
    store(pBufCount, max(_FPGA_POINTS - left, 0))
    return 0


@gt_function
def GT_2DComparePulse(ctl: Controller, chn: int, level: int, outputType: int, time: int) -> int:
    """One output now (it counts); a level output takes ``level``."""
    u, s = _unit2d(ctl, chn)
    if int(outputType) == 1:
        want = s.start_level ^ int(level)
        u.count += 1
        if want != u.level:
            _route(ctl, chn, u)
            u.level = want
            if u.on_level is not None:
                u.on_level(want)
    else:
        if int(time) < 1:
            raise ParameterError(f"time={time}: the pulse length in us, >= 1")
        u.count += 1
    return 0


class _Port:
    __slots__ = ("gpo",)

    def __init__(self) -> None:
        self.gpo: tuple[int, int] | None = None


def _route(ctl: Controller, chn: int, u: CompareChannel) -> None:
    """Send channel ``chn``'s level toggles to its general output (GT_SetComparePort)."""
    port = compare_units(ctl).settings.setdefault("port", _Port())
    if port.gpo is None:
        u.on_level = None
        return
    bit = 1 << port.gpo[int(chn)]

    def toggle(level: int) -> None:
        from .io_calls import read_do, write_do

        write_do(ctl, MC_GPO, read_do(ctl, MC_GPO) ^ bit)

    u.on_level = toggle


@gt_function
def GT_SetComparePort(ctl: Controller, channel: int, hsio0: int, hsio1: int) -> int:
    """0 the HSIO pins, 1 general outputs hsio0 + 1 and hsio1 + 1."""
    port = compare_units(ctl).settings.setdefault("port", _Port())
    port.gpo = (int(hsio0), int(hsio1)) if int(channel) == 1 else None
    for chn in (0, 1):
        _route(ctl, chn, _unit2d(ctl, chn)[0])
    return 0


# --- position compare (GTN) -----------------------------------------------------------------
class _Pos:
    __slots__ = ("linear", "linear2d", "mode")

    def __init__(self) -> None:
        self.mode: tuple | None = None
        self.linear: tuple | None = None
        self.linear2d: tuple | None = None


def _pos(ctl: Controller, core: int, index: int) -> tuple[Controller, CompareChannel, _Pos]:
    c = _core(ctl, core)
    units = compare_units(c)
    key = ("pos", int(core), int(index))
    return c, units.get(key), units.settings.setdefault(key, _Pos())


def _require_mode(s: _Pos, what: str, index: int, linear: bool | None = None) -> tuple:
    if s.mode is None:
        raise CommandError(f"{what}: compare {index} has no mode (GT_SetPosCompareMode)")
    if linear is not None and (s.mode[0] == 1) != linear:
        want = "linear (mode 1)" if linear else "FIFO (mode 0)"
        raise CommandError(f"{what}: compare {index} is not in {want} mode")
    return s.mode


def _set_mode(ctl, core, index, pMode) -> int:
    m = struct_arg(pMode, _t("TPosCompareMode"), "pMode")
    c, u, s = _pos(ctl, core, index)
    if m.mode not in (0, 1):
        raise ParameterError(f"mode={m.mode}: 0 FIFO, 1 linear")
    if m.dimension not in (1, 2):
        raise ParameterError(f"dimension={m.dimension}: 1 or 2")
    if m.sourceMode not in (0, 1):
        raise ParameterError(f"sourceMode={m.sourceMode}: 0 encoder, 1 pulse (planned)")
    if m.outputMode not in (0, 1, 2):
        raise ParameterError(f"outputMode={m.outputMode}: 0 pulse, 1 level, 2 auto")
    planned = m.sourceMode == 1
    src = [_source(c, m.sourceX, planned)]
    if m.dimension == 2:
        src.append(_source(c, m.sourceY, planned))
    u.stop()
    u.clear_data()
    u.count = u.received = u.sent = 0
    u.last = None
    u.sources, u.dims, u.band = tuple(src), int(m.dimension), float(m.errorBand)
    u.pulse = m.outputMode != 1
    u.level = 0
    s.mode = tuple(getattr(m, f) for f, _ in m._fields_)
    return 0


def _get_mode(ctl, core, index, pMode) -> int:
    m = struct_arg(pMode, _t("TPosCompareMode"), "pMode")
    _, _, s = _pos(ctl, core, index)
    for (f, _), v in zip(m._fields_, s.mode or (0,) * len(m._fields_), strict=True):
        setattr(m, f, v)
    return 0


def _data(ctl, core, index, pData) -> int:
    d = struct_arg(pData, _t("TPosCompareData"), "pData")
    _, u, s = _pos(ctl, core, index)
    if _require_mode(s, "GT_PosCompareData", index, linear=False)[1] != 1:
        raise CommandError(f"GT_PosCompareData: compare {index} is two-dimensional; use 2D data")
    u.push(0, [Point(float(d.pos), 0.0, d.hso, d.gpo, d.segmentNumber)])
    return 0


def _data2d(ctl, core, index, pData) -> int:
    d = struct_arg(pData, _t("TPosCompareData2D"), "pData")
    _, u, s = _pos(ctl, core, index)
    if _require_mode(s, "GT_PosCompareData2D", index, linear=False)[1] != 2:
        raise CommandError(f"GT_PosCompareData2D: compare {index} is one-dimensional")
    u.push(0, [Point(float(d.posX), float(d.posY), d.hso, d.gpo, d.segmentNumber)])
    return 0


def _linear_points(count: int, start: tuple, step: tuple, hso: int, gpo: int) -> list[Point]:
    if not 1 <= count <= FIFO_POINTS:
        raise ParameterError(f"count={count}: 1..{FIFO_POINTS}")
    out = []
    for k in range(count):
        xy = [start[j] + k * step[j] for j in range(len(start))]
        out.append(Point(float(xy[0]), float(xy[1]) if len(xy) > 1 else 0.0, hso, gpo, k + 1))
    return out


def _set_linear(ctl, core, index, pLinear) -> int:
    lin = struct_arg(pLinear, _t("TPosCompareLinear"), "pLinear")
    _, u, s = _pos(ctl, core, index)
    if _require_mode(s, "GT_SetPosCompareLinear", index, linear=True)[1] != 1:
        raise CommandError(f"GT_SetPosCompareLinear: compare {index} is two-dimensional")
    pts = _linear_points(lin.count, (lin.startPos,), (lin.interval,), lin.hso, lin.gpo)
    u.stop()
    u.clear_data()
    u.push(0, pts)
    s.linear = tuple(getattr(lin, f) for f, _ in lin._fields_)
    return 0


def _get_linear(ctl, core, index, pLinear) -> int:
    lin = struct_arg(pLinear, _t("TPosCompareLinear"), "pLinear")
    _, _, s = _pos(ctl, core, index)
    for (f, _), v in zip(lin._fields_, s.linear or (0,) * len(lin._fields_), strict=True):
        setattr(lin, f, v)
    return 0


def _set_linear2d(ctl, core, index, pLinear) -> int:
    lin = struct_arg(pLinear, _t("TPosCompareLinear2D"), "pLinear")
    _, u, s = _pos(ctl, core, index)
    if _require_mode(s, "GT_SetPosCompareLinear2D", index, linear=True)[1] != 2:
        raise CommandError(f"GT_SetPosCompareLinear2D: compare {index} is one-dimensional")
    pts = _linear_points(
        lin.count,
        (lin.startPosX, lin.startPosY),
        (lin.intervalX, lin.intervalY),
        lin.hso,
        lin.gpo,
    )
    u.stop()
    u.clear_data()
    u.push(0, pts)
    s.linear2d = tuple(getattr(lin, f) for f, _ in lin._fields_)
    return 0


def _get_linear2d(ctl, core, index, pLinear) -> int:
    lin = struct_arg(pLinear, _t("TPosCompareLinear2D"), "pLinear")
    _, _, s = _pos(ctl, core, index)
    for (f, _), v in zip(lin._fields_, s.linear2d or (0,) * len(lin._fields_), strict=True):
        setattr(lin, f, v)
    return 0


def _start(ctl, core, index) -> int:
    _, u, s = _pos(ctl, core, index)
    _require_mode(s, "GT_PosCompareStart", index)
    u.start()
    return 0


def _stop(ctl, core, index) -> int:
    _pos(ctl, core, index)[1].stop()
    return 0


def _clear(ctl, core, index) -> int:
    _, u, s = _pos(ctl, core, index)
    u.stop()
    u.clear_data()
    u.count = u.received = u.sent = 0
    u.last = None
    s.linear = s.linear2d = None
    return 0


def _status(ctl, core, index, pStatus) -> int:
    st = struct_arg(pStatus, _t("TPosCompareStatus"), "pStatus")
    _, u, s = _pos(ctl, core, index)
    last = u.last or Point(0.0)
    st.mode = s.mode[0] if s.mode else 0
    st.run = 1 if u.running else 0
    st.space = min(u.space(0), 0xFFFF)
    st.pulseCount = u.count & 0xFFFFFFFF
    st.hso, st.gpo = last.hso & 0xFFFF, last.gpo & 0xFFFF
    st.segmentNumber = last.segment & 0xFFFFFFFF
    return 0


def _info(ctl, core, index, pInfo) -> int:
    info = struct_arg(pInfo, _t("TPosCompareInfo"), "pInfo")
    _, u, s = _pos(ctl, core, index)
    info.config = 1 if s.mode else 0
    info.fifoEmpty = 0 if (u.fifos[0] or u.fifos[1]) else 1
    info.head, info.tail = u.sent & 0xFFFF, u.received & 0xFFFF
    info.commandReceive, info.commandSend = u.received & 0xFFFFFFFF, u.sent & 0xFFFFFFFF
    now = [round(f()) for f in u.sources] + [0, 0]
    info.posX, info.posY = now[0], now[1]
    return 0


def _space(ctl, core, index, pSpace) -> int:
    _, u, _ = _pos(ctl, core, index)
    store(pSpace, min(u.space(0), 0xFFFF))
    return 0


def _both(impl, name: str, doc: str):
    """``GT_<name>`` and ``GTN_<name>`` (the same parameters, core first in both)."""
    out = []
    for prefix in ("GT_", "GTN_"):

        def fn(ctl, *args, _impl=impl):
            return _impl(ctl, *args)

        params = list(inspect.signature(impl).parameters.values())
        fn.__signature__ = inspect.Signature(params)  # type: ignore[attr-defined]
        fn.__name__ = fn.__qualname__ = prefix + name
        fn.__doc__ = doc
        out.append(gt_function(fn))
    return out


GT_SetPosCompareMode, GTN_SetPosCompareMode = _both(
    _set_mode, "SetPosCompareMode", "Mode, dimension, sources and output of compare ``index``."
)
GT_GetPosCompareMode, GTN_GetPosCompareMode = _both(
    _get_mode, "GetPosCompareMode", "The mode set last (zeros before any)."
)
GT_PosCompareData, GTN_PosCompareData = _both(
    _data, "PosCompareData", "Append one point to a one-dimensional FIFO compare."
)
GT_PosCompareData2D, GTN_PosCompareData2D = _both(
    _data2d, "PosCompareData2D", "Append one point to a two-dimensional FIFO compare."
)
GT_SetPosCompareLinear, GTN_SetPosCompareLinear = _both(
    _set_linear, "SetPosCompareLinear", "``count`` points from ``startPos`` every ``interval``."
)
GT_GetPosCompareLinear, GTN_GetPosCompareLinear = _both(
    _get_linear, "GetPosCompareLinear", "The linear points set last (zeros before any)."
)
GT_SetPosCompareLinear2D, GTN_SetPosCompareLinear2D = _both(
    _set_linear2d, "SetPosCompareLinear2D", "``count`` points on a line in the plane."
)
GT_GetPosCompareLinear2D, GTN_GetPosCompareLinear2D = _both(
    _get_linear2d, "GetPosCompareLinear2D", "The 2D linear points set last."
)
GT_PosCompareStart, GTN_PosCompareStart = _both(_start, "PosCompareStart", "Start comparing.")
GT_PosCompareStop, GTN_PosCompareStop = _both(_stop, "PosCompareStop", "Stop (points stay).")
GT_PosCompareClear, GTN_PosCompareClear = _both(
    _clear, "PosCompareClear", "Stop, empty the FIFO, counts 0."
)
GT_PosCompareStatus, GTN_PosCompareStatus = _both(
    _status, "PosCompareStatus", "Run flag, room, outputs and the last point reached."
)
GT_PosCompareInfo, GTN_PosCompareInfo = _both(
    _info, "PosCompareInfo", "Configuration, FIFO counters and the watched positions."
)


@gt_function
def GTN_PosCompareSpace(ctl: Controller, core: int, index: int, pSpace: Any) -> int:
    """Room left in the FIFO of compare ``index``."""
    return _space(ctl, core, index, pSpace)


# --- triggers -------------------------------------------------------------------------------
def _trigger_index(ctl: Controller, i: int) -> int:
    return check_range("i", i, 1, resource_count(ctl))


def _edges(ctl: Controller, probe_type: int, probe_index: int, latch):
    kind, index, pos_now = latch
    if probe_type == MC_HOME:
        unit = capture_unit(ctl, probe_index)
        same = kind == 1 and index == probe_index

        def home() -> list[Edge]:
            return [
                Edge(e.active, e.pos if same else pos_now())
                for e in unit.edges
                if e.signal == CAPTURE_HOME
            ]

        return home
    if probe_type == MC_GPI:
        check_range("probeIndex", probe_index, 1, GPIO_COUNT)
        io = digital_io(ctl)
        bit = 1 << (probe_index - 1)
        prev = [bool(io.gpi & bit)]

        def gpi() -> list[Edge]:
            level = bool(io.gpi & bit)
            if level == prev[0]:
                return []
            prev[0] = level
            return [Edge(level, pos_now())]

        return gpi
    raise ParameterError(f"probeType={probe_type}: MC_HOME 3 or MC_GPI 4")


def _arm(ctl: Controller, i: int, t: Any, latch: tuple[int, int], ex: bool) -> None:
    n = _trigger_index(ctl, i)
    kind, index = latch
    item = 1 if kind == 3 else 0
    pos_now = position_source(ctl, kind, index, item)
    if t.sense not in (0, 1):
        raise ParameterError(f"sense={t.sense}: 0 the input becomes active, 1 inactive")
    if t.windowOnly not in (0, 1):
        raise ParameterError(f"windowOnly={t.windowOnly}: 0 or 1")
    edges = _edges(ctl, int(t.probeType), int(t.probeIndex), (kind, index, pos_now))
    window = (int(t.firstPosition), int(t.lastPosition)) if t.windowOnly else None
    if window is not None and window[0] > window[1]:
        raise ParameterError(f"firstPosition={window[0]} > lastPosition={window[1]}")
    values = tuple(getattr(t, f) for f, _ in t._fields_)
    triggers(ctl).by_index[n] = Trigger(
        edges, int(t.sense), int(t.offset), int(t.loop), window, (ex, values)
    )


@gt_function
def GT_SetTrigger(ctl: Controller, i: int, pTrigger: Any) -> int:
    """Arm trigger ``i``: latch encoder ``encoder`` at the input's edge."""
    t = struct_arg(pTrigger, _t("TTrigger"), "pTrigger")
    axis_resources(ctl, t.encoder)
    _arm(ctl, i, t, (1, int(t.encoder)), ex=False)
    return 0


@gt_function
def GT_SetTriggerEx(ctl: Controller, i: int, pTrigger: Any) -> int:
    """Arm trigger ``i``: latch ``latchType``/``latchIndex`` at the input's edge."""
    t = struct_arg(pTrigger, _t("TTriggerEx"), "pTrigger")
    kinds = {MC_ENCODER: 1, MC_PROFILE: 2, MC_AXIS: 3}
    kind = kinds.get(int(t.latchType))
    if kind is None:
        raise ParameterError(f"latchType={t.latchType}: MC_ENCODER 23, MC_AXIS 30 or MC_PROFILE 31")
    _arm(ctl, i, t, (kind, int(t.latchIndex)), ex=True)
    return 0


def _read_back(ctl: Controller, i: int, pTrigger: Any, name: str, ex: bool) -> int:
    cls = _t(name)
    out = struct_arg(pTrigger, cls, "pTrigger")
    trig = triggers(ctl).by_index.get(_trigger_index(ctl, i))
    values: tuple = (0,) * len(cls._fields_)
    if trig is not None:
        was_ex, given = trig.settings
        if was_ex == ex:
            values = given
        elif ex:  # set by GT_SetTrigger: the encoder is the latch
            values = (MC_ENCODER, *given)
        else:  # set by GT_SetTriggerEx: an encoder latch reads as its encoder
            values = given[1:]
    for (f, _), v in zip(cls._fields_, values, strict=True):
        setattr(out, f, v)
    return 0


@gt_function
def GT_GetTrigger(ctl: Controller, i: int, pTrigger: Any) -> int:
    return _read_back(ctl, i, pTrigger, "TTrigger", ex=False)


@gt_function
def GT_GetTriggerEx(ctl: Controller, i: int, pTrigger: Any) -> int:
    return _read_back(ctl, i, pTrigger, "TTriggerEx", ex=True)


def _status_of(ctl: Controller, i: int, count: int, ptr: Any, name: str) -> None:
    first = _trigger_index(ctl, i)
    n = check_range("count", count, 1, resource_count(ctl) - first + 1)
    if ptr is None:
        raise ParameterError("the status pointer is NULL")
    arr = ptr.struct(_t(name) * n)
    by = triggers(ctl).by_index
    for k in range(n):
        t: Trigger | None = by.get(first + k)
        s = arr[k]
        s.execute = 1 if t is not None and t.execute else 0
        s.done = 1 if t is not None and t.done else 0
        s.position = t.position if t is not None else 0
        if hasattr(s, "clock"):
            s.clock = (t.clock if t is not None else 0) & 0xFFFFFFFF
            s.loopCount = t.loops if t is not None else 0


@gt_function
def GT_GetTriggerStatus(ctl: Controller, i: int, pTriggerStatus: Any, count: int = 1) -> int:
    _status_of(ctl, i, count, pTriggerStatus, "TTriggerStatus")
    return 0


@gt_function
def GT_GetTriggerStatusEx(ctl: Controller, i: int, pTriggerStatusEx: Any, count: int = 1) -> int:
    _status_of(ctl, i, count, pTriggerStatusEx, "TTriggerStatusEx")
    return 0


@gt_function
def GT_ClearTriggerStatus(ctl: Controller, i: int) -> int:
    """Arm trigger ``i`` again (status 0); 1 when it was never set."""
    t = triggers(ctl).by_index.get(_trigger_index(ctl, i))
    if t is None:
        raise CommandError(f"GT_ClearTriggerStatus: trigger {i} is not set (GT_SetTrigger)")
    t.clear()
    return 0
