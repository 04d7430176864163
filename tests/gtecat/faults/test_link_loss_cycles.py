"""A link loss cycle by cycle through the GT API, and what the drive reports about it.

Lockstep clock, two drives that map 603Fh (axis 2 is slave 1):

* the master reads the slaves' states in the first cycle whose working counter is short
  (:mod:`gtecat.master.bus`), so from that cycle on everything the application reads
  agrees: ``GT_IsEcatReady`` 0, ``GT_GetEcatSlaves`` the slaves still there, the reads of
  the vanished slave's objects and raw data return 1, its axis shows the alarm with the
  servo off - no window of stale "healthy" reads;
* one lost frame is no loss: in that cycle the reads keep their last values and return 0;
* once the cable is back, the drive whose sync-manager watchdog ran out says why it
  stopped: 603Fh 8130h (CiA 301 life guard / heartbeat error), cleared by the fault reset
  (GT_ClrSts; GT_AxisOn enables afterwards);
* the error register (1001h and the emergency) follows the class of the code (CiA 301).
"""

from __future__ import annotations

from ctypes import byref, c_long, c_short, c_ubyte, c_uint32, c_ushort
from pathlib import Path

import pytest

from gtecat import faults, gt
from gtecat.drives.faults import error_register
from gtecat.eni.topology import load_topology
from gtecat.eni.writer import write_eni_file
from gtecat.gt.bus_calls import _raw_slaves

ALARM, SERVO_ON = 1 << 1, 1 << 9

_SERVO = """
[[slave]]
kind = "servo"
name = "Drive {n}"
rx = ["0x6040:0:16", "0x607A:0:32", "0x6060:0:8", "0x60B8:0:16"]
tx = ["0x603F:0:16", "0x6041:0:16", "0x6064:0:32", "0x6061:0:8", "0x60B9:0:16"]
"""


@pytest.fixture(scope="module")
def eni(tmp_path_factory: pytest.TempPathFactory) -> Path:
    d = tmp_path_factory.mktemp("linkloss")
    topo = d / "two.toml"
    topo.write_text("cycle_time_us = 1000\n" + _SERVO.format(n=0) + _SERVO.format(n=1))
    path = d / "two.eni"
    write_eni_file(load_topology(topo), path)
    return path


def wait(pred, ms: int) -> bool:
    for _ in range(ms):
        if pred():
            return True
        gt.GTE_Wait(1)
    return pred()


def ready() -> int:
    st = c_short()
    assert gt.GT_IsEcatReady(byref(st)) == 0
    return st.value


def sts(axis: int) -> int:
    v = c_long()
    assert gt.GT_GetSts(axis, byref(v)) == 0
    return v.value


def up(eni: Path, log: Path | None = None) -> None:
    assert (
        gt.GT_Open(
            eni=str(eni),
            clock="lockstep",
            log=str(log) if log else "",
        )
        == 0
    )
    assert gt.GT_InitEcatComm() == 0, gt.GTE_GetLastError()
    assert wait(lambda: ready() == 1, 200)
    assert gt.GT_StartEcatComm() == 0
    assert gt.GT_Reset() == 0
    for a in (1, 2):
        assert gt.GT_AxisOn(a) == 0, gt.GTE_GetLastError()
    gt.GTE_Wait(20)


def reads(axis: int, raw_offset: int) -> dict[str, int]:
    """The return codes of the reads an error handler makes."""
    enc, hs, ec, sw, mode = c_long(), c_ushort(), c_ushort(), c_ushort(), c_ushort()
    raw, pos = (c_ubyte * 2)(), (c_ubyte * 4)()
    return {
        "enc": gt.GT_GetEcatEncPos(axis, byref(enc)),
        "homing": gt.GT_GetEcatHomingStatus(axis, byref(hs)),
        "error": gt.GT_GetEcatErrorCode(axis, byref(ec)),
        "raw": gt.GT_GetEcatRawData(raw_offset, 2, raw),
        # the same PDO objects by index, as the vendor demos read them
        "pdo": gt.GT_GetEcatAxisPdoData(axis, 0x6041, byref(sw))
        | gt.GT_GetEcatAxisPdoData(axis, 0x6064, pos) << 1,
        "mode": gt.GT_GetEcatAxisMode(axis, byref(mode)),
    }


