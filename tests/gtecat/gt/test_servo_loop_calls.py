"""The pulse / analog servo loop of a GTS card and the card calls around it, as applications call
them (vendor GTS header: ``TPid``, ``GT_SetPid``, ``GT_CtrlMode``, ``GT_SetDac``,
``GT_GetAdc``, ``GT_SetDoBitReverse``, ``GT_GetDiReverseCount``, ``GT_MultiAxisOn``; GTN
header: ``GT_LmtsOnEx``, ``GT_SetSoftLimitMode`` with ``SOFT_LIMIT_MODE_STOP`` 0,
``GT_GetResMax``, ``GT_GetDiEx``).  What the vendor leaves open is decided in
``gtecat/controller/servo_loop.py`` and ``gtecat/gt/servo_loop_calls.py``; each decision
has its check here.
"""

from __future__ import annotations

import ctypes
from ctypes import byref, c_double, c_long, c_short, c_ulong

import pytest

from gtecat import gt
from gtecat.native import header

from .conftest import EXAMPLES, bring_up


@pytest.fixture
def card():
    assert gt.GT_Open(card="gts:4", clock="lockstep", log="") == 0


def test_tpid_has_the_vendor_layout_and_is_in_gts_h():
    P = gt.TPid
    offsets = {f: getattr(P, f).offset for f, _ in P._fields_}
    assert offsets == {
        "kp": 0, "ki": 8, "kd": 16, "kvff": 24, "kaff": 32,
        "integralLimit": 40, "derivativeLimit": 44, "limit": 48,
    }  # fmt: skip
    assert ctypes.sizeof(P) == 56
    text = header.render()
    assert "typedef struct TPid {" in text
    assert "short GT_SetPid(short control, short index, TPid *pPid);" in text
    assert "short GTN_GetDac(short core, short dac, short *pValue, short count=1," in text


def test_pid_sets_are_kept_per_control_and_index(card):
    pid = gt.TPid()
    assert gt.GT_GetPid(1, 1, byref(pid)) == 0
    assert (pid.kp, pid.ki, pid.kvff, pid.limit) == (1.0, 0.0, 0.0, 32767)  # the defaults
    pid.kp, pid.kd, pid.integralLimit = 3.5, 0.25, 2000
    assert gt.GT_SetPid(2, 2, byref(pid)) == 0
    back = gt.TPid()
    assert gt.GT_GetPid(2, 2, byref(back)) == 0
    assert (back.kp, back.kd, back.integralLimit) == (3.5, 0.25, 2000)
    assert gt.GT_GetPid(2, 1, byref(back)) == 0 and back.kp == 1.0  # the other set untouched
    assert gt.GT_SetPid(2, 3, byref(pid)) == 7  # two sets
    assert gt.GT_SetPid(5, 1, byref(pid)) == 7  # a 4-axis card
    pid.limit = -1
    assert gt.GT_SetPid(1, 1, byref(pid)) == 7


def test_an_analog_axis_drives_its_dac_and_a_pulse_axis_frees_it(card):
    pid = gt.TPid(kp=2.0, kvff=0.0, limit=30000)
    assert gt.GT_SetPid(1, 1, byref(pid)) == 0
    assert gt.GT_CtrlMode(1, 0) == 0 and gt.GT_AxisOn(1) == 0
    dac = c_short()
    assert gt.GT_GetDac(1, byref(dac)) == 0 and dac.value == 0  # the axis follows its plan
    assert gt.GT_SetDac(1, byref(c_short(500))) == 1
    assert "control loop" in gt.GTE_GetLastError()
    assert gt.GT_SetDac(2, byref(c_short(-1200))) == 0  # axis 2 is a pulse axis
    assert gt.GT_GetDac(2, byref(dac)) == 0 and dac.value == -1200
    values = (c_short * 2)()
    assert gt.GT_GetDac(1, values, 2) == 0 and list(values) == [0, -1200]
    assert gt.GT_AxisOff(1) == 0 and gt.GT_SetDac(1, byref(c_short(700))) == 0
    assert gt.GT_GetDac(1, byref(dac)) == 0 and dac.value == 700
    assert gt.GT_Reset() == 0 and gt.GT_GetDac(2, byref(dac)) == 0 and dac.value == 0
    assert gt.GT_GetDac(5, byref(dac)) == 7
    assert gt.GT_StepPulse(3) == 0 and gt.GT_StepDir(3) == 0 and gt.GT_StepDir(9) == 7


