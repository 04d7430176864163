"""Record chosen values every cycle into a numpy buffer (traces, CSV, plots).

A signal is named by a short spec:

* ``S:0xIIII:SS`` - PDO entry ``index:subindex`` of slave ``S`` (either direction),
  e.g. ``0:0x6041:0``; an ENI ``ProcessImage`` variable name works too;
* ``axisN.X`` - axis ``N``'s
  ``prf`` planned position (pulse), ``enc`` encoder position 6064h (counts),
  ``err`` planned minus actual (pulse), ``vel`` planned velocity (pulse/ms),
  ``encvel`` actual velocity (606Ch when mapped, else 6064h per ms; counts/ms),
  ``sw`` statusword 6041h, ``cw`` controlword 6040h, ``mode`` modes of operation display
  6061h (read from the emulated drive when the ENI does not map it), ``state`` the CiA-402
  state the statusword shows, ``machine`` the true mechanical position (emulated drives only).

Samples are taken after every cycle (``Controller.sample`` hook), so a trace
is exactly what the bus carried, cycle by cycle; each row is stamped with the
controller time at the end of its cycle, the time ``GT_GetClock`` and the
``pClock`` of ``GT_GetPrfPos`` report for the same values.  The buffer grows by doubling
(amortised O(1) per sample, one numpy row write).

Each signal has a kind that decides how it is plotted: ``value`` (a line), ``bits`` (a word
of named bits: statusword, controlword, 60FDh digital inputs, IO bytes: one stepped row per
bit that is ever set), ``state`` (the CiA-402 state: a labelled band) and ``mode`` (6061h:
a labelled band).
"""

from __future__ import annotations

import csv
import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from gtecat.drives.cia402 import STATE_PATTERN, Cw, State, Sw
from gtecat.drives.modes import OpMode
from gtecat.eni.numbers import parse_int

from ..errors import ParameterError
from .core import Controller

Getter = Callable[[], float]

_ENTRY = re.compile(r"^(\d+):(0x[0-9a-fA-F]+|#x[0-9a-fA-F]+|\d+):(0x[0-9a-fA-F]+|\d+)$")
AXIS_SIGNALS = ("prf", "enc", "err", "vel", "encvel", "sw", "cw", "mode", "state", "machine")
_AXIS = re.compile(rf"^axis(\d+)\.({'|'.join(AXIS_SIGNALS)})$")

#: bit names of the words a trace shows as bit rows (CiA 402, 60FDh of CiA 402 8.4.2)
SW_BITS = {
    0: "ready to switch on",
    1: "switched on",
    2: "operation enabled",
    3: "fault",
    4: "voltage enabled",
    5: "quick stop (0 = active)",
    6: "switch on disabled",
    7: "warning",
    9: "remote",
    10: "target reached",
    11: "internal limit active",
    12: "bit 12 (set-point ack / homing attained / following)",
    13: "bit 13 (following error / homing error)",
}
CW_BITS = {
    0: "switch on",
    1: "enable voltage",
    2: "quick stop (0 = active)",
    3: "enable operation",
    4: "bit 4 (new set-point / homing start)",
    5: "bit 5",
    6: "bit 6",
    7: "fault reset",
    8: "halt",
}
DI_BITS = {0: "negative limit", 1: "positive limit", 2: "home switch", 16: "probe 1", 17: "probe 2"}
STATE_NAMES = {int(s): s.name.replace("_", " ").lower() for s in State}
MODE_NAMES = {
    0: "no mode",
    1: "PP",
    2: "VL",
    3: "PV",
    4: "TQ",
    6: "homing",
    7: "IP",
    8: "CSP",
    9: "CSV",
    10: "CST",
}
assert set(MODE_NAMES) >= {int(m) for m in OpMode}


@dataclass(frozen=True, slots=True)
class Kind:
    """How a signal is shown: a line, named bits, or a band of named values."""

    kind: str  # "value" | "bits" | "state" | "mode"
    unit: str = ""
    bits: dict[int, str] | None = None  # bit number -> name (bits)
    width: int = 16


VALUE = Kind("value")


def state_of(statusword: int) -> int:
    """The CiA-402 state code a statusword shows (-1 when it matches no pattern)."""
    for state, (mask, value) in STATE_PATTERN.items():
        if statusword & mask == value:
            return int(state)
    return -1


