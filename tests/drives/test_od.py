"""The object dictionary: types, access, ranges, AL-state rules, hooks, complete access."""

from __future__ import annotations

import struct

import pytest
from hypothesis import given
from hypothesis import strategies as st

from gtecat.drives.abort import SdoAbort, SdoAbortCode
from gtecat.drives.od import (
    PREOP_ONLY,
    TYPE_INFO,
    Access,
    DataType,
    ObjectCode,
    ObjectDictionary,
    PdoDir,
    Variable,
)
from gtecat.drives.slave import AlState


def make_od() -> tuple[ObjectDictionary, dict[str, int]]:
    od = ObjectDictionary()
    store = {"x": 7}
    od.add_var(0x2000, "u16", DataType.UINT16, default=0x1234)
    od.add_var(0x2001, "i8 ranged", DataType.INT8, low=-10, high=10)
    od.add_var(0x2002, "ro", DataType.UINT32, Access.RO, default=99)
    od.add_var(0x2003, "wo", DataType.UINT32, Access.WO)
    od.add_var(0x2004, "const", DataType.UINT8, Access.CONST, default=5)
    od.add_var(0x2005, "real", DataType.REAL32, default=1.5)
    od.add_var(0x2006, "string", DataType.VISIBLE_STRING, default="hello", max_size=16)
    od.add_var(0x2007, "bool", DataType.BOOL)
    od.add_var(0x2008, "preop only", DataType.UINT16, write_states=PREOP_ONLY)
    od.add_var(0x2009, "enum", DataType.INT8, allowed=[1, 3, 8])
    od.add_var(
        0x200A,
        "hooked",
        DataType.INT32,
        getter=lambda: store["x"],
        setter=lambda v: store.__setitem__("x", v),
    )
    od.add_var(0x200B, "u64", DataType.UINT64, default=2**63)
    od.add_record(
        0x3000,
        "record",
        [
            Variable(0x3000, 1, "a", DataType.UINT16, default=1),
            Variable(0x3000, 2, "b", DataType.INT32, default=-2),
            Variable(0x3000, 3, "c", DataType.UINT8, Access.RO, default=3),
        ],
    )
    od.add_record(
        0x3001, "strings", [Variable(0x3001, 1, "s", DataType.VISIBLE_STRING, default="x")]
    )
    return od, store


def code_of(fn, *args, **kw) -> int:  # type: ignore[no-untyped-def]
    with pytest.raises(SdoAbort) as e:
        fn(*args, **kw)
    return e.value.code


def test_upload_encodes_little_endian_per_type() -> None:
    od, _ = make_od()
    assert od.upload(0x2000, 0) == b"\x34\x12"
    assert od.upload(0x2002, 0) == struct.pack("<I", 99)
    assert od.upload(0x2004, 0) == b"\x05"
    assert od.upload(0x2005, 0) == struct.pack("<f", 1.5)
    assert od.upload(0x2006, 0) == b"hello"
    assert od.upload(0x200B, 0) == struct.pack("<Q", 2**63)
    assert od.upload(0x3000, 0) == b"\x03"
    assert od.upload(0x3000, 2) == struct.pack("<i", -2)


def test_download_and_refusals() -> None:
    od, store = make_od()
    od.download(0x2000, 0, b"\xff\xff")
    assert od.upload(0x2000, 0) == b"\xff\xff"
    od.download(0x2001, 0, b"\xf6")  # -10
    assert code_of(od.download, 0x2001, 0, b"\x0b") == SdoAbortCode.VALUE_TOO_HIGH
    assert code_of(od.download, 0x2001, 0, b"\xf5") == SdoAbortCode.VALUE_TOO_LOW
    assert code_of(od.download, 0x2002, 0, b"\0\0\0\0") == SdoAbortCode.WRITE_OF_READ_ONLY
    assert code_of(od.download, 0x2004, 0, b"\0") == SdoAbortCode.WRITE_OF_READ_ONLY
    assert code_of(od.upload, 0x2003, 0) == SdoAbortCode.READ_OF_WRITE_ONLY
    od.download(0x2003, 0, b"\1\0\0\0")
    assert code_of(od.download, 0x2000, 0, b"\0\0\0") == SdoAbortCode.LENGTH_TOO_HIGH
    assert code_of(od.download, 0x2000, 0, b"\0") == SdoAbortCode.LENGTH_TOO_LOW
    assert code_of(od.download, 0x2007, 0, b"\2") == SdoAbortCode.VALUE_RANGE_EXCEEDED
    assert code_of(od.download, 0x2009, 0, b"\2") == SdoAbortCode.VALUE_RANGE_EXCEEDED
    od.download(0x2009, 0, b"\3")
    assert code_of(od.upload, 0x4000, 0) == SdoAbortCode.OBJECT_DOES_NOT_EXIST
    assert code_of(od.upload, 0x2000, 1) == SdoAbortCode.SUBINDEX_DOES_NOT_EXIST
    assert code_of(od.download, 0x2006, 0, b"x" * 17) == SdoAbortCode.LENGTH_TOO_HIGH
    od.download(0x2006, 0, b"hi\0")
    assert od.find(0x2006, 0).value == "hi"
    od.download(0x200A, 0, struct.pack("<i", -5))
    assert store["x"] == -5 and od.upload(0x200A, 0) == struct.pack("<i", -5)


