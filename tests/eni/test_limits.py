"""Hostile numbers and encodings are refused at the reader (issue 12 item 6, eni/limits.py).

Every case an outside fuzzer found is a regression test here: the reader raises
an EniError whose text names the file:line, the field and the legal range.
"""

from __future__ import annotations

import functools
import re
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gtecat.eni.errors import EniError
from gtecat.eni.layout import build_layout
from gtecat.eni.limits import Limit, RangeError, cycle_ns_from_us
from gtecat.eni.numbers import MAX_DIGITS, TooLong, parse_int
from gtecat.eni.reader import parse_eni
from tests.conftest import examples

from .googol_text import GSlave, render
from .snippets import area, eni, entry, image, line_of, pdo, process_data, servo_slave, slave

HUGE_HEX = "#x" + "F" * 4000
HUGE_DEC = "9" * 5000


def _refused(text: str | bytes, line: int, *needles: str, source: str = "bad.eni") -> EniError:
    """Parse, expect an EniError at ``line`` whose text holds ``needles`` (field, range)."""
    with pytest.raises(EniError) as info:
        parse_eni(text, source)
    err = info.value
    assert err.line == line, str(err)
    assert str(err).startswith(f"{source}:{line}: "), str(err)
    for n in needles:
        assert n in str(err), (n, str(err))
    assert len(str(err)) < 400, "a hostile value must not be echoed whole"
    return err


# --- cycle time -----------------------------------------------------------------------------
CYCLE_RANGE_US = "31.25..1000000 us"
CYCLE_RANGE_NS = "31250..1000000000"


def _xml_cycle(value: str) -> str:
    return eni(servo_slave()).replace("<CycleTime>1000<", f"<CycleTime>{value}<")


@pytest.mark.parametrize(
    "value", ["0.001", "1e999", "0", "-1000", "31.2", "1000001", "nan", "Infinity", "1e-999"]
)
def test_xml_cycle_time_out_of_range(value: str) -> None:
    text = _xml_cycle(value)
    _refused(text, line_of(text, "<CycleTime>"), "CycleTime", value, CYCLE_RANGE_US)


@pytest.mark.parametrize(
    ("value", "ns"),
    [
        ("31.25", 31_250),
        ("62.5", 62_500),
        ("1e3", 1_000_000),
        ("#x3E8", 1_000_000),
        ("1000000", 1_000_000_000),
        (" 250 ", 250_000),
    ],
)
def test_xml_cycle_time_in_range(value: str, ns: int) -> None:
    assert parse_eni(_xml_cycle(value), "ok.eni").cycle_time_ns == ns


def test_xml_cycle_time_not_a_number() -> None:
    text = _xml_cycle("fast")
    _refused(text, line_of(text, "<CycleTime>"), "'fast'", CYCLE_RANGE_US)


def _googol_cycle(value: str) -> str:
    text = render([GSlave("IO", 1, 2, [[(0x7000, 1, 8)]], [])])
    return text.replace(
        "cycletime0,Section=DWORD,Value=1000000", f"cycletime0,Section=DWORD,Value={value}"
    )


@pytest.mark.parametrize("value", ["-1000", "-1", "1", "30000", "1000000001", HUGE_DEC])
def test_googol_cycle_time_out_of_range(value: str) -> None:
    """A negative cycletime0 made the first GT call spin forever."""
    text = _googol_cycle(value)
    err = _refused(
        text, line_of(text, "cycletime0"), "cycletime0", CYCLE_RANGE_NS, "0 for not given"
    )
    assert err.slave == 0


def test_googol_cycle_time_zero_is_not_given() -> None:
    assert parse_eni(_googol_cycle("0"), "ok.eni").cycle_time_ns is None
    assert parse_eni(_googol_cycle("31250"), "ok.eni").cycle_time_ns == 31_250


ONE_SLAVE = '[[slave]]\nkind = "servo"\n'


def test_topology_cycle_time_uses_the_same_range() -> None:
    from gtecat.eni.topology import parse_topology

    with pytest.raises(EniError, match=r"31\.25\.\.1000000 us"):
        parse_topology(f"cycle_time_us = 1e-3\n{ONE_SLAVE}")
    assert parse_topology(f"cycle_time_us = 62.5\n{ONE_SLAVE}").cycle_time_ns == 62_500


# --- the XML declaration's encoding ------------------------------------------------------------
def _declared(name: str, bom: bytes = b"") -> bytes:
    return bom + eni(servo_slave()).replace('encoding="utf-8"', f'encoding="{name}"').encode()


