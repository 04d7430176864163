"""The inspection endpoint of a running controller: a Unix socket, JSON lines.

Protocol (one JSON object per line, UTF-8, both ways; documented for other clients):

    request   {"id": 7, "op": "snapshot", "args": []}
    reply     {"id": 7, "ok": true, "result": ...}
              {"id": 7, "ok": false, "error": "one line saying why"}

``{"op": "subscribe", "args": ["snapshot", 40]}`` answers ``{"id": null, "ok": true,
"result": null}`` and then, every 40 ms until the client closes, pushes
``{"push": "snapshot", "result": ...}``: the result is made and sent by the cycle's thread
between two cycles, the connection's thread only keeps time (the cheapest way to watch).

``op`` is one of :data:`gtecat.inspect.ops.OPS` (``info``, ``layout``, ``snapshot``,
``log``, ``jog``, ``trap``, ``stop``) or of :data:`gtecat.native.field.OPS` (the bus
verbs' ``slaves``, ``pdos``, ``sdos``, ``states``, ``data``, ``reg_read``, ``sii``,
``sdo_upload``/``sdo_download``, the field side, ``trace_start``/``trace_read``/
``trace_stop``).  A connection's traces stop when it closes.  Requests on one connection
are answered in order; any number of connections are served at once.

**Never slowing the cycle.**  Nothing runs in the cycle while nobody is attached.  The
socket is served by one daemon thread per connection.  A request is not
run there: it is queued and run by the thread that runs the cycles, at the start of the
next cycle, before anything of that cycle (so between two cycles, exactly where an
application's GT call runs; the vectorised axis bank sees it as one).  While a connection
is open the cycle pays a few attribute checks when nothing is queued.  When no cycle runs
for :data:`IDLE_S` (an
application waiting for input, a lockstep test between steps, an idle ``gtecat
controller``), the endpoint thread runs the request itself: with the lock every change of
the controller takes (the controller server's call lock; else the clock's lock, which every
GT call and every cycle holds, in every clock mode), and after a handshake with the cycle so
the two never overlap (a cycle run for another card of one time, which takes no lock of
this one; a run of many cycles at once that began before the connection opened is waited
for too: while a connection is open no new one begins).  The clock's lock is taken before
the handshake, as a cycle holds it before it: a request that takes it again (a fault
injected, :mod:`gtecat.faults`) cannot wait for a cycle that waits for the request.
(Requests are short.)

**When it publishes.**  :func:`publish` is called by ``GT_Open`` (and so by ``gtecat
controller``, which opens through it); ``gtecat serve`` publishes the same endpoint over its
chain of slaves once it answers frames (:mod:`gtecat.inspect.serve`: its requests run
between two frames).  ``GTECAT_INSPECT=0`` turns it off; the pytest
plugin sets that default for the test run (thousands of short controllers; a test that
wants an endpoint sets ``GTECAT_INSPECT=1``).  Starting costs a thread and a socket.
"""

from __future__ import annotations

import contextlib
import itertools
import json
import logging
import os
import select
import socket
import sys
import threading
import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..controller.epoch import changed as readers_changed
from . import enabled, runtime

log = logging.getLogger(__name__)

#: no cycle for this long: the endpoint thread answers itself (module docstring)
IDLE_S = 0.02
_COUNTER = itertools.count(1)


@dataclass(eq=False)
class _Request:
    fn: Callable[[], Any]
    done: threading.Event = field(default_factory=threading.Event)
    claimed: bool = False
    result: Any = None
    error: BaseException | None = None


class _Conn:
    """What the operations of one connection run on (gtecat.native.field's Context
    plus what the panel's operations need)."""

    def __init__(self, endpoint: Endpoint) -> None:
        from ..native.field import Context

        self.field = Context(endpoint.ctl)
        self.ctl = endpoint.ctl
        self.kind = endpoint.kind
        self.homing: dict[int, int | None] = {}


