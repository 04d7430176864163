"""What an inspection endpoint answers beyond the bus verbs' operations.

The bus verbs' operations are :data:`gtecat.native.field.OPS` (the same functions a
``gtecat controller`` runs for ``--controller``).  This module adds what the panel reads
every few tens of milliseconds and the few commands it may send:

* :func:`info` - who this is (pid, kind, ENI, clock, backend, cycle time);
* :func:`layout` - slaves and PDO entries with their bit offsets in the logical image and
  in the GT raw image (the ``gtecat map --json`` document, plus each entry's type), the
  axes, the names of the GT status bits; asked once;
* :func:`snapshot` - the process image bytes, every slave's AL state and status code, the
  last cycle's working counter and the count of short ones (every cycle's, kept by the
  master), and per axis what the GT readers return (planned and
  encoder positions, velocity, following error, ``GT_GetSts``); asked at the page's rate.
  It reads what the master and the axis resources hold (the bank-aware readers, so a
  vectorised axis is not released by being looked at);
* :func:`log` - the master log from a line on, and the recent non-zero GT returns;
* :func:`jog`, :func:`trap`, :func:`stop` - motion as ``GT_PrfJog``/``GT_PrfTrap`` +
  ``GT_SetVel``/``GT_SetPos`` + ``GT_Update`` and ``GT_Stop`` would start it, with the same
  checks and refusals (an axis must be servo-on, in CSP, without a blocking flag).

Every operation runs between two cycles (:mod:`.endpoint`), so it never waits for one.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from ..errors import BusError, ParameterError

Op = Callable[..., Any]
OPS: dict[str, Op] = {}
#: operations that change the machine (the panel sends them only with --control)
CONTROL = frozenset(
    {
        "jog",
        "trap",
        "stop",
        "sdo_download",
        "reg_write",
        "states",
        "set_input_bit",
        "set_input",
        "fault_inject",
        "fault_clear",
    }
)


#: operations a client may subscribe to (pushed at a period, gtecat.inspect.endpoint)
PUSHABLE = frozenset({"snapshot"})


def _op(fn: Op) -> Op:
    OPS[fn.__name__] = fn
    return fn


def _master(ctx: Any) -> Any:
    m = ctx.ctl.master
    if m is None:
        raise BusError("the bus is not up yet (GT_InitEcatComm first)")
    return m


def _session_of(ctl: Any) -> Any:
    """gt's session when ``ctl`` is one of its cards (the GT error ring is that session's)."""
    from ..gt import _core

    s = _core.SESSION
    return s if s.where(ctl) is not None else None


@_op
def info(ctx: Any) -> dict[str, Any]:
    import os

    ctl = ctx.ctl
    o = ctl.options
    return {
        "pid": os.getpid(),
        "kind": ctx.kind,
        "eni": str(o.eni),
        "clock": str(o.clock),
        "backend": str(o.backend),
        "cycle_ns": ctl.clock.cycle_ns,
        "bus_up": ctl.master is not None,
        "axes": sorted(ctl.axes),
    }


@_op
def layout(ctx: Any) -> dict[str, Any]:
    m = _master(ctx)
    lay = m.layout
    doc = lay.to_json()
    by_key = {}
    for s in lay.slaves:
        for p in s.entries:
            by_key[(s.position, p.direction.value, p.index, p.subindex, p.logical_bit)] = p
    for s in doc["slaves"]:
        for e in s["entries"]:
            d = "out" if e["dir"] == "out" else "in"
            for p in lay.slaves[s["position"]].entries:
                if (
                    p.index == e["index"]
                    and p.subindex == e["subindex"]
                    and p.logical_bit == e["logical_bit"]
                    and ("out" if p.direction.name == "OUT" else "in") == d
                ):
                    e["type"] = p.data_type
                    e["signed"] = p.signed
                    break
    doc["outputs_offset"] = 0
    doc["inputs_offset"] = m.image.outputs_bytes
    doc["axes"] = [
        {"axis": ref.axis, "slave": ref.slave, "channel": getattr(ref, "channel", 0)}
        for ref in lay.axes
    ]
    # here, not at the top: a panel attached to another process imports this module for
    # CONTROL and needs none of the controller (its import, numpy and the bank, was half of
    # that panel's start)
    from ..controller.axis_status import AxisStatus

    doc["status_bits"] = {str(int(f).bit_length() - 1): f.name for f in AxisStatus}
    doc["emulated"] = _emulated(ctx.ctl)
    doc["cycle_ns"] = ctx.ctl.clock.cycle_ns
    doc.update(_names())
    return doc


def _names() -> dict[str, Any]:
    """Bit and state names the page shows (one table each, the recorder's and CiA 402's)."""
    from gtecat.drives.cia402 import STATE_PATTERN

    from ..controller.recorder import CW_BITS, DI_BITS, MODE_NAMES, SW_BITS

    return {
        "sw_bits": {str(k): v for k, v in SW_BITS.items()},
        "cw_bits": {str(k): v for k, v in CW_BITS.items()},
        "di_bits": {str(k): v for k, v in DI_BITS.items()},
        "mode_names": {str(k): v for k, v in MODE_NAMES.items()},
        "states_402": [
            [s.name.replace("_", " ").lower(), mask, value]
            for s, (mask, value) in STATE_PATTERN.items()
        ],
    }


def _emulated(ctl: Any) -> bool:
    from ..master.backends.emulated import EmulatedBackend

    return isinstance(ctl.backend, EmulatedBackend)


_AXIS_READS = ("prf_pos", "prf_vel", "enc_pos", "enc_vel", "axis_error")


@_op
def snapshot(ctx: Any) -> dict[str, Any]:
    """What changes every cycle (module docstring); cheap: one copy of the image, cached
    AL states (no bus traffic), the axes' bank-aware readers."""
    ctl = ctx.ctl
    m = _master(ctx)
    clock = ctl.clock
    axes = []
    for n, res in sorted(ctl.resources.items()):
        row = [n]
        row += [float(getattr(res, a)) for a in _AXIS_READS]
        row.append(int(res.status()))
        row.append(_homing(ctx, n, res))
        axes.append(row)
    stats = getattr(ctl.backend, "stats", None)  # pysoem's BusStats (frames it lost)
    if callable(stats):
        stats = None
    return {
        "t_ms": (clock.now_ns - ctl.reset_ns) / 1e6,
        "cycles": clock.cycles,
        "image": m.image.buffer.tobytes().hex(),
        "states": [int(s) for s in m.states],
        "codes": [int(c) for c in m._codes],
        "wkc": int(m.last.wkc),
        "expected": int(m.last.expected),
        "wkc_errors": int(m.wkc_errors),
        "lost_frames": int(getattr(stats, "lost_frames", 0) or 0),
        "error": m.error,
        "log_lines": len(ctl.log.lines),
        "axes": axes,
        "axis_fields": ["axis", *_AXIS_READS, "sts", "homing"],
    }


