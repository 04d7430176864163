"""The controller process: one virtual controller served over a Unix socket or TCP.

A :class:`Server` owns gt's in-process session (``SESSION``: bus, clock, axes) and
answers the calls of any number of clients (``libgts.so``, its ctypes users, other
tools), one request and one reply per GT call (:mod:`gtecat.native.protocol`).  Calls
are serialised (one selector thread, :attr:`Server.lock` held while a call runs), so
a call is atomic with respect to a cycle and every call, from whichever client,
costs the same virtual latency in ``auto`` mode.

The dispatcher calls the same Python GT functions as ``from gtecat import gt``, with
ctypes buffers of exactly the sizes the client's pointers have, so argument checks,
return codes and reasons are the Python ones.

Decisions:

* ``GT_Open`` of a client attaches it: the first one opens the controller (with the
  options the server was started with, else the ``GTECAT_*`` environment of the
  server), later clients find it open and return 0; a client that opens twice gets -6,
  as a Python program does.  ``GT_Close`` detaches the client;
  the controller stays (it is the device).  Calls of a client that has not opened
  (or has closed) return -1, as in Python before ``GT_Open``.
* **Cards** (:mod:`gtecat.controller.cards`): every call carries the card it addresses
  (the client's current card, ``GT_SetCardNo``, or the multi-card ABI's ``cardNum``).  A
  client opens each card it uses; the first client to open a card opens its controller,
  which stays when the client closes it.  ``GT_SetCardNo`` / ``GT_GetCardNo`` are the
  client's own setting (two programs on one controller do not share it).
* In ``auto`` mode the server keeps the wall floor (:mod:`gtecat.native.floor`)
  unless asked not to, so native clients that sleep between polls see time pass.
* **Scheduling** (:mod:`gtecat.scheduling`): the controller process
  (``gtecat controller``, the one libgts starts) gives :attr:`Server.realtime`, and the
  server then serves under SCHED_FIFO while other programs could hold every CPU
  (:data:`REALTIME_OVER_CPUS`; a normal process woken then may wait for another program's
  time slice) and under its
  normal policy, with its spin, otherwise; it never spins while real-time.  While the
  CPUs are that busy it also runs on the CPU of the client it served last, real-time or
  not (:attr:`Server.beside`, the client's process from the Unix socket), so that other
  programs, not the client, take the other CPUs.  A server inside
  another program (a test's) leaves the program's scheduling alone.
* Every client is served independently: its bytes are buffered until a frame is whole and
  its replies until it reads them, so a client that sends half a frame, or stops reading,
  delays nobody; it is dropped after :data:`IO_TIMEOUT_S`.
* Over TCP (:mod:`gtecat.native.transport`) a connection must present the token in its
  hello within :data:`AUTH_TIMEOUT_S`; before that, frames larger than a hello, any other
  message or a wrong token close it with a log line.
"""

from __future__ import annotations

import contextlib
import ctypes
import json
import logging
import os
import select
import socket
import struct
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from gtecat.eni.errors import GtecatError

from .. import scheduling
from ..controller.epoch import changed as readers_changed
from ..gt import _core, declared
from ..gt.fast import READERS, wire_reader
from ..inspect import endpoint as _inspect
from . import field as field_ops
from . import transport
from .floor import WallFloor
from .protocol import (
    BLOCK,
    CALL,
    CALL_GTN,
    CARD_SHIFT,
    CHUNK,
    F64,
    FIELD_REPLY,
    FRAME,
    HELLO,
    HELLO_REPLY,
    I64,
    MAX_FRAME,
    MSG_CALL,
    MSG_FIELD,
    MSG_HELLO,
    PROTOCOL_VERSION,
    PTR,
    PTR_NULL,
    PTR_TOO_BIG,
    PTR_UNKNOWN,
    FunctionPlan,
    Kind,
    element_type,
    plans,
    table_digest,
)

log = logging.getLogger("gtecat.native.server")

#: a client that sends half a frame, or stops reading replies, this long is dropped
IO_TIMEOUT_S = 10.0
#: a TCP connection that has not presented its token this long is dropped
AUTH_TIMEOUT_S = 5.0
#: the largest frame before the hello (a hello with the longest token fits)
MAX_HELLO_FRAME = 64 + transport.MAX_TOKEN
#: connections that have not greeted yet, at most (more are closed at once)
MAX_PENDING = 256
#: how long the server keeps serving one client before it looks at the others
#: (GTECAT_SERVER_SPIN_US; see Server._readable); by default only where this process
#: may run on two CPUs or more (on one, spinning keeps the client from sending)
DEFAULT_SPIN_US = 100


def _runnable_over_cpus() -> int:
    """Threads runnable now (/proc/loadavg's 4th field, this server among them) less the
    CPUs this process may use; 0 where it cannot be read."""
    try:
        with open("/proc/loadavg", encoding="ascii") as f:
            running = int(f.read().split()[3].split("/")[0])
        cpus = len(os.sched_getaffinity(0))
    except (OSError, ValueError, IndexError, AttributeError):
        return 0
    return running - cpus


#: runnable threads beyond the CPUs from which the server runs real-time (Server.realtime):
#: the server and its client count two while a client polls, so from here other programs
#: alone can hold every CPU.  (From one on, as the spin stops, the p50 on a machine shared
#: with lighter work rose from 10 to 24-31 us: a real-time wake-up costs more than a normal one.)
REALTIME_OVER_CPUS = 2


