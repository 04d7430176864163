"""The servo loop of GTS cards and the card-level calls around it, through the GT API.

What the loop functions keep and read back is decided in :mod:`gtecat.controller.servo_loop`
(PID sets, analog/pulse modes, DAC and ADC channels).  The others, and the decisions the
vendor's headers leave open:

* ``GT_GetDiEx(diType, pValue, count)``: ``count`` words of 32 inputs; word 1 is
  ``GT_GetDi``'s value, the card has no further terminals of a type (they read 0).
* ``GT_SetDoBitReverse(doType, doIndex, value, reverseTime)``: output ``doIndex`` takes
  ``value`` now and the opposite level ``reverseTime`` ms later (a timed pulse, e.g. an
  alarm-clear pulse).  ``MC_GPO`` and ``MC_CLEAR`` only: an enable that switches itself
  is refused (7).  The flip back changes the output register only.
* ``GT_GetDiReverseCount`` / ``GT_SetDiReverseCount``: how often each input of a type
  changed level (``GT_GetDi``'s view, sampled every cycle).  The controller watches a type
  from the first call naming it; ``GT_SetDiReverseCount`` presets the counters.
* ``GT_LmtSns(sense)`` (bit 2(n-1) the positive, 2(n-1)+1 the negative limit of axis n, 1 =
  the other level) and ``GT_SetSense(dataType, dataIndex, value)`` (``MC_LIMIT_POSITIVE``,
  ``MC_LIMIT_NEGATIVE``, ``MC_ALARM``, ``MC_HOME``, ``MC_GPI``, ``MC_ARRIVE``) are the
  ``reverse`` key of the configuration file's ``[limitPositiveN]`` ... ``[gpiN]`` sections,
  set at run time: they act exactly as loading a configuration with those ``reverse``
  values (``GT_GetDi``, the limits, the home capture), and ``GT_GetSense`` reads it back.
* ``GT_MultiAxisOn/Off(mask)``: bit ``i`` is axis ``i + 1``; a bit for an axis that does
  not exist returns 7 before any axis changes.
* ``GT_LmtsOnEx/OffEx(axis, limitType, limitMode)``: ``limitMode`` 0 the limit switches
  (as ``GT_LmtsOn/Off``), 1 the soft limits (off: put aside, on: back as they were), -1
  both.  ``GT_SetSoftLimitMode``: mode 0 (``SOFT_LIMIT_MODE_STOP``: past the limit the axis
  stops with its abrupt-stop deceleration) is the emulated one; mode 1 (hold the axis
  inside the limits) returns 1, saying it is not emulated.
* ``GT_GetResMax`` / ``GT_GetResCount(type)``: what the card could hold and what this one
  has, for ``MC_AXIS``, ``MC_PROFILE``, ``MC_CONTROL``, ``MC_ENCODER``, ``MC_STEP``,
  ``MC_DAC`` (the card's or core's axes; the EtherCAT core holds up to 32), ``MC_ADC`` (8),
  ``MC_GPI`` / ``MC_GPO`` (16), ``MC_EXT_MODULE`` / ``MC_EXT_DI`` / ``MC_EXT_DO`` /
  ``MC_EXT_AI`` / ``MC_EXT_AO`` (the machine's extension modules; up to 16 modules).
* ``GT_SetCardNo(index)``: the card later calls address, 0..15 (7 otherwise), one per
  process; it works before ``GT_Open``, which then opens that card
  (:mod:`gtecat.controller.cards` says what each card is).  ``GT_SetCore(core)`` (GTN
  header): the core the ``GT_*`` functions address, 1 or 2, one per process; the
  ``GTN_*`` functions name their own.
* ``GT_GetAtlTorque`` / ``GT_GetEcatAxisAtlTorque``: the vendor GTN header's spellings of
  ``GT_GetEcatAxisAtITorque`` (6077h).
"""

from __future__ import annotations

import ctypes
from typing import Any

