"""GT_LoadConfig with the vendor's ``*.cfg`` on a bus (lockstep clock): what each setting
does, read back through the GT calls (manual 4.3-4.6, 9.2-9.4, chapter 13 entry 83).

The real files come from ``../shared/fixtures/googol`` (copied to ``tmp_path`` only when a
test edits one); ``../controller/data/gts400_4axis.cfg`` is a GTS-400 file written here.
"""

from __future__ import annotations

import random
import re
import tempfile
from ctypes import byref, c_double, c_long
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gtecat import gt
from tests.conftest import SHARED_FIXTURES, examples, needs_fixture
from tests.gtecat.controller.test_config_file import FIXTURES, GTS400, mutate

from .conftest import bring_up

ALARM, POS_ERR, POS_LIM, NEG_LIM = 1 << 1, 1 << 4, 1 << 5, 1 << 6
SMOOTH, MOVING = 1 << 7, 1 << 10
SMARTHOME, GTN = FIXTURES


def fixture(name: str) -> Path:
    path = SHARED_FIXTURES / "googol" / name
    if not path.is_file():
        pytest.skip(needs_fixture(path.name))
    return path


def edited(tmp_path: Path, name: str, edits: dict[str, dict[str, str]], out: str = "") -> Path:
    """A copy of fixture ``name`` with ``{"axis1": {"key": "value"}}`` replaced (each must hit)."""
    lines = fixture(name).read_text(encoding="ascii").splitlines()
    todo = {(s, k) for s, keys in edits.items() for k in keys}
    section = None
    for i, line in enumerate(lines):
        if m := re.fullmatch(r"\[(\w+)\]", line):
            section = m.group(1)
        elif "=" in line:
            key = line.split("=")[0]
            if key in edits.get(section, {}):
                lines[i] = f"{key}={edits[section][key]}"
                todo.discard((section, key))
    assert not todo, f"not in {name}: {todo}"
    path = tmp_path / (out or name)
    path.write_text("\n".join(lines) + "\n", encoding="ascii")
    return path


def machine(tmp_path: Path, body: str) -> str:
    p = tmp_path / "machine.toml"
    p.write_text(body)
    return str(p)


def up(tmp_path: Path | None = None, body: str = "", eni: str = "manual_fig5_2.eni") -> None:
    opts = {"machine": machine(tmp_path, body)} if tmp_path is not None and body else {}
    bring_up(eni, clock="lockstep", **opts)


def load(path: Path | str) -> int:
    return gt.GT_LoadConfig(str(path))


def log() -> list[str]:
    return [line for line in gt.GTE_Controller().log.lines if "GT_LoadConfig" in line]


def sts(axis: int = 1) -> int:
    s = c_long()
    assert gt.GT_GetSts(axis, byref(s)) == 0
    return s.value


def settle(axis: int = 1) -> int:
    """GT_ClrSts as 4.4 asks, then a cycle: the flags the new configuration gives."""
    assert gt.GT_ClrSts(axis) == 0
    gt.GTE_Wait(2)
    return sts(axis)


def double(getter, axis: int = 1) -> float:
    v = c_double()
    assert getter(axis, byref(v)) == 0
    return v.value


def trap_to(axis: int, pos: int, vel: float = 20, acc: float = 1) -> None:
    assert gt.GT_AxisOn(axis) == 0, gt.GTE_GetLastError()
    prm = gt.TTrapPrm()
    prm.acc, prm.dec, prm.velStart, prm.smoothTime = acc, acc, 0, 0
    assert gt.GT_PrfTrap(axis) == 0, gt.GTE_GetLastError()
    assert gt.GT_SetTrapPrm(axis, byref(prm)) == 0
    assert gt.GT_SetPos(axis, pos) == 0 and gt.GT_SetVel(axis, vel) == 0
    assert gt.GT_Update(1 << (axis - 1)) == 0, gt.GTE_GetLastError()
    for _ in range(100_000):
        gt.GTE_Wait(1)
        if not sts(axis) & MOVING:
            break
    gt.GTE_Wait(5)


