"""The same fault objects on the wire: ``gtecat serve --fault FILE`` against a real master.

pysoem (SOEM, through gtecat's pysoem backend and the GT API in the realtime clock) on one
end of a veth pair, ``gtecat serve`` with ``[[fault]]`` tables on the other: a mailbox abort
a lost mailbox answer and a protocol fault reach the SDO calls, a link down after slave 1
takes slaves 2 and 3 out of the process data (GT_IsEcatReady 0, their IO calls refused) until
its time is over, a working counter off by one makes GT_IsEcatReady 0 while it lasts, and a
latched AL error keeps slave 3 out until it is cleared, a power-cycled slave 2 (its ESC
without address or configuration) is found and brought back, 30 lost answers make a dip,
and so do answers cut short, with a wrong index, replayed or late; a slave that retreats to
SAFEOP is brought back: one script of steps.  Needs
root and pysoem (skipped with the reason); several seconds of two processes, so it runs with
GTECAT_LONG=1.
"""

from __future__ import annotations

from ctypes import byref, c_short, c_ubyte, c_uint32
from pathlib import Path

import pytest

from tests.conftest import EXAMPLES, LONG
from tests.gtecat import scenario_common

pytestmark = [pytest.mark.wire]

if not LONG:
    pytest.skip("two processes for several seconds (GTECAT_LONG=1)", allow_module_level=True)

from tests.gtecat.master.backends import test_pysoem_veth as pv  # noqa: E402  (skips itself)

veth = pv.veth
frame_timeout_for_a_python_slave = pv.frame_timeout_for_a_python_slave

FAULTS = """
[[fault]]
kind = "mailbox_abort"
slave = 0
index = 0x6060
code = 0x06090030
[[fault]]
kind = "mailbox_lost"
slave = 0
index = 0x6061
[[fault]]
kind = "mailbox_protocol"
slave = 1
index = 0x6061
variant = "wrong_service"
[[fault]]
kind = "link_down"
after_slave = 1
after_cycles = 1500
duration_ms = 1500
name = "cut"
[[fault]]
kind = "wkc_offset"
offset = -1
command = "LRW"
after = "cut"
after_ms = 4000
duration_ms = 600
name = "wkc"
[[fault]]
kind = "al_error"
slave = 3
code = 0x1B
after = "wkc"
after_ms = 3000
duration_ms = 1000
name = "al"
[[fault]]
kind = "power_cycle"
slave = 2
after = "al"
after_ms = 4000
name = "power"
[[fault]]
kind = "drop_responses"
count = 30
after = "power"
after_ms = 5000
name = "drops"
[[fault]]
kind = "frame_truncate"
bytes = 8
count = 30
after = "drops"
after_ms = 3000
name = "cut_short"
[[fault]]
kind = "frame_wrong_index"
count = 30
after = "cut_short"
after_ms = 3000
name = "wrong_index"
[[fault]]
kind = "frame_replay"
count = 30
after = "wrong_index"
after_ms = 3000
name = "replayed"
[[fault]]
kind = "frame_delay"
us = 40000
count = 5
after = "replayed"
after_ms = 3000
name = "late"
[[fault]]
kind = "retreat_safeop"
slave = 2
code = 0x1B
after = "late"
after_ms = 1500
"""


def _ready(gt) -> int:
    st = c_short()
    gt.GT_IsEcatReady(byref(st))
    return st.value


