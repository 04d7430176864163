"""GT_LoadConfig's configuration file: the options of manual 4.3 as a small text format.

The vendor's tool (MCT2008) writes a binary-opaque ``*.cfg``; its format is not
public, so gtecat reads its own, documented here and in ``docs/config_file.md``::

    # a comment (also ';'); blank lines are ignored
    [axis 1]                      # or [axis1]: GT axis 1
    active = 1                    # 4.3.1 item 9: 0 = no status or safety checks
    profile_scale = 1 1           # alpha beta, GT_ProfileScale (4.3.1 item 2)
    encoder_scale = 1 1           # alpha beta, GT_EncScale (item 3)
    alarm = on                    # GT_AlarmOn / GT_AlarmOff (item 4)
    alarm_input = 1               # whose drive fault is the alarm: an axis number, or none
    positive_limit = on           # GT_LmtsOn / GT_LmtsOff(axis, MC_LIMIT_POSITIVE) (item 5)
    positive_limit_input = 1      # whose 60FDh bit 1: an axis number, or none
    negative_limit = on           # (item 6)
    negative_limit_input = 1      # whose 60FDh bit 0
    smooth_stop_input = none      # extension (items 7-8 are "配置无效"): AXIS:BIT of 60FDh
    abrupt_stop_input = none      #   e.g. 1:2 = axis 1's home switch input
    soft_limit = 2147483647 -2147483648   # extension: GT_SetSoftLimit positive negative
    pos_err = 32767               # extension: GT_SetPosErr
    axis_band = 0 0               # extension: GT_SetAxisBand band time

    [encoder 1]
    active = 1                    # 4.3.2 item 6: 0 = the reading is frozen
    reverse = 0                   # GT_EncSns bit (item 2)
    source = external             # external (GT_EncOn, 6064h) or pulse (GT_EncOff, 607Ah)

    [profile 1]
    active = 1                    # 4.3.3 item 4: 0 = GT_Update refused
    smooth_stop_dec = 1           # GT_SetStopDec, pulse/ms² (item 2)
    abrupt_stop_dec = 1000        # (item 3)

Rules: keys and ``on``/``off`` (also 1/0, true/false, yes/no) are
case-insensitive; a key left out keeps the controller's current setting (after
GT_Reset: table 4-4); sections for axes the bus does not have are read and
ignored (a file written for an 8-axis machine loads on a 2-axis bus); an
unknown section or key, a bad value or a duplicate is an error naming the file
and line (GT_LoadConfig returns 7) and nothing is applied.  An input set to
``none`` cannot be switched by GT_AlarmOn/Off or GT_LmtsOn/Off (they return 1,
as chapter 13 describes).  As 4.4 says, call GT_ClrSts after loading so that
flags latched under the old configuration are re-evaluated.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..errors import ParameterError
from .motion import STOP_DEC_MAX, StopDecel
from .safety import POS_ERR_MAX, StopInput
from .scale import Scale

if TYPE_CHECKING:
    from .core import Controller


class ConfigFileError(ParameterError):
    """A configuration file that cannot be used (GT_LoadConfig returns 7)."""


_SECTION = re.compile(r"^\[\s*(axis|encoder|profile)\s*(\d+)\s*\]$", re.IGNORECASE)
_ON = {"on": True, "1": True, "true": True, "yes": True}
_OFF = {"off": False, "0": False, "false": False, "no": False}
_UNSET = object()


@dataclass
class Section:
    kind: str
    number: int
    line: int
    values: dict[str, Any] = field(default_factory=dict)


@dataclass
class Config:
    """A parsed configuration file: ``sections[(kind, number)]`` with typed values."""

    path: Path
    sections: dict[tuple[str, int], Section] = field(default_factory=dict)

    def get(self, kind: str, number: int) -> dict[str, Any]:
        s = self.sections.get((kind, number))
        return s.values if s is not None else {}


# --- value parsers ----------------------------------------------------------------------------
def _switch(v: str) -> bool:
    low = v.lower()
    if low in _ON:
        return _ON[low]
    if low in _OFF:
        return _OFF[low]
    raise ValueError(f"{v!r} is not on/off")


def _int(v: str) -> int:
    return int(v, 0)


def _ints(n: int):
    def parse(v: str) -> tuple[int, ...]:
        parts = v.replace(",", " ").split()
        if len(parts) != n:
            raise ValueError(f"expected {n} integers, got {v!r}")
        return tuple(_int(p) for p in parts)

    return parse


def _input(v: str) -> int | None:
    if v.lower() == "none":
        return None
    n = _int(v)
    if n < 1:
        raise ValueError(f"input {n}: an axis number is >= 1 (or none)")
    return n


def _stop_input(v: str) -> StopInput | None:
    if v.lower() == "none":
        return None
    m = re.fullmatch(r"(\d+)\s*:\s*(\d+)", v)
    if not m:
        raise ValueError(f"{v!r} is not AXIS:BIT (a bit of that axis's 60FDh) or none")
    axis, bit = int(m.group(1)), int(m.group(2))
    if axis < 1 or not 0 <= bit <= 31:
        raise ValueError(f"{v!r}: axis >= 1 and bit 0..31")
    return StopInput(axis, bit)


def _scale(v: str) -> Scale:
    a, b = _ints(2)(v)
    return Scale(a, b)


def _source(v: str) -> bool:
    low = v.lower()
    if low in ("external", "encoder"):
        return True
    if low in ("pulse", "pulse_counter"):
        return False
    raise ValueError(f"{v!r} is not external or pulse")


def _dec(v: str) -> float:
    x = float(v)
    if not 0 < x <= STOP_DEC_MAX:
        raise ValueError(f"{x:g} not in (0, 32767] pulse/ms²")
    return x


def _pos_err(v: str) -> int:
    x = _int(v)
    if not 0 < x <= POS_ERR_MAX:
        raise ValueError(f"{x} not in (0, 2147483648]")
    return x


def _soft(v: str) -> tuple[int, int]:
    pos, neg = _ints(2)(v)
    if pos <= neg:
        raise ValueError(f"positive {pos} must be greater than negative {neg}")
    return pos, neg


def _band(v: str) -> tuple[int, int]:
    band, time = _ints(2)(v)
    if band < 0 or time < 0:
        raise ValueError("band and time must be >= 0")
    return band, time


KEYS: dict[str, dict[str, Any]] = {
    "axis": {
        "active": _switch,
        "profile_scale": _scale,
        "encoder_scale": _scale,
        "alarm": _switch,
        "alarm_input": _input,
        "positive_limit": _switch,
        "positive_limit_input": _input,
        "negative_limit": _switch,
        "negative_limit_input": _input,
        "smooth_stop_input": _stop_input,
        "abrupt_stop_input": _stop_input,
        "soft_limit": _soft,
        "pos_err": _pos_err,
        "axis_band": _band,
    },
    "encoder": {"active": _switch, "reverse": _switch, "source": _source},
    "profile": {"active": _switch, "smooth_stop_dec": _dec, "abrupt_stop_dec": _dec},
}


# --- reading ----------------------------------------------------------------------------------
def parse_config(text: str, path: Path | str = "<text>") -> Config:
    """Parse the text of a configuration file (errors name ``path`` and the line)."""
    path = Path(path)
    cfg = Config(path)
    current: Section | None = None
    for lineno, raw in enumerate(text.splitlines(), start=1):
        line = re.split(r"\s[#;]|^[#;]", raw, maxsplit=1)[0].strip()
        if not line:
            continue

        def fail(msg: str, lineno: int = lineno) -> ConfigFileError:
            return ConfigFileError(f"{path}:{lineno}: {msg}")

        if line.startswith("["):
            m = _SECTION.match(line)
            if not m:
                raise fail(f"{line!r} is not a section [axis N], [encoder N] or [profile N]")
            kind, number = m.group(1).lower(), int(m.group(2))
            if number < 1:
                raise fail(f"{kind} number {number} must be >= 1")
            if (kind, number) in cfg.sections:
                raise fail(f"[{kind} {number}] appears twice")
            current = cfg.sections[(kind, number)] = Section(kind, number, lineno)
            continue
        if "=" not in line:
            raise fail(f"{line!r} is not 'key = value'")
        if current is None:
            raise fail("a key before any [section]")
        key, value = (p.strip() for p in line.split("=", 1))
        key = key.lower()
        parser = KEYS[current.kind].get(key)
        if parser is None:
            raise fail(
                f"unknown key {key!r} in [{current.kind} {current.number}] "
                f"(known: {', '.join(KEYS[current.kind])})"
            )
        if key in current.values:
            raise fail(f"{key!r} given twice in [{current.kind} {current.number}]")
        try:
            current.values[key] = parser(value)
        except (ValueError, ParameterError) as e:
            raise fail(f"{key} = {value!r}: {e}") from None
    return cfg


def read_config(path: str | Path) -> Config:
    """Read and parse a configuration file; ConfigFileError (7) when missing or bad."""
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ConfigFileError(f"configuration file {p} not found (cwd {Path.cwd()})") from None
    except (OSError, UnicodeDecodeError) as e:
        raise ConfigFileError(f"configuration file {p} cannot be read: {e}") from None
    return parse_config(text, p)


# --- applying ---------------------------------------------------------------------------------
def apply_config(ctl: Controller, cfg: Config) -> None:
    """Apply ``cfg`` to the controller's axes (the caller checked that none moves)."""
    for n, ax in ctl.axes.items():
        res = ax.motion
        a = cfg.get("axis", n)
        s = res.safety
        if "active" in a:
            s.active = a["active"]
        if "profile_scale" in a:
            res.set_profile_scale(a["profile_scale"])
        if "encoder_scale" in a:
            res.set_enc_scale(a["encoder_scale"])
        for key, attr in (
            ("alarm", "alarm_on"),
            ("alarm_input", "alarm_input"),
            ("positive_limit", "positive_on"),
            ("positive_limit_input", "positive_input"),
            ("negative_limit", "negative_on"),
            ("negative_limit_input", "negative_input"),
            ("smooth_stop_input", "smooth_stop_input"),
            ("abrupt_stop_input", "abrupt_stop_input"),
            ("pos_err", "pos_err"),
        ):
            if key in a:
                setattr(s, attr, a[key])
        if "soft_limit" in a:
            s.set_soft_limits(*a["soft_limit"])
        if "axis_band" in a:
            res.band.set(*a["axis_band"])
        e = cfg.get("encoder", n)
        if "active" in e:
            res.encoder.active = e["active"]
        if "reverse" in e:
            res.encoder.sense = -1 if e["reverse"] else 1
        if "source" in e:
            res.set_encoder_source(e["source"])
        p = cfg.get("profile", n)
        if "active" in p:
            res.profile.active = p["active"]
        if "smooth_stop_dec" in p or "abrupt_stop_dec" in p:
            d = res.profile.stop_dec
            res.profile.stop_dec = StopDecel(
                p.get("smooth_stop_dec", d.smooth), p.get("abrupt_stop_dec", d.abrupt)
            )
    for ax in ctl.axes.values():
        ax.motion.bind_inputs()
