"""The one bit helper (LSB-first EtherCAT images, ETG.1000.4 logical addressing)."""

from hypothesis import given
from hypothesis import strategies as st

from gtecat.eni.bits import copy_bits, get_bits, set_bits


def _as_int(buf: bytes) -> int:
    return int.from_bytes(buf, "little")


@given(st.binary(min_size=1, max_size=16), st.data())
def test_get_bits_matches_integer_model(buf, data):
    n_bits = len(buf) * 8
    off = data.draw(st.integers(0, n_bits - 1))
    length = data.draw(st.integers(1, n_bits - off))
    expected = (_as_int(buf) >> off) & ((1 << length) - 1)
    assert get_bits(buf, off, length) == expected


@given(st.binary(min_size=1, max_size=16), st.data())
def test_set_bits_changes_only_its_bits(buf, data):
    n_bits = len(buf) * 8
    off = data.draw(st.integers(0, n_bits - 1))
    length = data.draw(st.integers(1, n_bits - off))
    value = data.draw(st.integers(0, (1 << length) - 1))
    b = bytearray(buf)
    set_bits(b, off, length, value)
    mask = ((1 << length) - 1) << off
    assert _as_int(b) & ~mask == _as_int(buf) & ~mask
    assert get_bits(b, off, length) == value


@given(st.binary(min_size=1, max_size=12), st.binary(min_size=1, max_size=12), st.data())
def test_copy_bits_is_an_fmmu(src, dst, data):
    length = data.draw(st.integers(1, min(len(src), len(dst)) * 8))
    s_off = data.draw(st.integers(0, len(src) * 8 - length))
    d_off = data.draw(st.integers(0, len(dst) * 8 - length))
    out = bytearray(dst)
    copy_bits(src, s_off, out, d_off, length)
    assert get_bits(out, d_off, length) == get_bits(src, s_off, length)
    mask = ((1 << length) - 1) << d_off
    assert _as_int(out) & ~mask == _as_int(dst) & ~mask


def test_signed_read():
    assert get_bits(b"\xff\x7f", 0, 16, signed=True) == 0x7FFF
    assert get_bits(b"\x00\x80", 0, 16, signed=True) == -32768
    assert get_bits(b"\x0e", 1, 3, signed=True) == -1