def test_al_state_rules() -> None:
    od, _ = make_od()
    od.download(0x2008, 0, b"\1\0", al_state=AlState.PREOP)
    for state in (AlState.SAFEOP, AlState.OP):
        err = code_of(od.download, 0x2008, 0, b"\1\0", al_state=state)
        assert err == SdoAbortCode.CANNOT_TRANSFER_DEVICE_STATE


def test_setter_abort_gets_the_entry_address() -> None:
    od = ObjectDictionary()

    def refuse(_v: int) -> None:
        raise SdoAbort(SdoAbortCode.CANNOT_TRANSFER_LOCAL_CONTROL, 0, 0)

    od.add_var(0x2100, "refuses", DataType.UINT8, setter=refuse)
    with pytest.raises(SdoAbort) as e:
        od.download(0x2100, 0, b"\1")
    assert (e.value.code, e.value.index, e.value.subindex) == (0x08000021, 0x2100, 0)


def test_complete_access_of_a_record() -> None:
    od, _ = make_od()
    assert od.upload(0x3000, 0, complete_access=True) == b"\x03\x00" + struct.pack("<HiB", 1, -2, 3)
    assert od.upload(0x3000, 1, complete_access=True) == struct.pack("<HiB", 1, -2, 3)
    od.download(0x3000, 1, struct.pack("<HiB", 10, -20, 3), complete_access=True)
    assert od.upload(0x3000, 2) == struct.pack("<i", -20)
    err = code_of(od.download, 0x3000, 1, struct.pack("<HiB", 1, 1, 4), complete_access=True)
    assert err == SdoAbortCode.WRITE_OF_READ_ONLY
    err = code_of(od.upload, 0x3000, 2, complete_access=True)
    assert err == SdoAbortCode.SUBINDEX_CANNOT_BE_WRITTEN
    err = code_of(od.upload, 0x3001, 0, complete_access=True)
    assert err == SdoAbortCode.COMPLETE_ACCESS_NOT_SUPPORTED
    err = code_of(od.download, 0x3000, 1, struct.pack("<HiBB", 1, 1, 3, 0), complete_access=True)
    assert err == SdoAbortCode.LENGTH_TOO_HIGH
    err = code_of(od.download, 0x3000, 1, b"\1\0\1", complete_access=True)
    assert err == SdoAbortCode.LENGTH_MISMATCH
    # complete access on a VAR is a plain access of subindex 0
    assert od.upload(0x2000, 0, complete_access=True) == od.upload(0x2000, 0)


def test_placeholder_objects() -> None:
    od = ObjectDictionary()
    var = od.placeholder(0x2222, 3, 16, PdoDir.RX)
    assert var.data_type is DataType.UINT16 and var.access is Access.RW and var.placeholder
    assert od.obj(0x2222).code is ObjectCode.RECORD
    assert od.upload(0x2222, 0) == b"\x03"
    od.download(0x2222, 3, b"\1\2")
    assert var.value == 0x0201
    tx = od.placeholder(0x2223, 0, 32, PdoDir.TX)
    assert tx.access is Access.RO


@given(
    st.sampled_from(
        [t for t in DataType if not TYPE_INFO[t].is_string and t is not DataType.REAL32]
    ),
    st.data(),
)
def test_integer_types_round_trip(dt: DataType, data: st.DataObject) -> None:
    info = TYPE_INFO[dt]
    value = data.draw(st.integers(int(info.low), int(info.high)))
    od = ObjectDictionary()
    od.add_var(0x2000, "v", dt)
    raw = Variable(0x2000, 0, "v", dt).encode(value)
    assert len(raw) == info.size
    od.download(0x2000, 0, raw)
    assert od.upload(0x2000, 0) == raw
    assert od.find(0x2000, 0).value == value


#: every entry of make_od, one missing object and one missing subindex
_ENTRIES = [(0x2000 + k, 0) for k in range(12)] + [(0x3000, k) for k in range(4)]
_ENTRIES += [(0x3001, 1), (0x4000, 0), (0x2000, 1)]


def _outcome(fn, *args):  # type: ignore[no-untyped-def]
    try:
        fn(*args)
    except SdoAbort as e:
        return (int(e.code), e.index, e.subindex, str(e))
    return "ok"


@given(
    st.sampled_from(_ENTRIES),
    st.sampled_from([1, 2, 4]),
    st.data(),
    st.sampled_from([AlState.PREOP, AlState.OP]),
)
def test_a_value_downloaded_is_its_bytes_downloaded(entry, size, data, state) -> None:  # type: ignore[no-untyped-def]
    """download_value(value, size) is download() of the value's little-endian bytes: the same
    abort (a guard's, a length's, a range's, a read-only entry's before its length) or the
    same value stored, whether the entry takes the value as it is or not."""
    value = data.draw(st.integers(-(1 << (8 * size - 1)), (1 << (8 * size)) - 1))
    index, sub = entry
    results = []
    for by_value in (False, True):
        od, store = make_od()

        def guard(var: Variable, al_state: AlState) -> None:
            if var.index == 0x2000 and al_state == AlState.OP:
                raise SdoAbort(SdoAbortCode.OBJECT_MAPPED_TO_RXPDO, var.index, var.subindex)

        od.download_guard = guard
        if by_value:
            got = _outcome(od.download_value, index, sub, value, size, state)
        else:
            raw = value.to_bytes(size, "little", signed=value < 0)
            got = _outcome(od.download, index, sub, raw, False, state)
        var = od.find(index, sub)
        held = None if var is None else var.get()
        raw = None if var is None else var.encode(held)  # (a REAL32's NaN: its bytes)
        results.append((got, raw, type(held), store["x"]))
    assert results[0] == results[1]