class Endpoint:
    """One controller's endpoint (module docstring).

    What is particular to a controller is in a few methods a subclass replaces (the
    ``gtecat serve`` endpoint, :mod:`gtecat.inspect.serve`): :meth:`_setup` and
    :meth:`_install` (how requests reach the thread that runs the cycles), :meth:`_idle`
    (a request no cycle took), :meth:`_meta` (what ``gtecat ps`` shows), :meth:`_context`
    and :meth:`_lookup` (what the operations run on, and which there are)."""

    #: the longest request line a client may send (bytes); a longer one ends the connection
    max_line = 1 << 20
    #: connections open at once at most (0: no limit); one more is told so and closed
    max_conns = 0
    #: a connection's requests start this many seconds apart at least (0: as they come)
    min_gap_s = 0.0

    def __init__(self, ctl: Any, kind: str = "python", lock: Any = None) -> None:
        self.ctl = ctl
        self.kind = kind
        #: the lock every change of ``ctl`` takes, when there is one (a controller server's)
        self.lock = lock
        self.id = ""
        self.path: Path | None = None
        self._pending: deque[_Request] = deque()
        self._claim = threading.Lock()
        self._gate = threading.Lock()
        self._flags = [False, False]  # [a cycle runs, the endpoint thread answers itself]
        self._stop = threading.Event()
        self._sock: socket.socket | None = None
        self._threads: list[threading.Thread] = []
        self._conns: set[socket.socket] = set()
        self._watchers = 0  # open connections: the cycle is wrapped only while one is open
        self._watch_lock = threading.Lock()
        self._setup()

    # --- the cycle side --------------------------------------------------------------------
    def _setup(self) -> None:
        self._run_cycle = self.ctl.clock._run_cycle
        self._cycle = self._make_cycle()

    def _make_cycle(self) -> Callable[[], None]:
        """The clock's cycle with the queue served first (a closure: the fewest operations
        per cycle; ``flags`` = [a cycle runs, the endpoint thread answers itself])."""
        run = self._run_cycle
        pending = self._pending
        flags = self._flags
        gate = self._gate
        serve = self._serve_pending

        def cycle() -> None:
            flags[0] = True
            while flags[1]:  # the endpoint thread is answering itself: wait for it
                flags[0] = False
                with gate:
                    pass
                flags[0] = True
            try:
                if pending:
                    serve()
                run()
            finally:
                flags[0] = False

        return cycle

    def _serve_pending(self) -> None:
        while self._pending:
            with self._claim:
                if not self._pending:
                    return
                req = self._pending.popleft()
                if req.claimed:
                    continue
                req.claimed = True
            _run(req)

    def _watch(self, delta: int) -> None:
        """Wrap the clock's cycle while a connection is open; nobody watching costs nothing."""
        with self._watch_lock:
            self._watchers += delta
            self._install(self._watchers > 0 and not self._stop.is_set())

    def _install(self, on: bool) -> None:
        """The clock runs :meth:`_cycle` (the queue served first) or its own cycle."""
        clock = self.ctl.clock
        if on:
            clock._run_cycle = self._cycle
        elif clock._run_cycle == self._cycle:
            clock._run_cycle = self._run_cycle

    # --- running one request ------------------------------------------------------------------
    def execute(self, fn: Callable[[], Any]) -> Any:
        """Run ``fn`` between two cycles (module docstring) and return its result."""
        req = _Request(fn)
        self._pending.append(req)
        if not req.done.wait(IDLE_S):
            self._idle(req)
            req.done.wait()
        if req.error is not None:
            raise req.error
        return req.result

    def _claimed(self, req: _Request) -> bool:
        """Take ``req`` from the queue's side: True when no cycle has taken it yet."""
        with self._claim:
            mine = not req.claimed
            req.claimed = True
        return mine

    def _idle(self, req: _Request) -> None:
        """No cycle took ``req`` for :data:`IDLE_S`: the endpoint thread runs it."""
        if self._claimed(req):
            self._direct_run(req)

    def _direct_run(self, req: _Request) -> None:
        lock = self.lock
        clock = self.ctl.clock
        if lock is None:
            lock = clock.lock
        flags = self._flags
        ctl = self.ctl
        with lock if lock is not None else contextlib.nullcontext(), self._gate:
            flags[1] = True
            try:
                # a cycle, or a run of cycles at once that began before the cycle was
                # wrapped (Controller.run_cycles: the compiled kernel lets go of the GIL)
                while flags[0] or getattr(ctl, "in_batch", False):
                    time.sleep(0.0002)
                _run(req, in_cycle=False)
            finally:
                flags[1] = False

    # --- the socket side -------------------------------------------------------------------------
    def _meta(self) -> dict[str, Any]:
        """Who published the endpoint, beyond pid, program and start (``gtecat ps``)."""
        o = self.ctl.options
        return {
            "eni": str(Path(str(o.eni)).resolve()) if o.eni else "",
            "clock": str(o.clock),
            "backend": str(o.backend),
        }

    def publish(self) -> Endpoint:
        folder = runtime.checked_folder()
        runtime.sweep(folder)
        pid = os.getpid()
        n = next(_COUNTER)
        self.id = str(pid) if n == 1 else f"{pid}-{n}"
        self.path = folder / f"{self.id}.sock"
        runtime.remove(self.path)
        s = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        old = os.umask(0o177)
        try:
            s.bind(str(self.path))
        finally:
            os.umask(old)
        os.chmod(self.path, 0o600)
        s.listen(16)
        self._sock = s
        meta = {
            "pid": pid,
            "kind": self.kind,
            "program": " ".join(sys.argv) or sys.executable,
            **self._meta(),
            "started": time.time(),
        }
        tmp = self.path.with_suffix(".tmp")
        tmp.write_text(json.dumps(meta), encoding="utf-8")
        os.chmod(tmp, 0o600)
        tmp.replace(self.path.with_suffix(".json"))
        t = threading.Thread(target=self._accept, name="gtecat-inspect", daemon=True)
        t.start()
        self._threads.append(t)
        return self

    def close(self) -> None:
        """Stop serving, remove the files, give the clock its own cycle back."""
        self._stop.set()
        self._install(False)
        if self._sock is not None:
            with contextlib.suppress(OSError):
                self._sock.shutdown(socket.SHUT_RDWR)
            self._sock.close()
            self._sock = None
        for c in list(self._conns):
            with contextlib.suppress(OSError):
                c.shutdown(socket.SHUT_RDWR)
        if self.path is not None:
            runtime.remove(self.path)
        while self._pending:  # nobody runs cycles any more: answer what waits
            req = self._pending.popleft()
            req.error = ConnectionError("the running gtecat closed")
            req.done.set()

    def _accept(self) -> None:
        sock = self._sock
        while not self._stop.is_set() and sock is not None:
            try:
                conn, _ = sock.accept()
            except OSError:
                return
            if self.max_conns and len(self._conns) >= self.max_conns:
                with contextlib.suppress(OSError), conn:
                    error = f"{self.max_conns} connections are open already: try again later"
                    conn.sendall(json.dumps({"id": None, "ok": False, "error": error}).encode())
                    conn.sendall(b"\n")
                continue
            self._conns.add(conn)
            t = threading.Thread(
                target=self._serve, args=(conn,), name="gtecat-inspect-conn", daemon=True
            )
            t.start()

    def _context(self) -> Any:
        """What the operations of one connection run on."""
        return _Conn(self)

    def _lookup(self, op: str) -> Callable[..., Any] | None:
        """The operation ``op`` as ``fn(ctx, *args)``; None: there is none of that name."""
        from ..native import field
        from . import ops

        fn = ops.OPS.get(op)
        if fn is not None:
            return fn
        if op in field.OPS:
            return lambda ctx, *args: field.run(ctx.field, op, list(args))
        return None

    def _known(self) -> list[str]:
        from ..native import field
        from . import ops

        return sorted({*ops.OPS, *field.OPS})

    def _serve(self, conn: socket.socket) -> None:
        ctx = self._context()
        self._watch(+1)
        limit, gap = self.max_line, self.min_gap_s
        last = 0.0
        try:
            with conn, conn.makefile("rb") as rf, conn.makefile("wb") as wf:
                while True:
                    line = rf.readline(limit + 1)
                    if not line or self._stop.is_set():
                        return
                    if gap:  # a client asking without pause is slowed down, not served faster
                        wait = last + gap - time.monotonic()
                        if wait > 0:
                            time.sleep(wait)
                        last = time.monotonic()
                    t0 = time.thread_time_ns()
                    if len(line) > limit:  # no JSON parsed, the connection ends
                        error = f"a request line is {limit // 1024} KiB at most"
                        reply = {"id": None, "ok": False, "error": error}
                        wf.write(json.dumps(reply).encode() + b"\n")
                        wf.flush()
                        return
                    sub = _subscription(line)
                    reply = self._answer(ctx, line) if sub is None else self._check_sub(sub)
                    wf.write(json.dumps(reply, separators=(",", ":")).encode() + b"\n")
                    wf.flush()
                    COST[0] += 1
                    COST[1] += time.thread_time_ns() - t0
                    if sub is not None and reply["ok"]:
                        self._push(ctx, conn, sub)  # until the client goes
                        return
        except (OSError, ValueError):
            pass
        finally:
            self._conns.discard(conn)
            traces = getattr(getattr(ctx, "field", None), "traces", None)
            if traces:
                with contextlib.suppress(Exception):
                    self.execute(ctx.field.stop_traces)
            self._watch(-1)

    # --- subscriptions: the cycle's thread sends, the connection's thread only keeps time ------
    def _check_sub(self, sub: tuple[str, float, list[Any]]) -> dict[str, Any]:
        from . import ops

        op, period, _ = sub
        if op not in ops.PUSHABLE or self._lookup(op) is None:
            return {"id": None, "ok": False, "error": f"{op!r} cannot be subscribed to"}
        if not 0.005 <= period <= 10:
            return {"id": None, "ok": False, "error": "period_ms must be 5..10000"}
        return {"id": None, "ok": True, "result": None}

    def _push(self, ctx: _Conn, conn: socket.socket, sub: tuple[str, float, list[Any]]) -> None:
        """Every ``period``: one line ``{"push": op, "result": ...}`` (module docstring)."""
        op, period, args = sub
        fn = self._lookup(op)
        assert fn is not None  # _check_sub looked
        last: _Request | None = None
        late: list[bytes] = []  # what the cycle's thread could not send at once

        def push() -> None:
            data = json.dumps({"push": op, "result": fn(ctx, *args)}, separators=(",", ":"))
            data = data.encode() + b"\n"
            if late:
                late.append(data)
                return
            try:
                n = conn.send(data, socket.MSG_DONTWAIT)
            except BlockingIOError:
                n = 0
            if n < len(data):
                late.append(data[n:])

        while not self._stop.is_set():
            t0 = time.thread_time_ns()
            if late:
                conn.sendall(b"".join(late))
                late.clear()
            if last is not None and not last.done.is_set():
                self._idle_push(last)
            if last is None or last.done.is_set():
                last = _Request(push)
                self._pending.append(last)
            COST[1] += time.thread_time_ns() - t0
            readable, _, _ = select.select([conn], [], [], period)
            if readable and not conn.recv(4096, socket.MSG_DONTWAIT):
                return  # the client has gone
            COST[0] += 1

    def _idle_push(self, req: _Request) -> None:
        """A pushed result no cycle made for a whole period: the application is idle."""
        if self._claimed(req):
            self._direct_run(req)

    def _answer(self, ctx: _Conn, line: bytes) -> dict[str, Any]:
        rid = None
        try:
            msg = json.loads(line)
            if not isinstance(msg, dict):
                raise ValueError("a request is a JSON object")
            rid = msg.get("id")
            op = str(msg.get("op", ""))
            args = msg.get("args") or []
            if not isinstance(args, list):
                raise ValueError("args is a list")
            return {"id": rid, "ok": True, "result": self.request(ctx, op, args)}
        except Exception as e:  # one line back, never a dead endpoint
            text = str(e) if not isinstance(e, KeyError) else f"no such key {e}"
            return {"id": rid, "ok": False, "error": text or type(e).__name__}

    def request(self, ctx: _Conn, op: str, args: list[Any]) -> Any:
        from ..errors import ParameterError

        fn = self._lookup(op)
        if fn is None:
            known = self._known()
            raise ParameterError(f"no operation {op!r} (there are {', '.join(known)})")
        if op == "data" and len(args) > 1 and int(args[1] or 0) > 0:
            # let the cycles pass here, not inside one: read after them
            self._wait_cycles(int(args[1]))
            args = [args[0], 0]
        return self.execute(lambda: fn(ctx, *args))

    def _wait_cycles(self, n: int) -> None:
        clock = self.ctl.clock
        target = clock.cycles + n
        deadline = time.monotonic() + max(1.0, n * clock.cycle_ns / 1e9 * 4)
        while clock.cycles < target and time.monotonic() < deadline:
            time.sleep(0.001)


