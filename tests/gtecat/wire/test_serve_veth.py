"""``gtecat serve`` on one end of a veth pair, SOEM (pysoem) as the master on the other.

The test makes its own veth pair (unique names, always deleted) and skips, with
the reason, where it cannot: not root, no ``ip``, no pysoem, or the kernel
refuses the pair.  Every wait is bounded.
"""

from __future__ import annotations

import contextlib
import json
import math
import os
import select
import shutil
import signal
import socket
import struct
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from tests.conftest import needs_fixture
from tests.gtecat.wire import rawmaster

ROOT = Path(__file__).resolve().parents[3]
FIG52 = ROOT / "examples" / "manual_fig5_2.eni"
TWINCAT = ROOT.parent / "shared" / "fixtures" / "eni" / "twincat_ek1100_el2008_el4002_el1809.xml"

wire = pytest.mark.wire
# one veth pair and one `gtecat serve` serve the module: under pytest-xdist (--dist
# loadgroup) it stays on one worker
pytestmark = pytest.mark.xdist_group("serve_veth")


def _skip_reason() -> str | None:
    if sys.platform != "linux":
        return "veth pairs and AF_PACKET sockets are Linux only"
    if os.geteuid() != 0:
        return "creating a veth pair and raw sockets need root (CAP_NET_ADMIN, CAP_NET_RAW)"
    if shutil.which("ip") is None:
        return "no `ip` command (iproute2) to create the veth pair"
    try:
        import pysoem  # noqa: F401
    except ImportError:
        return "pysoem is not installed"
    return None


@contextlib.contextmanager
def veth_pair() -> Iterator[tuple[str, str]]:
    """A fresh veth pair (master end, slave end), deleted on the way out (the raw master's,
    skipped with the reason where this machine cannot make one)."""
    reason = _skip_reason()
    if reason:
        pytest.skip(reason)
    with contextlib.ExitStack() as stack:
        try:
            pair = stack.enter_context(rawmaster.veth_pair("gt"))
        except OSError as e:
            pytest.skip(str(e))
        yield pair


@pytest.fixture(scope="module")
def veth() -> Iterator[tuple[str, str]]:
    """The pair the shared figure 5-2 server runs on."""
    with veth_pair() as pair:
        yield pair


@pytest.fixture
def spare_veth() -> Iterator[tuple[str, str]]:
    """A pair of its own, for tests that start their own server."""
    with veth_pair() as pair:
        yield pair


class Server:
    """``python -m gtecat serve`` in a subprocess."""

    def __init__(self, eni: Path, iface: str, stats: Path, *extra: str) -> None:
        self.stats = stats
        self.proc = subprocess.Popen(
            [
                sys.executable,
                "-m",
                "gtecat",
                "serve",
                "--eni",
                str(eni),
                "--iface",
                iface,
                "--stats-json",
                str(stats),
                # a fraction of a CPU beside the suite's workers (``extra`` may say otherwise)
                "--wait",
                "predict",
                *extra,
            ],
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
            cwd=ROOT,
        )
        assert self.proc.stdout is not None
        ready, _, _ = select.select([self.proc.stdout], [], [], 30)
        line = self.proc.stdout.readline() if ready else ""
        if "ready" not in line:
            self.stop()
            pytest.fail(f"gtecat serve did not start: {line!r} {self.output!r}")
        self.banner = line

    output = ""

    def stop(self, sig: int = signal.SIGTERM) -> int:
        if self.proc.poll() is None:
            self.proc.send_signal(sig)
        try:
            out, _ = self.proc.communicate(timeout=10)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            out, _ = self.proc.communicate(timeout=10)
        self.output = out or ""
        return self.proc.returncode

    def report(self) -> dict:
        return json.loads(self.stats.read_text())


@pytest.fixture(scope="module")
def fig52(veth: tuple[str, str], tmp_path_factory: pytest.TempPathFactory) -> Iterator[Server]:
    server = Server(FIG52, veth[1], tmp_path_factory.mktemp("serve") / "stats.json")
    try:
        yield server
    finally:
        rc = server.stop()
        assert rc == 0, server.output


@contextlib.contextmanager
def soem(iface: str) -> Iterator[object]:
    import pysoem

    master = pysoem.Master()
    master.open(iface)
    try:
        with rawmaster.patient_soem():  # SOEM's 2 ms per frame: a loaded machine misses it
            yield master
    finally:
        with contextlib.suppress(Exception):
            master.state = pysoem.INIT_STATE
            master.write_state()
        master.close()


def cycle(master, n: int = 1) -> int:
    wkc = 0
    for _ in range(n):
        master.send_processdata()
        wkc = master.receive_processdata(rawmaster.SOEM_FRAME_US)  # bounded, for a loaded box
    return wkc


