"""``gtecat serve`` publishes an inspection endpoint: ``gtecat ps`` lists it, ``gtecat fault
inject|list|clear --attach ID`` breaks its chain at runtime while a real master (SOEM through
pysoem) runs it in OP, and the master sees each fault (working counters, SDO abort codes)
and the recovery once it is cleared.

One veth pair and one ``gtecat serve`` for the module (a private runtime folder); the CLI
verbs run in this process.  Skipped, with the reason, without root, ``ip`` or pysoem.
Every wait is bounded.
"""

from __future__ import annotations

import contextlib
import importlib.util
import json
import socket
import threading
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from gtecat.cli.main import main
from gtecat.errors import BusError
from gtecat.inspect.client import Attached
from tests.gtecat.wire.rawmaster import SOEM_DEFAULT_FRAME_US, SOEM_FRAME_US, patient_soem
from tests.gtecat.wire.test_serve_veth import FIG52, Server, cycle, soem, to_op, veth_pair

pytestmark = [pytest.mark.wire, pytest.mark.xdist_group("serve_attach")]

#: figure 5-2: four slaves, each with outputs and inputs (LRW: 3 per slave)
EXPECTED_WKC = 12


def rig_stop(server: Server) -> int:
    """Stop the serve once (its output kept in ``server.output``); its exit code."""
    if server.proc.returncode is None:
        server.stop()
    return server.proc.returncode


