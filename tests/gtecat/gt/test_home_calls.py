"""The GTS card personality and its GT calls: smart home, capture, card IO, EtherCAT refusals.

Facts: ``../shared/reference/gts-header-facts.md`` "Smart home" (THomePrm / THomeStatus
layouts, constants, prototypes) and seed 002.  Every expected position is computed here
from the machine description (switch windows, index pulses), never from the code: a card
latches home and index edges exactly (+-1 count), an EtherCAT drive's touch probe latches
the index exactly, the 60FDh home bit of an EtherCAT drive is sampled once per cycle (the
capture is the middle of that cycle's travel: within ``v * T / 2`` and the count).
"""

from __future__ import annotations

import ctypes
import dataclasses
import importlib.util
import sys
from ctypes import byref, c_double, c_long, c_short, c_uint32

import pytest

from gtecat import gt
from gtecat.controller.digital_io import digital_io
from gtecat.controller.smart_home import smart_home
from gtecat.drives.machine import AxisMachine, MachineDescription
from gtecat.native import header
from tests.conftest import EXAMPLES, SHARED_FIXTURES, needs_fixture

from .conftest import bring_up

MOVING, SERVO, NEG_FLAG = 1 << 10, 1 << 9, 1 << 6


# --- the structures and constants of the header -----------------------------------------------
def test_structures_have_the_header_layout():
    P, S = gt.THomePrm, gt.THomeStatus
    offsets = {
        "mode": 0,
        "moveDir": 2,
        "indexDir": 4,
        "edge": 6,
        "triggerIndex": 8,
        "pad1": 10,
        "velHigh": 16,
        "velLow": 24,
        "acc": 32,
        "dec": 40,
        "smoothTime": 48,
        "pad2": 50,
        "homeOffset": 56,
        "searchHomeDistance": 60,
        "searchIndexDistance": 64,
        "escapeStep": 68,
        "pad3": 72,
    }
    assert {f[0]: getattr(P, f[0]).offset for f in P._fields_} == offsets
    assert ctypes.sizeof(P) == 80
    assert [f[0] for f in S._fields_] == [
        "run",
        "stage",
        "error",
        "pad1",
        "capturePos",
        "targetPos",
    ]
    assert ctypes.sizeof(S) == 16 and S.capturePos.offset == 8


def test_constants_have_the_header_values():
    assert (gt.CAPTURE_HOME, gt.CAPTURE_INDEX, gt.CAPTURE_PROBE) == (1, 2, 3)
    modes = ("LIMIT", "LIMIT_HOME", "LIMIT_INDEX", "LIMIT_HOME_INDEX", "HOME", "HOME_INDEX")
    assert [getattr(gt, f"HOME_MODE_{m}") for m in modes] == [10, 11, 12, 13, 20, 22]
    assert (gt.HOME_MODE_INDEX, gt.HOME_MODE_FORCED_HOME, gt.HOME_MODE_FORCED_HOME_INDEX) == (
        30,
        40,
        41,
    )
    stages = (
        "IDLE START SEARCH_LIMIT SEARCH_LIMIT_STOP SEARCH_LIMIT_ESCAPE SEARCH_LIMIT_RETURN "
        "SEARCH_LIMIT_RETURN_STOP SEARCH_HOME SEARCH_HOME_RETURN SEARCH_INDEX SEARCH_GPI "
        "SEARCH_GPI_RETURN GO_HOME END"
    ).split()
    assert [getattr(gt, f"HOME_STAGE_{s}") for s in stages] == [
        0, 1, 10, 11, 13, 15, 16, 20, 25, 30, 40, 45, 80, 100,
    ]  # fmt: skip
    errors = (
        "NONE NOT_TRAP_MODE DISABLE ALARM STOP STAGE HOME_MODE SET_CAPTURE_HOME NO_HOME "
        "SET_CAPTURE_INDEX NO_INDEX"
    ).split()
    assert [getattr(gt, f"HOME_ERROR_{e}") for e in errors] == list(range(11))