def test_the_dac_carries_kp_times_the_following_error(card):
    """kp x (planned - actual): with the plan moved under an analog axis whose encoder
    does not follow (the position is set on the profile only), the command shows it."""
    assert gt.GT_SetPid(1, 1, byref(gt.TPid(kp=0.5, limit=100))) == 0
    assert gt.GT_CtrlMode(1, 0) == 0 and gt.GT_AxisOn(1) == 0
    err = c_double()
    assert gt.GT_SetPrfPos(1, 150) == 0 and gt.GT_GetAxisError(1, byref(err)) == 0
    dac = c_short()
    assert gt.GT_GetDac(1, byref(dac)) == 0
    assert dac.value == max(-100, min(100, round(0.5 * err.value)))


def test_analog_inputs_from_the_field(card):
    assert gt.GTE_SetAdc(2, -2.5) == 0
    volts, raw = (c_double * 2)(), (c_short * 2)()
    assert gt.GT_GetAdc(1, volts, 2) == 0 and list(volts) == [0.0, -2.5]
    assert gt.GT_GetAdcValue(1, raw, 2) == 0 and list(raw) == [0, round(-0.25 * 32767)]
    assert gt.GT_GetAdc(9, byref(c_double())) == 7 and gt.GTE_SetAdc(1, 11.0) == 7


def test_timed_output_pulse_and_input_edge_counts(card):
    assert gt.GT_SetDoBitReverse(gt.MC_GPO, 3, 1, 20) == 0
    do = c_long()
    assert gt.GT_GetDo(gt.MC_GPO, byref(do)) == 0 and do.value == 0b100
    assert gt.GTE_Wait(19) == 0 and gt.GT_GetDo(gt.MC_GPO, byref(do)) == 0 and do.value == 0b100
    assert gt.GTE_Wait(2) == 0 and gt.GT_GetDo(gt.MC_GPO, byref(do)) == 0 and do.value == 0
    assert gt.GT_SetDoBitReverse(gt.MC_ENABLE, 1, 1, 5) == 7
    counts = (c_ulong * 2)()
    assert gt.GT_GetDiReverseCount(gt.MC_GPI, 4, counts, 2) == 0 and list(counts) == [0, 0]
    for level in (1, 0, 1):
        assert gt.GTE_SetGpi(5, level) == 0 and gt.GTE_Wait(2) == 0
    assert gt.GT_GetDiReverseCount(gt.MC_GPI, 4, counts, 2) == 0 and list(counts) == [0, 3]
    assert gt.GT_SetDiReverseCount(gt.MC_GPI, 5, byref(c_ulong(100))) == 0
    assert gt.GTE_SetGpi(5, 0) == 0 and gt.GTE_Wait(2) == 0
    assert gt.GT_GetDiReverseCount(gt.MC_GPI, 5, counts, 1) == 0 and counts[0] == 101
    words = (c_long * 2)()
    assert gt.GT_GetDiEx(gt.MC_GPI, words, 2) == 0 and list(words) == [0, 0]
    assert gt.GTE_SetGpi(16, 1) == 0 and gt.GT_GetDiEx(gt.MC_GPI, words, 2) == 0
    assert list(words) == [1 << 15, 0]


