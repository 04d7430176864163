"""The inspection endpoint of a ``gtecat serve``: its chain of slaves, seen and broken at runtime.

The endpoint of :mod:`.endpoint` (the same socket, protocol, runtime folder and ``gtecat
ps`` entry), published by ``gtecat serve`` once it answers frames.  What differs from a
controller's:

* **Where a request runs.**  The serve's one thread answers frames and steps the slaves; a
  request is queued and that thread runs it between two frames, in its housekeeping (every
  few milliseconds, never inside a frame or a step), so the slaves need no lock.  The
  endpoint's own threads only read and write the sockets; they never touch the chain.  A
  request the loop has not taken within :data:`TAKE_S` (the server is stopping) ends with
  an error.
* **What there is to ask.**  ``info``, ``slaves``, ``pdos``, ``states`` (read; the master on
  the wire sets the states), ``reg_read`` and ``sii`` (the ESC's memory as it holds it:
  reading it acknowledges nothing the master waits for), ``sdo_upload`` (from the slave's
  own dictionary, not through its mailbox), ``snapshot`` (AL states and
  status codes, frame counters), ``log`` (the serve's log: every fault armed, started,
  ended) and the faults (``fault_inject``,
  ``fault_list``, ``fault_clear``: :mod:`gtecat.faults` on the serve's
  :class:`~gtecat.faults.WireBus`, the same injector as ``--fault FILE``).  The process
  image, axes, SDO transfers, motion and traces belong to the master on the other end of
  the wire: those operations are refused with a sentence that says so.
* **A client cannot slow the frames.**  Each connection has one request at a time (it
  waits for its answer), and the loop runs at most :data:`PER_PASS` requests per pass;
  the operations are short (no dictionary walks, no bus traffic); a request line is 64 KiB at
  most, a connection's requests start 5 ms apart at least (a client that floods the
  endpoint, even with lines answered at once as errors, costs the process a few per cent
  of a CPU), at most 8 connections are open; and the interpreter is asked to switch
  threads every :data:`SWITCH_S` (5 ms by default), so a connection's thread reading a
  request holds the serve's thread back that long at most.
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

from ..errors import BusError, ParameterError
from .endpoint import Endpoint, _Request, _run, enabled

#: a request the serve's loop has not taken within this many seconds fails
TAKE_S = 2.0
#: requests the loop runs per pass at most (the rest wait for the next pass, a few ms)
PER_PASS = 4
#: the thread switch interval under a published endpoint (seconds)
SWITCH_S = 0.0002


class ServeHost:
    """What a serve's operations act on: its server, chain and ENI, a log, the faults."""

    def __init__(
        self,
        server: Any,
        config: Any,
        *,
        eni: str | Path,
        iface: str,
        say: Callable[[str], None] | None = None,
    ) -> None:
        from gtecat.eni.layout import build_layout

        from ..master.masterlog import MasterLog

        self.server = server
        self.chain = server.chain
        self.config = config
        #: the ENI's layout: axes and GT raw regions as a controller on this bus has them
        self.layout = build_layout(config)
        self.eni = str(eni)
        self.iface = iface
        #: what the serve did worth a line (faults): kept here (``log``) and said on stderr
        self.log = MasterLog(clock_ms=lambda: round(self.t_ms()))
        self._say = say
        self.injector: Any = None
        self.bus: Any = None

    def t_ms(self) -> float:
        """The slaves' time: ms since the server started answering (0 before)."""
        server = self.server
        t0 = server.stats.started_ns
        return (server.clock() - t0) / 1e6 if t0 else 0.0

    def note(self, message: str) -> None:
        self.log(message)
        if self._say is not None:
            self._say(message)

    def fault_injector(self, create: bool = True) -> Any:
        """The injector of the served chain (:func:`gtecat.faults.injector_for` asks here),
        made on first use: its hooks run after every step and between frames."""
        if self.injector is None and create:
            from ..faults import Injector, WireBus

            bus = WireBus(self.chain, self.server, log=self.note)
            bus.at(int(self.t_ms() * 1e6))
            injector = Injector(bus)

            def step(t_ns: int) -> None:
                bus.at(t_ns)
                injector.tick()

            def poll(t_ns: int) -> None:
                bus.at(t_ns)
                injector.tick(cycle=False)

            self.server.step_hooks.append(step)
            self.server.poll_hooks.append(poll)
            self.bus, self.injector = bus, injector
        return self.injector


