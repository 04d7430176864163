"""Record chosen values every cycle into a numpy buffer (traces, CSV, plots).

A signal is named by a short spec:

* ``S:0xIIII:SS`` - PDO entry ``index:subindex`` of slave ``S`` (either direction),
  e.g. ``0:0x6041:0``; an ENI ``ProcessImage`` variable name works too;
* ``axisN.prf`` / ``.enc`` / ``.err`` / ``.sw`` / ``.cw`` / ``.mode`` / ``.machine`` -
  axis ``N``'s planned position (pulses), encoder position 6064h (counts),
  planned minus actual (pulses), statusword, controlword, mode display, and
  the true mechanical position (emulated drives only).

Samples are taken after every cycle (``Controller.sample`` hook), so a trace
is exactly what the bus carried, cycle by cycle; each row is stamped with the
controller time at the end of its cycle, the time ``GT_GetClock`` and the
``pClock`` of ``GT_GetPrfPos`` report for the same values.  The buffer grows by doubling
(amortised O(1) per sample, one numpy row write).
"""

from __future__ import annotations

import csv
import re
from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np

from eni.numbers import parse_int

from ..errors import ParameterError
from .core import Controller

Getter = Callable[[], float]

_ENTRY = re.compile(r"^(\d+):(0x[0-9a-fA-F]+|#x[0-9a-fA-F]+|\d+):(0x[0-9a-fA-F]+|\d+)$")
_AXIS = re.compile(r"^axis(\d+)\.(prf|enc|err|sw|cw|mode|machine)$")


def _axis_getter(ctl: Controller, n: int, what: str) -> Getter:
    ax = ctl.axis(n)
    if what == "prf":
        return lambda: ax.prf_pos
    if what == "enc":
        acc = ax.io.require(0x6064)
        return acc.get
    if what == "err":
        acc = ax.io.require(0x6064)
        return lambda: ax.prf_pos - ax.counts_to_pulses(acc.get())
    if what == "sw":
        return ax.io.require(0x6041).get
    if what == "cw":
        return ax.io.require(0x6040).get
    if what == "mode":
        return ax.io.require(0x6061).get
    # machine: the emulated drive's true mechanical position
    from ..master.backends.emulated import EmulatedBackend

    backend = ctl.backend
    slaves = backend.slaves if isinstance(backend, EmulatedBackend) else None
    if slaves is None:
        raise ParameterError(f"axis{n}.machine needs the emulated backend")
    channel = slaves[ax.io.slave].channel(ax.io.channel)
    return lambda: float(channel.machine_position)


def signal(ctl: Controller, spec: str) -> Getter:
    """A getter for one signal spec (see the module docstring)."""
    spec = spec.strip()
    m = _AXIS.match(spec)
    if m:
        return _axis_getter(ctl, int(m.group(1)), m.group(2))
    master = ctl.require_master()
    layout = master.layout
    m = _ENTRY.match(spec)
    if m:
        slave, index, sub = int(m.group(1)), parse_int(m.group(2)), parse_int(m.group(3))
        p = layout.entry(slave, index, sub)
        if p is None:
            raise ParameterError(f"slave {slave} maps no 0x{index:04X}:{sub:02X}")
        return master.image.access(p).get
    for var in layout.config.variables:
        if var.name == spec:
            from eni.layout import Placement

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
            return master.image.access(p).get
    raise ParameterError(
        f"unknown signal {spec!r}: use SLAVE:INDEX:SUB (e.g. 0:0x6041:0), an ENI variable "
        "name, or axisN.prf|enc|err|sw|cw|mode|machine"
    )


class Recorder:
    """Samples signals after every cycle while attached to a controller."""

    def __init__(self, ctl: Controller, specs: Sequence[str], capacity: int = 4096) -> None:
        self.ctl = ctl
        self.names = [s.strip() for s in specs]
        self._getters = [signal(ctl, s) for s in self.names]
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
        path = Path(path)
        with path.open("w", newline="", encoding="utf-8") as fh:
            w = csv.writer(fh)
            w.writerow(["time_ms", *self.names])
            for row in self.data:
                w.writerow([f"{row[0]:.3f}", *(f"{v:.6g}" for v in row[1:])])
        return path

    def plot(self, path: str | Path, title: str = "gtecat trace") -> Path:
        """One panel per signal against time, event marks as vertical lines."""
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        path = Path(path)
        n = max(1, len(self.names))
        fig, axes = plt.subplots(n, 1, figsize=(10, 1.8 * n + 1), sharex=True, squeeze=False)
        t = self.data[:, 0]
        for i, name in enumerate(self.names):
            ax = axes[i][0]
            ax.plot(t, self.data[:, 1 + i], lw=1)
            ax.set_ylabel(name, fontsize=8)
            ax.grid(alpha=0.3)
            for ms, _text in self.events:
                ax.axvline(ms, color="tab:red", lw=0.6, alpha=0.5)
        for ms, text in self.events:
            axes[0][0].annotate(
                text,
                (ms, 1.0),
                xycoords=("data", "axes fraction"),
                fontsize=7,
                rotation=30,
                ha="left",
                va="bottom",
            )
        axes[-1][0].set_xlabel("controller time (ms)")
        fig.suptitle(title)
        fig.tight_layout()
        fig.savefig(path, dpi=110)
        plt.close(fig)
        return path