@pytest.mark.parametrize("name", ["rot13", "base64", "zlib", "hex", "uu"])
def test_non_text_encoding_is_refused(name: str) -> None:
    _refused(_declared(name), 1, f"not a text encoding: {name!r}", "UTF-8")


@pytest.mark.parametrize("name", ["nope", "", "a\x00b", "x" * 300])
def test_unknown_encoding_is_refused(name: str) -> None:
    _refused(_declared(name), 1, "unknown encoding")


def test_a_bom_decides_over_the_declaration() -> None:
    assert len(parse_eni(_declared("rot13", b"\xef\xbb\xbf"), "ok.eni").slaves) == 1
    text = eni(servo_slave()).replace('encoding="utf-8"', 'encoding="GB2312"')
    for codec in ("utf-16", "utf-32"):
        assert len(parse_eni(text.encode(codec), "ok.eni").slaves) == 1


def test_codecs_that_fail_without_a_position() -> None:
    _refused(_declared("undefined"), 1, "not valid undefined")
    _refused(_declared("punycode"), 1, "not valid punycode")


# --- identity and addresses ------------------------------------------------------------------
IDENTITY_RANGE = "0x0..0xFFFFFFFF"


@pytest.mark.parametrize("tag", ["VendorId", "ProductCode", "RevisionNo", "SerialNo"])
@pytest.mark.parametrize("value", [str(2**32), "-1", HUGE_HEX, HUGE_DEC, "#x100000000"])
def test_identity_fields_are_32_bits(tag: str, value: str) -> None:
    extra = f"<{tag}>{value}</{tag}>\n"
    kwargs = {"vendor": "", "info_extra": extra} if tag == "VendorId" else {"info_extra": extra}
    if tag == "ProductCode":
        kwargs["product"] = ""
    text = eni(slave("S", "", **kwargs))
    err = _refused(text, line_of(text, f"<{tag}>"), tag, IDENTITY_RANGE)
    assert err.slave == 0


def test_identity_2_32_minus_1_is_accepted() -> None:
    cfg = parse_eni(eni(slave("S", "", vendor="#xFFFFFFFF", product="4294967295")), "ok.eni")
    assert cfg.slaves[0].identity.vendor_id == cfg.slaves[0].identity.product_code == 2**32 - 1


@pytest.mark.parametrize("value", [-1, 65536, 2**64])
def test_phys_addr_is_16_bits(value: int) -> None:
    text = eni(slave("S", "", phys=value))
    _refused(text, line_of(text, "<PhysAddr>"), "PhysAddr", "0..65535")


def test_auto_inc_addr_signed_or_unsigned() -> None:
    minus_one = eni(slave("S", "", info_extra="<AutoIncAddr>-1</AutoIncAddr>\n"))
    assert parse_eni(minus_one, "ok.eni").slaves[0].auto_inc_addr == 0xFFFF
    text = eni(slave("S", "", info_extra="<AutoIncAddr>65536</AutoIncAddr>\n"))
    _refused(text, line_of(text, "<AutoIncAddr>"), "AutoIncAddr", "-32768..65535")


# --- object addresses, bit lengths, sync managers ----------------------------------------------
def _one_entry(
    index: str = "#x7000", sub: str = "1", bits: str = "8", pdo_index: str = "#x1600"
) -> str:
    e = f"<Entry><Index>{index}</Index><SubIndex>{sub}</SubIndex><BitLen>{bits}</BitLen></Entry>\n"
    return eni(slave("S", process_data(area("Send", 0, 8) + pdo("RxPdo", pdo_index, e, sm=2))))


@pytest.mark.parametrize(
    ("kwargs", "needle", "field", "legal"),
    [
        ({"sub": "256"}, "<SubIndex>", "SubIndex", "0..255"),
        ({"sub": "-1"}, "<SubIndex>", "SubIndex", "0..255"),
        ({"index": "#x10000"}, "<Entry>", "Index", "0x0..0xFFFF"),
        ({"index": HUGE_HEX}, "<Entry>", "Index", "0x0..0xFFFF"),
        ({"bits": "0"}, "<Entry>", "BitLen", "1..524280"),
        ({"bits": str(2**64)}, "<Entry>", "BitLen", "1..524280"),
        ({"pdo_index": "#x10000"}, "<Index>#x10000", "Index", "0x0..0xFFFF"),
    ],
)
def test_entry_fields(kwargs: dict[str, str], needle: str, field: str, legal: str) -> None:
    text = _one_entry(**kwargs)
    _refused(text, line_of(text, needle), field, legal)


