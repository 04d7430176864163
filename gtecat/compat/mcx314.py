"""The MCX314 card library (its manual's chapter 4) over our axes.

``from gtecat.compat import mcx314 as m`` and the functions of tables 4-2 to 4-7 with
the manual's names and argument order.  The library has no open call (the card is found at
power-up): the first call opens the card (the one ``GT_Open`` opened, else a ``gts:4`` card
with the ``GTECAT_*`` settings); :func:`Open` (ours) chooses its options.  The manual's
functions are ``void``: they return None, and a value outside the manual's range (or a call
the card cannot do now) raises :class:`~gtecat.compat.CompatError` naming it; the
``unsigned`` readers return the register (32-bit two's complement for positions).

Decisions where the manual is silent (besides the shared ones of :mod:`._card`):

* **``axis`` is a bit mask** (X 0x1, Y 0x2, Z 0x4, U 0x8), as the manual writes it for the
  interpolation pairs (xy 0x3 ...) and for its I/O functions ("可多軸設置"): a register
  call writes every selected axis (the MCX314 way); range 1..15.
* **LINEDATA / CIRCLEDATA** (4.5: "初速度、速度、加速度等") hold ``SV, V, A, D, K`` as
  ctypes ints; ``D = 0`` decelerates with ``A``.  The end point of an interpolation is
  each axis's ``SetP`` register, an arc's centre the ``SetC`` registers (both relative to
  the start, 4.5.2); ``SetFP`` / ``SetCP`` (table 4-4's names) are the same calls.
* **Speeds** (4.4): the formulas of the manual with M from ``SetRange`` (M = 8000000/R, all
  axes), ``SetMultiple`` (M directly, per axis) or ``SetMaxSpeed`` (the smallest M with
  ``8000·M >= max speed``, all axes).  An interpolation uses the lowest selected axis's M
  and counts speed in base pulses (:mod:`gtecat.controller.crd.base_pulse`).
* **Curves**: ``_C`` interpolations run at constant ``V``; ``_T`` with T ramps and the
  deceleration ``AutoDec`` / ``ManualDec`` chose (``ManualDec(axis, DecPulse)``: at
  ``DecPulse`` base pulses); a T arc needs ``ManualDec`` (4.4 note: raises otherwise);
  ``_S`` lines with S ramps.  ``SCurve_F``'s unnamed fifth argument has no effect (the
  text names no deceleration: S drives are symmetric).  ``LINEDATA``/``CIRCLEDATA`` are
  taken by their fields (or their layout), not their class.
  ``TCurve_F`` / ``SCurve_F`` ``Pulse`` is relative, its sign the direction.
* **Soft limits**: ``SLMTP(n)`` / ``SLMTM(n)`` make COMP+ / COMP- soft limits of all
  axes (``SetCompP`` / ``SetCompM(axis, data)``); ``n`` is the "active level" the thesis
  names, kept (a comparison has none), ``RESET`` turns them off; ``SLMTSig(n)`` compares
  with LP (0) or EP (1).
* **Signal levels** (``HLMTP``, ``HLMTM``, ``ALMSig``, ``InPosSig``, ``HomeTypeN``'s
  level bits) set the level the card reads as active, as gtecat.compat._card's
  "Electrical levels" describes (the ADT850's logic settings); ``EnableALM`` /
  ``EnableInPos`` make the alarm stop drives / drives wait for INPOS.  ``EncoderMode`` /
  ``EncoderCWCCW`` set the real counter's input and direction.  ``SetPulseMode`` and
  ``SetAO`` change nothing here and say so in :func:`last_error`.
* **Axis numbers**: every ``axis`` is the chip's bit mask (X 1, Y 2, Z 4, U 8), as the
  thesis writes the interpolation pairs (xy 0x3 ...); the readers (``ReadLPS``,
  ``ReadEPS``, ``ReadCV``, ``ReadCA``) read one axis ("為各軸分別讀取"): 1, 2, 4 or 8.
  Decision: a plain axis number is not guessed (3 could be Z or X+Y, 4 Z or U): a value
  that is no single axis's bit raises CompatError naming the four.
* **Homing** ``HomeTypeN(WR1Reg, SV, V, A)``: ``WR1Reg`` is the chip's WR1 (IN k enable
  and level bits, the interrupt enables); every axis is homed, negatively, unless ours
  ``axis=`` / ``direction=`` say otherwise (:func:`HomeType1`).  The origin signal is the
  lowest enabled IN; the EZ of types 3/4 is IN1.  The slow speed is SV.  The call
  returns when the axes stand (it runs the controller), like the manual's blocking flow
  (figures 3-28 to 3-31).
* **Bit-pattern interpolation** is named in table 4-1 but no function is documented;
  :func:`BitPattern` (ours) takes per-step ``(+, -)`` bit words per axis and runs them as
  one-base-pulse lines at constant ``V``.
"""

