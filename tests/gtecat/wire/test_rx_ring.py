"""The receive ring (gtecat.wire.rx_ring) and the serve loop's wait modes, on a veth pair.

A raw socket on the other end sends the frames; every wait is bounded.
"""

from __future__ import annotations

import json
import os
import select
import signal
import socket
import struct
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from tests.gtecat.wire.rawmaster import BRD, ETHERTYPE, LRD, RawMaster, veth_pair, why_not_root

ROOT = Path(__file__).resolve().parents[3]
FIG52 = ROOT / "examples" / "manual_fig5_2.eni"

pytestmark = [
    pytest.mark.wire,
    pytest.mark.skipif(why_not_root() is not None, reason=why_not_root() or ""),
]


def _sender(iface: str) -> socket.socket:
    s = socket.socket(socket.AF_PACKET, socket.SOCK_RAW, socket.htons(ETHERTYPE))
    s.bind((iface, ETHERTYPE))
    return s


def _frame(i: int, size: int) -> bytes:
    head = b"\xff" * 6 + b"\x04\x00\x00\x00\x00\x07" + struct.pack(">H", ETHERTYPE)
    body = struct.pack("<I", i) + bytes([i & 0xFF]) * (size - 18)
    return head + body


def test_the_ring_delivers_every_frame_intact_in_order_with_kernel_times() -> None:
    from gtecat.wire.rx_ring import open_ring
    from gtecat.wire.serve import open_raw_socket

    with veth_pair("rr") as (a, b):
        rx = open_raw_socket(b)
        ring = open_ring(rx)
        assert ring is not None, "the kernel refused PACKET_RX_RING"
        tx = _sender(a)
        buf = memoryview(bytearray(2048))
        try:
            assert not ring.ready()
            with pytest.raises(BlockingIOError):
                ring.take(buf)
            sent = [_frame(i, 60 + (i * 37) % 1400) for i in range(3 * ring.frames + 5)]
            last_t = 0
            got = 0
            for batch in range(0, len(sent), 100):  # more than the ring holds, in bursts
                t0 = time.clock_gettime_ns(time.CLOCK_REALTIME)
                for f in sent[batch : batch + 100]:
                    tx.send(f)
                deadline = time.monotonic() + 5
                while got < min(batch + 100, len(sent)):
                    if not ring.ready():
                        assert time.monotonic() < deadline, f"frame {got} never arrived"
                        select.select([rx], [], [], 0.05)
                        continue
                    n, t = ring.take(buf)
                    assert bytes(buf[:n]) == sent[got], f"frame {got}"
                    assert t0 - 1_000_000 <= t <= time.clock_gettime_ns(time.CLOCK_REALTIME)
                    assert t >= last_t
                    last_t = t
                    got += 1
            assert not ring.ready()
        finally:
            ring.close()
            rx.close()
            tx.close()


def test_a_socket_that_is_not_a_packet_socket_gets_no_ring() -> None:
    from gtecat.wire.rx_ring import open_ring

    a, b = socket.socketpair(socket.AF_UNIX, socket.SOCK_DGRAM)
    try:
        assert open_ring(a) is None
    finally:
        a.close()
        b.close()


def _configured_chain():
    """Two mini slaves, the second with an FMMU for a 2-byte LRD (process data)."""
    from tests.drives.esc.mini import mini_chain

    chain = mini_chain(2)
    esc = chain.escs[1]
    esc.write(0x0800, struct.pack("<HHBBBB", 0x1000, 2, 0x64, 0, 1, 0))
    esc.write(0x0808, struct.pack("<HHBBBB", 0x1400, 2, 0x20, 0, 1, 0))
    esc.write(0x0600, struct.pack("<IHBBHBBB3x", 0, 4, 0, 7, 0x1000, 0, 1, 1))
    return chain


@pytest.mark.parametrize("wait", ["predict", "sleep", "spin"])
@pytest.mark.sample(1)
def test_every_wait_mode_answers_a_1khz_master(wait: str) -> None:
    from gtecat.wire.serve import WireServer

    with veth_pair("rw") as (a, b):
        chain = _configured_chain()
        server = WireServer(chain, b, wait=wait, poll_s=0.005)
        thread = threading.Thread(target=server.serve, daemon=True)
        thread.start()
        try:
            with RawMaster(a) as m:  # every frame answered, however late a loaded host makes it
                deadline = time.monotonic() + 5
                while True:  # the loop is up once a BRD comes back
                    try:
                        m.brd(0x0000, 2)
                        break
                    except Exception:
                        assert time.monotonic() < deadline, "the server never answered"
                n = 300
                next_t = time.perf_counter()
                for _ in range(n):
                    # 1 ms after the last frame, never sooner: a master held back by a loaded
                    # machine does not send the frames it owes back to back.  (The master
                    # sleeps its cycle out: spinning it cost a third of a second of CPU,
                    # and only the serve's wait modes are under test.)
                    next_t = max(next_t + 0.001, time.perf_counter())
                    time.sleep(max(0.0, next_t - time.perf_counter()))
                    m.transact(LRD, 0, 0, bytes(4))  # process data (an FMMU takes part)
        finally:
            server.stop.set()
            thread.join(5)
            server.close()
        assert not thread.is_alive(), "the serve loop did not stop"
        report = server.report()
        assert report["receive_path"] == "rx ring"
        assert report["wait_mode"] == wait
        assert report["latency"]["count"] >= 301
        assert chain.slaves[1].steps >= 200  # about one step per process-data frame
        if wait == "predict":
            pacing = report["pacing"]
            # a cycle learned: 1 ms, stretched by a loaded machine, never shorter
            assert 900 <= pacing["period_us"] <= 20000
            # a loaded machine breaks the master's own rhythm now and then; the loop then
            # sleeps in poll until it is steady again (every frame was answered regardless)
            assert pacing["missed_windows"] <= 100


