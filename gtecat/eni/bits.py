"""The one bit helper: sub-byte reads, writes and copies in LSB-first process images.

EtherCAT packs process data least significant bit first (ETG.1000.4 logical
addressing): bit ``k`` of an image is bit ``k % 8`` of byte ``k // 8``.  Every
entry that is not byte aligned goes through these functions.
"""

from __future__ import annotations

Buffer = bytearray | memoryview


def get_bits(buf: bytes | Buffer, bit_offset: int, bit_len: int, *, signed: bool = False) -> int:
    """Read ``bit_len`` bits starting at ``bit_offset`` as an integer."""
    if bit_len <= 0:
        return 0
    first = bit_offset >> 3
    last = (bit_offset + bit_len - 1) >> 3
    raw = int.from_bytes(bytes(buf[first : last + 1]), "little")
    value = (raw >> (bit_offset & 7)) & ((1 << bit_len) - 1)
    if signed and value >> (bit_len - 1):
        value -= 1 << bit_len
    return value


def set_bits(buf: Buffer, bit_offset: int, bit_len: int, value: int) -> None:
    """Write the low ``bit_len`` bits of ``value`` at ``bit_offset``; other bits untouched."""
    if bit_len <= 0:
        return
    first = bit_offset >> 3
    last = (bit_offset + bit_len - 1) >> 3
    shift = bit_offset & 7
    mask = ((1 << bit_len) - 1) << shift
    raw = int.from_bytes(bytes(buf[first : last + 1]), "little")
    raw = (raw & ~mask) | ((value << shift) & mask)
    buf[first : last + 1] = raw.to_bytes(last - first + 1, "little")


def copy_bits(src: bytes | Buffer, src_bit: int, dst: Buffer, dst_bit: int, bit_len: int) -> None:
    """Copy ``bit_len`` bits between two LSB-first images (an FMMU in software)."""
    if bit_len <= 0:
        return
    if not (src_bit & 7) and not (dst_bit & 7) and not (bit_len & 7):
        s, d, n = src_bit >> 3, dst_bit >> 3, bit_len >> 3
        dst[d : d + n] = src[s : s + n]
        return
    set_bits(dst, dst_bit, bit_len, get_bits(src, src_bit, bit_len))
