"""SII EEPROM content (ETG.1000.6 5.4, ETG.2010): what masters read from word addresses."""

from __future__ import annotations

import itertools
import struct

import pytest
from hypothesis import given
from hypothesis import strategies as st

from gtecat.drives.esc.sii import (
    SII_SOFT_LIMIT,
    Category,
    CoeDetails,
    MailboxProtocol,
    SiiError,
    SiiInfo,
    SmType,
    build_sii,
    default_layout,
    iter_categories,
    parse_sii,
    sii_crc,
    sii_info_for,
)
from gtecat.eni.model import Direction, Identity, Pdo, PdoEntry
from tests.drives.esc.mini import MiniSlave


def _word(raw: bytes, w: int) -> int:
    return struct.unpack_from("<H", raw, 2 * w)[0]


def _dword(raw: bytes, w: int) -> int:
    return struct.unpack_from("<I", raw, 2 * w)[0]


def test_identity_and_mailbox_sit_where_soem_reads_them() -> None:
    slave = MiniSlave(0, "Servo X", Identity(0x47544543, 0x00010001, 7, 1234))
    raw = build_sii(sii_info_for(slave))
    assert _dword(raw, 0x08) == 0x47544543  # ECT_SII_MANUF
    assert _dword(raw, 0x0A) == 0x00010001  # ECT_SII_ID
    assert _dword(raw, 0x0C) == 7  # ECT_SII_REV
    assert _dword(raw, 0x0E) == 1234
    assert _dword(raw, 0x18) == (128 << 16) | 0x1000  # SM0 offset + size
    assert _dword(raw, 0x1A) == (128 << 16) | 0x1080  # SM1 offset + size
    assert _word(raw, 0x1C) == MailboxProtocol.COE | MailboxProtocol.FOE
    assert _word(raw, 0x3F) == 1  # version


def test_checksum_is_the_crc8_of_the_first_seven_words() -> None:
    raw = build_sii(sii_info_for(MiniSlave(0, "A", Identity(1, 2))))
    assert raw[14] == sii_crc(raw[:14])
    # a CRC without final XOR over data + CRC is zero
    assert sii_crc(raw[:15]) == 0


def test_crc_of_a_known_header() -> None:
    # CRC-8 x^8+x^2+x+1 preset FFh, not reflected, no final XOR: check value FBh
    # (the same polynomial preset 00h is CRC-8/SMBus with check value F4h)
    assert sii_crc(b"123456789") == 0xFB


def test_categories_end_with_ffff_and_string_one_is_the_name() -> None:
    slave = MiniSlave(0, "Drive Name", Identity(1, 2))
    raw = build_sii(sii_info_for(slave))
    cats = [c for c, _ in iter_categories(raw)]
    assert cats[:3] == [Category.GENERAL, Category.FMMU, Category.SYNCM]
    assert Category.STRINGS in cats and Category.TXPDO in cats and Category.RXPDO in cats
    strings = dict(iter_categories(raw))[Category.STRINGS]
    assert strings[1] == len("Drive Name") and strings[2:12] == b"Drive Name"
    general = dict(iter_categories(raw))[Category.GENERAL]
    assert general[5] == (
        CoeDetails.SDO | CoeDetails.SDO_INFO | CoeDetails.PDO_ASSIGN | CoeDetails.PDO_CONFIG
    )


def test_sm_layout_with_and_without_mailbox() -> None:
    with_mbx = default_layout(True, 6, 10)
    assert [s.type for s in with_mbx] == [
        SmType.MAILBOX_OUT,
        SmType.MAILBOX_IN,
        SmType.OUTPUTS,
        SmType.INPUTS,
    ]
    assert [(s.start, s.length, s.control) for s in with_mbx] == [
        (0x1000, 128, 0x26),
        (0x1080, 128, 0x22),
        (0x1100, 6, 0x64),
        (0x1400, 10, 0x20),
    ]
    plain = default_layout(False, 0, 2)
    assert [s.type for s in plain] == [SmType.OUTPUTS, SmType.INPUTS]
    assert plain[0].enable == 0 and plain[1].enable == 1
    for sms in (with_mbx, plain, default_layout(True, 400, 400, 256)):
        # mailboxes have one buffer, process data three
        spans = sorted(
            (s.start, s.start + (1 if s.type <= SmType.MAILBOX_IN else 3) * max(s.length, 1))
            for s in sms
        )
        assert all(a[1] <= b[0] for a, b in itertools.pairwise(spans)), spans


def test_pdo_categories_carry_the_slave_mapping_on_its_sm() -> None:
    slave = MiniSlave(0, "A", Identity(1, 2), rx_bits=48, tx_bits=80)
    info = parse_sii(build_sii(sii_info_for(slave)))
    assert [(p.index, p.sm) for p in info.rx_pdos] == [(0x1600, 2)]
    assert [(p.index, p.sm) for p in info.tx_pdos] == [(0x1A00, 3)]
    assert sum(p.bit_len for p in info.rx_pdos) == 48
    assert sum(p.bit_len for p in info.tx_pdos) == 80
    plain = parse_sii(build_sii(sii_info_for(MiniSlave(0, "B", Identity(1, 2), 2, 3, False))))
    assert [p.sm for p in plain.rx_pdos] == [0] and [p.sm for p in plain.tx_pdos] == [1]
    assert not plain.has_mailbox and plain.mailbox_protocols == 0


