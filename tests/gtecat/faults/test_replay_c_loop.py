"""The replay's calls made in the C entries' loop (gtecat.gt.centry.replay_loop) give what the
Python loop gives: the same calls made, the same count, the same first divergence - for every
kind of value the loop sets and compares (signed and unsigned integers of each width, doubles,
floats, arrays' bytes), for values it leaves to Python (a number of another type, one the
object does not hold, a NaN), and for a recorded session and its tampered copies."""

from __future__ import annotations

import ctypes
from collections.abc import Callable
from ctypes import byref, c_double, c_long, c_ubyte
from pathlib import Path
from typing import Any

import pytest

from gtecat import gt
from gtecat.errors import ParameterError
from gtecat.faults import record as rec
from gtecat.gt import centry

from .conftest import changed, fig5_2_jogging, recorded

pytestmark = pytest.mark.skipif(centry.replay_loop() is None, reason=centry.REASON or "no loop")


def _twice(a: int, p: Any, *rest: Any) -> int:
    """A GT-like function: the value ``a`` times what ``p``'s object holds, left there (an
    array's every element); its code ``a - 3`` (0 for a = 3)."""
    obj = getattr(p, "_obj", p)  # (byref(x): x)
    if isinstance(obj, ctypes.Array):
        for j in range(len(obj)):
            obj[j] = obj[j] * a
    else:
        obj.value = obj.value * a
    return a - 3


def _steps(lines: list[dict[str, Any]]) -> list[tuple[Any, Any]]:
    """Each entry made ready as the replay makes a form's calls: one call per function,
    code and values left (its form), each line's values beside it."""
    pool: dict[Any, Any] = {}
    calls: dict[Any, Any] = {}
    steps = []
    for e in lines:
        call, vals = rec._prepare(e, _twice, pool)
        steps.append((calls.setdefault((e["c"], e["r"], "o" in e), call), vals))
    return steps


def _both(steps: list[tuple[Any, Any]], mp: pytest.MonkeyPatch) -> tuple[Any, int]:
    """(the replay's answer, the steps the Python loop made) with the C loop, checked
    against the Python loop's answer."""
    made = [0]
    step = rec._step

    def counted(*a: Any) -> Any:
        made[0] += 1
        return step(*a)

    answers = []
    for loop in (False, True):
        mp.setattr(rec, "C_LOOP", loop)
        mp.setattr(rec, "_step", counted if loop else step)
        try:
            answers.append(rec._replay(steps, None, None))
        except ParameterError as e:  # (a value the object refuses: damaged, both ways)
            answers.append(str(e))
    mp.setattr(rec, "_step", step)
    assert answers[1] == answers[0]
    return answers[1], made[0]


def _call(c: str, before: Any, after: Any, a: int = 2, rc: int = -1) -> dict[str, Any]:
    e: dict[str, Any] = {"c": f"F_{c}", "a": [a, {"ref": {"c": c, "v": before}}], "r": rc}
    if after != before:
        e["o"] = {"1": {"ref": {"c": c, "v": after}}}
    return e


