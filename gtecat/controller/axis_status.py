"""The axis status word of GT_GetSts (manual 6.3.1, table 6-2) and the in-position check (11.7).

Bits 1, 4, 5, 6, 7 and 8 latch: once set they stay until GT_ClrSts finds their
cause gone (6.3.1: "触发以后，不会自动清 0").  Bits 9, 10 and 11 are states:

* bit 9 servo enabled - the controller has the drive in *operation enabled*
  (GT_AxisOn succeeded and the drive has not dropped out since);
* bit 10 the profile is planning a motion (a stop ramp included); it is the
  planner's state, not the motor's (6.3.1: "只表示理论上的运动状态");
* bit 11 in position: off unless GT_SetAxisBand gave a band > 0.  Set once the
  profile stands (bit 10 = 0) and ``|planned - encoder|`` (axis values,
  GT_GetAxisError) has stayed within the band (``<= band``) for the hold time;
  cleared at once when the profile moves or the error leaves the band.  The
  hold time is counted in whole cycles: the flag rises at the first cycle whose
  time is at least ``time · 250 µs`` after the first in-band cycle (a hold
  time of 0 sets it at that first cycle).
"""

from __future__ import annotations

from enum import IntFlag


class AxisStatus(IntFlag):
    """Table 6-2."""

    ALARM = 1 << 1
    POS_ERROR = 1 << 4
    POSITIVE_LIMIT = 1 << 5
    NEGATIVE_LIMIT = 1 << 6
    SMOOTH_STOP = 1 << 7
    ABRUPT_STOP = 1 << 8
    SERVO_ON = 1 << 9
    MOVING = 1 << 10
    ARRIVED = 1 << 11


LATCHED = (
    AxisStatus.ALARM
    | AxisStatus.POS_ERROR
    | AxisStatus.POSITIVE_LIMIT
    | AxisStatus.NEGATIVE_LIMIT
    | AxisStatus.SMOOTH_STOP
    | AxisStatus.ABRUPT_STOP
)
#: latched flags that refuse every new motion until GT_ClrSts (limits refuse one direction)
BLOCKING = AxisStatus.ALARM | AxisStatus.POS_ERROR | AxisStatus.SMOOTH_STOP | AxisStatus.ABRUPT_STOP

#: GT_SetAxisBand time unit
BAND_TIME_UNIT_NS = 250_000


class InPosition:
    """GT_SetAxisBand / GT_GetAxisBand and the bit-11 timer."""

    __slots__ = ("_hold_ns", "_since", "arrived", "band", "time")

    def __init__(self) -> None:
        self.reset()

    def reset(self) -> None:
        """Off (11.7: "控制器复位后，默认该功能未开启")."""
        self.band = 0
        self.time = 0
        self._hold_ns = 0
        self._since: int | None = None
        self.arrived = False

    def set(self, band: int, time: int) -> None:
        self.band = band
        self.time = time
        self._hold_ns = time * BAND_TIME_UNIT_NS
        self._since = None
        self.arrived = False

    @property
    def enabled(self) -> bool:
        return self.band > 0

    def update(self, t_ns: int, standing: bool, error: float) -> None:
        """One cycle at time ``t_ns``: profile standing? axis error (pulse)."""
        if self.band <= 0:
            return
        if standing and -self.band <= error <= self.band:
            since = self._since
            if since is None:
                since = self._since = t_ns
            if not self.arrived and t_ns - since >= self._hold_ns:
                self.arrived = True
        else:
            self._since = None
            self.arrived = False
