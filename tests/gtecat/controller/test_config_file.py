"""GT_LoadConfig's text format (gtecat/config_file.py, docs/config_file.md)."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from gtecat.controller.config_file import ConfigFileError, parse_config, read_config
from gtecat.controller.safety import StopInput
from gtecat.controller.scale import Scale

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


def test_every_key_parses_to_its_value():
    cfg = parse_config(FULL, "full.cfg")
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
        ("[axis 0]\n", 1, ">= 1"),
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