def to_op(master) -> None:
    import pysoem

    assert master.state_check(pysoem.SAFEOP_STATE, 2_000_000) == pysoem.SAFEOP_STATE
    master.state = pysoem.OP_STATE
    cycle(master)
    master.write_state()
    deadline = time.monotonic() + 5
    while master.state_check(pysoem.OP_STATE, 10_000) != pysoem.OP_STATE:
        cycle(master)
        assert time.monotonic() < deadline, "the chain did not reach OP"


def expected_layout(eni: Path):
    from gtecat.eni.layout import build_layout
    from gtecat.eni.reader import read_eni

    config = read_eni(eni)
    return config, build_layout(config)


# --- the tests ----------------------------------------------------------------------------------
@wire
def test_config_init_finds_every_slave(veth, fig52: Server) -> None:
    config, _ = expected_layout(FIG52)
    with soem(veth[0]) as master:
        assert master.config_init() == len(config.slaves)
        for s, want in zip(master.slaves, config.slaves, strict=True):
            assert (s.man, s.id, s.rev) == (
                want.identity.vendor_id,
                want.identity.product_code,
                want.identity.revision_no,
            )
            # SOEM copies the SII of an earlier slave with the same identity, name included
            first = next(c for c in config.slaves if c.identity == want.identity)
            assert s.name == first.name


@wire
def test_pdo_map_matches_the_eni_and_every_cycle_has_the_expected_wkc(veth, fig52) -> None:
    config, _ = expected_layout(FIG52)
    with soem(veth[0]) as master:
        master.config_init()
        master.config_map()
        for s, want in zip(master.slaves, config.slaves, strict=True):
            assert len(s.output) == math.ceil(want.out_bits / 8)
            assert len(s.input) == math.ceil(want.in_bits / 8)
        expected = sum(2 * bool(c.out_bits) + bool(c.in_bits) for c in config.slaves)
        assert master.expected_wkc == expected
        to_op(master)
        wkcs = [cycle(master) for _ in range(300)]
        assert wkcs == [expected] * 300


@wire
def test_sdo_read_write_and_abort_codes(veth, fig52) -> None:
    import pysoem

    config, _ = expected_layout(FIG52)
    with soem(veth[0]) as master:
        master.config_init()
        drive = master.slaves[0]
        vendor = struct.unpack("<I", drive.sdo_read(0x1018, 1))[0]
        assert vendor == config.slaves[0].identity.vendor_id
        drive.sdo_write(0x6060, 0, bytes([8]))
        assert drive.sdo_read(0x6060, 0) == bytes([8])
        name = drive.sdo_read(0x1008, 0)  # longer than 4 bytes: a normal (not expedited) upload
        assert len(name) > 4
        with pytest.raises(pysoem.SdoError) as err:
            drive.sdo_read(0x5555, 0)
        assert err.value.abort_code == 0x06020000  # object does not exist
        with pytest.raises(pysoem.SdoError) as err:
            drive.sdo_write(0x1000, 0, struct.pack("<I", 1))
        assert err.value.abort_code == 0x06010002  # attempt to write a read-only object


@wire
def test_a_drive_is_enabled_and_moved_through_pdos(veth, fig52) -> None:
    # figure 5-2 drives: outputs 6040h u16, 607Ah i32; inputs 6041h u16, 6064h i32, 60FDh u32
    with soem(veth[0]) as master:
        master.config_init()
        master.config_map()
        drive = master.slaves[0]
        drive.sdo_write(0x6060, 0, bytes([8]))  # cyclic synchronous position
        to_op(master)
        cycle(master, 5)
        start = struct.unpack_from("<i", drive.input, 2)[0]
        # each controlword until the drive shows its state (a frame lost on a loaded machine
        # costs a cycle, not the test): ready to switch on, switched on, operation enabled
        for cw, shows in ((0x0006, 0x0021), (0x0007, 0x0023), (0x000F, 0x0027)):
            drive.output = struct.pack("<Hi", cw, start)
            deadline = time.monotonic() + 5
            while time.monotonic() < deadline:
                cycle(master)
                if struct.unpack_from("<H", drive.input)[0] & 0x006F == shows:
                    break
        status = struct.unpack_from("<H", drive.input)[0]
        assert status & 0x006F == 0x0027, f"statusword 0x{status:04X} is not OPERATION ENABLED"
        # a CSP ramp of 20 counts a cycle, sent as a master does: at most one step per
        # millisecond, the drive's cycle (a master that sent them as fast as it could made the
        # drive see jumps of hundreds of counts per cycle when the host was busy, and its
        # servo overshot by as many)
        target = start
        for _ in range(200):
            target += 20
            drive.output = struct.pack("<Hi", 0x000F, target)
            cycle(master)
            time.sleep(0.001)
        positions = []
        deadline = time.monotonic() + 5
        while time.monotonic() < deadline:
            cycle(master)
            positions.append(struct.unpack_from("<i", drive.input, 2)[0])
            if positions[-1] == target:
                break
        assert positions[-1] == start + 4000, positions[-10:]
        assert positions == sorted(positions)  # it moved there, monotonically
        assert struct.unpack_from("<H", drive.input)[0] & 0x006F == 0x0027


