"""The controller's runs of cycles at once keep the bus's steadiness between runs
(Controller._run_cycles): whatever else changes the bus makes them look again."""

from __future__ import annotations

import struct
from ctypes import byref, c_double, c_long, c_ubyte

import pytest

from gtecat import gt
from gtecat.controller.epoch import EPOCH
from gtecat.drives.io_slaves import IoSlave
from gtecat.drives.slave import VirtualSlave
from gtecat.eni.model import Identity
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


# --- the quick cycle the readers' C entries run (Controller.arm_quick) -----------------------


@pytest.mark.parametrize("hooks", ["before_cycle", "pre_cycle", "post_cycle", "sample", "watch"])
@pytest.mark.parametrize("how", ["append", "assign"])
def test_a_controller_hook_added_between_polls_runs_every_cycle(fig5_2, hooks, how):
    """A cycle hook of the controller added in place or by assigning a new list, between
    polls that only the readers' C entries make: it runs in every cycle from the next on."""
    ctl = fig5_2
    _polls(200)
    seen: list[int] = []

    def hook(*_args: object) -> None:
        seen.append(1)

    if how == "append":
        getattr(ctl, hooks).append(hook)
    else:
        setattr(ctl, hooks, [*getattr(ctl, hooks), hook])
    t0 = ctl.clock.cycles
    _polls(400)
    assert len(seen) == ctl.clock.cycles - t0 > 0


def test_a_master_hook_list_assigned_between_polls_runs_every_cycle(fig5_2):
    ctl = fig5_2
    _polls(200)
    seen: list[int] = []
    ctl.master.on_cycle = [lambda m: seen.append(1)]
    t0 = ctl.clock.cycles
    _polls(400)
    assert len(seen) == ctl.clock.cycles - t0 > 0


def test_a_cycle_wrapped_between_polls_runs_through_the_wrapper(fig5_2):
    """An inspection endpoint wraps the clock's cycle: the quick cycles stop at once."""
    ctl = fig5_2
    _polls(200)
    own = ctl.clock._run_cycle
    seen: list[int] = []

    def wrapped() -> None:
        seen.append(1)
        own()

    ctl.clock._run_cycle = wrapped
    t0 = ctl.clock.cycles
    _polls(400)
    ctl.clock._run_cycle = own
    assert len(seen) == ctl.clock.cycles - t0 > 0


def _moves_and_polls(ctl, watch: bool, band: bool = False, waits: bool = False) -> list:
    """Trap moves of both axes polled through the C entries; what the readers saw
    (``band``: axis 1 with an in-position band, its status word's bit 11 set in the
    cycles, manual 11.7; ``waits``: a wait of 1 ms every 37 polls, after which the next
    due cycle is armed for the entries too)."""
    if watch:  # a hook that does nothing: every cycle then goes the general way
        ctl.watch.append(lambda: None)
    gt.GT_AxisOn(2)
    if band:
        assert gt.GT_SetAxisBand(1, 20, 40) == 0
    s, d = c_long(), c_double()
    seen = []
    for rnd in range(4):
        ax = 1 + rnd % 2
        assert gt.GT_PrfTrap(ax) == 0
        p = gt.TTrapPrm()
        p.acc, p.dec = 0.5, 0.5
        assert gt.GT_SetTrapPrm(ax, byref(p)) == 0
        assert gt.GT_SetVel(ax, 20.0) == 0
        assert gt.GT_SetPos(ax, 3000 * (rnd + 1)) == 0
        assert gt.GT_Update(1 << (ax - 1)) == 0
        for i in range(6000):
            gt.GT_GetSts(ax, byref(s))
            if i % 499 == 0:
                gt.GT_GetPrfPos(ax, byref(d))
                gt.GT_GetEncPos(3 - ax, byref(c_double()))
                seen.append((s.value, d.value))
            if waits and i % 37 == 0:
                gt.GTE_Wait(1)
            if i % 97 == 0:  # (spans: read from the bank's lists of the cycle)
                span, words = (c_double * 2)(), (c_long * 2)()
                assert gt.GT_GetPrfPos(1, span, 2) == 0
                assert gt.GT_GetSts(1, words, 2) == 0
                seen.append((*span, *words))
    seen.append((ctl.clock.cycles, ctl.clock.now_ns, ctl.master.cycles))
    bank = ctl.bank
    seen.append((bank.rows_run, bank.bank_cycles, bank.frozen_rows_run, bank.csp.cycles))
    seen.append(bytes(ctl.master.image.buffer))
    return seen