from __future__ import annotations

import ctypes
import functools
import math
from collections.abc import Callable, Sequence
from typing import Any

from ..controller.crd import bank
from ..controller.epoch import changed as readers_changed
from ..controller.motion.scurve import SCurveParams
from ._card import (
    ALARM,
    AXES,
    GPIN,
    INPOS,
    LMTM,
    LMTP,
    STOP0,
    CompatError,
    PulseCard,
    integer,
    open_card,
)
from ._card import last_error as last_error
from ._card import set_last_error as _set_error

_CARD: list[PulseCard | None] = [None]
PULSE_MAX = 268_435_455
HOME_TIMEOUT_MS = 600_000.0
#: how long a homing step waits for INPOS once its pulses are out (EnableInPos)
INPOS_WAIT_MS = 10_000.0
_MASKS2 = {0x3: (1, 2), 0x5: (1, 3), 0x9: (1, 4), 0x6: (2, 3), 0xA: (2, 4), 0xC: (3, 4)}
_MASKS3 = {0x7: (1, 2, 3), 0xB: (1, 2, 4), 0xD: (1, 3, 4), 0xE: (2, 3, 4)}


class LINEDATA(ctypes.Structure):
    """Linear interpolation speeds (module docstring)."""

    _fields_ = [("SV", ctypes.c_int), ("V", ctypes.c_int), ("A", ctypes.c_int),
                ("D", ctypes.c_int), ("K", ctypes.c_int)]  # fmt: skip


class CIRCLEDATA(ctypes.Structure):
    """Circular interpolation speeds (module docstring)."""

    _fields_ = [("SV", ctypes.c_int), ("V", ctypes.c_int), ("A", ctypes.c_int),
                ("D", ctypes.c_int), ("K", ctypes.c_int)]  # fmt: skip


def _api(fn: Callable[..., Any]) -> Callable[..., Any]:
    """Record the reason of a failure, then let the CompatError through (``void`` calls)."""

    @functools.wraps(fn)
    def call(*args: Any, **kwargs: Any) -> Any:
        card = _CARD[0]
        try:
            return fn(*args, **kwargs)
        except CompatError as e:
            _set_error(f"{fn.__name__}: {e}")
            raise
        except Exception as e:  # a controller refusal: the same clear error
            _set_error(f"{fn.__name__}: {e}")
            raise CompatError(f"{fn.__name__}: {e}") from e
        finally:
            readers_changed()  # (the card changed without a GT call: controller/epoch.py)
            if card is not None:
                card.tick()

    return call


def _card() -> PulseCard:
    """The card; the first call of a program opens it (the thesis' library has no open
    call: the card is there from power-up), with the card ``GT_Open`` opened if there is
    one, else a ``gts:4`` card with the ``GTECAT_*`` settings."""
    if _CARD[0] is None:
        Open()
    card = _CARD[0]
    assert card is not None
    return card


def _axes(axis: Any) -> list[int]:
    m = integer("axis", axis, 1, 15)
    return [n for n in AXES if m >> (n - 1) & 1]


def _each(axis: Any) -> tuple[PulseCard, list[int]]:
    return _card(), _axes(axis)


# --- opening (ours) -------------------------------------------------------------------------
def Open(**options: Any) -> None:
    """Open the card (GT_Open's options; an open pulse-card controller is used as it is)."""
    if _CARD[0] is not None:
        _CARD[0].close()
        _CARD[0] = None
    try:
        _CARD[0] = open_card("MCX314", **options)
    except Exception as e:
        _set_error(f"Open: {e}")
        raise CompatError(f"Open: {e}") from e
    for n in AXES:
        _CARD[0].regs[n].settings["fp"] = 0
        _CARD[0].regs[n].settings["cp"] = 0


def Close() -> None:
    """Release the card (the controller stays open)."""
    if _CARD[0] is not None:
        _CARD[0].close()
        _CARD[0] = None


# --- 4.3 initial settings ---------------------------------------------------------------------
@_api
def SetPulseMode(axis: int, mode: int) -> None:
    """Single (0) or double (1) pulse output (4.3).  Decision: the emulated amplifier
    takes either (it is set up for the card's output), so nothing changes; the call says
    so in :func:`last_error`."""
    card, axes = _each(axis)
    for n in axes:
        card.regs[n].settings["pulse_mode"] = integer("mode", mode, 0, 1)
    _set_error("SetPulseMode: kept; the emulated amplifier takes either pulse output mode")


