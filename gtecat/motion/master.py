"""What a Gear or Follow slave follows: master selection and follow direction (manual 7.5.2, 7.6.2).

``GT_SetGearMaster`` / ``GT_SetFollowMaster(profile, masterIndex, masterType,
masterItem)`` pick the master: the planned output of profile ``masterIndex``
(``*_MASTER_PROFILE`` = 2, the default), encoder ``masterIndex``
(``*_MASTER_ENCODER`` = 1) or axis ``masterIndex`` (``*_MASTER_AXIS`` = 3,
where ``masterItem`` 0 takes its planned and 1 its encoder position).  The
planners do not look these up: the controller resolves the choice into a
``source`` callable returning the master position (pulse) of the current
cycle, so the planners are testable with a fake master.

``GT_PrfGear`` / ``GT_PrfFollow(profile, dir)``: 0 follows the master both
ways, 1 only its positive motion, -1 only its negative motion.  Model: each
cycle's master increment passes the filter (a one-way clutch): a blocked
increment moves the slave by nothing, so after a reversal the slave resumes
as soon as the master moves its way again.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from enum import IntEnum

from ..errors import ParameterError
from . import checks

MasterSource = Callable[[], float]
"""The master position (pulse) this cycle."""


class MasterType(IntEnum):
    """GEAR_MASTER_* / FOLLOW_MASTER_* (same values in both, chapter 13 entries 108, 110)."""

    ENCODER = 1
    PROFILE = 2
    AXIS = 3


class MasterItem(IntEnum):
    """``masterItem`` for an AXIS master: its planned (0) or encoder (1) position."""

    PROFILE = 0
    ENCODER = 1


@dataclass(frozen=True, slots=True)
class MasterSpec:
    """One master choice as GT_Get*Master reports it."""

    index: int
    type: MasterType = MasterType.PROFILE
    item: MasterItem = MasterItem.PROFILE

    @classmethod
    def checked(cls, slave: int | None, index: object, type: object, item: object) -> MasterSpec:
        """Validate a GT_Set*Master call: a bad value is a ParameterError (return 7)."""
        i = checks.integer("masterIndex", index)
        if i < 1:
            raise ParameterError(f"masterIndex must be >= 1, got {index!r}")
        if slave is not None and i == slave:
            raise ParameterError(f"masterIndex must differ from the slave profile {slave}")
        t = checks.integer("masterType", type)
        if t not in tuple(MasterType):
            raise ParameterError(
                f"masterType must be 1 (encoder), 2 (profile) or 3 (axis), got {type!r}"
            )
        m = checks.integer("masterItem", item)
        if m not in (0, 1):
            raise ParameterError(f"masterItem must be 0 (planned) or 1 (encoder), got {item!r}")
        return cls(i, MasterType(t), MasterItem(m))


def direction(value: object) -> int:
    """A ``dir`` argument of GT_PrfGear / GT_PrfFollow: 0, 1 or -1."""
    d = checks.integer("dir", value)
    if d not in (-1, 0, 1):
        raise ParameterError(
            f"dir must be 0 (both ways), 1 (positive) or -1 (negative), got {value!r}"
        )
    return d


def passed(delta: float, dir: int) -> float:
    """The part of a master increment a slave with follow direction ``dir`` follows."""
    if dir > 0:
        return delta if delta > 0.0 else 0.0
    if dir < 0:
        return delta if delta < 0.0 else 0.0
    return delta