def _subscription(line: bytes) -> tuple[str, float, list[Any]] | None:
    """``{"op": "subscribe", "args": [OP, PERIOD_MS, *ARGS]}`` -> (OP, seconds, ARGS)."""
    if b'"subscribe"' not in line:
        return None
    try:
        msg = json.loads(line)
        if msg.get("op") != "subscribe":
            return None
        op, period, *args = msg.get("args") or []
        return str(op), float(period) / 1000, list(args)
    except (ValueError, TypeError, AttributeError):
        return None


def _run(req: _Request, in_cycle: bool = True) -> None:
    """Run a request; in the cycle's thread its CPU time is counted here (in the
    endpoint's thread the whole request is counted around it)."""
    t0 = time.thread_time_ns() if in_cycle else 0
    try:
        req.result = req.fn()
    except BaseException as e:
        req.error = e
    finally:
        # (a control operation changes the controller without a GT call: what the GT
        # readers' C entries kept is asked again, gtecat/controller/epoch.py)
        readers_changed()
        if in_cycle:
            COST[1] += time.thread_time_ns() - t0
        req.done.set()


#: [requests answered, CPU ns this process spent on them: reading, running, answering];
#: what watching costs the application (tools/bench_panel.py reports it)
COST = [0, 0]


# --- publishing ---------------------------------------------------------------------------------
_PUBLISHED: dict[int, Endpoint] = {}  # id(controller) -> its endpoint
#: what this process is (``gtecat controller`` says "controller") and the lock its changes take
KIND = "python"
LOCK: Any = None