@_api
def SetMultiple(axis: int, data: int) -> None:
    """The multiplier M, 1..500."""
    card, axes = _each(axis)
    m = integer("data", data, 1, 500)
    for n in axes:
        card.regs[n].m = float(m)
        card._limit_mode(n)


@_api
def SetRange(data: int) -> None:
    """R, 16000..8000000, all axes: M = 8000000/R."""
    card = _card()
    r = integer("data", data, 16_000, 8_000_000)
    for n in AXES:
        card.regs[n].m = 8_000_000 / r
        card._limit_mode(n)


@_api
def SetMaxSpeed(data: int) -> None:
    """The fastest drive speed (PPS) 1..4000000: M = ceil(data/8000), all axes."""
    card = _card()
    m = max(math.ceil(integer("data", data, 1, 4_000_000) / 8000), 1)
    for n in AXES:
        card.regs[n].m = float(m)
        card._limit_mode(n)


# --- 4.4 basic motion -------------------------------------------------------------------------
def _register(attr: str, lo: int, hi: int, doc: str, live: bool = False) -> Callable:
    @_api
    def setter(axis: int, data: int) -> None:
        card, axes = _each(axis)
        v = integer("data", data, lo, hi)
        for n in axes:
            setattr(card.regs[n], attr, v)
            if attr in ("a", "d"):
                card._limit_mode(n)
            if live:
                card.change_speed(n)

    setter.__doc__ = doc
    return setter


SetSV = _register("sv", 1, 8000, "Initial speed SV, 1..8000: SV·M PPS.")
SetV = _register("v", 1, 8000, "Drive speed V, 1..8000: V·M PPS (while driving: re-planned).", True)
SetA = _register("a", 1, 8000, "Acceleration A, 1..8000: A·125·M PPS/s.")
SetD = _register("d", 1, 8000, "Deceleration D, 1..8000: D·125·M PPS/s (D != A: asymmetric).")
SetAA = _register("k", 1, 65_535, "Jerk parameter K, 1..65535: 62.5e6/K·M PPS/s².")
for _f, _n in ((SetSV, "SetSV"), (SetV, "SetV"), (SetA, "SetA"), (SetD, "SetD"),
               (SetAA, "SetAA")):  # fmt: skip
    _f.__name__ = _f.__qualname__ = _n


@_api
def SetAO(axis: int, data: int) -> None:
    """The deceleration offset, 0..65535 (4.4: pulses a fixed drive runs at SV after its
    deceleration, so a stepper does not stop from speed).  Decision: the emulated
    deceleration ends exactly at SV on the last pulse (no rounding to make up for), so
    the offset changes nothing; kept, and said in :func:`last_error`."""
    card, axes = _each(axis)
    for n in axes:
        card.regs[n].settings["ao"] = integer("data", data, 0, 65_535)
    _set_error("SetAO: kept; the emulated deceleration reaches SV on the last pulse")


@_api
def Pulse(axis: int, data: int) -> None:
    """Output pulses of the next fixed drive, 0..268435455 (its direction: TCurve_F's sign)."""
    card, axes = _each(axis)
    for n in axes:
        card.regs[n].settings["pulse"] = integer("data", data, 0, PULSE_MAX)


@_api
def AutoDec() -> None:
    """Automatic deceleration of fixed drives, all axes."""
    card = _card()
    for n in AXES:
        card.regs[n].manual = False


@_api
def ManualDec(axis: int, DecPulse: int) -> None:
    """Manual deceleration at ``DecPulse`` pulses from the start (interpolation: base pulses)."""
    card, axes = _each(axis)
    p = integer("DecPulse", DecPulse, 0, PULSE_MAX)
    for n in axes:
        card.regs[n].manual = True
        card.regs[n].dec_pos = p


ManDec = ManualDec  # table 4-3's name


def _curve(axis: Any, sv: Any, v: Any, a: Any, d: Any, k: Any, s: bool) -> tuple:
    card, axes = _each(axis)
    vals = (
        integer("SV", sv, 1, 8000),
        integer("V", v, 1, 8000),
        integer("A", a, 1, 8000),
        integer("D", d, 0, 8000),
        integer("K", k, 1, 65_535),
    )
    for n in axes:
        r = card.regs[n]
        r.sv, r.v, r.a, r.k = vals[0], vals[1], vals[2], vals[4]
        r.d, r.asym = (vals[3], True) if vals[3] else (vals[2], False)
        r.s_curve = s
    return card, axes


def _fixed(card: PulseCard, axes: list[int], pulse: Any) -> None:
    p = integer("Pulse", pulse, -PULSE_MAX, PULSE_MAX)
    for n in axes:
        card.drive(n, abs(p), 1 if p >= 0 else -1)