def test_gts_h_declares_the_smart_home():
    text = header.render()
    assert "typedef struct THomePrm {" in text and "typedef struct THomeStatus {" in text
    assert "short GT_GoHome(short axis, THomePrm *pHomePrm);" in text
    assert "short GTN_GetHomeStatus(short core, short axis, THomeStatus *pHomeStatus);" in text
    assert (
        "short GT_GetCaptureStatus(short encoder, short *pStatus, long *pValue, short count=1, "
        "unsigned long *pClock=NULL);" in text
    )
    assert "#define HOME_MODE_LIMIT 10" in text and "#define CAPTURE_INDEX 2" in text
    assert "short GT_LoadConfig(const char *pFile);" in text  # C++ string literals, seed 002


# --- the card ---------------------------------------------------------------------------------
LO, HI, IDX0, CPR = 10000, 12000, 1234, 5000
PROBE = (15000, 15500)


def card_machine(start: float = 0.0) -> MachineDescription:
    axis = AxisMachine(
        position=start,
        counts_per_rev=CPR,
        index_offset=IDX0,
        negative_limit=-30000,
        positive_limit=30000,
        home_switch=((LO, HI),),
        probe1=(PROBE,),
    )
    return MachineDescription({1: axis, 2: AxisMachine(position=LO + 500)})


def open_card(axes: int = 2, start: float = 0.0, clock: str = "lockstep") -> None:
    assert gt.GT_Open(card=f"gts:{axes}", machine=card_machine(start), clock=clock, log="") == 0
    for a in range(1, axes + 1):
        assert gt.GT_AxisOn(a) == 0, gt.GTE_GetLastError()


def wait(pred, ms: int = 60_000) -> None:
    for _ in range(ms):
        if pred():
            return
        gt.GTE_Wait(1)
    raise AssertionError("timed out")


def moving(axis: int) -> bool:
    sts = c_long()
    assert gt.GT_GetSts(axis, byref(sts)) == 0
    return bool(sts.value & MOVING)


def trap_to(axis: int, pos: int, vel: float = 20.0) -> None:
    prm = gt.TTrapPrm(acc=1.0, dec=1.0)
    assert gt.GT_PrfTrap(axis) == 0 and gt.GT_SetTrapPrm(axis, byref(prm)) == 0
    assert gt.GT_SetPos(axis, pos) == 0 and gt.GT_SetVel(axis, vel) == 0
    assert gt.GT_Update(1 << (axis - 1)) == 0, gt.GTE_GetLastError()
    wait(lambda: not moving(axis))


def test_card_opens_with_its_axes_and_no_bus():
    open_card(axes=4)
    sts = c_long()
    assert gt.GT_GetSts(4, byref(sts)) == 0 and sts.value & SERVO
    assert gt.GT_GetSts(5, byref(sts)) == 7
    enc = c_double()
    assert gt.GT_GetEncPos(1, byref(enc)) == 0 and enc.value == 0.0


@pytest.mark.parametrize(
    ("name", "args"),
    [
        ("GT_InitEcatComm", ()),
        ("GT_IsEcatReady", (byref(c_short()),)),
        ("GT_GetEcatEncPos", (1, byref(c_long()))),
        ("GT_SetTouchProbeFunction", (1, 0)),
        ("GT_StartEcatHoming", (1,)),
        ("GT_SetPosScale", (1, 2)),
        ("GTE_UnplugSlave", (0,)),
    ],
)
def test_ethercat_functions_answer_1_naming_the_card(name, args):
    open_card()
    assert getattr(gt, name)(*args) == 1
    assert "GTS-200 pulse card" in gt.GTE_GetLastError()
    if name.startswith("GT_"):
        assert getattr(gt, "GTN_" + name[3:])(1, *args) == 1


def test_card_from_the_environment_and_bad_cards(monkeypatch):
    monkeypatch.setenv("GTECAT_CARD", "gts:8")
    assert gt.GT_Open(log="", clock="lockstep") == 0
    assert gt.GT_AxisOn(8) == 0
    gt.GT_Close()
    monkeypatch.delenv("GTECAT_CARD")
    for bad in ("gts:0", "gts:9", "pci:4", "gts"):
        assert gt.GT_Open(card=bad, log="") == 7, bad
        assert "card=" in gt.GTE_GetLastError()