def test_sync_manager_numbers() -> None:
    e = entry("#x7000", 1, 8)
    text = eni(slave("S", process_data(area("Send", 0, 8) + pdo("RxPdo", "#x1600", e, sm=16))))
    _refused(text, line_of(text, "<RxPdo"), "Sm 16", "0..15")
    sm = f"<Sm{'9' * 5000}><Type>Outputs</Type><Pdo>#x1600</Pdo></Sm{'9' * 5000}>\n"
    text = eni(slave("S", process_data(area("Send", 0, 8) + sm + pdo("RxPdo", "#x1600", e))))
    _refused(text, line_of(text, "<Sm9"), "sync manager", "0..15")
    sm = "<Sm2><Type>Outputs</Type><Pdo>#x1600</Pdo>\n<Pdo>#x10000</Pdo></Sm2>\n"
    text = eni(slave("S", process_data(area("Send", 0, 8) + sm + pdo("RxPdo", "#x1600", e))))
    _refused(text, line_of(text, "<Pdo>#x10000"), "PDO index", "0x0..0xFFFF")


def test_init_cmd_fields() -> None:
    def cmd(body: str) -> str:
        return (
            "<Mailbox><CoE><InitCmds>\n<InitCmd><Transition>PS</Transition>"
            f"{body}</InitCmd>\n</InitCmds></CoE></Mailbox>\n"
        )

    for body, field, legal in [
        ("<Index>#x10000</Index>", "Index", "0x0..0xFFFF"),
        ("<Index>#x1C12</Index><SubIndex>256</SubIndex>", "SubIndex", "0..255"),
        ("<Index>1</Index><Timeout>-5</Timeout>", "Timeout", "0..2147483647"),
        ("<Index>1</Index><Ccs>3</Ccs>", "Ccs 3", "1..2"),
    ]:
        text = eni(slave("S", cmd(body)))
        _refused(text, line_of(text, "<InitCmd>"), field, legal)


# --- the logical images: sizes and offsets in the 32-bit address space ------------------------
def test_byte_size_2_64_is_refused() -> None:
    text = eni(servo_slave(), image("", "", 2**64, 16))
    _refused(text, line_of(text, "<ByteSize>"), "ByteSize", "0..4294967296")


def test_area_beyond_the_logical_address_space() -> None:
    text = eni(servo_slave(start_out=2**35))
    _refused(text, line_of(text, "<Send>"), "BitStart", "0..34359738367")
    text = eni(servo_slave(start_out=2**35 - 16))
    _refused(text, line_of(text, "<Send>"), "Send bits", "32-bit logical address space")


@pytest.mark.parametrize(("offs", "size"), [(-8, 8), (2**40, 8), (2**35 - 4, 8), (0, -1)])
def test_variable_offsets(offs: int, size: int) -> None:
    var = f"<Variable><Name>x</Name><BitSize>{size}</BitSize><BitOffs>{offs}</BitOffs></Variable>\n"
    text = eni(servo_slave(), image("", var))
    _refused(text, line_of(text, "<Variable>"), "logical address space")


# --- the Googol INI -----------------------------------------------------------------------------
SERVO = GSlave(
    "Servo",
    0x705,
    0x4010,
    [[(0x6040, 0, 16)]],
    [[(0x6041, 0, 16)]],
    servo=True,
    nservo=1,
    start_sdos=[(0x6060, 0, 1, 8)],
)


def _g(old: str, new: str) -> str:
    text = render([SERVO])
    assert old in text, old
    return text.replace(old, new, 1)