@pytest.mark.parametrize(("band", "waits"), [(False, False), (True, False), (True, True)])
def test_quick_cycles_give_what_the_general_way_gives(band, waits):
    """The same calls with the quick cycles and with every cycle the general way (a watch
    hook that does nothing): the same values read, the same clock, the same cycles, the
    bank's and its drives' counts, the same process image.  The quick ones counted by the
    entries themselves where nothing but counting was to do (Controller._book_in_c): the
    readers' epoch one more a cycle, as the general way has it."""
    runs = []
    for watch in (False, True):
        bring_up()
        assert gt.GT_AxisOn(1) == 0
        ctl = gt.GTE_Controller()
        many = ctl.bank.many_cycles
        runs.append(_moves_and_polls(ctl, watch, band, waits))
        if not watch:
            assert ctl.bank.many_cycles - many > 1000  # (the quick ones ran)
            assert ctl.quick_cbook[0] == 1  # (booked in C)
            s, cycles, epoch = c_long(), ctl.clock.cycles, EPOCH.n
            for _ in range(2000):  # (a poll of an idle axis: every cycle a quick one)
                gt.GT_GetSts(1, byref(s))
            assert ctl.clock.cycles - cycles == EPOCH.n - epoch == 100
            assert ctl.quick_cbook[0] == 1
        gt.GT_Close()
    assert runs[0] == runs[1]


def test_an_output_written_between_polls_reaches_the_io_slave(fig5_2):
    """A raw write to an IO slave's outputs between polls: the next cycle takes it to the
    slave (its fixed point, kept between runs, is not the image's)."""
    ctl = fig5_2
    pos, slave = _io_slave(ctl)
    _polls(200)
    start = sum(len(s.rx) + len(s.tx) for s in ctl.master.backend.slaves[:pos])
    for value in (0x5A, 0xA5, 0x00):
        assert gt.GT_SetEcatRawData(start, 1, (c_ubyte * 1)(value)) == 0
        _polls(60)
        assert slave.rx[0] == value
        assert slave.field_outputs[0] == value


def _write_through_buffer(how: str, fi: bytearray, value: int) -> None:
    if how == "memoryview":
        memoryview(fi)[0] = value
    elif how == "pack_into":
        struct.pack_into("B", fi, 0, value)
    else:
        c_ubyte.from_buffer(fi).value = value  # (the export ends with the ctypes object)


@pytest.mark.parametrize("clock", ["auto", "lockstep"])
@pytest.mark.parametrize("how", ["memoryview", "pack_into", "ctypes"])
def test_field_input_written_through_the_buffer_protocol_reaches_the_image(clock, how):
    """A terminal's input byte written through the buffer protocol, which the field inputs
    cannot count as they count an item's write: on a steady bus, in runs of cycles at once
    (lockstep: GTE_Wait) or in the readers' C entries' quick cycles (auto: polls only), the
    next cycles still carry it to the image - once, then again with another value."""
    bring_up(clock=clock)
    try:
        assert gt.GT_AxisOn(1) == 0
        ctl = gt.GTE_Controller()
        pos, slave = _io_slave(ctl)
        buf = (c_ubyte * 1)()
        s = c_long()

        def settle() -> None:
            if clock == "lockstep":
                gt.GTE_Wait(20)
            else:
                for _ in range(400):  # twenty cycles of polls (50 us each)
                    gt.GT_GetSts(1, byref(s))

        settle()
        settle()
        assert ctl.bank.many_cycles > 0  # (steady: runs of cycles at once)
        for value in (0x5A, 0xA5):
            _write_through_buffer(how, slave.field_inputs, value)
            settle()
            assert gt.GT_EcatIOReadInput(pos, len(slave.rx), 1, buf) == 0
            assert buf[0] == value, (how, clock, hex(buf[0]))
            assert slave.tx[0] == value
    finally:
        gt.GT_Close()


