"""What a client may ask of a controller process beyond the GT API: the field side and the bus.

The GT functions cross the socket as the table declares them; the emulator's Python
objects (``GTE_Controller()``, ``GTE_Slave()``, a :class:`~gtecat.controller.recorder.Recorder`)
cannot.  This module declares the small set of operations that stand in for them, one
function per operation (:data:`OPS`); the controller runs them under its call lock
(:mod:`gtecat.native.server`, message ``FIELD``) and :class:`gtecat.native.client.Field`
is their Python face.  Arguments and results are plain JSON values (bytes as hex text).

* the bus, as the inspection verbs show it: :func:`slaves`, :func:`pdos`,
  :func:`sdo_upload`, :func:`sdo_download` (``gtecat slaves|pdos|sdo --controller``);
* the field side of the emulated bus, what a test does to the machine: a drive fault
  (:func:`inject_fault`, :func:`clear_injected_fault`), the mechanics pushed
  (:func:`set_machine_position`), an analog input, an IO terminal's input
  (:func:`set_input`, :func:`set_input_bit`) and output (:func:`get_output`), a drive's
  state (:func:`drive`);
* traces: :func:`trace_start` / :func:`trace_read` / :func:`trace_stop` record signals
  every cycle in the controller (the specs of :mod:`gtecat.controller.recorder`); a
  client's traces stop when it disconnects.

:func:`slave_rows` and :func:`pdo_rows` are also what ``gtecat slaves|pdos`` print for
a bus of their own, so both ways show the same rows.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

from drives.slave import AlState
from eni.model import Direction

from ..controller.core import Controller
from ..errors import BusError, ParameterError


# --- rows shared with the inspection verbs -----------------------------------------------------
def check_position(count: int, position: int) -> int:
    if not 0 <= position < count:
        raise ParameterError(
            f"no slave {position}: the bus has slaves 0..{count - 1}"
            if count
            else f"no slave {position}: the bus has none"
        )
    return position


def slave_rows(master: Any, positions: Sequence[int]) -> list[dict[str, Any]]:
    """One row per slave: position, AL state, identity, axes, GT raw region."""
    states = master.refresh_states()
    rows = []
    for pos in positions:
        sl, cfg = master.layout.slaves[pos], master.layout.config.slaves[pos]
        rows.append(
            {
                "position": sl.position,
                "state": AlState(states[pos]).name,
                "name": cfg.name,
                "vendor_id": cfg.identity.vendor_id,
                "product_code": cfg.identity.product_code,
                "revision": cfg.identity.revision_no,
                "axes": list(sl.axes),
                "gt_offset": sl.gt_offset,
                "gt_size": sl.gt_size,
            }
        )
    return rows


def pdo_rows(config: Any, positions: Sequence[int]) -> list[dict[str, Any]]:
    """Per slave its assigned PDOs (sync manager, direction) and their entries."""
    out = []
    for pos in positions:
        s = config.slaves[pos]
        pdos = []
        for d, plist in ((Direction.OUT, s.rx_pdos), (Direction.IN, s.tx_pdos)):
            for p in plist:
                pdos.append(
                    {
                        "dir": "out" if d == Direction.OUT else "in",
                        "sm": p.sm,
                        "index": p.index,
                        "name": p.name,
                        "entries": [
                            {
                                "index": e.index,
                                "subindex": e.subindex,
                                "bits": e.bit_len,
                                "name": e.name,
                                "type": e.data_type,
                            }
                            for e in p.entries
                        ],
                    }
                )
        out.append({"position": s.position, "name": s.name, "pdos": pdos})
    return out


# --- the operations ----------------------------------------------------------------------------
@dataclass(eq=False)
class Context:
    """What an operation runs on: the open controller and the asking client's traces."""

    ctl: Controller
    traces: dict[int, Any] = field(default_factory=dict)
    next_trace: int = 1

    def stop_traces(self) -> None:
        for rec in self.traces.values():
            rec.stop()
        self.traces.clear()


