"""GTN_ readers on cores 2.. of a bus of more than 32 axes (views of core 1's bus,
gtecat.controller.core_view) answered by the C entries as core 1 answers the bus axis
32·(core-1)+axis: the same values, return codes and reasons as the Python path, for every
local axis, those beyond a core's drives (resources at rest, as the manual's span rule
reads them), beyond 32, cores the bus does not have, and a card whose second core is its own
(no view: the Python path)."""

from __future__ import annotations

import itertools
from ctypes import byref, c_double, c_long
from pathlib import Path
from typing import Any

import pytest

from gtecat import gt
from gtecat.gt import centry
from tools.gen_axes_eni import write_axes_eni

from .conftest import bring_up

N = 40  # core 1 whole, core 2 with 8 axes (bus axes 33..40)


@pytest.fixture
def bus(tmp_path: Path) -> Any:
    if centry._MAKE is None:
        pytest.skip(f"the C entries are not built here: {centry.REASON}")
    bring_up(str(write_axes_eni(N, tmp_path / "bus.eni")), clock="lockstep")
    masks: dict[int, int] = {}
    for a in range(1, N + 1):
        c, n = (a - 1) // 32 + 1, (a - 1) % 32 + 1
        assert gt.GTN_AxisOn(c, n) == 0
        prm = gt.TTrapPrm()
        prm.acc = prm.dec = 0.5
        gt.GTN_PrfTrap(c, n)
        gt.GTN_SetTrapPrm(c, n, byref(prm))
        gt.GTN_SetPos(c, n, (-1) ** a * 1_000_000)
        gt.GTN_SetVel(c, n, 5 + a % 9)
        masks[c] = masks.get(c, 0) | 1 << (n - 1)
    for c, m in masks.items():
        assert gt.GTN_Update(c, m) == 0
    gt.GTE_Wait(37)
    yield
    gt.GT_Close()


def _reads(core: int, axis: int) -> list[tuple[Any, ...]]:
    out = []
    for name, t in (("GetSts", c_long), ("GetPrfPos", c_double), ("GetEncPos", c_double),
                    ("GetPrfVel", c_double), ("GetAxisPrfPos", c_double)):  # fmt: skip
        fn = getattr(gt, "GTN_" + name, None)
        if fn is None:
            continue
        o = t()
        rc = fn(core, axis, byref(o))
        out.append((name, rc, o.value, gt.GTE_GetLastError() if rc else ""))
        o2 = t()
        rc2 = fn(core, axis, o2, 1, None)  # (the object itself, count 1, pClock NULL)
        out.append((name, rc2, o2.value))
    return out


PLACES = [(c, n) for c in (2, 3) for n in (0, 1, 2, 8, 9, 31, 32, 33)] + [(2, -1), (40, 1)]


def test_cores_beyond_one_read_as_the_python_path(bus: Any) -> None:
    assert centry.GATES[2] == 1  # (the bus's cores 2.. are views: the C entries answer them)
    seen = {}
    for place in PLACES:
        seen[place] = _reads(*place)
    centry.GATES[2] = 0  # the Python path for every core but 1
    try:
        for place in PLACES:
            assert _reads(*place) == seen[place], place
    finally:
        centry.GATES[2] = 1
    # and they are the bus axes' own, as core 1 reads them
    for c, n in ((2, 1), (2, 8)):
        assert [r[:3] for r in seen[(c, n)]] == [r[:3] for r in _reads(1, 32 * (c - 1) + n)]
    assert seen[(3, 1)][0][1] == 7 and seen[(2, 33)][0][1] == 7  # (no such core, local axis)


def test_a_card_with_a_second_core_of_its_own_closes_the_view_gate(bus: Any) -> None:
    from gtecat.gt import _core

    s = _core.SESSION
    assert centry.GATES[2] == 1
    s.controllers[7] = s.controllers[1]  # (any other core of the card's own: no views)
    try:
        assert centry.GATES[2] == 0
    finally:
        del s.controllers[7]
    assert centry.GATES[2] == 1


SPANS = [(2, 32, 2), (2, 1, 33), (2, 30, 3), (2, 1, 32), (2, 8, 2), (2, 1, 8), (2, 7, 2)]


def test_a_span_reads_the_same_at_every_call(bus: Any) -> None:
    """A span of a core beyond 1 answers as that core's table path does at every call (the
    first call is the table path's): inside the core, core 1's fast path by the bus axes;
    past the core's 32 axes, 7 every time (it once answered 7, then the next core's axes)."""
    for (core, axis, count), name in itertools.product(SPANS, ("GTN_GetPrfPos", "GTN_GetSts")):
        fn = getattr(gt, name)
        t = c_long if name.endswith("Sts") else c_double
        seen = []
        for _ in range(3):
            arr = (t * count)()
            rc = fn(core, axis, arr, count, None)
            seen.append((rc, list(arr)))
        assert seen[0] == seen[1] == seen[2], (name, core, axis, count, seen)
        if axis + count - 1 > 32:
            assert seen[0][0] == 7, (name, core, axis, count)
