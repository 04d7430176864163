"""Fixed-point and 32-bit arithmetic against an independent integer model (gtecat.programs.fixed).

The model computes with exact rationals (``Fraction``) and decimal rounding, then
reduces to 32 bits through numpy's ``int32`` cast - none of the code under test.  The
same operations are also run through the compiler and the program runtime
(``r = a op b;`` in a motion program), so what a program computes is what the model
says: overflow wraps modulo 2**32, ``double *`` rounds toward minus infinity,
``double /`` and ``int /`` ``%`` truncate toward zero, shifts count modulo 32.
"""

from __future__ import annotations

import math
from decimal import ROUND_HALF_UP, Decimal
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from gtecat.programs import fixed

WORD = st.integers(-(1 << 31), (1 << 31) - 1)
SMALL = st.integers(-40_000, 40_000)
WORDS = st.one_of(WORD, SMALL, st.sampled_from([0, 1, -1, 65536, -65536, 1 << 31 - 1]))


# --- the model ------------------------------------------------------------------------------------
def m_wrap(x: int) -> int:
    return int(np.array([x % (1 << 32)], dtype=np.uint64).astype(np.uint32).view(np.int32)[0])


def m_trunc(q: Fraction) -> int:
    return math.trunc(q)


def m_fmul(a: int, b: int) -> int:
    return m_wrap(math.floor(Fraction(a) * Fraction(b) / 65536))


def m_fdiv(a: int, b: int) -> int:
    return m_wrap(m_trunc(Fraction(a * 65536, b)))


def m_idiv(a: int, b: int) -> int:
    return m_wrap(m_trunc(Fraction(a, b)))


def m_imod(a: int, b: int) -> int:
    return m_wrap(a - b * m_trunc(Fraction(a, b)))


def m_from_float(x: float) -> int | None:
    q = (Decimal(x) * 65536).quantize(Decimal(1), rounding=ROUND_HALF_UP)
    v = int(q)
    return v if -(1 << 31) <= v < (1 << 31) else None


# --- the functions --------------------------------------------------------------------------------
@given(WORDS, WORDS)
def test_add_sub_mul_wrap_like_a_32_bit_alu(a, b):
    assert fixed.iadd(a, b) == m_wrap(a + b)
    assert fixed.isub(a, b) == m_wrap(a - b)
    assert fixed.imul(a, b) == m_wrap(a * b)


@given(WORDS, WORDS)
def test_int_division_truncates_toward_zero(a, b):
    assume(b != 0)
    assert fixed.idiv(a, b) == m_idiv(a, b)
    assert fixed.imod(a, b) == m_imod(a, b)
    if m_idiv(a, b) == m_trunc(Fraction(a, b)):  # no overflow: C's identity holds
        assert fixed.idiv(a, b) * b + fixed.imod(a, b) == a


@given(WORDS, WORDS)
def test_fixed_multiply_rounds_down_and_divide_truncates(a, b):
    assert fixed.fmul(a, b) == m_fmul(a, b)
    assume(b != 0)
    assert fixed.fdiv(a, b) == m_fdiv(a, b)


@given(WORDS, st.integers(-100, 100))
def test_shifts_count_modulo_32_and_keep_the_sign(a, n):
    assert fixed.shl(a, n) == m_wrap(a * (1 << (n % 32)))
    assert fixed.shr(a, n) == math.floor(Fraction(a, 1 << (n % 32)))


@given(WORDS)
def test_casts(a):
    assert fixed.to_int(a) == m_trunc(Fraction(a, 65536))
    assert fixed.from_int(a) == m_wrap(a * 65536)
    assert fixed.ineg(a) == m_wrap(-a)


@given(st.floats(allow_nan=False, allow_infinity=False, min_value=-40_000, max_value=40_000))
def test_host_values_round_to_the_nearest_step_or_are_refused(x):
    want = m_from_float(x)
    if want is None:
        with pytest.raises(OverflowError):
            fixed.from_float(x)
    else:
        assert fixed.from_float(x) == want
        assert abs(fixed.to_float(want) - x) <= 2**-17


def test_division_by_zero_is_an_error():
    for fn in (fixed.idiv, fixed.imod, fixed.fdiv):
        with pytest.raises(ZeroDivisionError):
            fn(5, 0)