# --- capture on the card: exact latches -------------------------------------------------------
def capture(encoder: int = 1) -> tuple[int, int]:
    status, value = c_short(), c_long()
    assert gt.GT_GetCaptureStatus(encoder, byref(status), byref(value)) == 0
    return status.value, value.value


@pytest.mark.parametrize(
    ("mode", "sense", "target", "want"),
    [
        (gt.CAPTURE_HOME, 0, 20000, LO),  # falling edge: the switch is reached
        (gt.CAPTURE_HOME, 1, 20000, HI),  # rising edge: the switch is left
        (gt.CAPTURE_INDEX, 0, 20000, IDX0),  # the first index pulse on the way
        (gt.CAPTURE_PROBE, 0, 20000, PROBE[0]),
        (gt.CAPTURE_PROBE, 1, 20000, PROBE[1]),
    ],
)
@pytest.mark.sample(2)
def test_card_capture_latches_the_encoder_at_the_edge(mode, sense, target, want):
    open_card()
    assert gt.GT_SetCaptureSense(1, mode, sense) == 0
    assert gt.GT_SetCaptureMode(1, mode) == 0
    assert capture() == (0, 0)
    trap_to(1, target)
    status, value = capture()
    assert status == 1 and abs(value - want) <= 1, value
    m = c_short()
    assert gt.GT_GetCaptureMode(1, byref(m)) == 0 and m.value == mode


def test_capture_stays_latched_until_cleared_and_clear_rearms_it():
    open_card()
    assert gt.GT_SetCaptureMode(1, gt.CAPTURE_INDEX) == 0
    trap_to(1, 4000)
    assert capture() == (1, IDX0)
    trap_to(1, 7000)  # passes 6234: no new capture while latched
    assert capture() == (1, IDX0)
    assert gt.GT_ClearCaptureStatus(1) == 0
    assert capture()[0] == 0
    trap_to(1, 12000)
    assert capture() == (1, IDX0 + 2 * CPR)


def test_capture_of_several_encoders_and_bad_arguments():
    open_card()
    status, value, clock = (c_short * 2)(), (c_long * 2)(), c_uint32()
    assert gt.GT_GetCaptureStatus(1, status, value, 2, byref(clock)) == 0
    assert list(status) == [0, 0]
    assert gt.GT_GetCaptureStatus(2, status, value, 2) == 7  # no encoder 3
    assert gt.GT_SetCaptureMode(1, 4) == 7
    assert gt.GT_SetCaptureSense(1, gt.CAPTURE_HOME, 2) == 7
    assert gt.GT_SetCaptureMode(3, gt.CAPTURE_HOME) == 7


# --- card IO ----------------------------------------------------------------------------------
def di(kind: int, raw: bool = False) -> int:
    v = c_long()
    assert (gt.GT_GetDiRaw if raw else gt.GT_GetDi)(kind, byref(v)) == 0
    return v.value


def do(kind: int) -> int:
    v = c_long()
    assert gt.GT_GetDo(kind, byref(v)) == 0
    return v.value


def test_get_di_reads_the_machine_inputs_of_each_axis():
    open_card(start=-30100)  # axis 1 on its negative limit; axis 2 has no switches
    assert di(gt.MC_LIMIT_NEGATIVE) == 0b01 and di(gt.MC_LIMIT_POSITIVE) == 0
    trap_to(1, LO + 100)
    assert di(gt.MC_HOME) == 0b01 and di(gt.MC_LIMIT_NEGATIVE) == 0
    gt.GTE_Slave(1).channel(0).inject_fault("alarm")
    gt.GTE_Wait(5)
    assert di(gt.MC_ALARM) == 0b10
    assert gt.GTE_SetGpi(5, 1) == 0 and gt.GTE_SetGpi(1, 1) == 0
    assert di(gt.MC_GPI) == 0b10001
    assert gt.GTE_SetGpi(17, 1) == 7
    assert gt.GT_GetDi(99, byref(c_long())) == 7


