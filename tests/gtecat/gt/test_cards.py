"""Several cards in one process and the second core of a card, as applications drive them:
``GT_SetCardNo`` then ``GT_*`` (gtecat.controller.cards)."""

from __future__ import annotations

from ctypes import byref, c_double, c_long, c_short, c_ulong

from gtecat import gt
from tests.conftest import EXAMPLES

from .conftest import bring_up

ALARM = 1 << 1
RUNNING = 1 << 10
SERVO = 1 << 9


def _card(n: int) -> None:
    assert gt.GT_SetCardNo(n) == 0


def _jog(axis: int, vel: float) -> None:
    jog = gt.TJogPrm(acc=0.5, dec=0.5, smooth=0)
    assert gt.GT_AxisOn(axis) == 0, gt.GTE_GetLastError()
    assert gt.GT_PrfJog(axis) == 0 and gt.GT_SetJogPrm(axis, byref(jog)) == 0
    assert gt.GT_SetVel(axis, vel) == 0 and gt.GT_Update(1 << (axis - 1)) == 0


def _value(fn, axis: int, kind=c_double) -> float:
    v = kind()
    assert fn(axis, byref(v)) == 0, gt.GTE_GetLastError()
    return v.value


def test_two_cards_jog_their_own_axis_1_and_one_faults_alone():
    bring_up(clock="lockstep")  # card 0: the figure 5-2 bus
    _card(1)
    assert gt.GT_Open(1, 1) == 0  # card 1: an identical controller of its own
    assert gt.GT_Open() == -6 and "card 1 is already open" in gt.GTE_GetLastError()
    assert gt.GT_InitEcatComm() == 0
    ready = c_short()
    while gt.GT_IsEcatReady(byref(ready)) == 0 and ready.value != 1:
        gt.GTE_Wait(1)  # lockstep: one time for both cards
    assert gt.GT_StartEcatComm() == 0
    index = c_short()
    assert gt.GT_GetCardNo(byref(index)) == 0 and index.value == 1
    _jog(1, 20.0)
    _card(0)
    _jog(1, 5.0)
    gt.GTE_Wait(200)  # the time of card 0's calls is card 1's too
    assert _value(gt.GT_GetPrfVel, 1) == 5.0
    _card(1)
    assert _value(gt.GT_GetPrfVel, 1) == 20.0
    assert _value(gt.GT_GetPrfPos, 1) > 3000
    assert _value(gt.GT_GetPrfVel, 2) == 0.0  # axis 2 of card 1 stands

    _card(0)  # card 0's drive faults; card 1 does not notice
    gt.GTE_Slave(0).channel(0).inject_fault("alarm")
    gt.GTE_Wait(20)
    assert _value(gt.GT_GetSts, 1, c_long) & ALARM
    _card(1)
    sts = _value(gt.GT_GetSts, 1, c_long)
    assert not sts & ALARM and sts & RUNNING and sts & SERVO
    # its IO too: an output set on card 1 is card 1's
    assert gt.GT_SetEcatRawData(32, 1, (c_short * 1)(0x55)) == 0
    gt.GTE_Wait(2)
    raw = (c_short * 1)()
    assert gt.GT_GetEcatRawData(32, 1, raw) == 0 and raw[0] & 0xFF == 0x55
    _card(0)
    assert gt.GT_GetEcatRawData(32, 1, raw) == 0 and raw[0] & 0xFF == 0

    assert gt.GT_Close() == 0  # card 0 only
    assert gt.GT_GetSts(1, byref(c_long())) == -1
    assert "the controller is not open" in gt.GTE_GetLastError()
    _card(1)
    before = _value(gt.GT_GetPrfPos, 1)
    gt.GTE_Wait(10)
    assert _value(gt.GT_GetPrfPos, 1) > before  # card 1 keeps running
    clock = c_ulong()
    assert gt.GT_GetClock(byref(clock)) == 0 and clock.value > 200
    assert gt.GT_SetCardNo(16) == 7 and gt.GT_SetCardNo(-1) == 7
    _card(2)
    assert gt.GT_AxisOn(1) == -1 and "card 2 is not open" in gt.GTE_GetLastError()


def test_a_card_described_in_the_machine_file(tmp_path):
    """[card.1] of the machine description: a 2-axis pulse card beside the EtherCAT card 0;
    its own files (log, MRAM) beside card 0's."""
    machine = tmp_path / "station.toml"
    machine.write_text(
        '[axis.1]\npositive_limit = 1000\n\n[card.1]\nhardware = "gts:2"\n\n'
        "[card.1.axis.2]\nhome_switch = [[-50, 50]]\n",
        encoding="utf-8",
    )
    log = tmp_path / "Gecat.log"
    bring_up(clock="lockstep", machine=str(machine), log=str(log))
    _card(1)
    assert gt.GT_Open() == 0, gt.GTE_GetLastError()
    count = c_short()
    assert gt.GT_GetResCount(gt.MC_AXIS, byref(count)) == 0 and count.value == 2
    assert gt.GT_InitEcatComm() == 1 and "pulse card" in gt.GTE_GetLastError()
    assert gt.GT_AxisOn(2) == 0
    home = c_long()
    assert gt.GT_GetDi(gt.MC_HOME, byref(home)) == 0 and home.value & 0b10  # its own switch
    gt.GT_Close()
    assert (tmp_path / "Gecat.card1.log").is_file() and log.is_file()

    bad = tmp_path / "bad.toml"
    bad.write_text('[card.1]\nhardware = "gts:2"\ncolour = "red"\n', encoding="utf-8")
    _card(0)
    gt.GT_Close()
    assert gt.GT_Open(eni=str(EXAMPLES / "manual_fig5_2.eni"), machine=str(bad), log="") == 0
    _card(1)
    assert gt.GT_Open() == 7 and "unknown key(s) colour" in gt.GTE_GetLastError()


