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
  server), later ones find it open and return 0.  ``GT_Close`` detaches the client;
  the controller stays (it is the device).  Calls of a client that has not opened
  (or has closed) return -1, as in Python before ``GT_Open``.
* In ``auto`` mode the server keeps the wall floor (:mod:`gtecat.native.floor`)
  unless asked not to, so native clients that sleep between polls see time pass.
"""

from __future__ import annotations

import contextlib
import ctypes
import logging
import os
import select
import selectors
import socket
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..gt import _core
from ..gt.table import SCALARS
from . import cdecl
from .floor import WallFloor
from .protocol import (
    BLOCK,
    CALL,
    F64,
    FRAME,
    HELLO,
    HELLO_REPLY,
    I64,
    MAX_FRAME,
    MSG_CALL,
    MSG_HELLO,
    PROTOCOL_VERSION,
    PTR,
    PTR_NULL,
    PTR_TOO_BIG,
    PTR_UNKNOWN,
    REPLY,
    FunctionPlan,
    Kind,
    plans,
    table_digest,
)

log = logging.getLogger("gtecat.native.server")

#: a client that sends half a frame, or stops reading replies, this long is dropped
IO_TIMEOUT_S = 10.0
#: how long the server keeps serving one client before it looks at the others
#: (GTECAT_SERVER_SPIN_US; see Server._readable)
DEFAULT_SPIN_US = 0

NOT_OPEN = "this client has not opened the controller: call GT_Open first"


def socket_path(address: str) -> str:
    """``unix:/path``, ``/path`` or ``unix:@name`` (Linux abstract) -> the AF_UNIX address."""
    addr = address[5:] if address.startswith("unix:") else address
    if not addr:
        raise ValueError(f"controller address {address!r} names no socket")
    if addr.startswith("@"):
        return "\0" + addr[1:]
    return addr


class ProtocolError(Exception):
    """A client sent something this protocol does not allow; its connection is closed."""


def _elem(ctype: str, long_size: int) -> Any:
    """The ctypes element behind a pointer of C type ``ctype`` for this client."""
    if ctype in ("long", "unsigned long"):
        signed = ctype == "long"
        return {
            4: ctypes.c_int32 if signed else ctypes.c_uint32,
            8: ctypes.c_int64 if signed else ctypes.c_uint64,
        }[long_size]
    if ctype in SCALARS:
        return getattr(ctypes, SCALARS[ctype][0])
    return cdecl.structure(ctype)


_INT, _DOUBLE, _TEXT, _ANY, _BUF = range(5)
_i64 = I64.unpack_from
_f64 = F64.unpack_from
_ptr = PTR.unpack_from


class _Decoder:
    """One function's request layout for one client ``long`` size, compiled once."""

    __slots__ = ("_arrays", "fn_gt", "fn_gtn", "plan", "steps")

    def __init__(self, plan: FunctionPlan, long_size: int) -> None:
        self.plan = plan
        steps = []
        for a in plan.args:
            if a.kind is Kind.INT:
                steps.append((_INT, None, 0, False, a.param.name))
            elif a.kind is Kind.DOUBLE:
                steps.append((_DOUBLE, None, 0, False, a.param.name))
            else:
                code = {Kind.TEXT: _TEXT, Kind.OUT_ANY: _ANY}.get(a.kind, _BUF)
                elem = _elem(a.param.ctype, long_size)
                steps.append((code, elem, ctypes.sizeof(elem), a.carries_back, a.param.name))
        self.steps = tuple(steps)
        self._arrays: dict[tuple[Any, int], Any] = {}
        self.fn_gt = _core.REGISTRY.get(plan.name)
        self.fn_gtn = _core.REGISTRY.get("GTN_" + plan.name[3:]) if plan.proto.gtn else None

    def _array(self, elem: Any, n: int) -> Any:
        key = (elem, n)
        t = self._arrays.get(key)
        if t is None:
            t = self._arrays[key] = elem * n
        return t

    def decode(self, body: memoryview, pos: int) -> tuple[list[Any], list[Any]]:
        """(arguments for the GT function, out-buffers in order; None for NULL)."""
        args: list[Any] = []
        backs: list[Any] = []
        end = len(body)
        for code, elem, esize, back, name in self.steps:
            if code == _INT:
                args.append(_i64(body, pos)[0])
                pos += 8
                continue
            if code == _DOUBLE:
                args.append(_f64(body, pos)[0])
                pos += 8
                continue
            size = _ptr(body, pos)[0]
            pos += 4
            if size == PTR_NULL:
                args.append(None)
                if back:
                    backs.append(None)
                continue
            if size == PTR_UNKNOWN:
                if code != _ANY:
                    raise ProtocolError(f"{self.plan.name}: size unknown for {name}")
                buf: Any = []  # grows to what the call writes
                args.append(buf)
                backs.append(buf)
                continue
            if size == PTR_TOO_BIG:
                size, data = 0, b""
            elif size < 0 or pos + size > end:
                raise ProtocolError(f"{self.plan.name}: bad size {size} for {name}")
            else:
                data = body[pos : pos + size]
                pos += size
            if code == _TEXT:
                args.append(bytes(data))
                continue
            raw = bytearray(data)
            if size % esize:
                arr: Any = self._array(ctypes.c_ubyte, size).from_buffer(raw)
            else:
                arr = self._array(elem, size // esize).from_buffer(raw)
            args.append(arr)
            if back:
                backs.append(raw)
        if pos != end:
            raise ProtocolError(f"{self.plan.name}: {end - pos} bytes left after the arguments")
        return args, backs


@dataclass(eq=False)
class _Client:
    sock: socket.socket
    peer: str
    buf: bytearray = field(default_factory=bytearray)
    long_size: int = 0  # 0 until the hello
    opened: bool = False
    decoders: dict[int, _Decoder] = field(default_factory=dict)


def _reply(rc: int, backs: list[Any], text: str) -> bytes:
    parts = []
    n = 0
    for b in backs:
        if b is None:
            continue
        data = bytes(b) if not isinstance(b, list) else bytes(int(v) & 0xFF for v in b)
        parts.append(BLOCK.pack(len(data)))
        parts.append(data)
        n += 1
    t = text.encode("utf-8", "replace")[:4000] if text else b""
    body = REPLY.pack(rc, n, len(t)) + b"".join(parts) + t
    return FRAME.pack(len(body)) + body


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
            spin_us = float(os.environ.get("GTECAT_SERVER_SPIN_US", DEFAULT_SPIN_US))
        self.spin_s = max(0.0, spin_us) / 1e6
        self.lock = threading.RLock()
        self.calls = 0
        self._floor: WallFloor | None = None
        self._floor_clock: Any = None
        self._lifeline = lifeline_fd
        self._remove_dir = remove_dir
        self._stop = threading.Event()
        self._wake_r, self._wake_w = os.pipe()
        self._thread: threading.Thread | None = None
        self._clients: dict[socket.socket, _Client] = {}
        self._sel = selectors.DefaultSelector()
        self._listener = self._listen()

    # --- socket ------------------------------------------------------------------------
    def _listen(self) -> socket.socket:
        s = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        if not self.path.startswith("\0") and os.path.exists(self.path):
            probe = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
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
        sel = self._sel
        sel.register(self._listener, selectors.EVENT_READ, "accept")
        sel.register(self._wake_r, selectors.EVENT_READ, "wake")
        if self._lifeline is not None:
            sel.register(self._lifeline, selectors.EVENT_READ, "lifeline")
        try:
            while not self._stop.is_set():
                floor = self._current_floor()
                timeout = floor.idle_timeout() if floor is not None else None
                events = sel.select(timeout)
                if not events and floor is not None:
                    with self.lock:
                        floor.look()
                    continue
                for key, _ in events:
                    what = key.data
                    if what == "accept":
                        self._accept()
                    elif what == "wake":
                        os.read(self._wake_r, 64)
                    elif what == "lifeline":
                        if not os.read(self._lifeline, 64):  # type: ignore[arg-type]
                            log.info("the program that started this controller has ended")
                            self._stop.set()
                    else:
                        self._readable(what)
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
        for c in list(self._clients.values()):
            self._drop(c)
        with contextlib.suppress(Exception):
            self._sel.close()
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
        self._clients[sock] = client
        self._sel.register(sock, selectors.EVENT_READ, client)

    def _drop(self, c: _Client) -> None:
        self._clients.pop(c.sock, None)
        with contextlib.suppress(Exception):
            self._sel.unregister(c.sock)
        c.sock.close()

    def _readable(self, c: _Client) -> None:
        """Serve what ``c`` sent; then, for ``spin_s``, serve its next request at once
        (a client polling in a loop sends it within microseconds; answering it without
        a round through the selector, and without either side falling asleep, roughly
        halves the round trip)."""
        sock = c.sock
        deadline = 0.0
        while True:
            try:
                data = sock.recv(1 << 16)
            except BlockingIOError:
                if not self.spin_s:
                    return
                now = time.perf_counter()
                if not deadline:
                    deadline = now + self.spin_s
                if now >= deadline:
                    return
                continue
            except OSError:
                data = b""
            if not data:
                self._drop(c)
                return
            deadline = 0.0
            if not self._frames(c, data):
                return

    def _frames(self, c: _Client, data: bytes) -> bool:
        """Answer every whole frame in the client's buffer; False once it is dropped."""
        buf = c.buf
        if not buf and len(data) >= 4 and FRAME.unpack_from(data, 0)[0] == len(data) - 4:
            # the usual case: exactly one whole request
            try:
                self._send(c.sock, self._message(c, memoryview(data)[4:]))
            except (ProtocolError, OSError) as e:
                log.info("client %s: %s; connection closed", c.peer, e)
                self._drop(c)
                return False
            return True
        buf += data
        try:
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
            more = c.sock.recv(max(need - len(buf), 1 << 16))
            if not more:
                raise OSError("the connection closed inside a frame")
            buf += more

    @staticmethod
    def _send(sock: socket.socket, data: bytes) -> None:
        """Send a reply; a client that stops reading for 10 s is dropped (OSError)."""
        view = memoryview(data)
        deadline = 0.0
        while view:
            try:
                view = view[sock.send(view) :]
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
        if kind == MSG_HELLO:
            return self._hello(c, body)
        if kind != MSG_CALL:
            raise ProtocolError(f"message type {kind}")
        if not c.long_size:
            raise ProtocolError("a call before the hello")
        _, gtn, fid, core = CALL.unpack_from(body, 0)
        dec = c.decoders.get(fid)
        if dec is None:
            table = plans()
            if fid >= len(table):
                raise ProtocolError(f"function id {fid} unknown")
            dec = c.decoders[fid] = _Decoder(table[fid], c.long_size)
        args, backs = dec.decode(body, CALL.size)
        with self.lock:
            rc, text = self._call(c, dec, bool(gtn), core, args)
        return _reply(rc, backs, text)

    def _hello(self, c: _Client, body: memoryview) -> bytes:
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

    def _call(
        self, c: _Client, dec: _Decoder, gtn: bool, core: int, args: list[Any]
    ) -> tuple[int, str]:
        plan = dec.plan
        name = plan.name
        self.calls += 1
        if name in ("GT_Open", "GT_Close"):
            if gtn and core != 1:  # the Python twin refuses it (7) before doing anything
                return _invoke(dec.fn_gtn, (core, *args))
            if name == "GT_Open":
                return self._open(c, gtn, core, args)
            c.opened = False
            return 0, ""
        if not c.opened:
            return _core.CMD_COMM, f"{name} returned -1: {NOT_OPEN}"
        if plan.unsupported:
            return _core.CMD_ERROR, plan.unsupported
        fn = dec.fn_gtn if gtn else dec.fn_gt
        if fn is None:
            return _core.CMD_NO_RESPONSE, f"{name}: not implemented by this gtecat"
        floor = self._current_floor()
        if floor is not None:
            floor.look()
        return _invoke(fn, (core, *args) if gtn else args)

    def _open(self, c: _Client, gtn: bool, core: int, args: list[Any]) -> tuple[int, str]:
        if 1 not in _core.SESSION.controllers:
            errors = _core.SESSION.errors
            before = errors[-1] if errors else None
            opener = _core.REGISTRY["GT_Open"]
            # "local": this process is the controller, whatever GTECAT_CONTROLLER says
            rc = opener(*args, controller="local", **self.open_options)
            if rc != 0:
                e = errors[-1] if errors and errors[-1] is not before else None
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
    errors = _core.SESSION.errors
    before = errors[-1] if errors else None
    rc = fn(*args)
    if rc != 0 and errors and errors[-1] is not before:
        e = errors[-1]
        return rc, f"{e.function} returned {e.code}: {e.reason}"
    return rc, ""


def wait_for(address: str, timeout_s: float = 10.0) -> None:
    """Return once something accepts connections at ``address`` (TimeoutError otherwise)."""
    path = socket_path(address)
    deadline = time.monotonic() + timeout_s
    while True:
        s = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
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