@_api
def TCurve_F(axis: int, SV: int, m_V: int, A: int, Pulse: int) -> None:
    """T-curve fixed drive of ``Pulse`` pulses (relative)."""
    card, axes = _curve(axis, SV, m_V, A, 0, 1, False)
    _fixed(card, axes, Pulse)


@_api
def TCurve_C(axis: int, SV: int, V: int, A: int, direction: int = 0) -> None:
    """T-curve continuous drive until a stop (``direction`` ours: 0 +, 1 -)."""
    card, axes = _curve(axis, SV, V, A, 0, 1, False)
    for n in axes:
        card.drive(n, None, -1 if integer("direction", direction, 0, 1) else 1)


@_api
def SCurve_F(
    axis: int, m_SV: int, m_V: int, m_A: int, unnamed: int, m_K: int, m_Pulse: int
) -> None:
    """S-curve fixed drive. The prototype's fifth argument has no name and the text names
    SV, V, A and K only: it is taken (an int, checked) and has no effect; the curve is
    symmetric (deceleration = A)."""
    integer("unnamed", unnamed, -(2**31), 2**31 - 1)
    card, axes = _curve(axis, m_SV, m_V, m_A, 0, m_K, True)
    _fixed(card, axes, m_Pulse)


@_api
def SCurve_C(axis: int, m_SV: int, m_V: int, m_A: int, m_K: int, direction: int = 0) -> None:
    """S-curve continuous drive until a stop."""
    card, axes = _curve(axis, m_SV, m_V, m_A, 0, m_K, True)
    for n in axes:
        card.drive(n, None, -1 if integer("direction", direction, 0, 1) else 1)


@_api
def DecStop(axis: int) -> None:
    """Decelerating stop (the chip's command; the manual lists it among the basic commands)."""
    card, axes = _each(axis)
    for n in axes:
        card.decel_stop(n)


@_api
def SuddenStop(axis: int) -> None:
    """Immediate stop."""
    card, axes = _each(axis)
    for n in axes:
        card.sudden_stop(n)


# --- 4.5 interpolation ------------------------------------------------------------------------
def _data(p: Any, cls: type) -> Any:
    """A LINEDATA / CIRCLEDATA by its fields, not its class: a program's own structure
    (ctypes, or any object) with ``SV, V, A, D, K`` works, as in C any struct of that
    layout would; a ctypes structure without those names is read by layout (five ints)."""
    obj = getattr(p, "_obj", p)
    if isinstance(obj, ctypes._Pointer):
        obj = obj.contents
    names = [f[0] for f in cls._fields_]
    if all(hasattr(obj, n) for n in names):
        return obj
    if isinstance(obj, ctypes.Structure) and ctypes.sizeof(obj) >= ctypes.sizeof(cls):
        return cls.from_buffer_copy(bytes(memoryview(obj).cast("B"))[: ctypes.sizeof(cls)])
    raise CompatError(
        f"a {cls.__name__} (fields {', '.join(names)}), or a pointer to one, is expected"
    )


def _prm(card: PulseCard, master: int, d: Any, shape: str) -> SCurveParams:
    m = card.regs[master].m
    sv = integer("SV", d.SV, 1, 8000)
    v = integer("V", d.V, 1, 8000)
    if shape == "C":
        return SCurveParams(v * m / 1000, v * m / 1000)
    a = integer("A", d.A, 1, 8000)
    dd = integer("D", d.D, 0, 8000) or a
    jerk = 62.5e6 / integer("K", d.K, 1, 65_535) * m / 1e9 if shape == "S" else math.inf
    return SCurveParams(sv * m / 1000, v * m / 1000, a * 125 * m / 1e6, dd * 125 * m / 1e6, jerk)


def _line(pLD: Any, axis: Any, table: dict, shape: str) -> None:
    card = _card()
    d = _data(pLD, LINEDATA)
    m = integer("axis", axis, 1, 15)
    if m not in table:
        raise CompatError(f"axis={m:#x}: one of {', '.join(hex(k) for k in table)}")
    axes = list(table[m])
    master = axes[0]
    delta = tuple(card.regs[n].settings.get("fp", 0) for n in axes)
    regs = card.regs[master]
    decel = "manual" if regs.manual else "auto"
    card.interpolate(axes, master, PulseCard.line(delta), _prm(card, master, d, shape), decel,
                     float(regs.dec_pos))  # fmt: skip


