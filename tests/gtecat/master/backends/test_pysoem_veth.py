"""End to end: pysoem (SOEM) on one end of a veth pair, ``gtecat serve`` on the other.

Each test gets its own veth pair (unique names, always deleted) and its own
``gtecat serve`` process.  The same scenario module runs on the emulated
backend and on this wire, and must observe the same things (issue 7,
deliver 5); a slave runner stopped mid-run drops ``GT_IsEcatReady`` to 0 and
the bus comes back to 1 when the runner is started again.  Needs root (or
CAP_NET_ADMIN + CAP_NET_RAW); skipped with the reason otherwise.
"""

from __future__ import annotations

import itertools
import json
import os
import select
import shutil
import subprocess
import sys
from collections.abc import Iterator
from ctypes import byref, c_double, c_long, c_short, c_ubyte
from pathlib import Path

import pytest

from tests.conftest import EXAMPLES, ROOT
from tests.gtecat import scenario_common

pytestmark = pytest.mark.wire

MACHINE = """
[axis.1]
position = 1000
home_switch = [[40000, 50000]]
probe1 = [[8000, 9000]]
[axis.2]
position = -500
probe1 = [[5000, 5100]]
"""

_counter = itertools.count()


def _why_not() -> str | None:
    try:
        import pysoem  # noqa: F401
    except ImportError:
        return "pysoem is not installed"
    if not sys.platform.startswith("linux"):
        return "veth pairs need Linux"
    if shutil.which("ip") is None:
        return "the ip command (iproute2) is missing"
    if os.geteuid() != 0:
        return "creating a veth pair and raw sockets need root"
    return None


_REASON = _why_not()
if _REASON:
    pytest.skip(_REASON, allow_module_level=True)


@pytest.fixture(autouse=True)
def frame_timeout_for_a_python_slave() -> Iterator[None]:
    """SOEM gives a frame 2 ms (EC_TIMEOUTRET) before it sends it again. `gtecat serve` is
    Python on a shared VM and answered a frame in 5-10 ms now and then (its --stats-json
    showed it), after which SOEM's repeated mailbox exchanges read a stale answer (a mapping
    count of 4 for 6, an SDO with no abort code) and these tests failed about one run in
    three; 20 ms was missed as well on a busier machine. They test our pysoem backend, not
    the wire latency (issue 16 measures that), so here a frame gets
    :data:`~tests.gtecat.wire.rawmaster.SOEM_FRAME_US`."""
    from tests.gtecat.wire.rawmaster import patient_soem

    with patient_soem():
        yield


def _ip(*args: str, check: bool = True) -> subprocess.CompletedProcess:
    return subprocess.run(["ip", *args], capture_output=True, text=True, check=check)


@pytest.fixture
def veth() -> Iterator[tuple[str, str]]:
    """A fresh veth pair (master end, slave end), deleted whatever happens."""
    tag = f"{os.getpid() % 100000:05d}{next(_counter) % 100:02d}"
    a, b = f"gtm{tag}", f"gts{tag}"  # 10 characters, under IFNAMSIZ
    res = _ip("link", "add", a, "type", "veth", "peer", "name", b, check=False)
    if res.returncode:
        pytest.skip(f"cannot create a veth pair: {res.stderr.strip()}")
    try:
        for name in (a, b):
            Path(f"/proc/sys/net/ipv6/conf/{name}/disable_ipv6").write_text("1")
            _ip("link", "set", name, "up")
        yield a, b
    finally:
        _ip("link", "del", a, check=False)


class Runner:
    """One ``gtecat serve`` process (the slave runner)."""

    def __init__(self, eni: Path, iface: str, machine: Path | None = None) -> None:
        self.args = [
            sys.executable,
            "-m",
            "gtecat.cli.serve_cmd",
            "--eni",
            str(eni),
            "--iface",
            iface,
            # SCHED_FIFO (root runs these tests): on two CPUs shared with the realtime cycle
            # thread and another xdist worker, a plain process sat out 5-10 ms scheduler slices
            "--rt-priority",
            "10",
            # a fraction of a CPU: this file tests the backend, not the latency
            "--wait",
            "predict",
        ]
        if machine is not None:
            self.args += ["--machine", str(machine)]
        self.proc: subprocess.Popen | None = None

    def start(self, timeout_s: float = 20.0) -> None:
        self.proc = subprocess.Popen(
            self.args, cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True
        )
        assert self.proc.stdout is not None
        ready, _, _ = select.select([self.proc.stdout], [], [], timeout_s)
        line = self.proc.stdout.readline() if ready else ""
        if "ready" not in line:
            self.stop()
            pytest.fail(f"gtecat serve did not start: {line!r}")

    def stop(self) -> None:
        if self.proc is not None and self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(10)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        self.proc = None


