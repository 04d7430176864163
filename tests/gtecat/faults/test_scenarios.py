"""Every fault kind through the GT API, as a user's error handler sees it.

One small machine each (``full_servo.eni``: one drive with 603Fh and 60FDh mapped, one IO
slave; ``manual_fig5_2.eni``: two drives and two IO slaves), lockstep clock: what the
application reads is asserted - GT_GetSts bits (1 alarm, 5/6 limits, 9 servo on),
GT_GetEcatErrorCode, GT_IsEcatReady, GT_GetEcatSlaves, the return codes of calls made
while a slave is gone, the SDO abort codes - and that the manual's recovery (GT_ClrSts: the
fault reset, then GT_AxisOn) brings the axis back once the cause is gone.
"""

from __future__ import annotations

from ctypes import byref, c_double, c_long, c_short, c_ubyte, c_uint32, c_ushort
from pathlib import Path

import pytest

from gtecat import faults, gt
from gtecat.errors import ParameterError
from gtecat.faults import FaultSpecError
from gtecat.master.bus import SDO_TIMEOUT_MS
from tests.conftest import EXAMPLES

ALARM, POS_LIMIT, SERVO_ON = 1 << 1, 1 << 5, 1 << 9

MACHINE = """
[axis.1]
position = 0
negative_limit = -200000
positive_limit = 200000
probe1 = [[1000, 1200]]
following_error_window = 2000
"""


@pytest.fixture(scope="module")
def machine(tmp_path_factory: pytest.TempPathFactory) -> Path:
    p = tmp_path_factory.mktemp("faults") / "machine.toml"
    p.write_text(MACHINE)
    return p


def up(eni: str = "full_servo.eni", machine: Path | None = None, axes: int = 1) -> None:
    opts = {"machine": str(machine)} if machine else {}
    assert gt.GT_Open(eni=str(EXAMPLES / eni), clock="lockstep", log="", **opts) == 0
    assert gt.GT_InitEcatComm() == 0, gt.GTE_GetLastError()
    assert wait(lambda: ready() == 1, 200)
    assert gt.GT_StartEcatComm() == 0
    assert gt.GT_Reset() == 0
    for a in range(1, axes + 1):
        assert gt.GT_AxisOn(a) == 0, gt.GTE_GetLastError()
    gt.GTE_Wait(20)


def wait(pred, ms: int) -> bool:
    for _ in range(ms):
        if pred():
            return True
        gt.GTE_Wait(1)
    return pred()


def ready() -> int:
    st = c_short()
    gt.GT_IsEcatReady(byref(st))
    return st.value


def sts(axis: int = 1) -> int:
    v = c_long()
    assert gt.GT_GetSts(axis, byref(v)) == 0
    return v.value


def error_code(axis: int = 1) -> int:
    v = c_ushort()
    assert gt.GT_GetEcatErrorCode(axis, byref(v)) == 0, gt.GTE_GetLastError()
    return v.value


def enc(axis: int = 1) -> float:
    v = c_double()
    gt.GT_GetEncPos(axis, byref(v))
    return v.value


def trap(pos: int, vel: float = 20, axis: int = 1) -> None:
    prm = gt.TTrapPrm()
    prm.acc = prm.dec = 0.5
    assert gt.GT_PrfTrap(axis) == 0
    assert gt.GT_SetTrapPrm(axis, byref(prm)) == 0
    assert gt.GT_SetPos(axis, pos) == 0
    assert gt.GT_SetVel(axis, vel) == 0
    assert gt.GT_Update(1 << (axis - 1)) == 0


def recover(axis: int = 1) -> None:
    """The manual's way back: clear the status, servo on again (the drive's fault reset)."""
    assert gt.GT_ClrSts(axis, 1) == 0
    assert gt.GT_AxisOn(axis) == 0, gt.GTE_GetLastError()
    assert wait(lambda: sts(axis) & SERVO_ON and not sts(axis) & ALARM, 100)