def test_multi_axis_on_off_and_limit_modes(card):
    sts = c_long()
    assert gt.GT_MultiAxisOn(0b0101) == 0
    on = [gt.GT_GetSts(a, byref(sts)) == 0 and bool(sts.value & 1 << 9) for a in (1, 2, 3)]
    assert on == [True, False, True]
    assert gt.GT_MultiAxisOff(1 << 4) == 7 and "no axis [5]" in gt.GTE_GetLastError()
    assert gt.GT_MultiAxisOff(0b0001) == 0 and gt.GT_GetSts(1, byref(sts)) == 0
    assert not sts.value & 1 << 9
    pos, neg = c_long(), c_long()
    assert gt.GT_SetSoftLimit(3, 5000, -5000) == 0
    assert gt.GT_LmtsOffEx(3, -1, gt.LIMIT_MODE_SOFT) == 0
    assert gt.GT_GetSoftLimit(3, byref(pos), byref(neg)) == 0
    assert (pos.value, neg.value) == (0x7FFFFFFF, -0x80000000)
    assert gt.GT_LmtsOnEx(3) == 0 and gt.GT_GetSoftLimit(3, byref(pos), byref(neg)) == 0
    assert (pos.value, neg.value) == (5000, -5000)
    assert gt.GT_LmtsOffEx(3, -1, 2) == 7
    mode = c_short()
    assert gt.GT_SetSoftLimitMode(3, gt.SOFT_LIMIT_MODE_STOP) == 0
    assert gt.GT_GetSoftLimitMode(3, byref(mode)) == 0 and mode.value == 0
    assert gt.GT_SetSoftLimitMode(3, gt.SOFT_LIMIT_MODE_LIMIT) == 1
    assert "not emulated" in gt.GTE_GetLastError()


def test_resources_and_the_card_number(card):
    n = c_short()
    assert gt.GT_GetResMax(gt.MC_AXIS, byref(n)) == 0 and n.value == 4
    assert gt.GT_GetResCount(gt.MC_DAC, byref(n)) == 0 and n.value == 4
    assert gt.GT_GetResMax(gt.MC_GPI, byref(n)) == 0 and n.value == 16
    assert gt.GT_GetResCount(gt.MC_EXT_MODULE, byref(n)) == 0 and n.value == 0
    assert gt.GT_GetResMax(99, byref(n)) == 7
    gt.GT_Close()
    assert gt.GT_SetCardNo(0) == 0  # before GT_Open, as applications call it
    assert gt.GT_SetCardNo(16) == 7
    assert gt.GT_GetCardNo(byref(n)) == 0 and n.value == 0
    assert gt.GT_SetCardNo(1) == 0  # a second card (tests/gtecat/gt/test_cards.py)
    assert gt.GT_GetCardNo(byref(n)) == 0 and n.value == 1


def test_the_gtn_torque_spellings_read_6077h():
    bring_up("full_servo.eni", clock="lockstep")  # a drive that maps 6077h
    a, b, c = c_short(), c_short(), c_short()
    assert gt.GTN_GetEcatAxisAtITorque(1, 1, byref(a)) == 0
    assert gt.GTN_GetAtlTorque(1, 1, byref(b)) == 0
    assert gt.GTN_GetEcatAxisAtlTorque(1, 1, byref(c)) == 0
    assert a.value == b.value == c.value
    n = c_short()
    assert gt.GTN_GetResMax(1, gt.MC_AXIS, byref(n)) == 0 and n.value == 32
    assert gt.GTN_GetResCount(1, gt.MC_AXIS, byref(n)) == 0 and n.value == 12  # the controller's


def test_the_axis_count_is_the_controllers_before_the_bus_is_up():
    """The vendor's EtherCAT demo counts axes (and from them cores) before GTN_InitEcatComm:
    the controller's 12 axes, whatever the bus holds, as the count forms accept them."""
    from gtecat.drives.machine import MachineDescription

    assert gt.GT_Open(eni=str(EXAMPLES / "manual_fig5_2.eni"), clock="lockstep", log="") == 0
    n = c_short()
    assert gt.GTN_GetResCount(1, gt.MC_AXIS, byref(n)) == 0 and n.value == 12
    gt.GT_Close()
    bring_up(clock="lockstep")  # the figure 5-2 bus: 2 axes
    assert gt.GTN_GetResCount(1, gt.MC_AXIS, byref(n)) == 0 and n.value == 12
    sts = (c_long * 12)()
    assert gt.GT_GetSts(1, sts, 12) == 0 and gt.GT_GetSts(1, sts, 13) == 7
    gt.GT_Close()
    assert gt.GT_Open(card="gts:4", machine=MachineDescription({}), clock="lockstep", log="") == 0
    assert gt.GT_GetResCount(gt.MC_AXIS, byref(n)) == 0 and n.value == 4  # a GTS-400 card


