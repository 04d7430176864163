"""PDO mapping/assignment objects, remapping in PREOP, size checks, and the codec."""

from __future__ import annotations

import struct
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gtecat.drives.abort import SdoAbort, SdoAbortCode
from gtecat.drives.coe import SdoClient
from gtecat.drives.drive import Cia402Drive
from gtecat.drives.od import ObjectDictionary, PdoDir
from gtecat.drives.pdo_mapping import PdoMapping, pack_entry, unpack_entry
from gtecat.drives.slave import AlState, AlStatusCode
from gtecat.eni.bits import get_bits, set_bits
from gtecat.eni.model import Direction, Identity, Pdo, PdoEntry
from tests.conftest import examples
from tests.drives.test_drive import Rig


def test_entry_packing() -> None:
    assert pack_entry(0x6040, 0, 16) == 0x60400010
    assert unpack_entry(0x607A0020) == (0x607A, 0, 32)


def test_codec_is_compiled_again_only_when_the_mapping_changes() -> None:
    rig = Rig(op=False)
    d = rig.drive
    first = d.codec
    assert d.mapping.compile() is first  # the same entries: the same (immutable) codec
    d.request_state(AlState.PREOP)
    sdo = rig.sdo
    sdo.download(0x1C12, 0, b"\x00")
    sdo.download(0x1601, 0, b"\x00")
    sdo.download(0x1601, 1, struct.pack("<I", 0x60400010))
    sdo.download(0x1601, 0, b"\x01")
    sdo.download(0x1C12, 1, struct.pack("<H", 0x1601))
    sdo.download(0x1C12, 0, b"\x01")
    d.expected_sizes = d.pdo_sizes()
    assert d.request_state(AlState.SAFEOP) == AlStatusCode.NO_ERROR
    assert d.codec is not first and d.codec.rx_bits == 16
    var = d.od.find(0x6040, 0)
    assert var is not None and d.codec.rx_vars == [var]


def test_remap_in_preop_then_size_check() -> None:
    rig = Rig(op=False)
    d = rig.drive
    d.request_state(AlState.PREOP)
    sdo = rig.sdo
    sdo.download(0x1C12, 0, b"\x00")
    sdo.download(0x1601, 0, b"\x00")
    for k, entry in enumerate((0x60400010, 0x60FF0020, 0x60600008), start=1):
        sdo.download(0x1601, k, struct.pack("<I", entry))
    sdo.download(0x1601, 0, b"\x03")
    sdo.download(0x1C12, 1, struct.pack("<H", 0x1601))
    sdo.download(0x1C12, 0, b"\x01")
    assert d.pdo_sizes()[0] == 56
    d.expected_sizes = (48, d.pdo_sizes()[1])  # the ENI expects something else
    assert d.request_state(AlState.SAFEOP) == AlStatusCode.INVALID_OUTPUT_CONFIGURATION
    assert d.al_state == AlState.PREOP and d.al_error
    d.expected_sizes = (56, 1)
    assert d.request_state(AlState.SAFEOP) == AlStatusCode.INVALID_INPUT_CONFIGURATION
    d.expected_sizes = d.pdo_sizes()
    assert d.request_state(AlState.SAFEOP) == AlStatusCode.NO_ERROR
    assert len(d.rx) == 7
    assert d.request_state(AlState.OP) == AlStatusCode.NO_ERROR
    d.rx[:] = struct.pack("<Hib", 0x06, 12345, 9)
    d.step(0, 1_000_000)
    ch = d.channel(0)
    assert (ch.controlword, ch.target_velocity, ch.mode_req) == (6, 12345, 9)
    # mapping objects are frozen outside PREOP
    with pytest.raises(SdoAbort) as e:
        sdo.download(0x1C12, 0, b"\x00")
    assert e.value.code == SdoAbortCode.CANNOT_TRANSFER_DEVICE_STATE