# --- the drive --------------------------------------------------------------------------------
@pytest.mark.parametrize(
    ("code", "name"),
    [
        (0x2310, "overcurrent"),
        (0x3210, "overvoltage"),
        (0x3220, "undervoltage"),
        (0x4310, "overtemperature"),
        (0x7305, "encoder"),
        (0x8611, "following_error"),
    ],
)
def test_drive_fault_mid_trap_sets_the_alarm_and_recovers(code: int, name: str) -> None:
    up()
    trap(100_000)
    gt.GTE_Wait(30)
    fid = faults.inject("drive_fault", axis=1, code=name)
    assert wait(lambda: sts() & ALARM, 10)
    assert error_code() == code
    assert not sts() & SERVO_ON
    gt.GTE_Wait(50)
    if code != 0x8611:  # a persisting cause: the fault reset is refused until it is gone
        gt.GT_ClrSts(1, 1)
        gt.GT_AxisOn(1)
        gt.GTE_Wait(20)
        assert error_code() == code
    assert faults.clear(fid) == 1
    recover()
    assert error_code() == 0


def test_sto_removes_torque_and_shows_ff10() -> None:
    up()
    trap(100_000)
    gt.GTE_Wait(30)
    faults.inject("sto", axis=1)
    assert wait(lambda: sts() & ALARM, 10)
    assert error_code() == 0xFF10
    faults.clear()
    recover()


def pdo(index: int, axis: int = 1) -> int:
    v = c_ushort()
    assert gt.GT_GetEcatAxisPdoData(axis, index, byref(v)) == 0, gt.GTE_GetLastError()
    return v.value


QSA, SOD, OE = 0x07, 0x40, 0x27  # statusword & 0x6F: quick stop active, switch on disabled, ...


def test_quick_stop_input_ramps_the_drive_down() -> None:
    """The drive brakes on its quick-stop ramp (6085h: 5,000,000 counts/s², 605Ah 2) in quick
    stop active, then goes to switch on disabled by itself: the controller lets it finish
    (controlword "quick stop" 0002h meanwhile; disable voltage would make it coast)."""
    up()
    trap(100_000, vel=50)  # 50,000 counts/s
    gt.GTE_Wait(300)
    p = enc()
    faults.inject("quick_stop", axis=1)
    states, cws = [], []
    for _ in range(30):
        gt.GTE_Wait(1)
        states.append(pdo(0x6041) & 0x6F)
        cws.append(pdo(0x6040))
    assert states[:8] == [QSA] * 8  # 10 ms of ramp (v/a), not one cycle
    assert states[-1] == SOD and cws[-1] == 0x0000
    assert 0x0002 in cws
    assert not sts() & SERVO_ON
    assert enc() - p < 300  # v²/2a = 250 counts (it coasted 5000 before)
    gt.GTE_Wait(100)
    assert enc() - p < 300
    faults.clear()
    recover()


def test_a_quick_stop_that_stays_is_never_left_by_the_controller() -> None:
    """605Ah 6: the drive stops and stays in quick stop active; the input released, the
    controller's "quick stop" keeps it there (no transition 16 back to operation by itself):
    GT_AxisOn brings it back."""
    up()
    ab = c_uint32()
    assert gt.GT_EcatSDODownload(0, 0x605A, 0, (c_ubyte * 2)(6, 0), 2, byref(ab)) == 0
    trap(100_000, vel=50)
    gt.GTE_Wait(150)
    faults.inject("quick_stop", axis=1)
    gt.GTE_Wait(30)
    assert pdo(0x6041) & 0x6F == QSA and pdo(0x6040) == 0x0002
    faults.clear()
    gt.GTE_Wait(10)
    assert pdo(0x6041) & 0x6F == QSA
    assert not sts() & SERVO_ON
    assert gt.GT_AxisOn(1) == 0, gt.GTE_GetLastError()
    assert wait(lambda: pdo(0x6041) & 0x6F == OE and sts() & SERVO_ON, 50)