@pytest.mark.parametrize(
    ("wiring", "raw", "logical"),
    [
        (None, 0, 1),  # wired as the configuration expects: normally closed, read right
        ("normally_closed", 0, 1),
        ("normally_open", 1, 0),  # the file disagrees with the machine: read inverted
    ],
)
def test_get_di_applies_the_configuration_reverse_get_di_raw_does_not(
    tmp_path, wiring, raw, logical
):
    """On the home switch, ``[home1] reverse=1``: GT_GetDiRaw is the line, GT_GetDi the line
    through ``reverse``; the switch's wiring is the machine description's ``switch_wiring``,
    else what the file expects (config_file.switch_sense)."""
    machine = card_machine()
    if wiring is not None:
        a = dataclasses.replace(machine.axis(1), switch_wiring=wiring)
        machine = MachineDescription({**machine.axes, 1: a})
    assert gt.GT_Open(card="gts:2", machine=machine, clock="lockstep", log="") == 0
    for a in (1, 2):
        assert gt.GT_AxisOn(a) == 0
    trap_to(1, LO + 100)
    # no file yet (reverse 0): a normally-closed line is off on the switch, read as is
    before = (0, 0) if wiring == "normally_closed" else (1, 1)
    assert (di(gt.MC_HOME, raw=True) & 1, di(gt.MC_HOME) & 1) == before
    cfg = tmp_path / "home.cfg"
    cfg.write_text("[home1]\nactive=1\nreverse=1\nfilterTime=3\n")
    assert gt.GT_LoadConfig(str(cfg)) == 0, gt.GTE_GetLastError()
    assert di(gt.MC_HOME, raw=True) & 1 == raw
    assert di(gt.MC_HOME) & 1 == logical


def test_set_do_drives_enable_clear_and_general_outputs():
    open_card()
    assert gt.GT_SetDo(gt.MC_GPO, 0x8001) == 0 and do(gt.MC_GPO) == 0x8001
    assert gt.GT_SetDoBit(gt.MC_GPO, 2, 1) == 0 and do(gt.MC_GPO) == 0x8003
    assert gt.GT_SetDoBit(gt.MC_GPO, 17, 1) == 7
    assert do(gt.MC_ENABLE) == 0b11
    assert gt.GT_SetDo(gt.MC_ENABLE, 0b10) == 0 and do(gt.MC_ENABLE) == 0b10
    sts = c_long()
    assert gt.GT_GetSts(1, byref(sts)) == 0 and not sts.value & SERVO
    assert gt.GT_SetDoBit(gt.MC_ENABLE, 1, 1) == 0 and do(gt.MC_ENABLE) == 0b11
    ch = gt.GTE_Slave(0).channel(0)
    ch.inject_fault("alarm")
    gt.GTE_Wait(20)
    ch.clear_injected_fault()
    assert gt.GT_SetDoBit(gt.MC_CLEAR, 1, 1) == 0  # the amplifier's alarm-clear input
    assert ch.state.name == "SWITCH_ON_DISABLED"
    assert gt.GT_SetDo(gt.MC_DAC, 0) == 7


# --- smart home through the GT calls ----------------------------------------------------------
def home_prm(**kw) -> gt.THomePrm:
    prm = gt.THomePrm()
    assert gt.GT_GetHomePrm(1, byref(prm)) == 0
    for k, v in {"velHigh": 40.0, "velLow": 4.0, "acc": 2.0, "dec": 2.0, **kw}.items():
        setattr(prm, k, v)
    return prm


def go_home(prm: gt.THomePrm, axis: int = 1, core: int | None = None) -> gt.THomeStatus:
    if core is None:
        assert gt.GT_GoHome(axis, byref(prm)) == 0, gt.GTE_GetLastError()
    else:
        assert gt.GTN_GoHome(core, axis, byref(prm)) == 0, gt.GTE_GetLastError()
    st = gt.THomeStatus()
    wait(lambda: gt.GT_GetHomeStatus(axis, byref(st)) == 0 and not st.run)
    return st