def _drive_mode(ctl: Controller, n: int) -> Getter:
    """6061h of axis ``n`` read from the emulated drive (when the ENI does not map it)."""
    from ..master.backends.emulated import EmulatedBackend

    ax = ctl.axis(n)
    backend = ctl.backend
    if not isinstance(backend, EmulatedBackend):
        raise ParameterError(
            f"axis{n}.mode: slave {ax.io.slave} maps no 0x6061:00 (modes of operation display); "
            "on a real bus map it in the ENI (`gtecat map` lists what is mapped)"
        )
    slave = backend.slaves[ax.io.slave]
    var = slave.od.find(0x6061 + 0x800 * ax.io.channel, 0)
    if var is None:
        raise ParameterError(f"axis{n}.mode: the drive has no 0x6061:00")
    return lambda: float(var.get())


def _axis_getter(ctl: Controller, n: int, what: str) -> tuple[Getter, Kind]:
    ax = ctl.axis(n)
    if what == "prf":
        return (lambda: ax.prf_pos), Kind("value", "pulse")
    if what == "enc":
        acc = ax.io.require(0x6064)
        return acc.get, Kind("value", "counts")
    if what == "err":
        acc = ax.io.require(0x6064)
        return (lambda: ax.prf_pos - ax.counts_to_pulses(acc.get())), Kind("value", "pulse")
    if what == "vel":
        from .resources import axis_resources

        res = axis_resources(ctl, n)
        return (lambda: res.axis_prf_vel), Kind("value", "pulse/ms")
    if what == "encvel":
        mapped = ax.io.get(0x606C)
        if mapped is not None:  # 606Ch is counts/s (CiA 402): per ms like the planned velocity
            return (lambda: mapped.get() / 1000.0), Kind("value", "counts/ms")
        acc = ax.io.require(0x6064)
        last = [float(acc.get()), ctl.clock.now_ns]

        def derived() -> float:
            now, pos = ctl.clock.now_ns, float(acc.get())
            dt = (now - last[1]) / 1e6
            v = (pos - last[0]) / dt if dt > 0 else 0.0
            last[0], last[1] = pos, now
            # a jump no drive moves (homing redefines 6064h): not a velocity
            return v if abs(v) < 1e5 else float("nan")

        return derived, Kind("value", "counts/ms")
    if what == "sw":
        return ax.io.require(0x6041).get, Kind("bits", bits=SW_BITS)
    if what == "cw":
        return ax.io.require(0x6040).get, Kind("bits", bits=CW_BITS)
    if what == "state":
        sw = ax.io.require(0x6041).get
        return (lambda: float(state_of(int(sw())))), Kind("state")
    if what == "mode":
        mode = ax.io.get(0x6061)
        return (mode.get if mode is not None else _drive_mode(ctl, n)), Kind("mode")
    # machine: the emulated drive's true mechanical position
    from ..master.backends.emulated import EmulatedBackend

    backend = ctl.backend
    slaves = backend.slaves if isinstance(backend, EmulatedBackend) else None
    if slaves is None:
        raise ParameterError(f"axis{n}.machine needs the emulated backend")
    channel = slaves[ax.io.slave].channel(ax.io.channel)
    return (lambda: float(channel.machine_position)), Kind("value", "counts")


_IO_NAME = re.compile(r"\b(D[IO]|digital|byte)\b", re.I)


def _entry_kind(index: int, bits: int, name: str) -> Kind:
    base = index
    for k in range(8):  # channel k of a multi-axis module: +0x800·k
        if index - 0x800 * k in (0x6041, 0x6040, 0x6061, 0x60FD):
            base = index - 0x800 * k
            break
    if base == 0x6041 and bits == 16:
        return Kind("bits", bits=SW_BITS)
    if base == 0x6040 and bits == 16:
        return Kind("bits", bits=CW_BITS)
    if base == 0x6061 and bits == 8:
        return Kind("mode")
    if base == 0x60FD:
        return Kind("bits", bits=DI_BITS, width=bits)
    if bits == 1:
        return Kind("bits", bits={0: name or "on"}, width=1)
    if 0x6000 <= index < 0x8000 and bits <= 32 and _IO_NAME.search(name):
        return Kind("bits", width=bits)  # IO terminal bytes: the bits that switch
    return VALUE


