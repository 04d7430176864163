"""The controller process: one virtual controller served over a Unix socket.

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
* In ``auto`` mode the server keeps the wall floor (:mod:`gtecat.native.floor`)
  unless asked not to, so native clients that sleep between polls see time pass.
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

from ..gt import _core, declared
from ..gt.fast import READERS, wire_reader
from ..inspect import endpoint as _inspect
from . import field as field_ops
from .floor import WallFloor
from .protocol import (
    BLOCK,
    CALL,
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
    SOCKET_TYPE,
    FunctionPlan,
    Kind,
    element_type,
    plans,
    socket_path,
    table_digest,
)

log = logging.getLogger("gtecat.native.server")

#: a client that sends half a frame, or stops reading replies, this long is dropped
IO_TIMEOUT_S = 10.0
#: how long the server keeps serving one client before it looks at the others
#: (GTECAT_SERVER_SPIN_US; see Server._readable); by default only where this process
#: may run on two CPUs or more (on one, spinning keeps the client from sending)
DEFAULT_SPIN_US = 100


def _cpus_busy() -> bool:
    """More threads runnable than this process may use CPUs (/proc/loadavg's 4th field)."""
    try:
        with open("/proc/loadavg", encoding="ascii") as f:
            running = int(f.read().split()[3].split("/")[0])
        cpus = len(os.sched_getaffinity(0))
    except (OSError, ValueError, IndexError, AttributeError):
        return False
    return running > cpus


def default_spin_us() -> float:
    try:
        cpus = len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        cpus = os.cpu_count() or 1
    return DEFAULT_SPIN_US if cpus >= 2 else 0.0


NOT_OPEN = "this client has not opened the controller: call GT_Open first"


class ProtocolError(Exception):
    """A client sent something this protocol does not allow; its connection is closed."""


_i64 = I64.unpack_from
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
    sock: socket.socket
    peer: str
    buf: bytearray = field(default_factory=bytearray)
    long_size: int = 0  # 0 until the hello
    opened: bool = False
    decoders: dict[int, _Decoder] = field(default_factory=dict)
    field: field_ops.Context | None = None  # its traces


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


class _Poller:
    """epoll where there is one (Linux), poll elsewhere: fd -> readable."""

    def __init__(self) -> None:
        self._ep = select.epoll() if hasattr(select, "epoll") else None
        self._p = None if self._ep is not None else select.poll()

    def register(self, fd: int) -> None:
        if self._ep is not None:
            self._ep.register(fd, select.EPOLLIN)
        else:
            self._p.register(fd, select.POLLIN)  # type: ignore[union-attr]

    def unregister(self, fd: int) -> None:
        with contextlib.suppress(OSError, KeyError, ValueError):
            (self._ep or self._p).unregister(fd)  # type: ignore[union-attr]

    def poll(self, timeout_s: float | None) -> list[tuple[int, int]]:
        if self._ep is not None:
            return self._ep.poll(-1 if timeout_s is None else timeout_s)
        ms = None if timeout_s is None else int(timeout_s * 1000)
        return self._p.poll(ms)  # type: ignore[union-attr]

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
    ) -> None:
        self.address = address
        self.path = socket_path(address)
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
        self.lock = threading.RLock()
        # its endpoint (gtecat ps) says "controller" while it serves; given back when it stops
        self._inspect_before = (_inspect.KIND, _inspect.LOCK)
        _inspect.KIND, _inspect.LOCK = "controller", self.lock
        self.calls = 0
        self._floor: WallFloor | None = None
        self._floor_clock: Any = None
        self._lifeline = lifeline_fd
        self._remove_dir = remove_dir
        self._stop = threading.Event()
        self._wake_r, self._wake_w = os.pipe()
        self._thread: threading.Thread | None = None
        self._clients: dict[int, _Client] = {}  # by file descriptor
        self._decoders: dict[tuple[int, int], _Decoder] = {}  # (long size, fid)
        self._poller = _Poller()
        self._listener = self._listen()

    # --- socket ------------------------------------------------------------------------
    def _listen(self) -> socket.socket:
        s = socket.socket(socket.AF_UNIX, SOCKET_TYPE)
        if not self.path.startswith("\0") and os.path.exists(self.path):
            probe = socket.socket(socket.AF_UNIX, SOCKET_TYPE)
            try:
                probe.connect(self.path)
            except OSError:
                os.unlink(self.path)  # a stale socket of a controller that died
            else:
                s.close()
                raise OSError(f"a controller already listens at {self.address}")
            finally:
                probe.close()
        s.bind(self.path)
        s.listen(64)
        s.setblocking(False)
        return s

    def fileno(self) -> int:
        return self._listener.fileno()

    # --- the loop ------------------------------------------------------------------------
    def serve_forever(self) -> None:
        poller = self._poller
        listen_fd = self._listener.fileno()
        poller.register(listen_fd)
        poller.register(self._wake_r)
        if self._lifeline is not None:
            poller.register(self._lifeline)
        clients = self._clients
        try:
            while not self._stop.is_set():
                floor = self._current_floor()
                timeout = floor.idle_timeout() if floor is not None else None
                events = poller.poll(timeout)
                if not events and floor is not None:
                    with self.lock:
                        floor.look()
                    continue
                for fd, _ in events:
                    c = clients.get(fd)
                    if c is not None:
                        self._readable(c)
                    elif fd == listen_fd:
                        self._accept()
                    elif fd == self._wake_r:
                        os.read(self._wake_r, 64)
                    elif fd == self._lifeline:
                        if not os.read(self._lifeline, 64):
                            log.info("the program that started this controller has ended")
                            self._stop.set()
        finally:
            self._cleanup()

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
            os.write(self._wake_w, b"x")
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
        if not self.path.startswith("\0"):
            with contextlib.suppress(OSError):
                os.unlink(self.path)
            if self._remove_dir:
                with contextlib.suppress(OSError):
                    Path(self.path).parent.rmdir()
        for fd in (self._wake_r, self._wake_w):
            with contextlib.suppress(OSError):
                os.close(fd)

    def _accept(self) -> None:
        try:
            sock, _ = self._listener.accept()
        except BlockingIOError:
            return
        sock.setblocking(False)
        client = _Client(sock, peer=f"fd {sock.fileno()}")
        self._clients[sock.fileno()] = client
        self._poller.register(sock.fileno())

    def _drop(self, c: _Client) -> None:
        if self._clients.pop(c.sock.fileno(), None) is not None:
            self._poller.unregister(c.sock.fileno())
        if c.field is not None:
            with self.lock:
                c.field.stop_traces()
        c.sock.close()

    def _spin_budget(self) -> float:
        """Seconds to spin for this client's next request: none while more threads are
        runnable than this process has CPUs (spinning would take the CPU the client waits
        for), half the last one after a spin that found nothing (a short probe every 256
        rounds once it is none), up to ``spin_s``."""
        if not self.spin_s:
            return 0.0
        now = time.monotonic()
        if now >= self._busy_next:
            self._busy_next = now + 0.01
            self._busy = _cpus_busy()
        if self._busy:
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
        wake-up)."""
        recv = c.sock.recv
        deadline = 0.0
        budget = -1.0
        while True:
            try:
                data = recv(CHUNK)
            except BlockingIOError:
                if budget < 0.0:
                    budget = self._spin_budget()
                if not budget:
                    return
                now = time.perf_counter()
                if not deadline:
                    deadline = now + budget
                if now >= deadline:
                    self._spin_done(False)
                    return
                os.sched_yield()  # the client first, where it shares this CPU
                continue
            except OSError:
                data = b""
            if not data:
                self._drop(c)
                return
            if deadline:
                self._spin_done(True)
            deadline = 0.0
            budget = -1.0
            if not self._frames(c, data):
                return

    def _frames(self, c: _Client, data: bytes) -> bool:
        """Answer every whole frame in the client's buffer; False once it is dropped."""
        buf = c.buf
        try:
            if not buf and len(data) >= 4 and FRAME.unpack_from(data, 0)[0] == len(data) - 4:
                # the usual case: exactly one whole request in one record
                self._send(c.sock, self._message(c, memoryview(data)[4:]))
                return True
            buf += data
            while len(buf) >= 4:
                (n,) = FRAME.unpack_from(buf, 0)
                if n > MAX_FRAME:
                    raise ProtocolError(f"frame of {n} bytes")
                if len(buf) < 4 + n:
                    self._wait_rest(c, 4 + n)
                body = memoryview(bytes(buf[4 : 4 + n]))
                del buf[: 4 + n]
                self._send(c.sock, self._message(c, body))
        except ProtocolError as e:
            log.warning("client %s: %s; connection closed", c.peer, e)
            self._drop(c)
            return False
        except OSError as e:
            log.info("client %s: %s; connection closed", c.peer, e)
            self._drop(c)
            return False
        return True

    @staticmethod
    def _wait_rest(c: _Client, need: int) -> None:
        """The rest of a frame is on its way: read it (OSError after 10 s without it)."""
        buf = c.buf
        deadline = time.monotonic() + IO_TIMEOUT_S
        while len(buf) < need:
            left = deadline - time.monotonic()
            if left <= 0 or not select.select([c.sock], [], [], left)[0]:
                raise OSError("a frame cut short (no more bytes within 10 s)")
            more = c.sock.recv(max(need - len(buf), CHUNK))
            if not more:
                raise OSError("the connection closed inside a frame")
            buf += more

    @staticmethod
    def _send(sock: socket.socket, data: bytes) -> None:
        """Send a reply in records of at most CHUNK bytes; a client that stops reading for
        10 s is dropped (OSError)."""
        n = 0
        if len(data) <= CHUNK:  # the usual case: one record, sent at once
            try:
                n = sock.send(data)
            except BlockingIOError:
                n = 0
            if n == len(data):
                return
        view = memoryview(data)[n:]
        deadline = 0.0
        while view:
            try:
                view = view[sock.send(view[:CHUNK]) :]
                continue
            except BlockingIOError:
                pass
            if not deadline:
                deadline = time.monotonic() + IO_TIMEOUT_S
            left = deadline - time.monotonic()
            if left <= 0 or not select.select([], [sock], [], left)[1]:
                raise OSError("the client does not read its replies")

    # --- messages ------------------------------------------------------------------------
    def _message(self, c: _Client, body: memoryview) -> bytes:
        if not body:
            raise ProtocolError("empty frame")
        kind = body[0]
        if kind == MSG_CALL and c.long_size:
            _, gtn, fid, core = CALL.unpack_from(body, 0)
            dec = c.decoders.get(fid)
            if dec is None:
                dec = c.decoders[fid] = self._decoder(c.long_size, fid)
            if dec.fast is not None and c.opened and not gtn:
                with self.lock:
                    if self.wall_floor:
                        floor = self._current_floor()
                        if floor is not None:
                            floor.look()
                    out = dec.fast(body)
                if out is not None:
                    self.calls += 1
                    return out
            args, backs = dec.decode(body, CALL.size)
            with self.lock:
                rc, text = self._call(c, dec, gtn, core, args)
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

    def _field(self, c: _Client, body: memoryview) -> bytes:
        """A field-side or bus operation (:mod:`gtecat.native.field`)."""
        try:
            req = json.loads(bytes(body[1:]).decode("utf-8"))
            op, args = str(req["op"]), list(req.get("args", []))
        except (ValueError, KeyError, TypeError) as e:
            raise ProtocolError(f"a field request that is not JSON {{op, args}}: {e}") from None
        status, result = 0, None
        with self.lock:
            ctl = _core.SESSION.controllers.get(1)
            if ctl is None:
                status, result = 1, "the controller is not open yet (no client has called GT_Open)"
            else:
                if c.field is None or c.field.ctl is not ctl:
                    if c.field is not None:
                        c.field.stop_traces()
                    c.field = field_ops.Context(ctl)
                try:
                    result = field_ops.run(c.field, op, args)
                except GtecatError as e:
                    status, result = 1, str(e)
                except Exception as e:  # a field operation never takes the controller down
                    log.exception("field operation %s failed", op)
                    status, result = 1, f"internal error in the emulator: {type(e).__name__}: {e}"
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
        if not c.opened or plan.name in ("GT_Open", "GT_Close", "GTN_OpenCard"):
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
            c.opened = False
            return 0, ""
        return _core.CMD_COMM, f"{name} returned -1: {NOT_OPEN}"

    def _open(self, c: _Client, gtn: int, core: int, args: list[Any]) -> tuple[int, str]:
        if c.opened:  # as in Python: the same program opening twice
            return _core.CMD_OPEN, (
                "GT_Open returned -6: the controller is already open "
                "(GT_Open called twice; call GT_Close first)"
            )
        if 1 not in _core.SESSION.controllers:
            opener = _core.REGISTRY["GT_Open"]
            # "local": this process is the controller, whatever GTECAT_CONTROLLER says
            rc = opener(*args, controller="local", **self.open_options)
            if rc != 0:
                e = _core.SESSION.last
                return rc, (f"GT_Open returned {rc}: {e.reason}" if e else "")
        c.opened = True
        return 0, ""

    # --- time ----------------------------------------------------------------------------
    def _current_floor(self) -> WallFloor | None:
        if not self.wall_floor:
            return None
        ctl = _core.SESSION.controllers.get(1)
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
    path = socket_path(address)
    deadline = time.monotonic() + timeout_s
    while True:
        s = socket.socket(socket.AF_UNIX, SOCKET_TYPE)
        try:
            s.connect(path)
            return
        except OSError:
            if time.monotonic() > deadline:
                raise TimeoutError(f"no controller at {address} after {timeout_s:g} s") from None
            time.sleep(0.01)
        finally:
            s.close()


__all__ = ["NOT_OPEN", "ProtocolError", "Server", "socket_path", "wait_for"]
