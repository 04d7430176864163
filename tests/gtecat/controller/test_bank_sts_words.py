"""The bank's list of GT_GetSts words (a few rows): made again only when a flag it is made from
changed; the words read through GT_GetSts are the table path's in every case."""

from __future__ import annotations

from ctypes import byref, c_long

from gtecat import gt
from gtecat.gt._core import SESSION
from tests.gtecat.controller.test_bank import AXES, ENI, open_bus


def _words() -> list[int]:
    sts = (c_long * AXES)()
    assert gt.GT_GetSts(1, sts, AXES) == 0
    one = c_long()
    for a in range(1, AXES + 1):  # the table path's word of each axis
        assert gt.GT_GetSts.slow(a, byref(one)) == 0
        assert one.value == sts[a - 1], a
    return list(sts)


def test_the_words_are_made_again_only_when_a_flag_changed(tmp_path) -> None:
    machine = tmp_path / "m.toml"
    machine.write_text("")
    try:
        open_bus(str(ENI), str(machine), "on")
        for a in range(1, AXES + 1):
            assert gt.GT_AxisOn(a) == 0
        gt.GTE_Wait(20)
        bank = SESSION.controllers[1].bank
        assert bank is not None and 0 < bank.n <= 32
        first = _words()
        made = bank._sts_last[1]
        gt.GTE_Wait(5)
        assert _words() == first
        assert bank._sts_last[1] is made  # nothing changed: the same list
        # a move starts (bit 10), then one axis goes servo off (bit 9 gone)
        assert gt.GT_PrfTrap(3) == 0 and gt.GT_SetVel(3, 5.0) == 0 and gt.GT_SetPos(3, 5000) == 0
        assert gt.GT_Update(1 << 2) == 0
        gt.GTE_Wait(3)
        moving = _words()
        assert moving[2] & 0x400 and not first[2] & 0x400
        assert bank._sts_last[1] is not made
        assert gt.GT_AxisOff(5) == 0
        gt.GTE_Wait(2)
        off = _words()
        assert not off[4] & 0x200 and first[4] & 0x200
    finally:
        gt.GT_Close()