def test_core_2_is_the_cards_second_core(tmp_path):
    """A GTN application: reset both cores, one configuration file per core, clear and
    enable 12 axes of core 2, move one of them; core 1 does not move."""
    assert gt.GTN_Open(5, 1, eni=str(EXAMPLES / "manual_fig5_2.eni"), log="") == 0
    assert gt.GTN_Reset(1) == 0 and gt.GTN_Reset(2) == 0
    cfg = tmp_path / "gtn_core2.cfg"  # as the vendor's tool writes one file per core
    cfg.write_text("".join(f"[axis{k}]\nactive=1\n\n" for k in range(1, 13)))
    assert gt.GTN_LoadConfig(2, str(cfg)) == 0, gt.GTE_GetLastError()
    assert gt.GTN_ClrSts(2, 1, 12) == 0
    n = c_short()
    assert gt.GTN_GetResMax(2, gt.MC_AXIS, byref(n)) == 0 and n.value == 12
    for axis in range(1, 13):
        assert gt.GTN_AxisOn(2, axis) == 0, gt.GTE_GetLastError()
    trap = gt.TTrapPrm(acc=1, dec=1, velStart=0, smoothTime=0)
    assert gt.GTN_PrfTrap(2, 3) == 0 and gt.GTN_SetTrapPrm(2, 3, byref(trap)) == 0
    assert gt.GTN_SetPos(2, 3, 2000) == 0 and gt.GTN_SetVel(2, 3, 40) == 0
    assert gt.GTN_Update(2, 1 << 2) == 0
    sts = c_long()
    while gt.GTN_GetSts(2, 3, byref(sts)) == 0 and sts.value & RUNNING:
        pass  # an application's polling loop: every call lets time pass
    pos = c_double()
    assert gt.GTN_GetEncPos(2, 3, byref(pos)) == 0 and pos.value == 2000
    assert gt.GTN_GetPrfPos(2, 1, byref(pos)) == 0 and pos.value == 0
    assert gt.GTN_GetPrfPos(1, 1, byref(pos)) == 1  # core 1's bus is not up: its own state
    assert gt.GTN_Reset(3) == 7 and "core 3 does not exist" in gt.GTE_GetLastError()
    assert gt.GTN_EcatIOReadInput(2, 0, 0, 2, byref(c_short())) == 1  # no EtherCAT there
    # GT_SetCore: the GT_* functions address core 2 (the fast paths step aside)
    core = c_short()
    assert gt.GT_GetCore(byref(core)) == 0 and core.value == 1
    assert gt.GT_SetCore(2) == 0 and gt.GT_GetCore(byref(core)) == 0 and core.value == 2
    assert gt.GT_GetEncPos(3, byref(pos)) == 0 and pos.value == 2000
    assert gt.GT_GetSts(3, byref(sts)) == 0 and sts.value & SERVO
    assert gt.GTN_GetEncPos(1, 3, byref(pos)) == 1  # GTN_* name their core
    assert gt.GT_SetCore(3) == 7 and "core=3 out of range 1..2" in gt.GTE_GetLastError()
    assert gt.GT_SetCore(1) == 0
    assert gt.GT_GetEncPos(3, byref(pos)) == 1  # core 1 again: its bus is not up
    assert gt.GTN_Close() == 0
    assert gt.GTN_GetSts(2, 3, byref(sts)) == -1  # closed with its card


def test_a_described_core_2_and_the_multi_card_twin(tmp_path):
    """[core.2] gives core 2 its own pulse hardware; a second card has its own core 2."""
    machine = tmp_path / "gtn.toml"
    machine.write_text('[core.2]\nhardware = "gts:4"\n', encoding="utf-8")
    assert gt.GT_Open(card="gts:8", machine=str(machine), clock="lockstep", log="") == 0
    n = c_short()
    assert gt.GTN_GetResCount(2, gt.MC_AXIS, byref(n)) == 0 and n.value == 4
    assert gt.GTN_GetResCount(1, gt.MC_AXIS, byref(n)) == 0 and n.value == 8
    _card(1)
    assert gt.GT_Open() == 0
    # card 1's core 2: no [card.1.core.2] table, the card's own pulse personality (gts:8)
    assert gt.GTN_GetResCount(2, gt.MC_AXIS, byref(n)) == 0 and n.value == 8
    assert gt.GTN_AxisOn(2, 8) == 0
    _card(0)
    assert gt.GTN_AxisOn(2, 8) == 7  # card 0's core 2 has 4 axes


def test_on_a_bus_of_more_than_32_axes_core_2_is_the_bus_axes_33_and_up(tmp_path):
    """The card's own core 2, opened by an early GTN_Reset(2), gives way to the bus's axes
    33.. once the bus is up (gtecat.controller.core_view)."""
    from tools.gen_axes_eni import write_axes_eni

    eni = write_axes_eni(33, tmp_path / "axes33.eni")
    assert gt.GT_Open(eni=str(eni), log="", clock="lockstep") == 0
    assert gt.GTN_Reset(2) == 0  # before the bus: the card's second core
    n = c_short()
    assert gt.GTN_GetResCount(2, gt.MC_AXIS, byref(n)) == 0 and n.value == 12
    assert gt.GT_InitEcatComm() == 0
    ready = c_short()
    while gt.GT_IsEcatReady(byref(ready)) == 0 and ready.value != 1:
        gt.GTE_Wait(1)
    assert gt.GT_StartEcatComm() == 0
    assert gt.GTN_AxisOn(2, 1) == 0  # bus axis 33
    assert gt.GTN_AxisOn(2, 2) == 7 and "bus axes 33..33" in gt.GTE_GetLastError()
