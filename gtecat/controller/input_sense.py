"""One counter of the changes to how the controller senses its inputs.

``GT_GetDi`` / ``GT_GetDiRaw`` (:mod:`gtecat.gt.io_calls`) combine each axis's input bit
(60FDh, 6041h), read live at every call, with its sense: the loaded configuration's
``reverse`` (a vendor file, ``GT_SetSense``, ``GT_LmtSns``; forgotten at ``GT_Reset``), the
machine description's switch wiring, and which axes the bus has.  The GT fast path keeps
that combination per controller and input type (:func:`keep`) until the next change: every
place that changes any part of it calls :func:`changed`, which counts it (:data:`EPOCH`)
and drops every kept reader, so a reader needs no check of its own per call
(``tests/gtecat/gt/test_fast_di.py`` changes each and holds the fast reader to the table
path).  What is read live needs no call: the levels in the process image (a switch fault
holding or toggling a bit acts there) and the general-purpose input register.
"""

from __future__ import annotations

import weakref
from collections.abc import Callable
from typing import Any

#: how many changes there have been (one item: read as ``EPOCH[0]``)
EPOCH = [0]
#: the controllers holding readers (in their ``input_plans``)
_KEEPERS: weakref.WeakSet[Any] = weakref.WeakSet()


def keep(ctl: Any, key: int, reader: Callable[[], int]) -> Callable[[], int]:
    """Keep ``reader`` as ``ctl.input_plans[key]`` until the next :func:`changed`."""
    _KEEPERS.add(ctl)
    ctl.input_plans[key] = reader
    return reader


def changed(*_: object) -> None:
    """The sense of some input may have changed (any controller's): kept readers go."""
    EPOCH[0] += 1
    for ctl in list(_KEEPERS):
        ctl.input_plans.clear()


__all__ = ["EPOCH", "changed", "keep"]
