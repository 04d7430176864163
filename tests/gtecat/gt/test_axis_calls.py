"""Axis-level EtherCAT GT calls on a virtual CiA-402 drive (manual chapter 5 table 5-1,
chapter 13 entries 4, 5, 34-42, 100-102, 113-114; vendor header GT_GetEcatAxisPdoData,
GT_GetEcatErrorCode), with the objects at the offsets ``gtecat map`` gives."""

from __future__ import annotations

import functools
import json
import subprocess
import sys
from ctypes import byref, c_double, c_long, c_short, c_ubyte, c_uint32, c_ulong, c_ushort

import pytest

from gtecat import gt
from tests.conftest import EXAMPLES

from .conftest import bring_up

FULL = "full_servo.eni"


@functools.cache
def _map_output(eni: str) -> str:
    """What ``gtecat map ENI --json`` prints (run once per file in this process: the
    command reads the file alone, so every test of it gets the same text)."""
    return subprocess.run(
        [sys.executable, "-m", "gtecat", "map", str(EXAMPLES / eni), "--json"],
        capture_output=True,
        text=True,
        check=True,
    ).stdout


def _map_offsets(eni: str) -> dict[tuple[int, int, int], int]:
    doc = json.loads(_map_output(eni))
    return {
        (s["position"], e["index"], e["subindex"]): e["gt_bit"] // 8
        for s in doc["slaves"]
        for e in s["entries"]
    }


def test_axis_on_walks_the_state_machine_and_off_disables():
    bring_up(FULL)
    sw = c_ushort()
    off = _map_offsets(FULL)[(0, 0x6041, 0)]
    assert gt.GT_AxisOn(1) == 0, gt.GTE_GetLastError()
    gt.GT_GetEcatRawData(off, 2, byref(sw))
    assert sw.value & 0x6F == 0x27  # operation enabled (cia402-facts 1.2)
    assert gt.GT_AxisOff(1) == 0
    gt.GTE_Wait(3)
    gt.GT_GetEcatRawData(off, 2, byref(sw))
    assert sw.value & 0x6F != 0x27


def test_modes_switch_and_6061_follows_through_raw_data():
    bring_up(FULL)
    offsets = _map_offsets(FULL)
    mode = c_short()
    for m in (9, 10, 3, 8):
        assert gt.GT_SetEcatAxisMode(1, m) == 0, gt.GTE_GetLastError()
        gt.GTE_Wait(3)
        assert gt.GT_GetEcatAxisMode(1, byref(mode)) == 0 and mode.value == m
        raw = c_ubyte()
        assert gt.GT_GetEcatRawData(offsets[(0, 0x6061, 0)], 1, byref(raw)) == 0
        assert raw.value == m
    assert gt.GT_SetEcatAxisMode(1, 5) == 7  # not a mode of entry 100
    assert gt.GT_SetEcatAxisMode(3, 8) == 7  # no axis 3
    assert "axis 3" in gt.GTE_GetLastError()


def test_unmapped_objects_return_1_naming_the_object():
    bring_up("manual_fig5_2.eni")  # maps only 6040/607A/6041/6064/60FD
    v = c_long()
    cases = [
        (gt.GT_GetEcatEncVel, "0x606C"),
        (gt.GT_GetEcatAxisPE, "0x60F4"),
        (gt.GT_GetEcatAxisAtITorque, "0x6077"),
        (gt.GT_GetEcatAxisAtICurrent, "0x6078"),
        (gt.GT_GetEcatAxisMode, "0x6061"),
        (gt.GT_GetEcatErrorCode, "0x603F"),
        (gt.GT_GetEcatAxisDO, "0x60FE"),
    ]
    for fn, obj in cases:
        assert fn(1, byref(v)) == 1, fn.__name__
        assert obj in gt.GTE_GetLastError(), gt.GTE_GetLastError()
    assert gt.GT_SetEcatAxisPT(2, 100) == 1 and "0x6871" not in gt.GTE_GetLastError()
    assert "0x6071" in gt.GTE_GetLastError()
    assert gt.GT_GetEcatEncPos(2, byref(v)) == 0  # mapped: fine