@pytest.fixture
def machine(tmp_path: Path) -> Path:
    p = tmp_path / "machine.toml"
    p.write_text(MACHINE)
    return p


@pytest.fixture
def runner(veth, machine) -> Iterator[Runner]:
    r = Runner(EXAMPLES / "manual_fig5_2.eni", veth[1], machine)
    r.start()
    try:
        yield r
    finally:
        r.stop()


def test_scenario_gives_the_same_results_on_both_backends(veth, runner, machine):
    eni = str(EXAMPLES / "manual_fig5_2.eni")
    emulated = scenario_common.run(eni=eni, machine=str(machine))
    wire = scenario_common.run(
        eni=eni, machine=str(machine), backend="pysoem", iface=veth[0], clock="realtime"
    )
    assert emulated["ready"] is True, emulated
    assert wire["ready"] is True, wire
    assert [e["enabled"] for e in wire["enable"]] == [True, True]
    assert wire["raw_regions"] == emulated["raw_regions"]
    assert wire["io"] == emulated["io"]
    assert wire["sdo"] == emulated["sdo"]
    if wire.get("home") != scenario_common.SKIPPED:
        # axis 1 homes on its switch (method 19) and crosses probe window 1 on the way
        assert wire["home"][0]["method"] == 19 and wire["home"][0]["status"] == 3
        assert wire["probe"][0]["captured"] and wire["probe"][0]["rise1"] == 8000
    assert scenario_common.comparable(wire) == scenario_common.comparable(emulated)


BIT_TERMINALS = """
[[slave]]
kind = "io"
name = "EL1004"
product_code = 0x03EC3052
di = 4
packing = "bits"
[[slave]]
kind = "servo"
name = "Dual"
channels = 2
[[slave]]
kind = "io"
name = "EL2002"
product_code = 0x07D23052
do = 2
packing = "bits"
[[slave]]
kind = "io"
name = "EL1002"
product_code = 0x03EA3052
di = 2
do = 3
packing = "bits"
[[slave]]
kind = "coupler"
name = "IBM"
modules = ["DI16", "DO16", "AI4", "AO4"]
[[slave]]
kind = "io"
name = "EL2004"
product_code = 0x07D43052
do = 4
di = 1
packing = "bits"
"""


@pytest.mark.long
def test_bit_terminals_packed_by_soem_keep_the_gt_offsets(veth, machine, tmp_path):
    """SOEM packs slaves under 8 bits into shared IO map bytes; GT offsets must not move."""
    from gtecat.eni.topology import parse_topology
    from gtecat.eni.writer import write_eni_file

    eni = tmp_path / "bits.xml"
    write_eni_file(parse_topology(BIT_TERMINALS), eni)
    r = Runner(eni, veth[1], machine)
    r.start()
    try:
        emulated = scenario_common.run(eni=str(eni), machine=str(machine))
        wire = scenario_common.run(
            eni=str(eni), machine=str(machine), backend="pysoem", iface=veth[0], clock="realtime"
        )
    finally:
        r.stop()
    assert wire["ready"] is True, wire
    assert [x["outputs"] for x in wire["io"]] == [x["outputs"] for x in emulated["io"]]
    assert scenario_common.comparable(wire) == scenario_common.comparable(emulated)


def _ready(gt) -> int:
    status = c_short()
    gt.GT_IsEcatReady(byref(status))
    return status.value


def _wait_ready(gt, value: int, ms: int) -> bool:
    return scenario_common.wait_until(gt, lambda: _ready(gt) == value, ms=ms, step_ms=5)


@pytest.mark.long
def test_slave_runner_stopped_and_restarted(veth, runner, machine):
    from gtecat import gt

    gt.GT_Close()
    assert (
        gt.GT_Open(
            eni=str(EXAMPLES / "manual_fig5_2.eni"),
            backend="pysoem",
            iface=veth[0],
            clock="realtime",
            log="",
        )
        == 0
    )
    try:
        assert gt.GT_InitEcatComm() == 0, gt.GTE_GetLastError()
        assert _wait_ready(gt, 1, 3000)
        runner.stop()
        assert _wait_ready(gt, 0, 3000)
        ctl = gt.GTE_Controller()
        assert ctl.master.wkc_errors > 0
        runner.start()
        assert _wait_ready(gt, 1, 10_000), "\n".join(ctl.log.lines[-10:])
        assert "Working counter changed" in ctl.log.text()
        assert ctl.backend.stats.recoveries >= 1
        from gtecat.master.backends.cycle_stats import cycle_stats

        stats = cycle_stats(ctl)
        assert stats["bus"]["wkc_errors"] > 0 and stats["bus"]["lost_frames"] > 0
    finally:
        gt.GT_Close()