Op = Callable[..., Any]
#: operation name -> function(ctx, *args); the wire's and Field's names
OPS: dict[str, Op] = {}


def _op(fn: Op) -> Op:
    OPS[fn.__name__] = fn
    return fn


def _master(ctx: Context) -> Any:
    m = ctx.ctl.master
    if m is None:
        raise BusError("the bus is not up yet (GT_InitEcatComm first)")
    return m


def _positions(ctx: Context, position: int | None) -> list[int]:
    n = len(_master(ctx).layout.slaves)
    return [check_position(n, int(position))] if position is not None else list(range(n))


def _virtual(ctx: Context, slave: int) -> Any:
    from ..master.backends.emulated import EmulatedBackend

    backend = ctx.ctl.backend
    if not isinstance(backend, EmulatedBackend):
        raise BusError(
            "the field side exists on the emulated bus only (GT_InitEcatComm first; "
            f"this controller's bus is {type(backend).__name__})"
        )
    return backend.slaves[check_position(len(backend.slaves), int(slave))]


def _channel(ctx: Context, slave: int, channel: int) -> Any:
    s = _virtual(ctx, slave)
    if not hasattr(s, "channel"):
        raise ParameterError(f"slave {slave} ({s.name}) is not a drive")
    try:
        return s.channel(int(channel))
    except (IndexError, KeyError, ValueError):
        raise ParameterError(f"slave {slave} has no drive channel {channel}") from None


def _io(ctx: Context, slave: int) -> Any:
    s = _virtual(ctx, slave)
    if not hasattr(s, "set_input"):
        raise ParameterError(f"slave {slave} ({s.name}) is not an IO terminal")
    return s


@_op
def slaves(ctx: Context, position: int | None = None) -> list[dict[str, Any]]:
    return slave_rows(_master(ctx), _positions(ctx, position))


@_op
def pdos(ctx: Context, position: int | None = None) -> list[dict[str, Any]]:
    return pdo_rows(_master(ctx).layout.config, _positions(ctx, position))


def _od_entry(ctx: Context, slave: int, index: int, subindex: int) -> dict[str, str]:
    """The emulated slave's dictionary name and type of an object ({} if unknown)."""
    try:
        od = getattr(_virtual(ctx, slave), "od", None)
    except BusError:
        return {}
    var = od.find(index, subindex) if od is not None else None
    return {"name": var.name, "type": var.data_type.name} if var is not None else {}


@_op
def sdo_upload(ctx: Context, slave: int, index: int, subindex: int) -> dict[str, Any]:
    """{"bytes": hex, "name"/"type": the dictionary's, where the emulated slave has one}."""
    m = _master(ctx)
    check_position(len(m.layout.slaves), int(slave))
    raw = m.sdo_upload(int(slave), int(index), int(subindex))
    return {"bytes": raw.hex(), **_od_entry(ctx, slave, index, subindex)}


@_op
def sdo_download(ctx: Context, slave: int, index: int, subindex: int, data: str) -> None:
    m = _master(ctx)
    check_position(len(m.layout.slaves), int(slave))
    m.sdo_download(int(slave), int(index), int(subindex), bytes.fromhex(data))


@_op
def sdo_entry(ctx: Context, slave: int, index: int, subindex: int) -> dict[str, str]:
    """The dictionary's name and type of an object ({} when the slave has no dictionary)."""
    check_position(len(_master(ctx).layout.slaves), int(slave))
    return _od_entry(ctx, slave, index, subindex)


@_op
def inject_fault(ctx: Context, slave: int, kind: str | int, channel: int = 0) -> int:
    """A drive fault (``"alarm"``, ``"encoder"``, ... or a 603Fh code); returns its code."""
    return int(_channel(ctx, slave, channel).inject_fault(kind))


@_op
def clear_injected_fault(ctx: Context, slave: int, channel: int = 0) -> None:
    _channel(ctx, slave, channel).clear_injected_fault()