from ..controller.cards import CARD_CORES as _CARD_CORES
from ..controller.cards import MAX_CARDS as _MAX_CARDS
from ..controller.config_file import apply_config, parse_vendor, vendor_settings
from ..controller.core import Controller
from ..controller.core_view import AXES_PER_CORE
from ..controller.digital_io import GPIO_COUNT, digital_io
from ..controller.ext_io import ext_io
from ..controller.resources import axis_resources, resource_count
from ..controller.safety import SOFT_NEGATIVE_OFF, SOFT_POSITIVE_OFF
from ..controller.servo_loop import ADC_CHANNELS, PID_SETS, PidSet, servo_loop
from ..errors import CommandError, ParameterError
from . import axis_calls
from ._core import SESSION, check_range, gt_function, store, store_array, struct_arg
from .axis_calls import axis_off, axis_on
from .constants import (
    MC_ADC,
    MC_ALARM,
    MC_ARRIVE,
    MC_AXIS,
    MC_CLEAR,
    MC_CONTROL,
    MC_DAC,
    MC_ENCODER,
    MC_GPI,
    MC_GPO,
    MC_HOME,
    MC_LIMIT_NEGATIVE,
    MC_LIMIT_POSITIVE,
    MC_PROFILE,
    MC_STEP,
)
from .io_calls import _DI_TYPES, di_value, read_di
from .status_calls import GT_LmtsOff, GT_LmtsOn

# vendor GTN header constants used here
MC_EXT_MODULE = 60
MC_EXT_DI = 61
MC_EXT_DO = 62
MC_EXT_AI = 63
MC_EXT_AO = 64
STEP_DIR = 0
STEP_PULSE = 1
LIMIT_MODE_EXTERNAL = 0
LIMIT_MODE_SOFT = 1
LIMIT_MODE_ALL = -1
SOFT_LIMIT_MODE_STOP = 0
SOFT_LIMIT_MODE_LIMIT = 1


class TPid(ctypes.Structure):
    """PID parameters of a control: GT_SetPid / GT_GetPid (vendor GTS header).

    kp, ki, kd: gains; kvff, kaff: velocity / acceleration feed-forward; integralLimit,
    derivativeLimit, limit: output limits (DAC units, up to 32767).
    """

    _fields_ = (
        ("kp", ctypes.c_double),
        ("ki", ctypes.c_double),
        ("kd", ctypes.c_double),
        ("kvff", ctypes.c_double),
        ("kaff", ctypes.c_double),
        ("integralLimit", ctypes.c_int32),
        ("derivativeLimit", ctypes.c_int32),
        ("limit", ctypes.c_int16),
    )


def _control(ctl: Controller, n: int, what: str = "control") -> int:
    ctl.axis(check_range(what, n, 1, 0x7FFF))  # 7 naming the axes when it does not exist
    return int(n)


# --- PID, modes ----------------------------------------------------------------------------------
@gt_function
def GT_SetPid(ctl: Controller, control: int, index: int, pPid: Any) -> int:
    """Parameter set ``index`` (1..2) of ``control`` (kept, read back; the module docstring)."""
    c = _control(ctl, control)
    prm = struct_arg(pPid, TPid, "pPid")
    for name in ("integralLimit", "derivativeLimit"):
        if getattr(prm, name) < 0:
            raise ParameterError(f"{name}={getattr(prm, name)}: a limit is not negative")
    if not 0 <= prm.limit <= 32767:
        raise ParameterError(f"limit={prm.limit}: 0..32767")
    values = {f: getattr(prm, f) for f, _ in TPid._fields_}
    servo_loop(ctl).pid[(c, int(index))] = PidSet(**values)
    return 0


@gt_function
def GT_GetPid(ctl: Controller, control: int, index: int, pPid: Any) -> int:
    c = _control(ctl, control)
    prm = struct_arg(pPid, TPid, "pPid")
    s = servo_loop(ctl).pid_set(c, int(index))
    for f, _ in TPid._fields_:
        setattr(prm, f, getattr(s, f))
    return 0


