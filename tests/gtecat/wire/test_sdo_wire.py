"""An SDO on the wire: the cycles run while it waits, and its failures carry the emulated
bus's abort codes.

pysoem (through gtecat's pysoem backend and the GT API, realtime clock) on one end of a veth
pair, ``gtecat serve --sm-watchdog`` with ``[[fault]]`` tables on the other.  While
``GT_EcatSDOUpload`` waits for an answer the slave never sends (the master's mailbox timeout,
700 ms), the cyclic exchange goes on as in a real controller's firmware: ``GT_GetClock``
counts the cycles that ran, an axis in a Trap move keeps moving, and the drive's sync
manager watchdog stays fed (no alarm).  ``pAbort_code`` is what the emulated bus gives for
the same fault: 05040000h for a lost answer, 08000000h for a protocol fault, the slave's
code for an abort.  Needs root and pysoem (skipped with the reason).
"""

from __future__ import annotations

import contextlib
import time
from collections.abc import Iterator
from ctypes import byref, c_double, c_long, c_ubyte, c_uint32
from pathlib import Path

import pytest

from tests.conftest import EXAMPLES, LONG
from tests.gtecat import scenario_common
from tests.gtecat.master.backends import test_pysoem_veth as pv  # (skips itself)

pytestmark = [pytest.mark.wire]

veth = pv.veth
frame_timeout_for_a_python_slave = pv.frame_timeout_for_a_python_slave

ENI = EXAMPLES / "manual_fig5_2.eni"
VEL = 20.0  # counts per ms
TIMED_OUT, GENERAL_ERROR, OUT_OF_RANGE = 0x05040000, 0x08000000, 0x06090030
ALARM = 1 << 1

#: one fault per object, each for the first SDO to it (none of them is touched at bring-up)
FAULTS = f"""
[[fault]]
kind = "mailbox_lost"
slave = 0
index = 0x6067
[[fault]]
kind = "mailbox_protocol"
slave = 0
index = 0x6068
variant = "short"
[[fault]]
kind = "mailbox_protocol"
slave = 0
index = 0x6066
variant = "wrong_service"
[[fault]]
kind = "mailbox_abort"
slave = 0
index = 0x6065
code = {OUT_OF_RANGE}
[[fault]]
kind = "mailbox_protocol"
slave = 1
index = 0x6068
[[fault]]
kind = "mailbox_lost"
slave = 1
index = 0x6067
"""


def _clock(gt) -> int:
    c = c_long()
    gt.GT_GetClock(byref(c))
    return c.value


def _enc(gt, axis: int) -> float:
    v = c_double()
    assert gt.GT_GetEncPos(axis, byref(v)) == 0, gt.GTE_GetLastError()
    return v.value


def _sts(gt, axis: int) -> int:
    s = c_long()
    assert gt.GT_GetSts(axis, byref(s)) == 0
    return s.value


def _upload(gt, slave: int, index: int) -> tuple[int, int, str]:
    data, size, abort = (c_ubyte * 4)(), c_uint32(), c_uint32(0xDEADBEEF)
    rc = gt.GT_EcatSDOUpload(slave, index, 0, data, 4, byref(size), byref(abort))
    return rc, abort.value, gt.GTE_GetLastError()


def _download(gt, slave: int, index: int) -> tuple[int, int, str]:
    data, abort = (c_ubyte * 4)(100), c_uint32(0xDEADBEEF)
    rc = gt.GT_EcatSDODownload(slave, index, 0, data, 4, byref(abort))
    return rc, abort.value, gt.GTE_GetLastError()