def test_velocity_and_torque_modes_move_the_drive():
    bring_up(FULL)
    assert gt.GT_AxisOn(1) == 0
    assert gt.GT_SetEcatAxisMode(1, 9) == 0
    assert gt.GT_SetEcatAxisPV(1, 20000) == 0  # counts/s
    gt.GTE_Wait(300)
    vel, pos = c_long(), c_long()
    assert gt.GT_GetEcatEncVel(1, byref(vel)) == 0
    assert vel.value == pytest.approx(20000, rel=0.05)
    assert gt.GT_GetEcatEncPos(1, byref(pos)) == 0 and pos.value > 2000
    assert gt.GT_SetEcatAxisPV(1, 0) == 0
    gt.GTE_Wait(200)
    assert gt.GT_SetEcatAxisMode(1, 10) == 0
    assert gt.GT_SetEcatAxisPT(1, 50) == 0
    gt.GTE_Wait(50)
    torque = c_short()
    assert gt.GT_GetEcatAxisAtITorque(1, byref(torque)) == 0 and torque.value > 0
    # back to CSP: the controller takes the actual position, the axis does not jump
    gt.GT_SetEcatAxisPT(1, 0)
    gt.GT_GetEcatEncPos(1, byref(pos))
    assert gt.GT_SetEcatAxisMode(1, 8) == 0
    gt.GTE_Wait(20)
    after = c_long()
    gt.GT_GetEcatEncPos(1, byref(after))
    st = gt.GTE_Slave(0).channel(0)
    assert st.state.name == "OPERATION_ENABLED"
    assert abs(after.value - pos.value) < 2000


def test_digital_io_and_analog_inputs_of_the_axis():
    bring_up(FULL)
    ch = gt.GTE_Slave(0).channel(0)
    ch.set_analog_input(1, 1234)
    ch.set_analog_input(2, -42)
    gt.GTE_Wait(2)
    ai = c_short()
    assert gt.GT_GetEcatAxisAI(1, 1, byref(ai)) == 0 and ai.value == 1234
    assert gt.GT_GetEcatAxisAI(1, 2, byref(ai)) == 0 and ai.value == -42
    assert gt.GT_GetEcatAxisAI(1, 3, byref(ai)) == 7
    assert gt.GT_SetEcatAxisDO(1, 0x00010000) == 0
    do = c_ulong()
    assert gt.GT_GetEcatAxisDO(1, byref(do)) == 0 and do.value == 0x00010000
    di = c_ulong()
    assert gt.GT_GetEcatAxisDI(1, byref(di)) == 0


def test_pdo_data_by_object_and_pos_scale():
    bring_up(FULL)
    buf = (c_ubyte * 4)()
    assert gt.GT_GetEcatAxisPdoData(1, 0x6041, buf) == 0
    sw = c_ushort()
    gt.GT_GetEcatRawData(_map_offsets(FULL)[(0, 0x6041, 0)], 2, byref(sw))
    assert int.from_bytes(bytes(buf[:2]), "little") == sw.value
    assert gt.GT_GetEcatAxisPdoData(1, 0x60B9, buf) == 1
    assert "0x60B9" in gt.GTE_GetLastError()
    scale = c_short()
    assert gt.GT_SetPosScale(1, 6) == 0 and gt.GT_GetPosScale(1, byref(scale)) == 0
    assert scale.value == 6
    assert gt.GT_SetPosScale(1, 40) == 7


def test_sdo_existing_missing_read_only_against_cia301_abort_codes():
    bring_up(FULL)
    data, size, abort = (c_ubyte * 8)(), c_uint32(), c_uint32()
    assert gt.GT_EcatSDOUpload(0, 0x6502, 0, data, 8, byref(size), byref(abort)) == 0
    assert int.from_bytes(bytes(data[:4]), "little") & 0x80  # CSP supported
    cases = [
        (0x2FFF, 0, 0x06020000),  # object does not exist
        (0x6099, 9, 0x06090011),  # subindex does not exist
    ]
    for index, sub, code in cases:
        assert gt.GT_EcatSDOUpload(0, index, sub, data, 8, byref(size), byref(abort)) == 1
        assert abort.value == code
    two = (c_ubyte * 2)(0, 0)
    assert gt.GT_EcatSDODownload(0, 0x6041, 0, two, 2, byref(abort)) == 1
    assert abort.value == 0x06010002  # read-only
    four = (c_ubyte * 4)(1, 2, 3, 4)
    assert gt.GT_EcatSDODownload(0, 0x6060, 0, four, 4, byref(abort)) == 1
    assert abort.value == 0x06070012  # length too high
    home = (c_ubyte * 4)(*(12345).to_bytes(4, "little"))
    assert gt.GT_EcatSDODownload(0, 0x607C, 0, home, 4, byref(abort)) == 0 and abort.value == 0
    assert gt.GT_EcatSDOUpload(0, 0x607C, 0, data, 8, byref(size), byref(abort)) == 0
    assert size.value == 4 and int.from_bytes(bytes(data[:4]), "little") == 12345