@gt_function
def GT_CtrlMode(ctl: Controller, axis: int, mode: int) -> int:
    """Axis ``axis`` analog (0, the DAC carries the command) or pulse (1)."""
    servo_loop(ctl).ctrl_mode[_control(ctl, axis, "axis")] = int(mode)
    return 0


@gt_function
def GT_StepDir(ctl: Controller, step: int) -> int:
    """Step channel ``step`` puts out step + direction."""
    servo_loop(ctl).step_mode[_control(ctl, step, "step")] = STEP_DIR
    return 0


@gt_function
def GT_StepPulse(ctl: Controller, step: int) -> int:
    """Step channel ``step`` puts out pulse + pulse (CW/CCW)."""
    servo_loop(ctl).step_mode[_control(ctl, step, "step")] = STEP_PULSE
    return 0


# --- DAC, ADC ------------------------------------------------------------------------------------
def _dac_value(ctl: Controller, n: int) -> int:
    loop = servo_loop(ctl)
    ax = ctl.axes.get(n)
    if ax is not None and loop.analog(n) and ax.servo_on:
        s = loop.pid_set(n, loop.active_set.get(n, 1))
        res = axis_resources(ctl, n)
        cmd = s.kp * res.axis_error + s.kvff * res.axis_prf_vel
        return max(-s.limit, min(s.limit, round(cmd)))
    return loop.dac.get(n, 0)


def _dacs(ctl: Controller, dac: int, count: int) -> range:
    first = check_range("dac", dac, 1, 0x7FFF)
    n = check_range("count", count, 1, 0x7FFF)
    last = first + n - 1
    if last not in ctl.axes:
        top = max(ctl.axes, default=0)
        raise ParameterError(f"dac {first}..{last}: the card has analog outputs 1..{top}")
    return range(first, last + 1)


@gt_function
def GT_SetDac(ctl: Controller, dac: int, pValue: Any, count: int = 1) -> int:
    """Free analog outputs ``dac`` .. to -32768..32767 (+-10 V); 1 on a closed-loop one."""
    chans = _dacs(ctl, dac, count)
    values = [int(v) for v in pValue.load_values(len(chans))]
    loop = servo_loop(ctl)
    for n in chans:
        if loop.analog(n) and ctl.axes[n].servo_on:
            raise CommandError(
                f"GT_SetDac: dac {n} carries the control loop of analog axis {n} (servo on); "
                "switch the axis off or make it a pulse axis (GT_CtrlMode) first"
            )
    for n, v in zip(chans, values, strict=True):
        loop.dac[n] = v
    return 0


@gt_function
def GT_GetDac(ctl: Controller, dac: int, pValue: Any, count: int = 1, pClock: Any = None) -> int:
    chans = _dacs(ctl, dac, count)
    store_array(pValue, [_dac_value(ctl, n) for n in chans])
    store(pClock, ctl.clock_ms() & 0xFFFFFFFF)
    return 0


def _adcs(adc: int, count: int) -> range:
    first = check_range("adc", adc, 1, ADC_CHANNELS)
    n = check_range("count", count, 1, ADC_CHANNELS - first + 1)
    return range(first, first + n)


@gt_function
def GT_GetAdc(ctl: Controller, adc: int, pValue: Any, count: int = 1, pClock: Any = None) -> int:
    """Analog inputs ``adc`` .. in volts (1..8)."""
    loop = servo_loop(ctl)
    store_array(pValue, [loop.adc[n - 1] for n in _adcs(adc, count)])
    store(pClock, ctl.clock_ms() & 0xFFFFFFFF)
    return 0


@gt_function
def GT_GetAdcValue(
    ctl: Controller, adc: int, pValue: Any, count: int = 1, pClock: Any = None
) -> int:
    """Analog inputs as ``short``: +-32767 = +-10 V."""
    loop = servo_loop(ctl)
    store_array(pValue, [round(loop.adc[n - 1] / 10.0 * 32767) for n in _adcs(adc, count)])
    store(pClock, ctl.clock_ms() & 0xFFFFFFFF)
    return 0