def error_code(axis: int) -> int:
    ec = c_ushort()
    assert gt.GT_GetEcatErrorCode(axis, byref(ec)) == 0, gt.GTE_GetLastError()
    return ec.value


def slaves() -> int:
    n = c_short()
    gt.GT_GetEcatSlaves(byref(n))
    return n.value


def test_the_application_sees_the_loss_from_the_first_cycle(eni: Path, tmp_path: Path) -> None:
    log = tmp_path / "Gecat.log"
    up(eni, log)
    image = gt.GTE_Controller().master.image
    offset = next(o for o in range(0, 512, 2) if _raw_slaves(image, o, 2) == [1])
    healthy = {"enc": 0, "homing": 0, "error": 0, "raw": 0, "pdo": 0, "mode": 0}
    lost = {"enc": 1, "homing": 1, "error": 1, "raw": 1, "pdo": 3, "mode": 1}
    assert reads(2, offset) == healthy and sts(2) & SERVO_ON

    # one lost frame: not ready for that cycle, nothing else changes
    faults.inject("drop_responses", count=1)
    gt.GTE_Wait(1)
    assert ready() == 0 and slaves() == 2
    assert reads(2, offset) == healthy
    assert sts(2) & SERVO_ON and not sts(2) & ALARM
    gt.GTE_Wait(1)
    assert ready() == 1

    # the cable behind slave 0 is pulled
    faults.inject("link_down", after_slave=0, duration_ms=300)
    assert reads(2, offset) == healthy  # not yet: no cycle has run since
    for cycle in range(1, 16):
        gt.GTE_Wait(1)
        where = f"cycle {cycle} of the loss"
        assert ready() == 0 and slaves() == 1, where
        assert reads(2, offset) == lost, where
        assert "slave 1" in gt.GTE_GetLastError(), where
        for name, index in (("GT_GetEcatAxisPdoData", 0x6041), ("GT_GetEcatEncPos", 0x6064)):
            args = (2, index, byref(c_ushort())) if "Pdo" in name else (2, byref(c_long()))
            assert getattr(gt, name)(*args) == 1, where
            assert f"slave 1 (Drive 1) does not answer: 0x{index:04X}" in gt.GTE_GetLastError()
        s2 = sts(2)
        assert s2 & ALARM and not s2 & SERVO_ON, where
        assert reads(1, 0) | {"raw": 0} == healthy, where  # slave 0 goes on
        assert sts(1) & SERVO_ON and not sts(1) & ALARM, where

    # the cable is back: the drive says why it stopped (its watchdog ran out)
    assert wait(lambda: ready() == 1, 800)
    assert error_code(2) == 0x8130
    assert sts(2) & ALARM and not sts(2) & SERVO_ON
    assert error_code(1) == 0
    # the fault reset is GT_ClrSts (manual 9.3): GT_AxisOn in FAULT says so and leaves it
    assert gt.GT_AxisOn(2) == 1 and "GT_ClrSts" in gt.GTE_GetLastError()
    assert error_code(2) == 0x8130
    assert gt.GT_ClrSts(2, 1) == 0
    assert error_code(2) == 0  # FAULT -> switch on disabled, 8130h cleared
    assert gt.GT_AxisOn(2) == 0, gt.GTE_GetLastError()
    assert wait(lambda: sts(2) & SERVO_ON and not sts(2) & ALARM, 100)
    gt.GT_Close()
    text = log.read_text()
    assert "CoE EMERGENCY 0x8130 0x11" in text  # generic + communication


def sdo_u8(slave: int, index: int) -> int:
    data = (c_ubyte * 4)()
    size, abort = c_uint32(), c_uint32()
    rc = gt.GT_EcatSDOUpload(slave, index, 0, data, 4, byref(size), byref(abort))
    assert rc == 0, (hex(abort.value), gt.GTE_GetLastError())
    return data[0]


