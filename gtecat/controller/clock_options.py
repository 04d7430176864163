"""The clock options of ``GT_Open``: ``cycle_ms`` and ``call_latency_us``, checked once.

Both are numbers a caller types (``GT_Open(cycle_ms=0.5, call_latency_us=20)``); no file and
no environment variable gives them.  :func:`check` takes them as ``GT_Open`` received them and
refuses a bad one with :class:`~gtecat.errors.ParameterError` (``GT_Open`` returns 7, the
manual's "parameter error" of table 3-1, as for any other option it refuses), naming the
option, the value and the legal range; it never lets a value through that would make the
clock fail later (a traceback from inside a GT call), stop (no time passing) or never run a
cycle.

* ``cycle_ms`` - the controller (and bus) cycle in milliseconds; None: the ENI's cycle
  time, else 1 ms.  Legal: the bus cycles an ENI may give (:data:`gtecat.eni.limits.CYCLE_NS`,
  31.25 us to 1 s, the one place that range is written), so ``GT_Open`` and the ENI reader
  accept the same cycles.  Rounded to whole nanoseconds, the clock's unit.
* ``call_latency_us`` - the controller time one GT call costs in the ``auto`` clock (a host
  round trip).  Legal: 0 (calls cost no time: it moves only by waits, as in ``lockstep``)
  or 0.001 us (1 ns, the clock's resolution) up to :data:`MAX_CALL_LATENCY_NS`, 1 s.  Why
  1 s: a real host call takes tens of microseconds over PCIe and a few milliseconds at most
  over a network; a call that costs a second of controller time is no host a program can
  be tested against, it is the longest legal cycle, and the bound keeps the clock's integer
  nanoseconds (signed 64-bit memory the GT readers' C entries share) far from overflowing
  however many calls a program makes.  A positive value under 1 ns is refused rather than
  rounded to 0, which would silently stop time in a polling loop.

Numbers are ``int``, ``float``, ``decimal.Decimal`` and the other real numbers
(``fractions.Fraction``, numpy scalars); ``bool`` is not a number here (``cycle_ms=True``
is a mistake, not 1 ms), nor is a string (``"1"``), None where a number is needed, a list
or NaN; an infinity is out of range.
"""

from __future__ import annotations

import dataclasses
import numbers
from decimal import Decimal
from typing import TYPE_CHECKING, Any

from gtecat.eni.limits import CYCLE_NS

from ..errors import ParameterError

if TYPE_CHECKING:
    from .core import Options

#: the longest controller time one GT call may cost (module docstring): 1 s
MAX_CALL_LATENCY_NS = 1_000_000_000

_NS_PER_MS = 1_000_000
_NS_PER_US = 1_000


def _text(ns: int, per: int) -> str:
    """``ns`` in a unit of ``per`` ns, exactly and without a trailing zero (31250, 10**6 ->
    ``0.03125``)."""
    return format((Decimal(ns) / per).normalize(), "f")


#: the legal cycle_ms, from the ENI's range
CYCLE_MS_TEXT = (
    f"{_text(CYCLE_NS.lo, _NS_PER_MS)}..{_text(CYCLE_NS.hi, _NS_PER_MS)} ms (a positive cycle "
    f"of {_text(CYCLE_NS.lo, _NS_PER_US)} us to {_text(CYCLE_NS.hi, 10**9)} s, as in an ENI)"
)
#: the legal call_latency_us
CALL_LATENCY_US_TEXT = (
    f"0 or {_text(1, _NS_PER_US)}..{_text(MAX_CALL_LATENCY_NS, _NS_PER_US)} us (0: a call "
    f"costs no controller time; at most {_text(MAX_CALL_LATENCY_NS, 10**9)} s a call)"
)


def _show(value: Any) -> str:
    """``value`` for a message: as typed, a huge integer in hex, a long text cut short."""
    if isinstance(value, int) and not isinstance(value, bool) and abs(value) >= 1 << 128:
        text = f"{value:#x}"  # (repr of a huge int is refused: sys.set_int_max_str_digits)
    else:
        text = repr(value)
    if len(text) > 40:
        return f"{text[:16]}...{text[-8:]} ({len(text)} characters)"
    return text


def _number(name: str, value: Any, unit: str, legal: str) -> Decimal:
    """``value`` exactly, as a finite Decimal, or the option's error."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real | Decimal):
        raise ParameterError(f"{name}={_show(value)} is not a number of {unit}: legal is {legal}")
    try:
        if isinstance(value, Decimal):
            d = value
        else:
            d = Decimal(int(value) if isinstance(value, numbers.Integral) else float(value))
    except (OverflowError, ValueError, TypeError):  # (a Fraction beyond any float)
        d = Decimal("Infinity")
    if d.is_nan():
        raise ParameterError(f"{name}={_show(value)} is not a number of {unit}: legal is {legal}")
    if not d.is_finite():
        raise _out_of_range(name, value, legal)
    return d


def _out_of_range(name: str, value: Any, legal: str) -> ParameterError:
    return ParameterError(f"{name}={_show(value)} is out of range: legal is {legal}")


def cycle_ns(cycle_ms: Any) -> int | None:
    """The cycle ``cycle_ms`` gives, in whole nanoseconds (None: not given); else
    :class:`ParameterError` (module docstring)."""
    if cycle_ms is None:
        return None
    ms = _number("cycle_ms", cycle_ms, "milliseconds", CYCLE_MS_TEXT)
    ns = ms * _NS_PER_MS
    if not CYCLE_NS.lo <= ns <= CYCLE_NS.hi:
        raise _out_of_range("cycle_ms", cycle_ms, CYCLE_MS_TEXT)
    return int(ns.to_integral_value())


def call_latency_ns(call_latency_us: Any) -> int:
    """The controller time ``call_latency_us`` gives a GT call, in whole nanoseconds; else
    :class:`ParameterError` (module docstring)."""
    us = _number("call_latency_us", call_latency_us, "microseconds", CALL_LATENCY_US_TEXT)
    ns = us * _NS_PER_US
    if ns != 0 and not 1 <= ns <= MAX_CALL_LATENCY_NS:
        raise _out_of_range("call_latency_us", call_latency_us, CALL_LATENCY_US_TEXT)
    return int(ns.to_integral_value())


def check(options: Options) -> Options:
    """``options`` with its clock options checked and made plain floats (what the controller
    computes with); :class:`ParameterError` naming the first bad one."""
    cyc = cycle_ns(options.cycle_ms)
    lat = call_latency_ns(options.call_latency_us)
    return dataclasses.replace(
        options,
        cycle_ms=None if cyc is None else float(options.cycle_ms),
        call_latency_us=float(options.call_latency_us) if lat else 0.0,
    )


__all__ = [
    "CALL_LATENCY_US_TEXT",
    "CYCLE_MS_TEXT",
    "MAX_CALL_LATENCY_NS",
    "call_latency_ns",
    "check",
    "cycle_ns",
]