@gt_function
def GTE_SetAdc(ctl: Controller, adc: int, voltage: float) -> int:
    """Emulator only: the voltage on the card's analog input ``adc`` (1..8)."""
    servo_loop(ctl).set_adc(adc, voltage)
    return 0


# --- card IO around the loop ---------------------------------------------------------------------
@gt_function
def GT_GetDiEx(ctl: Controller, diType: int, pValue: Any, count: int = 1) -> int:
    n = check_range("count", count, 1, 0x7FFF)
    word = read_di(ctl, diType, raw=False) & 0xFFFFFFFF
    words = [word - (1 << 32) if word >= 1 << 31 else word] + [0] * (n - 1)
    store_array(pValue, words)
    return 0


class _Pulses:
    """Pending flips of GT_SetDoBitReverse: (due ns, doType, bit, level)."""

    def __init__(self, ctl: Controller) -> None:
        self.pending: list[tuple[int, int, int, int]] = []
        self.ctl = ctl

    def __call__(self, t: int, dt: int) -> None:
        if not self.pending:
            return
        io = digital_io(self.ctl)
        keep = []
        for due, t_type, bit, level in self.pending:
            if t < due:
                keep.append((due, t_type, bit, level))
                continue
            reg = io.gpo if t_type == MC_GPO else io.clear
            reg = reg | bit if level else reg & ~bit
            if t_type == MC_GPO:
                io.set_gpo(reg)
            else:
                io.clear = reg & 0xFFFF
        self.pending = keep


_Pulses.bank_safe = True  # type: ignore[attr-defined]  # output registers only


def _pulses(ctl: Controller) -> _Pulses:
    for f in ctl.pre_cycle:
        if isinstance(f, _Pulses):
            return f
    p = _Pulses(ctl)
    ctl.pre_cycle.append(p)
    ctl.on_reset.append(lambda c: p.pending.clear())
    return p


@gt_function
def GT_SetDoBitReverse(
    ctl: Controller, doType: int, doIndex: int, value: int, reverseTime: int
) -> int:
    """Output ``doIndex`` to ``value`` now, to the other level ``reverseTime`` ms later."""
    if int(doType) not in (MC_GPO, MC_CLEAR):
        raise ParameterError(f"doType={doType}: MC_GPO 12 or MC_CLEAR 11 (timed pulses)")
    top = GPIO_COUNT if doType == MC_GPO else max(ctl.axes, default=0)
    i = check_range("doIndex", doIndex, 1, top)
    from .io_calls import GT_SetDoBit

    rc = GT_SetDoBit.__wrapped__(ctl, doType, i, value)
    due = ctl.clock.now_ns + int(reverseTime) * 1_000_000
    _pulses(ctl).pending.append((due, int(doType), 1 << (i - 1), 0 if value else 1))
    return rc


class _EdgeCounter:
    """Counts level changes of the watched input types, once per cycle."""

    def __init__(self, ctl: Controller) -> None:
        self.ctl = ctl
        self.last: dict[int, int] = {}
        self.counts: dict[tuple[int, int], int] = {}

    def watch(self, di_type: int) -> None:
        if di_type not in self.last:
            self.last[di_type] = di_value(self.ctl, di_type)

    def __call__(self, t: int, dt: int) -> None:
        for di_type, before in self.last.items():
            now = di_value(self.ctl, di_type)  # (read_di's, without its look-ups)
            changed = now ^ before
            while changed:
                bit = changed & -changed
                key = (di_type, bit.bit_length())
                self.counts[key] = (self.counts.get(key, 0) + 1) & 0xFFFFFFFF
                changed ^= bit
            self.last[di_type] = now


_EdgeCounter.bank_safe = True  # type: ignore[attr-defined]  # reads inputs only