def _observe() -> list[int]:
    """What an application sees of the inputs: GT_GetDi of the limits and home, and the
    limit flags of GT_GetSts after GT_ClrSts."""
    seen = []
    for t in (gt.MC_LIMIT_POSITIVE, gt.MC_LIMIT_NEGATIVE, gt.MC_HOME):
        v = c_long()
        assert gt.GT_GetDi(t, byref(v)) == 0
        seen.append(v.value)
    assert gt.GT_ClrSts(1, 2) == 0
    gt.GTE_Wait(2)
    for a in (1, 2):
        s = c_long()
        assert gt.GT_GetSts(a, byref(s)) == 0
        seen.append(s.value & 0x60)
    return seen


def test_limit_and_input_senses_act_as_the_configuration_files_reverse(tmp_path):
    """GT_LmtSns (GTS manual example 4-2: bits 0/1 axis 1's positive/negative limit) and
    GT_SetSense set the ``reverse`` a configuration file sets: the same observations on a
    machine whose switches are stated normally open.  Where the machine description does
    not state the wiring, the switches are wired as the application expects (a ``reverse=1``
    of its file, or a sense it sets, is a normally-closed switch): neither changes what is
    seen, as on the machine the application was written for."""
    from gtecat.drives.machine import AxisMachine, MachineDescription

    def machine(wiring: str | None) -> MachineDescription:
        return MachineDescription(
            {
                1: AxisMachine(positive_limit=-100.0, switch_wiring=wiring),
                2: AxisMachine(home_switch=((-50.0, 50.0),), switch_wiring=wiring),
            }
        )

    stated, unstated = machine("normally_open"), machine(None)
    assert gt.GT_Open(card="gts:2", machine=stated, clock="lockstep", log="") == 0
    plain = _observe()
    assert gt.GT_LmtSns(0b0000_1001) == 0  # axis 1 positive, axis 2 negative
    assert gt.GT_SetSense(gt.MC_HOME, 2, 1) == 0
    at_run_time = _observe()
    sense = c_short()
    assert gt.GT_GetSense(gt.MC_LIMIT_NEGATIVE, 2, byref(sense)) == 0 and sense.value == 1
    assert gt.GT_GetSense(gt.MC_LIMIT_NEGATIVE, 1, byref(sense)) == 0 and sense.value == 0
    assert gt.GT_SetSense(9, 1, 1) == 7 and gt.GT_SetSense(gt.MC_HOME, 3, 1) == 7
    gt.GT_Close()
    cfg = tmp_path / "senses.cfg"
    cfg.write_text(
        "[limitPositive1]\nreverse=1\n[limitNegative1]\nreverse=0\n"
        "[limitPositive2]\nreverse=0\n[limitNegative2]\nreverse=1\n[home2]\nreverse=1\n",
        encoding="utf-8",
    )
    assert gt.GT_Open(card="gts:2", machine=stated, clock="lockstep", log="") == 0
    assert gt.GT_LoadConfig(str(cfg)) == 0, gt.GTE_GetLastError()
    assert _observe() == at_run_time != plain
    gt.GT_Close()
    assert gt.GT_Open(card="gts:2", machine=unstated, clock="lockstep", log="") == 0
    assert _observe() == plain
    assert gt.GT_LoadConfig(str(cfg)) == 0, gt.GTE_GetLastError()
    assert _observe() == plain  # wired as the file expects
    assert gt.GT_LmtSns(0b0000_1000) == 0  # a sense set at run time: the same rule
    assert _observe() == plain
    sense = c_short()
    assert gt.GT_GetSense(gt.MC_LIMIT_POSITIVE, 1, byref(sense)) == 0 and sense.value == 0