def _circle(pCD: Any, axis: Any, ccw: bool, shape: str) -> None:
    card = _card()
    d = _data(pCD, CIRCLEDATA)
    m = integer("axis", axis, 1, 15)
    if m not in _MASKS2:
        raise CompatError(f"axis={m:#x}: one of {', '.join(hex(k) for k in _MASKS2)}")
    axes = list(_MASKS2[m])
    master = axes[0]
    regs = card.regs[master]
    if shape == "T" and not regs.manual:
        raise CompatError(
            "a T-curve arc needs ManualDec (MCX314 library manual 4.4: AutoDec cannot be used)"
        )
    end = tuple(card.regs[n].settings.get("fp", 0) for n in axes)
    ctr = tuple(card.regs[n].settings.get("cp", 0) for n in axes)
    card.interpolate(axes, master, PulseCard.arc(end, ctr, ccw), _prm(card, master, d, shape),
                     "manual" if shape == "T" else "auto", float(regs.dec_pos))  # fmt: skip


@_api
def SetC(axis: int, data: int) -> None:
    """Arc centre coordinate of the selected axes, relative to the start."""
    card, axes = _each(axis)
    for n in axes:
        card.regs[n].settings["cp"] = integer("data", data, -8_388_608, 8_388_607)


@_api
def SetP(axis: int, data: int) -> None:
    """Interpolation end point of the selected axes, relative to the start."""
    card, axes = _each(axis)
    for n in axes:
        card.regs[n].settings["fp"] = integer("data", data, -8_388_608, 8_388_607)


SetCP, SetFP = SetC, SetP  # table 4-4's names


def _interp_fn(name: str, doc: str, body: Callable[[Any, Any], None]) -> Callable:
    def fn(p: Any, axis: int) -> None:
        body(p, axis)

    fn.__name__ = fn.__qualname__ = name
    fn.__doc__ = doc
    return _api(fn)


Line2D_C = _interp_fn(
    "Line2D_C", "2-axis line, constant V.", lambda p, a: _line(p, a, _MASKS2, "C")
)
Line3D_C = _interp_fn(
    "Line3D_C", "3-axis line, constant V.", lambda p, a: _line(p, a, _MASKS3, "C")
)
Line2D_T = _interp_fn("Line2D_T", "2-axis line, T-curve.", lambda p, a: _line(p, a, _MASKS2, "T"))
Line3D_T = _interp_fn("Line3D_T", "3-axis line, T-curve.", lambda p, a: _line(p, a, _MASKS3, "T"))
Line2D_S = _interp_fn("Line2D_S", "2-axis line, S-curve.", lambda p, a: _line(p, a, _MASKS2, "S"))
Line3D_S = _interp_fn("Line3D_S", "3-axis line, S-curve.", lambda p, a: _line(p, a, _MASKS3, "S"))
CircleCW_C = _interp_fn("CircleCW_C", "Clockwise arc, constant V.",
                        lambda p, a: _circle(p, a, False, "C"))  # fmt: skip
CircleCCW_C = _interp_fn("CircleCCW_C", "Counter-clockwise arc, constant V.",
                         lambda p, a: _circle(p, a, True, "C"))  # fmt: skip
CircleCW_T = _interp_fn("CircleCW_T", "Clockwise arc, T-curve (needs ManualDec).",
                        lambda p, a: _circle(p, a, False, "T"))  # fmt: skip
CircleCCW_T = _interp_fn("CircleCCW_T", "Counter-clockwise arc, T-curve (needs ManualDec).",
                         lambda p, a: _circle(p, a, True, "T"))  # fmt: skip


@_api
def BitPattern(axis: int, V: int, plus: Sequence[Sequence[int]], minus: Sequence[Sequence[int]]):
    """Ours (module docstring): bit-pattern interpolation of the axes in ``axis`` at constant
    ``V``; ``plus[i]`` / ``minus[i]`` are the 16-bit words of the i-th selected axis, bit b
    of word w = step 16·w + b (LSB first), a + / - pulse at that step."""
    card, axes = _each(axis)
    v = integer("V", V, 1, 8000)
    if len(plus) != len(axes) or len(minus) != len(axes):
        raise CompatError("one plus and one minus word list per selected axis")
    words = {len(p) for p in plus} | {len(m) for m in minus}
    if len(words) != 1:
        raise CompatError("every axis needs the same number of words")
    nwords = words.pop()
    m = card.regs[axes[0]].m
    prm = SCurveParams(v * m / 1000, v * m / 1000)
    for w in range(nwords):
        for b in range(16):
            step = []
            for k in range(len(axes)):
                pw = integer("plus", plus[k][w], 0, 0xFFFF)
                mw = integer("minus", minus[k][w], 0, 0xFFFF)
                up, down = pw >> b & 1, mw >> b & 1
                if up and down:
                    raise CompatError(f"axis {axes[k]} step {16 * w + b}: both + and - set")
                step.append(up - down)
            if any(step):
                card.interpolate(axes, axes[0], PulseCard.line(tuple(step)), prm, "none")


