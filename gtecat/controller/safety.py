"""Safety settings of one axis: alarm, hardware and soft limits, following error, stop inputs.

Manual chapter 9 and 4.3.1; the cycle that applies them is in
:mod:`gtecat.controller.resources`.  What each setting means on an EtherCAT axis:

* **Alarm** (驱动报警, 9.3): the drive's fault - statusword 6041h bit 3 (*fault*,
  also set in *fault reaction active*) of the axis whose alarm input this is
  (its own by default).  GT_AlarmOn/Off enable or ignore it (default on).
* **Hardware limits** (限位开关, 9.2): 60FDh bit 1 (positive) and bit 0
  (negative) of the input axis (its own by default); GT_LmtsOn/Off per switch
  (default on).  A configuration file may set an input to ``none``: then it
  cannot be switched on or off (GT_AlarmOn/Off, GT_LmtsOn/Off return 1 - the
  "已经配置了...无效" of chapter 13).  4.3.1 allows taking another axis's
  input ("将轴 2 的限位信号配给轴 1"): an input number is an axis number.
* **Soft limits** (软限位, 9.2, entry 121): positive 0x7FFFFFFF and negative
  0x80000000 by default, which no planned position passes (disabled, "没有触发的").
  The emergency stop starts where the plan crosses the limit, inside the cycle
  (:func:`limit_crossing`; the rule is in :mod:`gtecat.controller.resources`).
* **Following-error limit** (GT_SetPosErr, entry 116): in pulses, range
  (0, 2147483648]; default 32767 pulses, which the manual leaves open (the
  drive's own following-error window 6065h still guards the motor).
* **Smooth/abrupt stop inputs** (4.3.1 items 7-8, 9.4): the manual's
  configuration tool marks them "配置无效" (not available); as an extension a
  configuration file may name a bit of an axis's 60FDh (``axis:bit``) as the
  smooth-stop or abrupt-stop input.  None by default.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..errors import ParameterError

SOFT_POSITIVE_OFF = 0x7FFFFFFF
SOFT_NEGATIVE_OFF = -0x80000000
POS_ERR_MAX = 2147483648
POS_ERR_DEFAULT = 32767

LIMIT_POSITIVE_BIT = 1 << 1  # 60FDh bit 1 (CiA 402: positive limit switch)
LIMIT_NEGATIVE_BIT = 1 << 0  # 60FDh bit 0 (negative limit switch)


def limit_crossing(
    p0: float, v0: float, p1: float, v1: float, level: float, cycle_ms: float
) -> tuple[float, float, float]:
    """When, where and how fast the plan passes ``level`` between two samples.

    ``(p0, v0)`` is the previous sample, ``(p1, v1)`` the one a cycle later, which is
    past ``level``.  Between them the plan is taken as the cubic Hermite curve through
    both positions with both velocities: exact wherever the planner's piece is a
    polynomial of degree 3 at most across the cycle (constant acceleration: Trap, Jog at
    its limits, PT; smoothTime's linear acceleration), within ``|Δacc|·cycle`` of the
    speed where a piece boundary falls inside the cycle (the speed is then held to the
    faster of the two samples, which the curve overshoots at an acceleration jump, e.g.
    where a Trap reaches its speed).  Returns ``(f, p, v)``: the
    crossing ``f·cycle_ms`` after the previous sample at ``p = level``, and the speed
    there (0 if the curve reaches ``level`` without moving on past it); when ``p0`` is
    already at or past ``level`` (a limit lying exactly on a sample, a limit set
    behind the axis) ``(0, p0, v0)``.
    """
    side = 1.0 if p1 > level else -1.0
    if (p0 - level) * side >= 0.0:
        return 0.0, p0, v0 if v0 * side > 0.0 else 0.0
    d0, d1, m0, m1 = p0 - level, p1 - level, v0 * cycle_ms, v1 * cycle_ms

    def h(f: float) -> float:  # Hermite curve - level
        g = 1.0 - f
        return g * g * ((1.0 + 2.0 * f) * d0 + f * m0) + f * f * ((3.0 - 2.0 * f) * d1 - g * m1)

    lo, hi = 0.0, 1.0  # h(lo) on p0's side, h(hi) past level
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if h(mid) * side > 0.0:
            hi = mid
        else:
            lo = mid
    f = hi
    v = (
        6.0 * f * (1.0 - f) * (p1 - p0)
        + (1.0 - f) * (1.0 - 3.0 * f) * m0
        + f * (3.0 * f - 2.0) * m1
    ) / cycle_ms
    if v * side <= 0.0:
        return f, level, 0.0
    top = max(abs(v0), abs(v1))  # the curve overshoots where the acceleration jumps
    return f, level, v if abs(v) <= top else math.copysign(top, v)


@dataclass(slots=True)
class StopInput:
    """A 60FDh bit of some axis used as a stop input (configuration file extension)."""

    axis: int
    bit: int


@dataclass(slots=True)
class Safety:
    """The safety settings of one axis (table 4-4 defaults)."""

    #: axis whose drive fault is this axis's alarm input (None: configured "none")
    alarm_input: int | None
    alarm_on: bool = True
    positive_input: int | None = None
    negative_input: int | None = None
    positive_on: bool = True
    negative_on: bool = True
    soft_positive: int = SOFT_POSITIVE_OFF
    soft_negative: int = SOFT_NEGATIVE_OFF
    pos_err: int = POS_ERR_DEFAULT
    smooth_stop_input: StopInput | None = None
    abrupt_stop_input: StopInput | None = None
    active: bool = True

    @classmethod
    def defaults(cls, axis: int) -> Safety:
        return cls(alarm_input=axis, positive_input=axis, negative_input=axis)

    def set_soft_limits(self, positive: int, negative: int) -> None:
        """GT_SetSoftLimit: "正向软限位必须大于负向软限位" (9.2.2)."""
        if positive <= negative:
            raise ParameterError(
                f"positive soft limit {positive} must be greater than the negative one {negative}"
            )
        self.soft_positive = positive
        self.soft_negative = negative

    def set_pos_err(self, error: int) -> None:
        if not 0 < error <= POS_ERR_MAX:
            raise ParameterError(f"error={error} out of range (0, 2147483648] pulse (entry 116)")
        self.pos_err = error