def channel(slave: int = 0, k: int = 0):
    return gt.GTE_Slave(slave).channel(k)


# --- both real files load, and say in the log what they leave aside ------------------------------
def test_smarthome_file_loads_on_a_two_axis_bus_and_logs_what_it_does_not_apply():
    up()
    assert load(fixture(SMARTHOME)) == 0, gt.GTE_GetLastError()
    lines = log()
    assert len(lines) == 4, lines
    assert "138 sections read, applied to axes 1-2" in lines[0]
    # no switch_wiring in the machine: its normally-closed limits are wired as it expects
    assert "inputs: limitPositive1 reverse=1 (a normally-closed switch)" in lines[3]
    assert "limitNegative1 reverse=1" in lines[3]
    assert lines[1].endswith(
        "pulse-card resources without an EtherCAT counterpart, accepted and ignored: "
        "[dac1-12] [step1-4] [gpo1-16] [gpi1-16] [enable1-8] [clear1-8] [arrive1-8] [mpg1-7]"
    )
    assert "this bus has axes 1-2; accepted and not applied: [profile3-8] [axis3-8] " in lines[2]
    assert "[encoder3-11]" in lines[2] and "[alarm3-8]" in lines[2]


def test_gtn_file_loads_on_twelve_axes_and_on_two(tmp_path):
    up(eni="twelve_axes.eni")
    assert load(fixture(GTN)) == 0, gt.GTE_GetLastError()
    lines = log()
    assert "268 sections read, applied to axes 1-12" in lines[0]
    assert "[control1-12] but errorLimit" in lines[1] and "[gpi1-64]" in lines[1]
    assert not any("not applied" in line for line in lines)
    gt.GT_Close()
    up()
    assert load(fixture(GTN)) == 0
    assert any("[axis3-12]" in line for line in log())


def test_gts400_file_and_its_crlf_gbk_variant_load(tmp_path):
    up(eni="twelve_axes.eni")
    assert load(GTS400) == 0, gt.GTE_GetLastError()
    text = GTS400.read_text().replace("[axis3]", "[axis3]\n; 第3轴: 步进电机, 限位常闭")
    variant = tmp_path / "GTS400.CFG"
    variant.write_bytes(text.replace("\n", "\r\n").encode("gbk"))
    assert load(variant) == 0, gt.GTE_GetLastError()


# --- profile: stop decelerations, active ---------------------------------------------------------
def test_stop_decelerations_read_back_with_get_stop_dec(tmp_path):
    up()
    cfg = edited(tmp_path, SMARTHOME, {"profile1": {"decSmoothStop": "2.5"}})
    assert load(cfg) == 0, gt.GTE_GetLastError()
    smooth, abrupt = c_double(), c_double()
    assert gt.GT_GetStopDec(1, byref(smooth), byref(abrupt)) == 0
    assert (smooth.value, abrupt.value) == (2.5, 1000.0)
    assert gt.GT_GetStopDec(2, byref(smooth), byref(abrupt)) == 0
    assert (smooth.value, abrupt.value) == (1.0, 1000.0)


def test_inactive_profile_refuses_motion(tmp_path):
    up()
    assert load(edited(tmp_path, GTN, {"profile2": {"active": "0"}})) == 0
    assert gt.GT_PrfTrap(2) == 1 and "not active" in gt.GTE_GetLastError()
    assert gt.GT_PrfTrap(1) == 0


# --- axis: alarm and limit inputs -----------------------------------------------------------------
def test_index_minus_one_is_none_so_alarm_and_limit_switching_return_1():
    """The manual's test.cfg ("取消了各轴的报警和限位") writes index -1 (entries 2, 3, 81)."""
    up()
    assert load(fixture(GTN)) == 0
    assert gt.GT_AlarmOn(1) == 1 and "none" in gt.GTE_GetLastError()
    assert gt.GT_LmtsOn(1) == 1
    channel().inject_fault("alarm")
    gt.GTE_Wait(3)
    assert not sts() & ALARM  # no alarm input: the drive's fault is not the axis's alarm
    assert gt.GT_Reset() == 0 and gt.GT_AlarmOn(1) == 0  # GT_Reset: table 4-4 again