class Rig:
    def __init__(self, server: Server, master: object, run: Path) -> None:
        self.server, self.master, self.run = server, master, run
        self.id = str(server.proc.pid)

    def cli(self, capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
        rc = main([*argv, "--attach", self.id])
        out = capsys.readouterr()
        return rc, out.out, out.err

    def cycles(self, n: int, timeout_us: int = SOEM_FRAME_US) -> list[int]:
        out = []
        for _ in range(n):
            self.master.send_processdata()  # type: ignore[attr-defined]
            out.append(self.master.receive_processdata(timeout_us))  # type: ignore[attr-defined]
        return out

    def cycle_until(self, wkc: int, seconds: float = 5.0) -> bool:
        deadline = time.monotonic() + seconds
        while time.monotonic() < deadline:
            if self.cycles(1)[0] == wkc:
                return True
        return False

    def log(self) -> list[str]:
        with Attached(self.run / f"{self.id}.sock") as c:
            return c.call("log")["lines"]


@contextlib.contextmanager
def serve_rig(tmp: Path) -> Iterator[tuple[str, str, Path]]:
    """A veth pair (master end, slave end) and a private runtime folder whose endpoints are
    published (the test run's default is GTECAT_INSPECT=0); SOEM gives a frame
    :data:`~tests.gtecat.wire.rawmaster.SOEM_FRAME_US`, not 2 ms, before it sends it again or
    counts it lost: a Python serve on a loaded test machine answers late now and then."""
    xdg = tmp / "xdg"
    xdg.mkdir(mode=0o700)
    with (
        pytest.MonkeyPatch.context() as mp,
        veth_pair() as (master_if, slave_if),
        patient_soem(),
    ):
        mp.setenv("XDG_RUNTIME_DIR", str(xdg))
        mp.setenv("GTECAT_INSPECT", "1")
        yield master_if, slave_if, xdg / "gtecat"


@pytest.fixture(scope="module")
def rig(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Rig]:
    tmp = tmp_path_factory.mktemp("serve_attach")
    with serve_rig(tmp) as (master_if, slave_if, run):
        # sleeping between frames: the lightest on the CPU (the answers need not be fast here)
        server = Server(
            FIG52, slave_if, tmp / "stats.json", "--rt-priority", "off", "--wait", "sleep"
        )
        try:
            with soem(master_if) as master:
                assert master.config_init() == 4
                master.config_map()
                assert master.expected_wkc == EXPECTED_WKC
                to_op(master)
                assert cycle(master, 5) == EXPECTED_WKC
                yield Rig(server, master, run)
        finally:
            rig_stop(server)


@pytest.fixture(autouse=True)
def _faults_cleared_after(request: pytest.FixtureRequest) -> Iterator[None]:
    """What a test armed on the module's serve is cleared after it, passed or failed (a
    fault left armed by a failed test would fail the next test in its stead)."""
    yield
    if "rig" in request.fixturenames:
        rig: Rig = request.getfixturevalue("rig")
        deadline = time.monotonic() + 10
        while rig.server.proc.poll() is None:
            try:
                with Attached(rig.run / f"{rig.id}.sock") as c:
                    c.call("fault_clear")
                return
            except BusError as e:
                # a closed connection's place is freed when its thread sees the close: after
                # a test that held every place (the hostile client's) the endpoint may still
                # refuse, with its line or (the refusal closed before our request was sent)
                # a broken pipe, while the serve itself runs on
                refused = "connections are open already" in str(e) or "went away" in str(e)
                if not refused or time.monotonic() > deadline:
                    raise
                time.sleep(0.02)


def test_ps_lists_the_serve_and_its_slaves_answer(rig: Rig, capsys) -> None:
    assert f"id {rig.id} (gtecat ps)" in rig.server.banner
    assert main(["ps", "--json"]) == 0
    (entry,) = json.loads(capsys.readouterr().out)
    assert (entry["id"], entry["kind"], entry["clock"]) == (rig.id, "serve", "wall")
    assert entry["backend"].startswith("wire gts") and entry["eni"].endswith("manual_fig5_2.eni")
    rc, out, _ = rig.cli(capsys, "states", "--json")
    assert rc == 0 and [r["state"] for r in json.loads(out)] == ["OP"] * 4
    rc, out, _ = rig.cli(capsys, "slaves", "--json")
    rows = json.loads(out)
    assert rc == 0 and [r["gt_offset"] for r in rows] == [0, 16, 32, 36]  # manual 5.2.2.4
    # what belongs to the master on the other end of the wire: one clear line, no traceback
    rc, _, err = rig.cli(capsys, "data")
    assert rc == 1 and "needs a controller" in err and "Traceback" not in err
    rc, _, err = rig.cli(capsys, "states", "INIT")
    assert rc == 1 and "does not change its slaves' states" in err
    rc, _, err = rig.cli(capsys, "panel")
    want = "is a gtecat serve" if importlib.util.find_spec("aiohttp") else "needs aiohttp"
    assert rc == 1 and want in err, err


def test_drop_responses_armed_at_runtime_loses_that_many_answers(rig: Rig, capsys) -> None:
    assert rig.cycles(3) == [EXPECTED_WKC] * 3
    rc, out, _ = rig.cli(capsys, "fault", "inject", "drop_responses", "count=3")
    # its number is the serve's count of faults so far (1 when this test runs first)
    fid = out.split(":")[0].removeprefix("fault ")
    assert rc == 0 and out == f"fault {fid}: the next 3 answers lost, at once (active)\n", out
    # the three answers the serve drops never come, late or not: the master waits SOEM's own
    # 2 ms for them (not the patient half second per frame); the others, the patient time
    wkcs = rig.cycles(3, SOEM_DEFAULT_FRAME_US) + rig.cycles(7)
    assert [w for w in wkcs if w != EXPECTED_WKC] == [wkcs[0]] * 3 and wkcs[0] <= 0, wkcs
    assert wkcs[3:] == [EXPECTED_WKC] * 7  # spent: the bus goes on by itself
    lines = rig.log()
    assert any(f"Fault {fid} started: the next 3 answers lost" in ln for ln in lines), lines
    assert any(f"Fault {fid} ended (spent)" in ln for ln in lines), lines


def test_link_down_until_cleared(rig: Rig, capsys) -> None:
    rc, out, _ = rig.cli(capsys, "fault", "inject", "link_down", "after_slave=1")
    assert rc == 0 and "(active)" in out
    assert rig.cycle_until(EXPECTED_WKC // 2), "slaves 2 and 3 did not vanish"
    assert rig.cycles(5) == [EXPECTED_WKC // 2] * 5
    rc, out, _ = rig.cli(capsys, "slaves", "--json")
    assert [r["link"] for r in json.loads(out)] == ["up", "up", "down", "down"]
    rc, out, _ = rig.cli(capsys, "fault", "list", "--json")
    (listed,) = json.loads(out)
    assert (listed["kind"], listed["state"]) == ("link_down", "active")
    rc, out, _ = rig.cli(capsys, "fault", "clear")
    assert rc == 0 and out.strip() == "1 fault cleared"
    assert rig.cycle_until(EXPECTED_WKC), "the link did not come back"
    assert rig.cycles(5) == [EXPECTED_WKC] * 5
    rc, out, _ = rig.cli(capsys, "fault", "list")
    assert out.strip() == "no fault armed or active"
    assert any("ended (cleared): link down after slave 1" in ln for ln in rig.log())


def test_mailbox_abort_reaches_the_masters_sdo_read_until_cleared(rig: Rig, capsys) -> None:
    import pysoem

    drive = rig.master.slaves[0]  # type: ignore[attr-defined]
    assert drive.sdo_read(0x6060, 0) is not None
    rc, _, _ = rig.cli(
        capsys, "fault", "inject", "mailbox_abort", "slave=0", "index=0x6060", "code=0x06090030",
        "count=0",
    )  # fmt: skip
    assert rc == 0
    for _ in range(2):  # count=0: every request, until cleared
        with pytest.raises(pysoem.SdoError) as err:
            drive.sdo_read(0x6060, 0)
        assert err.value.abort_code == 0x06090030
    assert drive.sdo_read(0x6061, 0) is not None  # another object: untouched
    assert rig.cycles(3) == [EXPECTED_WKC] * 3  # the process data goes on
    rc, out, _ = rig.cli(capsys, "fault", "clear")
    assert rc == 0 and out.strip() == "1 fault cleared"
    assert drive.sdo_read(0x6060, 0) is not None


def test_a_hostile_client_does_not_delay_the_frames(rig: Rig, capsys) -> None:
    """Requests answered at once (errors) as fast as a connection can send them, a line past
    the limit, more connections than allowed: every frame meanwhile is answered, none lost.
    (Each within SOEM_FRAME_US: how fast is not measurable on a loaded test machine, where
    even without a client a frame waited more than 20 ms now and then; a loop that served
    the flood before its frames would leave them unanswered as long as the flood lasts.)"""
    stop = threading.Event()
    sent = [0]

    def flood() -> None:
        with socket.socket(socket.AF_UNIX, socket.SOCK_STREAM) as s:
            s.connect(str(rig.run / f"{rig.id}.sock"))
            s.settimeout(1)
            rf = s.makefile("rb")
            while not stop.is_set():
                s.sendall(b'{"id": 1, "op": "no such op"}\nnot json\n')
                rf.readline()
                rf.readline()
                sent[0] += 2

    t = threading.Thread(target=flood, daemon=True)
    t.start()
    try:
        time.sleep(0.05)
        wkcs = rig.cycles(100)
    finally:
        stop.set()
        t.join(5)
    assert sent[0] > 0
    assert wkcs == [EXPECTED_WKC] * 100
    with socket.socket(socket.AF_UNIX, socket.SOCK_STREAM) as s:
        s.connect(str(rig.run / f"{rig.id}.sock"))
        s.settimeout(5)
        s.sendall(b"[" * (65 * 1024))  # no newline, past the limit: refused, connection ended
        reply = s.makefile("rb").readline()
        assert b"64 KiB at most" in reply and b'"ok": false' in reply
    with Attached(rig.run / f"{rig.id}.sock") as c:  # the endpoint still answers
        assert c.call("info")["kind"] == "serve"
    # connections past the limit are told so and closed; the others go on
    held = [socket.socket(socket.AF_UNIX, socket.SOCK_STREAM) for _ in range(9)]
    try:
        for s in held:
            s.settimeout(5)
            s.connect(str(rig.run / f"{rig.id}.sock"))
            time.sleep(0.01)  # accepted in this order
        assert b"8 connections are open already" in held[-1].makefile("rb").readline()
        held[0].sendall(b'{"id": 5, "op": "info"}\n')
        assert b'"kind":"serve"' in held[0].makefile("rb").readline()
    finally:
        for s in held:
            s.close()
    assert rig.cycles(3) == [EXPECTED_WKC] * 3


@pytest.mark.long
def test_the_serve_said_every_fault_on_stderr_and_stops_cleanly(rig: Rig) -> None:
    """As for ``--fault FILE``: each fault armed, started and ended has its line; the
    endpoint's files go with the serve."""
    assert rig_stop(rig.server) == 0, rig.server.output
    out = rig.server.output
    for line in (
        "gtecat serve: Fault 1 armed: the next 3 answers lost, at once.",
        "gtecat serve: Fault 1 ended (spent): the next 3 answers lost.",
        "gtecat serve: Fault 2 ended (cleared): link down after slave 1",
    ):
        assert line in out, out
    assert not list(rig.run.glob("*.sock")) and not list(rig.run.glob("*.json"))


@pytest.mark.long("an application on the pysoem backend for several seconds")
def test_an_application_sees_faults_injected_at_runtime(tmp_path: Path, capsys) -> None:
    """What the application sees through the GT API (gtecat's own master on pysoem, the
    realtime clock) while faults are added and cleared on the serve by the command line: a
    link down makes GT_IsEcatReady 0 and refuses slave 2's IO until cleared, a mailbox abort
    reaches GT_EcatSDOUpload's abort code, lost answers make a dip the bus recovers from."""
    from ctypes import byref, c_short, c_ubyte, c_uint32

    from gtecat import gt
    from tests.gtecat import scenario_common

    def ready() -> int:
        st = c_short()
        gt.GT_IsEcatReady(byref(st))
        return st.value

    def until(pred, ms: int) -> bool:
        return scenario_common.wait_until(gt, pred, ms=ms, step_ms=5)

    with serve_rig(tmp_path) as (master_if, slave_if, _run):
        server = Server(FIG52, slave_if, tmp_path / "stats.json", "--rt-priority", "off")
        sid = str(server.proc.pid)

        def fault(*words: str) -> str:
            assert main(["fault", *words, "--attach", sid]) == 0
            return capsys.readouterr().out

        try:
            assert (
                gt.GT_Open(eni=str(FIG52), backend="pysoem", iface=master_if, clock="realtime") == 0
            )
            assert gt.GT_InitEcatComm() == 0, gt.GTE_GetLastError()
            assert until(lambda: ready() == 1, 5000)
            fault("inject", "link_down", "after_slave=1")
            buf = (c_ubyte * 2)()
            assert until(lambda: ready() == 0, 3000)
            assert until(lambda: gt.GT_EcatIOReadInput(2, 0, 2, buf) == 1, 2000)
            assert fault("clear").strip() == "1 fault cleared"
            assert until(lambda: ready() == 1, 8000)
            assert gt.GT_EcatIOReadInput(2, 0, 2, buf) == 0
            fault("inject", "mailbox_abort", "slave=0", "index=0x6060", "code=0x06090030")
            data, size, abort = (c_ubyte * 4)(), c_uint32(), c_uint32()
            rc = gt.GT_EcatSDOUpload(0, 0x6060, 0, data, 4, byref(size), byref(abort))
            assert rc != 0 and abort.value == 0x06090030, gt.GTE_GetLastError()
            assert gt.GT_EcatSDOUpload(0, 0x6060, 0, data, 4, byref(size), byref(abort)) == 0
            fault("inject", "drop_responses", "count=30")
            assert until(lambda: ready() == 0, 3000)
            assert until(lambda: ready() == 1, 8000)
            assert fault("list").strip() == "no fault armed or active"
        finally:
            gt.GT_Close()
            rig_stop(server)
        for line in ("Fault 1 started: link down after slave 1", "Fault 3 ended (spent)"):
            assert line in server.output, server.output