def test_a_closed_brake_ends_in_a_following_error(machine: Path) -> None:
    up(machine=machine)
    faults.inject("brake", axis=1)
    trap(100_000)
    assert wait(lambda: sts() & ALARM, 500)
    assert error_code() == 0x8611
    assert abs(enc()) < 50  # the motor never turned
    faults.clear()
    recover()


# --- the machine and the field ---------------------------------------------------------------
def test_a_stuck_limit_switch_shows_the_limit_bit(machine: Path) -> None:
    up(machine=machine)
    faults.inject("switch_stuck", axis=1, switch="positive", value=1)
    assert wait(lambda: sts() & POS_LIMIT, 10)
    faults.clear()
    gt.GTE_Wait(2)
    assert gt.GT_ClrSts(1, 1) == 0
    gt.GTE_Wait(5)
    assert not sts() & POS_LIMIT


def test_a_chattering_switch_toggles_and_latches(machine: Path) -> None:
    up(machine=machine)
    faults.inject("switch_chatter", axis=1, switch="positive", period_cycles=3)
    raw = (c_ubyte * 4)()
    seen = set()
    for _ in range(12):
        gt.GTE_Wait(1)
        gt.GT_GetEcatRawData(37, 4, raw)  # 60FDh
        seen.add(raw[0] & 2)
    assert seen == {0, 2}
    assert sts() & POS_LIMIT  # the controller latches the limit it saw


def test_encoder_loses_counts_and_reads_noise(machine: Path) -> None:
    up(machine=machine)
    before = enc()
    faults.inject("encoder_lost", axis=1, counts=500)
    gt.GTE_Wait(1)
    assert enc() == pytest.approx(before - 500, abs=10)  # the reading slipped
    # the drive's loop closes the error it now sees (within 6065h: no fault): the reading
    # is back on the demand, the motor 500 counts further on, until homed again
    assert wait(lambda: abs(enc() - before) < 1, 100)
    m = c_double()
    gt.GTE_GetMachinePos(1, byref(m))
    assert m.value == pytest.approx(500, abs=1)
    assert not sts() & ALARM
    faults.clear()
    faults.inject("encoder_noise", axis=1, counts=20)
    values = set()
    for _ in range(10):
        gt.GTE_Wait(1)
        values.add(enc())
    assert len(values) > 3 and all(abs(v - before) <= 22 for v in values)


def test_a_missing_probe_never_switches(machine: Path) -> None:
    up(machine=machine)
    raw = (c_ubyte * 4)()
    faults.inject("probe_missing", axis=1)
    gt.GTE_Wait(2)
    gt.GTE_Slave(0).channel(0).machine_position = 1100  # inside the probe window
    gt.GTE_Wait(2)
    gt.GT_GetEcatRawData(37, 4, raw)
    assert raw[2] & 1 == 0
    faults.clear()
    gt.GTE_Wait(2)
    gt.GT_GetEcatRawData(37, 4, raw)
    assert raw[2] & 1 == 1


def test_a_stuck_io_input() -> None:
    up()
    faults.inject("io_stuck", slave=1, bit=3, value=1)
    gt.GTE_Slave(1).set_input_bit(3, False)  # the field says off; the input stays on
    gt.GTE_Wait(2)
    buf = (c_ubyte * 2)()
    assert gt.GT_EcatIOReadInput(1, 2, 1, buf) == 0
    assert buf[0] & 8