@pytest.mark.long
def test_sigusr1_reports_a_phase_and_starts_the_latency_records_afresh(tmp_path) -> None:
    stats = tmp_path / "stats.json"
    with veth_pair("ru") as (a, b):
        proc = subprocess.Popen(
            [sys.executable, "-m", "gtecat", "serve", "--eni", str(FIG52), "--iface", b,
             "--stats-json", str(stats), "--wait", "predict"],
            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, cwd=ROOT,
        )  # fmt: skip
        try:
            assert proc.stdout is not None
            ready, _, _ = select.select([proc.stdout], [], [], 30)
            assert ready and "ready" in proc.stdout.readline()
            with RawMaster(a) as m:
                for _ in range(40):
                    assert m.transact(BRD, 0, 0x0130, bytes(2)).wkc >= 1
                proc.send_signal(signal.SIGUSR1)
                deadline = time.monotonic() + 10
                first = None
                while first is None or first.get("snapshot") != 1:
                    assert time.monotonic() < deadline, "no snapshot written"
                    time.sleep(0.01)
                    if stats.exists():
                        first = json.loads(stats.read_text())
                for _ in range(25):
                    assert m.transact(BRD, 0, 0x0130, bytes(2)).wkc >= 1
            proc.send_signal(signal.SIGTERM)
            proc.communicate(timeout=10)
        finally:
            if proc.poll() is None:
                proc.kill()
                proc.communicate(timeout=10)
        assert proc.returncode == 0
        assert first["latency"]["count"] == 40
        final = json.loads(stats.read_text())
        assert final["latency"]["count"] == 25  # only the frames after the snapshot
        assert final["received"] == 65  # the counters go on


@pytest.mark.parametrize("wait", ["predict", "sleep"])
@pytest.mark.long
def test_predict_lingers_after_an_answer_for_a_master_in_a_burst(wait: str, tmp_path) -> None:
    """Bring-up traffic (register and mailbox exchanges, no cycle to learn): a master sends its
    next frame microseconds after our answer. In predict mode the loop spins a while after each
    answer (LINGER_NS) instead of sleeping, so those frames need no wake-up; sleep mode keeps
    its one wake-up per frame. ``gtecat serve`` runs in its own process, as users run it (in a
    thread of the master's process the spin would hold the GIL the master needs to send)."""
    from .rawmaster import ServeProcess

    cpus = sorted(os.sched_getaffinity(0))
    if len(cpus) < 2:
        pytest.skip("one CPU: a spinning server and the master would share it")
    root = Path(__file__).resolve().parents[3]
    stats = tmp_path / "stats.json"
    mine = os.sched_getaffinity(0)
    with veth_pair("rl") as (a, b):
        # server and master on different CPUs, as a machine with room for both runs them
        server = ServeProcess(
            root / "examples" / "manual_fig5_2.eni",
            b,
            stats,
            f"--wait={wait}",
            f"--cpu={cpus[-1]}",
            # the long linger is the normal-priority one; under SCHED_FIFO a wake-up costs
            # tens of microseconds and the loop lingers only LINGER_RT_NS (its spin would hold
            # the CPU against the master and any other server)
            "--rt-priority=off",
            cwd=root,
        )
        os.sched_setaffinity(0, {cpus[0]})
        try:
            with RawMaster(a, timeout=0.5) as m:
                deadline = time.monotonic() + 5
                while True:
                    try:
                        m.brd(0x0000, 2)
                        break
                    except Exception:
                        assert time.monotonic() < deadline, "the server never answered"
                for _ in range(100):
                    # AL status, no process data (no cycle to learn); a master thinks a while
                    # between frames (SOEM: 50-300 us per mailbox step), longer than the loop
                    # takes to see its own answer go by
                    t = time.perf_counter() + 150e-6
                    while time.perf_counter() < t:
                        pass
                    m.brd(0x0130, 2)
        finally:
            os.sched_setaffinity(0, mine)
            assert server.stop() == 0, server.output
    lingered = json.loads(stats.read_text())["lingered"]
    if wait == "predict":
        # frames of the burst found the loop awake (how many depends on the machine: a frame
        # that comes while the loop still sees its own answer go by is taken there)
        assert lingered >= 5, lingered
    else:
        assert lingered == 0