def test_the_manual_warning_0_1_times_3_is_not_0_3():
    tenth, three, point3 = (
        fixed.from_literal("0.1"),
        fixed.from_literal("3.0"),
        fixed.from_literal("0.3"),
    )
    assert tenth == 6554 and point3 == 19661
    assert fixed.fmul(tenth, three) == 19662 != point3
    assert fixed.STEP == 0.0000152587890625


def test_range_limits():
    assert fixed.DOUBLE_MIN == -32768.0
    assert fixed.from_float(32767.99998) == (1 << 31) - 1
    with pytest.raises(OverflowError):
        fixed.from_float(32768.0)
    assert fixed.from_float(-32768.0) == -(1 << 31)
    assert fixed.idiv(-(1 << 31), -1) == -(1 << 31)  # wraps, no trap
    assert fixed.int_from_float(2.5) == 3 and fixed.int_from_float(-2.5) == -3
    with pytest.raises(OverflowError):
        fixed.int_from_float(2.0**31)


# --- the same through a motion program ----------------------------------------------------------
_PROGRAM = """
int ia; int ib; int ir;
double da; double db; double dr;
int f()
{{
    {stmt}
    return 0;
}}
"""
_INT_OPS = {
    "+": lambda a, b: m_wrap(a + b),
    "-": lambda a, b: m_wrap(a - b),
    "*": lambda a, b: m_wrap(a * b),
    "/": m_idiv,
    "%": m_imod,
    "<<": lambda a, b: m_wrap(a * (1 << (b % 32))),
    ">>": lambda a, b: math.floor(Fraction(a, 1 << (b % 32))),
    "&": lambda a, b: a & b,
    "|": lambda a, b: a | b,
    "^": lambda a, b: a ^ b,
    "<": lambda a, b: int(a < b),
    ">=": lambda a, b: int(a >= b),
    "==": lambda a, b: int(a == b),
    "&&": lambda a, b: int(bool(a) and bool(b)),
    "||": lambda a, b: int(bool(a) or bool(b)),
}
_DOUBLE_OPS = {
    "+": lambda a, b: m_wrap(a + b),
    "-": lambda a, b: m_wrap(a - b),
    "*": m_fmul,
    "/": m_fdiv,
}


@pytest.fixture(scope="module")
def programs():
    from tests.gtecat.programs.conftest import Host

    cache: dict[str, Host] = {}

    def get(stmt: str) -> Host:
        if stmt not in cache:
            cache[stmt] = Host(_PROGRAM.format(stmt=stmt))
        return cache[stmt]

    return get


def _run(h, sets: dict[str, int], result: str) -> tuple[int, int]:
    for k, v in sets.items():
        h.set_g(k, v)
    h.start()
    h.until_idle()
    return h.rt.status(0).error, h.g(result)


@pytest.mark.parametrize("op", sorted(_INT_OPS))
@settings(deadline=None)
@given(a=WORDS, b=WORDS)
@pytest.mark.sample(4)
def test_int_operations_in_a_program_match_the_model(programs, op, a, b):
    err, r = _run(programs(f"ir = ia {op} ib;"), {"ia": a, "ib": b}, "ir")
    if op in "/%" and b == 0:
        assert err == 101
    else:
        assert err == 0 and r == _INT_OPS[op](a, b)


@pytest.mark.parametrize("op", sorted(_DOUBLE_OPS))
@settings(deadline=None)
@given(a=WORDS, b=WORDS)
def test_double_operations_in_a_program_match_the_model(programs, op, a, b):
    err, r = _run(programs(f"dr = da {op} db;"), {"da": a, "db": b}, "dr")
    if op == "/" and b == 0:
        assert err == 101
    else:
        assert err == 0 and r == _DOUBLE_OPS[op](a, b)


@settings(deadline=None)
@given(a=WORDS)
def test_casts_in_a_program_match_the_model(programs, a):
    _, r = _run(programs("ir = (int)da;"), {"da": a}, "ir")
    assert r == m_trunc(Fraction(a, 65536))
    _, r = _run(programs("dr = (double)ia;"), {"ia": a}, "dr")
    assert r == m_wrap(a * 65536)
    _, r = _run(programs("ir = -ia;"), {"ia": a}, "ir")
    assert r == m_wrap(-a)
    _, r = _run(programs("ir = ~ia;"), {"ia": a}, "ir")
    assert r == m_wrap(~a)
    _, r = _run(programs("ir = !ia;"), {"ia": a}, "ir")
    assert r == int(a == 0)