# --- 4.6 I/O signals --------------------------------------------------------------------------
def _axis_setting(name: str, doc: str, apply: Callable[[PulseCard, int, int], None]) -> Callable:
    def fn(n: int, axis: int) -> None:
        card, axes = _each(axis)
        v = integer("n", n, 0, 1)
        for a in axes:
            apply(card, a, v)

    fn.__name__ = fn.__qualname__ = name
    fn.__doc__ = doc
    return _api(fn)


def _set_logic(k: int) -> Callable[[PulseCard, int, int], None]:
    def apply(card: PulseCard, a: int, v: int) -> None:
        card.regs[a].logic[k] = v

    return apply


HLMTP = _axis_setting(
    "HLMTP",
    "4.6: the hardware + limit's active level, 0 Low, 1 Hi (the level the card reads as "
    'active: gtecat.compat._card, "Electrical levels").',
    _set_logic(LMTP),
)
HLMTM = _axis_setting(
    "HLMTM", "4.6: the hardware - limit's active level (as HLMTP).", _set_logic(LMTM)
)
ALMSig = _axis_setting(
    "ALMSig", "4.6: the alarm input's active level, 0 Low, 1 Hi.", _set_logic(ALARM)
)
InPosSig = _axis_setting(
    "InPosSig", "4.6: the in-position input's active level, 0 Low, 1 Hi.", _set_logic(INPOS)
)
EncoderMode = _axis_setting(
    "EncoderMode",
    "4.6: the real counter's input: 2-phase A/B (0) or single pulses up/down (1). The "
    "emulated amplifier gives A/B: set to 1, the counter holds its reading "
    "(gtecat.compat._card ``counted``).",
    lambda card, a, v: card.count_mode(a, v, None, None),
)
EncoderCWCCW = _axis_setting(
    "EncoderCWCCW",
    "4.6 (named, not described): the real counter's direction, 0 as the encoder turns, "
    "1 reversed (decision: the chip's counting-direction setting).",
    lambda card, a, v: card.count_mode(a, None, v, None),
)


@_api
def HLMTSig(n: int, axis: int) -> None:
    """Hardware limits stop at once (0) or decelerating (1)."""
    card, axes = _each(axis)
    v = integer("n", n, 0, 1)
    for a in axes:
        card.regs[a].limit_decel = bool(v)
        card._limit_mode(a)


@_api
def SLMTP(n: int) -> None:
    """Sets up the COMP+ soft limit of all axes; ``n`` is its active level (0 low, 1 high),
    as the thesis writes it.

    Decision: a soft limit is a comparison, with no electrical level; the call turns the
    COMP+ limit on whatever ``n`` is (0 and 1 alike), and keeps ``n``. ``RESET`` turns it
    off."""
    card = _card()
    level = integer("n", n, 0, 1)
    for a in AXES:
        card.regs[a].soft[0] = True
        card.regs[a].settings["slmtp_level"] = level


@_api
def SLMTM(n: int) -> None:
    """The COMP- soft limit of all axes, as :func:`SLMTP` (``n`` the active level)."""
    card = _card()
    level = integer("n", n, 0, 1)
    for a in AXES:
        card.regs[a].soft[1] = True
        card.regs[a].settings["slmtm_level"] = level


@_api
def SLMTSig(n: int) -> None:
    """The COMP registers compare with LP (0) or EP (1), all axes."""
    card = _card()
    for a in AXES:
        card.regs[a].soft_ep = bool(integer("n", n, 0, 1))


@_api
def EnableALM(n: int) -> None:
    """The amplifier alarm input of all axes on (1): active, it stops a drive at once
    and a drive started then ends at once."""
    card = _card()
    for a in AXES:
        card.regs[a].alarm_on = bool(integer("n", n, 0, 1))


@_api
def EnableInPos(n: int) -> None:
    """The in-position input of all axes on (1): a drive whose pulses are out is over
    only when the card sees INPOS active (the amplifier within 1 pulse of the plan,
    InPosSig's level); a homing step waits for it before the next."""
    card = _card()
    for a in AXES:
        card.regs[a].inpos_on = bool(integer("n", n, 0, 1))


