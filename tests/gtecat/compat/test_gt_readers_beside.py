"""An application that drives a card through a compat layer and reads it through the GT
readers as well: each read after a layer's call answers as the table path does (the
readers' kept values are asked again after every call of a layer, which changes the card
without a GT call)."""

from __future__ import annotations

from collections.abc import Callable
from ctypes import byref, c_double, c_long
from typing import Any

from gtecat import gt
from gtecat.compat import adt850 as adt
from gtecat.compat import gt400 as g

from .conftest import open_card


def _reads(axis: int, table: bool = False) -> tuple:
    m, s, p = c_long(), c_long(), c_double()
    for name, o in (("GT_GetPrfMode", m), ("GT_GetSts", s), ("GT_GetPrfPos", p)):
        fn = getattr(gt, name)
        assert (fn.slow if table else fn)(axis, byref(o)) == 0
    return m.value, s.value, p.value


def _check(steps: list[tuple[str, Callable[[], Any]]], axes: tuple[int, ...]) -> None:
    for what, step in steps:
        for a in axes:
            _reads(a)  # (polled before: values the C entries keep)
        step()
        for a in axes:
            assert _reads(a) == _reads(a, table=True), (what, a)


def test_adt850_calls_are_seen_by_the_next_gt_read() -> None:
    open_card(a1={"positive_limit": 1e9}, a2={"positive_limit": 1e9})
    assert adt.adt850_initial() == 1
    gt.GTE_Wait(5)
    _check(
        [
            ("pmove", lambda: adt.pmove(0, 1, 5000)),
            ("cycles", lambda: gt.GTE_Wait(20)),
            ("sudden_stop", lambda: adt.sudden_stop(0, 1)),
            ("continue_move", lambda: adt.continue_move(0, 2, 0)),
            ("set_command_pos", lambda: adt.set_command_pos(0, 1, 777)),
        ],
        (1, 2),
    )


def test_gt400_calls_are_seen_by_the_next_gt_read() -> None:
    open_card(a2={"positive_limit": 1e9})
    assert g.GT_Open() == 0
    _check(
        [
            ("axis on", lambda: (g.GT_Axis(2), g.GT_AxisOn())),
            ("trap", lambda: (g.GT_PrflT(), g.GT_SetVel(4), g.GT_SetAcc(0.1), g.GT_SetPos(900))),
            ("update", g.GT_Update),
            ("cycles", lambda: gt.GTE_Wait(30)),
            ("stop", g.GT_SmthStp),
            ("axis off", g.GT_AxisOff),
        ],
        (1, 2),
    )


def test_opening_a_layer_on_the_open_card_is_seen_by_the_next_gt_read() -> None:
    """A card opened and driven through the GT layer, axis 3 into its negative limit; a
    layer opened on it then sets its axes up (flags cleared): the next GT_GetSts says so."""
    from gtecat.compat import mcx314

    open_card(a3={"negative_limit": -50_000})
    for a in (1, 2, 3, 4):
        assert gt.GT_AxisOn(a) == 0
    prm = gt.TTrapPrm(acc=1.0, dec=1.0)
    assert gt.GT_PrfTrap(3) == 0 and gt.GT_SetTrapPrm(3, byref(prm)) == 0
    assert gt.GT_SetVel(3, 100) == 0 and gt.GT_SetPos(3, -60_000) == 0
    assert gt.GT_Update(1 << 2) == 0
    gt.GTE_Wait(1000)
    on_limit = _reads(3)
    assert on_limit[1] & 0x40  # (the negative limit, table 6-2 bit 6)
    mcx314.Open()
    assert _reads(3) == _reads(3, table=True) != on_limit