class _ServeConn:
    """One connection's context: the serve (as ``ctl``, what the fault operations take)."""

    def __init__(self, endpoint: ServeEndpoint) -> None:
        self.ctl = endpoint.host
        self.host = endpoint.host
        self.kind = endpoint.kind


class ServeEndpoint(Endpoint):
    """A ``gtecat serve``'s endpoint (module docstring)."""

    max_line = 64 * 1024
    max_conns = 8
    #: 200 requests a second per connection at most: a client that floods the endpoint
    #: costs the serve's CPU a few per cent, not a share that delays frames
    min_gap_s = 0.005

    def __init__(self, host: ServeHost) -> None:
        self.host = host
        super().__init__(host, "serve")

    # --- requests run by the serve's loop, between frames ------------------------------------
    def _setup(self) -> None:
        self._hook = self.run_pending
        self.host.server.poll_hooks.append(self._hook)

    def _install(self, on: bool) -> None:
        """The loop looks at the queue between frames all the time (one test of a deque)."""
        if not on and self._stop.is_set():
            hooks = self.host.server.poll_hooks
            if self._hook in hooks:
                hooks.remove(self._hook)

    def run_pending(self, t_ns: int = 0) -> None:
        """Run what the connections asked (:data:`PER_PASS` at most); the serve's loop calls
        it between frames with the slaves' time."""
        pending = self._pending
        if not pending:
            return
        bus = self.host.bus
        if bus is not None:
            bus.at(t_ns)
        for _ in range(PER_PASS):
            with self._claim:
                if not pending:
                    return
                req = pending.popleft()
                if req.claimed:
                    continue
                req.claimed = True
            _run(req)

    def _idle(self, req: _Request) -> None:
        """No pass of the loop took ``req`` in :data:`~gtecat.inspect.endpoint.IDLE_S`: wait
        for one (a sleeping loop passes every 20 ms), never run it here."""
        if req.done.wait(TAKE_S):
            return
        if self._claimed(req):
            req.error = BusError(f"gtecat serve did not take the request within {TAKE_S:g} s")
            req.done.set()

    def _idle_push(self, req: _Request) -> None:
        pass  # the loop makes it on its next pass

    def _wait_cycles(self, n: int) -> None:
        pass  # no operation of a serve waits for cycles

    # --- what the endpoint shows and answers -------------------------------------------------
    def _meta(self) -> dict[str, Any]:
        return {
            "eni": str(Path(self.host.eni).resolve()),
            "clock": "wall",
            "backend": f"wire {self.host.iface}",
        }

    def _context(self) -> _ServeConn:
        return _ServeConn(self)

    def _lookup(self, op: str) -> Callable[..., Any] | None:
        fn = OPS.get(op)
        if fn is not None:
            return fn
        from ..native import field
        from . import ops

        if op in ops.OPS or op in field.OPS:
            return _needs_controller(op)
        return None

    def _known(self) -> list[str]:
        return sorted(OPS)

    def publish(self) -> ServeEndpoint:
        # what the operations import is imported now, not by the loop between two frames
        from .. import faults  # noqa: F401
        from ..controller import inspect  # noqa: F401
        from ..native import field  # noqa: F401
        from . import ops  # noqa: F401

        super().publish()
        sys.setswitchinterval(SWITCH_S)
        return self


def _needs_controller(op: str) -> Callable[..., Any]:
    def refuse(_ctx: Any, *_args: Any) -> Any:
        raise BusError(
            f"{op!r} needs a controller: a gtecat serve only plays the slaves, the process "
            "image, axes, SDO downloads, register writes and traces are its master's (on "
            f"the other end of the wire); a serve answers {', '.join(sorted(OPS))}"
        )

    return refuse