def test_get_home_prm_defaults_after_reset_and_the_last_go_home_after():
    open_card()
    prm = gt.THomePrm()
    prm.pad1[0] = 7
    assert gt.GT_GetHomePrm(1, byref(prm)) == 0
    assert (prm.mode, prm.moveDir, prm.indexDir, prm.edge, prm.triggerIndex) == (20, 1, 1, 0, -1)
    assert (prm.velHigh, prm.velLow, prm.acc, prm.dec, prm.smoothTime) == (10, 1, 1, 1, 0)
    assert (prm.homeOffset, prm.searchHomeDistance, prm.escapeStep, prm.pad1[0]) == (0, 0, 1000, 0)
    st = go_home(home_prm(mode=gt.HOME_MODE_HOME, homeOffset=77))
    back = gt.THomePrm()
    assert gt.GT_GetHomePrm(1, byref(back)) == 0
    assert (back.mode, back.homeOffset, back.velHigh) == (20, 77, 40.0)
    assert (st.capturePos, st.targetPos) == (LO, LO + 77)
    assert gt.GT_Reset() == 0 and gt.GT_GetHomePrm(1, byref(back)) == 0 and back.homeOffset == 0


def test_go_home_return_codes():
    open_card()
    assert gt.GT_GoHome(1, None) == 7
    assert gt.GT_GoHome(1, byref(home_prm(moveDir=0))) == 7
    assert gt.GT_GoHome(3, byref(home_prm())) == 7
    assert gt.GT_GoHome(1, byref(home_prm(mode=99))) == 1
    st = gt.THomeStatus()
    assert gt.GT_GetHomeStatus(1, byref(st)) == 0
    assert (st.run, st.error) == (0, gt.HOME_ERROR_HOME_MODE)
    assert gt.GT_PrfPt(1) == 0  # Jog is taken over (below); PT, Gear, Follow are refused
    assert gt.GT_GoHome(1, byref(home_prm(mode=gt.HOME_MODE_HOME))) == 1
    assert gt.GT_GetHomeStatus(1, byref(st)) == 0 and st.error == gt.HOME_ERROR_NOT_TRAP_MODE


def _jog(vel: float, ms: int) -> None:
    """The vendor smart-home demo's jog button: PrfJog, GetJogPrm, SetJogPrm, SetVel, Update."""
    jog = gt.TJogPrm()
    assert gt.GT_PrfJog(1) == 0
    assert gt.GT_GetJogPrm(1, byref(jog)) == 0
    jog.acc, jog.dec, jog.smooth = 0.1, 0.1, 0
    assert gt.GT_SetJogPrm(1, byref(jog)) == 0
    assert gt.GT_SetVel(1, vel) == 0
    assert gt.GT_Update(1) == 0
    gt.GTE_Wait(ms)


@pytest.mark.parametrize("released", [True, False], ids=["after-GT_Stop", "still-jogging"])
def test_go_home_straight_after_a_jog_homes_as_the_card_does(released):
    """The vendor smart-home demo: jog (button down), GT_Stop(255, 255) (button up), then
    its home button: GT_ClrSts, GT_GetHomePrm, GT_GoHome - no GT_PrfTrap - and the card
    homes.  Straight after the GT_Stop the jog still ramps down; without it the jog runs:
    either way GT_GoHome stops it smoothly, switches to Trap and homes (smart_home
    ``_leave_jog``), with a master-log line."""
    open_card()
    ctl = gt.GTE_Controller()
    _jog(5.0, 200)  # 1000 counts up, at 5 pulse/ms
    if released:
        assert gt.GT_Stop(255, 255) == 0
    sts = c_long()
    assert gt.GT_GetSts(1, byref(sts)) == 0 and sts.value & MOVING  # still moving
    assert gt.GT_ClrSts(1) == 0
    st = go_home(home_prm(mode=gt.HOME_MODE_HOME, moveDir=1))
    assert (st.stage, st.error) == (gt.HOME_STAGE_END, gt.HOME_ERROR_NONE)
    assert st.capturePos == LO  # the home switch's edge, as from a standstill
    mode = c_long()
    assert gt.GT_GetPrfMode(1, byref(mode)) == 0 and mode.value == 0  # Trap
    assert any("was in Jog mode and moving" in line for line in ctl.log.lines)