def publish(ctl: Any) -> Endpoint | None:
    """Publish ``ctl``'s endpoint (unless ``GTECAT_INSPECT=0``); a folder that cannot be
    used is one warning, never a failed GT_Open."""
    if not enabled() or id(ctl) in _PUBLISHED:
        return _PUBLISHED.get(id(ctl))
    ep = Endpoint(ctl, KIND, LOCK)
    try:
        ep.publish()
    except Exception as e:
        ep.close()
        log.warning("gtecat: no inspection endpoint: %s", e)
        return None
    _PUBLISHED[id(ctl)] = ep
    return ep


def unpublish(ctl: Any) -> None:
    ep = _PUBLISHED.pop(id(ctl), None)
    if ep is not None:
        ep.close()


def published(ctl: Any) -> Endpoint | None:
    return _PUBLISHED.get(id(ctl))


def attached() -> bool:
    """Some endpoint of this process has a connection open or a request waiting: its
    threads then need the interpreter between the application's calls.  (A client that
    just connected gets it within the interpreter's switch interval and is counted here
    from its first line on.)"""
    for ep in _PUBLISHED.values():
        if ep._watchers or ep._pending:
            return True
    return False


def _close_all() -> None:
    for ep in list(_PUBLISHED.values()):
        ep.close()
    _PUBLISHED.clear()


import atexit  # noqa: E402  (the files go with the process, whatever way it ends normally)

atexit.register(_close_all)

__all__ = ["IDLE_S", "Endpoint", "enabled", "publish", "published", "unpublish"]