# --- the operations ------------------------------------------------------------------------------
Op = Callable[..., Any]
OPS: dict[str, Op] = {}


def _op(fn: Op) -> Op:
    OPS[fn.__name__] = fn
    return fn


def _check(host: ServeHost, position: int | None) -> list[int]:
    from ..controller.inspect import check_position

    n = len(host.config.slaves)
    return [check_position(n, int(position))] if position is not None else list(range(n))


def _cut(host: ServeHost) -> set[int]:
    return {e.position for e in host.chain.cut}


@_op
def info(ctx: Any) -> dict[str, Any]:
    import os

    host = ctx.host
    s = host.server
    return {
        "pid": os.getpid(),
        "kind": "serve",
        "eni": host.eni,
        "iface": host.iface,
        "step": s.step_mode,
        "cycle_ns": s.cycle_ns,
        "slaves": len(host.config.slaves),
        "bus_up": True,
        "axes": [],
    }


@_op
def positions(ctx: Any, position: int | None = None) -> list[int]:
    """``[position]`` (checked) or every slave's."""
    return _check(ctx.host, position)


@_op
def slaves(ctx: Any, position: int | None = None) -> list[dict[str, Any]]:
    """The rows of ``gtecat slaves``: the slave's own AL state; axes and GT raw region as
    a controller with this ENI numbers them; ``link`` down behind a link_down fault."""
    from gtecat.drives.slave import AlState

    host = ctx.host
    cut = _cut(host)
    rows = []
    for pos in _check(host, position):
        cfg, slave, sl = host.config.slaves[pos], host.chain.slaves[pos], host.layout.slaves[pos]
        rows.append(
            {
                "position": pos,
                "state": AlState(slave.al_state).name,
                "name": cfg.name,
                "vendor_id": cfg.identity.vendor_id,
                "product_code": cfg.identity.product_code,
                "revision": cfg.identity.revision_no,
                "axes": list(sl.axes),
                "gt_offset": sl.gt_offset,
                "gt_size": sl.gt_size,
                "link": "down" if pos in cut else "up",
            }
        )
    return rows


@_op
def pdos(ctx: Any, position: int | None = None) -> list[dict[str, Any]]:
    """The PDOs the ENI assigns (the rows of ``gtecat pdos``)."""
    from ..controller.inspect import pdo_rows

    return pdo_rows(ctx.host.config, _check(ctx.host, position))


@_op
def states(ctx: Any, position: int | None = None, target: str | None = None) -> list[dict]:
    """Each slave's AL state and status code (the rows of ``gtecat states``)."""
    from gtecat.drives.slave import AlState

    from ..controller.inspect import al_code_name

    if target is not None:
        raise ParameterError(
            "a gtecat serve does not change its slaves' states: its master does (or inject "
            "a fault: gtecat fault inject al_error / retreat_safeop / power_cycle)"
        )
    host = ctx.host
    rows = []
    for pos in _check(host, position):
        slave = host.chain.slaves[pos]
        state, code = AlState(slave.al_state).name, int(slave.al_status_code)
        rows.append(
            {
                "position": pos,
                "name": host.config.slaves[pos].name,
                "before": state,
                "state": state,
                "status_code": code if slave.al_error else 0,
                "status": al_code_name(code) if slave.al_error and code else "",
                "refused": None,
            }
        )
    return rows


def _esc(host: ServeHost, position: int) -> Any:
    pos = _check(host, position)[0]
    return next(e for e in (*host.chain.escs, *host.chain.cut) if e.position == pos)


@_op
def reg_read(ctx: Any, position: int, address: int, size: int) -> str:
    """ESC memory as the slave's ESC holds it (hex).  Not a read on the wire: no event
    is acknowledged, no mailbox emptied, so the master on the wire misses nothing."""
    from gtecat.drives.esc.registers import MEMORY_SIZE

    esc = _esc(ctx.host, position)
    address, size = int(address), int(size)
    if size < 1 or address < 0 or address + size > MEMORY_SIZE:
        raise ParameterError(f"0x{address:04X}+{size} is outside the ESC's 64 KiB")
    return bytes(esc.mem[address : address + size]).hex()