def test_mailbox_size_follows_the_slaves_sdo_server() -> None:
    slave = MiniSlave(0, "A", Identity(1, 2))
    slave.sdo = type("Sdo", (), {"mailbox_size": 256})()  # type: ignore[attr-defined]
    info = sii_info_for(slave)
    assert info.rx_mailbox == (0x1000, 256) and info.tx_mailbox == (0x1100, 256)


def test_a_slave_without_pdo_lists_gets_a_stand_in_of_the_right_size() -> None:
    class Bare(MiniSlave):
        rx_pdos = ()
        tx_pdos = ()

    slave = Bare(0, "bare", Identity(1, 2), 20, 9, False)
    slave.rx_pdos = slave.tx_pdos = ()
    info = sii_info_for(slave)
    assert sum(p.bit_len for p in info.rx_pdos) == 20
    assert sum(p.bit_len for p in info.tx_pdos) == 9


def test_too_many_names_are_dropped_to_stay_inside_a_masters_cache() -> None:
    entries = tuple(
        PdoEntry(0x6000 + k, 1, 8, f"a rather long entry name {k:04d}") for k in range(200)
    )
    info = SiiInfo(Identity(1, 2), "big", tx_pdos=(Pdo(0x1A00, Direction.IN, entries),))
    raw = build_sii(info)
    assert len(raw) <= SII_SOFT_LIMIT
    assert parse_sii(raw).name == "big"
    assert sum(p.bit_len for p in parse_sii(raw).tx_pdos) == 1600


def test_entries_wider_than_a_byte_count_are_refused() -> None:
    info = SiiInfo(
        Identity(1, 2), "x", tx_pdos=(Pdo(0x1A00, Direction.IN, (PdoEntry(1, 1, 300),)),)
    )
    with pytest.raises(SiiError):
        build_sii(info)


def test_malformed_content_raises_sii_error() -> None:
    raw = bytearray(build_sii(sii_info_for(MiniSlave(0, "A", Identity(1, 2)))))
    with pytest.raises(SiiError):
        parse_sii(bytes(raw[:140]))


names = st.text(st.characters(min_codepoint=32, max_codepoint=126), min_size=1, max_size=40)
entry = st.builds(
    PdoEntry,
    index=st.integers(0x1000, 0xFFFF),
    subindex=st.integers(0, 255),
    bit_len=st.integers(1, 64),
    name=names,
    data_type=st.sampled_from(["UINT", "DINT", "BOOL", "USINT", "UDINT", ""]),
)


@given(
    st.integers(0, 2**32 - 1),
    st.integers(0, 2**32 - 1),
    st.integers(0, 2**32 - 1),
    names,
    st.lists(entry, max_size=6),
    st.lists(entry, max_size=6),
    st.booleans(),
)
def test_build_parse_round_trip(vendor, product, revision, name, rx, tx, mailbox) -> None:
    layout = default_layout(mailbox, 8, 8)
    info = SiiInfo(
        Identity(vendor, product, revision),
        name,
        group="grp",
        mailbox_protocols=MailboxProtocol.COE if mailbox else MailboxProtocol(0),
        rx_mailbox=(layout[0].start, layout[0].length) if mailbox else (0, 0),
        tx_mailbox=(layout[1].start, layout[1].length) if mailbox else (0, 0),
        coe_details=CoeDetails.SDO if mailbox else CoeDetails(0),
        sync_managers=layout,
        rx_pdos=(Pdo(0x1600, Direction.OUT, tuple(rx), "out", 2 if mailbox else 0),) if rx else (),
        tx_pdos=(Pdo(0x1A00, Direction.IN, tuple(tx), "in", 3 if mailbox else 1),) if tx else (),
    )
    back = parse_sii(build_sii(info))
    assert back.identity == info.identity
    assert back.name == name and back.group == "grp"
    assert back.sync_managers == info.sync_managers
    assert back.rx_mailbox == info.rx_mailbox and back.tx_mailbox == info.tx_mailbox
    for mine, theirs in ((info.rx_pdos, back.rx_pdos), (info.tx_pdos, back.tx_pdos)):
        assert [(e.index, e.subindex, e.bit_len, e.name) for p in mine for e in p.entries] == [
            (e.index, e.subindex, e.bit_len, e.name) for p in theirs for e in p.entries
        ]
        assert [p.sm for p in mine] == [p.sm for p in theirs]
    assert back.extra["checksum"] == back.extra["crc"]


# --- issue 16, item 5: the SII lists the mapping the slave really has ---------------------------
def test_a_drive_sii_lists_its_real_mapping_with_names() -> None:
    from tests.drives.esc.test_mailbox import drive_esc

    esc = drive_esc()
    info = parse_sii(bytes(esc.sii))
    rx = [(e.index, e.subindex, e.bit_len, e.name) for p in info.rx_pdos for e in p.entries]
    tx = [(e.index, e.subindex, e.bit_len) for p in info.tx_pdos for e in p.entries]
    assert rx == [(0x6040, 0, 16, "Controlword"), (0x607A, 0, 32, "Target position")]
    assert tx == [(0x6041, 0, 16), (0x6064, 0, 32), (0x60FD, 0, 32)]
    assert [p.index for p in info.rx_pdos] == [0x1600] and info.rx_pdos[0].sm == 2
    assert info.coe_details & CoeDetails.SDO_INFO