def test_home_index_through_the_gtn_twin():
    open_card()
    st = go_home(home_prm(mode=gt.HOME_MODE_HOME_INDEX, indexDir=-1, homeOffset=-34), core=1)
    assert (st.stage, st.error) == (gt.HOME_STAGE_END, 0)
    assert st.capturePos == 6234  # the first index below the home edge 10000: 1234 + 5000
    assert st.targetPos == 6200
    status, value = capture()  # the capture shows the homing's last latch
    assert (status, value) == (1, 6234)


def test_forced_home_on_a_gpi_the_field_side_drives():
    open_card()
    ctl = gt.GTE_Controller()
    ch = gt.GTE_Slave(0).channel(0)
    # the field: GPI 3 is a sensor active from 15000 on (its level follows the mechanics)
    io = digital_io(ctl)
    ctl.post_cycle.insert(0, lambda t, dt: io.set_gpi(3, ch.machine_position >= 15000))
    st = go_home(home_prm(mode=gt.HOME_MODE_FORCED_HOME, triggerIndex=3))
    assert st.error == 0 and abs(st.capturePos - 15000) <= 4 / 2 + 1  # sampled at velLow


@pytest.mark.long
def test_seed_002_polling_loop_sees_and_clears_the_limit_flag():
    """Seed 002's moveHomeInner loop: GT_GetHomeStatus + GT_ClrSts until run drops."""
    open_card(start=5000, clock="auto")
    assert gt.GT_ZeroPos(1) == 0
    prm = home_prm(mode=gt.HOME_MODE_LIMIT, moveDir=-1, velHigh=50, velLow=20, acc=5, dec=5)
    prm.homeOffset, prm.escapeStep, prm.searchHomeDistance = 10000, 1000, 0
    assert gt.GT_ClearCaptureStatus(1) == 0 and gt.GT_PrfTrap(1) == 0
    assert gt.GT_GoHome(1, byref(prm)) == 0
    st, sts, seen = gt.THomeStatus(), c_long(), 0
    while True:
        assert gt.GT_GetHomeStatus(1, byref(st)) == 0
        assert gt.GT_GetSts(1, byref(sts)) == 0
        seen |= sts.value
        assert gt.GT_ClrSts(1) == 0
        if not st.run:
            break
    assert seen & NEG_FLAG
    assert (st.stage, st.error) == (gt.HOME_STAGE_END, 0)
    # zeroed at 5000: the limit at -30000 is -35000 on the encoder (sampled: 20/2 + 1)
    assert abs(st.capturePos - (-35000)) <= 11 and st.targetPos == st.capturePos + 10000
    machine = c_double()
    assert gt.GTE_GetMachinePos(1, byref(machine)) == 0
    assert abs(machine.value - (-20000)) <= 11


def test_the_example_runs_seed_002s_flow():
    spec = importlib.util.spec_from_file_location("smart_home_example", EXAMPLES / "smart_home.py")
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    sys.modules["smart_home_example"] = mod
    spec.loader.exec_module(mod)
    r = mod.run(axis=3, clock="lockstep")
    assert (r["stage"], r["error"]) == (gt.HOME_STAGE_END, gt.HOME_ERROR_NONE)
    assert abs(r["capturePos"] - (-50000)) <= 11  # smart_home_machine.toml: limit at -50000
    assert r["targetPos"] == r["capturePos"] + 10000
    assert (r["prf"], r["enc"]) == (0.0, 0.0)
    assert abs(r["machine"] - (-40000)) <= 11
    assert r["sts"] == SERVO  # servo on, no flag left


def test_the_vendor_test_cfg_wires_no_limit_to_axis_3_and_the_search_uses_its_terminal():
    """smarthome_test.cfg (the vendor's MCT) sets axis 3's limits to index -1 (none)."""
    cfg = SHARED_FIXTURES / "googol" / "smarthome_test.cfg"
    if not cfg.is_file():
        pytest.skip(needs_fixture("the Googol configuration files"))
    m = MachineDescription({3: AxisMachine(negative_limit=-20000)})
    assert gt.GT_Open(card="gts:4", machine=m, clock="lockstep", log="") == 0
    assert gt.GT_LoadConfig(str(cfg)) == 0 and gt.GT_AxisOn(3) == 0
    prm = gt.THomePrm()
    assert gt.GT_GetHomePrm(3, byref(prm)) == 0
    prm.mode, prm.moveDir, prm.velHigh, prm.velLow, prm.acc, prm.dec = 10, -1, 50, 20, 5, 5
    prm.homeOffset, prm.escapeStep = 10000, 1000
    st = go_home(prm, axis=3)
    assert (st.stage, st.error) == (gt.HOME_STAGE_END, 0)
    assert abs(st.capturePos - (-20000)) <= 11  # the terminal, seen without the limit check


