"""Where every PDO entry lives: its logical bit and its GT raw bit (manual 5.2.2.4, 5.2.2.5).

Two views of the same bytes (DESIGN.md "Process image and the GT raw offsets"):

* the *logical* images (one per direction) that the bus moves: an entry sits
  at the bit offset the configuration states (never recomputed), else at its
  slave's ``Send``/``Recv`` start plus the entries before it in mapping order;
* the *GT raw* image that ``GT_GetEcatRawData``/``GT_SetEcatRawData`` address:
  slaves in bus order, each slave's region = its output bytes (assigned RxPDO
  entries in mapping order, packed LSB first, rounded up to a whole byte)
  immediately followed by its input bytes (TxPDO entries, same rule).  Slave 0
  starts at 0; each next region starts where the previous ended.

Axes (DESIGN.md): a CiA-402 channel ``k`` of a slave is the 16-bit controlword
``0x6040+0x800*k:0`` mapped as output together with the 16-bit statusword
``0x6041+0x800*k:0`` as input; GT axes are numbered from 1 over the channels
in bus order.  A Googol INI slave that says ``type=0`` (IO) gets no axis, and
one that says ``nservo=n`` (n > 0) gets at most ``n``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from .datatypes import CHANNEL_STRIDE, MAX_CHANNELS, cia402_name, cia402_type, entry_signed
from .model import Direction, EniConfig, Slave


@dataclass(frozen=True, slots=True)
class Placement:
    """One PDO entry placed in both images."""

    slave: int
    direction: Direction
    pdo: int
    index: int
    subindex: int
    name: str
    bits: int
    data_type: str
    signed: bool
    #: bit offset in its direction's logical image, as the ENI gives it
    logical_bit: int
    #: bit offset in the GT raw image (DESIGN.md rule)
    gt_bit: int
    #: bit offset inside the slave's own rx (OUT) or tx (IN) buffer
    slave_bit: int

    @property
    def is_padding(self) -> bool:
        return self.index == 0 and not self.name

    @property
    def gt_byte(self) -> int:
        return self.gt_bit >> 3


@dataclass(frozen=True, slots=True)
class SlaveLayout:
    """One slave's region of the GT raw image and its areas in the logical images."""

    position: int
    name: str
    gt_offset: int  # bytes
    out_bytes: int
    in_bytes: int
    out_logical_bit: int | None
    out_bits: int
    in_logical_bit: int | None
    in_bits: int
    #: CiA-402 channels k (controlword 0x6040+0x800k out and statusword 0x6041+0x800k in)
    channels: tuple[int, ...]
    #: their 1-based GT axis numbers
    axes: tuple[int, ...]
    entries: tuple[Placement, ...]

    @property
    def gt_size(self) -> int:
        return self.out_bytes + self.in_bytes


@dataclass(frozen=True, slots=True)
class AxisRef:
    axis: int
    slave: int
    channel: int


@dataclass(frozen=True)
class Layout:
    """The whole process image: per-slave regions, entries, axes and image sizes."""

    config: EniConfig
    slaves: tuple[SlaveLayout, ...]
    axes: tuple[AxisRef, ...]
    gt_raw_bytes: int
    outputs_bytes: int
    inputs_bytes: int
    _index: dict[tuple[int, int, int, Direction], Placement] = field(
        default_factory=dict, repr=False, compare=False
    )
    #: (slave, index, subindex) -> what :meth:`entry` finds without a direction (outputs
    #: first): one lookup for a controller asking whether an object is mapped at all
    _either: dict[tuple[int, int, int], Placement] = field(
        default_factory=dict, repr=False, compare=False
    )
    _axes: dict[int, AxisRef] = field(default_factory=dict, repr=False, compare=False)

    def __post_init__(self) -> None:
        for s in self.slaves:
            for p in s.entries:
                if not p.is_padding:
                    self._index.setdefault((p.slave, p.index, p.subindex, p.direction), p)
        for (slave, index, subindex, direction), p in self._index.items():
            if direction == Direction.OUT or (slave, index, subindex) not in self._either:
                self._either[slave, index, subindex] = p
        for a in self.axes:
            self._axes[a.axis] = a

    def entry(
        self, slave: int, index: int, subindex: int = 0, direction: Direction | None = None
    ) -> Placement | None:
        """The placement of ``index:subindex`` in ``slave`` (outputs first when no direction)."""
        if direction is not None:
            return self._index.get((slave, index, subindex, direction))
        return self._either.get((slave, index, subindex))

    def axis_entry(self, axis: int, index: int, subindex: int = 0) -> Placement | None:
        """The object ``index`` (as for channel 0, e.g. 0x6064) of a GT axis (1-based)."""
        ref = self._axes.get(axis)
        if ref is None:
            return None
        # (entry's lookup inline: an axis's first look at each object it uses comes here)
        return self._either.get((ref.slave, index + CHANNEL_STRIDE * ref.channel, subindex))

    def axis(self, axis: int) -> AxisRef | None:
        return self._axes.get(axis)

    def mapped_objects(self) -> set[tuple[int, int]]:
        """``(slave, index)`` of every object mapped at subindex 0 (either direction): the
        ones :meth:`entry` finds, in one set for a caller asking about many."""
        return {(slave, index) for slave, index, sub, _ in self._index if not sub}

    def to_json(self) -> dict[str, Any]:
        """The ``gtecat map --json`` document (DESIGN.md "The stable surface").

        ``axis`` is the slave's first GT axis (the schema's key); ``axes`` adds all
        of them, so a multi-axis module (0x6040+0x800*k) shows every channel's axis.
        """
        slaves = []
        for s in self.slaves:
            slaves.append(
                {
                    "position": s.position,
                    "name": s.name,
                    "axis": s.axes[0] if s.axes else None,
                    # every GT axis of the slave (a multi-axis module has several)
                    "axes": list(s.axes),
                    "gt_offset": s.gt_offset,
                    "gt_size": s.gt_size,
                    "entries": [
                        {
                            "dir": "out" if p.direction == Direction.OUT else "in",
                            "index": p.index,
                            "subindex": p.subindex,
                            "name": p.name,
                            "bits": p.bits,
                            "gt_bit": p.gt_bit,
                            "logical_bit": p.logical_bit,
                        }
                        for p in s.entries
                        if not p.is_padding
                    ],
                }
            )
        return {
            "slaves": slaves,
            "gt_raw_bytes": self.gt_raw_bytes,
            "outputs_bytes": self.outputs_bytes,
            "inputs_bytes": self.inputs_bytes,
        }


