"""``gtecat serve``: virtual slaves answering a real master on a network interface.

A :class:`WireServer` owns a raw ``AF_PACKET`` socket bound to EtherType 88A4h
on one interface (one end of a veth pair in tests, a spare NIC in a lab) and a
:class:`gtecat.drives.esc.Chain`.  Its loop, single-threaded so the slaves never need
locks:

1. receive a frame (``recv_into`` a preallocated buffer, no copies);
2. let the chain process it in place and send it straight back - the answer
   leaves before any slave work, so the frame-in -> frame-out latency is the
   ESC emulation alone;
3. then do the slave side: mailbox requests and answers (:meth:`Chain.service`),
   and the slaves' cycle.

When the slaves step (``step_mode``):

* ``"frame"`` (default): once per received frame that carried process data (an
  FMMU took part), with ``dt`` = wall time since the previous step, clamped to
  ``max_dt_ns``.  The slaves run at the master's cycle, whatever it is, like a
  drive synchronised to SM2 events.  A master that splits its image over several
  frames steps the slaves once per frame with the real (short) ``dt`` between
  them; ``min_gap_ns`` can merge such bursts into one step.  The inputs a
  frame returns are those of the previous step: one cycle of delay, as on a real
  bus.
* ``"cycle"``: on a wall-clock timer every ``cycle_ns`` (the ENI cycle time),
  independent of the master, like a drive in free run.

Latency: the cyclic datagram is answered from input snapshots and its outputs
reach the slaves after the send (:class:`gtecat.drives.esc.chain.Chain`); the slaves'
step answers a frame that arrives meanwhile between two slaves; the garbage
collector runs between frames, never inside one; sends bypass the qdisc.  The
recorded latency is honest: from the kernel's receive timestamp (SO_TIMESTAMPNS,
so time the frame waited in the socket counts) to the return of ``send``;
``processing`` (user-space receive -> send called) and ``send`` (the syscall,
which on a veth pair includes delivering the frame to the peer's socket) are
recorded apart.

Between frames the loop checks the sync manager watchdogs and stops within
``poll_s`` of :attr:`stop` being set (Ctrl-C / SIGTERM in the CLI).  Malformed
frames are counted and dropped by the chain; nothing a frame contains can end
the loop.  ``busy_poll`` spins instead of sleeping in ``poll`` (one core at
100 %, no wake-up latency); :func:`gtecat.scheduling.take` asks for SCHED_FIFO.
"""

from __future__ import annotations

import ctypes
import errno
import gc
import logging
import os
import select
import socket
import struct
import threading
import time
from array import array
from collections.abc import Callable
from dataclasses import dataclass, field

from gtecat.drives.esc import Chain
from gtecat.drives.esc.frames import ETHERTYPE_ECAT
from gtecat.eni.errors import GtecatError

from ..master.pcap import PcapWriter
from .pacing import Pacing
from .rx_ring import SOL_PACKET, RxRing, open_ring

log = logging.getLogger(__name__)


class WireError(GtecatError):
    """The network side cannot be used (no interface, no rights)."""


class LatencyRecorder:
    """Frame-in -> frame-out times of the last ``size`` frames, in nanoseconds."""

    def __init__(self, size: int = 1 << 16) -> None:
        self.samples = array("q", bytes(8 * size))
        self.size = size
        self.count = 0
        #: samples over 1 ms and over 2 ms (SOEM's frame timeout), of all, not only the kept
        self.over_1ms = 0
        self.over_2ms = 0

    def add(self, ns: int) -> None:
        self.samples[self.count % self.size] = ns
        self.count += 1
        if ns > 1_000_000:
            self.over_1ms += 1
            if ns > 2_000_000:
                self.over_2ms += 1

    def summary(self) -> dict[str, float]:
        n = min(self.count, self.size)
        if not n:
            return {"count": 0}
        data = sorted(self.samples[:n])

        def pct(p: float) -> float:
            return data[min(n - 1, int(p * n))] / 1000.0

        return {
            "count": self.count,
            "mean_us": sum(data) / n / 1000.0,
            "p50_us": pct(0.50),
            "p90_us": pct(0.90),
            "p99_us": pct(0.99),
            "max_us": data[-1] / 1000.0,
            "over_1ms": self.over_1ms,
            "over_2ms": self.over_2ms,
        }