# --- the bus ------------------------------------------------------------------------------------
def test_link_down_after_slave_1_loses_the_slaves_behind() -> None:
    up("manual_fig5_2.eni", axes=2)
    fid = faults.inject("link_down", after_slave=1)
    gt.GTE_Wait(30)
    assert ready() == 0
    n = c_short()
    gt.GT_GetEcatSlaves(byref(n))
    assert n.value == 2
    buf = (c_ubyte * 2)()
    assert gt.GT_EcatIOReadInput(2, 0, 2, buf) == 1
    assert "slave 2" in gt.GTE_GetLastError()
    assert not sts(1) & ALARM  # the drives before the break go on
    m = gt.GTE_Controller().master
    assert m.last.wkc < m.last.expected
    faults.clear(fid)
    assert wait(lambda: ready() == 1, 500)
    assert gt.GT_EcatIOReadInput(2, 0, 2, buf) == 0


def test_link_down_before_a_drive_sets_its_alarm() -> None:
    up("manual_fig5_2.eni", axes=2)
    faults.inject("link_down", after_slave=0, duration_ms=100)
    gt.GTE_Wait(30)
    assert sts(2) & ALARM and not sts(1) & ALARM
    assert wait(lambda: ready() == 1, 800)  # the cable is back: the master recovers
    recover(2)


@pytest.mark.parametrize(
    "kind",
    ["drop_responses", "frame_truncate", "frame_wrong_index", "frame_replay", "frame_delay"],
)
def test_lost_or_stale_answers_show_in_is_ecat_ready(kind: str) -> None:
    up("manual_fig5_2.eni", axes=2)
    faults.inject(kind, count=3, **({"us": 5000} if kind == "frame_delay" else {}))
    gt.GTE_Wait(1)
    if kind != "frame_replay":  # a replayed answer carries a good working counter
        assert ready() == 0
    gt.GTE_Wait(5)
    assert ready() == 1
    assert faults.listing() == []  # spent
    assert not sts(1) & ALARM  # three lost frames are no comm loss


def test_wkc_offset_per_command_and_area() -> None:
    up("manual_fig5_2.eni", axes=2)
    faults.inject("wkc_offset", offset=-2, command="LRW", area=[0, 4])
    gt.GTE_Wait(2)
    m = gt.GTE_Controller().master
    assert m.last.wkc == m.last.expected - 2
    assert ready() == 0
    faults.clear()
    faults.inject("wkc_offset", offset=1, command="BRD")  # not the cyclic command: no effect
    gt.GTE_Wait(2)
    assert ready() == 1


@pytest.mark.parametrize("kind", ["power_cycle", "retreat_safeop", "al_error"])
def test_a_slave_that_falls_from_op(kind: str) -> None:
    up()
    faults.inject(kind, slave=0, **({"code": 0x1B} if kind == "al_error" else {}))
    assert wait(lambda: sts() & ALARM, 50)
    assert ready() == 0
    states = gt.GTE_Controller().master.states
    if kind == "al_error":
        gt.GTE_Wait(300)  # the latched error: the master's recovery is refused
        assert ready() == 0 and states[0].name != "OP"
        faults.clear()
    assert wait(lambda: ready() == 1, 500)
    recover()


# --- the mailbox ---------------------------------------------------------------------------------
def sdo_upload(slave: int, index: int) -> tuple[int, int]:
    data, size, abort = (c_ubyte * 4)(), c_uint32(), c_uint32()
    rc = gt.GT_EcatSDOUpload(slave, index, 0, data, 4, byref(size), byref(abort))
    return rc, abort.value