# --- 4.7 homing -------------------------------------------------------------------------------
def _search(card: PulseCard, axes: list[int], direction: int, prm: tuple[int, int, int],
            cond: Callable[[int], bool], immediate: bool) -> None:  # fmt: skip
    """Drive ``axes`` on until ``cond(axis)``, then stop (at once or decelerating)."""
    sv, v, a = prm
    for n in axes:
        r = card.regs[n]
        r.sv, r.v, r.a, r.s_curve, r.asym = sv, v, a, False, False
        if cond(n):
            continue
        card.drive(n, None, direction)
    t = waited = 0.0
    while any(card.driving(n) for n in axes):
        card.wait_cycle()
        t += card.cycle_ms
        for n in axes:
            if card.pulsing(n) and cond(n) and not card.regs[n].stopped_by_user:
                (card.sudden_stop if immediate else card.decel_stop)(n)
        if not any(card.pulsing(n) for n in axes):
            waited += card.cycle_ms
            if waited > INPOS_WAIT_MS:
                for n in axes:
                    card.regs[n].await_inpos = False
                raise CompatError(
                    f"homing: the axes stand but INPOS never came within {INPOS_WAIT_MS:g} ms "
                    "(EnableInPos on, InPosSig's level never seen)"
                )
        if t > HOME_TIMEOUT_MS:
            for n in axes:
                card.sudden_stop(n)
            raise CompatError(f"homing: no signal within {HOME_TIMEOUT_MS:.0f} ms")
    for n in axes:
        if card.regs[n].stopdata & 0x18:
            raise CompatError(f"homing: axis {n} ran into a limit before its origin signal")


def _in(k: int) -> int:
    """The input index (gtecat.compat._card SIGNALS) of the chip's IN k: IN0-IN2 are the
    ADT850's STOP0-STOP2 (home switch, encoder Z, probe 1); IN3 is an input nothing in the
    machine drives (it reads high)."""
    return STOP0 + k if k < 3 else GPIN


def _home(
    kind: int, WR1Reg: Any, SV: Any, V: Any, A: Any, axis: Any = None, direction: Any = -1
) -> None:
    card = _card()
    w = integer("WR1Reg", WR1Reg, 0, 0xFFFF)
    prm = (integer("SV", SV, 1, 8000), integer("V", V, 1, 8000), integer("A", A, 1, 8000))
    if integer("direction", direction, -1, 1) == 0:
        raise CompatError("direction=0: -1 (negative, the default) or 1 (positive)")
    g = int(direction)
    slow = (prm[0], prm[0], prm[2])
    ins = [k for k in range(4) if w >> (2 * k + 1) & 1]
    if not ins:
        raise CompatError("WR1Reg enables no input (bit 1 IN0, bit 3 IN1, bit 5 IN2, bit 7 IN3)")
    org = ins[0]
    chosen = _axes(axis) if axis is not None else list(AXES)
    for n in chosen:  # the chip's WR1 of every axis: IN k enabled with its level bit
        for k in ins:
            card.regs[n].logic[_in(k)] = w >> (2 * k) & 1
    can = [n for n in chosen if _can_find(card, n, org, g)]
    lost = [n for n in chosen if n not in can]
    if lost and (axis is not None or not can):
        raise CompatError(
            f"homing: axis {', '.join(map(str, lost))} has no IN{org} signal "
            f"{'ahead' if g < 0 else 'ahead in the positive direction'} in the machine "
            "description: the search would never end"
        )
    if lost:
        _set_error(f"HomeType{kind}: axis {', '.join(map(str, lost))} left standing: no IN{org} "
                   "signal ahead in the machine description")  # fmt: skip
    axes = can
    on = lambda n: card.active(n, _in(org))  # noqa: E731
    off = lambda n: not on(n)  # noqa: E731
    ez = lambda n: card.active(n, _in(1))  # noqa: E731
    _search(card, axes, g, prm, on, immediate=False)
    if kind == 2:
        _search(card, axes, -g, slow, off, immediate=True)
        _search(card, axes, g, slow, on, immediate=True)
    elif kind == 3:
        _search(card, axes, g, slow, ez, immediate=True)
    elif kind == 4:
        _search(card, axes, g, slow, ez, immediate=True)
        _search(card, axes, -g, slow, off, immediate=True)
        _search(card, axes, g, slow, on, immediate=True)


def _can_find(card: PulseCard, n: int, org: int, g: int) -> bool:
    """Whether axis ``n``'s search in direction ``g`` can meet IN ``org`` (it is active
    now, or the machine has it ahead; a limit ahead does not count: the search would end
    on the limit, an error)."""
    if card.active(n, _in(org)):
        return True
    return org < 3 and card.signal_ahead(n, org, g, limits=False)


