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


def _polls(n: int) -> int:
    """``n`` reader polls (50 us of the auto clock each); the controller's clock after."""
    s = c_long()
    for _ in range(n):
        gt.GT_GetSts(1, byref(s))
    return gt.GTE_Controller().clock.now_ns


def test_field_input_written_in_place_reaches_the_image(fig5_2):
    """A test writing a terminal's input byte in place (``slave.field_inputs[0] = x``)."""
    pos, slave = _io_slave(fig5_2)
    _polls(200)
    slave.field_inputs[0] = 0x3C
    _polls(200)
    buf = (c_ubyte * 1)()
    assert gt.GT_EcatIOReadInput(pos, len(slave.rx), 1, buf) == 0
    assert buf[0] == 0x3C


@pytest.mark.parametrize("which", ["io", "drive"])
def test_an_emergency_queued_between_polls_is_fetched(fig5_2, which):
    """``emit_emergency`` on an IO slave or on a drive the axis bank runs: the master fetches
    and logs it at the next cycle (ETG.1000.6 5.6.4), as it does with the bank off."""
    ctl = fig5_2
    _polls(200)
    slave = _io_slave(ctl)[1] if which == "io" else ctl.master.backend.slaves[0]
    before = ctl.master.emergency_count
    slave.emit_emergency(0x2310, 0x01)
    _polls(200)
    assert ctl.master.emergency_count == before + 1
    assert not slave.emergencies
    assert any("CoE EMERGENCY 0x2310" in line for line in ctl.log.lines)


def test_a_master_hook_added_between_polls_runs_every_cycle(fig5_2):
    ctl = fig5_2
    _polls(200)
    seen: list[int] = []
    ctl.master.on_cycle.append(lambda m: seen.append(1))
    t0 = ctl.clock.cycles
    _polls(400)
    assert len(seen) == ctl.clock.cycles - t0 > 0


def test_a_cable_pulled_by_hand_in_front_of_a_banked_drive(fig5_2):
    """``backend.unplug`` (a scenario's own comm loss) in front of a drive the bank runs: the
    working counter falls, the axis alarms (GT_GetSts bit 1) as with the bank off."""
    ctl = fig5_2
    _polls(200)
    assert ctl.bank.n_alive
    ctl.master.backend.unplug(0)
    s = c_long()
    for _ in range(2000):
        gt.GT_GetSts(1, byref(s))
        if s.value & 0x2:
            break
    assert s.value & 0x2, hex(s.value)