def default_spin_us() -> float:
    try:
        cpus = len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        cpus = os.cpu_count() or 1
    return DEFAULT_SPIN_US if cpus >= 2 else 0.0


NOT_OPEN = "this client has not opened the controller: call GT_Open first"
#: what a client sets for itself: its current card and the core of its GT_x calls
_OWN_SETTINGS = frozenset({"GT_SetCardNo", "GT_GetCardNo", "GT_SetCore", "GT_GetCore"})


class ProtocolError(Exception):
    """A client sent something this protocol does not allow; its connection is closed."""


_i64 = I64.unpack_from
#: let another thread run (Windows has no os.sched_yield; sleep(0) yields there)
_yield = getattr(os, "sched_yield", None) or (lambda: time.sleep(0))
_f64 = F64.unpack_from
_ptr = PTR.unpack_from
_byref = ctypes.byref

Step = Callable[[Any, int, list, list], int]


def _int_step(body: Any, pos: int, args: list, backs: list) -> int:
    args.append(_i64(body, pos)[0])
    return pos + 8


def _double_step(body: Any, pos: int, args: list, backs: list) -> int:
    args.append(_f64(body, pos)[0])
    return pos + 8


def _text_step(fname: str, name: str) -> Step:
    def step(body: Any, pos: int, args: list, backs: list) -> int:
        size = _ptr(body, pos)[0]
        pos += 4
        if size == PTR_NULL:
            args.append(None)
            return pos
        if size < 0 or pos + size > len(body):
            raise ProtocolError(f"{fname}: bad size {size} for {name}")
        args.append(bytes(body[pos : pos + size]))
        return pos + size

    return step