def test_field_inputs_counted_when_their_length_changes():
    """What moves the field inputs' bytes (a new length) counts as a write: the compiled
    check's copy of them is only compared while nothing was counted."""
    s = IoSlave(0, "io", Identity(vendor_id=0, product_code=0), tx_pdos=())
    s.field_inputs = bytearray(2)
    fi = s.field_inputs
    for change in (
        lambda: fi.append(1),
        lambda: fi.extend(b"\x01"),
        lambda: fi.insert(0, 1),
        lambda: fi.pop(),
        lambda: fi.remove(1),
        lambda: fi.clear(),
        lambda: fi.__iadd__(b"\x00\x01"),
        lambda: fi.__imul__(2),
        lambda: fi.__delitem__(0),
        lambda: fi.reverse(),
    ):
        before = VirtualSlave.outside_changes
        change()
        assert VirtualSlave.outside_changes > before
    assert type(s.field_inputs) is type(fi)


def _move_polled(ctl, with_do: bool) -> list:
    """Axis 1's Trap move polled on the auto clock, ``with_do``: a GT_GetDo among the polls
    (its reader reaches the drive's outputs, which gives the bank's axes back)."""
    s, d = c_long(), c_double()
    for _ in range(400):
        gt.GT_GetSts(1, byref(s))
    assert ctl.bank.n_alive == ctl.bank.n  # (banked: the quick cycles run)
    assert gt.GT_PrfTrap(1) == 0
    p = gt.TTrapPrm()
    p.acc = p.dec = 0.1
    assert gt.GT_SetTrapPrm(1, byref(p)) == 0
    assert gt.GT_SetVel(1, 5.0) == 0
    assert gt.GT_SetPos(1, 100_000) == 0
    assert gt.GT_Update(1) == 0
    seen = []
    for i in range(6000):
        if i == 400:  # (a call of the same latency without it)
            fn = gt.GT_GetDo if with_do else gt.GT_GetDi
            assert fn(12 if with_do else 4, byref(c_long())) == 0  # (MC_GPO, MC_GPI)
        gt.GT_GetSts(1, byref(s))
        if i % 250 == 0:
            assert gt.GT_GetPrfPos(1, byref(d)) == 0
            seen.append((ctl.clock.cycles, s.value, d.value))
    return seen


def test_a_release_inside_a_reader_call_stops_the_quick_cycles(fig5_2):
    """A reader's call that gives the bank's axes back (GT_GetDo) while an axis moves: the
    quick cycles the C entries ran for the bank stop (the axis moved by its objects then,
    the bank claims it again), so the move goes on as without that call - it stood still
    while time passed before."""
    ctl = fig5_2
    with_do = _move_polled(ctl, True)
    assert ctl.bank.n_alive == ctl.bank.n  # (claimed again)
    gt.GT_Close()
    bring_up()
    assert gt.GT_AxisOn(1) == 0
    gt.GTE_Wait(20)
    assert _move_polled(gt.GTE_Controller(), False) == with_do
    assert with_do[-1][2] > with_do[len(with_do) // 2][2] > 100  # (it moved all along)


def test_emergencies_arrive_whichever_slaves_the_bank_holds(fig5_2):
    """The master's look at the queues (EmulatedBackend.emergencies) skips them while nothing
    was queued since a look that left them empty: one queued on a slave the bank takes
    afterwards, or behind a pulled cable until it is back, still arrives, once."""
    be = fig5_2.master.backend
    _polls(200)
    kept = be.claimed
    try:
        be.claimed = set()
        assert be.emergencies() == []
        be.slaves[0].emit_emergency(0x2310, 0x01)
        be.claimed = {0}  # taken by the bank after it queued one
        assert [(p, e.code) for p, e in be.emergencies()] == [(0, 0x2310)]
        assert be.emergencies() == []
        be.claimed = set()
        assert be.emergencies() == []
        be.unplug(0)
        be.slaves[0].emit_emergency(0x7500, 0x01)
        assert be.emergencies() == [] and be.emergencies() == []
        be.replug(0)
        assert [(p, e.code) for p, e in be.emergencies()] == [(0, 0x7500)]
        assert be.emergencies() == []
    finally:
        be.claimed = kept
