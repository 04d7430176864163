"""Touch probe (ETG.6010 / CiA 402): both probes of one drive channel.

Objects (cia402-facts §4): 0x60B8 function, 0x60B9 status, 0x60BA–0x60BD latched
positions (TP1 rising, TP1 falling, TP2 rising, TP2 falling), 0x60D5–0x60D8 edge
counters in the same order, 0x60D1–0x60D4 timestamps (same order; 60D2/60D3 are
confirmed, 60D1/60D4 inferred), 0x60D0:01/02 source selection for source code 10b.

0x60B8 per probe (TP2 = bits + 8): bit 0 enable, bit 1 continuous (0 = first event),
bits 3:2 source (00 probe input, 01 encoder zero impulse, 10 per 0x60D0, 11 reserved =
no trigger), bit 4 latch on the rising edge, bit 5 on the falling edge.

0x60B9: bit 0 TP1 enabled, bit 1 rising value stored, bit 2 falling value stored,
bits 8/9/10 the same for TP2, and the user-defined toggle bits (manual 5.2.2.3: a
stored bit stays set, so continuous mode needs a "new value" flag; GTHD uses bit 6
for TP1 rising, example 5-3).  This drive toggles, in continuous mode, on every new
stored value: **bit 6 TP1 rising, bit 7 TP1 falling, bit 14 TP2 rising, bit 15 TP2
falling**.  The toggle bits keep their state across disable/enable, so a master that
remembers the last seen state (example 5-3's ``xPreSts``) never misses a capture.

Rules (cia402-facts §4, S1 timing diagram, Beckhoff EP7211):

* enabling a probe (bit 0 rising) sets status bit 0 and arms both edges;
* disabling clears status bits enable/rising/falling; the values stay;
* clearing an edge-enable bit clears that edge's stored bit (value stays); setting it
  again re-arms that edge;
* first-event mode stores only the first edge of each kind until re-armed (edge
  enable or probe enable cleared and set again); continuous mode overwrites;
* writing the same function value again changes nothing (PDOs repeat it every cycle).

Captured value = the encoder position at the exact crossing, interpolated inside the
cycle: ``round(p0_enc + f * (p1_enc - p0_enc))`` with ``f`` the fraction of the
cycle's machine travel where the edge lies.  Timestamps likewise:
``t_ns - dt_ns + round(f * dt_ns)``, where ``t_ns`` is the time of the ``p1`` sample.
Edge counters count every edge of the selected source while the probe and that
edge's enable bit are on (also edges a first-event latch ignores), wrapping at 16 bits.
The encoder zero impulse is a pulse of no width: each index position gives a rising
and a falling edge at the same place.
"""

from __future__ import annotations

import math

from gtecat.eni.errors import GtecatError

from .machine import AxisMachine
from .signal_edges import Window, merge_windows, window_edges

__all__ = ["TOGGLE_BITS", "TouchProbe", "TouchProbeError"]

# 60B9 toggle bit per slot (TP1 rising, TP1 falling, TP2 rising, TP2 falling)
TOGGLE_BITS = (6, 7, 14, 15)

SOURCE_INPUT, SOURCE_INDEX, SOURCE_60D0, SOURCE_RESERVED = 0, 1, 2, 3


class TouchProbeError(GtecatError):
    """A touch probe function or source value out of range."""


