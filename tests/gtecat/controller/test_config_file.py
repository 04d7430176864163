"""GT_LoadConfig's file reader (gtecat/controller/config_file.py, docs/config_file.md).

The vendor's ``*.cfg`` (the two real files in ``../shared/fixtures/googol``, a GTS-400 file
written here in ``data/`` and variants of it: CRLF, GBK comments, BOM, case), then
gtecat's earlier format, still read for one release.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gtecat.controller.config_file import (
    SCHEMA,
    Config,
    ConfigFileError,
    VendorConfig,
    integer,
    is_legacy,
    parse_config,
    parse_vendor,
    read_config,
)
from gtecat.controller.safety import StopInput
from gtecat.controller.scale import Scale
from tests.conftest import SHARED_FIXTURES, examples, needs_fixture

DATA = Path(__file__).parent / "data"
GTS400 = DATA / "gts400_4axis.cfg"
FIXTURES = ("smarthome_test.cfg", "coordinate_gtn_core1.cfg")


def fixture_text(name: str) -> str:
    path = SHARED_FIXTURES / "googol" / name
    if not path.is_file():
        pytest.skip(needs_fixture(path.name))
    return path.read_text(encoding="ascii")


# --- the vendor format: real files ---------------------------------------------------------------
@pytest.mark.parametrize("name", FIXTURES)
def test_every_section_and_key_of_the_real_files_is_known(name):
    """grep the file: each [kindN] and key=value line is in SCHEMA and was read."""
    text = fixture_text(name)
    cfg = parse_config(text, name)
    assert isinstance(cfg, VendorConfig)
    current = None
    seen = 0
    for line in text.splitlines():
        if m := re.fullmatch(r"\[([A-Za-z]+)(\d+)\]", line):
            current = (m.group(1), int(m.group(2)))
            assert current[0] in SCHEMA
            assert current in cfg.sections
        elif "=" in line:
            key = line.split("=")[0]
            assert key in SCHEMA[current[0]], (current, key)
            assert cfg.sections[current].settings[key].key == key
            seen += 1
    assert seen == sum(len(s.settings) for s in cfg.sections.values())


def test_smarthome_values():
    cfg = parse_vendor(fixture_text("smarthome_test.cfg"), "test.cfg")
    assert cfg.get("profile", 1) == {"active": True, "decSmoothStop": 1.0, "decAbruptStop": 1000.0}
    a1, a5 = cfg.get("axis", 1), cfg.get("axis", 5)
    assert a1["alarmType"] == 2 and a1["alarmIndex"] == -1
    assert (a1["limitPositiveIndex"], a1["limitNegativeIndex"]) == (1, 1)
    assert a5["alarmIndex"] == 5 and a5["prfMap"] == 0x10 and a5["encMap"] == 0x10
    assert cfg.get("limitPositive", 1) == {"active": True, "reverse": True, "filterTime": 3}
    assert cfg.get("encoder", 1)["captureSource"] == 1 and not cfg.get("encoder", 1)["reverse"]
    assert cfg.get("encoder", 11)["reverse"] is True
    assert cfg.numbers("mpg") == list(range(1, 8)) and cfg.numbers("dac") == list(range(1, 13))


def test_gtn_values():
    cfg = parse_vendor(fixture_text("coordinate_gtn_core1.cfg"), "gtn_core1.cfg")
    assert cfg.numbers("axis") == list(range(1, 13)) and cfg.numbers("gpi") == list(range(1, 65))
    assert cfg.get("axis", 12)["prfMap"] == 2048
    assert cfg.get("control", 3) == {
        "active": False,
        "axis": -1,
        "encoder1": -1,
        "encoder2": -1,
        "errorLimit": 32767,
        "filterType1": 0,
        "filterType2": 0,
        "filterType3": 0,
        "encoderSmooth": 8,
        "controlSmooth": 8,
    }
    assert cfg.get("profile", 12)["decAbruptStop"] == 1000.0


# --- the vendor format: files as they vary --------------------------------------------------------
def test_gts400_file_hex_values_blank_lines_and_comments():
    cfg = read_config(GTS400)
    assert isinstance(cfg, VendorConfig)
    assert cfg.get("control", 1)["errorLimit"] == 0x7FFF and cfg.get("dac", 1)["limit"] == 0x7FFF
    assert cfg.get("axis", 4)["prfMap"] == 8 and cfg.get("profile", 3)["decSmoothStop"] == 0.5
    assert cfg.get("limitNegative", 3)["reverse"] and cfg.numbers("encoder") == [1, 2, 3, 4, 5]


def _variants(text: str) -> dict[str, bytes]:
    gbk_comment = "; 第3轴限位开关常闭（接线见电气图）"
    lines = text.split("\n")
    commented = []
    for line in lines:
        commented.append(line)
        if line.startswith("[axis"):
            commented.append(gbk_comment)
    upper = re.sub(r"^(\w+)=", lambda m: m.group(1).upper() + " = ", text, flags=re.M)
    return {
        "crlf": text.replace("\n", "\r\n").encode("ascii"),
        "cr": text.replace("\n", "\r").encode("ascii"),
        "gbk_comments": "\r\n".join(commented).encode("gbk"),
        "utf8_bom": b"\xef\xbb\xbf" + "\n".join(commented).encode("utf-8"),
        "utf16": "\r\n".join(commented).encode("utf-16"),
        "keys_upper_spaced": upper.replace("[axis", "[AXIS").encode("ascii"),
        "inline_comments": re.sub(r"^(active=1)$", r"\1   ; on", text, flags=re.M).encode(),
        "dos_eof": text.encode("ascii") + b"\x1a",
        "no_final_newline": text.rstrip("\n").encode("ascii"),
    }


@pytest.mark.parametrize("variant", sorted(_variants("")))
def test_variants_read_the_same(tmp_path, variant):
    text = GTS400.read_text(encoding="ascii")
    reference = parse_vendor(text)
    p = tmp_path / f"{variant}.cfg"
    p.write_bytes(_variants(text)[variant])
    cfg = read_config(p)
    assert isinstance(cfg, VendorConfig)
    assert {k: s.values() for k, s in cfg.sections.items()} == {
        k: s.values() for k, s in reference.sections.items()
    }


@pytest.mark.parametrize(
    ("value", "expected"),
    [
        *[("1", 1), ("-1", -1), ("+7", 7), ("010", 10)],
        *[("0x1F", 31), ("0X10", 16), ("-0x10", -16), ("1.000000", 1), ("2e3", 2000)],
    ],
)
def test_integers_decimal_hex_or_integral_floats(value, expected):
    assert integer(value) == expected


@pytest.mark.parametrize("value", ["", "1.5", "0x", "one", "1 2", "nan", "inf", "1" * 50, "0b1"])
def test_not_integers(value):
    with pytest.raises(ValueError):
        integer(value)


@pytest.mark.parametrize(
    ("text", "line", "words"),
    [
        ("[axis1]\ndecSmothStop=1\n", 2, "unknown key 'decSmothStop' in [axis1]"),
        ("[profile1]\ndecSmothStop=1\n", 2, "unknown key 'decSmothStop' in [profile1]"),
        ("[motor1]\nactive=1\n", 1, "unknown section [motor1]"),
        ("[axis]\n", 1, "unknown section [axis]"),
        ("[axis0]\n", 1, "1..32767"),
        ("[axis1]\n[axis1]\n", 2, "twice (first at line 1)"),
        ("[axis1]\nactive=1\nACTIVE=0\n", 3, "'ACTIVE' given twice"),
        ("active=1\n", 1, "before any [section]"),
        ("[axis1]\njust words\n", 2, "neither"),
        ("[axis1]\nactive=2\n", 2, "active='2'"),
        ("[axis1]\nactive=\n", 2, "not a number"),
        ("[profile1]\ndecSmoothStop=fast\n", 2, "decSmoothStop='fast'"),
        ("[profile1]\ndecAbruptStop=40000\n", 2, "32767"),
        ("[profile1]\ndecSmoothStop=0\n", 2, "(0, 32767]"),
        ("[axis1]\nalarmType=12\n", 2, "not a digital input"),
        ("[axis1]\nalarmIndex=0\n", 2, "-1 (none)"),
        ("[axis2]\nprfMap=0x1\n", 2, "axis 2 takes profile 2 alone"),
        ("[axis1]\nencMap=0\n", 2, "encoder 1 alone"),
        ("[axis1]\nprfMapAlpha1=2\n", 2, "needs prfMapBeta1"),
        ("[axis1]\nencMapAlpha1=1\nencMapBeta1=2\n", 3, "|alpha|"),
        ("[axis1]\nprfMapAlpha1=0\nprfMapBeta1=1\n", 3, "out of range"),
        ("[control1]\nerrorLimit=0\n", 2, "out of range 1..2147483648"),
        ("[encoder1]\ncaptureSource=2\n", 2, "pulse counter"),
        ("[gpi1]\nfilterTime=-1\n", 2, "out of range"),
    ],
)
def test_vendor_errors_name_file_line_and_key(text, line, words):
    with pytest.raises(ConfigFileError) as e:
        parse_vendor(text, "my.cfg")
    assert str(e.value).startswith(f"my.cfg:{line}: ") and words in str(e.value)


def test_scale_pair_and_second_slot():
    cfg = parse_vendor("[axis1]\nprfMapAlpha1=-4\nprfMapBeta1=2\nprfMapAlpha2=0\nprfMapBeta2=9\n")
    a = cfg.get("axis", 1)
    assert (a["prfMapAlpha1"], a["prfMapBeta1"]) == (-4, 2)
    assert (a["prfMapAlpha2"], a["prfMapBeta2"]) == (0, 9)  # the unused second slot: read only


# --- random damage never escapes as anything but ConfigFileError ----------------------------------
_junk = st.text(alphabet="[]=;#-+.0123456789xXaAeE_ \tprofilexncdr", max_size=24)
_mutation = st.tuples(
    st.sampled_from(["replace", "value", "key", "delete", "duplicate", "insert"]),
    st.integers(0, 10_000),
    _junk,
)


def mutate(lines: list[str], mutations) -> list[str]:
    out = list(lines)
    for op, where, junk in mutations:
        if not out:
            out = [junk]
            continue
        i = where % len(out)
        key, eq, value = out[i].partition("=")
        if op == "replace":
            out[i] = junk
        elif op == "value" and eq:
            out[i] = f"{key}={junk}"
        elif op == "key" and eq:
            out[i] = f"{junk}={value}"
        elif op == "delete":
            del out[i]
        elif op == "duplicate":
            out.insert(i, out[i])
        else:
            out.insert(i, junk)
    return out


@settings(max_examples=examples(200, 25), deadline=None)
@given(st.sampled_from(FIXTURES), st.lists(_mutation, min_size=1, max_size=3))
def test_mutated_fixtures_parse_or_fail_with_file_and_line(name, mutations):
    path = SHARED_FIXTURES / "googol" / name
    if not path.is_file():
        pytest.skip(needs_fixture("the Googol configuration files"))
    text = "\n".join(mutate(path.read_text(encoding="ascii").splitlines(), mutations))
    try:
        parse_config(text, "mut.cfg")
    except ConfigFileError as e:
        assert re.match(r"mut\.cfg:\d+: ", str(e)), str(e)


# --- gtecat's earlier format (deprecated) ------------------------------------------------------
FULL = """
# every key of the format
[axis 1]
active = 1
profile_scale = 4 -2
encoder_scale = 1 1
alarm = off
alarm_input = none
positive_limit = ON
positive_limit_input = 2
negative_limit = no
negative_limit_input = 1
smooth_stop_input = 1:2
abrupt_stop_input = none
soft_limit = 1000 -1000
pos_err = 0x100
axis_band = 20 5
[encoder1]
active = 0
reverse = yes
source = pulse
[ Profile 3 ]   ; spaces and case
smooth_stop_dec = 2.5
abrupt_stop_dec = 32767
"""


def test_legacy_is_told_apart_by_spaced_headers_or_its_own_keys():
    assert is_legacy(FULL)
    assert is_legacy("[axis1]\nalarm = off\n")
    assert is_legacy("[motor 1]\n")
    assert not is_legacy("[axis1]\nactive=1\n[encoder1]\nreverse=1\n")
    assert not is_legacy(GTS400.read_text())


def test_every_key_parses_to_its_value():
    cfg = parse_config(FULL, "full.cfg")
    assert isinstance(cfg, Config)
    a = cfg.get("axis", 1)
    assert a["profile_scale"] == Scale(4, -2) and a["encoder_scale"] == Scale(1, 1)
    assert a["alarm"] is False and a["alarm_input"] is None
    assert a["positive_limit"] is True and a["positive_limit_input"] == 2
    assert a["negative_limit"] is False
    assert a["smooth_stop_input"] == StopInput(1, 2) and a["abrupt_stop_input"] is None
    assert a["soft_limit"] == (1000, -1000) and a["pos_err"] == 256 and a["axis_band"] == (20, 5)
    assert cfg.get("encoder", 1) == {"active": False, "reverse": True, "source": False}
    assert cfg.get("profile", 3) == {"smooth_stop_dec": 2.5, "abrupt_stop_dec": 32767.0}
    assert cfg.get("axis", 2) == {}


@pytest.mark.parametrize(
    ("text", "line", "words"),
    [
        ("[axis 1]\nalarm = maybe\n", 2, "on/off"),
        ("[axis 1]\nspeed = 3\n", 2, "unknown key"),
        ("alarm = on\n", 1, "before any"),
        ("[motor 1]\n", 1, "not a section"),
        ("[axis 0]\n", 1, "must be 1..32767"),
        ("[axis 1]\n[axis 1]\n", 2, "twice"),
        ("[axis 1]\nalarm = on\nalarm = off\n", 3, "twice"),
        ("[axis 1]\nprofile_scale = 1 2\n", 2, "alpha"),
        ("[axis 1]\nsoft_limit = -1 1\n", 2, "greater"),
        ("[axis 1]\npos_err = 0\n", 2, "(0, 2147483648]"),
        ("[axis 1]\nsmooth_stop_input = 1.2\n", 2, "AXIS:BIT"),
        ("[profile 1]\nabrupt_stop_dec = 40000\n", 2, "32767"),
        ("[encoder 1]\nsource = laser\n", 2, "external or pulse"),
        ("[axis 1]\njust words\n", 2, "key = value"),
    ],
)
def test_errors_name_file_and_line(text, line, words):
    with pytest.raises(ConfigFileError) as e:
        parse_config(text, "my.cfg")
    assert f"my.cfg:{line}:" in str(e.value) and words in str(e.value)


def test_missing_file(tmp_path):
    with pytest.raises(ConfigFileError, match="not found"):
        read_config(tmp_path / "none.cfg")


switch = st.booleans()
axis_values = st.fixed_dictionaries(
    {},
    optional={
        "alarm": switch,
        "positive_limit": switch,
        "negative_limit": switch,
        "alarm_input": st.none() | st.integers(1, 12),
        "pos_err": st.integers(1, 2147483648),
        "axis_band": st.tuples(st.integers(0, 1000), st.integers(0, 1000)),
    },
)


def render(sections: dict[int, dict]) -> str:
    out = []
    for n, values in sections.items():
        out.append(f"[axis {n}]")
        for k, v in values.items():
            if isinstance(v, bool):
                text = "on" if v else "off"
            elif v is None:
                text = "none"
            elif isinstance(v, tuple):
                text = " ".join(str(x) for x in v)
            else:
                text = str(v)
            out.append(f"{k} = {text}   # comment")
    return "\n".join(out) + "\n"


@given(st.dictionaries(st.integers(1, 16), axis_values, max_size=5))
def test_written_then_read_gives_the_same_settings(sections):
    cfg = parse_config(render(sections))
    for n, values in sections.items():
        assert cfg.get("axis", n) == values
