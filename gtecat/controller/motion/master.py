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

from ...errors import CommandError, ParameterError
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


class SlavePlanner:
    """What Gear and Follow share: the follow direction and the master choice.

    Subclasses set :attr:`MODE` (``"Gear"`` / ``"Follow"``, for the GT names in
    messages) and keep ``_state`` with ``_IDLE == 0`` when standing.
    """

    __slots__ = ("_dir", "_master", "_source", "_state", "profile")
    MODE = ""

    def _init_master(self, profile: int | None, dir: object, source: MasterSource | None) -> None:
        self.profile = profile
        self._dir = direction(dir)
        self._master: MasterSpec | None = None
        self._source = source

    @property
    def direction(self) -> int:
        """GT_PrfGear / GT_PrfFollow ``dir``: 0 both ways, 1 positive, -1 negative master motion."""
        return self._dir

    def set_direction(self, dir: object) -> None:
        """GT_Prf<mode> on a profile already in this mode: only the same ``dir`` is accepted."""
        d = direction(dir)
        self._require_idle(f"GT_Prf{self.MODE}")
        if d != self._dir:
            raise CommandError(
                f"GT_Prf{self.MODE}: the profile is in {self.MODE} mode with dir {self._dir}, "
                f"not {d}; switch to another mode first"
            )

    @property
    def master(self) -> MasterSpec | None:
        """GT_Get<mode>Master (None until GT_Set<mode>Master)."""
        return self._master

    def set_master(
        self,
        index: object,
        type: object = MasterType.PROFILE,
        item: object = 0,
        source: MasterSource | None = None,
    ) -> None:
        """GT_Set<mode>Master; ``source`` is the position the controller resolved for it."""
        spec = MasterSpec.checked(self.profile, index, type, item)
        self._require_idle(f"GT_Set{self.MODE}Master")
        self._master = spec
        if source is not None:
            self._source = source

    def bind_master(self, source: MasterSource) -> None:
        """Attach the master position source (the controller's resolution of the master)."""
        self._source = source

    def _require_idle(self, what: str) -> None:
        if self._state != 0:
            raise CommandError(f"{what}: the profile is moving; call GT_Stop first")

    def run_steps(self, masters: list[float]) -> tuple[list[float], list[float], list[float], int]:
        """One ``step()`` per master position of ``masters`` (what the source reads in each
        of those cycles; the axis bank's tables): the samples up to the end and the end
        sample's index (-1: the motion goes on)."""
        ps: list[float] = []
        vs_: list[float] = []
        as_: list[float] = []
        src = self._source
        self._source = iter(masters).__next__
        try:
            for j in range(len(masters)):
                p, v, a = self.step()  # type: ignore[attr-defined]
                ps.append(p)
                vs_.append(v)
                as_.append(a)
                if self._state == 0:
                    return ps, vs_, as_, j
        finally:
            self._source = src
        return ps, vs_, as_, -1
