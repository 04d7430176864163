"""The epoch of what the GT readers read: a number that grows wherever it may change.

A reader (GT_GetSts, GT_GetPrfPos, GT_GetDi, ...) reads the controller's state as its last
cycle left it and as the GT calls made since then changed it: the manual's controller
updates its status in its servo cycle.  So what a reader answers stays the same while no
cycle runs, no other call is made, no fault is injected and the session stays; the C
entries of the readers (:mod:`gtecat.gt.centry`) keep each value they write for the epoch
it was asked in and write it again while :data:`EPOCH` stays.  :data:`EPOCH` grows after
every cycle and every run of cycles, once its time is counted (the controller's clock calls
:func:`changed`: ``Clock.counted``), and at the end of every call of the table path and
every error recorded (:mod:`gtecat.gt._core`), every raw write into the process image,
every change of the session's gates, every fault injected or cleared, every call of a
compat layer (:mod:`gtecat.compat`) and every request of an inspection endpoint (a panel's
control operations).  Code that changes a controller's objects another way (a test's own
hand on them) calls :func:`changed`.
"""

from __future__ import annotations


class Epoch:
    """``n`` only grows (the C entries read it where :func:`gtecat.gt.centry` probed it)."""

    __slots__ = ("n",)

    def __init__(self) -> None:
        self.n = 1


#: the one epoch of the process
EPOCH = Epoch()


def changed() -> None:
    """What a reader's C entry kept may no longer be the value: it asks again."""
    EPOCH.n += 1
