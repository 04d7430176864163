"""The CiA-402 homing methods (object 0x6098) as data.

Sources: CiA 402-2 / IEC 61800-7-201 "Homing mode"; digest with citations in
``cia402-facts.md`` §3.2 (methods 1–14), §3.3 (17–37).

Every search method 1–14 reduces to a handful of facts, and method n+16 (17–30) is
method n without the index pulse (its home point is the switch edge itself):

* the reference signal: negative limit (1), positive limit (2) or home switch (3–14);
* the *reference crossing*: the direction in which the reference edge is finally
  crossed (the final approach, ``final_dir``) and the signal level after it
  (``active_after``).  For a home-switch window ``[low, high)`` the low edge is
  crossed ``+`` into / ``-`` out of the window, the high edge ``+`` out / ``-`` into
  it, so (final direction, level after) names the edge;
* the initial direction when the signal is inactive at start (``dir_if_inactive``).
  When it is active, the search heads for the sought edge: ``final_dir`` when the
  level after the crossing is *inactive* (the edge is ahead), ``-final_dir`` when it
  is *active* (leave the signal first, then cross back);
* the limit switch on which the search may reverse once (7–10: PL, 11–14: NL;
  none for 1–6: any other limit hit is a homing error).

Methods 3/4 assume a "positive" home switch (active from its edge up to the positive
end), 5/6 a "negative" one; a finite window works as long as the start lies on the
side the method assumes, otherwise the search runs into a limit and fails, as on a
real drive.  Methods 7–14 treat each home-switch window as a cam with two edges.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import IntEnum


class Signal(IntEnum):
    """Switch inputs a homing search looks at (logical levels, as in 0x60FD bits 0–2)."""

    NEGATIVE_LIMIT = 0
    POSITIVE_LIMIT = 1
    HOME_SWITCH = 2


class MethodKind(IntEnum):
    SEARCH = 1  # 1–14, 17–30: find a switch edge (then maybe an index pulse)
    INDEX_ONLY = 2  # 33, 34: first index pulse in a fixed direction
    CURRENT_POSITION = 3  # 35, 37: the current position is the home point


@dataclass(frozen=True, slots=True)
class MethodSpec:
    """What one homing method looks for (see the module docstring)."""

    number: int
    kind: MethodKind
    final_dir: int  # +1 / -1: direction of the final approach (and of the index search)
    uses_index: bool
    signal: Signal | None = None
    active_after: bool = False  # signal level after the reference crossing
    dir_if_inactive: int = 0  # initial direction when the signal is inactive at start
    reversal_limit: Signal | None = None
    text: str = ""

    def initial_direction(self, signal_active: bool) -> int:
        if self.kind is not MethodKind.SEARCH:
            return self.final_dir
        if signal_active:
            return -self.final_dir if self.active_after else self.final_dir
        return self.dir_if_inactive


_NL, _PL, _HS = Signal.NEGATIVE_LIMIT, Signal.POSITIVE_LIMIT, Signal.HOME_SWITCH

# number: (signal, final_dir, active_after, dir_if_inactive, reversal limit, text)
_BASE: dict[int, tuple[Signal, int, bool, int, Signal | None, str]] = {
    1: (_NL, +1, False, -1, None, "negative limit switch, first index right of its edge"),
    2: (_PL, -1, False, +1, None, "positive limit switch, first index left of its edge"),
    3: (_HS, -1, False, +1, None, "positive home switch, first index left of its edge"),
    4: (_HS, +1, True, +1, None, "positive home switch, first index right of its edge"),
    5: (_HS, +1, False, -1, None, "negative home switch, first index right of its edge"),
    6: (_HS, -1, True, -1, None, "negative home switch, first index left of its edge"),
    7: (_HS, -1, False, +1, _PL, "home cam low edge, index left of it; start +, reverse on PL"),
    8: (_HS, +1, True, +1, _PL, "home cam low edge, index right of it; start +, reverse on PL"),
    9: (_HS, -1, True, +1, _PL, "home cam high edge, index left of it; start +, reverse on PL"),
    10: (_HS, +1, False, +1, _PL, "home cam high edge, index right of it; start +, reverse on PL"),
    11: (_HS, +1, False, -1, _NL, "home cam high edge, index right of it; start -, reverse on NL"),
    12: (_HS, -1, True, -1, _NL, "home cam high edge, index left of it; start -, reverse on NL"),
    13: (_HS, +1, True, -1, _NL, "home cam low edge, index right of it; start -, reverse on NL"),
    14: (_HS, -1, False, -1, _NL, "home cam low edge, index left of it; start -, reverse on NL"),
}


def _build() -> dict[int, MethodSpec]:
    table: dict[int, MethodSpec] = {}
    for n, (sig, fd, after, d0, rev, text) in _BASE.items():
        table[n] = MethodSpec(n, MethodKind.SEARCH, fd, True, sig, after, d0, rev, text)
        table[n + 16] = MethodSpec(
            n + 16,
            MethodKind.SEARCH,
            fd,
            False,
            sig,
            after,
            d0,
            rev,
            f"as method {n} without the index pulse: home is the switch edge itself",
        )
    table[33] = MethodSpec(33, MethodKind.INDEX_ONLY, -1, True, text="first index pulse moving -")
    table[34] = MethodSpec(34, MethodKind.INDEX_ONLY, +1, True, text="first index pulse moving +")
    for n in (35, 37):
        table[n] = MethodSpec(
            n, MethodKind.CURRENT_POSITION, +1, False, text="current position is home"
        )
    return table


METHODS: dict[int, MethodSpec] = _build()
SUPPORTED_METHODS: frozenset[int] = frozenset(METHODS)


def method_spec(number: int) -> MethodSpec | None:
    """The description of method ``number``, or None when this drive does not support it."""
    return METHODS.get(number)
