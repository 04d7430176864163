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
* **Following-error limit** (GT_SetPosErr, entry 116): in pulses, range
  (0, 2147483648]; default 32767 pulses, which the manual leaves open (the
  drive's own following-error window 6065h still guards the motor).
* **Smooth/abrupt stop inputs** (4.3.1 items 7-8, 9.4): the manual's
  configuration tool marks them "配置无效" (not available); as an extension a
  configuration file may name a bit of an axis's 60FDh (``axis:bit``) as the
  smooth-stop or abrupt-stop input.  None by default.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..errors import ParameterError

SOFT_POSITIVE_OFF = 0x7FFFFFFF
SOFT_NEGATIVE_OFF = -0x80000000
POS_ERR_MAX = 2147483648
POS_ERR_DEFAULT = 32767

LIMIT_POSITIVE_BIT = 1 << 1  # 60FDh bit 1 (CiA 402: positive limit switch)
LIMIT_NEGATIVE_BIT = 1 << 0  # 60FDh bit 0 (negative limit switch)


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