def test_mailbox_abort_lost_answer_and_protocol_fault() -> None:
    up()
    faults.inject("mailbox_abort", slave=0, index=0x6060, code=0x06090030)
    rc, code = sdo_upload(0, 0x6060)
    assert rc != 0 and code == 0x06090030
    assert sdo_upload(0, 0x6060) == (0, 0)  # once
    faults.inject("mailbox_lost", slave=0, count=2)
    clock = gt.GTE_Controller().clock
    t0, n0 = clock.now_ms, clock.cycles
    assert sdo_upload(0, 0x6061)[1] == 0x05040000  # SDO protocol timed out ...
    # ... once the master's mailbox timeout ran out, the cycles running meanwhile
    assert (clock.now_ms - t0, clock.cycles - n0) == (SDO_TIMEOUT_MS, SDO_TIMEOUT_MS)
    assert sdo_upload(0, 0x6061)[1] == 0x05040000
    t0 = clock.now_ms
    assert sdo_upload(0, 0x6061) == (0, 0)
    assert clock.now_ms == t0  # an answer comes within the cycle
    faults.inject("mailbox_protocol", slave=0, variant="wrong_service")
    rc, code = sdo_upload(0, 0x6061)
    assert rc != 0 and code == 0x08000000
    assert "not SDO_RESPONSE" in gt.GTE_GetLastError()


def test_a_lost_download_answer_costs_the_timeout_in_auto_too() -> None:
    assert gt.GT_Open(eni=str(EXAMPLES / "full_servo.eni"), clock="auto", log="") == 0
    assert gt.GT_InitEcatComm() == 0, gt.GTE_GetLastError()
    assert wait(lambda: ready() == 1, 200)
    faults.inject("mailbox_lost", slave=0, index=0x6081)
    clock, abort = gt.GTE_Controller().clock, c_uint32()
    t0 = clock.now_ms
    rc = gt.GT_EcatSDODownload(0, 0x6081, 0, (c_ubyte * 4)(1), 4, byref(abort))
    assert (rc, abort.value) == (1, 0x05040000)
    assert SDO_TIMEOUT_MS <= clock.now_ms - t0 <= SDO_TIMEOUT_MS + 1  # (+ the call's latency)


def test_an_abort_hits_its_step_only() -> None:
    up()
    faults.inject("mailbox_abort", slave=0, index=0x1008, code=0x06060000, step="download_init")
    data, size, abort = (c_ubyte * 64)(), c_uint32(), c_uint32()
    assert gt.GT_EcatSDOUpload(0, 0x1008, 0, data, 64, byref(size), byref(abort)) == 0
    assert bytes(data)[: size.value] == b"Servo 0"  # an upload is no download: it passes
    faults.clear()
    faults.inject("mailbox_abort", slave=0, index=0x1008, code=0x06060000, step="upload_init")
    rc = gt.GT_EcatSDOUpload(0, 0x1008, 0, data, 64, byref(size), byref(abort))
    assert rc != 0 and abort.value == 0x06060000
    gt.GTE_Slave(0).sdo.mailbox_size = 16  # a small mailbox: the name takes segments
    faults.inject("mailbox_abort", slave=0, index=0x1008, code=0x05040000, step="upload_segment")
    rc = gt.GT_EcatSDOUpload(0, 0x1008, 0, data, 64, byref(size), byref(abort))
    assert rc != 0 and abort.value == 0x05040000
    assert gt.GT_EcatSDOUpload(0, 0x1008, 0, data, 64, byref(size), byref(abort)) == 0


def test_abort_at_a_download_step_on_the_nth_sdo() -> None:
    up()
    faults.inject(
        "mailbox_abort",
        slave=0,
        index=0x6081,
        code=0x06090031,
        step="download_init",
        on_sdo=[0, 0x6081, 2],
    )
    data, abort = (c_ubyte * 4)(1, 0, 0, 0), c_uint32()
    assert gt.GT_EcatSDODownload(0, 0x6081, 0, data, 4, byref(abort)) == 0  # the 1st passes
    assert gt.GT_EcatSDODownload(0, 0x6081, 0, data, 4, byref(abort)) != 0
    assert abort.value == 0x06090031