@dataclass(slots=True)
class ServeStats:
    received: int = 0
    sent: int = 0
    steps: int = 0
    send_errors: int = 0
    receive_errors: int = 0
    internal_errors: int = 0
    #: frames answered between two slaves' steps
    answered_in_step: int = 0
    #: frames picked up while the loop lingered after an answer (predict mode, no cycle)
    lingered: int = 0
    started_ns: int = 0
    stopped_ns: int = 0
    #: kernel receive timestamp (or user-space receive) -> send returned
    latency: LatencyRecorder = field(default_factory=LatencyRecorder)
    #: kernel receive timestamp -> user-space receive returned (the frame waiting for us)
    wait: LatencyRecorder = field(default_factory=LatencyRecorder)
    #: user-space receive -> send called (the ESC emulation alone)
    processing: LatencyRecorder = field(default_factory=LatencyRecorder)
    #: the send syscall
    send: LatencyRecorder = field(default_factory=LatencyRecorder)
    #: whether ``latency`` starts at the kernel's receive timestamps
    kernel_timestamps: bool = False
    #: "rx ring", "recvmsg" (with time stamps) or "recv"
    receive_path: str = ""
    #: where the loop was when it took each frame, counted by FOUND index
    found: list[int] = field(default_factory=lambda: [0] * len(FOUND))
    #: the first LATE_KEPT frames answered later than 1 ms: when, how late, where found
    late: list[dict[str, object]] = field(default_factory=list)


#: where the loop was when it took a frame: spinning on the ring (around the predicted frame,
#: lingering after an answer, or --wait spin), asleep before the predicted window (the frame
#: came first and woke it), asleep in poll (no window: --wait sleep, a missed window, no cycle
#: learned), or inside the slaves' step (answered between two slaves)
FOUND = ("spinning", "woken", "polled", "in_step")
_SPINNING, _WOKEN, _POLLED, _IN_STEP = range(len(FOUND))
#: frames over 1 ms kept in the report with their details
LATE_KEPT = 32


#: how the loop waits for the next frame: sleeping in poll (a wake-up per frame),
#: predicting the master's cyclic frame and spinning only around its due time
#: (:mod:`gtecat.wire.pacing`; frame step mode), or spinning all the time (a whole CPU)
WAIT_MODES = ("predict", "sleep", "spin")

#: turns of the busy-poll spin between two looks at the stop flag, watchdogs and timers
SPIN_TURNS = 256
#: predict mode, no cycle learned: how long the loop spins after an answer before it sleeps
LINGER_NS = 500_000
#: the same under SCHED_FIFO: a real-time task wakes within tens of microseconds, and one that
#: spins holds its CPU against every normal task (the master) and every other server there
LINGER_RT_NS = 50_000

SO_TIMESTAMPNS = getattr(socket, "SO_TIMESTAMPNS", 35)
SCM_TIMESTAMPNS = SO_TIMESTAMPNS
PACKET_QDISC_BYPASS = 20  # linux/if_packet.h
_TIMESPEC = struct.Struct("@qq")
_ANC_SIZE = socket.CMSG_SPACE(_TIMESPEC.size) if hasattr(socket, "CMSG_SPACE") else 0


def open_raw_socket(iface: str) -> socket.socket:
    """A raw socket receiving and sending EtherCAT frames on ``iface``."""
    try:
        sock = socket.socket(socket.AF_PACKET, socket.SOCK_RAW, socket.htons(ETHERTYPE_ECAT))
    except PermissionError as exc:
        raise WireError(
            "raw sockets need root or CAP_NET_RAW (try sudo, or "
            "setcap cap_net_raw+ep on the python binary)"
        ) from exc
    try:
        sock.bind((iface, ETHERTYPE_ECAT))
    except OSError as exc:
        sock.close()
        if exc.errno in (errno.ENODEV, errno.ENXIO):
            raise WireError(f"no network interface {iface!r}") from exc
        raise WireError(f"cannot bind to {iface!r}: {exc.strerror}") from exc
    try:
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 1 << 20)
    except OSError:
        pass
    try:  # answers go straight to the driver, not through the queueing discipline
        sock.setsockopt(SOL_PACKET, PACKET_QDISC_BYPASS, 1)
    except OSError:
        pass
    sock.setblocking(False)
    return sock