@pytest.mark.long
def test_forced_following_error_faults_and_a_reset_clears_it():
    """cia402-facts pitfall 4: a set-point step beyond 6065h trips the following error."""
    bring_up(FULL)
    assert gt.GT_AxisOn(1) == 0
    ax = gt.GTE_Controller().axis(1)
    ax.prf_pos += 200_000  # an application bug: a jump in the CSP set-point
    gt.GTE_Wait(50)
    code = c_ushort()
    assert gt.GT_GetEcatErrorCode(1, byref(code)) == 0
    assert code.value == 0x8611
    sw = c_ushort()
    off = _map_offsets(FULL)[(0, 0x6041, 0)]
    gt.GT_GetEcatRawData(off, 2, byref(sw))
    assert sw.value & 0x4F == 0x08  # fault
    # the drive's CoE emergency is in the master log, as IgH writes it
    assert any("CoE EMERGENCY 0x8611" in line for line in gt.GTE_Controller().log.lines)
    assert gt.GT_AxisOn(1) == 1 and "0x8611" in gt.GTE_GetLastError()
    # fault reset through raw data: 0 then a rising edge of bit 7 (cia402-facts 1.3)
    cw_off = _map_offsets(FULL)[(0, 0x6040, 0)]
    for word in (0x0000, 0x0080, 0x0000):
        gt.GT_SetEcatRawData(cw_off, 2, byref(c_ushort(word)))
        gt.GTE_Wait(2)
    gt.GT_GetEcatRawData(off, 2, byref(sw))
    assert sw.value & 0x4F == 0x40  # switch on disabled
    assert gt.GT_AxisOn(1) == 0, gt.GTE_GetLastError()


def test_pdo_data_of_a_module_channel_never_reads_another_channel():
    """A 4-axis module (channel k at +0x800*k): axis 6 is channel 1 of slave 4.

    Its statusword is 0x6041 in channel-0 numbering and 0x6841 in its own; 0x7041 is
    channel 2's (axis 7), so asking axis 6 for it returns 1 instead of axis 7's value.
    """
    bring_up("twelve_axes.eni")
    assert gt.GT_AxisOn(7) == 0  # channel 2 enabled, channel 1 not: different statuswords
    own, zero = (c_ubyte * 2)(), (c_ubyte * 2)()
    assert gt.GT_GetEcatAxisPdoData(6, 0x6841, own) == 0
    assert gt.GT_GetEcatAxisPdoData(6, 0x6041, zero) == 0
    assert bytes(own) == bytes(zero)
    assert int.from_bytes(bytes(own), "little") & 0x4F == 0x40  # switch on disabled
    other = (c_ubyte * 2)()
    assert gt.GT_GetEcatAxisPdoData(6, 0x7041, other) == 1
    assert "channel 2" in gt.GTE_GetLastError() and "0x6841" in gt.GTE_GetLastError()
    assert gt.GT_GetEcatAxisPdoData(7, 0x7041, other) == 0
    assert int.from_bytes(bytes(other), "little") & 0x6F == 0x27  # operation enabled


def test_profile_position_through_raw_data_keeps_the_application_target():
    """PP (6060h = 1) with 607Ah and the set-point handshake written by GT_SetEcatRawData:
    the controller leaves 607Ah to the application while the drive is enabled outside CSP
    (it used to overwrite it with 6064h every cycle, so a PP move never went anywhere)."""
    bring_up(FULL, clock="lockstep")
    offsets = _map_offsets(FULL)
    assert gt.GT_AxisOn(1) == 0, gt.GTE_GetLastError()
    assert gt.GT_SetEcatAxisMode(1, 1) == 0
    gt.GTE_Wait(3)
    abort = c_uint32()
    for index, value in ((0x6081, 100_000), (0x6083, 1_000_000), (0x6084, 1_000_000)):
        data = (c_ubyte * 4)(*value.to_bytes(4, "little"))
        assert gt.GT_EcatSDODownload(0, index, 0, data, 4, byref(abort)) == 0
    target, cw = offsets[(0, 0x607A, 0)], offsets[(0, 0x6040, 0)]
    sw = c_ushort()
    assert gt.GT_SetEcatRawData(target, 4, byref(c_long(20_000))) == 0
    assert gt.GT_SetEcatRawData(cw, 2, byref(c_ushort(0x001F))) == 0  # new set-point
    gt.GTE_Wait(2)
    gt.GT_GetEcatRawData(offsets[(0, 0x6041, 0)], 2, byref(sw))
    assert sw.value & 0x1000  # SW12: set-point acknowledged
    assert gt.GT_SetEcatRawData(cw, 2, byref(c_ushort(0x000F))) == 0
    gt.GTE_Wait(400)
    pos, tp = c_long(), c_long()
    gt.GT_GetEcatRawData(target, 4, byref(tp))
    assert gt.GT_GetEcatEncPos(1, byref(pos)) == 0
    assert (tp.value, pos.value) == (20_000, 20_000)
    gt.GT_GetEcatRawData(offsets[(0, 0x6041, 0)], 2, byref(sw))
    assert sw.value & 0x0400  # SW10: target reached
    # back to CSP: the planned position is where PP left the axis, no jump
    assert gt.GT_SetEcatAxisMode(1, 8) == 0
    gt.GTE_Wait(5)
    prf = c_double()
    assert gt.GT_GetPrfPos(1, byref(prf)) == 0 and prf.value == 20_000
    assert gt.GT_GetEcatEncPos(1, byref(pos)) == 0 and pos.value == 20_000