def test_alarm_on_its_own_input_and_alarm_active_is_the_alarm_on_state(tmp_path):
    up()
    assert load(edited(tmp_path, SMARTHOME, {"axis1": {"alarmIndex": "1"}})) == 0
    channel().inject_fault("alarm")
    gt.GTE_Wait(3)
    assert sts() & ALARM
    channel().clear_injected_fault()
    assert settle() & ALARM == 0
    cfg = edited(tmp_path, SMARTHOME, {"axis1": {"alarmIndex": "1"}, "alarm1": {"active": "0"}})
    assert load(cfg) == 0
    channel().inject_fault("alarm")
    gt.GTE_Wait(3)
    assert not sts() & ALARM  # GT_AlarmOff state
    assert gt.GT_AlarmOn(1) == 0  # switchable: the input exists
    gt.GTE_Wait(2)
    assert sts() & ALARM


NO = 'switch_wiring = "normally_open"\n'  # the machine says: reverse=1 then inverts


def test_reverse_flips_the_limit_sense(tmp_path):
    """Axis 1 stands on its positive switch, which the machine description wires normally
    open; smarthome's limitPositive1/limitNegative1 have reverse=1 (normally-closed switches):
    the pressed switch reads released and the other one pressed.  (Without switch_wiring the
    switches are wired as the file expects: test_cfg_surroundings.)"""
    up(tmp_path, "[axis.1]\nposition = 100\npositive_limit = 50\n" + NO)
    gt.GTE_Wait(1)
    assert sts() & (POS_LIM | NEG_LIM) == POS_LIM  # table 4-4: own switches, normal sense
    assert load(fixture(SMARTHOME)) == 0, gt.GTE_GetLastError()
    assert settle() & (POS_LIM | NEG_LIM) == NEG_LIM
    normal = {"limitPositive1": {"reverse": "0"}, "limitNegative1": {"reverse": "0"}}
    assert load(edited(tmp_path, SMARTHOME, normal)) == 0
    assert settle() & (POS_LIM | NEG_LIM) == POS_LIM
    off = {**normal, "limitPositive1": {"reverse": "0", "active": "0"}}
    assert load(edited(tmp_path, SMARTHOME, off)) == 0
    assert settle() & (POS_LIM | NEG_LIM) == 0  # GT_LmtsOff state
    assert gt.GT_LmtsOn(1, gt.MC_LIMIT_POSITIVE) == 0
    gt.GTE_Wait(2)
    assert sts() & POS_LIM


def test_reverse_is_forgotten_by_gt_reset(tmp_path):
    up(tmp_path, "[axis.1]\nposition = 100\npositive_limit = 50\n" + NO)
    assert load(fixture(SMARTHOME)) == 0
    assert settle() & NEG_LIM
    assert gt.GT_Reset() == 0
    assert settle() & (POS_LIM | NEG_LIM) == POS_LIM
    assert gt.GT_LoadConfig(str(GTS400)) == 0  # a later file without axis 1's limits
    assert settle() & (POS_LIM | NEG_LIM) == POS_LIM


def test_limit_from_another_axis_and_from_a_home_switch(tmp_path):
    """4.3.1 "将轴 2 的限位信号配给轴 1"; and a home switch (MC_HOME 3) as positive limit."""
    up(tmp_path, "[axis.2]\nposition = 100\npositive_limit = 50\nhome_switch = [[0, 200]]\n" + NO)
    assert load(edited(tmp_path, SMARTHOME, {"axis1": {"limitPositiveIndex": "2"}})) == 0
    assert settle() & POS_LIM  # axis 2's switch, with limitPositive2's normal sense
    home = {"axis1": {"limitPositiveType": "3", "limitPositiveIndex": "2"}}
    assert load(edited(tmp_path, SMARTHOME, home)) == 0
    assert not settle() & POS_LIM  # smarthome's home2 has reverse=1: the pressed switch is off
    assert load(edited(tmp_path, SMARTHOME, {**home, "home2": {"reverse": "0"}})) == 0
    assert settle() & POS_LIM