def test_the_error_register_follows_the_class_of_the_code(eni: Path, tmp_path: Path) -> None:
    log = tmp_path / "Gecat.log"
    up(eni, log)
    assert sdo_u8(0, 0x1001) == 0
    expected = {0x2310: 0x03, 0x3210: 0x05, 0x3220: 0x05, 0x4310: 0x09}
    for code, register in expected.items():
        fid = faults.inject("drive_fault", axis=1, code=code)
        assert wait(lambda: sts(1) & ALARM, 50)
        assert error_code(1) == code
        assert sdo_u8(0, 0x1001) == register, hex(code)
        faults.clear(fid)
        assert gt.GT_ClrSts(1, 1) == 0
        assert gt.GT_AxisOn(1) == 0, gt.GTE_GetLastError()
        assert wait(lambda: sts(1) & SERVO_ON and not sts(1) & ALARM, 100)
        assert sdo_u8(0, 0x1001) == 0
    gt.GT_Close()
    text = log.read_text()
    for code, register in expected.items():
        assert f"CoE EMERGENCY 0x{code:04X} 0x{register:02X}" in text


@pytest.mark.parametrize(
    ("code", "register"),
    [
        (0, 0),
        (0x1000, 0x01),
        (0x2310, 0x03),
        (0x3210, 0x05),
        (0x4310, 0x09),
        (0x4410, 0x09),
        (0x7305, 0x01),
        (0x8100, 0x11),
        (0x8130, 0x11),
        (0x8611, 0x01),
        (0xFF10, 0x81),
    ],
)
def test_error_register_classes(code: int, register: int) -> None:
    assert error_register(code) == register


@pytest.fixture(scope="module")
def eni_io(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Two drives and an IO slave behind them."""
    d = tmp_path_factory.mktemp("linkloss_io")
    topo = d / "three.toml"
    topo.write_text(
        "cycle_time_us = 1000\n"
        + _SERVO.format(n=0)
        + _SERVO.format(n=1)
        + '[[slave]]\nkind = "io"\ndo = 8\ndi = 8\n'
    )
    path = d / "three.eni"
    write_eni_file(load_topology(topo), path)
    return path


def counts() -> tuple[int, int, int]:
    """GT_GetEcatSlaves both ways: (online, motion online, IO online)."""
    n, motion, io = c_short(), c_short(), c_short()
    assert gt.GT_GetEcatSlaves(byref(n)) == 0
    assert gt.GT_GetEcatSlaves(byref(motion), byref(io)) == 0
    return n.value, motion.value, io.value


def test_slave_counts_and_emergencies_follow_the_link(eni_io: Path, tmp_path: Path) -> None:
    """Both forms of GT_GetEcatSlaves count the slaves online (manual entry 45), split or not;
    an emergency a drive raises behind the cut arrives once the cable is back."""
    up(eni_io)
    master = gt.GTE_Controller().master
    assert counts() == (3, 2, 1)
    faults.inject("link_down", after_slave=0, duration_ms=300)
    # no cycle since the cut: nothing shows it yet, the count no more than the rest
    assert counts() == (3, 2, 1) and ready() == 1 and not sts(2) & ALARM
    gt.GTE_Wait(1)
    assert counts() == (1, 1, 0) and ready() == 0 and sts(2) & ALARM
    # drive 1's watchdog runs out (about 100 ms): its 8130h waits behind the cut
    assert wait(lambda: error_code(1) == 0 and master.backend.slaves[1].emergencies, 200)
    assert master.emergency_count == 0 and counts() == (1, 1, 0)
    assert wait(lambda: ready() == 1, 400)
    assert master.emergency_count == 1 and not master.backend.slaves[1].emergencies
    assert error_code(2) == 0x8130 and counts() == (3, 2, 1)
    faults.inject("link_down", after_slave=-1, duration_ms=50)  # the cable at the master
    gt.GTE_Wait(1)
    assert counts() == (0, 0, 0) and ready() == 0
    # link faults overlap: each one's end mends only its own cut
    faults.inject("link_down", after_slave=1, duration_ms=100)
    gt.GTE_Wait(1)
    assert counts() == (0, 0, 0)
    assert wait(lambda: counts() == (2, 2, 0), 60)  # the first is over, the second is not
    gt.GTE_Wait(20)
    assert counts() == (2, 2, 0)
    assert wait(lambda: counts() == (3, 2, 1), 60)
