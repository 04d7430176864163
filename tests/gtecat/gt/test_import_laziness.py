"""What importing ``gtecat.gt`` no longer makes for every function, and that the functions
behave as they did when it was made at import.

* The table binder of each function (:func:`gtecat.gt.args.binder`) is made by the
  function's first call that binds through it, not at import (most of the ~400 functions
  are never called in a process: a replay calls a handful).  Every function's binder is
  still made without error, and a first call answers as a later one does.
* The signatures share their :class:`inspect.Parameter` objects (one per parameter text):
  each is equal to the one made parameter by parameter from the table.
* The pointer types a fast path takes (:func:`gtecat.gt.args._scalar_types`) are found once
  per C type: the same sets as the parameter-by-parameter check gives.
"""

from __future__ import annotations

import ctypes
import inspect
import subprocess
import sys
from typing import Any

from gtecat import gt
from gtecat.errors import ParameterError
from gtecat.gt._core import REGISTRY
from gtecat.gt.args import _NUMERIC, Ref, _scalar_types, check_kind
from gtecat.gt.table import FUNCTIONS


def _table_function(fn: Any) -> Any:
    """The table path's function behind a public one (a fast path or a C entry in front)."""
    return getattr(fn, "slow", fn)


def _cell(fn: Any, name: str) -> Any:
    """The value of the closure variable ``name`` of the GT function ``fn`` (or of the
    function its compiled binder asks for the table's converters, which holds the binder)."""
    code = fn.__code__
    if name not in code.co_freevars:
        fn = _cell(fn, "_convs")
        code = fn.__code__
    return fn.__closure__[code.co_freevars.index(name)].cell_contents


def _emulated() -> dict[str, Any]:
    """Every emulated ``GT_``/``GTE_`` function's table path, by name."""
    out = {}
    for name, fn in REGISTRY.items():
        table = _table_function(fn)
        if name in FUNCTIONS and "_convs" in getattr(table, "__code__", None).co_freevars:
            out[name] = table
    return out


def test_the_import_makes_no_binder() -> None:
    """In a fresh process no function has its binder once ``gtecat.gt`` is imported; a first
    call of plain arguments binds through the compiled binder alone (``GT_x`` and its
    ``GTN_x`` twin), and the first argument of another shape makes the table binder."""
    code = (
        "from gtecat import gt\n"
        "from tests.gtecat.gt.test_import_laziness import _cell, _emulated\n"
        "made = [n for n, f in _emulated().items() if _cell(f, 'bind') is not None]\n"
        "vel, pos = _emulated()['GT_SetVel'], _emulated()['GT_SetPos']\n"
        "calls = [gt.GTN_SetVel(1, 1, 5.0), gt.GT_SetPos(1, 2)]\n"
        "plain = [_cell(f, 'bind') is None for f in (vel, pos)]\n"
        "calls += [gt.GTN_SetVel(1, 1, 'fast'), gt.GT_SetPos(1, 2.5)]\n"
        "odd = [_cell(f, 'bind') is not None for f in (vel, pos)]\n"
        "print(len(_emulated()), calls, plain, odd, '|', made)\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True, timeout=120
    )
    head, made = out.stdout.split("|", 1)
    count, after = head.split(" ", 1)
    assert int(count) > 300 and made.strip() == "[]", out.stdout
    # (not open: -1 for the plain calls, bound first; the others refused by the binder: 7)
    assert after.strip() == "[-1, -1, 7, 7] [True, True] [True, True]", out.stdout


def test_every_binder_is_made_and_kept() -> None:
    """Each function's binder is made without error when asked for, once."""
    functions = _emulated()
    assert len(functions) > 300
    for name, fn in functions.items():
        made = _cell(fn, "_binder")()
        assert callable(made) and made.convs is not None, name
        assert _cell(fn, "_binder")() is made and _cell(fn, "bind") is made, name


def test_a_first_call_answers_as_a_later_one() -> None:
    """A refusal of the binder (the controller is not even open) reads the same the first
    time (the binder made then) and the next."""
    answers = []
    for _ in range(2):
        answers.append((gt.GT_SetTrapPrm(1, "not a pointer"), gt.GTE_GetLastError()))
        answers.append((gt.GTN_SetVel(1, 1, "fast"), gt.GTE_GetLastError()))
        answers.append((gt.GT_SetPos(1, 2, 3), gt.GTE_GetLastError()))
    assert answers[:3] == answers[3:]
    assert [rc for rc, _ in answers[:3]] == [7, 7, 7], answers
    assert "pPrm" in answers[0][1] and "vel" in answers[1][1], answers


def test_the_signatures_are_the_tables() -> None:
    for name, fn in REGISTRY.items():
        proto = getattr(fn, "prototype", None)
        if proto is None or not name.startswith(("GT_", "GTE_")):
            continue
        want = []
        for p in proto.params:
            try:
                d = p.default_value()
            except KeyError:
                d = inspect.Parameter.empty
            want.append(
                inspect.Parameter(p.name, inspect.Parameter.POSITIONAL_OR_KEYWORD, default=d)
            )
        got = list(inspect.signature(fn).parameters.values())
        assert got[: len(want)] == want, name
        assert all(q.kind is inspect.Parameter.KEYWORD_ONLY for q in got[len(want) :]), name
    assert str(inspect.signature(gt.GT_GetSts)) == "(axis, pSts, count=1, pClock=None)"
    assert str(inspect.signature(gt.GT_SetVel)) == "(profile, vel)"


def test_the_pointer_types_are_found_per_c_type_as_per_parameter() -> None:
    """Every kind of pointer parameter of the table (what else it says of the pointer beside
    the C type: its direction, count, NULL)."""
    seen = set()
    for proto in FUNCTIONS.values():
        for p in proto.params:
            kind = (p.ctype, p.stars, p.text, p.direction, p.optional, type(p.count), p.mask)
            if not p.pointer or kind in seen:
                continue
            seen.add(kind)
            want = set()
            for t in _NUMERIC:
                try:
                    check_kind(p, Ref(p.name, 0, ctypes.sizeof(t), t))
                except ParameterError:
                    continue
                want.add(t)
            assert _scalar_types(p) == want, (proto.name, p)
    assert len(seen) > 50