@pytest.mark.parametrize(
    ("old", "new", "field", "legal"),
    [
        ("vid,Section=HEX,Value=0x705", "vid,Section=HEX,Value=0x100000000", "vid", IDENTITY_RANGE),
        (
            "vid,Section=HEX,Value=0x705",
            "vid,Section=HEX,Value=0x" + "f" * 4000,
            "vid",
            IDENTITY_RANGE,
        ),
        ("pcode,Section=HEX,Value=0x4010", "pcode,Section=HEX,Value=-1", "pcode", IDENTITY_RANGE),
        ("nservo,Section=DWORD,Value=1", "nservo,Section=DWORD,Value=9", "nservo", "0..8"),
        ("nservo,Section=DWORD,Value=1", "nservo,Section=DWORD,Value=-1", "nservo", "0..8"),
        (
            "nservo,Section=DWORD,Value=1",
            f"nservo,Section=DWORD,Value={HUGE_DEC}",
            "nservo",
            "0..8",
        ),
        ("type,Section=DWORD,Value=1", "type,Section=DWORD,Value=7", "type", "0..1"),
        (
            "slavenum,Section=DWORD,Value=1",
            "slavenum,Section=DWORD,Value=-1",
            "slavenum",
            "0..65535",
        ),
        (
            "position,Section=DWORD,Value=0",
            "position,Section=DWORD,Value=65535",
            "position",
            "0..65534",
        ),
        # a negative PDO count used to switch the count check off
        (
            "Value=3,Section=DWORD,Value=2,Section=DWORD,Value=1",
            "Value=3,Section=DWORD,Value=2,Section=DWORD,Value=-1",
            "PDO count",
            "0..255",
        ),
        ("Value=3,Section=DWORD,Value=2", "Value=3,Section=DWORD,Value=7", "direction", "1..2"),
        (
            "syncitem,Section=DWORD,Value=3",
            "syncitem,Section=DWORD,Value=16",
            "sync manager",
            "0..15",
        ),
        (
            "pdoitem,Section=HEX,Value=0x1600,Section=DWORD,Value=1",
            "pdoitem,Section=HEX,Value=0x1600,Section=DWORD,Value=256",
            "entry count",
            "0..255",
        ),
        (
            "pdoitem,Section=HEX,Value=0x1600",
            "pdoitem,Section=HEX,Value=0x10000",
            "PDO index",
            "0x0..0xFFFF",
        ),
        (
            "Value=0x6040,Section=DWORD,Value=0,Section=DWORD,Value=16,Section=DWORD,Value=1",
            "Value=0x6040,Section=DWORD,Value=0,Section=DWORD,Value=16,Section=DWORD,Value=2",
            "enabled",
            "0..1",
        ),
        (
            "entryitem,Section=HEX,Value=0x6040,Section=DWORD,Value=0,Section=DWORD,Value=16",
            "entryitem,Section=HEX,Value=0x6040,Section=DWORD,Value=0,Section=DWORD,Value=0",
            "bit length",
            "1..524280",
        ),
        (
            "entryitem,Section=HEX,Value=0x6040,Section=DWORD,Value=0",
            "entryitem,Section=HEX,Value=0x6040,Section=DWORD,Value=256",
            "subindex",
            "0..255",
        ),
        (
            "mapitem,Section=HEX,Value=0x6040",
            f"mapitem,Section=HEX,Value={HUGE_HEX}",
            "index",
            "0x0..0xFFFF",
        ),
        (
            "startitem,Section=HEX,Value=0x6060,Section=DWORD,Value=0,Section=DWORD,Value=1",
            "startitem,Section=HEX,Value=0x6060,Section=DWORD,Value=0,Section=DWORD,Value=9",
            "size",
            "1..8",
        ),
        # the value used to be cut to its size silently
        (
            "Section=DWORD,Value=1,Section=HEX,Value=0x8",
            "Section=DWORD,Value=1,Section=HEX,Value=0x100",
            "value",
            "-128..255",
        ),
    ],
)
def test_googol_fields(old: str, new: str, field: str, legal: str) -> None:
    text = _g(old, new)
    _refused(text, line_of(text, new[:40]), field, legal, source="Gecat.eni")


def test_googol_start_sdo_value_signed_or_unsigned() -> None:
    text = _g(
        "Section=DWORD,Value=1,Section=HEX,Value=0x8", "Section=DWORD,Value=1,Section=HEX,Value=-1"
    )
    assert parse_eni(text, "ok.eni").slaves[0].init_cmds[0].data == b"\xff"


def test_googol_sync_section_number() -> None:
    text = _g("[slave_sync2_PDO]\n", f"[slave_sync{'9' * 5000}_PDO]\n")
    _refused(text, line_of(text, "[slave_sync999"), "sync manager", "0..15", source="Gecat.eni")


def test_googol_non_integer_for_an_integer_field() -> None:
    text = _g("nservo,Section=DWORD,Value=1", "nservo,Section=STRING,Value=one")
    _refused(text, line_of(text, "nservo"), "nservo 'one' is not an integer", "0..8")


# --- the helpers ------------------------------------------------------------------------------
def test_parse_int_refuses_more_digits_than_any_field_before_converting() -> None:
    with pytest.raises(TooLong):
        parse_int("1" * (MAX_DIGITS + 1))
    assert parse_int("0" * 5000 + "7") == 7  # leading zeros are not significant
    for bad in ("--5", "1e3", "0x", "+", "٣"):
        with pytest.raises(ValueError):
            parse_int(bad)