@contextlib.contextmanager
def _bus(veth, tmp_path: Path, clock: str) -> Iterator[object]:
    """``gtecat serve --sm-watchdog --fault`` on the slave end; the GT API on pysoem with
    ``clock``, up and in OP, axis 1 on and in a Trap move at :data:`VEL`."""
    from gtecat import gt

    faults = tmp_path / "faults.toml"
    faults.write_text(FAULTS)
    r = pv.Runner(ENI, veth[1])
    r.args += ["--sm-watchdog", "--fault", str(faults)]
    r.start()
    gt.GT_Close()
    try:
        assert gt.GT_Open(eni=str(ENI), backend="pysoem", iface=veth[0], clock=clock, log="") == 0
        up: dict = {}
        assert scenario_common.bring_up(gt, up), (up, gt.GTE_GetLastError())
        assert gt.GT_AxisOn(1) == 0, gt.GTE_GetLastError()
        prm = gt.TTrapPrm()
        assert gt.GT_PrfTrap(1) == 0 and gt.GT_GetTrapPrm(1, byref(prm)) == 0
        prm.acc, prm.dec, prm.smoothTime = 1.0, 1.0, 0
        assert gt.GT_SetTrapPrm(1, byref(prm)) == 0
        assert gt.GT_SetPos(1, round(_enc(gt, 1)) + 10_000_000) == 0
        assert gt.GT_SetVel(1, VEL) == 0 and gt.GT_Update(1) == 0, gt.GTE_GetLastError()
        gt.GTE_Wait(100)  # at speed (20 ms of acceleration)
        yield gt
    finally:
        gt.GT_Close()
        proc = r.proc
        r.stop()
        if proc is not None and proc.stdout is not None:
            print(proc.stdout.read())  # the serve's own lines (its faults), shown on a failure


@pytest.fixture
def wire(veth, tmp_path: Path) -> Iterator[object]:
    """:func:`_bus` in the realtime clock (the default on pysoem)."""
    with _bus(veth, tmp_path, "realtime") as gt:
        yield gt


def _lost_answer_runs_the_cycles(gt, slave: int = 0, *, paced: bool = True) -> None:
    """An SDO whose answer is lost: 05040000h after the mailbox timeout, during which the
    cycles ran (the clock counts them) and the axis moved with them, the watchdog fed.
    ``paced``: the cycles before ran on the wall clock too (realtime), so the drive's lag
    behind its targets is the same before and after; in virtual time they ran faster than
    the drive moves, and it catches up while the SDO waits."""
    c0, e0, w0 = _clock(gt), _enc(gt, 1), time.monotonic()
    rc, abort, why = _upload(gt, slave, 0x6067)
    wall_ms = (time.monotonic() - w0) * 1000
    ran, moved = _clock(gt) - c0, _enc(gt, 1) - e0
    assert rc == 1 and abort == TIMED_OUT, why
    assert "no answer within the mailbox timeout (700 ms)" in why
    assert 650 <= wall_ms < 3000, wall_ms
    # the clock counts the cycles that really ran: all of them on a quiet machine (the
    # realtime clock skips the periods a late cycle overran, as it does in a plain wait; a
    # loaded machine makes many late, so the check is that they ran, not how fast: held
    # during the SDO, none would)
    assert ran >= 0.25 * wall_ms, (ran, wall_ms)
    # ... and the axis moved with them
    if paced:  # (a loaded machine delays some frames of the serve's drive: it lags a little)
        assert 0.6 * VEL * ran - 3 * VEL <= moved <= 1.1 * VEL * ran + 3 * VEL, (moved, ran)
    else:
        assert moved >= 0.9 * VEL * ran, (moved, ran)
    gt.GTE_Wait(20)
    assert not _sts(gt, 1) & ALARM, "the drive's SM watchdog ran out: process data stopped"
    # the next SDO to the same slave is answered
    assert _upload(gt, slave, 0x6067)[:2] == (0, 0)