def _channels(slave: Slave) -> tuple[int, ...]:
    outs = {(e.index, e.subindex): e.bit_len for p in slave.rx_pdos for e in p.entries}
    ins = {(e.index, e.subindex): e.bit_len for p in slave.tx_pdos for e in p.entries}
    found = tuple(
        k
        for k in range(MAX_CHANNELS)
        if outs.get((0x6040 + CHANNEL_STRIDE * k, 0)) == 16
        and ins.get((0x6041 + CHANNEL_STRIDE * k, 0)) == 16
    )
    if slave.servo_hint is False:
        return ()
    if slave.servo_hint and slave.nservo_hint and slave.nservo_hint > 0:
        found = found[: slave.nservo_hint]
    return found


def build_layout(cfg: EniConfig) -> Layout:
    """Place every assigned entry of ``cfg`` in the logical and GT raw images."""
    slaves: list[SlaveLayout] = []
    axes: list[AxisRef] = []
    gt = 0
    ends = {Direction.OUT: 0, Direction.IN: 0}
    for s in cfg.slaves:
        out_bits = s.out_bits
        in_bits = s.in_bits
        out_bytes = (out_bits + 7) // 8
        in_bytes = (in_bits + 7) // 8
        placements: list[Placement] = []
        starts: dict[Direction, int | None] = {}
        for d, pdos, area, base in (
            (Direction.OUT, s.rx_pdos, s.outputs, gt * 8),
            (Direction.IN, s.tx_pdos, s.inputs, (gt + out_bytes) * 8),
        ):
            start = area.bit_start if area is not None else None
            if start is None:  # no area: anchor on a stated entry, else after the others
                cum = 0
                for p in pdos:
                    for e in p.entries:
                        if e.logical_bit is not None and start is None:
                            start = e.logical_bit - cum
                        cum += e.bit_len
                if start is None and cum:
                    start = (ends[d] + 7) // 8 * 8
            starts[d] = start if (out_bits if d == Direction.OUT else in_bits) else None
            bit = 0
            for p in pdos:
                for e in p.entries:
                    logical = e.logical_bit if e.logical_bit is not None else (start or 0) + bit
                    data_type = e.data_type or cia402_type(e.index, e.subindex, e.bit_len)
                    placements.append(
                        Placement(
                            slave=s.position,
                            direction=d,
                            pdo=p.index,
                            index=e.index,
                            subindex=e.subindex,
                            name=e.name or cia402_name(e.index, e.subindex, e.bit_len),
                            bits=e.bit_len,
                            data_type=data_type,
                            signed=entry_signed(data_type, e.index, e.subindex, e.bit_len),
                            logical_bit=logical,
                            gt_bit=base + bit,
                            slave_bit=bit,
                        )
                    )
                    ends[d] = max(ends[d], logical + e.bit_len)
                    bit += e.bit_len
            if area is not None:
                ends[d] = max(ends[d], area.bit_start + area.bit_len)
        channels = _channels(s)
        first_axis = len(axes) + 1
        slave_axes = tuple(range(first_axis, first_axis + len(channels)))
        axes.extend(AxisRef(a, s.position, k) for a, k in zip(slave_axes, channels, strict=True))
        slaves.append(
            SlaveLayout(
                position=s.position,
                name=s.name,
                gt_offset=gt,
                out_bytes=out_bytes,
                in_bytes=in_bytes,
                out_logical_bit=starts[Direction.OUT],
                out_bits=out_bits,
                in_logical_bit=starts[Direction.IN],
                in_bits=in_bits,
                channels=channels,
                axes=slave_axes,
                entries=tuple(placements),
            )
        )
        gt += out_bytes + in_bytes
    return Layout(
        config=cfg,
        slaves=tuple(slaves),
        axes=tuple(axes),
        gt_raw_bytes=gt,
        outputs_bytes=max(cfg.outputs_bytes, (ends[Direction.OUT] + 7) // 8),
        inputs_bytes=max(cfg.inputs_bytes, (ends[Direction.IN] + 7) // 8),
    )
