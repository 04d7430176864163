"""Consistency checks every configuration passes, whichever reader or builder made it.

The readers check what only they can see (sizes against ``Send``/``Recv``,
stated offsets against mapping order, every number against its range in
:mod:`gtecat.eni.limits`, with the file's lines); this module checks the model as a
whole: every number inside the same ranges (a net for builders that do not
read a file), unique slave addresses, no object mapped twice in one slave and
direction, and no two entries sharing a bit of a logical image (the process
image is one flat buffer per direction, DESIGN.md).
"""

from __future__ import annotations

from itertools import pairwise
from typing import NamedTuple

from . import limits
from .errors import EniError
from .model import Direction, EniConfig, Slave
from .numbers import fmt_index


def _err(cfg: EniConfig, s: Slave, message: str, element: str) -> EniError:
    return EniError(
        message, file=cfg.source, line=s.line, slave=s.position, slave_name=s.name, element=element
    )


def _check_ranges(cfg: EniConfig) -> None:
    """Every number of the model inside its range (:mod:`gtecat.eni.limits`)."""
    try:
        limits.SLAVE_COUNT.check(len(cfg.slaves), "number of slaves")
        limits.IMAGE_BYTES.check(cfg.outputs_bytes, "output image size")
        limits.IMAGE_BYTES.check(cfg.inputs_bytes, "input image size")
        if cfg.cycle_time_ns is not None:
            limits.CYCLE_NS.check(cfg.cycle_time_ns, "cycle time")
    except ValueError as exc:
        raise EniError(str(exc), file=cfg.source) from None
    for s in cfg.slaves:
        label = "Info"
        try:
            ident = s.identity
            for value, what in (
                (ident.vendor_id, "VendorId"),
                (ident.product_code, "ProductCode"),
                (ident.revision_no, "RevisionNo"),
                (ident.serial_no, "SerialNo"),
            ):
                limits.IDENTITY.check(value, what)
            limits.PHYS_ADDR.check(s.phys_addr, "PhysAddr")
            limits.AUTO_INC_ADDR.check(s.auto_inc_addr, "AutoIncAddr")
            for area, what in ((s.outputs, "Send"), (s.inputs, "Recv")):
                if area is not None:
                    label = f"ProcessData/{what}"
                    limits.BIT_OFFSET.check(area.bit_start, "BitStart")
                    limits.BIT_LENGTH.check(area.bit_len, "BitLength")
                    limits.check_span(area.bit_start, area.bit_len, what)
            for p in (*s.rx_pdos, *s.tx_pdos):
                label = "PDO"  # (named where a check fails: the labels cost more than checks)
                limits.INDEX.check(p.index, "PDO index")
                if p.sm is not None:
                    limits.SM.check(p.sm, "sync manager")
                for e in p.entries:
                    limits.INDEX.check(e.index, "index")
                    limits.SUBINDEX.check(e.subindex, "subindex")
                    label = "entry"
                    limits.ENTRY_BITS.check(e.bit_len, "bit length")
                    if e.logical_bit is not None:
                        limits.BIT_OFFSET.check(e.logical_bit, "logical bit")
                        limits.check_span(e.logical_bit, e.bit_len, "entry")
            label = "InitCmd"
            for c in s.init_cmds:
                limits.INDEX.check(c.index, "InitCmd index")
                limits.SUBINDEX.check(c.subindex, "InitCmd subindex")
        except ValueError as exc:
            if label == "PDO":
                label = f"PDO 0x{p.index & 0xFFFF:04X}"
            elif label == "entry":
                label = f"PDO 0x{p.index:04X} entry {fmt_index(e.index, e.subindex)}"
            raise _err(cfg, s, str(exc), label) from None


class _EntryLabel(NamedTuple):
    """The label "PDO 0x1600 entry 0x6040:00", made into text only for a message (a bus of
    a thousand drives has thousands of entries, and nearly every file none to report)."""

    pdo: int
    index: int
    subindex: int

    def __str__(self) -> str:
        return f"PDO 0x{self.pdo:04X} entry {fmt_index(self.index, self.subindex)}"


def check_config(cfg: EniConfig) -> None:
    """Raise :class:`EniError` on the first inconsistency found."""
    _check_ranges(cfg)
    phys: dict[int, Slave] = {}
    auto: dict[int, Slave] = {}
    for i, s in enumerate(cfg.slaves):
        if s.position != i:
            raise _err(cfg, s, f"slave at bus position {i} says position {s.position}", "position")
        for addr, seen, what in (
            (s.phys_addr, phys, "PhysAddr"),
            (s.auto_inc_addr, auto, "AutoIncAddr"),
        ):
            if not addr:
                continue
            if addr in seen:
                other = seen[addr]
                raise _err(
                    cfg,
                    s,
                    f"{what} {addr} is also the address of slave {other.position} ({other.name})",
                    f"Info/{what}",
                )
            seen[addr] = s

    # (start, end, slave, (pdo, index, subindex)) per direction: the entry's label is made
    # from the plain tuple only for a message (a tuple subclass made per entry costs more)
    spans: dict[Direction, list[tuple[int, int, Slave, tuple[int, int, int]]]] = {
        d: [] for d in Direction
    }
    for s in cfg.slaves:
        for d, pdos, area in (
            (Direction.OUT, s.rx_pdos, s.outputs),
            (Direction.IN, s.tx_pdos, s.inputs),
        ):
            seen_obj: set[tuple[int, int]] = set()
            cum = 0
            for p in pdos:
                if p.direction != d:
                    raise _err(
                        cfg,
                        s,
                        f"PDO 0x{p.index:04X} has the wrong direction",
                        f"PDO 0x{p.index:04X}",
                    )
                for e in p.entries:
                    where = (p.index, e.index, e.subindex)
                    if e.bit_len <= 0:
                        raise _err(cfg, s, "entry with no bits", str(_EntryLabel(*where)))
                    if not e.is_padding:
                        key = (e.index, e.subindex)
                        if key in seen_obj:
                            raise _err(
                                cfg,
                                s,
                                f"{fmt_index(*key)} is mapped twice as "
                                f"{'output' if d == Direction.OUT else 'input'}",
                                str(_EntryLabel(*where)),
                            )
                        seen_obj.add(key)
                    if e.logical_bit is not None:
                        start = e.logical_bit
                    elif area is not None:
                        start = area.bit_start + cum
                    else:
                        start = None
                    if start is not None:
                        if start < 0:
                            raise _err(
                                cfg, s, f"negative logical bit {start}", str(_EntryLabel(*where))
                            )
                        spans[d].append((start, start + e.bit_len, s, where))
                    cum += e.bit_len
    for d, items in spans.items():
        items.sort(key=lambda t: (t[0], t[1]))
        image = "output" if d == Direction.OUT else "input"
        for (a0, a1, sa, la), (b0, b1, sb, lb) in pairwise(items):
            if b0 < a1:
                raise _err(
                    cfg,
                    sb,
                    f"bits {b0}..{b1 - 1} of the {image} image overlap slave {sa.position} "
                    f"({sa.name}) {_EntryLabel(*la)} at bits {a0}..{a1 - 1}",
                    str(_EntryLabel(*lb)),
                )