@pytest.mark.parametrize(
    ("c", "v"),
    [
        ("c_byte", -60), ("c_short", -3000), ("c_int", -(2**30)), ("c_long", -(2**62)),
        ("c_ubyte", 120), ("c_ushort", 30000), ("c_uint", 2**31), ("c_ulong", 2**62),
        ("c_double", -1234.5), ("c_float", 0.25),
    ],
)  # fmt: skip
def test_each_kind_of_value_matches_and_diverges_as_in_python(
    c: str, v: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    ok = [_call(c, v // 2 if type(v) is int else v / 2, v) for _ in range(5)]
    (n, div), python_made = _both(_steps(ok), monkeypatch)
    assert (n, div) == (5, None) and python_made == 0  # (every call in C)
    bad = [*ok[:3], _call(c, v // 2 if type(v) is int else v / 2, v - 1), *ok[:2]]
    (n, div), _ = _both(_steps(bad), monkeypatch)
    assert n == 4 and div is not None and div.what == "argument 2"
    rc = [*ok[:2], _call(c, v // 2 if type(v) is int else v / 2, v, rc=0)]
    (n, div), _ = _both(_steps(rc), monkeypatch)
    assert (n, div.what if div else None) == (3, "return code")


@pytest.mark.parametrize(
    ("c", "before", "after"),
    [
        ("c_double", 3, 6),  # (ints for a double: Python sets and compares them)
        ("c_long", 2.0, 4.0),  # (floats for an integer: Python refuses, as before)
        ("c_ubyte", 200, 144),  # (a product the byte wraps, 400 -> 144: in C too)
        ("c_ulong", 2**63 + 1, 2),  # (past a long long: Python compares)
        ("c_double", float("nan"), float("nan")),
        ("c_float", 1e39, 2e39),  # (past a float's range)
    ],
)
def test_values_the_loop_leaves_to_python_give_python_answers(
    c: str, before: Any, after: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    lines = [_call(c, before, after) for _ in range(3)]
    _both(_steps(lines), monkeypatch)


def test_arrays_bytes_are_set_and_compared_in_c(monkeypatch: pytest.MonkeyPatch) -> None:
    def line(vals: list[float], out: list[float]) -> dict[str, Any]:
        arr = {"arr": "c_double", "n": 3, "v": vals}
        return {
            "c": "F_arr",
            "a": [2, arr, 3, None],
            "r": -1,
            "o": {"1": {"arr": "c_double", "n": 3, "v": out}},
        }

    ok = [line([1.0, 2.0, k], [2.0, 4.0, 2 * k]) for k in (3.0, 4.0, 5.0)]
    (n, div), python_made = _both(_steps(ok), monkeypatch)
    assert (n, div, python_made) == (3, None, 0)
    bad = [*ok[:2], line([1.0, 2.0, 7.0], [2.0, 4.5, 14.0])]
    (n, div), _ = _both(_steps(bad), monkeypatch)
    assert n == 3 and div is not None and div.what == "argument 2 element [1]"


def _poll(k: int) -> None:
    """A pass of a polling application: status, positions one by one and as arrays, the
    raw image, the clock, a wait."""
    sts, pos, clk = c_long(), c_double(), ctypes.c_ulong()
    arr, raw = (c_double * 4)(), (c_ubyte * 8)()
    gt.GT_GetSts(1, byref(sts))
    gt.GT_GetPrfPos(1, byref(pos))
    gt.GT_GetEncPos(1, arr, 2, None)
    gt.GT_GetEcatRawData(0, 8, raw)
    gt.GT_GetClock(byref(clk))
    if k % 3 == 0:
        gt.GTE_Wait(1.0)


def _session() -> None:
    fig5_2_jogging(4.0)
    for k in range(300):
        _poll(k)


@pytest.fixture(scope="module")
def session_file(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return recorded(tmp_path_factory.mktemp("loop") / "s.gtrec", _session)


@pytest.mark.parametrize(
    ("picked", "change"),
    [
        (None, None),
        (lambda s: '"GT_GetPrfPos"' in s and '"o"' in s, "value"),
        (lambda s: '"GT_GetEncPos"' in s and '"o"' in s, "array"),
        (lambda s: '"GT_GetEcatRawData"' in s, "raw"),
        (lambda s: '"GT_GetSts"' in s, "rc"),
    ],
    ids=["whole", "value", "array", "raw", "rc"],
)
def test_a_recorded_session_and_its_tampered_copies(
    session_file: Path,
    tmp_path: Path,
    picked: Callable[[str], bool] | None,
    change: str | None,
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    def tamper(e: dict[str, Any]) -> None:
        if change == "rc":
            e["r"] = 1
        elif change == "value":
            e["o"]["1"]["ref"]["v"] += 1
        elif change == "array":
            e["o"]["1"]["v"][1] += 1
        else:  # (the bytes the call leaves: written back, or left as they were)
            held = e["o"]["2"] if "o" in e else e["a"][2]
            held["hex"] = ("00" if held["hex"][:2] == "ff" else "ff") + held["hex"][2:]

    path = session_file
    if picked is not None:
        path = tmp_path / "t.gtrec"
        changed(session_file, path, picked, 120, tamper)
    answers = []
    for loop in (False, True):
        monkeypatch.setattr(rec, "C_LOOP", loop)
        answers.append(rec.replay(path))
    assert answers[0] == answers[1]
    _n, div = answers[1]
    assert (div is None) == (picked is None), div