def _edges(ctl: Controller, di_type: int) -> _EdgeCounter:
    if type(di_type) is not int or di_type not in _DI_TYPES:
        read_di(ctl, di_type, raw=False)  # 7 for a type that is not an input type, and why
    for f in ctl.pre_cycle:
        if isinstance(f, _EdgeCounter):
            f.watch(int(di_type))
            return f
    e = _EdgeCounter(ctl)
    ctl.pre_cycle.append(e)
    e.watch(int(di_type))
    return e


def _di_span(ctl: Controller, di_type: int, di_index: int, count: int) -> range:
    top = GPIO_COUNT if int(di_type) == MC_GPI else max(ctl.axes, default=0)
    first = check_range("diIndex", di_index, 1, top)
    n = check_range("count", count, 1, top - first + 1)
    return range(first, first + n)


@gt_function
def GT_GetDiReverseCount(
    ctl: Controller, diType: int, diIndex: int, pReverseCount: Any, count: int = 1
) -> int:
    e = _edges(ctl, diType)
    span = _di_span(ctl, diType, diIndex, count)
    store_array(pReverseCount, [e.counts.get((int(diType), i), 0) for i in span])
    return 0


@gt_function
def GT_SetDiReverseCount(
    ctl: Controller, diType: int, diIndex: int, pReverseCount: Any, count: int = 1
) -> int:
    e = _edges(ctl, diType)
    span = _di_span(ctl, diType, diIndex, count)
    values = pReverseCount.load_values(len(span))
    for i, v in zip(span, values, strict=True):
        e.counts[(int(diType), i)] = int(v) & 0xFFFFFFFF
    return 0


# --- input senses ----------------------------------------------------------------------------
_SENSE_SECTIONS = {
    MC_LIMIT_POSITIVE: "limitPositive",
    MC_LIMIT_NEGATIVE: "limitNegative",
    MC_ALARM: "alarm",
    MC_HOME: "home",
    MC_GPI: "gpi",
    MC_ARRIVE: "arrive",
}


def _sense_section(ctl: Controller, data_type: int, index: int) -> str:
    kind = _SENSE_SECTIONS.get(int(data_type))
    if kind is None:
        raise ParameterError(
            f"dataType={data_type}: MC_LIMIT_POSITIVE 0, MC_LIMIT_NEGATIVE 1, MC_ALARM 2, "
            "MC_HOME 3, MC_GPI 4 or MC_ARRIVE 5"
        )
    top = GPIO_COUNT if kind == "gpi" else max(ctl.axes, default=0)
    check_range("dataIndex", index, 1, top)
    return kind


def _reverse(ctl: Controller, name: str, items: list[tuple[str, int, int]]) -> None:
    """Set ``reverse`` of ``[kind n]`` as a configuration file would."""
    text = "".join(f"[{kind}{n}]\nreverse={v}\n" for kind, n, v in items)
    apply_config(ctl, parse_vendor(text, name))


@gt_function
def GT_LmtSns(ctl: Controller, sense: int) -> int:
    """The level of every limit switch: bit 2(n-1) positive, 2(n-1)+1 negative of axis n."""
    s = int(sense) & 0xFFFF
    items = []
    for n in range(1, 9):
        if n in ctl.axes:
            items.append(("limitPositive", n, s >> (2 * n - 2) & 1))
            items.append(("limitNegative", n, s >> (2 * n - 1) & 1))
    _reverse(ctl, "GT_LmtSns", items)
    return 0


@gt_function
def GT_SetSense(ctl: Controller, dataType: int, dataIndex: int, value: int) -> int:
    """Input ``dataIndex`` of type ``dataType`` read at the other level (1) or not (0)."""
    kind = _sense_section(ctl, dataType, dataIndex)
    _reverse(ctl, "GT_SetSense", [(kind, int(dataIndex), int(value))])
    return 0


@gt_function
def GT_GetSense(ctl: Controller, dataType: int, dataIndex: int, pValue: Any) -> int:
    kind = _sense_section(ctl, dataType, dataIndex)
    section = vendor_settings(ctl).get((kind, int(dataIndex)), {})
    store(pValue, 1 if section.get("reverse", False) else 0)
    return 0