def test_faults_on_the_wire(veth, tmp_path: Path) -> None:
    from gtecat import gt

    faults = tmp_path / "faults.toml"
    faults.write_text(FAULTS)
    r = pv.Runner(EXAMPLES / "manual_fig5_2.eni", veth[1])
    r.args += ["--fault", str(faults)]
    r.start()
    try:
        assert (
            gt.GT_Open(
                eni=str(EXAMPLES / "manual_fig5_2.eni"),
                backend="pysoem",
                iface=veth[0],
                clock="realtime",
            )
            == 0
        )
        assert gt.GT_InitEcatComm() == 0, gt.GTE_GetLastError()
        assert scenario_common.wait_until(gt, lambda: _ready(gt) == 1, ms=5000, step_ms=5)
        data, size, abort = (c_ubyte * 4)(), c_uint32(), c_uint32()
        rc = gt.GT_EcatSDOUpload(0, 0x6060, 0, data, 4, byref(size), byref(abort))
        assert rc != 0 and abort.value == 0x06090030, gt.GTE_GetLastError()
        assert gt.GT_EcatSDOUpload(0, 0x6060, 0, data, 4, byref(size), byref(abort)) == 0
        rc = gt.GT_EcatSDOUpload(0, 0x6061, 0, data, 4, byref(size), byref(abort))
        assert rc != 0, "a lost answer is an error"
        rc = gt.GT_EcatSDOUpload(1, 0x6061, 0, data, 4, byref(size), byref(abort))
        assert rc != 0, "a protocol fault is an error"
        assert scenario_common.wait_until(gt, lambda: _ready(gt) == 0, ms=5000, step_ms=5)
        buf = (c_ubyte * 2)()
        assert scenario_common.wait_until(
            gt, lambda: gt.GT_EcatIOReadInput(2, 0, 2, buf) == 1, ms=2000, step_ms=5
        )
        assert scenario_common.wait_until(gt, lambda: _ready(gt) == 1, ms=8000, step_ms=10)
        assert gt.GT_EcatIOReadInput(2, 0, 2, buf) == 0
        # the working counter off by one: not ready while it lasts, then ready again
        assert scenario_common.wait_until(gt, lambda: _ready(gt) == 0, ms=8000, step_ms=5)
        assert scenario_common.wait_until(gt, lambda: _ready(gt) == 1, ms=8000, step_ms=10)
        # slave 3 latches AL status 001Bh: out of OP, the recovery refused until it is over
        assert scenario_common.wait_until(gt, lambda: _ready(gt) == 0, ms=8000, step_ms=5)
        assert scenario_common.wait_until(
            gt, lambda: gt.GT_EcatIOReadInput(3, 0, 2, buf) == 1, ms=3000, step_ms=5
        )
        assert "slave 3" in gt.GTE_GetLastError()
        assert scenario_common.wait_until(gt, lambda: _ready(gt) == 1, ms=10000, step_ms=10)
        # slave 2 power-cycled: its ESC forgot its address and configuration; the master
        # finds it in INIT and brings it back
        assert scenario_common.wait_until(gt, lambda: _ready(gt) == 0, ms=8000, step_ms=5)
        assert scenario_common.wait_until(gt, lambda: _ready(gt) == 1, ms=15000, step_ms=10)
        # 30 cyclic answers lost: a dip, then the bus goes on by itself
        assert scenario_common.wait_until(gt, lambda: _ready(gt) == 0, ms=10000, step_ms=2)
        assert scenario_common.wait_until(gt, lambda: _ready(gt) == 1, ms=10000, step_ms=10)
        # frame faults: 30 answers cut short, 30 with another datagram index, 30 replays of
        # the previous answer, 5 answers 40 ms late (past SOEM's wait): SOEM takes none of
        # them for the cycle's answer; each is a run of bad working counters in the master
        # log, and the bus goes on by itself
        ctl = gt.GTE_Controller()
        frame_faults_from = len(ctl.log.lines)
        for what in ("cut short", "wrong index", "replayed", "late"):
            seen = len(ctl.log.lines)

            def back(seen: int = seen) -> bool:
                return any("Working counter back to 12/12" in x for x in ctl.log.lines[seen:])

            assert scenario_common.wait_until(gt, back, ms=8000, step_ms=5), what
            assert scenario_common.wait_until(gt, lambda: _ready(gt) == 1, ms=8000, step_ms=10)
        # slave 2 leaves OP for SAFEOP by itself (AL status 001Bh): the master sees it leave
        # (the working counter, its AL status) and brings it back into the process data (it
        # comes 1.5 s after the late answers: perhaps before their check above has ended)
        seen = frame_faults_from

        def since() -> str:
            return "\n".join(ctl.log.lines[seen:])

        assert scenario_common.wait_until(
            gt, lambda: "Back in process data: slaves 2" in since(), ms=10000, step_ms=5
        ), since()
        assert "slave 2 (IO 2) SAFEOP+ERROR, AL status 0x001B" in since()
        assert scenario_common.wait_until(gt, lambda: _ready(gt) == 1, ms=10000, step_ms=10)
        assert gt.GT_EcatIOReadInput(2, 0, 2, buf) == 0
        assert "internal error" not in ctl.log.text()
    finally:
        gt.GT_Close()
        proc = r.proc
        r.stop()
        if proc is not None and proc.stdout is not None:
            print(proc.stdout.read())  # the serve's own lines (its faults), shown on a failure