def _home_fn(kind: int, doc: str) -> Callable:
    def fn(WR1Reg: int, SV: int, V: int, A: int, *, axis: int | None = None,
           direction: int = -1) -> None:  # fmt: skip
        _home(kind, WR1Reg, SV, V, A, axis, direction)

    fn.__name__ = fn.__qualname__ = f"HomeType{kind}"
    fn.__doc__ = doc + _HOME_DOC
    return _api(fn)


_HOME_DOC = """

    4.7: ``WR1Reg`` is the chip's WR1 register, written to every axis homed: bit 2k+1
    enables IN k as a stop input and bit 2k is its active level (0 Low, 1 Hi; IN0 the
    home switch, IN1 the encoder Z, IN2 probe 1, IN3 an input nothing drives); the
    lowest enabled IN is the origin signal, types 3 and 4 stop on IN1 at SV.  Bits 8-15
    are the chip's interrupt enables: taken, no interrupts are emulated.

    Decisions (the thesis names no axis and no direction): every axis is homed, in the
    negative direction.  An axis whose machine description has no origin signal ahead
    is left standing (named in ``last_error()``; the chip would search until stopped);
    none able to find it: CompatError.  Ours, after the thesis' arguments: ``axis`` (a
    bit mask; then every axis of it must find its signal) and ``direction`` (1
    positive).  The call returns when the axes stand (with EnableInPos: in position); a
    limit met first raises CompatError."""


HomeType1 = _home_fn(1, "Search the origin signal, decelerate and stop (figure 3-28).")
HomeType2 = _home_fn(2, "Type 1, then back off at SV and approach the origin slowly (3-29).")
HomeType3 = _home_fn(3, "Type 1, then on at SV to the encoder Z and stop (3-30).")
HomeType4 = _home_fn(4, "Type 1, Z at SV, back off, approach the origin slowly (3-31).")


# --- 4.8 position registers -------------------------------------------------------------------
def _u32(x: float) -> int:
    return round(x) & 0xFFFFFFFF


def _s32(name: str, data: Any) -> int:
    v = integer(name, data, -(2**31), 2**32 - 1)
    return v - 2**32 if v >= 2**31 else v


@_api
def LPS(axis: int, data: int) -> None:
    """Write the logic position counter of the selected axes (nothing moves)."""
    card, axes = _each(axis)
    for n in axes:
        card.set_lp(n, _s32("data", data))


@_api
def EPS(axis: int, data: int) -> None:
    """Write the real position counter."""
    card, axes = _each(axis)
    for n in axes:
        card.set_ep(n, _s32("data", data))


def _one(axis: Any) -> tuple[PulseCard, int]:
    card = _card()
    m = integer("axis", axis, 0, 15)
    if m not in (1, 2, 4, 8):
        raise CompatError(
            f"axis={m}: one axis is read at a time, by its bit: X 1, Y 2, Z 4, U 8 "
            "(not an axis number)"
        )
    return card, {1: 1, 2: 2, 4: 3, 8: 4}[m]


@_api
def ReadLPS(axis: int) -> int:
    """The logic position counter, unsigned 32 bits."""
    card, n = _one(axis)
    return _u32(card.lp(n))


@_api
def ReadEPS(axis: int) -> int:
    """The real position counter, unsigned 32 bits."""
    card, n = _one(axis)
    return _u32(card.ep(n))


@_api
def ReadCV(axis: int) -> int:
    """The current drive speed in V units, 0 standing."""
    card, n = _one(axis)
    return round(card.speed(n))


@_api
def ReadCA(axis: int) -> int:
    """The current acceleration in A units; at constant speed it holds the value the ramp
    ended with (the thesis: the register holds its value), 0 before any drive."""
    card, n = _one(axis)
    return round(card.accel(n, held=True))


@_api
def SetCompP(axis: int, data: int) -> None:
    """COMP+ of the selected axes."""
    card, axes = _each(axis)
    for n in axes:
        card.regs[n].comp[0] = _s32("data", data)


@_api
def SetCompM(axis: int, data: int) -> None:
    """COMP- of the selected axes."""
    card, axes = _each(axis)
    for n in axes:
        card.regs[n].comp[1] = _s32("data", data)


@_api
def RESET() -> None:
    """Stop every drive at once and put the registers back to their opening values."""
    card = _card()
    for c in bank(card.ctl).systems.values():
        if c.running:
            c.abort()
    for n in AXES:
        card.sudden_stop(n)
        r = card.regs[n]
        lp, ep = r.lp_off, r.ep_off
        card.regs[n] = type(r)(lp_off=lp, ep_off=ep)
        card.regs[n].settings.update(fp=0, cp=0)
        card._limit_mode(n)


def card() -> PulseCard | None:
    """Emulator-only: the open card object."""
    return _CARD[0]