@_op
def sii(ctx: Any, position: int) -> str:
    """The slave's SII EEPROM (hex): what the serve built from the ENI."""
    return bytes(_esc(ctx.host, position).sii).hex()


class _Dictionaries:
    """The slaves' object dictionaries, as :class:`gtecat.controller.inspect.BusView`'s
    dictionary look-ups (``sdo_find``) expect them."""

    def __init__(self, host: ServeHost) -> None:
        self.host = host

    def check(self, position: int) -> int:
        return _check(self.host, position)[0]

    def od(self, position: int) -> Any:
        slave = self.host.chain.slaves[self.check(position)]
        od = getattr(slave, "od", None)
        if od is None:
            raise BusError(f"slave {slave.position} ({slave.name}) has no CoE object dictionary")
        return od


@_op
def sdo_upload(ctx: Any, slave: int, index: int, subindex: int) -> dict[str, Any]:
    """An object's value from the slave's own dictionary (hex), with its name and type.
    Not an SDO on the wire: the master's mailbox exchange is not touched (and a mailbox
    fault does not apply to it)."""
    od = _Dictionaries(ctx.host).od(slave)
    raw = od.upload(int(index), int(subindex))
    return {"bytes": bytes(raw).hex(), **sdo_entry(ctx, slave, index, subindex)}


@_op
def sdo_entry(ctx: Any, slave: int, index: int, subindex: int) -> dict[str, str]:
    """The dictionary's name and type of an object ({} when the slave has none)."""
    try:
        od = _Dictionaries(ctx.host).od(slave)
    except BusError:
        return {}
    var = od.find(int(index), int(subindex))
    return {"name": var.name, "type": var.data_type.name} if var is not None else {}


@_op
def sdo_find(ctx: Any, slave: int, name: str, subindex: int | None = None) -> dict[str, Any]:
    """The object called ``name`` in the slave's dictionary: {index, subindex, name, type}."""
    from ..controller.inspect import BusView

    sub = None if subindex is None else int(subindex)
    return BusView.sdo_find(_Dictionaries(ctx.host), int(slave), str(name), sub)  # type: ignore[arg-type]


@_op
def snapshot(ctx: Any) -> dict[str, Any]:
    """What changes: the slaves' AL states and status codes, the link, the counters."""
    host = ctx.host
    s = host.server
    chain_slaves = host.chain.slaves
    return {
        "t_ms": host.t_ms(),
        "cycles": s.stats.steps,
        "states": [int(sl.al_state) for sl in chain_slaves],
        "codes": [int(sl.al_status_code) if sl.al_error else 0 for sl in chain_slaves],
        "link_down_after": min(_cut(host), default=None),
        "received": s.stats.received,
        "sent": s.stats.sent,
        "dropped": host.chain.stats.dropped,
        "log_lines": len(host.log.lines),
        "faults": 0 if host.injector is None else len(host.injector.entries),
    }


@_op
def log(ctx: Any, start: int = 0) -> dict[str, Any]:
    """The serve's log lines from ``start`` on (there are no GT calls on a serve)."""
    start = max(0, int(start))
    return {"start": start, "lines": ctx.host.log.lines[start:], "gt_errors": []}


def _fault_ops() -> None:
    from . import ops

    for name in ("fault_inject", "fault_list", "fault_clear"):
        OPS[name] = ops.OPS[name]


_fault_ops()


def publish(host: ServeHost) -> ServeEndpoint | None:
    """Publish ``host``'s endpoint (unless ``GTECAT_INSPECT=0``); a folder that cannot be
    used is one warning on stderr, never a failed serve."""
    if not enabled():
        return None
    ep = ServeEndpoint(host)
    try:
        ep.publish()
    except Exception as e:
        ep.close()
        print(f"warning: no inspection endpoint: {e}", file=sys.stderr)
        return None
    return ep


__all__ = ["OPS", "ServeEndpoint", "ServeHost", "publish"]