def test_acontis_fixture_init_commands_apply(shared_fixtures: Path) -> None:
    from gtecat.eni.reader import read_eni

    cfg = read_eni(shared_fixtures / "eni" / "acontis_training_slaves.xml")
    for slave in cfg.slaves:
        d = Cia402Drive(
            slave.position,
            slave.name,
            slave.identity,
            rx_pdos=slave.rx_pdos,
            tx_pdos=slave.tx_pdos,
        )
        d.expected_sizes = (slave.out_bits, slave.in_bits)
        assert d.request_state(AlState.PREOP) == AlStatusCode.NO_ERROR
        client = SdoClient(d.mailbox)
        for cmd in slave.init_cmds:
            assert "PS" in cmd.transitions
            client.download(cmd.index, cmd.subindex, cmd.data, cmd.complete_access)
        assert d.pdo_sizes() == (slave.out_bits, slave.in_bits)
        assert d.request_state(AlState.SAFEOP) == AlStatusCode.NO_ERROR
        assert client.upload(0x1C12, 0, complete_access=True)[:6] == bytes.fromhex("020000160116")
        # the fixed PDOs of the ENI are read-only
        d.request_state(AlState.PREOP)
        with pytest.raises(SdoAbort) as e:
            client.download(0x1600, 0, b"\x00")
        assert e.value.code == SdoAbortCode.WRITE_OF_READ_ONLY


def test_bit_entries_and_gaps_of_the_generator_slave() -> None:
    """acontis 'Generator': 16 + 1 + 1 + 14-bit gap + 32 bits per RxPDO."""
    entries = (
        PdoEntry(0x7000, 1, 16),
        PdoEntry(0x7000, 2, 1),
        PdoEntry(0x7000, 3, 1),
        PdoEntry(0, 0, 14),
        PdoEntry(0x7000, 5, 32),
    )
    tx = Pdo(0x1A00, Direction.IN, (PdoEntry(0x6000, 1, 32), PdoEntry(0x6000, 2, 1)))
    d = Cia402Drive(
        0, "gen", Identity(1, 2), rx_pdos=[Pdo(0x1600, Direction.OUT, entries)], tx_pdos=[tx]
    )
    assert d.pdo_sizes() == (64, 33)
    for s in (AlState.PREOP, AlState.SAFEOP, AlState.OP):
        d.request_state(s)
    d.rx[:] = struct.pack("<HBBI", 0xABCD, 0b10, 0xFF, 0xDEADBEEF)
    d.step(0, 1_000_000)
    od = d.od
    assert od.find(0x7000, 1).value == 0xABCD
    assert od.find(0x7000, 2).value == 0 and od.find(0x7000, 3).value == 1
    assert od.find(0x7000, 5).value == 0xDEADBEEF
    od.find(0x6000, 1).value = 0x01020304
    od.find(0x6000, 2).value = 1
    d.step(1_000_000, 1_000_000)
    assert bytes(d.tx) == b"\x04\x03\x02\x01\x01"


@settings(max_examples=examples(80, 20), deadline=None)
@given(
    st.lists(
        st.tuples(st.booleans(), st.sampled_from([1, 2, 3, 5, 7, 8, 12, 16, 24, 32])),
        min_size=1,
        max_size=12,
    ),
    st.data(),
)
def test_codec_round_trips_any_layout(layout: list[tuple[bool, int]], data: st.DataObject) -> None:
    od = ObjectDictionary()
    rx_entries, tx_entries = [], []
    for k, (gap, bits) in enumerate(layout, start=1):
        if gap:
            rx_entries.append(PdoEntry(0, 0, bits))
            tx_entries.append(PdoEntry(0, 0, bits))
        else:
            rx_entries.append(PdoEntry(0x2000, k, bits))
            tx_entries.append(PdoEntry(0x2100, k, bits))
    mapping = PdoMapping(
        od,
        [Pdo(0x1600, Direction.OUT, tuple(rx_entries))],
        [Pdo(0x1A00, Direction.IN, tuple(tx_entries))],
    )
    codec = mapping.compile()
    total = sum(b for _, b in layout)
    assert (codec.rx_bits, codec.tx_bits) == (total, total) == mapping.sizes()
    # decode: random bytes -> every entry equals an independent bit read
    raw = bytearray(data.draw(st.binary(min_size=codec.rx_bytes, max_size=codec.rx_bytes)))
    codec.decode(raw)
    off = 0
    for k, (gap, bits) in enumerate(layout, start=1):
        if not gap:
            assert od.find(0x2000, k).value == get_bits(raw, off, bits)
        off += bits
    # encode: random values -> bytes an independent bit writer produces
    expected = bytearray(codec.tx_bytes)
    off = 0
    for k, (gap, bits) in enumerate(layout, start=1):
        if not gap:
            value = data.draw(st.integers(0, (1 << bits) - 1))
            od.find(0x2100, k).value = value
            set_bits(expected, off, bits, value)
        off += bits
    out = bytearray(codec.tx_bytes)
    codec.encode(out)
    assert out == expected


