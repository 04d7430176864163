"""Switch and encoder faults against the drive's own homing, the controller's smart homing
and the drive's position loop, through the GT API as a user's program meets them.

What a switch reads is one signal (60FDh): a home switch stuck inactive gives CiA 402
homing method 3 no edge, so the search runs into the positive limit and ends in a homing
error (GT_GetEcatHomingStatus 5); stuck active, the method starts as on the switch, heads
for the edge that leaves it and meets the negative limit instead; a chattering one homes on
the first edge the drive sees.  A negative limit stuck inactive is never found by method 1:
the search ends at its travel bound; a positive limit stuck active stops method 1 as soon as it
turns back toward it (a limit is a level).  The controller's smart homing (GT_GoHome) on an
EtherCAT axis and on a GTS card sees the same.  Counts an encoder loses move the drive's
measured position for good: 60F4h shows the error at once, and beyond 6065h for longer
than 6066h the drive faults with 8611h.  The axis bank gives such axes back to the scalar
drive: the same session with and without it ends alike.

Machine (drive counts): limits at -20000 / +20000, a "positive" home switch from 5000 up,
an index pulse at 300 + 1000k.  Healthy method 3 from 0 homes on the index left of 5000
(4300), method 1 on the first index right of -20000 (-19700).
"""

from __future__ import annotations

from ctypes import byref, c_double, c_long, c_short, c_uint32, c_ushort
from pathlib import Path

import pytest

from gtecat import faults, gt
from gtecat.drives.machine import AxisMachine, MachineDescription
from tests.conftest import EXAMPLES

ALARM = 1 << 1
HOMING_DONE, HOMING_FAILED = 3, 5

MACHINE = """
[axis.1]
position = 0
counts_per_rev = 1000
negative_limit = -20000
positive_limit = 20000
home_switch = [[5000, 20000]]
index_offset = 300
following_error_window = 10000
"""


@pytest.fixture(scope="module")
def machine(tmp_path_factory: pytest.TempPathFactory) -> Path:
    p = tmp_path_factory.mktemp("switches") / "machine.toml"
    p.write_text(MACHINE)
    return p


@pytest.fixture(autouse=True)
def _closed():
    gt.GT_Close()
    yield
    gt.GT_Close()


def up(machine: Path, eni: str = "homing_probe.eni", bank: str = "auto") -> None:
    gt.GT_Close()
    opts = dict(clock="lockstep", log="", machine=str(machine), bank=bank)
    assert gt.GT_Open(eni=str(EXAMPLES / eni), **opts) == 0
    assert gt.GT_InitEcatComm() == 0, gt.GTE_GetLastError()
    st = c_short()
    for _ in range(300):
        if gt.GT_IsEcatReady(byref(st)) == 0 and st.value == 1:
            break
        gt.GTE_Wait(1)
    assert gt.GT_StartEcatComm() == 0
    assert gt.GT_Reset() == 0
    assert gt.GT_AxisOn(1) == 0, gt.GTE_GetLastError()
    gt.GTE_Wait(10)


def machine_pos() -> float:
    m = c_double()
    assert gt.GTE_GetMachinePos(1, byref(m)) == 0
    return m.value


def pdo(index: int) -> int:
    """A 32-bit (or smaller) object of the axis's PDO, signed."""
    v = c_uint32()
    assert gt.GT_GetEcatAxisPdoData(1, index, byref(v)) == 0, gt.GTE_GetLastError()
    x = v.value
    return x - (1 << 32) if x & (1 << 31) else x