def test_smooth_stop_input_from_a_home_switch(tmp_path):
    """9.4: a stop input (extension: the tool says "配置无效") - here home switch 1."""
    up(tmp_path, "[axis.1]\nhome_switch = [[-100, 100]]\n" + NO)
    stop = {"axis1": {"smoothStopType": "3", "smoothStopIndex": "1"}}
    assert load(edited(tmp_path, GTN, stop)) == 0
    gt.GTE_Wait(2)
    assert sts() & SMOOTH
    assert load(edited(tmp_path, GTN, {**stop, "home1": {"reverse": "1"}})) == 0
    assert not settle() & SMOOTH


def test_inputs_on_card_terminals_or_missing_axes_are_noted(tmp_path):
    up()
    cfg = edited(
        tmp_path,
        GTN,
        {
            "axis1": {"smoothStopIndex": "3", "limitPositiveIndex": "7"},
            "axis2": {"alarmIndex": "2"},
            "alarm2": {"reverse": "1"},
        },
    )
    assert load(cfg) == 0, gt.GTE_GetLastError()
    notes = log()[-1]
    assert "axis 1 positive limit = limitPositive7: no axis 7 on this bus" in notes
    assert "axis 1 smooth stop = gpi3, a card terminal: none" in notes
    # the machine description does not say how the alarm is wired: as the file expects
    assert "alarm2 reverse=1 (an alarm that opens in fault)" in notes
    gt.GTE_Wait(2)
    assert not sts(2) & ALARM  # the application's own file leaves its healthy axis usable


def test_an_alarm_reverse_against_a_stated_wiring_inverts_it(tmp_path):
    up(tmp_path, '[axis.2]\nswitch_wiring = "normally_open"\n')
    edits = {
        "axis1": {"smoothStopIndex": "3", "limitPositiveIndex": "7"},
        "axis2": {"alarmIndex": "2"},
        "alarm2": {"reverse": "1"},
    }
    assert load(edited(tmp_path, GTN, edits)) == 0, gt.GTE_GetLastError()
    assert "axis 2 alarm = alarm2 reverse=1: active while drive 2 is not in fault" in log()[-1]
    gt.GTE_Wait(2)
    assert sts(2) & ALARM  # reversed: the healthy drive is "in alarm"


# --- scaling, encoder, following error ------------------------------------------------------------
def test_prf_map_alpha_beta_scales_the_axis(tmp_path):
    """prfMapAlpha1/Beta1 = GT_ProfileScale: ΔP_profile / ΔP_axis = 2 / 1 (4.3.1 item 2)."""
    up()
    cfg = edited(tmp_path, GTN, {"axis1": {"prfMapAlpha1": "2", "encMapAlpha1": "4"}})
    assert load(cfg) == 0, gt.GTE_GetLastError()
    trap_to(1, 2000)
    assert double(gt.GT_GetPrfPos) == 2000
    assert double(gt.GT_GetAxisPrfPos) == 1000
    assert double(gt.GT_GetEncPos) == pytest.approx(1000)  # the drive went to 1000
    assert double(gt.GT_GetAxisEncPos) == pytest.approx(250)  # encoder 4:1


def test_encoder_reverse_0_counts_against_the_drive_and_1_with_it(tmp_path):
    """The tool writes reverse=1, the vendor's reset state (entry 18): counts as the drive does."""
    up()
    assert load(fixture(GTN)) == 0
    trap_to(1, 1000)
    assert double(gt.GT_GetEncPos) == pytest.approx(1000)
    assert load(edited(tmp_path, GTN, {"encoder1": {"reverse": "0"}})) == 0
    trap_to(1, 1500)
    assert double(gt.GT_GetEncPos) == pytest.approx(500)  # counted 500 the other way


