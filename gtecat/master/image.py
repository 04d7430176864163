"""The process image: two logical images (outputs, inputs) and the GT raw view over them.

The logical images are what a backend moves (DESIGN.md "Process image"): one
flat byte buffer holds the outputs then the inputs, and ``outputs`` /
``inputs`` are numpy views of it, never copies (SOEM's IOmap).  The GT raw
image of manual 5.2.2.4 (slaves in bus order, each slave's output bytes then
its input bytes) is not stored: :class:`ProcessImage` maps every raw byte to
the logical byte it stands for, so ``GT_GetEcatRawData`` is one numpy gather.
Slaves whose areas are not byte aligned go through :mod:`gtecat.eni.bits`.
"""

from __future__ import annotations

import functools
import struct
from dataclasses import dataclass

import numpy as np

from gtecat.eni.bits import copy_bits, get_bits, set_bits
from gtecat.eni.layout import Layout, Placement
from gtecat.eni.model import Direction

from ..errors import ParameterError

_INT_FMT = {8: "b", 16: "h", 32: "i", 64: "q"}


@functools.cache
def _struct(fmt: str) -> struct.Struct:
    """One (immutable) codec per format for every accessor of every slave."""
    return struct.Struct(fmt)


@dataclass(frozen=True, slots=True)
class Segment:
    """One slave's area in one direction: raw bytes <-> logical bits."""

    slave: int
    direction: Direction
    raw_offset: int  # first GT raw byte
    raw_bytes: int  # whole bytes in the raw view
    logical_bit: int  # first bit in the direction's logical image
    bit_len: int

    @property
    def aligned(self) -> bool:
        return not (self.logical_bit & 7)


class EntryAccess:
    """Fast typed access to one mapped entry of the logical image."""

    __slots__ = ("_buf", "_fmt", "_off", "bits", "placement", "signed")

    def __init__(self, image: ProcessImage, placement: Placement) -> None:
        self.placement = placement
        self.bits = placement.bits
        self.signed = placement.signed
        base = 0 if placement.direction == Direction.OUT else image.outputs_bytes
        bit = base * 8 + placement.logical_bit
        self._buf = image.view
        fmt = _INT_FMT.get(self.bits) if not (bit & 7) else None
        if fmt is not None:
            self._fmt = _struct("<" + (fmt if self.signed else fmt.upper()))
            self._off = bit >> 3
        else:
            self._fmt = None
            self._off = bit

    def get(self) -> int:
        if self._fmt is not None:
            return self._fmt.unpack_from(self._buf, self._off)[0]
        return get_bits(self._buf, self._off, self.bits, signed=self.signed)

    def bit_at(self, b: int) -> tuple[memoryview, int, int] | None:
        """Where bit ``b`` of the entry's value lies: ``(buffer, byte, shift)`` such that
        ``buffer[byte] >> shift & 1 == get() >> b & 1`` (little-endian, LSB first, as
        :meth:`get` reads it); None for a bit past the entry's width."""
        if not 0 <= b < self.bits:
            return None
        bit = (self._off << 3 if self._fmt is not None else self._off) + b
        return self._buf, bit >> 3, bit & 7

    def set(self, value: int) -> None:
        value = int(value)
        if self._fmt is not None:
            # wrap like the C types the manual uses (no exception on overflow)
            mask = (1 << self.bits) - 1
            v = value & mask
            if self.signed and v >> (self.bits - 1):
                v -= 1 << self.bits
            self._fmt.pack_into(self._buf, self._off, v)
        else:
            set_bits(self._buf, self._off, self.bits, value)