@pytest.mark.long
def test_terminate_then_init_again(veth, runner):
    from gtecat import gt

    gt.GT_Close()
    gt.GT_Open(
        eni=str(EXAMPLES / "manual_fig5_2.eni"),
        backend="pysoem",
        iface=veth[0],
        clock="realtime",
        log="",
    )
    try:
        for _ in range(2):
            assert gt.GT_InitEcatComm() == 0, gt.GTE_GetLastError()
            assert _wait_ready(gt, 1, 3000)
            assert gt.GT_TerminateEcatComm() == 0
            assert _ready(gt) == 0
    finally:
        gt.GT_Close()


def test_no_slave_on_the_wire_is_minus_10(veth):
    from gtecat import gt
    from tests.gtecat.wire.rawmaster import SOEM_DEFAULT_FRAME_US, patient_soem

    gt.GT_Close()
    gt.GT_Open(
        eni=str(EXAMPLES / "manual_fig5_2.eni"),
        backend="pysoem",
        iface=veth[0],
        clock="realtime",
        log="",
    )
    try:
        # nothing answers here by design: SOEM's own 2 ms per frame (its scan resends each
        # unanswered reset write for 3 frame timeouts: 1.5 s each at the patient 500 ms)
        with patient_soem(SOEM_DEFAULT_FRAME_US):
            assert gt.GT_InitEcatComm() == -10
        assert veth[0] in gt.GTE_GetLastError()
        status = c_short(7)  # the README's polling loop ends: 1 with the init's reason
        assert gt.GT_IsEcatReady(byref(status)) == 1 and status.value == 0
        assert "GT_InitEcatComm failed (-10" in gt.GTE_GetLastError()
    finally:
        gt.GT_Close()


@pytest.mark.long
def test_other_slaves_than_the_eni_is_minus_8(veth, machine):
    from gtecat import gt

    r = Runner(EXAMPLES / "manual_fig5_4.eni", veth[1])
    r.start()
    gt.GT_Close()
    gt.GT_Open(
        eni=str(EXAMPLES / "manual_fig5_2.eni"),
        backend="pysoem",
        iface=veth[0],
        clock="realtime",
        log="",
    )
    try:
        assert gt.GT_InitEcatComm() == -8
        assert "slave 0" in gt.GTE_GetLastError()
    finally:
        gt.GT_Close()
        r.stop()


ALARM, SERVO_ON, MOVING = 1 << 1, 1 << 9, 1 << 10


def _sts(gt, axis: int) -> int:
    s = c_long()
    assert gt.GT_GetSts(axis, byref(s)) == 0
    return s.value


def _pos(gt, fn: str, axis: int) -> float:
    v = c_double()
    assert getattr(gt, fn)(axis, byref(v)) == 0
    return v.value


def _move(gt, axis: int, target: int, vel: float = 50.0) -> None:
    prm = gt.TTrapPrm()
    assert gt.GT_PrfTrap(axis) == 0
    assert gt.GT_GetTrapPrm(axis, byref(prm)) == 0
    prm.acc, prm.dec, prm.smoothTime = 0.5, 0.5, 0
    assert gt.GT_SetTrapPrm(axis, byref(prm)) == 0
    assert gt.GT_SetPos(axis, target) == 0 and gt.GT_SetVel(axis, vel) == 0
    assert gt.GT_Update(1 << (axis - 1)) == 0, gt.GTE_GetLastError()