def _homing(ctx: Any, n: int, res: Any) -> int | None:
    """GT_GetEcatHomingStatus's value (0 homing, 3 homed, 5 not homed or failed), read
    from the homing run's own record: the axis object itself is not touched (the bank may
    be running it)."""
    from ..gt.homing_calls import _STATE, HOMING_FAILED, HOMING_IN_PROGRESS

    st = _STATE.get(ctx.ctl.axes.get(n))
    if st is None:
        return HOMING_FAILED  # no run since the bus came up: not homed
    return HOMING_IN_PROGRESS if st.active else int(st.result)


def ctl_axis(ctl: Any, n: int) -> Any:
    ax = ctl.axes.get(int(n))
    if ax is None:
        raise ParameterError(f"no axis {n}" + (f" (axes 1..{max(ctl.axes)})" if ctl.axes else ""))
    return ax


@_op
def log(ctx: Any, start: int = 0) -> dict[str, Any]:
    """Master log lines from ``start`` on, and the recent non-zero GT returns."""
    lines = ctx.ctl.log.lines
    start = max(0, int(start))
    s = _session_of(ctx.ctl)
    errors = []
    if s is not None:
        errors = [
            {"function": e.function, "code": e.code, "reason": e.reason, "clock_ms": e.clock_ms}
            for e in list(s.errors)[-20:]
        ]
    return {"start": start, "lines": lines[start:], "gt_errors": errors}