def drive_homing(method: int, timeout_ms: int = 6000) -> int:
    """Homing mode 6, 6099h:01 50000 / :02 20000 counts/s, 609Ah 500000 counts/s² (within
    what the motor can do at 1000 counts a revolution): the final status."""
    assert gt.GT_SetHomingMode(1, 6) == 0, gt.GTE_GetLastError()
    assert gt.GT_SetEcatHomingPrm(1, method, 50000, 20000, 500000, 0, 0) == 0
    assert gt.GT_StartEcatHoming(1) == 0, gt.GTE_GetLastError()
    h = c_short()
    for _ in range(timeout_ms // 10):
        gt.GTE_Wait(10)
        assert gt.GT_GetEcatHomingStatus(1, byref(h)) == 0
        if h.value in (HOMING_DONE, HOMING_FAILED):
            return h.value
    return h.value


# --- the drive's homing (6060h = 6) -------------------------------------------------------------
@pytest.mark.parametrize(
    ("fault", "method", "status", "where"),
    [
        (None, 3, HOMING_DONE, lambda x: x == pytest.approx(4300, abs=1)),
        ({"switch": "home", "value": 0}, 3, HOMING_FAILED, lambda x: x >= 20000),
        ({"switch": "home", "value": 1}, 3, HOMING_FAILED, lambda x: x <= -20000),
        (None, 1, HOMING_DONE, lambda x: x == pytest.approx(-19700, abs=1)),
        ({"switch": "negative", "value": 0}, 1, HOMING_FAILED, lambda x: x < -60000),
        # behind the axis while it heads for the negative limit, then ahead of it once
        # method 1 turns back for the index pulse: a held limit input stops the search there
        ({"switch": "positive", "value": 1}, 1, HOMING_FAILED, lambda x: -23000 < x < -19000),
    ],
    ids=[
        "healthy-3",
        "home-stuck-off",
        "home-stuck-on",
        "healthy-1",
        "negative-limit-stuck-off",
        "positive-limit-stuck-on-behind",
    ],
)
def test_the_drive_homing_reads_the_switches_as_60fd_shows_them(
    machine: Path, fault, method, status, where
) -> None:
    up(machine)
    if fault:
        faults.inject("switch_stuck", axis=1, **fault)
        gt.GTE_Wait(2)
    assert drive_homing(method) == status, gt.GTE_GetLastError()
    assert where(machine_pos())
    sw = pdo(0x6041)
    assert bool(sw & (1 << 13)) == (status == HOMING_FAILED)  # SW13 homing error


def test_a_chattering_home_switch_homes_on_the_first_edge_the_drive_sees(machine: Path) -> None:
    up(machine)
    faults.inject("switch_chatter", axis=1, switch="home", period_cycles=40)
    assert drive_homing(3) == HOMING_DONE
    x = machine_pos()
    assert x != pytest.approx(4300, abs=1)  # not the machine's switch edge
    off = (x - 300) % 1000
    assert min(off, 1000 - off) <= 1  # on an index pulse (the drive's position window)


# --- the controller's smart homing (GT_GoHome) -------------------------------------------------
def go_home(search: int) -> gt.THomeStatus:
    prm = gt.THomePrm()
    assert gt.GT_GetHomePrm(1, byref(prm)) == 0
    prm.mode, prm.moveDir, prm.triggerIndex, prm.edge = 20, 1, -1, 0
    prm.velHigh, prm.velLow, prm.acc, prm.dec = 80, 8, 4, 4
    prm.homeOffset, prm.searchHomeDistance = 500, search
    assert gt.GT_PrfTrap(1) == 0
    assert gt.GT_GoHome(1, byref(prm)) == 0, gt.GTE_GetLastError()
    st = gt.THomeStatus()
    for _ in range(3000):
        assert gt.GT_GetHomeStatus(1, byref(st)) == 0
        if not st.run:
            break
        gt.GTE_Wait(1)
    return st


@pytest.mark.parametrize("stuck", [None, 0], ids=["healthy", "home-stuck-off"])
@pytest.mark.parametrize("where", ["ethercat", "card"])
def test_smart_homing_reads_the_faulted_home_switch(machine: Path, where, stuck) -> None:
    if where == "card":
        desc = MachineDescription(
            {1: AxisMachine(counts_per_rev=1000, index_offset=300, negative_limit=-20000,
                            positive_limit=20000, home_switch=((5000, 20000),))}
        )  # fmt: skip
        assert gt.GT_Open(card="gts:1", machine=desc, clock="lockstep", log="") == 0
        assert gt.GT_AxisOn(1) == 0
    else:
        up(machine)
    if stuck is not None:
        faults.inject("switch_stuck", axis=1, switch="home", value=stuck)
    gt.GTE_Wait(2)
    st = go_home(search=10000)
    if stuck is None:
        assert (st.error, st.stage) == (gt.HOME_ERROR_NONE, gt.HOME_STAGE_END)
        # a card latches the edge, an EtherCAT axis samples 60FDh: half a cycle at velHigh
        assert st.capturePos == pytest.approx(5000, abs=1 if where == "card" else 41)
    else:
        assert st.error == gt.HOME_ERROR_NO_HOME
        assert machine_pos() > 6000  # searched on, past the machine's switch


def test_the_older_gt_home_of_a_card_reads_it_too() -> None:
    desc = MachineDescription(
        {1: AxisMachine(negative_limit=-20000, positive_limit=20000, home_switch=((5000, 20000),))}
    )
    assert gt.GT_Open(card="gts:1", machine=desc, clock="lockstep", log="") == 0
    assert gt.GT_AxisOn(1) == 0
    faults.inject("switch_stuck", axis=1, switch="home", value=0)
    gt.GTE_Wait(2)
    assert gt.GT_Home(1, 10000, 80, 4, 0) == 0, gt.GTE_GetLastError()
    sts = c_short()
    for _ in range(1000):
        rc = gt.GT_HomeSts(1, byref(sts))
        if rc or sts.value:
            break
        gt.GTE_Wait(1)
    assert (rc, sts.value) == (1, 0)  # failed: no home before the end of the search
    assert machine_pos() > 6000


# --- the encoder ---------------------------------------------------------------------------------
def test_counts_lost_beyond_the_window_show_in_60f4_and_fault_the_drive_8611(
    machine: Path,
) -> None:
    up(machine, eni="full_servo.eni")
    enc0 = pdo(0x6064)
    faults.inject("encoder_lost", axis=1, counts=40000)
    gt.GTE_Wait(1)
    assert pdo(0x6064) == pytest.approx(enc0 - 40000, abs=100)
    assert pdo(0x60F4) == pytest.approx(40000, abs=100)  # demand - actual: the drive sees it
    gt.GTE_Wait(30)
    code = c_ushort()
    assert gt.GT_GetEcatErrorCode(1, byref(code)) == 0
    assert code.value == 0x8611
    sts = c_long()
    gt.GT_GetSts(1, byref(sts))
    assert sts.value & ALARM
    # the counts stay lost: the fault reset brings the drive back, not the counts
    assert gt.GT_ClrSts(1) == 0
    assert gt.GT_AxisOn(1) == 0, gt.GTE_GetLastError()
    gt.GTE_Wait(20)
    assert pdo(0x6064) - round(machine_pos()) == enc0 - 40000


def test_encoder_noise_reaches_60f4_as_it_reaches_6064(machine: Path) -> None:
    up(machine, eni="full_servo.eni")
    faults.inject("encoder_noise", axis=1, counts=50)
    seen = set()
    for _ in range(10):
        gt.GTE_Wait(1)
        actual, error, target = pdo(0x6064), pdo(0x60F4), pdo(0x607A)
        assert error == target - actual  # 60F4h = demand - actual, from the same reading
        seen.add(error)
    assert len(seen) > 3


# --- the axis bank hands the faulted axes to the scalar drive --------------------------------
def _session(machine: Path, bank: str) -> tuple:
    up(machine, bank=bank)
    faults.inject("switch_chatter", axis=1, switch="home", period_cycles=40, after_cycles=30)
    status = drive_homing(3)
    where = machine_pos()
    assert gt.GT_SetHomingMode(1, 8) == 0, gt.GTE_GetLastError()
    faults.clear()
    faults.inject("encoder_lost", axis=1, counts=300, after_cycles=25)
    gt.GTE_Wait(60)
    return status, where, pdo(0x6064), machine_pos()


def test_with_and_without_the_axis_bank_alike(machine: Path) -> None:
    assert _session(machine, "auto") == _session(machine, "off")


@pytest.mark.parametrize("method", [1, 17])
def test_a_chattering_limit_behind_the_search_is_not_met(machine: Path, method: int) -> None:
    """Methods 1 and 17 search negative from 0: the positive limit lies behind them, so its
    edges, forced while the search runs away from it, stop nothing (as outside homing)."""
    up(machine)
    faults.inject("switch_chatter", axis=1, switch="positive", period_cycles=7, duration_ms=200)
    assert drive_homing(method) == HOMING_DONE, gt.GTE_GetLastError()
    assert machine_pos() == pytest.approx(-19700 if method == 1 else -20000, abs=1)