@wire
def test_distributed_clocks_configure_and_tick(veth, fig52) -> None:
    with soem(veth[0]) as master:
        master.config_init()
        master.config_map()
        assert master.config_dc()
        for slave in master.slaves:  # SOEM's ec_dcsync0: SYNC0 every millisecond
            slave.dc_sync(1, 1_000_000)
        to_op(master)
        cycle(master, 10)
        before = master.dc_time
        time.sleep(0.02)
        assert cycle(master, 10) == master.expected_wkc
        assert master.dc_time - before >= 15_000_000  # the reference clock runs in ns


@wire
def test_malformed_frames_are_dropped_and_the_chain_keeps_running(spare_veth, tmp_path) -> None:
    server = Server(FIG52, spare_veth[1], tmp_path / "stats.json")
    try:
        sock = socket.socket(socket.AF_PACKET, socket.SOCK_RAW, socket.htons(0x88A4))
        sock.bind((spare_veth[0], 0x88A4))
        head = b"\xff" * 6 + b"\x02\x00\x00\x00\x00\x01" + b"\x88\xa4"
        junk = [
            head + struct.pack("<H", 0x1000 | 40) + bytes(10),  # datagrams shorter than announced
            head + struct.pack("<H", 0x1000 | 14) + bytes([7, 0, 0, 0, 0, 0, 0xFF, 0x87]),
            head + b"\x01",  # not even a frame header
        ]
        try:
            for frame in junk * 10:
                sock.send(frame.ljust(60, b"\0") if len(frame) > 16 else frame)
        finally:
            sock.close()
        with soem(spare_veth[0]) as master:
            assert master.config_init() == 4
            master.config_map()
            to_op(master)
            assert cycle(master, 20) == master.expected_wkc
    finally:
        assert server.stop() == 0, server.output
    chain = server.report()["chain"]
    assert chain["dropped"] == 30 and chain["errors"] == 0


@wire
@pytest.mark.long
def test_clean_shutdown_on_sigint_and_sigterm(spare_veth, tmp_path: Path) -> None:
    for sig in (signal.SIGINT, signal.SIGTERM):
        stats = tmp_path / f"stats{int(sig)}.json"
        server = Server(FIG52, spare_veth[1], stats, "--duration", "30")
        started = time.monotonic()
        rc = server.stop(sig)
        assert rc == 0, server.output
        assert time.monotonic() - started < 5
        assert "stopped" in server.output
        report = server.report()
        assert report["slaves"] == 4 and "latency" in report


@wire
def test_serve_reports_a_missing_interface_as_an_error(tmp_path: Path) -> None:
    reason = _skip_reason()
    if reason:
        pytest.skip(reason)
    out = subprocess.run(
        [sys.executable, "-m", "gtecat", "serve", "--eni", str(FIG52), "--iface", "gtnoexist0"],
        capture_output=True,
        text=True,
        timeout=60,
        cwd=ROOT,
    )
    assert out.returncode == 1
    assert "error: no network interface 'gtnoexist0'" in out.stderr


@wire
@pytest.mark.long
def test_bit_outputs_and_a_coupler_without_process_data(spare_veth, tmp_path: Path) -> None:
    if not TWINCAT.is_file():
        pytest.skip(needs_fixture(TWINCAT.name))
    config, _ = expected_layout(TWINCAT)
    server = Server(TWINCAT, spare_veth[1], tmp_path / "stats.json")
    try:
        with soem(spare_veth[0]) as master:
            assert master.config_init() == len(config.slaves)
            master.config_map()
            assert [len(s.output) for s in master.slaves] == [
                math.ceil(c.out_bits / 8) for c in config.slaves
            ]
            to_op(master)
            assert [cycle(master) for _ in range(50)] == [master.expected_wkc] * 50
    finally:
        assert server.stop() == 0, server.output
    assert server.report()["chain"]["dropped"] == 0


