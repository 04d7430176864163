"""Axis equivalent scaling (当量变换): GT_ProfileScale and GT_EncScale, manual 4.3.1 items 2-3.

``ΔP_profile / ΔP_axis = alpha / beta`` and ``ΔE_enc / ΔE_axis = alpha / beta``:
the axis's value moves ``beta/alpha`` times what the profile (or encoder) moves.
Alpha and beta lie in (-32767, 0) ∪ (0, 32767) and ``|alpha| >= |beta|``
(4.3.1 "注意" and chapter 13 entry 91); the default is 1:1 (table 4-4).

The relation is incremental, as 11.6 says: after GT_SetPrfPos / GT_SetEncPos the
axis value keeps its place until GT_SynchAxisPos.  So an axis value is kept as
``axis = ratio · source + offset`` (:class:`AffineLink`), where only a
redefinition or GT_SynchAxisPos changes ``offset``.  With 1:1 and offset 0 the
axis value *is* the source value, bit for bit (a Trap move ends exactly on its
target in both).
"""

from __future__ import annotations

from dataclasses import dataclass

from ..errors import ParameterError

SCALE_LIMIT = 32767


@dataclass(frozen=True, slots=True)
class Scale:
    """One alpha/beta pair (validated)."""

    alpha: int = 1
    beta: int = 1

    def __post_init__(self) -> None:
        for name, v in (("alpha", self.alpha), ("beta", self.beta)):
            if isinstance(v, bool) or not isinstance(v, int):
                raise ParameterError(f"{name}={v!r} must be an integer")
            if v == 0 or not -SCALE_LIMIT < v < SCALE_LIMIT:
                raise ParameterError(f"{name}={v} out of range (-32767, 0) and (0, 32767)")
        if abs(self.alpha) < abs(self.beta):
            raise ParameterError(
                f"|alpha| ({abs(self.alpha)}) must be >= |beta| ({abs(self.beta)}) "
                "(manual 4.3.1: Alpha >= Beta)"
            )

    @classmethod
    def checked(cls, alpha: object, beta: object) -> Scale:
        try:
            a, b = int(alpha), int(beta)  # type: ignore[call-overload]
        except (TypeError, ValueError):
            raise ParameterError(f"alpha={alpha!r}, beta={beta!r} must be integers") from None
        if a != alpha or b != beta:
            raise ParameterError(f"alpha={alpha!r}, beta={beta!r} must be integers")
        return cls(a, b)

    @property
    def ratio(self) -> float:
        """Axis units per source unit, ``beta / alpha``."""
        return self.beta / self.alpha


class AffineLink:
    """``axis = ratio · source + offset``, kept so that a scale change never moves the axis."""

    __slots__ = ("offset", "ratio", "scale")

    def __init__(self) -> None:
        self.scale = Scale()
        self.ratio = 1.0
        self.offset = 0.0

    def axis(self, source: float) -> float:
        if self.ratio == 1.0:
            return source + self.offset if self.offset else source
        return self.ratio * source + self.offset

    def source(self, axis: float) -> float:
        """The source value that maps onto ``axis``."""
        if self.ratio == 1.0:
            return axis - self.offset if self.offset else axis
        return (axis - self.offset) / self.ratio

    def set_scale(self, scale: Scale, source: float) -> None:
        """New alpha/beta; the axis value at ``source`` stays where it is."""
        here = self.axis(source)
        self.scale = scale
        self.ratio = scale.ratio
        self.anchor(source, here)

    def anchor(self, source: float, axis: float) -> None:
        """From now on ``source`` maps onto ``axis`` (a redefinition of either side)."""
        self.offset = axis - self.ratio * source
        if self.offset == 0.0:
            self.offset = 0.0  # no -0.0

    def synch(self) -> None:
        """GT_SynchAxisPos: the axis value becomes ``ratio · source`` again."""
        self.offset = 0.0

    def reset(self) -> None:
        self.scale = Scale()
        self.ratio = 1.0
        self.offset = 0.0
