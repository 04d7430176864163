"""What a client may ask of a controller process beyond the GT API: the field side and the bus.

The GT functions cross the socket as the table declares them; the emulator's Python
objects (``GTE_Controller()``, ``GTE_Slave()``, a :class:`~gtecat.controller.recorder.Recorder`)
cannot.  This module declares the small set of operations that stand in for them, one
function per operation (:data:`OPS`); the controller runs them under its call lock
(:mod:`gtecat.native.server`, message ``FIELD``) and :class:`gtecat.native.client.Field`
is their Python face.  Arguments and results are plain JSON values (bytes as hex text).

* the bus, as the inspection verbs show it (``gtecat VERB --controller``): :func:`positions`,
  :func:`slaves`, :func:`pdos`, :func:`sdo_upload`, :func:`sdo_download`, :func:`sdo_entry`,
  :func:`sdo_find`, :func:`sdos`, :func:`states`, :func:`reg_read`, :func:`reg_write`,
  :func:`sii`, :func:`data`, :func:`cstruct`, :func:`graph`; each is the method of the same
  name of :class:`gtecat.controller.inspect.BusView`, which a verb calls itself on a bus of
  its own, so both ways print the same;
* the field side of the emulated bus, what a test does to the machine: a drive fault
  (:func:`inject_fault`, :func:`clear_injected_fault`), the mechanics pushed
  (:func:`set_machine_position`), an analog input, an IO terminal's input
  (:func:`set_input`, :func:`set_input_bit`) and output (:func:`get_output`), a drive's
  state (:func:`drive`);
* traces: :func:`trace_start` / :func:`trace_read` / :func:`trace_stop` record signals
  every cycle in the controller (the specs of :mod:`gtecat.controller.recorder`); a
  client's traces stop when it disconnects.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

from ..controller.core import Controller
from ..controller.inspect import BusView, check_position, pdo_rows, slave_rows, view
from ..errors import BusError, ParameterError


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


def _view(ctx: Context) -> BusView:
    if ctx.ctl.master is None:
        raise BusError("the bus is not up yet (GT_InitEcatComm first)")
    return view(ctx.ctl)


@_op
def positions(ctx: Context, position: int | None = None) -> list[int]:
    """``[position]`` (checked) or every slave's."""
    return _view(ctx).positions(position)


@_op
def slaves(ctx: Context, position: int | None = None) -> list[dict[str, Any]]:
    return _view(ctx).slaves(position)


@_op
def pdos(ctx: Context, position: int | None = None) -> list[dict[str, Any]]:
    return _view(ctx).pdos(position)


@_op
def sdo_upload(ctx: Context, slave: int, index: int, subindex: int) -> dict[str, Any]:
    """{"bytes": hex, "name"/"type": the dictionary's, where the emulated slave has one}."""
    v = _view(ctx)
    raw = v.sdo_upload(slave, index, subindex)
    return {"bytes": raw.hex(), **v.sdo_entry(slave, index, subindex)}


@_op
def sdo_download(ctx: Context, slave: int, index: int, subindex: int, data: str) -> None:
    _view(ctx).sdo_download(slave, index, subindex, bytes.fromhex(data))


@_op
def sdo_entry(ctx: Context, slave: int, index: int, subindex: int) -> dict[str, str]:
    """The dictionary's name and type of an object ({} when the slave has no dictionary)."""
    return _view(ctx).sdo_entry(slave, index, subindex)


@_op
def sdo_find(ctx: Context, slave: int, name: str, subindex: int | None = None) -> dict[str, Any]:
    """The object called ``name`` in the slave's dictionary: {index, subindex, name, type}."""
    return _view(ctx).sdo_find(slave, str(name), None if subindex is None else int(subindex))


@_op
def sdos(
    ctx: Context, position: int | None = None, values: bool = True, grep: str | None = None
) -> list[dict[str, Any]]:
    return _view(ctx).sdos(position, bool(values), grep)


@_op
def states(ctx: Context, position: int | None = None, target: str | None = None) -> list[dict]:
    return _view(ctx).states(position, target)


@_op
def reg_read(ctx: Context, position: int, address: int, size: int) -> str:
    """The bytes (hex) of an ESC register range."""
    return _view(ctx).reg_read(position, address, size).hex()


@_op
def reg_write(ctx: Context, position: int, address: int, data: str) -> None:
    _view(ctx).reg_write(position, address, bytes.fromhex(data))


@_op
def sii(ctx: Context, position: int) -> str:
    """The slave's SII (hex)."""
    return _view(ctx).sii(position).hex()


@_op
def data(ctx: Context, position: int | None = None, cycles: int = 0) -> list[dict[str, Any]]:
    return _view(ctx).data(position, int(cycles))


@_op
def cstruct(ctx: Context, prefix: str = "", position: int | None = None) -> str:
    return _view(ctx).cstruct(str(prefix), position)


@_op
def graph(ctx: Context) -> str:
    return _view(ctx).graph()


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