def fine_timers() -> bool:
    """Ask Linux for a timer slack of 1 ns (``PR_SET_TIMERSLACK``): a normal process's sleeps
    end up to 50 us late by default, on purpose (timers are merged to save wake-ups), and the
    predicted window's sleep must end on time.  False where the call is not available."""
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        return libc.prctl(29, 1, 0, 0, 0) == 0  # PR_SET_TIMERSLACK = 29
    except (OSError, AttributeError):
        return False


def pin_to_cpu(cpu: int) -> None:
    """Run this process on ``cpu`` alone.  On a small machine the master's busy loop and the
    server's spin around the frame otherwise meet on one CPU now and then (the scheduler moves
    the master there while the server sleeps), and each frame then waits for a context switch."""
    try:
        os.sched_setaffinity(0, {cpu})
    except (OSError, AttributeError, ValueError) as exc:
        raise WireError(f"cannot run on CPU {cpu}: {exc}") from exc


def host_steal() -> tuple[int, int]:
    """(all CPU time, steal) of the machine so far, in clock ticks, from ``/proc/stat``: on a
    virtual machine, steal is time the hypervisor ran something else on our CPUs - a frame
    that arrives for a CPU that is not running waits for it, whatever our priority.
    (0, 0) where unreadable."""
    try:
        with open("/proc/stat") as fh:
            fields = fh.readline().split()[1:]
        ticks = [int(x) for x in fields[:8]]
    except (OSError, ValueError):
        return 0, 0
    return sum(ticks), ticks[7] if len(ticks) > 7 else 0


#: the kernel's preemption models, as ``/sys/kernel/debug/sched/preempt`` and ``preempt=`` name them
PREEMPTION_MODELS = ("none", "voluntary", "full", "lazy", "rt")
#: models under which a normal task inside a system call keeps its CPU until the call ends or
#: reaches a preemption point: a real-time wake-up on that CPU waits for it (measured on the
#: development VM: a frame taken 4.2 ms late behind another program's system call)
UNPREEMPTIBLE = ("none", "voluntary")


def kernel_preemption(
    debugfs: str = "/sys/kernel/debug/sched/preempt",
    cmdline: str = "/proc/cmdline",
    configs: tuple[str, ...] = ("/proc/config.gz", f"/boot/config-{os.uname().release}"),
) -> str | None:
    """The running kernel's preemption model (one of PREEMPTION_MODELS), or ``None`` where it
    cannot be told: the debugfs switch of a PREEMPT_DYNAMIC kernel (the chosen model in
    parentheses), else ``preempt=`` on the command line, else the kernel configuration."""
    try:
        with open(debugfs) as fh:
            text = fh.read()
        start, end = text.find("("), text.find(")")
        if 0 <= start < end and text[start + 1 : end] in PREEMPTION_MODELS:
            return text[start + 1 : end]
    except OSError:
        pass
    try:
        with open(cmdline) as fh:
            for word in fh.read().split():
                if word.startswith("preempt=") and word[8:] in PREEMPTION_MODELS:
                    return word[8:]
    except OSError:
        pass
    for path in configs:
        try:
            if path.endswith(".gz"):
                import gzip

                with gzip.open(path, "rt") as fh:
                    config = fh.read()
            else:
                with open(path) as fh:
                    config = fh.read()
        except (OSError, EOFError):
            continue
        options = {line.strip() for line in config.splitlines()}
        for option, model in (
            ("CONFIG_PREEMPT_RT=y", "rt"),
            ("CONFIG_PREEMPT=y", "full"),
            ("CONFIG_PREEMPT_LAZY=y", "lazy"),
            ("CONFIG_PREEMPT_VOLUNTARY=y", "voluntary"),
            ("CONFIG_PREEMPT_NONE=y", "none"),
        ):
            if option in options:
                return model
        return None
    return None