# --- axes ----------------------------------------------------------------------------------------
def _mask_axes(ctl: Controller, mask: int) -> list[int]:
    m = int(mask) & 0xFFFFFFFF
    axes = [i + 1 for i in range(32) if m >> i & 1]
    missing = [a for a in axes if a not in ctl.axes]
    if missing:
        have = f"1..{max(ctl.axes)}" if ctl.axes else "none"
        raise ParameterError(f"mask=0x{m:X}: no axis {missing} (axes {have})")
    return axes


@gt_function
def GT_MultiAxisOn(ctl: Controller, mask: int) -> int:
    """Every axis of ``mask`` on (bit 0 = axis 1), in axis order."""
    for a in _mask_axes(ctl, mask):
        axis_on(ctl, axis_calls.bus_axis(ctl, a) if ctl.card is None else ctl.axis(a))
    return 0


@gt_function
def GT_MultiAxisOff(ctl: Controller, mask: int) -> int:
    for a in _mask_axes(ctl, mask):
        axis_off(ctl, axis_calls.bus_axis(ctl, a) if ctl.card is None else ctl.axis(a))
    return 0


def _limit_ex(ctl: Controller, axis: int, limit_type: int, limit_mode: int, on: bool) -> None:
    mode = int(limit_mode)
    if mode not in (LIMIT_MODE_ALL, LIMIT_MODE_EXTERNAL, LIMIT_MODE_SOFT):
        raise ParameterError(f"limitMode={mode}: 0 switches, 1 soft limits, -1 both")
    res = axis_resources(ctl, axis)
    if mode != LIMIT_MODE_SOFT:
        fn = GT_LmtsOn if on else GT_LmtsOff
        fn.__wrapped__(ctl, axis, limit_type)
    if mode != LIMIT_MODE_EXTERNAL:
        loop = servo_loop(ctl)
        s = res.safety
        n = int(axis)
        if on and n in loop.soft_stash:
            s.set_soft_limits(*loop.soft_stash.pop(n))
        elif not on and (s.soft_positive, s.soft_negative) != (
            SOFT_POSITIVE_OFF,
            SOFT_NEGATIVE_OFF,
        ):
            loop.soft_stash[n] = (s.soft_positive, s.soft_negative)
            s.set_soft_limits(SOFT_POSITIVE_OFF, SOFT_NEGATIVE_OFF)


@gt_function
def GT_LmtsOnEx(ctl: Controller, axis: int, limitType: int = -1, limitMode: int = -1) -> int:
    """Limits on: the switches (limitMode 0), the soft limits put aside (1), or both (-1)."""
    _limit_ex(ctl, axis, limitType, limitMode, True)
    return 0


@gt_function
def GT_LmtsOffEx(ctl: Controller, axis: int, limitType: int = -1, limitMode: int = -1) -> int:
    """Limits off: the switches (0), the soft limits (1, put aside until GT_LmtsOnEx), both (-1)."""
    _limit_ex(ctl, axis, limitType, limitMode, False)
    return 0


@gt_function
def GT_SetSoftLimitMode(ctl: Controller, axis: int, mode: int) -> int:
    axis_resources(ctl, axis)
    if int(mode) == SOFT_LIMIT_MODE_LIMIT:
        raise CommandError(
            "GT_SetSoftLimitMode: mode 1 (hold the axis inside the soft limits) is not "
            "emulated; mode 0 (stop past the limit) is"
        )
    servo_loop(ctl).soft_limit_mode[int(axis)] = int(mode)
    return 0


@gt_function
def GT_GetSoftLimitMode(ctl: Controller, axis: int, pMode: Any) -> int:
    axis_resources(ctl, axis)
    store(pMode, servo_loop(ctl).soft_limit_mode.get(int(axis), SOFT_LIMIT_MODE_STOP))
    return 0


# --- resources, card number ----------------------------------------------------------------------
_PER_AXIS = (MC_AXIS, MC_PROFILE, MC_CONTROL, MC_ENCODER, MC_STEP, MC_DAC)