# --- triggers, scripts, TOML, words -------------------------------------------------------------
def test_triggers_at_time_after_cycles_and_position(machine: Path) -> None:
    up(machine=machine)
    t = c_long()
    gt.GT_GetClock(byref(t))
    faults.inject("drive_fault", axis=1, code=0x4310, at_ms=t.value + 50)
    gt.GTE_Wait(45)
    assert not sts() & ALARM
    assert wait(lambda: sts() & ALARM, 10)
    faults.clear()
    recover()
    faults.inject("switch_stuck", axis=1, switch="positive", after_cycles=20)
    gt.GTE_Wait(15)
    assert not sts() & POS_LIMIT
    assert wait(lambda: sts() & POS_LIMIT, 10)
    faults.clear()
    gt.GTE_Wait(2)
    gt.GT_ClrSts(1, 1)
    faults.inject("drive_fault", axis=1, code=0x2310, when_position=[1, 3000])
    trap(10_000)
    assert wait(lambda: sts() & ALARM, 1000)
    assert 2900 < enc() < 4000


def test_a_script_and_the_machine_toml(tmp_path: Path) -> None:
    m = tmp_path / "m.toml"
    m.write_text(
        MACHINE
        + """
[[fault]]
kind = "link_down"
after_slave = 0
at_ms = 100
duration_ms = 50
name = "cut"

[[fault]]
kind = "drive_fault"
axis = 1
code = 0x3220
after = "cut"
after_ms = 300
"""
    )
    up(machine=m)
    listed = faults.listing()
    assert [f["kind"] for f in listed] == ["link_down", "drive_fault"]
    assert "once fault 1 has started" in listed[1]["describe"]
    assert wait(lambda: ready() == 0, 150)
    assert wait(lambda: ready() == 1, 400)
    assert wait(lambda: error_code() == 0x3220, 400)
    log = gt.GTE_Controller().log
    text = "\n".join(getattr(log, "lines", []) or [])
    assert not text or "Fault 1 started" in text


def test_words_and_refusals() -> None:
    assert faults.describe({"kind": "link_down", "after_slave": 1, "at_ms": 500}) == (
        "link down after slave 1 (slaves 2.. vanish), at 500 ms"
    )
    assert "on the 3rd SDO to 0x6060 of slave 0" in faults.describe(
        {"kind": "mailbox_abort", "slave": 0, "index": 0x6060, "on_sdo": [0, 0x6060, 3]}
    )
    with pytest.raises(FaultSpecError, match="unknown fault kind"):
        faults.describe({"kind": "melt"})
    with pytest.raises(FaultSpecError, match="needs axis"):
        faults.describe({"kind": "drive_fault"})
    with pytest.raises(FaultSpecError, match="one trigger"):
        faults.describe({"kind": "sto", "axis": 1, "at_ms": 1, "after_cycles": 2})
    up()
    with pytest.raises(ParameterError, match="no axis 7"):
        faults.inject("drive_fault", axis=7)
    with pytest.raises(ParameterError, match="nothing follows"):
        faults.inject("link_down", after_slave=1)


def test_faults_show_in_the_trace_and_the_master_log(tmp_path: Path) -> None:
    from gtecat.controller.recorder import Recorder

    log = tmp_path / "Gecat.log"
    assert gt.GT_Open(eni=str(EXAMPLES / "full_servo.eni"), clock="lockstep", log=str(log)) == 0
    assert gt.GT_InitEcatComm() == 0
    assert wait(lambda: ready() == 1, 200)
    rec = Recorder(gt.GTE_Controller(), ["faults"]).start()
    faults.inject("drop_responses", count=0, after_ms=5, duration_ms=10)
    gt.GTE_Wait(30)
    rec.stop()
    seen = rec.column("faults").tolist()
    assert seen[0] == 0 and max(seen) == 1 and seen[-1] == 0
    faults.inject("drive_fault", axis=1, code="overtemperature")
    gt.GTE_Wait(5)
    gt.GT_Close()
    text = log.read_text()
    assert "Fault 1 armed: every answer lost" in text and "Fault 1 started" in text
    assert "Fault 1 ended (over)" in text
    assert "CoE EMERGENCY 0x4310" in text  # the drive's emergency, as the master logs it


