"""The GTS pulse card's own hardware: N step/dir axes, their drives, inputs and capture latches.

``GTECAT_CARD=gts:N`` (or ``GT_Open(card="gts:N")``) opens a controller that is a Googol
GTS motion card (GTS-400 = ``gts:4``, GTS-800 = ``gts:8``) instead of an EtherCAT master.
The controller core is the same; this module is what lies below it on a card.

**How the card is modelled.**  Each axis's step/direction output drives a servo (or
stepper) amplifier that follows the pulses with the same mechanics model as the
EtherCAT drives (``gtecat.drives.mechanics``: acceleration limit, following error), and the
axis's encoder counts the motor.  We build that as an internal bus of N single-axis
:class:`gtecat.drives.drive.Cia402Drive` in cyclic synchronous position mode (one slave per
axis, outputs 6040h/607Ah, inputs 6041h/6064h/60FDh/603Fh), exchanged in-process every
cycle: the pulse train of a cycle is the step of 607Ah, the enable output is 6040h, the
encoder is 6064h, the drive's alarm output is its fault bit (6041h bit 3).  The card's
limit, home and index inputs come from the machine description of each axis (60FDh bits
0/1/2 carry the limit and home levels; the index is ``index_offset`` + k·``counts_per_rev``),
as the field leaves them: a switch a fault forces (``switch_stuck``, ``switch_chatter``,
``probe_missing`` of :mod:`gtecat.faults`) reads in 60FDh and latches as it is forced.
Nobody sees this bus: it is never "initialised" by the application, no EtherCAT
function works on it (the controller refuses them, :mod:`gtecat.controller.card`).

The amplifiers do not see the card's limit switches (``limit_reaction = "none"``): on
a pulse card the *card* stops an axis at a limit, as the controller's limit check does.

**Capture latches.**  A GTS card latches the encoder counter in hardware at an edge of
the home input, the index (Z) pulse or the probe input.  :class:`CardBackend` models that:
every cycle it takes each axis's mechanics travel ``p0 -> p1`` and reports the exact edges
crossed (:class:`Edge`: which signal, rising or falling, and the fraction of the cycle at
which it happened).  The controller's capture (:mod:`gtecat.controller.capture`) turns a
fraction into the encoder value at that instant; that is exact to the count (the motor
moves linearly within a cycle in the mechanics model).  A home or probe input the field forces
has no position: while it is forced (at either sample) the card sees its level once per
cycle, and an edge of it latches at the cycle's sample (fraction 1), moving or not; a
switch stuck gives none.  Limits are not latched by the
card: they are sampled once per cycle (60FDh), as the card's firmware does.

The card's general-purpose terminals (``MC_GPI`` / ``MC_GPO``) are registers of the
controller (:mod:`gtecat.controller.digital_io`); nothing in the machine description
drives them.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from gtecat.drives.drive import Cia402Drive, DriveSettings
from gtecat.drives.faults import forced_level
from gtecat.drives.machine import AxisMachine, MachineDescription
from gtecat.drives.signal_edges import level, merge_windows, window_edges
from gtecat.eni.layout import Layout, build_layout
from gtecat.eni.topology import build_config

from ..errors import ParameterError
from .backends.emulated import EmulatedBackend

#: card kinds GTECAT_CARD names, and how many axes each may have: a GTS card, a GTN
#: card's core (up to 32 axes, the width of GT_Update's mask)
CARD_KINDS = {"gts": (1, 8), "gtn": (1, 32)}

_SPEC = re.compile(r"^\s*([a-zA-Z]+)\s*:\s*(\d+)\s*$")
_RX = ["0x6040:0:16", "0x607A:0:32"]
_TX = ["0x6041:0:16", "0x6064:0:32", "0x60FD:0:32", "0x603F:0:16"]
#: 60FDh bits of the inputs the card latches: home switch, probe input 1
_HOME, _PROBE = 1 << 2, 1 << 16
_SAMPLED = _HOME | _PROBE


@dataclass(frozen=True, slots=True)
class CardSpec:
    """A parsed ``GTECAT_CARD`` value: ``gts:4`` -> ``CardSpec("gts", 4)``."""

    kind: str
    axes: int

    @property
    def name(self) -> str:
        return f"{self.kind.upper()}-{self.axes}00"


def parse_card(spec: str) -> CardSpec:
    """``"gts:4"`` -> ``CardSpec``; ParameterError naming what is wrong otherwise."""
    m = _SPEC.match(str(spec))
    if not m:
        raise ParameterError(f"card={spec!r}: expected KIND:AXES, e.g. gts:4 (GTECAT_CARD)")
    kind, n = m[1].lower(), int(m[2])
    if kind not in CARD_KINDS:
        raise ParameterError(
            f"card={spec!r}: unknown card kind {kind!r}; known: {', '.join(CARD_KINDS)}"
        )
    lo, hi = CARD_KINDS[kind]
    if not lo <= n <= hi:
        raise ParameterError(f"card={spec!r}: a {kind} card has {lo}..{hi} axes, not {n}")
    return CardSpec(kind, n)


def card_layout(spec: CardSpec, cycle_us: float = 1000) -> Layout:
    """The internal bus of the card: one CSP drive per axis (module docstring)."""
    slaves = [
        {
            "kind": "servo",
            "name": f"{spec.name} axis {k + 1}",
            "mailbox": True,
            "init_cmds": False,
            "rx": _RX,
            "tx": _TX,
        }
        for k in range(spec.axes)
    ]
    cfg = build_config(
        {"cycle_time_us": cycle_us, "master": f"gtecat {spec.name}", "slave": slaves},
        f"<{spec.kind}:{spec.axes}>",
    )
    return build_layout(cfg)


@dataclass(frozen=True, slots=True)
class Edge:
    """One edge a card input made during the last cycle.

    ``signal``: ``"home"``, ``"index"`` or ``"probe"``; ``rising``: the input became
    active (the level the machine description gives: inside a home window, at an
    index pulse - which rises and falls at the same place); ``fraction``: when, as a
    fraction of the cycle (0 = the previous sample, 1 = this one).
    """

    signal: str
    rising: bool
    fraction: float


class CardBackend(EmulatedBackend):
    """The card's axes, exchanged in-process, with the capture edges of every cycle."""

    name = "gts-card"

    def __init__(self, spec: CardSpec, machine: MachineDescription, layout: Layout) -> None:
        self.spec = spec
        settings = DriveSettings(limit_reaction="none", device_name=f"{spec.name} amplifier")
        slaves = []
        for k, sl in enumerate(layout.config.slaves):
            drive = Cia402Drive(
                sl.position,
                sl.name,
                sl.identity,
                rx_pdos=sl.rx_pdos,
                tx_pdos=sl.tx_pdos,
                channels=1,
                machines=[machine.axis(k + 1)],
                settings=settings,
            )
            slaves.append(drive)
        super().__init__(machine, slaves=slaves)
        self._home = [merge_windows(d.channel(0).machine.home_switch) for d in slaves]
        self._probe = [merge_windows(d.channel(0).machine.probe1) for d in slaves]
        self._last = [d.channel(0).machine_position for d in slaves]
        #: the 60FDh bits the field forced at the last sample, per axis (see ``exchange``)
        self._forced: list[tuple[int, int]] = [(0, 0)] * len(slaves)
        #: edges of the last cycle, per axis (1-based)
        self.edges: dict[int, list[Edge]] = {k + 1: [] for k in range(len(slaves))}

    def drive(self, axis: int) -> Cia402Drive:
        """The amplifier of card axis ``axis`` (1-based)."""
        return self.slaves[axis - 1]  # type: ignore[return-value]

    def exchange(self, t_ns: int, dt_ns: int) -> int:
        wkc = super().exchange(t_ns, dt_ns)
        for k, slave in enumerate(self.slaves):
            ch = slave.channel(0)  # type: ignore[attr-defined]
            p0, p1 = self._last[k], ch.machine_position
            self._last[k] = p1
            out: list[Edge] = []
            forced = ch.forced_switches()
            was, self._forced[k] = self._forced[k], forced
            sampled = was[0] | was[1] | forced[0] | forced[1]
            if p1 != p0:
                span = p1 - p0
                if not sampled & _HOME:
                    for x, rising in window_edges(self._home[k], p0, p1):
                        out.append(Edge("home", rising, (x - p0) / span))
                for x in ch.machine.index_positions(p0, p1):
                    out.append(Edge("index", True, (x - p0) / span))
                if not sampled & _PROBE:
                    for x, rising in window_edges(self._probe[k], p0, p1):
                        out.append(Edge("probe", rising, (x - p0) / span))
            if sampled & _SAMPLED:  # (at the sample: after every edge within the travel)
                self._sampled_edges(k, ch.machine, p0, p1, was, forced, sampled, out)
            self.edges[k + 1] = out
        return wkc

    def _sampled_edges(
        self,
        k: int,
        m: AxisMachine,
        p0: float,
        p1: float,
        was: tuple[int, int],
        now: tuple[int, int],
        sampled: int,
        out: list[Edge],
    ) -> None:
        """Edges of the inputs the field forces, seen at this cycle's sample (fraction 1):
        the level at ``p0`` under the masks ``was`` against the level at ``p1`` under ``now``."""
        for bit, signal, windows in ((_HOME, "home", self._home[k]), (_PROBE, "probe", None)):
            if not sampled & bit:
                continue
            if windows is None:
                l0 = m.probe_active(1, p0)
                l1 = m.probe_active(1, p1)
            else:
                l0, l1 = level(windows, p0), level(windows, p1)
            a = bool(forced_level(bit if l0 else 0, *was) & bit)
            b = bool(forced_level(bit if l1 else 0, *now) & bit)
            if a != b:
                out.append(Edge(signal, b, 1.0))


__all__ = ["CARD_KINDS", "CardBackend", "CardSpec", "Edge", "card_layout", "parse_card"]