def _resources(ctl: Controller, res_type: int) -> tuple[int, int]:
    """(max, count) of resource type ``res_type``."""
    t = int(res_type)
    io = ext_io(ctl)
    if t in _PER_AXIS:
        # the count is the controller's own (resource_count: a GTS card's axes, else 12),
        # before GT_InitEcatComm too: applications size their loops by it at start-up (the
        # vendor's EtherCAT demo counts its cores from it before the bus is up), and the
        # count forms of chapter 13 accept every one of these axes
        card = getattr(ctl, "card", None)
        top = card.spec.axes if card is not None else AXES_PER_CORE
        return top, resource_count(ctl)
    fixed = {MC_ADC: ADC_CHANNELS, MC_GPI: GPIO_COUNT, MC_GPO: GPIO_COUNT}
    if t in fixed:
        return fixed[t], fixed[t]
    ext = {
        MC_EXT_MODULE: len(io.modules),
        MC_EXT_DI: sum(m.spec.di for m in io.modules.values()),
        MC_EXT_DO: sum(m.spec.do for m in io.modules.values()),
        MC_EXT_AI: sum(m.spec.ai for m in io.modules.values()),
        MC_EXT_AO: sum(m.spec.ao for m in io.modules.values()),
    }
    if t in ext:
        top = 16 if t == MC_EXT_MODULE else ext[t]
        return top, ext[t]
    raise ParameterError(
        f"type={t}: MC_AXIS, MC_PROFILE, MC_CONTROL, MC_ENCODER, MC_STEP, MC_DAC, MC_ADC, "
        "MC_GPI, MC_GPO or MC_EXT_MODULE..MC_EXT_AO"
    )


@gt_function
def GT_GetResMax(ctl: Controller, type: int, pCount: Any) -> int:
    store(pCount, _resources(ctl, type)[0])
    return 0


@gt_function
def GT_GetResCount(ctl: Controller, type: int, pCount: Any) -> int:
    store(pCount, _resources(ctl, type)[1])
    return 0


@gt_function
def GT_SetCardNo(index: int) -> int:
    """The card later calls address, 0..15 (the current card of the process; GT_Open
    opens it: :mod:`gtecat.controller.cards`)."""
    SESSION.select(check_range("index", index, 0, _MAX_CARDS - 1))
    return 0


@gt_function
def GT_GetCardNo(pIndex: Any) -> int:
    """The current card (GT_SetCardNo; 0 at start)."""
    store(pIndex, SESSION.card)
    return 0


@gt_function
def GT_SetCore(core: int) -> int:
    """The core the ``GT_*`` functions address, 1 or 2 (the ``GTN_*`` ones name theirs):
    one per process, as the current card (:mod:`gtecat.controller.cards`)."""
    SESSION.core = check_range("core", core, 1, _CARD_CORES)
    return 0


@gt_function
def GT_GetCore(pCore: Any) -> int:
    """The core the ``GT_*`` functions address (GT_SetCore; 1 at start)."""
    store(pCore, SESSION.core)
    return 0


# --- the GTN header's spellings of the torque reading --------------------------------------------
@gt_function
def GT_GetAtlTorque(ctl: Controller, axis: int, pTorque: Any) -> int:
    """Torque actual value 6077h (per mille of rated torque), as GT_GetEcatAxisAtITorque."""
    ax = axis_calls.bus_axis(ctl, axis)
    axis_calls.reachable(ax, 0x6077)
    store(pTorque, ax.io.read(0x6077))
    return 0


@gt_function
def GT_GetEcatAxisAtlTorque(ctl: Controller, axis: int, pTorque: Any) -> int:
    """GT_GetEcatAxisAtITorque as the vendor's GTN header spells it (6077h)."""
    ax = axis_calls.bus_axis(ctl, axis)
    axis_calls.reachable(ax, 0x6077)
    store(pTorque, ax.io.read(0x6077))
    return 0


__all__ = ["PID_SETS", "TPid"]