# --- EtherCAT axes ----------------------------------------------------------------------------
ECAT_LO = 100000  # homing_probe_machine.toml's axis 1: home switch from 100000 on


def ecat_machine() -> MachineDescription:
    return MachineDescription(
        {
            1: AxisMachine(
                position=80000,
                counts_per_rev=10000,
                index_offset=3000,
                negative_limit=-100000,
                positive_limit=400000,
                home_switch=((ECAT_LO, 400000),),
                following_error_window=20000,
            )
        }
    )


@pytest.mark.parametrize("eni", ["homing_probe.eni", "manual_fig5_2.eni"])
@pytest.mark.long
def test_ethercat_home_index_mode_captures_the_index_exactly(eni):
    """homing_probe.eni maps the touch probe (PDO); figure 5-2's bus does not (SDO)."""
    bring_up(eni, machine=ecat_machine(), clock="lockstep")
    assert gt.GT_AxisOn(1) == 0
    st = go_home(home_prm(mode=gt.HOME_MODE_HOME_INDEX, indexDir=1, homeOffset=-300))
    assert (st.stage, st.error) == (gt.HOME_STAGE_END, 0)
    assert st.capturePos == 103000  # first index (3000 + 10000k) beyond the home edge
    assert st.targetPos == 102700
    machine = c_double()
    assert gt.GTE_GetMachinePos(1, byref(machine)) == 0 and abs(machine.value - 102700) <= 1


def test_ethercat_home_edge_is_sampled_within_half_a_cycle():
    bring_up("homing_probe.eni", machine=ecat_machine(), clock="lockstep")
    assert gt.GT_AxisOn(1) == 0
    st = go_home(home_prm(mode=gt.HOME_MODE_HOME))
    assert st.error == 0 and abs(st.capturePos - ECAT_LO) <= 40 / 2 + 1  # velHigh 40, 1 ms


@pytest.mark.long
def test_ethercat_limit_and_limit_home_index_modes():
    bring_up("homing_probe.eni", machine=ecat_machine(), clock="lockstep")
    assert gt.GT_AxisOn(1) == 0
    fast = dict(velHigh=200.0, acc=10.0, dec=10.0)
    st = go_home(home_prm(mode=gt.HOME_MODE_LIMIT, moveDir=-1, homeOffset=1000, **fast))
    assert st.error == 0 and abs(st.capturePos - (-100000)) <= 4 / 2 + 1
    assert st.targetPos == st.capturePos + 1000
    st = go_home(home_prm(mode=gt.HOME_MODE_LIMIT_HOME_INDEX, moveDir=-1, indexDir=1, **fast))
    assert (st.error, st.capturePos) == (0, 103000)


def test_ethercat_axis_without_60fd_cannot_capture_the_home(tmp_path):
    from gtecat.eni.topology import parse_topology
    from gtecat.eni.writer import write_eni_file

    topo = parse_topology(
        '[[slave]]\nkind = "servo"\nrx = ["0x6040:0:16", "0x607A:0:32"]\n'
        'tx = ["0x6041:0:16", "0x6064:0:32"]\n'
    )
    eni = tmp_path / "no60fd.eni"
    write_eni_file(topo, eni)
    bring_up(str(eni), clock="lockstep")
    assert gt.GT_AxisOn(1) == 0
    assert gt.GT_GoHome(1, byref(home_prm())) == 1
    st = gt.THomeStatus()
    assert gt.GT_GetHomeStatus(1, byref(st)) == 0 and st.error == gt.HOME_ERROR_SET_CAPTURE_HOME
    assert smart_home(gt.GTE_Controller(), 1).reason
