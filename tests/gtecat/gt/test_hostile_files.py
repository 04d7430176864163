"""Hostile files a GT call reads (``.cfg`` for GT_LoadConfig, ``.c`` for GT_Compile): a
number of thousands of digits, an exponent beyond any double, a value that is not quite an
integer are refused with 7 or 1 and the file and line, never an internal error or a stall."""

from __future__ import annotations

from ctypes import byref

import pytest

from gtecat import gt
from tests.gtecat.gt.conftest import bring_up

HUGE = "9" * 5001


@pytest.mark.parametrize(
    "text, words",
    [
        (f"[axis{HUGE}]\nactive=1\n", "the number must be 1..32767"),
        (f"[axis1]\nactive={HUGE}\n", "5001 characters is not a number"),
        ("[profile1]\nactive=1e-999\n", "not an integer"),  # one rule: as written, not as
        ("[profile1]\nactive=0.5\n", "not an integer"),  # a float would round it
        ("[profile1]\ndecSmoothStop=1e999999999\n", "beyond the range of a double"),
        (f"[axis {HUGE}]\nactive = on\n", "the number must be 1..32767"),
        (f"[axis 1]\nsoft_limit = {HUGE} 0\n", "is not a number"),
    ],
)
def test_load_config_refuses_with_the_line(tmp_path, text, words):
    bring_up(clock="lockstep")
    cfg = tmp_path / "hostile.cfg"
    cfg.write_text(text)
    assert gt.GT_LoadConfig(str(cfg)) == 7
    reason = gt.GTE_GetLastError()
    assert words in reason and "hostile.cfg:" in reason and len(reason) < 400


def test_load_config_reads_an_integral_real_as_its_integer(tmp_path):
    bring_up(clock="lockstep")
    cfg = tmp_path / "ok.cfg"
    cfg.write_text("[profile1]\nactive=1.000000\n[profile2]\nactive=1e0\n")
    assert gt.GT_LoadConfig(str(cfg)) == 0, gt.GTE_GetLastError()


@pytest.mark.parametrize(
    "constant, words",
    [
        ("1e999", "exponent is beyond the double range"),
        ("1e99999999", "exponent is beyond the double range"),
        ("9" * 5000, "more than 60 digits"),
        ("0." + "1" * 5000, "more than 60 digits"),
        ("99999999999", "outside the 32-bit int range"),
    ],
)
def test_compile_refuses_constants_beyond_a_word_with_the_line(tmp_path, constant, words):
    src = tmp_path / "k.c"
    typ = "double" if "." in constant or "e" in constant else "int"
    src.write_text(f"{typ} x;\nint f()\n{{\n    x = {constant};\n    return 0;\n}}\n")
    info = gt.TCompileInfo()
    assert gt.GT_Compile(str(src), byref(info)) == 1
    assert info.pLineNo[0] == 4 and words in info.pMessage.decode()
    assert len(gt.GTE_GetLastError()) < 400


@pytest.mark.parametrize("name", ["P_\ufffd\ufffd KV", "\x01\x02\x9c"])
def test_load_config_given_memory_instead_of_a_name_says_so(name):
    """A C# wrapper that declares ``ref string pFile`` passes a char ** where GT_LoadConfig
    reads a char *: the bytes it finds are not a file name, and the reason says what to fix
    instead of quoting them as a missing file."""
    bring_up(clock="lockstep")
    assert gt.GT_LoadConfig(name) == 7
    reason = gt.GTE_GetLastError()
    assert "not text" in reason and "ref string" in reason