def _resources(ctx: Any, n: int) -> Any:
    """Axis ``n``'s resources, released from the bank first (as a GT call would be)."""
    from ..controller.resources import axis_resources

    ctl = ctx.ctl
    ax = ctl_axis(ctl, n)
    if ctl.bank is not None:
        ctl.bank.release_axis_object(ax)
        ctl.bank.dirty = True
    return axis_resources(ctl, int(n))


@_op
def jog(ctx: Any, axis: int, vel: float, acc: float = 0.1, dec: float = 0.1) -> None:
    """GT_PrfJog, GT_SetJogPrm, GT_SetVel(vel), GT_Update: jog at ``vel`` pulse/ms."""
    from ..controller.motion.jog import JogParams
    from ..controller.profile import PrfMode

    res = _resources(ctx, axis)
    if res.profile.mode != PrfMode.JOG or res.profile.planner.done:
        if res.profile.mode != PrfMode.JOG:
            res.prf_jog()
        res.set_jog_prm(JogParams(acc=float(acc), dec=float(dec), smooth=0.0))
    res.set_vel(float(vel))
    res.check_update()
    res.start()


@_op
def trap(ctx: Any, axis: int, pos: int, vel: float, acc: float = 0.1, dec: float = 0.1) -> None:
    """GT_PrfTrap, GT_SetTrapPrm, GT_SetPos, GT_SetVel, GT_Update: a point-to-point move."""
    from ..controller.motion.trap import TrapParams
    from ..controller.profile import PrfMode

    res = _resources(ctx, axis)
    moving = res.profile.mode == PrfMode.TRAP and not res.profile.planner.done
    if not moving:
        if res.profile.mode != PrfMode.TRAP:
            res.prf_trap()
        res.set_trap_prm(TrapParams(acc=float(acc), dec=float(dec), vel_start=0.0, smooth_time=0))
    res.set_target(int(pos))
    res.set_vel(float(vel))
    res.check_update()
    res.start()


@_op
def stop(ctx: Any, axis: int, abrupt: bool = False) -> None:
    """GT_Stop of one axis (smooth unless ``abrupt``)."""
    _resources(ctx, axis).stop(bool(abrupt))


__all__ = ["CONTROL", "OPS"]


# --- faults (gtecat.faults: ``gtecat fault``, the panel) -----------------------------------------
@_op
def fault_inject(ctx: Any, values: dict[str, Any]) -> dict[str, Any]:
    """Arm a fault from ``{"kind": ..., key: value}`` (a ``[[fault]]`` table); its listing."""
    from .. import faults

    if not isinstance(values, dict):
        raise ParameterError("a fault is {kind: ..., key: value}")
    spec = faults.spec_from_dict(values)
    fid = faults.inject(spec, ctl=ctx.ctl)
    for f in faults.listing(ctl=ctx.ctl):
        if f["id"] == fid:
            return f
    return {"id": fid, "state": "ended", "describe": spec.describe()}  # a power cycle: done


@_op
def fault_list(ctx: Any) -> list[dict[str, Any]]:
    from .. import faults

    return faults.listing(ctl=ctx.ctl)


@_op
def fault_clear(ctx: Any, ident: int | None = None) -> int:
    from .. import faults

    return faults.clear(None if ident is None else int(ident), ctl=ctx.ctl)
