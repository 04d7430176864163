"""The encoder resource (编码器, manual 4.2.1, 4.3.2, 8.2) of an EtherCAT axis.

On a bus axis the "encoder" counts what the drive reports in 6064h (position
actual value) - "总线上反馈的实际编码器增量值" (8.2) - in the controller's pulses
(drive counts / 2**GT_SetPosScale).  What the 4.3.2 options mean here:

* **GT_EncOn** ("外部编码器", the default): count 6064h.
  **GT_EncOff** ("脉冲计数器"): count what the controller sends, 607Ah (the
  pulse counter of a pulse axis counts the pulses it emits); the reading then
  follows the planned position whatever the drive does.
* **GT_EncSns** bit ``n-1`` = 1: encoder ``n`` counts the other way.  The
  manual's table 4-4 and entry 18 call the reset state "取反" (reversed), but
  example 4-1 sets a bit to reverse one encoder "and not the others"; on a bus
  axis a reversed default would make every encoder disagree with its drive,
  so here the reset state is 0 (not reversed) for every encoder.
* Switching source or direction, or GT_SetPosScale, never makes the reading
  jump: the count goes on from its value.  GT_SetEncPos sets the value.
* **Not active** (configuration file ``active = 0``, 4.3.2 item 6): the
  reading is frozen and its speed 0.

The count is incremental (each cycle adds the change of the source, wrapped as
a 32-bit difference, so 6064h overflowing never jumps) and exact: counts
divided by a power of two are exact doubles.  A homing run redefines 6064h;
:meth:`Encoder.rebase` then takes the drive's value as the reading.  Speed
(pulse/ms) and acceleration (pulse/ms²) are the first and second differences per
cycle.
"""

from __future__ import annotations

_WRAP = 1 << 32
_HALF = 1 << 31


class Encoder:
    """One encoder channel: source selection, direction, position, speed, acceleration."""

    __slots__ = ("_T", "_prev", "_primed", "acc", "active", "external", "pos", "sense", "vel")

    def __init__(self, cycle_ms: float) -> None:
        self._T = cycle_ms
        self._prev = 0
        self._primed = False
        self.reset()

    def reset(self) -> None:
        """Table 4-4: active, external encoder, not reversed; the reading keeps its value."""
        self.active = True
        self.external = True
        self.sense = 1
        self.vel = self.acc = 0.0
        if not self._primed:
            self.pos = 0.0

    def sample(self, raw: int, unit: float) -> None:
        """One cycle: ``raw`` is the source in drive counts, ``unit`` pulses per count."""
        if not self._primed:
            self._prev = raw
            self._primed = True
            self.pos = self.sense * raw * unit
            return
        d = raw - self._prev
        self._prev = raw
        if not self.active:
            return
        if d >= _HALF or d < -_HALF:
            d = (d + _HALF) % _WRAP - _HALF
        if d:
            step = self.sense * d * unit
            self.pos += step
            v = step / self._T
        else:
            v = 0.0
        self.acc = (v - self.vel) / self._T
        self.vel = v

    def freeze_speed(self) -> None:
        self.vel = self.acc = 0.0

    def set_pos(self, pos: float) -> None:
        """GT_SetEncPos / GT_ZeroPos: the reading becomes ``pos``; counting goes on from there."""
        self.pos = float(pos)

    def resync(self, raw: int) -> None:
        """The source changed (GT_EncOn/Off): keep the reading, count from ``raw`` on."""
        self._prev = raw

    def rebase(self, raw: int, unit: float) -> None:
        """Take the drive's own value as the reading (after the drive redefined it: homing)."""
        self._prev = raw
        self._primed = True
        self.pos = self.sense * raw * unit