class ProcessImage:
    """Logical output/input images plus the GT raw view of them."""

    def __init__(self, layout: Layout) -> None:
        self.layout = layout
        self.outputs_bytes = layout.outputs_bytes
        self.inputs_bytes = layout.inputs_bytes
        self.buffer = np.zeros(self.outputs_bytes + self.inputs_bytes, dtype=np.uint8)
        self.view = memoryview(self.buffer)  # the same bytes, for struct/bits
        self.outputs = self.buffer[: self.outputs_bytes]
        self.inputs = self.buffer[self.outputs_bytes :]
        self.size = layout.gt_raw_bytes
        self.segments: list[Segment] = []
        for s in layout.slaves:
            if s.out_bytes:
                self.segments.append(
                    Segment(
                        s.position,
                        Direction.OUT,
                        s.gt_offset,
                        s.out_bytes,
                        s.out_logical_bit or 0,
                        s.out_bits,
                    )
                )
            if s.in_bytes:
                self.segments.append(
                    Segment(
                        s.position,
                        Direction.IN,
                        s.gt_offset + s.out_bytes,
                        s.in_bytes,
                        s.in_logical_bit or 0,
                        s.in_bits,
                    )
                )
        self.aligned = all(seg.aligned for seg in self.segments)
        # raw byte k -> index in self.buffer (aligned case) and "is an output byte"
        self._raw_index = np.zeros(self.size, dtype=np.intp)
        self._raw_is_out = np.zeros(self.size, dtype=bool)
        # bits of a raw byte that belong to the slave (its last byte may be partly padding)
        self._raw_mask = np.zeros(self.size, dtype=np.uint8)
        self._full_bytes = True
        for seg in self.segments:
            base = 0 if seg.direction == Direction.OUT else self.outputs_bytes
            start = base + (seg.logical_bit >> 3)
            sl = slice(seg.raw_offset, seg.raw_offset + seg.raw_bytes)
            self._raw_index[sl] = np.arange(start, start + seg.raw_bytes)
            self._raw_is_out[sl] = seg.direction == Direction.OUT
            self._raw_mask[sl] = 0xFF
            if seg.bit_len & 7:
                self._raw_mask[seg.raw_offset + seg.raw_bytes - 1] = (1 << (seg.bit_len & 7)) - 1
                self._full_bytes = False

    # --- GT raw view (manual 5.2.2.4) -------------------------------------------
    def check_range(self, offset: int, size: int) -> None:
        if offset < 0 or size < 0 or offset + size > self.size:
            raise ParameterError(
                f"raw range offset={offset} size={size} outside the PDO image "
                f"(0..{self.size} bytes)"
            )

    def read_raw(self, offset: int, size: int) -> bytes:
        """Bytes ``offset .. offset+size`` of the GT raw image (outputs and inputs)."""
        self.check_range(offset, size)
        if self.aligned:
            data = self.buffer[self._raw_index[offset : offset + size]]
            if not self._full_bytes:
                data &= self._raw_mask[offset : offset + size]
            return data.tobytes()
        return bytes(self._slow_raw()[offset : offset + size])

    def write_raw(self, offset: int, data: bytes) -> None:
        """Write output bytes of the GT raw image; input bytes are refused (code 7)."""
        size = len(data)
        self.check_range(offset, size)
        if size and not self._raw_is_out[offset : offset + size].all():
            bad = offset + int(np.argmin(self._raw_is_out[offset : offset + size]))
            raise ParameterError(
                f"raw byte {bad} is an input byte (slave {self.slave_at(bad)}); only output "
                "bytes can be written"
            )
        if self.aligned:
            idx = self._raw_index[offset : offset + size]
            new = np.frombuffer(bytes(data), dtype=np.uint8)
            if not self._full_bytes:
                mask = self._raw_mask[offset : offset + size]
                new = (self.buffer[idx] & ~mask) | (new & mask)
            self.buffer[idx] = new
            return
        raw = self._slow_raw()
        raw[offset : offset + size] = data
        for seg in self.segments:
            if seg.direction != Direction.OUT:
                continue
            if seg.raw_offset + seg.raw_bytes <= offset or seg.raw_offset >= offset + size:
                continue
            copy_bits(raw, seg.raw_offset * 8, self.view, seg.logical_bit, seg.bit_len)

    def slave_at(self, raw_offset: int) -> int | None:
        for seg in self.segments:
            if seg.raw_offset <= raw_offset < seg.raw_offset + seg.raw_bytes:
                return seg.slave
        return None

    def _slow_raw(self) -> bytearray:
        raw = bytearray(self.size)
        for seg in self.segments:
            base = 0 if seg.direction == Direction.OUT else self.outputs_bytes * 8
            copy_bits(self.view, base + seg.logical_bit, raw, seg.raw_offset * 8, seg.bit_len)
        return raw

    # --- typed entries ------------------------------------------------------------
    def access(self, placement: Placement) -> EntryAccess:
        return EntryAccess(self, placement)

    def read_entry(self, placement: Placement) -> int:
        return EntryAccess(self, placement).get()

    def write_entry(self, placement: Placement, value: int) -> None:
        EntryAccess(self, placement).set(value)

    # --- FMMU in software (emulated backend) ---------------------------------------
    def to_slave(self, seg: Segment, dst: bytearray) -> None:
        """Copy a slave's output area into its RxPDO buffer."""
        if seg.aligned:
            start = seg.logical_bit >> 3
            n = min(len(dst), seg.raw_bytes)
            dst[:n] = self.view[start : start + n]
        else:
            copy_bits(self.view, seg.logical_bit, dst, 0, seg.bit_len)

    def from_slave(self, seg: Segment, src: bytes | bytearray) -> None:
        """Copy a slave's TxPDO buffer into its input area."""
        base = self.outputs_bytes
        if seg.aligned:
            start = base + (seg.logical_bit >> 3)
            full = seg.bit_len >> 3
            n = min(len(src), full)
            self.view[start : start + n] = src[:n]
            rest = seg.bit_len - n * 8
            if rest > 0 and len(src) > n:
                copy_bits(src, n * 8, self.view, (start + n) * 8, rest)
        else:
            copy_bits(src, 0, self.view, base * 8 + seg.logical_bit, seg.bit_len)
