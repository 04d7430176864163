"""The arithmetic of motion programs (manual 10.4.1-10.4.2): 32-bit ``int`` and 16.16 ``double``.

Every value a program holds is one 32-bit two's-complement word.  An ``int`` is the
word itself; a ``double`` is fixed point: the word counts 2**-16 steps, so it holds
-32768 .. 32767.9999847 with the smallest step 1/65536 = 0.0000152587890625 (10.4.1).

The manual says nothing about overflow or rounding; a 32-bit controller's integer
unit implies these rules, which every operation here follows:

* **Overflow wraps** (two's complement, modulo 2**32), for ``int`` and ``double``
  alike, in ``+ - * / << `` and in the casts: no trap, no saturation.
  ``INT_MIN / -1`` is ``INT_MIN``.
* ``int`` division and ``%`` truncate toward zero (C99); ``a % b`` has the sign of ``a``.
* ``double`` multiplication is the 64-bit product shifted right by 16, i.e. rounded
  toward minus infinity; ``double`` division is ``(a << 16) / b`` truncated toward zero.
* Division or ``%`` by zero is a runtime error of the program (:class:`ZeroDivisionError`).
* Shift counts are taken modulo 32; ``>>`` is arithmetic (the sign is kept).
* ``(int)d`` truncates toward zero, as C does; ``(double)i`` is ``i << 16`` (wraps
  beyond +-32767).
* Constants and values coming from the host (``GT_SetVarValue``, a GT function's
  ``double`` result) are rounded to the nearest step, halves away from zero; a value
  outside the range is refused (:class:`OverflowError`), never wrapped silently.

So ``0.1`` is 6554 steps (0.100006...), ``0.1 * 3.0`` is 19662 steps and ``0.3`` is
19661: they differ, as 10.4.2 warns.
"""

from __future__ import annotations

import math
from fractions import Fraction

FRAC_BITS = 16
ONE = 1 << FRAC_BITS  #: 1.0 in steps
INT_MIN = -(1 << 31)
INT_MAX = (1 << 31) - 1
DOUBLE_MIN = INT_MIN / ONE  #: -32768.0
DOUBLE_MAX = INT_MAX / ONE  #: 32767.9999847...
STEP = 1 / ONE


def wrap32(x: int) -> int:
    """``x`` modulo 2**32 as a signed 32-bit value."""
    return ((x + 0x80000000) & 0xFFFFFFFF) - 0x80000000


def _trunc_div(a: int, b: int) -> int:
    """C99 integer division: the quotient truncated toward zero."""
    if b == 0:
        raise ZeroDivisionError("division by zero")
    q = abs(a) // abs(b)
    return q if (a < 0) == (b < 0) else -q


# --- int -----------------------------------------------------------------------------------
def iadd(a: int, b: int) -> int:
    return wrap32(a + b)


def isub(a: int, b: int) -> int:
    return wrap32(a - b)


def imul(a: int, b: int) -> int:
    return wrap32(a * b)


def idiv(a: int, b: int) -> int:
    return wrap32(_trunc_div(a, b))


def imod(a: int, b: int) -> int:
    return wrap32(a - b * _trunc_div(a, b))


def ineg(a: int) -> int:
    return wrap32(-a)


def shl(a: int, n: int) -> int:
    return wrap32(a << (n & 31))


def shr(a: int, n: int) -> int:
    return a >> (n & 31)


# --- double (16.16) ------------------------------------------------------------------------
def fmul(a: int, b: int) -> int:
    """Product of two 16.16 values (64-bit product >> 16: rounded toward -inf)."""
    return wrap32((a * b) >> FRAC_BITS)


def fdiv(a: int, b: int) -> int:
    """Quotient of two 16.16 values ((a << 16) / b, truncated toward zero)."""
    return wrap32(_trunc_div(a << FRAC_BITS, b))


def to_int(raw: int) -> int:
    """``(int)d``: truncation toward zero."""
    return raw >> FRAC_BITS if raw >= 0 else -((-raw) >> FRAC_BITS)


def from_int(i: int) -> int:
    """``(double)i``: ``i << 16``, wrapped."""
    return wrap32(i << FRAC_BITS)


def to_float(raw: int) -> float:
    """The exact value of a 16.16 word as a Python float."""
    return raw / ONE


def _round_half_away(x: Fraction) -> int:
    n = math.floor(abs(x) + Fraction(1, 2))
    return n if x >= 0 else -n


def from_fraction(x: Fraction) -> int:
    """The nearest 16.16 word (halves away from zero); OverflowError outside the range."""
    raw = _round_half_away(x * ONE)
    if not INT_MIN <= raw <= INT_MAX:
        raise OverflowError(
            f"{float(x):g} is outside the motion-program double range "
            f"{DOUBLE_MIN:g} .. {DOUBLE_MAX:.7f}"
        )
    return raw


def from_float(x: float) -> int:
    """A host double as a 16.16 word (nearest step); OverflowError outside or not finite."""
    if not math.isfinite(x):
        raise OverflowError(f"{x} is not a finite number")
    return from_fraction(Fraction(x))


def from_literal(text: str) -> int:
    """A decimal floating constant of the source (``12.5``, ``1e-3``) as a 16.16 word."""
    return from_fraction(Fraction(text.rstrip("fF")))


def int_from_float(x: float) -> int:
    """A host double stored into an ``int`` variable: nearest integer (halves away from 0);
    OverflowError outside 32 bits."""
    if not math.isfinite(x):
        raise OverflowError(f"{x} is not a finite number")
    v = _round_half_away(Fraction(x))
    if not INT_MIN <= v <= INT_MAX:
        raise OverflowError(f"{x:g} does not fit a 32-bit int")
    return v


__all__ = [
    "DOUBLE_MAX",
    "DOUBLE_MIN",
    "FRAC_BITS",
    "INT_MAX",
    "INT_MIN",
    "ONE",
    "STEP",
    "fdiv",
    "fmul",
    "from_float",
    "from_fraction",
    "from_int",
    "from_literal",
    "iadd",
    "idiv",
    "imod",
    "imul",
    "ineg",
    "int_from_float",
    "isub",
    "shl",
    "shr",
    "to_float",
    "to_int",
    "wrap32",
]
