"""The two data FIFOs of the FIFO-fed modes: PT (manual 7.4.2 (4)) and Follow (7.6.2 (6)).

Both modes keep two independent FIFOs ("FIFO1", "FIFO2"; ``fifo`` argument 0
and 1 of the GT functions) of the same size, chosen by a memory flag:
GT_SetPtMemory 0 → 32 / 1 → 1024 segments, GT_SetFollowMemory 0 → 16 /
1 → 512 segments each.  A FIFO keeps its data after it was run (static PT,
Follow loops reuse it); the planner reads it by index.  What "running out"
means differs per mode and lives in the planner.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Generic, TypeVar

from ...errors import CommandError, ParameterError
from . import checks

T = TypeVar("T")

#: segments per FIFO for memory flag 0 / 1 (GT_SetPtMemory, chapter 13 entry 120)
PT_MEMORY_SIZES = (32, 1024)
#: segments per FIFO for memory flag 0 / 1 (GT_SetFollowMemory, chapter 13 entry 109)
FOLLOW_MEMORY_SIZES = (16, 512)


def fifo_index(fifo: object) -> int:
    """A FIFO argument: 0 (FIFO1) or 1 (FIFO2), else ParameterError (return 7)."""
    i = checks.integer("fifo", fifo)
    if i not in (0, 1):
        raise ParameterError(f"fifo must be 0 or 1, got {fifo!r}")
    return i


class SegmentFifo(Generic[T]):
    """One bounded FIFO of segments; ``space`` is what GT_PtSpace / GT_FollowSpace report."""

    __slots__ = ("_items", "capacity", "name")

    def __init__(self, capacity: int, name: str) -> None:
        self.capacity = capacity
        self.name = name
        self._items: list[T] = []

    def __len__(self) -> int:
        return len(self._items)

    def __getitem__(self, i: int) -> T:
        return self._items[i]

    def __iter__(self) -> Iterator[T]:
        return iter(self._items)

    @property
    def space(self) -> int:
        """Free segments."""
        return self.capacity - len(self._items)

    @property
    def last(self) -> T | None:
        """The segment pushed last, or None when empty."""
        return self._items[-1] if self._items else None

    def push(self, item: T) -> None:
        """Append one segment; a full FIFO is a CommandError (return 1: "no space")."""
        if len(self._items) >= self.capacity:
            raise CommandError(
                f"{self.name} is full ({self.capacity} segments): wait until space > 0"
            )
        self._items.append(item)

    def clear(self) -> None:
        self._items.clear()


class FifoPair(Generic[T]):
    """FIFO1 and FIFO2 of one profile, sized by the mode's memory flag."""

    __slots__ = ("_fifos", "_flag", "_sizes")

    def __init__(self, sizes: tuple[int, int], mode: str) -> None:
        self._sizes = sizes
        self._flag = 0
        self._fifos: tuple[SegmentFifo[T], SegmentFifo[T]] = (
            SegmentFifo(sizes[0], f"{mode} FIFO1 (fifo 0)"),
            SegmentFifo(sizes[0], f"{mode} FIFO2 (fifo 1)"),
        )

    def __getitem__(self, i: int) -> SegmentFifo[T]:
        return self._fifos[i]

    @property
    def memory(self) -> int:
        """The memory flag (0 = small, 1 = large FIFOs)."""
        return self._flag

    @property
    def capacity(self) -> int:
        """Segments per FIFO."""
        return self._sizes[self._flag]

    def set_memory(self, flag: object) -> None:
        """Resize both FIFOs; data that no longer fits is refused, never cut (CommandError)."""
        f = checks.integer("memory", flag)
        if f not in (0, 1):
            raise ParameterError(f"memory must be 0 or 1, got {flag!r}")
        size = self._sizes[f]
        for q in self._fifos:
            if len(q) > size:
                raise CommandError(
                    f"{q.name} holds {len(q)} segments, more than the {size} of memory {f}: "
                    "clear it first"
                )
        self._flag = f
        for q in self._fifos:
            q.capacity = size