class TouchProbe:
    """Both touch probes of one CiA-402 channel (see the module docstring)."""

    def __init__(self, machine: AxisMachine) -> None:
        self._m = machine
        self._inputs = (merge_windows(machine.probe1), merge_windows(machine.probe2))
        self._function = 0
        self.status = 0  # 0x60B9
        self.values = [0, 0, 0, 0]  # 0x60BA..0x60BD
        self.counters = [0, 0, 0, 0]  # 0x60D5..0x60D8
        self.timestamps = [0, 0, 0, 0]  # 0x60D1..0x60D4, ns (the OD masks to its width)
        self.source_select = [1, 2]  # 0x60D0:01/02 (1-4 TPn input, 5/6 zero impulse)
        self._armed = [False, False, False, False]

    @property
    def function(self) -> int:
        """0x60B8 as last written."""
        return self._function

    @function.setter
    def function(self, value: int) -> None:
        self.write_function(value)

    def write_function(self, value: int) -> None:
        """Write 0x60B8 (UINT16; a negative 16-bit ``short`` is taken as its bit pattern)."""
        if isinstance(value, bool) or not isinstance(value, int) or not -0x8000 <= value <= 0xFFFF:
            raise TouchProbeError(f"touch probe function 0x60B8 must be 16 bits, got {value!r}")
        new = value & 0xFFFF
        old = self._function
        status = self.status
        if new == old:  # (no enable or edge bit changes: nothing is armed or cleared)
            self.status = status & 0xFFFF
            return
        for probe in (0, 1):
            sh = 8 * probe
            en_old, en_new = (old >> sh) & 1, (new >> sh) & 1
            if en_new and not en_old:
                self._armed[2 * probe] = self._armed[2 * probe + 1] = True
                status = (status & ~(0b110 << sh)) | (1 << sh)
            elif en_old and not en_new:
                self._armed[2 * probe] = self._armed[2 * probe + 1] = False
                status &= ~(0b111 << sh)
            for edge in (0, 1):
                bit = 4 + edge + sh
                e_old, e_new = (old >> bit) & 1, (new >> bit) & 1
                if e_old and not e_new:
                    status &= ~(1 << (1 + edge + sh))
                elif e_new and not e_old:
                    self._armed[2 * probe + edge] = True
        self.status = status & 0xFFFF
        self._function = new

    def set_source(self, probe: int, value: int) -> None:
        """Write 0x60D0:probe (used when 60B8's source bits are 10b)."""
        if probe not in (1, 2) or not 1 <= value <= 6:
            raise TouchProbeError(f"0x60D0:{probe:02X} = {value!r} is not a supported source")
        self.source_select[probe - 1] = value

    def step(
        self,
        p0_machine: float,
        p1_machine: float,
        p0_enc: float,
        p1_enc: float,
        t_ns: int,
        dt_ns: int,
    ) -> None:
        """Latch the edges crossed while the mechanics moved from p0 to p1 during this cycle."""
        fn = self._function
        if not fn & 0x0101 or p0_machine == p1_machine:
            return
        span = p1_machine - p0_machine
        for probe in (0, 1):
            sh = 8 * probe
            if not (fn >> sh) & 1 or not (fn >> (4 + sh)) & 0b11:
                continue
            for x, rising in self._edges(probe, (fn >> (2 + sh)) & 0b11, p0_machine, p1_machine):
                edge = 0 if rising else 1
                if not (fn >> (4 + edge + sh)) & 1:
                    continue
                slot = 2 * probe + edge
                self.counters[slot] = (self.counters[slot] + 1) & 0xFFFF
                continuous = (fn >> (1 + sh)) & 1
                if not continuous and not self._armed[slot]:
                    continue
                f = (x - p0_machine) / span
                self.values[slot] = _int32(math.floor(p0_enc + f * (p1_enc - p0_enc) + 0.5))
                self.timestamps[slot] = int(t_ns) - int(dt_ns) + math.floor(f * dt_ns + 0.5)
                self.status |= 1 << (1 + edge + sh)
                if continuous:
                    self.status ^= 1 << TOGGLE_BITS[slot]
                else:
                    self._armed[slot] = False

    def _signal(self, probe: int, source: int) -> tuple[Window, ...] | None:
        """What ``probe`` with ``source`` (60B8h bits 3:2) latches: the windows of a probe
        input, None for the encoder's index pulses, () for nothing (reserved, TP3/TP4)."""
        if source == SOURCE_60D0:
            sel = self.source_select[probe]
            if sel in (1, 2):
                return self._inputs[sel - 1]
            if sel in (5, 6):
                return None
            return ()  # TP3/TP4 inputs do not exist on this machine
        if source == SOURCE_INPUT:
            return self._inputs[probe]
        if source == SOURCE_INDEX:
            return None
        return ()  # reserved source: never triggers

    def _edges(self, probe: int, source: int, p0: float, p1: float) -> list[tuple[float, bool]]:
        windows = self._signal(probe, source)
        if windows is not None:
            return window_edges(windows, p0, p1) if windows else []
        out: list[tuple[float, bool]] = []
        for x in self._m.index_positions(p0, p1):
            out.append((x, True))
            out.append((x, False))
        return out

    def quiet_bounds(self, pos: float) -> tuple[float, float]:
        """``(lo, hi)``: the nearest machine positions at or below and at or above ``pos``
        where an edge of what the function latches lies (a probe input's window boundary,
        an index pulse; -inf / inf: none).  A cycle whose travel stays strictly between the
        two finds no edge in :meth:`step`, so it latches, counts and toggles nothing: the
        axis bank runs a channel with an armed probe only while its travel does (and gives
        it back before a cycle that would reach either bound)."""
        fn = self._function
        lo, hi = -math.inf, math.inf
        for probe in (0, 1):
            sh = 8 * probe
            if not (fn >> sh) & 1 or not (fn >> (4 + sh)) & 0b11:
                continue  # (step skips such a probe)
            windows = self._signal(probe, (fn >> (2 + sh)) & 0b11)
            if windows is None:
                xs = self._index_near(pos)
            else:
                xs = [x for w in windows for x in w]
            for x in xs:
                if lo < x <= pos:
                    lo = x
                if pos <= x < hi:
                    hi = x
        return lo, hi

    def _index_near(self, pos: float) -> list[float]:
        """The index pulses around ``pos`` (at least the nearest one on either side), each
        position computed as :meth:`AxisMachine.index_positions` computes it."""
        m = self._m
        if m.index_offset is None or m.counts_per_rev <= 0:
            return []
        cpr = m.counts_per_rev
        k0 = math.floor((pos - m.index_offset) / cpr)
        return [float(m.index_offset + k * cpr) for k in range(k0 - 1, k0 + 3)]


def _int32(v: int) -> int:
    return (v + 0x8000_0000) % 0x1_0000_0000 - 0x8000_0000