def test_cycles_run_while_an_sdo_waits_and_the_codes_are_the_emulated_ones(wire) -> None:
    gt = wire
    assert not _sts(gt, 1) & ALARM
    _lost_answer_runs_the_cycles(gt)
    # protocol faults (an SDO response with no SDO in it, another CoE service's answer)
    # and an abort: their codes, at once
    for index in (0x6068, 0x6066):
        w0 = time.monotonic()
        rc, abort, why = _upload(gt, 0, index)
        assert rc == 1 and abort == GENERAL_ERROR, why
        assert time.monotonic() - w0 < 0.5
        assert _upload(gt, 0, index)[:2] == (0, 0)
    rc, abort, why = _upload(gt, 0, 0x6065)
    assert rc == 1 and abort == OUT_OF_RANGE, why
    assert _download(gt, 0, 0x6065)[:2] == (0, 0)
    assert not _sts(gt, 1) & ALARM


@pytest.mark.skipif(not LONG, reason="two more mailbox timeouts on the wire (GTECAT_LONG=1)")
def test_a_mailbox_error_reply_and_a_lost_download_answer(wire) -> None:
    """A mailbox error reply is 08000000h; SOEM reads the mailbox for its whole timeout after
    one (the slave repeats its reply on each repeat request), and the next SDO is answered
    all the same.  A download whose answer is lost: 05040000h after the timeout, the cycles
    running."""
    gt = wire
    rc, abort, why = _upload(gt, 1, 0x6068)
    assert rc == 1 and abort == GENERAL_ERROR, why
    assert "mailbox error" in why
    assert _upload(gt, 1, 0x6068)[:2] == (0, 0)
    c0, e0 = _clock(gt), _enc(gt, 1)
    rc, abort, why = _download(gt, 1, 0x6067)
    assert rc == 1 and abort == TIMED_OUT, why
    ran = _clock(gt) - c0
    assert ran >= 350 and _enc(gt, 1) - e0 == pytest.approx(VEL * ran, rel=0.1, abs=3 * VEL)
    assert _download(gt, 1, 0x6067)[:2] == (0, 0)
    assert not _sts(gt, 1) & ALARM


@pytest.mark.skipif(not LONG, reason="one more bus on the wire (GTECAT_LONG=1)")
@pytest.mark.parametrize("clock", ["lockstep", "auto"])
def test_virtual_clocks_run_the_cycles_while_an_sdo_waits_too(veth, tmp_path, clock) -> None:
    """In lockstep and auto the call itself runs them, one per bus cycle of wall time (no
    call, no cycle: a script that stops calling starves the slaves' watchdogs, as any
    lockstep script on a wire does)."""
    with _bus(veth, tmp_path, clock) as gt:
        _lost_answer_runs_the_cycles(gt, paced=False)


def test_the_emulated_bus_gives_the_same_codes() -> None:
    """The same faults on the emulated bus: the codes the wire test expects."""
    from gtecat import faults, gt

    gt.GT_Close()
    assert gt.GT_Open(eni=str(ENI), clock="lockstep", log="") == 0
    try:
        assert gt.GT_InitEcatComm() == 0
        faults.inject("mailbox_lost", slave=0, index=0x6067)
        faults.inject("mailbox_protocol", slave=0, index=0x6068, variant="short")
        faults.inject("mailbox_protocol", slave=0, index=0x6066, variant="wrong_service")
        faults.inject("mailbox_protocol", slave=1, index=0x6068)
        faults.inject("mailbox_abort", slave=0, index=0x6065, code=OUT_OF_RANGE)
        c0 = _clock(gt)
        assert _upload(gt, 0, 0x6067)[:2] == (1, TIMED_OUT)
        assert _clock(gt) - c0 == 700
        assert _upload(gt, 0, 0x6068)[:2] == (1, GENERAL_ERROR)
        assert _upload(gt, 0, 0x6066)[:2] == (1, GENERAL_ERROR)
        assert _upload(gt, 1, 0x6068)[:2] == (1, GENERAL_ERROR)
        assert _upload(gt, 0, 0x6065)[:2] == (1, OUT_OF_RANGE)
    finally:
        gt.GT_Close()
