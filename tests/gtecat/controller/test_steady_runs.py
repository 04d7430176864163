"""The controller's runs of cycles at once keep the bus's steadiness between runs
(Controller._run_cycles): whatever else changes the bus makes them look again."""

from __future__ import annotations

from ctypes import byref, c_long, c_ubyte

import pytest

from gtecat import gt
from gtecat.drives.io_slaves import IoSlave
from tests.gtecat.gt.conftest import bring_up


@pytest.fixture
def fig5_2():
    """Manual figure 5-2 (2 drives, 2 IO slaves) in the default (auto) clock, axis 1 on."""
    bring_up()
    assert gt.GT_AxisOn(1) == 0
    gt.GTE_Wait(20)
    yield gt.GTE_Controller()
    gt.GT_Close()


def _io_slave(ctl) -> tuple[int, IoSlave]:
    for pos, s in enumerate(ctl.master.backend.slaves):
        if isinstance(s, IoSlave) and len(s.tx):
            return pos, s
    raise AssertionError("figure 5-2 has an IO slave with inputs")


def test_field_input_set_between_polls_reaches_the_image(fig5_2):
    """An input set on the terminal from outside the GT layer (no GT call between) is read
    by a poll that only the readers' C entries make: their calls' cycles look again."""
    ctl = fig5_2
    pos, slave = _io_slave(ctl)
    buf = (c_ubyte * 1)()
    s = c_long()
    for _ in range(200):  # runs of cycles at once, steady: the controller keeps that
        gt.GT_GetSts(1, byref(s))
    assert ctl.bank.many_cycles > 0
    at = len(slave.rx)  # (a slave's region: its output bytes, then its input bytes)
    assert gt.GT_EcatIOReadInput(pos, at, 1, buf) == 0
    before = buf[0]
    slave.set_input_bit(0, not before & 1)
    for _ in range(200):  # ten cycles of polls (50 us each)
        gt.GT_GetSts(1, byref(s))
    assert gt.GT_EcatIOReadInput(pos, at, 1, buf) == 0
    assert buf[0] & 1 == (not before & 1)


def test_unplug_between_polls_is_seen(fig5_2):
    """A cable pulled (GTE_UnplugSlave) while the bus ran steady: the next polls' cycles
    see the slave gone and the axis reports the comm loss (GT_GetSts bit 1)."""
    ctl = fig5_2
    s = c_long()
    for _ in range(200):
        gt.GT_GetSts(1, byref(s))
    assert not s.value & 0x2
    assert gt.GTE_UnplugSlave(0) == 0
    for _ in range(400):
        gt.GT_GetSts(1, byref(s))
    assert s.value & 0x2, hex(s.value)
    assert ctl.master.offline