def signal_kind(ctl: Controller, spec: str) -> tuple[Getter, Kind]:
    """A getter for one signal spec and how to show it (see the module docstring)."""
    spec = spec.strip()
    m = _AXIS.match(spec)
    if m:
        return _axis_getter(ctl, int(m.group(1)), m.group(2))
    if spec == "faults":  # how many injected faults are active (gtecat.faults)

        def active() -> float:
            inj = getattr(ctl.backend, "injector", None)
            return float(sum(e.state == "active" for e in inj.entries)) if inj else 0.0

        return active, Kind("value", "faults")
    master = ctl.require_master()
    layout = master.layout
    m = _ENTRY.match(spec)
    if m:
        slave, index, sub = int(m.group(1)), parse_int(m.group(2)), parse_int(m.group(3))
        p = layout.entry(slave, index, sub)
        if p is None:
            raise ParameterError(f"slave {slave} maps no 0x{index:04X}:{sub:02X}")
        return master.image.access(p).get, _entry_kind(index, p.bits, p.name or "")
    for var in layout.config.variables:
        if var.name == spec:
            from gtecat.eni.layout import Placement

            p = Placement(
                slave=-1,
                direction=var.direction,
                pdo=0,
                index=0,
                subindex=0,
                name=var.name,
                bits=var.bit_size,
                data_type=var.data_type,
                signed=var.data_type.upper() in {"SINT", "INT", "DINT", "LINT"},
                logical_bit=var.bit_offset,
                gt_bit=0,
                slave_bit=0,
            )
            kind = Kind("bits", bits={0: var.name}, width=1) if var.bit_size == 1 else VALUE
            return master.image.access(p).get, kind
    raise ParameterError(
        f"unknown signal {spec!r}: use SLAVE:INDEX:SUB (e.g. 0:0x6041:0), an ENI variable "
        f"name, faults, or axisN.{'|'.join(AXIS_SIGNALS)}"
    )


def signal(ctl: Controller, spec: str) -> Getter:
    """A getter for one signal spec (see the module docstring)."""
    return signal_kind(ctl, spec)[0]


class Recorder:
    """Samples signals after every cycle while attached to a controller."""

    def __init__(self, ctl: Controller, specs: Sequence[str], capacity: int = 4096) -> None:
        self.ctl = ctl
        self.names = [s.strip() for s in specs]
        pairs = [signal_kind(ctl, s) for s in self.names]
        self._getters = [g for g, _ in pairs]
        self.kinds = [k for _, k in pairs]
        self._buf = np.zeros((max(16, capacity), 1 + len(self.names)), dtype=np.float64)
        self.n = 0
        self._attached = False
        self.events: list[tuple[float, str]] = []  # (ms, text) marks for plots

    def start(self) -> Recorder:
        if not self._attached:
            self.ctl.sample.append(self._sample)
            self._attached = True
        return self

    def stop(self) -> None:
        if self._attached:
            self.ctl.sample.remove(self._sample)
            self._attached = False

    def mark(self, text: str) -> None:
        """An event line on the plot at the current controller time."""
        self.events.append((self.ctl.clock.now_ns / 1e6, text))

    def _sample(self, t_ns: int) -> None:
        if self.n == len(self._buf):
            self._buf = np.concatenate([self._buf, np.zeros_like(self._buf)])
        row = self._buf[self.n]
        row[0] = t_ns / 1e6
        for i, g in enumerate(self._getters, start=1):
            row[i] = g()
        self.n += 1

    @property
    def data(self) -> np.ndarray:
        """``(n, 1 + signals)`` array; column 0 is controller time in ms."""
        return self._buf[: self.n]

    def column(self, name: str) -> np.ndarray:
        return self.data[:, 1 + self.names.index(name)]

    def to_csv(self, path: str | Path) -> Path:
        """One row per cycle, numbers only (states: ``State`` codes, modes: 6061h values)."""
        path = Path(path)
        with path.open("w", newline="", encoding="utf-8") as fh:
            w = csv.writer(fh)
            w.writerow(["time_ms", *self.names])
            for row in self.data:
                w.writerow([f"{row[0]:.3f}", *(f"{v:.6g}" for v in row[1:])])
        return path

    def plot(self, path: str | Path, title: str = "gtecat trace") -> Path:
        """Values as lines (one panel per unit), bit words as stepped rows of named bits,
        CiA-402 states and modes as labelled bands; event marks as vertical lines."""
        from .trace_plot import plot_recorder

        return plot_recorder(self, Path(path), title)


# keep the statusword/controlword flag types importable from here for plots and tests
__all__ = ["CW_BITS", "DI_BITS", "SW_BITS", "Cw", "Kind", "Recorder", "Sw", "signal", "state_of"]