# --- the runner loop itself, on a socket pair (no root needed) ------------------------------------
class FakeClock:
    """Advances by ``step`` ns on every reading: time moves only as the loop runs."""

    def __init__(self, step: int = 500_000) -> None:
        self.t = 0
        self.step = step

    def __call__(self) -> int:
        self.t += self.step
        return self.t


@contextlib.contextmanager
def running(server) -> Iterator[None]:
    import threading

    thread = threading.Thread(target=server.serve, daemon=True)
    thread.start()
    try:
        yield
    finally:
        server.stop.set()
        thread.join(5)
        assert not thread.is_alive(), "the serve loop did not stop"


def exchange(sock: socket.socket, frame: bytes, timeout: float = 5.0) -> bytes | None:
    sock.send(frame)
    ready, _, _ = select.select([sock], [], [], timeout)
    return sock.recv(2048) if ready else None


def test_runner_answers_steps_and_drops() -> None:
    from gtecat.drives.esc import Command, Datagram, decode_frame, encode_frame
    from gtecat.wire.serve import WireServer
    from tests.drives.esc.mini import mini_chain

    chain = mini_chain(2)
    ours, theirs = socket.socketpair(socket.AF_UNIX, socket.SOCK_DGRAM)
    server = WireServer(chain, "socketpair", sock=theirs, poll_s=0.005)
    with running(server):
        answer = exchange(ours, encode_frame([Datagram(Command.BRD, 0, 0, bytes(2))]))
        assert answer is not None and decode_frame(answer).datagrams[0].wkc == 2
        ours.send(b"\xff" * 12 + b"\x88\xa4\x05")  # truncated: dropped, not answered
        ours.send(b"\xff" * 12 + b"\x08\x00" + bytes(46))  # not EtherCAT: ignored
        # process data: an LRW that hits an FMMU steps the slaves once
        esc = chain.escs[1]
        esc.write(0x0800, struct.pack("<HHBBBB", 0x1000, 2, 0x64, 0, 1, 0))
        esc.write(0x0808, struct.pack("<HHBBBB", 0x1400, 2, 0x20, 0, 1, 0))
        esc.write(0x0600, struct.pack("<IHBBHBBB3x", 0, 4, 0, 7, 0x1000, 0, 1, 1))
        steps = chain.slaves[1].steps
        for _ in range(3):
            answer = exchange(ours, encode_frame([Datagram.logical(Command.LRD, 0, bytes(4))]))
            assert answer is not None
        assert exchange(ours, encode_frame([Datagram(Command.NOP, 0, 0, b"\0")])) is not None
    assert chain.slaves[1].steps == steps + 3  # one step per process-data frame
    assert chain.stats.dropped == 1 and chain.stats.ignored == 1
    assert server.stats.received == 7 and server.stats.sent == 5
    assert server.report()["latency"]["count"] == 5
    ours.close()
    server.close()


def test_runner_cycle_mode_steps_on_its_own_timer() -> None:
    from gtecat.wire.serve import WireServer
    from tests.drives.esc.mini import mini_chain

    chain = mini_chain(1)
    ours, theirs = socket.socketpair(socket.AF_UNIX, socket.SOCK_DGRAM)
    clock = FakeClock(step=250_000)
    server = WireServer(
        chain, "socketpair", sock=theirs, step_mode="cycle", cycle_ns=1_000_000, clock=clock
    )
    server.serve(duration_s=0.05)  # 50 ms of the fake clock, no frames at all
    steps = chain.slaves[0].steps
    assert 45 <= steps <= 51
    assert server.stats.received == 0
    ours.close()
    server.close()


def test_runner_refuses_a_bad_step_mode() -> None:
    from gtecat.wire.serve import WireServer
    from tests.drives.esc.mini import mini_chain

    with pytest.raises(ValueError, match="step_mode"):
        WireServer(mini_chain(1), "x", step_mode="sometimes")


@pytest.mark.long
def test_runner_survives_a_failing_slave_side() -> None:
    from gtecat.drives.esc import Command, Datagram, encode_frame
    from gtecat.wire.serve import WireServer
    from tests.drives.esc.mini import mini_chain

    chain = mini_chain(1)

    def broken() -> None:
        raise RuntimeError("a bug in the slave side")

    chain.service = broken  # type: ignore[method-assign]
    ours, theirs = socket.socketpair(socket.AF_UNIX, socket.SOCK_DGRAM)
    server = WireServer(chain, "socketpair", sock=theirs, poll_s=0.005)
    with running(server):
        for _ in range(3):
            assert exchange(ours, encode_frame([Datagram(Command.BRD, 0, 0, bytes(2))]))
    assert server.stats.internal_errors == 3 and server.stats.sent == 3
    ours.close()
    server.close()