def test_homing_interrupted_by_a_link_loss() -> None:
    """The cable goes at the homing's approach stage: while it is out the homing state is
    unknown (1 naming the slave), the axis is in alarm; back, the homing reads failed (5)."""
    from ctypes import c_ushort as u16

    m = EXAMPLES / "homing_probe_machine.toml"
    up("homing_probe.eni", machine=m)
    assert gt.GT_SetHomingMode(1, 6) == 0
    assert gt.GT_SetEcatHomingPrm(1, 3, 20000, 2000, 100000, 0, 0) == 0
    gt.GTE_Wait(10)
    faults.inject("link_down", after_slave=-1, at_homing=[1, "approach"], duration_ms=200)
    assert gt.GT_StartEcatHoming(1) == 0
    hs = u16()
    assert wait(lambda: gt.GT_GetEcatHomingStatus(1, byref(hs)) == 1, 2000)
    assert "homing state is unknown" in gt.GTE_GetLastError()
    assert sts() & ALARM
    assert wait(lambda: gt.GT_GetEcatHomingStatus(1, byref(hs)) == 0 and hs.value == 5, 1000)


def test_a_new_bus_keeps_the_injected_faults_and_ticks_them_once() -> None:
    up()
    faults.inject("drive_fault", axis=1, code=0x2310, at_ms=10**6)
    assert len(faults.listing()) == 1
    assert gt.GT_InitEcatComm() == 0  # a re-initialisation repairs nothing
    assert [(f["id"], f["state"], f["at_ms"]) for f in faults.listing()] == [(1, "armed", 10**6)]
    ctl = gt.GTE_Controller()
    ticks = [f for f in ctl.pre_cycle if type(getattr(f, "__self__", None)).__name__ == "Injector"]
    assert len(ticks) == 1 and ticks[0].__self__.bus.backend is ctl.backend


def test_a_pulled_cable_stays_pulled_through_a_re_initialisation() -> None:
    """GT_InitEcatComm again while a link is down: the cable is still out (the fault stays,
    active, as one armed at once would start once the bus is up); a spent one-shot fault is
    gone, a counted one goes on with what it has left; a new fault gets a new id."""
    up("manual_fig5_2.eni", axes=2)
    faults.inject("power_cycle", slave=3)  # once: over at once
    cut = faults.inject("link_down", after_slave=0)
    drops = faults.inject("drop_responses", count=5, at_ms=10**6)
    gt.GTE_Wait(5)
    n = c_short()
    gt.GT_GetEcatSlaves(byref(n))
    assert n.value == 1
    assert gt.GT_InitEcatComm() == 0
    assert [(f["id"], f["state"]) for f in faults.listing()] == [(cut, "active"), (drops, "armed")]
    gt.GTE_Wait(200)
    gt.GT_GetEcatSlaves(byref(n))
    assert (ready(), n.value) == (0, 1)
    assert sts(2) & ALARM
    assert faults.inject("sto", axis=1) == drops + 1
    assert faults.clear(cut) == 1
    assert wait(lambda: ready() == 1, 500)


def test_a_machine_fault_is_armed_anew_by_a_re_initialisation(tmp_path: Path) -> None:
    """A ``[[fault]]`` table belongs to the bring-up: armed again (not kept and doubled),
    beside an injected fault that is kept."""
    m = tmp_path / "m.toml"
    m.write_text('[[fault]]\nkind = "drive_fault"\naxis = 1\nat_ms = 1000000\nname = "late"\n')
    up(machine=m)
    faults.inject("brake", axis=1, at_ms=2 * 10**6)
    assert [f["kind"] for f in faults.listing()] == ["drive_fault", "brake"]
    assert gt.GT_InitEcatComm() == 0
    assert [(f["id"], f["kind"]) for f in faults.listing()] == [(2, "brake"), (3, "drive_fault")]