def _pointer_step(fname: str, name: str, elem: Any, back: bool, any_size: bool) -> Step:
    """One pointer parameter: its bytes become a ctypes object of the client's size, passed
    as ``byref`` (the binder's fast path); a single element (``&sts``) is the usual case."""
    one = ctypes.sizeof(elem)
    copy_one = elem.from_buffer_copy
    types: dict[int, Any] = {}

    def array(size: int) -> Any:
        t = types.get(size)
        if t is None:
            t = types[size] = elem * (size // one) if size % one == 0 else ctypes.c_ubyte * size
        return t

    def step(body: Any, pos: int, args: list, backs: list) -> int:
        size = _ptr(body, pos)[0]
        pos += 4
        if size == one and pos + one <= len(body):
            obj = copy_one(body, pos)
            args.append(_byref(obj))
            if back:
                backs.append(obj)
            return pos + one
        if size == PTR_NULL:
            args.append(None)
            if back:
                backs.append(None)
            return pos
        if size == PTR_UNKNOWN:
            if not any_size:
                raise ProtocolError(f"{fname}: size unknown for {name}")
            buf: list = []  # grows to what the call writes
            args.append(buf)
            backs.append(buf)
            return pos
        if size == PTR_TOO_BIG:
            obj = array(0)()  # refused by the call's room check
        elif size < 0 or pos + size > len(body):
            raise ProtocolError(f"{fname}: bad size {size} for {name}")
        else:
            obj = array(size).from_buffer_copy(body, pos) if size else array(0)()
            pos += size
        args.append(_byref(obj))
        if back:
            backs.append(obj)
        return pos

    return step


class _Decoder:
    """One function's request layout for one client ``long`` size, compiled once into a
    step per parameter."""

    __slots__ = ("fast", "fn_gt", "fn_gtn", "plan", "steps")

    def __init__(self, plan: FunctionPlan, long_size: int) -> None:
        self.plan = plan
        steps: list[Step] = []
        for a in plan.args:
            p = a.param
            if a.kind is Kind.INT:
                steps.append(_int_step)
            elif a.kind is Kind.DOUBLE:
                steps.append(_double_step)
            elif a.kind is Kind.TEXT:
                steps.append(_text_step(plan.name, p.name))
            else:
                elem = element_type(p.ctype, long_size)
                steps.append(
                    _pointer_step(plan.name, p.name, elem, a.carries_back, a.kind is Kind.OUT_ANY)
                )
        self.steps = tuple(steps)
        self.fn_gt = _core.REGISTRY.get(plan.name)
        self.fn_gtn = _core.REGISTRY.get("GTN_" + plan.name[3:]) if plan.proto.gtn else None
        #: the common request shape answered without decoding (gtecat.gt.fast), GT_ only
        self.fast = (
            wire_reader(plan.name, long_size, _core.SESSION)
            if plan.name in READERS and not _core.TAPPED
            else None
        )

    def decode(self, body: Any, pos: int) -> tuple[list[Any], list[Any]]:
        """(arguments for the GT function, out-buffers in order; None for NULL)."""
        args: list[Any] = []
        backs: list[Any] = []
        try:
            for step in self.steps:
                pos = step(body, pos, args, backs)
        except (struct.error, ValueError) as e:
            raise ProtocolError(f"{self.plan.name}: a request cut short ({e})") from None
        if pos != len(body):
            raise ProtocolError(
                f"{self.plan.name}: {len(body) - pos} bytes left after the arguments"
            )
        return args, backs


@dataclass(eq=False)
class _Client:
    #: None for the program's own connection to an in-process controller (answer)
    sock: socket.socket
    peer: str
    buf: bytearray = field(default_factory=bytearray)
    long_size: int = 0  # 0 until the hello
    #: the cards this client has opened (GT_Open after GT_SetCardNo, or cardNum)
    cards: set[int] = field(default_factory=set)
    decoders: dict[int, _Decoder] = field(default_factory=dict)
    #: reply bytes the client has not read yet (while any wait, its requests wait too)
    out: bytearray = field(default_factory=bytearray)
    #: per card: its traces
    fields: dict[int, field_ops.Context] = field(default_factory=dict)
    #: may call (a Unix socket client at once; a TCP client once its token was right)
    authed: bool = True
    #: monotonic time by which it must have greeted / completed its frame / read its
    #: replies, 0: none pending
    deadline: float = 0.0
    why_late: str = ""
    #: the client's process id where the socket tells it (Unix socket on Linux), else 0
    pid: int = 0


def _peer_pid(sock: socket.socket) -> int:
    """The process id at the other end of a Unix socket (SO_PEERCRED); 0 where unknown."""
    opt = getattr(socket, "SO_PEERCRED", None)
    if opt is None or sock.family != getattr(socket, "AF_UNIX", None):
        return 0
    try:
        return struct.unpack("3i", sock.getsockopt(socket.SOL_SOCKET, opt, 12))[0]
    except (OSError, struct.error):
        return 0


class _DropLog:
    """One log line per dropped connection, at most ``burst`` per ``window_s`` (a flood of
    bad connections must not become a flood of log lines); then a count."""

    def __init__(self, burst: int = 20, window_s: float = 10.0) -> None:
        self.burst, self.window_s = burst, window_s
        self.start, self.count, self.hidden = 0.0, 0, 0

    def __call__(self, level: int, text: str, *args: Any) -> None:
        now = time.monotonic()
        if now - self.start > self.window_s:
            if self.hidden:
                log.warning("%d more connections dropped in %.0f s", self.hidden, self.window_s)
            self.start, self.count, self.hidden = now, 0, 0
        self.count += 1
        if self.count <= self.burst:
            log.log(level, text, *args)
        else:
            self.hidden += 1


_REPLY_HEAD = struct.Struct("<IhHH")  # FRAME + REPLY
_REPLY_OK = _REPLY_HEAD.pack(6, 0, 0, 0)
_BLOCK = BLOCK.pack


def _reply(rc: int, backs: list[Any], text: str) -> bytes:
    t = text.encode("utf-8", "replace")[:4000] if text else b""
    if not backs:
        return _REPLY_OK if rc == 0 and not t else _REPLY_HEAD.pack(6 + len(t), rc, 0, len(t)) + t
    parts = [b""]
    n = 0
    total = 6 + len(t)
    for b in backs:
        if b is None:
            continue
        data = bytes(b) if type(b) is not list else bytes(int(v) & 0xFF for v in b)
        parts.append(_BLOCK(len(data)))
        parts.append(data)
        n += 1
        total += 4 + len(data)
    parts[0] = _REPLY_HEAD.pack(total, rc, n, len(t))
    parts.append(t)
    return b"".join(parts)


def _jsonable(v: Any) -> Any:
    """What json cannot write itself: numpy numbers and arrays, enums, dataclasses, bytes."""
    if hasattr(v, "tolist"):
        return v.tolist()
    if isinstance(v, bytes | bytearray):
        return bytes(v).hex()
    if hasattr(v, "__dataclass_fields__"):
        import dataclasses

        return dataclasses.asdict(v)
    return str(v)


#: poller events: the descriptor can be read (or hung up), can be written
READ, WRITE = 1, 4


class _Poller:
    """epoll where there is one (Linux), poll elsewhere, select on Windows: fd -> events
    (:data:`READ` / :data:`WRITE`); a descriptor waits for one of the two."""

    def __init__(self) -> None:
        self._ep = select.epoll() if hasattr(select, "epoll") else None
        self._p = select.poll() if self._ep is None and hasattr(select, "poll") else None
        self._sel: dict[int, bool] = {}  # select: fd -> waits for WRITE

    def register(self, fd: int, writable: bool = False) -> None:
        if self._ep is not None:
            self._ep.register(fd, select.EPOLLOUT if writable else select.EPOLLIN)
        elif self._p is not None:
            self._p.register(fd, select.POLLOUT if writable else select.POLLIN)
        else:
            self._sel[fd] = writable

    def modify(self, fd: int, writable: bool) -> None:
        if self._ep is not None:
            self._ep.modify(fd, select.EPOLLOUT if writable else select.EPOLLIN)
        elif self._p is not None:
            self._p.modify(fd, select.POLLOUT if writable else select.POLLIN)
        else:
            self._sel[fd] = writable

    def unregister(self, fd: int) -> None:
        with contextlib.suppress(OSError, KeyError, ValueError):
            if self._ep is not None:
                self._ep.unregister(fd)
            elif self._p is not None:
                self._p.unregister(fd)
            else:
                del self._sel[fd]

    def poll(self, timeout_s: float | None) -> list[tuple[int, int]]:
        if self._ep is not None:
            out = select.EPOLLOUT
            got = self._ep.poll(-1 if timeout_s is None else timeout_s)
        elif self._p is not None:
            out = select.POLLOUT
            got = self._p.poll(None if timeout_s is None else int(timeout_s * 1000))
        else:
            rd = [fd for fd, w in self._sel.items() if not w]
            wr = [fd for fd, w in self._sel.items() if w]
            r, w, x = select.select(rd, wr, wr, timeout_s)
            return [(fd, READ) for fd in r] + [(fd, WRITE) for fd in {*w, *x}]
        return [(fd, (WRITE if ev & out else 0) | (READ if ev & ~out else 0)) for fd, ev in got]

    def close(self) -> None:
        if self._ep is not None:
            self._ep.close()


class Server:
    """Serve the in-process GT session on ``address`` (see the module docstring)."""

    def __init__(
        self,
        address: str,
        *,
        open_options: dict[str, Any] | None = None,
        wall_floor: bool = True,
        lifeline_fd: int | None = None,
        remove_dir: bool = False,
        spin_us: float | None = None,
        token: str | None = None,
    ) -> None:
        addr = transport.parse(address)
        if addr.tcp and not token:
            raise ValueError("a controller on TCP needs a token (transport.make_token())")
        if token is not None:
            transport.check_token(token, "the token")
        self.token = token.encode() if addr.tcp and token else None
        self.path = addr.path
        self.open_options = dict(open_options or {})
        self.wall_floor = wall_floor
        if spin_us is None:
            env = os.environ.get("GTECAT_SERVER_SPIN_US", "")
            try:
                spin_us = float(env) if env else default_spin_us()
            except ValueError:
                log.warning("GTECAT_SERVER_SPIN_US=%r is not a number; using the default", env)
                spin_us = default_spin_us()
        self.spin_s = max(0.0, spin_us) / 1e6
        self._budget = self.spin_s  # the adaptive spin (_spin_budget)
        self._busy, self._busy_next, self._since_probe = False, 0.0, 0
        #: SCHED_FIFO while the CPUs are busy (set by the controller process before it
        #: serves; never for a server inside another program, a test's)
        self.realtime: scheduling.WhenBusy | None = None
        #: on the client's CPU while the CPUs are busy (set by the controller process)
        self.beside: scheduling.Beside | None = None
        self._served_pid = 0  # the process of the client served last
        self.lock = threading.RLock()
        #: clients whose call is running (a GTE_Wait serving others between its slices
        #: runs their calls inside it: :meth:`_serve_others`)
        self._running: list[_Client] = []
        # its endpoint (gtecat ps) says "controller" while it serves; given back when it stops
        self._inspect_before = (_inspect.KIND, _inspect.LOCK)
        _inspect.KIND, _inspect.LOCK = "controller", self.lock
        self.calls = 0
        self._floor: WallFloor | None = None
        self._floor_clock: Any = None
        self._lifeline = lifeline_fd
        self._remove_dir = remove_dir
        self._stop = threading.Event()
        self._wake_r, self._wake_w = socket.socketpair()  # select on Windows takes sockets only
        self._wake_r.setblocking(False)
        self._drop_log = _DropLog()
        self._thread: threading.Thread | None = None
        self._serving = 0  # the thread that serves the sockets (serve_forever's)
        self._clients: dict[int, _Client] = {}  # by file descriptor
        self._decoders: dict[tuple[int, int], _Decoder] = {}  # (long size, fid)
        self._poller = _Poller()
        self._listener = transport.listen(addr)
        self.addr = transport.bound(addr, self._listener)
        #: the address clients reach (with the chosen port for tcp:HOST:0)
        self.address = str(self.addr) if addr.tcp else address

    def fileno(self) -> int:
        return self._listener.fileno()

    # --- the loop ------------------------------------------------------------------------
    def serve_forever(self) -> None:
        self._serving = threading.get_ident()
        self._bound_spin(scheduling.is_realtime())
        poller = self._poller
        poller.register(self._listener.fileno())
        poller.register(self._wake_r.fileno())
        if self._lifeline is not None:
            poller.register(self._lifeline)
        try:
            while not self._stop.is_set():
                floor = self._current_floor()
                timeout = floor.idle_timeout() if floor is not None else None
                late = self._next_deadline()
                if late is not None:
                    left = max(0.0, late - time.monotonic())
                    timeout = left if timeout is None else min(timeout, left)
                events = poller.poll(timeout)
                if late is not None:
                    self._drop_late()
                if not events and floor is not None:
                    with self.lock:
                        floor.look()
                    continue
                for fd, ev in events:
                    self._event(fd, ev, self._readable)
        finally:
            self._cleanup()

    def _bound_spin(self, started_realtime: bool) -> None:
        """A server started real-time (``chrt``) and not switching by itself: its spin
        holds its CPU against everything else, so it spins at most RT_SPIN_CAP_US."""
        if self.realtime is None and started_realtime:
            self.spin_s = min(self.spin_s, scheduling.RT_SPIN_CAP_US / 1e6)
            self._budget = min(self._budget, self.spin_s)

    def _event(self, fd: int, ev: int, read: Callable[[_Client], None]) -> None:
        """One poller event: a client's (``read`` serves what it sent), a connection, the
        wake-up, or the lifeline."""
        c = self._clients.get(fd)
        if c is not None:
            if ev & WRITE:
                self._writable(c)
            elif ev & READ:
                read(c)
        elif fd == self._listener.fileno():
            self._accept()
        elif fd == self._wake_r.fileno():
            with contextlib.suppress(OSError):
                self._wake_r.recv(64)
        elif fd == self._lifeline:
            if not os.read(self._lifeline, 64):
                log.info("the program that started this controller has ended")
                self._stop.set()

    def _serve_others(self) -> None:
        """Between the slices of a long GTE_Wait (Controller.slice_hook): answer what the
        other clients sent meanwhile and take new connections, without waiting and without
        the spin, so a day's wait by one client delays no other by more than a slice.
        Their calls run inside the wait (their time counts toward it); a client whose call
        is running is left for later, and a wait inside such a call serves nobody."""
        if len(self._running) != 1 or self._stop.is_set():
            return
        if threading.get_ident() != self._serving:
            return  # a call of an in-process program: the serving thread reads the sockets
        busy = self._running[0]
        for fd, ev in self._poller.poll(0):
            if self._clients.get(fd) is not busy:
                self._event(fd, ev, self._read_once)

    def _read_once(self, c: _Client) -> None:
        """Serve what ``c`` sent, without :meth:`_readable`'s spin for its next request."""
        try:
            data = c.sock.recv(CHUNK)
        except BlockingIOError:
            return
        except OSError:
            data = b""
        if not data:
            self._drop(c)
        else:
            self._frames(c, data)

    def _next_deadline(self) -> float | None:
        late = [c.deadline for c in self._clients.values() if c.deadline]
        return min(late) if late else None

    def _drop_late(self) -> None:
        now = time.monotonic()
        for c in [c for c in self._clients.values() if c.deadline and c.deadline <= now]:
            self._drop_log(logging.WARNING, "client %s: %s; connection closed", c.peer, c.why_late)
            self._drop(c)

    def start(self) -> Server:
        """Serve from a background thread (tests, a Python program hosting the controller)."""
        self._thread = threading.Thread(
            target=self.serve_forever, name="gtecat-server", daemon=True
        )
        self._thread.start()
        return self

    def stop(self) -> None:
        self._stop.set()
        with contextlib.suppress(OSError):
            self._wake_w.send(b"x")
        if self._thread is not None and self._thread is not threading.current_thread():
            self._thread.join(timeout=5)

    def __enter__(self) -> Server:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()

    def _cleanup(self) -> None:
        if _inspect.LOCK is self.lock:  # a server in a process that goes on (a test's)
            _inspect.KIND, _inspect.LOCK = self._inspect_before
        for c in list(self._clients.values()):
            self._drop(c)
        with contextlib.suppress(Exception):
            self._poller.close()
        self._listener.close()
        if self.path and not self.path.startswith("\0"):
            with contextlib.suppress(OSError):
                os.unlink(self.path)
            if self._remove_dir:
                with contextlib.suppress(OSError):
                    Path(self.path).parent.rmdir()
        for s in (self._wake_r, self._wake_w):
            s.close()

    def _accept(self) -> None:
        for _ in range(64):  # a burst of connections, without starving the clients
            try:
                sock, _ = self._listener.accept()
            except (BlockingIOError, InterruptedError):
                return
            except OSError as e:  # out of descriptors: the others go on
                self._drop_log(logging.WARNING, "cannot accept a connection: %s", e)
                return
            sock.setblocking(False)
            peer = transport.peer_name(sock, f"fd {sock.fileno()}")
            client = _Client(sock, peer=peer, pid=_peer_pid(sock))
            if self.token is not None:
                transport.tune(sock)
                pending = sum(1 for c in self._clients.values() if not c.authed)
                if pending >= MAX_PENDING:
                    self._drop_log(
                        logging.WARNING,
                        "client %s: %d connections have not greeted yet; connection closed",
                        peer,
                        pending,
                    )
                    sock.close()
                    continue
                client.authed = False
                client.deadline = time.monotonic() + AUTH_TIMEOUT_S
                client.why_late = f"no hello with a token within {AUTH_TIMEOUT_S:g} s"
            self._clients[sock.fileno()] = client
            self._poller.register(sock.fileno())

    def _drop(self, c: _Client) -> None:
        if c.sock.fileno() < 0:
            return  # dropped already
        if self._clients.pop(c.sock.fileno(), None) is not None:
            self._poller.unregister(c.sock.fileno())
        if c.fields:
            with self.lock:
                for ctx in c.fields.values():
                    ctx.stop_traces()
        c.sock.close()

    # --- the program's own connection (an in-process controller: gtecat.native.inprocess) -
    def local_client(self) -> _Client:
        """A connection of this process that sends its frames by :meth:`answer`."""
        return _Client(None, peer="this program", pid=os.getpid())  # type: ignore[arg-type]

    def answer(self, c: _Client, frame: bytes) -> bytes:
        """The reply frame to one request frame of ``c`` (length prefix included) on the
        caller's thread; b"" for a frame the protocol does not allow (logged)."""
        try:
            if len(frame) < 4 or FRAME.unpack_from(frame, 0)[0] != len(frame) - 4:
                raise ProtocolError("a frame whose length is not its size")
            return self._message(c, memoryview(frame)[4:])
        except ProtocolError as e:
            log.warning("client %s: %s", c.peer, e)
            return b""

    def forget(self, c: _Client) -> None:
        """``c`` closed its connection: its traces stop (its cards go with it)."""
        if c.fields:
            with self.lock:
                for ctx in c.fields.values():
                    ctx.stop_traces()
        c.fields.clear()
        c.cards.clear()

    def _spin_budget(self) -> float:
        """Seconds to spin for this client's next request (and, every 10 ms, the look at
        the load that also switches :attr:`realtime`): none while more threads are
        runnable than this process has CPUs (spinning would take the CPU the client waits
        for), half the last one after a spin that found nothing (a short probe every 256
        rounds once it is none), up to ``spin_s``."""
        now = time.monotonic()
        if now >= self._busy_next:
            self._busy_next = now + 0.01
            over = _runnable_over_cpus()
            self._busy = over > 0
            crowded = over >= REALTIME_OVER_CPUS
            if self.realtime is not None:
                self.realtime.busy(crowded)
            if self.beside is not None:
                pid = self._served_pid if crowded else 0
                self.beside.look(
                    pid > 0,
                    scheduling.thread_cpu() if pid else None,
                    scheduling.thread_cpu(pid) if pid else None,
                )
        if not self.spin_s or self._busy:
            return 0.0
        if not self._budget:
            self._since_probe += 1
            if self._since_probe < 256:
                return 0.0
            self._since_probe = 0
            return self.spin_s / 8
        return self._budget

    def _spin_done(self, found: bool) -> None:
        if found:
            self._budget = min(self.spin_s, max(self._budget * 2, self.spin_s / 8))
        else:
            self._budget = self._budget / 2 if self._budget / 2 >= 1e-6 else 0.0

    def _readable(self, c: _Client) -> None:
        """Serve what ``c`` sent; then, for ``spin_s``, serve its next request at once
        (a client polling in a loop sends it within microseconds; answering it without
        a round through the poller, and without either side falling asleep, saves the
        wake-up).  Without a spin (:meth:`_spin_budget` 0: the CPUs are busy) it goes back
        to the poller at once after a reply: the read that would find nothing yet costs a
        system call and an exception per call, and the poller reports the next request."""
        recv = c.sock.recv
        self._served_pid = c.pid
        deadline = 0.0
        budget = 0.0  # this round's spin; asked for once a request was served
        while True:
            try:
                data = recv(CHUNK)
            except BlockingIOError:
                if not budget:
                    return
                now = time.perf_counter()
                if not deadline:
                    deadline = now + budget
                if now >= deadline:
                    self._spin_done(False)
                    return
                _yield()  # the client first, where it shares this CPU
                continue
            except OSError:
                data = b""
            if not data:
                self._drop(c)
                return
            if deadline:
                self._spin_done(True)
            deadline = 0.0
            if not self._frames(c, data) or c.out or c.buf:
                return  # dropped, or waiting for the client to read or to send the rest
            budget = self._spin_budget()
            if not budget:
                return

    def _frames(self, c: _Client, data: bytes) -> bool:
        """Answer every whole frame in the client's buffer; False once it is dropped.  A
        frame not yet whole waits in the buffer (the client has IO_TIMEOUT_S to send the
        rest); while the client has not read a reply, its next requests wait unread."""
        buf = c.buf
        try:
            if (
                not buf
                and c.authed
                and len(data) >= 4
                and FRAME.unpack_from(data, 0)[0] == len(data) - 4
            ):
                # the usual case: exactly one whole request in one record
                self._send(c, self._message(c, memoryview(data)[4:]))
                return True
            buf += data
            limit = MAX_FRAME if c.authed else MAX_HELLO_FRAME
            while len(buf) >= 4 and not c.out:
                (n,) = FRAME.unpack_from(buf, 0)
                if n > limit:
                    where = "" if c.authed else " before the hello"
                    raise ProtocolError(f"frame of {n} bytes{where}")
                if len(buf) < 4 + n:
                    if not c.deadline:
                        c.deadline = time.monotonic() + IO_TIMEOUT_S
                        c.why_late = f"a frame cut short (no more bytes within {IO_TIMEOUT_S:g} s)"
                    return True
                body = memoryview(bytes(buf[4 : 4 + n]))
                del buf[: 4 + n]
                self._send(c, self._message(c, body))
            if not c.out and c.authed and len(buf) < 4:
                c.deadline = 0.0
        except ProtocolError as e:
            self._drop_log(logging.WARNING, "client %s: %s; connection closed", c.peer, e)
            self._drop(c)
            return False
        except OSError as e:
            self._drop_log(logging.INFO, "client %s: %s; connection closed", c.peer, e)
            self._drop(c)
            return False
        return c.sock.fileno() >= 0

    def _send(self, c: _Client, data: bytes) -> None:
        """Send a reply in records of at most CHUNK bytes; what the client does not take now
        waits in its outbox (sent when it can take more; dropped after IO_TIMEOUT_S)."""
        if not c.out and len(data) <= CHUNK:  # the usual case: one record, sent at once
            try:
                n = c.sock.send(data)
            except BlockingIOError:
                n = 0
            if n == len(data):
                return
            data = data[n:]
        c.out += data
        self._flush(c)

    def _flush(self, c: _Client) -> None:
        out = c.out
        while out:
            try:
                n = c.sock.send(out[:CHUNK])
            except BlockingIOError:
                break
            del out[:n]
        if out:
            if not c.deadline or not c.why_late.startswith("does not read"):
                c.deadline = time.monotonic() + IO_TIMEOUT_S
                c.why_late = f"does not read its replies (none taken for {IO_TIMEOUT_S:g} s)"
            self._poller.modify(c.sock.fileno(), True)

    def _writable(self, c: _Client) -> None:
        try:
            self._flush(c)
        except OSError as e:
            self._drop_log(logging.INFO, "client %s: %s; connection closed", c.peer, e)
            self._drop(c)
            return
        if c.out:
            return
        c.deadline = 0.0
        self._poller.modify(c.sock.fileno(), False)
        if c.buf:  # requests that arrived while it was not reading
            self._frames(c, b"")

    # --- messages ------------------------------------------------------------------------
    def _message(self, c: _Client, body: memoryview) -> bytes:
        if not body:
            raise ProtocolError("empty frame")
        kind = body[0]
        if not c.authed and kind != MSG_HELLO:
            raise ProtocolError(f"message type {kind} before the hello with the token")
        if kind == MSG_CALL and c.long_size:
            _, flags, fid, core = CALL.unpack_from(body, 0)
            gtn, card = flags & CALL_GTN, flags >> CARD_SHIFT
            dec = c.decoders.get(fid)
            if dec is None:
                dec = c.decoders[fid] = self._decoder(c.long_size, fid)
            if dec.fast is not None and card in c.cards and not gtn and core == 1:
                with self.lock:
                    if self.wall_floor:
                        floor = self._current_floor()
                        if floor is not None:
                            floor.look()
                    session = _core.SESSION
                    if card == session.card:
                        out = dec.fast(body)
                    else:
                        with session.selected(card):
                            out = dec.fast(body)
                if out is not None:
                    self.calls += 1
                    return out
            args, backs = dec.decode(body, CALL.size)
            with self.lock:
                for ctl in _core.SESSION.all_controllers():
                    ctl.slice_hook = self._serve_others
                self._running.append(c)
                try:
                    # the client's card and, for GT_x, its core (gtecat.controller.cards);
                    # this process's own stay
                    with _core.SESSION.selected(card, None if gtn else core):
                        rc, text = self._call(c, dec, gtn, core, args)
                finally:
                    self._running.pop()
            return _reply(rc, backs, text)
        if kind == MSG_HELLO:
            return self._hello(c, body)
        if kind == MSG_FIELD:
            return self._field(c, body)
        if kind == MSG_CALL:
            raise ProtocolError("a call before the hello")
        raise ProtocolError(f"message type {kind}")

    def _decoder(self, long_size: int, fid: int) -> _Decoder:
        key = (long_size, fid)
        dec = self._decoders.get(key)
        if dec is None:
            table = plans()
            if fid >= len(table):
                raise ProtocolError(f"function id {fid} unknown")
            dec = self._decoders[key] = _Decoder(table[fid], long_size)
        return dec

    def _hello(self, c: _Client, body: memoryview) -> bytes:
        if len(body) < HELLO.size:
            raise ProtocolError("a hello cut short")
        _, version, long_size, digest = HELLO.unpack_from(body, 0)
        if not c.authed:
            self._check_token(c, body)
        status, text = 0, ""
        if version != PROTOCOL_VERSION or digest.decode("ascii", "replace") != table_digest():
            status = 1
            text = (
                f"libgts was built from another gtecat (protocol {version}, table "
                f"{digest.decode('ascii', 'replace')}); this controller speaks protocol "
                f"{PROTOCOL_VERSION}, table {table_digest()}: rebuild the program against "
                "`python3 -m gtecat lib --cflags --libs` of this gtecat"
            )
        elif long_size not in (4, 8):
            status, text = 1, f"sizeof(long) = {long_size} is not supported"
        else:
            c.long_size = long_size
        t = text.encode()
        out = HELLO_REPLY.pack(status, len(t)) + t
        return FRAME.pack(len(out)) + out

    def _check_token(self, c: _Client, body: memoryview) -> None:
        """The hello's token (``u16 length, bytes`` after the hello) against ours: right, the
        client may call; wrong or missing, it is told so and dropped."""
        assert self.token is not None
        given = b""
        tail = bytes(body[HELLO.size :])
        if len(tail) >= 2:
            (n,) = struct.unpack_from("<H", tail, 0)
            given = tail[2 : 2 + n]
        if transport.tokens_equal(given, self.token):
            c.authed = True
            c.deadline = 0.0
            return
        why = "a wrong token" if given else "no token"
        text = (
            f"this controller needs its token ({why} was given): set GTECAT_TOKEN or "
            "GTECAT_TOKEN_FILE, or token / token_file in gtecat.ini"
        ).encode()
        out = HELLO_REPLY.pack(1, len(text)) + text
        with contextlib.suppress(OSError):
            c.sock.send(FRAME.pack(len(out)) + out)
        raise ProtocolError(f"hello with {why}")

    def _field(self, c: _Client, body: memoryview) -> bytes:
        """A field-side or bus operation (:mod:`gtecat.native.field`)."""
        try:
            req = json.loads(bytes(body[1:]).decode("utf-8"))
            op, args = str(req["op"]), list(req.get("args", []))
            card = int(req.get("card", 0))
        except (ValueError, KeyError, TypeError) as e:
            raise ProtocolError(f"a field request that is not JSON {{op, args}}: {e}") from None
        status, result = 0, None
        with self.lock:
            ctl = _core.SESSION.cards.get(card, {}).get(1)  # the card's machine
            if ctl is None:
                status, result = (
                    1,
                    (
                        f"card {card} is not open (no client has opened it)"
                        if card
                        else "the controller is not open yet (no client has called GT_Open)"
                    ),
                )
            else:
                ctx = c.fields.get(card)
                if ctx is None or ctx.ctl is not ctl:
                    if ctx is not None:
                        ctx.stop_traces()
                    ctx = c.fields[card] = field_ops.Context(ctl)
                try:
                    result = field_ops.run(ctx, op, args)
                except GtecatError as e:
                    status, result = 1, str(e)
                except Exception as e:  # a field operation never takes the controller down
                    log.exception("field operation %s failed", op)
                    status, result = 1, f"internal error in the emulator: {type(e).__name__}: {e}"
                # (an SDO download, a register write, an input set: what the readers answer
                # and whether the bus is steady may have changed - controller/epoch.py)
                readers_changed()
        text = json.dumps(result, default=_jsonable).encode("utf-8")
        out = FIELD_REPLY.pack(status) + text
        return FRAME.pack(len(out)) + out

    def _call(
        self, c: _Client, dec: _Decoder, gtn: int, core: int, args: list[Any]
    ) -> tuple[int, str]:
        plan = dec.plan
        self.calls += 1
        if plan.declared:  # the same code whether or not the client opened (gt.declared)
            name = plan.proto.twin_name if gtn else plan.name
            code, why = declared.note(name)
            return code, f"{name} returned {code}: {why}"
        if plan.name in _OWN_SETTINGS:  # the client's own setting
            return _invoke(dec.fn_gtn, (core, *args)) if gtn else _invoke(dec.fn_gt, args)
        card = _core.SESSION.card
        if card not in c.cards or plan.name in ("GT_Open", "GT_Close", "GTN_OpenCard"):
            return self._open_close(c, dec, gtn, core, args)
        if plan.unsupported:  # the arguments are checked first, as in Python
            why = plan.null_refusal(args)
            if why is not None:
                return _core.CMD_PARAM, f"{plan.name} returned 7: {why}"
            return _core.CMD_ERROR, plan.unsupported
        fn = dec.fn_gtn if gtn else dec.fn_gt
        if fn is None:
            return _core.CMD_NO_RESPONSE, f"{plan.name}: not implemented by this gtecat"
        if self.wall_floor:
            floor = self._current_floor()
            if floor is not None:
                floor.look()
        rc = fn(core, *args) if gtn else fn(*args)
        if rc == 0:
            return 0, ""
        e = _core.SESSION.last
        return rc, (f"{e.function} returned {e.code}: {e.reason}" if e is not None else "")

    def _open_close(
        self, c: _Client, dec: _Decoder, gtn: int, core: int, args: list[Any]
    ) -> tuple[int, str]:
        name = dec.plan.name
        if name == "GTN_OpenCard":  # the GSN-E form of GT_Open; its arguments are reserved
            return self._open(c, 0, 1, [])
        if name in ("GT_Open", "GT_Close"):
            if gtn and core != 1:  # the Python twin refuses it (7) before doing anything
                return _invoke(dec.fn_gtn, (core, *args))
            if name == "GT_Open":
                return self._open(c, gtn, core, args)
            c.cards.discard(_core.SESSION.card)
            return 0, ""
        card = _core.SESSION.card
        if card:
            return _core.CMD_COMM, (
                f"{name} returned -1: this client has not opened card {card}: call GT_Open "
                f"after GT_SetCardNo({card})"
            )
        return _core.CMD_COMM, f"{name} returned -1: {NOT_OPEN}"

    def _open(self, c: _Client, gtn: int, core: int, args: list[Any]) -> tuple[int, str]:
        card = _core.SESSION.card
        if card in c.cards:  # as in Python: the same program opening twice
            return _core.CMD_OPEN, (
                f"GT_Open returned -6: {f'card {card}' if card else 'the controller'} is "
                "already open (GT_Open called twice; call GT_Close first)"
            )
        if 1 not in _core.SESSION.controllers:
            opener = _core.REGISTRY["GT_Open"]
            # "local": this process is the controller, whatever GTECAT_CONTROLLER says
            # another card: the first card's options and its description
            # (gtecat.controller.cards), not the options the server gives the first
            first = card == 0 or _core.SESSION.base_options is None
            rc = opener(*args, controller="local", **(self.open_options if first else {}))
            if rc != 0:
                e = _core.SESSION.last
                return rc, (f"GT_Open returned {rc}: {e.reason}" if e else "")
        c.cards.add(card)
        return 0, ""

    # --- time ----------------------------------------------------------------------------
    def _current_floor(self) -> WallFloor | None:
        if not self.wall_floor:
            return None
        ctl = _core.SESSION.first()  # every card shares its time
        if ctl is None:
            return None
        if ctl.clock is not self._floor_clock:
            self._floor_clock = ctl.clock
            self._floor = WallFloor(ctl.clock)
        floor = self._floor
        return floor if floor is not None and floor.active else None


def _invoke(fn: Any, args: Any) -> tuple[int, str]:
    """Call a GT function; its code and, when it is not 0, the reason it recorded."""
    rc = fn(*args)
    e = _core.SESSION.last
    if rc != 0 and e is not None:
        return rc, f"{e.function} returned {e.code}: {e.reason}"
    return rc, ""


def wait_for(address: str, timeout_s: float = 10.0) -> None:
    """Return once something accepts connections at ``address`` (TimeoutError otherwise)."""
    addr = transport.parse(address)
    deadline = time.monotonic() + timeout_s
    while True:
        try:
            transport.connect(addr, 1.0).close()
            return
        except OSError:
            if time.monotonic() > deadline:
                raise TimeoutError(f"no controller at {address} after {timeout_s:g} s") from None
            time.sleep(0.01)


__all__ = ["NOT_OPEN", "ProtocolError", "Server", "wait_for"]
