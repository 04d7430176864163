"""The cyclic frames of an ENI (ETG.2100 ``Config/Cyclic/Frame/Cmd``): the process images
cut into datagrams that fit Ethernet frames.

A master that follows the ENI word for word (TwinCAT, acontis EC-Master, the Googol
controller reading ``Gecat.eni``) sends each ``Frame`` as one Ethernet frame and each of
its ``Cmd`` as one datagram.  An Ethernet frame carries at most 1500 bytes (1514 without
FCS); the EtherCAT header takes 2 of them and each datagram 10 bytes of header and 2 of
working counter around its data (ETG.1000.4 5.3, 5.4).  So the datagrams of one frame
hold at most 1496 bytes, and one datagram alone at most :data:`MAX_DATAGRAM_DATA` = 1484
bytes of process data.

The writer keeps outputs and inputs apart (an LWR and an LRD at the logical addresses of
:func:`gtecat.eni.register_cmds.logical_bases`).  A bus whose two commands fit one frame
gets that one frame (as before); a larger one is cut, TwinCAT's way: the output image first,
then the input image, each in commands of consecutive bytes, frames filled in order.  A
command ends where a slave's area ends (the last whole slave that fits); only an area larger
than a datagram is cut inside, and a slave whose area two commands share counts in both.
The commands cover each image exactly once.  Each command's ``Cnt`` is what the ESCs
return (ETG.1000.4 5.4): +1 per slave with a write FMMU in an LWR's range, +1 per slave
with a read FMMU in an LRD's, and for an LRW +1 for a read and +2 for a write FMMU.
"""

from __future__ import annotations

from bisect import bisect_left, bisect_right
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

from .ethercat import DATAGRAM_HEADER_LEN, ECAT_HEADER_LEN, MAX_ECAT_LEN, WKC_LEN, Command
from .model import Direction, EniConfig, Slave
from .register_cmds import logical_bases, sm_maps

#: the bytes the datagrams of one frame take: header, data and working counter of each
FRAME_PAYLOAD = MAX_ECAT_LEN - ECAT_HEADER_LEN
#: what a datagram adds to its data
DATAGRAM_OVERHEAD = DATAGRAM_HEADER_LEN + WKC_LEN
#: the most process data one datagram carries (alone in its frame): 1484 bytes
MAX_DATAGRAM_DATA = FRAME_PAYLOAD - DATAGRAM_OVERHEAD

_COMMAND = {Direction.OUT: Command.LWR, Direction.IN: Command.LRD}


@dataclass(frozen=True, slots=True)
class CyclicCmd:
    """One process-data datagram of a cyclic frame."""

    command: Command
    direction: Direction
    offset: int  #: its first byte in its direction's image (``InputOffs``/``OutputOffs``)
    length: int  #: ``DataLength``
    address: int  #: ``Addr``: the logical address of its first byte
    wkc: int  #: ``Cnt``: the working counter the slaves return

    @property
    def size(self) -> int:
        """The bytes it takes in its frame."""
        return self.length + DATAGRAM_OVERHEAD


def fmmu_spans(s: Slave) -> dict[Direction, tuple[int, int]]:
    """Per direction, the bytes ``[start, end)`` of its image that the slave's FMMUs map
    (the register InitCmds write one FMMU per process-data SM); a direction without an
    FMMU is absent."""
    spans: dict[Direction, tuple[int, int]] = {}
    for m in sm_maps(s):
        if m.logical_bit is None or not m.length:
            continue
        first = m.logical_bit // 8
        last = (m.logical_bit + m.bits + 7) // 8
        had = spans.get(m.direction)
        spans[m.direction] = (
            (first, last) if had is None else (min(had[0], first), max(had[1], last))
        )
    return spans


def _clusters(spans: Iterable[tuple[int, int]]) -> tuple[list[int], list[int]]:
    """Spans that share a byte merged: (starts, ends), sorted.  A command ends between
    clusters, never inside one unless one cluster alone is larger than a datagram."""
    starts: list[int] = []
    ends: list[int] = []
    for a, b in sorted(spans):
        if ends and a < ends[-1]:
            ends[-1] = max(ends[-1], b)
        else:
            starts.append(a)
            ends.append(b)
    return starts, ends


def _cut(starts: Sequence[int], ends: Sequence[int], pos: int, limit: int) -> tuple[int, bool]:
    """Where a command from ``pos`` holding at most up to ``limit`` ends: (end, whether it
    ends outside every slave's area)."""
    k = bisect_right(starts, limit - 1) - 1  # the last cluster starting before limit
    if k < 0 or ends[k] <= limit:
        return limit, True  # limit falls between clusters (or is the image's end)
    if starts[k] > pos:
        return starts[k], True  # before the cluster limit cuts
    return limit, False  # one cluster larger than the room: cut inside it


def _wkc(
    cmds: list[tuple[Direction, int, int]], spans: dict[Direction, list[tuple[int, int]]]
) -> list[int]:
    """Per command (direction, start, end): how many slaves' spans it overlaps."""
    counts = [0] * len(cmds)
    for d in (Direction.OUT, Direction.IN):
        ks = [k for k, c in enumerate(cmds) if c[0] == d]
        if not ks:
            continue
        firsts = [cmds[k][1] for k in ks]
        for a, b in spans[d]:
            lo = bisect_right(firsts, a) - 1  # the command holding the span's first byte
            hi = bisect_left(firsts, b)  # the first command past its last byte
            for j in range(max(lo, 0), hi):
                counts[ks[j]] += 1
    return counts


def cyclic_frames(
    cfg: EniConfig, bases: dict[Direction, int] | None = None
) -> list[list[CyclicCmd]]:
    """The process-data frames of ``cfg``: each a list of commands whose datagrams fit one
    Ethernet frame; ``bases``: the logical address of each image (default
    :func:`~gtecat.eni.register_cmds.logical_bases`)."""
    if bases is None:
        bases = logical_bases(cfg.outputs_bytes)
    spans: dict[Direction, list[tuple[int, int]]] = {Direction.OUT: [], Direction.IN: []}
    for s in cfg.slaves:
        for d, span in fmmu_spans(s).items():
            spans[d].append(span)
    placed: list[tuple[int, Direction, int, int]] = []  # (frame, direction, start, end)
    frame, room = 0, FRAME_PAYLOAD
    for d, size in ((Direction.OUT, cfg.outputs_bytes), (Direction.IN, cfg.inputs_bytes)):
        starts, ends = _clusters(spans[d])
        pos = 0
        while pos < size:
            first_in_frame = room == FRAME_PAYLOAD
            cap = room - DATAGRAM_OVERHEAD
            if cap > 0:
                end, clean = _cut(starts, ends, pos, min(pos + cap, size))
                if clean or first_in_frame:
                    placed.append((frame, d, pos, end))
                    room -= DATAGRAM_OVERHEAD + end - pos
                    pos = end
                    continue
            frame, room = frame + 1, FRAME_PAYLOAD  # a fresh frame has room for a clean cut
    wkc = _wkc([(d, a, b) for _, d, a, b in placed], spans)
    frames: list[list[CyclicCmd]] = []
    for (f, d, a, b), n in zip(placed, wkc, strict=True):
        if f == len(frames):
            frames.append([])
        frames[f].append(CyclicCmd(_COMMAND[d], d, a, b - a, bases[d] + a, n))
    return frames