@pytest.mark.long
def test_bus_lost_mid_move_stops_the_axes_and_they_recover(veth, runner):
    """Issue 12 item 4 on the wire: the slave runner dies during a Trap move."""
    from gtecat import gt

    gt.GT_Close()
    assert (
        gt.GT_Open(
            eni=str(EXAMPLES / "manual_fig5_2.eni"),
            backend="pysoem",
            iface=veth[0],
            clock="realtime",
            log="",
        )
        == 0
    )
    wait = scenario_common.wait_until
    try:
        r: dict = {}
        assert scenario_common.bring_up(gt, r), r
        for a in (1, 2):
            assert gt.GT_AxisOn(a) == 0, gt.GTE_GetLastError()
            _move(gt, a, round(_pos(gt, "GT_GetEncPos", a)) + 1_000_000)
        assert wait(gt, lambda: _pos(gt, "GT_GetEncPos", 1) > 3000 + 1000, ms=3000)
        runner.stop()
        lost = lambda: all(  # noqa: E731
            _sts(gt, a) & ALARM and not _sts(gt, a) & (SERVO_ON | MOVING) for a in (1, 2)
        )
        assert wait(gt, lost, ms=2000), [_sts(gt, a) for a in (1, 2)]
        for a in (1, 2):
            frozen = _pos(gt, "GT_GetEncPos", a)
            assert _pos(gt, "GT_GetPrfPos", a) == frozen  # the plan sits on the encoder
        gt.GTE_Wait(200)
        for a in (1, 2):  # no runaway
            assert _pos(gt, "GT_GetPrfPos", a) == _pos(gt, "GT_GetEncPos", a)
        buf = (c_ubyte * 4)()
        assert gt.GT_EcatIOReadInput(2, 0, 4, buf) == 1
        assert "slave 2 (" in gt.GTE_GetLastError()
        assert gt.GT_GetEcatRawData(0, 2, buf) == 1
        assert "slave 0 (" in gt.GTE_GetLastError()
        assert gt.GT_AxisOn(1) == 1 and "slave 0 (" in gt.GTE_GetLastError()
        runner.start()
        assert _wait_ready(gt, 1, 10_000), "\n".join(gt.GTE_Controller().log.lines[-10:])
        assert gt.GT_EcatIOReadInput(2, 0, 4, buf) == 0
        assert gt.GT_ClrSts(1, 2) == 0
        assert not _sts(gt, 1) & ALARM and not _sts(gt, 2) & ALARM
        assert gt.GT_AxisOn(1) == 0, gt.GTE_GetLastError()
        start = round(_pos(gt, "GT_GetEncPos", 1))
        _move(gt, 1, start + 20_000)
        assert wait(gt, lambda: not _sts(gt, 1) & MOVING, ms=10_000)
        assert wait(gt, lambda: abs(_pos(gt, "GT_GetEncPos", 1) - start - 20_000) <= 2, ms=500)
    finally:
        gt.GT_Close()


# --- the inspection verbs through pysoem: ESC registers (FPRD/FPWR) and the SII (EEPROM) -----
def _verb(capsys, *argv: str) -> tuple[int, str, str]:
    from gtecat.cli.main import main

    capsys.readouterr()
    rc = main(list(argv))
    out, err = capsys.readouterr()
    return rc, out, err


@pytest.mark.long
def test_reg_and_sii_through_pysoem_read_what_the_emulated_bus_shows(veth, runner, capsys):
    eni = str(EXAMPLES / "manual_fig5_2.eni")
    wire = ("--eni", eni, "--backend", "pysoem", "--iface", veth[0])
    for argv in (("reg", "read", "-p", "0", "0x0130"), ("reg", "read", "0x0000", "8")):
        rc, out, err = _verb(capsys, *argv, *wire, "--json")
        assert rc == 0, err
        rows = json.loads(out)
        rc, local, err = _verb(capsys, *argv, "--eni", eni, "--json")
        assert rc == 0, err
        assert rows == json.loads(local), argv  # AL status OP; ESC type, revision, counts
    assert rows[0]["value"] & 0xFF == 0x11  # the virtual ESC's type

    rc, out, err = _verb(capsys, "sii", "read", *wire, "--json")
    assert rc == 0, err
    rc, local, _ = _verb(capsys, "sii", "read", "--eni", eni, "--json")
    wire_rows, own = json.loads(out), json.loads(local)

    # the SII is read up to its end category; `gtecat serve` places the IO
    # terminals' sync managers where the ENI's ProcessData/SmN says, the emulated bus where
    # the default layout does (so their PDOs name other SMs): every other field is the same
    def same(row: dict) -> dict:
        pdos = [{k: v for k, v in p.items() if k != "sm"} for p in row["pdos"]]
        return {k: v for k, v in row.items() if k not in ("bytes", "sync_managers")} | {
            "pdos": pdos
        }

    for w, o in zip(wire_rows, own, strict=True):
        assert same(w) == same(o)
        assert w["bytes"] > 0x80  # the header and the categories, not a fixed 4 KiB
    assert [w["sync_managers"] for w in wire_rows[:2]] == [o["sync_managers"] for o in own[:2]]
    assert [r["name"] for r in wire_rows] == ["GTHD 0", "GTHD 1", "IO 2", "IO 3"]

    rc, out, err = _verb(capsys, "reg", "write", "-p", "1", "0x0F10", "0x5AA5", *wire)
    assert rc == 0 and "a5 5a" in out, (out, err)  # written by FPWR, read back by FPRD