def test_capture_source_1_is_the_pulse_counter(tmp_path):
    up()
    assert load(fixture(SMARTHOME)) == 0  # encoders 1-4: captureSource=1
    enc = gt.GTE_Controller().axis(1).motion.encoder
    assert enc.external is False  # GT_EncOff: counts 607Ah
    assert load(fixture(GTN)) == 0
    assert enc.external is True


def test_error_limit_of_an_active_control_is_gt_set_pos_err(tmp_path):
    up()
    err = c_long()
    assert load(edited(tmp_path, GTN, {"control1": {"errorLimit": "0x400"}})) == 0
    assert gt.GT_GetPosErr(1, byref(err)) == 0 and err.value == 32767  # control1 active=0
    cfg = edited(tmp_path, GTN, {"control1": {"errorLimit": "0x400", "active": "1"}})
    assert load(cfg) == 0
    assert gt.GT_GetPosErr(1, byref(err)) == 0 and err.value == 1024


# --- errors: 7 with file:line and the key as written; nothing applied -----------------------------
def test_unknown_key_is_7_with_file_line_and_key(tmp_path):
    up()
    text = fixture(SMARTHOME).read_text().replace("decSmoothStop=1.000000", "decSmothStop=2", 1)
    bad = tmp_path / "test.cfg"
    bad.write_text(text)
    assert load(bad) == 7
    reason = gt.GTE_GetLastError()
    assert "test.cfg:3:" in reason and "'decSmothStop'" in reason and "[profile1]" in reason


def test_bad_value_or_unknown_section_is_7_and_nothing_is_applied(tmp_path):
    up()
    text = fixture(SMARTHOME).read_text()
    bad = tmp_path / "bad.cfg"
    bad.write_text(text.replace("decSmoothStop=1.000000", "decSmoothStop=2.5", 1) + "[laser1]\n")
    assert load(bad) == 7
    assert (
        f"bad.cfg:{len(text.splitlines()) + 1}: unknown section [laser1]" in gt.GTE_GetLastError()
    )
    smooth, abrupt = c_double(), c_double()
    gt.GT_GetStopDec(1, byref(smooth), byref(abrupt))
    assert smooth.value == 1.0  # nothing applied
    bad.write_text(text.replace("prfMap=0x1", "prfMap=0x1z"))
    assert load(bad) == 7 and "prfMap='0x1z'" in gt.GTE_GetLastError()


def test_legacy_file_still_loads_with_a_deprecation_line(tmp_path):
    up()
    old = tmp_path / "old.cfg"
    old.write_text("[axis 1]\nalarm = off\n")
    assert load(old) == 0
    assert "deprecated" in log()[-1]


# --- random damage: 0 or 7, never an exception (-7) -----------------------------------------------
@settings(max_examples=examples(100, 25), deadline=None)
@given(
    st.sampled_from(FIXTURES),
    st.lists(
        st.tuples(
            st.sampled_from(["replace", "value", "key", "delete", "duplicate", "insert"]),
            st.integers(0, 10_000),
            st.text(alphabet="[]=;#-+.0123456789xXaAeE_ profilexncdr", max_size=16),
        ),
        min_size=1,
        max_size=3,
    ),
    st.randoms(use_true_random=False),
)
def test_mutated_fixture_lines_give_0_or_7(name, mutations, rnd: random.Random):
    try:
        gt.GTE_Controller()  # one bus for every example (the fixture closes it at the end)
    except Exception:
        up()
    lines = fixture(name).read_text(encoding="ascii").splitlines()
    with tempfile.TemporaryDirectory() as d:
        path = Path(d) / "mut.cfg"
        path.write_text("\n".join(mutate(lines, mutations)) + rnd.choice(["", "\n", "\r\n"]))
        rc = load(path)
        assert rc in (0, 7), gt.GTE_GetLastError()
        if rc == 7:
            assert re.search(r"mut\.cfg:\d+: ", gt.GTE_GetLastError()), gt.GTE_GetLastError()