def test_limit_messages_name_the_field_and_the_range() -> None:
    lim = Limit(0, 0xFFFF, "a 16-bit thing", hex=True)
    with pytest.raises(RangeError, match=r"^Thing 0x10000 is out of range: legal is 0x0\.\.0xFFFF"):
        lim.parse("0x10000", "Thing")
    assert lim.parse("#xFFFF", "Thing") == 0xFFFF
    with pytest.raises(RangeError, match=r"\(4002 characters\)"):
        lim.parse(HUGE_HEX, "Thing")
    with pytest.raises(RangeError):
        cycle_ns_from_us(True, "cycle")


# --- property: mutated numbers of real files give a layout or an EniError, nothing else --------
_ROOT = Path(__file__).resolve().parents[2]
_SHARED = _ROOT.parent / "shared" / "fixtures"
_FILES = sorted(
    [
        *(_ROOT / "examples").glob("*.eni"),
        *(_ROOT / "tests" / "eni" / "data").glob("*.eni"),
        *_SHARED.glob("*/*.eni"),
        *_SHARED.glob("*/*.xml"),
    ]
)
_TEXTS = {p.name: p.read_text(encoding="utf-8", errors="surrogateescape") for p in _FILES}
# numbers in XML element text and attributes, and in Googol ``Section=<int type>,Value=`` pairs
_XML_NUMBER = re.compile(
    r'(?<=[>"])\s*([-+]?(?:#x[0-9A-Fa-f]+|0x[0-9A-Fa-f]+|\d+(?:\.\d+)?))\s*(?=[<"])'
)
_INI_NUMBER = re.compile(r"Section=(?:HEX|DWORD|WORD|BYTE|INT)\s*,\s*Value=([^,\r\n]*)", re.I)
_EDGES = [0, -1, 1, 255, 256, 0xFFFF, 0x10000, 2**31, 2**32 - 1, 2**32, 2**35, 2**64, -(2**63)]
_HOSTILE = st.one_of(
    st.integers(-(2**70), 2**70).map(str),
    st.sampled_from(_EDGES).map(str),
    st.sampled_from(_EDGES).map(lambda v: f"#x{v:X}" if v >= 0 else f"-0x{-v:X}"),
    st.integers(20, 5000).map(lambda n: "9" * n),
    st.integers(17, 4000).map(lambda n: "#x" + "F" * n),
    st.integers(17, 4000).map(lambda n: "-0x" + "f" * n),
    st.sampled_from(["1e999", "-0", "0x", "nan", "0.001", "-1e9", "", "1.5", "+7"]),
)


_REGISTER_CMD = re.compile(r"<InitCmd>(?:(?!</InitCmd>).)*?<Ado>.*?</InitCmd>", re.S)


def _spans(text: str) -> list[tuple[int, int]]:
    """The numbers a reader reads: not those of register InitCmds (``Cmd``/``Adp``/``Ado``
    commands), which the reader skips, so a mutation there would test nothing."""
    if not text.lstrip().startswith("<"):
        return [m.span(1) for m in _INI_NUMBER.finditer(text)]
    skipped = [m.span() for m in _REGISTER_CMD.finditer(text)]
    return [
        m.span(1)
        for m in _XML_NUMBER.finditer(text)
        if not any(a <= m.start(1) < b for a, b in skipped)
    ]


@functools.cache
def _spans_of(name: str) -> list[tuple[int, int]]:
    return _spans(_TEXTS[name])


def test_the_property_sees_every_family() -> None:
    assert len(_TEXTS) >= 5
    assert all(len(_spans_of(name)) > 10 for name in _TEXTS)


@settings(
    max_examples=examples(300, 30), deadline=None, suppress_health_check=[HealthCheck.too_slow]
)
@given(st.sampled_from(sorted(_TEXTS)), st.data())
def test_mutated_numbers_give_a_layout_or_an_eni_error(name: str, data: st.DataObject) -> None:
    text = _TEXTS[name]
    spans = _spans_of(name)
    picks = data.draw(st.lists(st.sampled_from(spans), min_size=1, max_size=3, unique=True))
    for start, end in sorted(picks, reverse=True):
        text = text[:start] + data.draw(_HOSTILE) + text[end:]
    try:
        build_layout(parse_eni(text, name))
    except EniError as err:
        assert str(err).startswith(name)
        assert len(str(err)) < 1000, "a hostile value must not be echoed whole"