def interface_is_up(iface: str) -> bool | None:
    """``True``/``False`` from sysfs; ``None`` when it cannot tell."""
    try:
        with open(f"/sys/class/net/{iface}/operstate") as fh:
            state = fh.read().strip()
    except OSError:
        return None
    return state in ("up", "unknown")


class WireServer:
    """A chain of virtual slaves served on one interface until :attr:`stop` is set."""

    def __init__(
        self,
        chain: Chain,
        iface: str,
        *,
        step_mode: str = "frame",
        cycle_ns: int = 1_000_000,
        max_dt_ns: int = 100_000_000,
        min_gap_ns: int = 0,
        poll_s: float = 0.02,
        busy_poll: bool = False,
        wait: str = "predict",
        clock: Callable[[], int] = time.monotonic_ns,
        sock: socket.socket | None = None,
        pcap: PcapWriter | None = None,
        use_ring: bool = True,
    ) -> None:
        if step_mode not in ("frame", "cycle"):
            raise ValueError(f"step_mode must be 'frame' or 'cycle', not {step_mode!r}")
        if cycle_ns <= 0:
            raise ValueError("cycle_ns must be positive")
        self.chain = chain
        self.iface = iface
        self.step_mode = step_mode
        self.cycle_ns = cycle_ns
        self.max_dt_ns = max_dt_ns
        self.min_gap_ns = min_gap_ns
        self.poll_s = poll_s
        if wait not in WAIT_MODES:
            raise ValueError(f"wait must be one of {', '.join(WAIT_MODES)}, not {wait!r}")
        #: how the loop waits for frames (WAIT_MODES); ``busy_poll`` = "spin"
        self.wait = "spin" if busy_poll else wait
        self.pacing = Pacing()
        #: predict mode, no cycle learned: the spin after an answer (LINGER_RT_NS under FIFO)
        self.linger_ns = LINGER_NS
        self.clock = clock
        self.stop = threading.Event()
        self.stats = ServeStats()
        #: every frame received and every answer sent, when set (``--pcap``)
        self.pcap = pcap
        #: receive through a PACKET_RX_RING where the socket takes one
        self.use_ring = use_ring
        self._sock = sock
        self._t0 = 0
        self._last_step: int | None = None
        self._last_out = -(1 << 62)  # when the last answer went out (the linger after it)
        #: a process-data frame was answered inside a step: one more step follows it
        self._step_due = False
        self._answered_in_this_step = False
        #: set (from a signal handler, say) to have :attr:`on_snapshot` called with the
        #: report between frames, then the latency records started afresh
        self.snapshot_due = False
        self.on_snapshot: Callable[[dict[str, object]], None] | None = None
        self.snapshots = 0
        #: (process CPU time, clock) when the records last started: the CPU share reported
        self._cpu_mark = (time.process_time(), clock())
        #: the host's CPU time and steal when the records last started
        self._steal_mark = host_steal()
        #: what an answer meets on its way back (gtecat.faults): called with the answered
        #: frame, its length and the receive time; returns the length to send (0: lost)
        self.frame_hook: Callable[[bytearray, int, int], int] | None = None
        #: called after every step of the slaves with the slaves' time (ns since the start)
        self.step_hooks: list[Callable[[int], None]] = []
        #: called between frames (every few ms) with that time: timers of the hooks above
        self.poll_hooks: list[Callable[[int], None]] = []

    def _snapshot(self) -> None:
        """Report what the latency records hold and start them afresh (``gtecat serve``:
        SIGUSR1), so a benchmark can time one phase of a run, e.g. only the paced cycles."""
        self.snapshot_due = False
        self.snapshots += 1
        if self.on_snapshot is not None:
            self.on_snapshot(self.report())
        s = self.stats
        self._cpu_mark = (time.process_time(), self.clock())
        s.latency, s.wait = LatencyRecorder(), LatencyRecorder()
        s.processing, s.send = LatencyRecorder(), LatencyRecorder()
        s.found, s.late = [0] * len(FOUND), []
        self._steal_mark = host_steal()

    # --- slave cycle -----------------------------------------------------------------------
    def _step(self, now: int, between: Callable[[], None] | None = None) -> None:
        self._answered_in_this_step = False
        last = self._last_step
        dt = self.cycle_ns if last is None else min(max(now - last, 0), self.max_dt_ns)
        self._last_step = now
        self.chain.step(now - self._t0, dt, between)
        self.stats.steps += 1
        for hook in self.step_hooks:
            hook(now - self._t0)

    # --- the loop --------------------------------------------------------------------------
    def serve(
        self, ready: Callable[[], None] | None = None, duration_s: float | None = None
    ) -> None:
        """Serve until :attr:`stop` is set or ``duration_s`` has passed."""
        sock = self._sock or open_raw_socket(self.iface)
        self._sock = sock
        sock.setblocking(False)
        chain, stats, clock = self.chain, self.stats, self.clock
        buf = bytearray(2048)
        view = memoryview(buf)
        send = sock.send
        receive = self._receiver(sock, view)
        poller = select.poll()
        poller.register(sock.fileno(), select.POLLIN)
        poll = poller.poll
        ring = self._ring
        waiting: Callable[[], object] = ring.ready if ring is not None else (lambda: poll(0))
        self._t0 = stats.started_ns = clock()
        deadline = None if duration_s is None else self._t0 + int(duration_s * 1e9)
        next_cycle = self._t0 + self.cycle_ns
        next_poll = self._t0
        frame_mode = self.step_mode == "frame"
        pcap = self.pcap
        spin = self.wait == "spin"
        predict = self.wait == "predict" and frame_mode
        pacing = self.pacing = Pacing()
        fd = sock.fileno()
        poll_ns = int(self.poll_s * 1e9)
        linger_ns = self.linger_ns
        self._sync_clocks()
        fine_timers()
        #: where the loop waits now (FOUND index), since when, and this thread's CPU time
        #: then where it keeps running (spinning; 0 asleep): the frame it takes is counted
        #: there, and a late one reported with it; the same two times at the slaves' step
        where = [_POLLED, 0, 0]
        step_mark = [0, 0]
        thread_time = time.thread_time_ns
        # maintainers' diagnostics: every frame's times and where it was found, as int64
        # records (kernel time, taken, send called, send returned, FOUND index, since)
        flog_path = os.environ.get("GTECAT_SERVE_FRAMELOG")
        flog = array("q") if flog_path else None

        def answer(in_step: bool) -> bool:
            """Receive, process and answer one frame; False when none was waiting."""
            try:
                n, t_kernel = receive()
            except BlockingIOError:
                return False
            except InterruptedError:
                return True
            except OSError as exc:
                self._receive_failed(exc)
                return False
            t_in = clock()
            stats.received += 1
            request = bytes(view[:n]) if pcap is not None else b""
            if not chain.process(buf, n, t_in):
                if pcap is not None:
                    pcap.write(request, self._wall(t_kernel or t_in))
                return True
            hook = self.frame_hook
            if hook is not None:
                n = hook(buf, n, t_in - self._t0)
                if n <= 0:  # lost on its way back: the master's frame times out
                    if pcap is not None:
                        pcap.write(request, self._wall(t_kernel or t_in))
                    self._guarded(chain.service)
                    return True
            t_send = clock()
            try:
                send(view[:n])
                stats.sent += 1
            except OSError as exc:
                stats.send_errors += 1
                if stats.send_errors <= 5:
                    log.warning("send failed: %s", exc)
            t_out = clock()
            self._last_out = t_out
            if chain.process_data:
                pacing.arrived(t_kernel or t_in)
            t_arrived = t_kernel or t_in
            found = _IN_STEP if in_step else where[0]
            stats.found[found] += 1
            if t_out - t_arrived > 1_000_000 and len(stats.late) < LATE_KEPT:
                since, cpu = step_mark if in_step else where[1:]
                record = self._late_record(t_arrived, t_in, t_out, found, since)
                if cpu:  # it kept running: how much of that time it really ran
                    wall, ran = clock() - since, thread_time() - cpu
                    record["not_running_us"] = round(max(0, wall - ran) / 1000, 1)
                stats.late.append(record)
            stats.latency.add(t_out - t_arrived)
            if flog is not None:
                flog.extend((t_kernel, t_in, t_send, t_out, found, where[1]))
            if t_kernel:
                stats.wait.add(t_in - t_kernel)
            stats.processing.add(t_send - t_in)
            stats.send.add(t_out - t_send)
            if pcap is not None:
                pcap.write(request, self._wall(t_kernel or t_in))
                pcap.write(view[:n], self._wall(t_send))
            if in_step:
                stats.answered_in_step += 1
                self._step_due |= frame_mode and chain.process_data
                return True
            self._guarded(chain.service)
            if frame_mode and chain.process_data:
                last = self._last_step
                if last is None or t_in - last >= self.min_gap_ns:
                    step_mark[0], step_mark[1] = clock(), thread_time()
                    self._guarded(self._step, t_in, between)
                    for _ in range(8):  # process data answered during a step: its own step
                        if not self._step_due:
                            break
                        self._step_due = False
                        self._guarded(chain.service)
                        self._guarded(self._step, clock(), between)
            return True

        def between() -> None:
            # one frame per step at most: a master sending back to back must neither keep
            # the step from finishing nor take every answer out of the step rhythm
            if not self._answered_in_this_step and waiting() and answer(True):
                self._answered_in_this_step = True

        gc.collect()
        gc.freeze()  # what exists now is never scanned again: no long collector pauses
        gc_was_enabled = gc.isenabled()
        gc.disable()  # young objects are collected between frames (below), never inside one
        if ready is not None:
            ready()
        try:
            while not self.stop.is_set():
                now = clock()
                if deadline is not None and now >= deadline:
                    break
                window = pacing.window() if predict else None
                # predict mode with no cycle learned (bring-up, mailbox exchanges): the
                # master's next frame follows our answer within microseconds, and a wake-up
                # from poll costs 50-150 us on a VM (SOEM's frame timeout is 2 ms), so the loop
                # spins a while after each answer before it sleeps
                linger = predict and window is None and now - self._last_out < linger_ns
                if spin or window is not None or linger:
                    turns = SPIN_TURNS
                    if window is not None:
                        opens, closes = window
                        if now < opens:  # sleep until the window opens; a frame ends it
                            where[0], where[1], where[2] = _WOKEN, now, 0
                            if select.select([fd], [], [], min(opens - now, poll_ns) / 1e9)[0]:
                                while answer(False):
                                    pass
                                turns = 0
                            elif opens - now <= poll_ns:  # woke for the window: how late
                                pacing.woke(clock() - opens)
                        elif now >= closes:  # the frame did not come: poll until it does
                            pacing.missed()
                            turns = 0
                    # a tight spin on the socket (a look at the ring's next slot, or one
                    # poll syscall, per turn); the loop's housekeeping below runs every
                    # SPIN_TURNS turns or after a frame
                    if where[0] != _SPINNING:
                        where[0], where[1], where[2] = _SPINNING, clock(), thread_time()
                    for _ in range(turns):
                        if waiting():
                            stats.lingered += linger
                            while answer(False):
                                pass
                            break
                else:
                    timeout_ms = int(self.poll_s * 1000)
                    if not frame_mode:
                        timeout_ms = max(
                            0, min(timeout_ms, (next_cycle - now + 999_999) // 1_000_000)
                        )
                    where[0], where[1], where[2] = _POLLED, now, 0
                    if poll(timeout_ms):
                        while answer(False):
                            pass
                now = clock()
                if not frame_mode:
                    while now >= next_cycle:
                        self._guarded(self._step, next_cycle, between)
                        next_cycle += self.cycle_ns
                        if now - next_cycle > 100 * self.cycle_ns:  # fell far behind: resync
                            next_cycle = now + self.cycle_ns
                if now >= next_poll and self._housekeeping_may_run(pacing, predict, now, next_poll):
                    if self.snapshot_due:
                        self._guarded(self._snapshot)
                    self._guarded(chain.poll, now)
                    for hook in self.poll_hooks:
                        self._guarded(hook, now - self._t0)
                    gc.collect(0)
                    self._sync_clocks()
                    next_poll = clock() + 5_000_000
        finally:
            if flog is not None and flog_path:
                with open(flog_path, "wb") as fh:
                    flog.tofile(fh)
            if gc_was_enabled:
                gc.enable()
            if pcap is not None:
                pcap.flush()
            stats.stopped_ns = clock()
            poller.unregister(sock.fileno())
            view.release()

    def _late_record(
        self, t_arrived: int, t_in: int, t_out: int, found: int, since: int
    ) -> dict[str, object]:
        """What the report says of a frame answered later than 1 ms."""
        return {
            "at_s": round((t_arrived - self._t0) / 1e9, 6),
            "latency_us": round((t_out - t_arrived) / 1000, 1),
            "wait_us": round((t_in - t_arrived) / 1000, 1),
            "found": FOUND[found],
            #: how long before the frame the loop began that wait or step (negative: after it)
            "waiting_since_us": round((t_arrived - since) / 1000, 1) if since else None,
            #: (spinning or in a step: it kept running) how much of the time since then this
            #: thread did not run: the hypervisor took its CPU (a guest kernel leaves steal out
            #: of a task's CPU time) or something above it ran; None where it slept
            "not_running_us": None,
        }

    #: a housekeeping pass (chain poll, inspection requests, a young-generation collection)
    #: takes up to this long; it does not start this close before the next frame's window
    HOUSEKEEPING_NS = 300_000
    #: ... unless it is this late (a master whose frames leave no gap: it runs anyway)
    HOUSEKEEPING_OVERDUE_NS = 50_000_000

    def _housekeeping_may_run(self, pacing: Pacing, predict: bool, now: int, due: int) -> bool:
        """Housekeeping runs between frames, not in the spin around the next one: a frame
        that arrived during a pass waited for the pass (the loaded-host tail of the answer
        time).  With a learned cycle it waits for the gap after an answer."""
        if not predict or now - due > self.HOUSEKEEPING_OVERDUE_NS:
            return True
        window = pacing.window()
        return window is None or not (window[0] - self.HOUSEKEEPING_NS <= now < window[1])

    # --- receive, with the kernel's timestamp when there is one ------------------------
    _realtime_offset = 0

    def _sync_clocks(self) -> None:
        if self.stats.kernel_timestamps or self.pcap is not None:
            self._realtime_offset = time.clock_gettime_ns(time.CLOCK_REALTIME) - self.clock()

    def _wall(self, t: int) -> int:
        """Our clock -> wall-clock ns (pcap timestamps)."""
        return t + self._realtime_offset

    _ring: RxRing | None = None

    def _receiver(self, sock: socket.socket, view: memoryview) -> Callable[[], tuple[int, int]]:
        """``receive() -> (bytes, kernel receive time on our clock or 0)``: from a receive
        ring where the socket takes one (:mod:`gtecat.wire.rx_ring`), else ``recvmsg``
        with SO_TIMESTAMPNS, else plain ``recv_into``."""
        stamps = self.clock is time.monotonic_ns
        ring = self._ring = open_ring(sock) if self.use_ring else None
        if ring is not None:
            self.stats.kernel_timestamps = stamps
            self.stats.receive_path = "rx ring"
            take = ring.take
            if not stamps:

                def ringed_plain() -> tuple[int, int]:
                    return take(view)[0], 0

                return ringed_plain
            self._sync_clocks()

            def ringed() -> tuple[int, int]:
                n, t = take(view)
                return n, t - self._realtime_offset

            return ringed
        stamps = stamps and _ANC_SIZE > 0
        if stamps:
            try:
                sock.setsockopt(socket.SOL_SOCKET, SO_TIMESTAMPNS, 1)
            except OSError:
                stamps = False
        self.stats.kernel_timestamps = stamps
        if not stamps:
            self.stats.receive_path = "recv"
            recv_into = sock.recv_into

            def plain() -> tuple[int, int]:
                return recv_into(view), 0

            return plain
        self.stats.receive_path = "recvmsg"
        self._sync_clocks()
        recvmsg_into, unpack = sock.recvmsg_into, _TIMESPEC.unpack
        bufs = [view]

        def stamped() -> tuple[int, int]:
            n, anc, _flags, _addr = recvmsg_into(bufs, _ANC_SIZE)
            for level, kind, data in anc:
                if level == socket.SOL_SOCKET and kind == SCM_TIMESTAMPNS:
                    sec, nsec = unpack(data[: _TIMESPEC.size])
                    return n, sec * 1_000_000_000 + nsec - self._realtime_offset
            return n, 0

        return stamped

    def _guarded(self, fn: Callable[..., object], *args: object) -> None:
        """Slave-side work: a bug there is logged and counted, the loop goes on."""
        try:
            fn(*args)
        except Exception:
            self.stats.internal_errors += 1
            if self.stats.internal_errors <= 10:
                log.exception("error in %s; the chain keeps running", getattr(fn, "__name__", fn))

    def _receive_failed(self, exc: OSError) -> None:
        if exc.errno in (errno.ENODEV, errno.ENXIO):
            raise WireError(f"interface {self.iface!r} disappeared") from exc
        self.stats.receive_errors += 1  # e.g. ENETDOWN while the link is down: wait for it
        if self.stats.receive_errors <= 5:
            log.warning("receive failed: %s", exc)
        time.sleep(self.poll_s)

    def close(self) -> None:
        if self._ring is not None:
            self._ring.close()
            self._ring = None
        if self._sock is not None:
            self._sock.close()
            self._sock = None
        if self.pcap is not None:
            self.pcap.close()

    def _cpu_percent(self) -> float:
        """This process's CPU use since the records started (a whole core = 100)."""
        cpu0, t0 = self._cpu_mark
        wall = (self.clock() - t0) / 1e9
        return round(100 * (time.process_time() - cpu0) / wall, 1) if wall > 0 else 0.0

    def _steal_percent(self) -> float | None:
        """The share of the machine's CPU time stolen by the hypervisor since the records
        started (``None`` where /proc/stat says nothing)."""
        total0, steal0 = self._steal_mark
        total1, steal1 = host_steal()
        if total1 <= total0:
            return None
        return round(100 * (steal1 - steal0) / (total1 - total0), 2)

    def report(self) -> dict[str, object]:
        """Counters and latency, for ``--stats-json`` and the benchmark."""
        s = self.stats
        elapsed = max((s.stopped_ns or self.clock()) - s.started_ns, 1) / 1e9
        return {
            "iface": self.iface,
            "slaves": len(self.chain),
            "step_mode": self.step_mode,
            "elapsed_s": round(elapsed, 3),
            "received": s.received,
            "sent": s.sent,
            "send_errors": s.send_errors,
            "receive_errors": s.receive_errors,
            "internal_errors": s.internal_errors,
            "steps": s.steps,
            "answered_in_step": s.answered_in_step,
            "lingered": s.lingered,
            "frames_per_s": round(s.sent / elapsed, 1),
            "chain": self.chain.stats.as_dict(),
            "latency": s.latency.summary(),
            "latency_from": "kernel receive timestamp" if s.kernel_timestamps else "recv",
            "receive_path": s.receive_path,
            "wait": s.wait.summary(),
            "processing": s.processing.summary(),
            "send": s.send.summary(),
            "pid": os.getpid(),
            "snapshot": self.snapshots,
            "cpu_percent": self._cpu_percent(),
            "wait_mode": self.wait,
            "found": dict(zip(FOUND, s.found, strict=True)),
            "late": list(s.late),
            "host_steal_percent": self._steal_percent(),
            "pacing": {
                "period_us": round(self.pacing.period_ns / 1000, 1),
                "jitter_us": round(self.pacing.jitter_ns / 1000, 1),
                "missed_windows": self.pacing.misses,
                "margin_us": round(self.pacing.margin_ns / 1000, 1),
            },
        }