@_op
def set_machine_position(ctx: Context, slave: int, value: float, channel: int = 0) -> None:
    """Push the mechanics (limit and home switches follow the position)."""
    _channel(ctx, slave, channel).machine_position = float(value)


@_op
def set_analog_input(ctx: Context, slave: int, n: int, value: int, channel: int = 0) -> None:
    _channel(ctx, slave, channel).set_analog_input(int(n), int(value))


@_op
def drive(ctx: Context, slave: int, channel: int = 0) -> dict[str, Any]:
    """A drive channel as the field sees it: CiA-402 state, words, positions."""
    ch = _channel(ctx, slave, channel)
    return {
        "state": getattr(ch.state, "name", str(ch.state)),
        "statusword": int(ch.statusword),
        "error_code": int(ch.error_code),
        "mode_display": int(ch.mode_display),
        "position_actual": int(ch.position_actual),
        "machine_position": float(ch.machine_position),
    }


@_op
def set_input(ctx: Context, slave: int, index: int, subindex: int, value: int) -> None:
    """What an IO terminal reads on an input object (from the next cycle)."""
    try:
        _io(ctx, slave).set_input(int(index), int(subindex), int(value))
    except KeyError as e:
        raise ParameterError(str(e.args[0]) if e.args else str(e)) from None


@_op
def set_input_bit(ctx: Context, slave: int, bit: int, on: bool) -> None:
    s = _io(ctx, slave)
    if not 0 <= int(bit) < len(s.field_inputs) * 8:
        raise ParameterError(f"slave {slave}: no input bit {bit}")
    s.set_input_bit(int(bit), bool(on))


@_op
def get_output(ctx: Context, slave: int, index: int, subindex: int) -> int:
    try:
        return int(_io(ctx, slave).get_output(int(index), int(subindex)))
    except KeyError as e:
        raise ParameterError(str(e.args[0]) if e.args else str(e)) from None


@_op
def trace_start(ctx: Context, specs: list[str]) -> int:
    """Record ``specs`` after every cycle from now on; returns the trace's id."""
    from ..controller.recorder import Recorder

    if isinstance(specs, str):
        specs = [s for s in specs.split(",") if s.strip()]
    rec = Recorder(ctx.ctl, list(specs)).start()
    tid = ctx.next_trace
    ctx.next_trace += 1
    ctx.traces[tid] = rec
    return tid


def _trace(ctx: Context, tid: int) -> Any:
    rec = ctx.traces.get(int(tid))
    if rec is None:
        raise ParameterError(f"no trace {tid} on this connection")
    return rec


@_op
def trace_read(ctx: Context, tid: int, start: int = 0) -> dict[str, Any]:
    """{"names": [...], "rows": [[time_ms, value, ...], ...]} from row ``start`` on."""
    rec = _trace(ctx, tid)
    return {"names": list(rec.names), "rows": rec.data[int(start) :].tolist()}


@_op
def trace_stop(ctx: Context, tid: int) -> None:
    _trace(ctx, tid).stop()
    del ctx.traces[int(tid)]


@_op
def cycle_stats(ctx: Context) -> dict[str, Any]:
    from ..master.backends.cycle_stats import cycle_stats as stats

    return stats(ctx.ctl)


def run(ctx: Context, op: str, args: Sequence[Any]) -> Any:
    """Run one operation (KeyError-free: an unknown name is a ParameterError)."""
    fn = OPS.get(op)
    if fn is None:
        raise ParameterError(f"no field operation {op!r} (there are {', '.join(sorted(OPS))})")
    try:
        return fn(ctx, *args)
    except TypeError as e:  # wrong number of arguments from a client
        if "positional argument" in str(e):
            raise ParameterError(f"{op}: {e}") from None
        raise


__all__ = ["OPS", "Context", "check_position", "pdo_rows", "run", "slave_rows"]