def test_codec_wraps_out_of_range_values_like_c() -> None:
    od = ObjectDictionary()
    od.add_var(0x6064, "pos", 0x0004, pdo=PdoDir.TX, getter=lambda: 2**31 + 5)  # INT32
    od.add_var(0x6077, "torque", 0x0003, pdo=PdoDir.TX, getter=lambda: 12.7)  # INT16
    tx = Pdo(0x1A00, Direction.IN, (PdoEntry(0x6064, 0, 32), PdoEntry(0x6077, 0, 16)))
    codec = PdoMapping(od, [], [tx]).compile()
    buf = bytearray(6)
    codec.encode(buf)
    assert struct.unpack("<ih", buf) == (-(2**31) + 5, 12)


def test_assignment_refusals() -> None:
    rig = Rig(op=False)
    rig.drive.request_state(AlState.PREOP)
    sdo = rig.sdo
    sdo.download(0x1C12, 0, b"\x00")
    with pytest.raises(SdoAbort) as e:
        sdo.download(0x1C12, 1, struct.pack("<H", 0x1A00))  # a TxPDO in the RxPDO assignment
    assert e.value.code == SdoAbortCode.VALUE_RANGE_EXCEEDED
    with pytest.raises(SdoAbort) as e:
        sdo.download(0x1C12, 0, b"\x09")  # more than the 8 slots
    assert e.value.code == SdoAbortCode.VALUE_TOO_HIGH
    sdo.download(0x1C12, 1, b"\x00\x00")
    with pytest.raises(SdoAbort) as e:
        sdo.download(0x1C12, 0, b"\x01")  # slot 1 is empty
    assert e.value.code == SdoAbortCode.PARAMETER_INCOMPATIBILITY
    # lenient: an unknown RxPDO index gets an empty mapping object
    sdo.download(0x1C12, 1, struct.pack("<H", 0x1700))
    sdo.download(0x1C12, 0, b"\x01")
    assert 0x1700 in rig.drive.od and rig.drive.pdo_sizes()[0] == 0


def test_real32_and_bool_off_the_byte_grid() -> None:
    od = ObjectDictionary()
    od.add_var(0x2000, "flag", 0x0001, pdo=PdoDir.RX | PdoDir.TX)  # BOOL
    od.add_var(0x2001, "real", 0x0008, pdo=PdoDir.RX | PdoDir.TX)  # REAL32
    entries = (PdoEntry(0x2000, 0, 1), PdoEntry(0x2001, 0, 32))
    codec = PdoMapping(
        od, [Pdo(0x1600, Direction.OUT, entries)], [Pdo(0x1A00, Direction.IN, entries)]
    ).compile()
    od.find(0x2000, 0).value, od.find(0x2001, 0).value = 1, 1.5
    buf = bytearray(5)
    codec.encode(buf)
    assert (
        int.from_bytes(buf, "little") == 1 | int.from_bytes(struct.pack("<f", 1.5), "little") << 1
    )
    od.find(0x2000, 0).value, od.find(0x2001, 0).value = 0, 0.0
    codec.decode(buf)
    assert (od.find(0x2000, 0).value, od.find(0x2001, 0).value) == (1, 1.5)
