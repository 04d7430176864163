"""GT_LoadConfig's configuration file: the ``*.cfg`` the vendor's tool writes (manual 4.3-4.4).

The vendor's Motion Controller Toolkit (MCT2008) saves its "controller
configuration" as plain INI text, one ``[kindN]`` section per controller
resource and ``key=value`` lines, values decimal, ``0x`` hex or floats::

    [profile1]                  [axis1]                      [limitPositive1]
    active=1                    active=1                     active=1
    decSmoothStop=1.000000      alarmType=2                  reverse=0
    decAbruptStop=1000.000000   alarmIndex=1                 filterTime=3
                                limitPositiveType=0 ...
                                prfMap=0x1  prfMapAlpha1=1 ...

Real files are in the vendor's sample ``.cfg`` files; ``docs/config_file.md`` is the
user's reference.  :data:`SCHEMA` declares every section and key; what each does
on an EtherCAT axis (axis/profile/encoder N = GT axis N, 4.3):

* ``[profileN]`` ``active`` (4.3.3 item 4: 0 = no motion starts), ``decSmoothStop`` /
  ``decAbruptStop`` (GT_SetStopDec, pulse/ms², (0, 32767]).
* ``[axisN]`` ``active`` (4.3.1 item 9: 0 = no status, limit, alarm or following-error
  checks); ``prfMap`` / ``encMap`` (bit N-1: profile / encoder N feeds the axis - on a bus
  axis N is fed by profile N and encoder N, so any other map is refused);
  ``prfMapAlpha1/Beta1`` (GT_ProfileScale) and ``encMapAlpha1/Beta1`` (GT_EncScale) scale
  that first (only) mapped source; ``...Alpha2/Beta2`` would scale a second one and are
  read and unused.  The inputs ``alarm``, ``limitPositive``, ``limitNegative``,
  ``smoothStop``, ``abruptStop`` each name a ``...Type`` (an ``MC_*`` resource type) and
  an ``...Index``: **-1 is "none"** - the tool's "none" choice.  (The manual's own
  ``test.cfg`` of examples 6-1, 7-1, 7-2, 9-1, "配置文件取消了各轴的报警和限位", writes
  index -1 for every alarm and limit while its ``[alarmN]`` / ``[limitPositiveN]`` stay
  active; its ``servo.cfg`` writes the axis number where they are wired.)  GT_AlarmOn/Off
  and GT_LmtsOn/Off then return 1, as chapter 13 says ("配置文件...配置了报警无效").
* Input sources on a bus: ``MC_LIMIT_POSITIVE`` (0) N = 60FDh bit 1 of axis N,
  ``MC_LIMIT_NEGATIVE`` (1) N = 60FDh bit 0, ``MC_HOME`` (3) N = 60FDh bit 2,
  ``MC_ALARM`` (2) N = 6041h bit 3 (drive fault) of axis N.  ``MC_GPI`` (4),
  ``MC_ARRIVE`` (5), ``MC_MPG`` (6) are the card's own terminals: no input here (noted in
  the master log unless the index is -1, which is what the tool writes for the stop
  inputs, "配置无效").
* ``[limitPositiveN]`` / ``[limitNegativeN]`` / ``[homeN]`` / ``[alarmN]``: ``active``
  is the GT_LmtsOn/Off (GT_AlarmOn/Off) state of the axes that take this input (a stop
  input whose source is not active is none); ``reverse=1`` says the switch is
  normally closed; the emulated switch is wired the way the file expects unless the machine
  description's ``switch_wiring`` says otherwise (:func:`switch_sense`), so only a file that
  disagrees with a stated wiring reads the switch inverted; an alarm's ``reverse=1`` follows
  the same rule (against a stated ``switch_wiring`` it inverts the alarm: active while the
  drive is *not* in fault, noted in the log);
  ``filterTime`` is the card's input debounce (MCT writes 3): on a bus the drive
  debounces its own inputs and the master samples 60FDh / 6041h once a cycle, so the
  value is stored (:func:`vendor_settings`) and filters nothing again.  The drive's own
  homing (6098h) reads its home switch itself: ``[homeN] reverse`` matters only where
  a home input is a limit or stop source here.
* ``[encoderN]`` ``active`` (4.3.2 item 6: 0 = reading frozen); ``reverse``: the tool
  writes 1, the vendor's reset state ("系统复位后，默认为编码器计数方向取反", entry 18,
  table 4-4), which on a bus axis is "count as the drive reports 6064h" - the emulator's
  reset state (:mod:`gtecat.controller.encoder`); ``reverse=0`` makes the encoder count
  the other way.  ``captureSource`` (4.3.2 item 3 "脉冲计数源"): 0 = external encoder
  (GT_EncOn, 6064h), 1 = pulse counter (GT_EncOff, 607Ah).  The pulse counter counts the
  pulses the controller sends, whatever ``reverse`` says: the tool writes ``reverse=0``
  beside ``captureSource=1`` and ``reverse=1`` beside ``captureSource=0`` (both fixtures,
  every axis), and on the vendor's card both count with the profile.  ``captureHomeSense`` /
  ``captureIndexSense`` ("配置无效", capture is the drive's touch probe here) and
  ``filterType`` (the card's quadrature input filter) are stored.
* ``[controlN]``: the card's servo loop; on a bus the drive closes the loop.  Only
  ``errorLimit`` means something here: GT_SetPosErr(N) - unless that section says
  ``active=0``.  The PID filters and smoothing are stored.
* ``[dacN]``, ``[stepN]``, ``[gpoN]``, ``[gpiN]``, ``[enableN]``, ``[clearN]``,
  ``[arriveN]``, ``[mpgN]``: pulse-card terminals (analogue out, pulse out, card IO, servo
  enable, alarm clear, in-position, hand wheel).  On a bus the drive gets 607Ah, enable and
  fault reset are 6040h, IO is ``GT_EcatIO*``: read, checked, stored, and named once in
  the master log.

Rules: sections and keys are case-insensitive (the Windows INI functions are); comment
lines start with ``;`` or ``#``, text after one on a line is a comment too; blank lines,
CRLF / CR line ends, a UTF-8 BOM and GBK comments are fine.  A key left out keeps the
controller's current setting (GT_Reset: table 4-4).  Sections for resources the bus does
not have (axes 5-8 of an 8-axis file on a 4-axis bus) are checked and noted in the log.
An unknown section or key, a malformed or out-of-range value, a duplicate key or section
is :class:`ConfigFileError` (GT_LoadConfig 7) naming ``file:line`` and the key as written,
and nothing is applied.  As 4.4 says, call GT_ClrSts after loading.

gtecat's own earlier format (``[axis 1]``, ``alarm = off``, ``smooth_stop_dec = 2``,
``soft_limit``...) is still read for one release, with a deprecation line in the master
log; a file is taken for it when a section header has a space before its number or a key
only that format has appears (:func:`is_legacy`).  Its reader is :func:`parse_legacy`.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from decimal import Decimal
from pathlib import Path
from typing import TYPE_CHECKING, Any

from .._attrs import PerObject
from ..errors import ParameterError
from .input_sense import changed as sense_changed
from .motion import STOP_DEC_MAX, StopDecel
from .safety import LIMIT_NEGATIVE_BIT, LIMIT_POSITIVE_BIT, POS_ERR_MAX, StopInput
from .scale import Scale

if TYPE_CHECKING:
    from .core import Controller
    from .resources import AxisResources


class ConfigFileError(ParameterError):
    """A configuration file that cannot be used (GT_LoadConfig returns 7)."""


# --- resource types (vendor header, gt.constants; the controller does not import gt) ------------
MC_NONE = -1
MC_LIMIT_POSITIVE = 0
MC_LIMIT_NEGATIVE = 1
MC_ALARM = 2
MC_HOME = 3
MC_GPI = 4
MC_ARRIVE = 5
MC_MPG = 6

_SW_FAULT = 0x0008  # 6041h bit 3
#: a bus input: section kind of its settings, PDO object, bit
BUS_INPUTS: dict[int, tuple[str, int, int]] = {
    MC_LIMIT_POSITIVE: ("limitPositive", 0x60FD, 1),
    MC_LIMIT_NEGATIVE: ("limitNegative", 0x60FD, 0),
    MC_HOME: ("home", 0x60FD, 2),
    MC_ALARM: ("alarm", 0x6041, 3),
}
#: the card's own input terminals: no EtherCAT counterpart
CARD_INPUTS = {MC_GPI: "gpi", MC_ARRIVE: "arrive", MC_MPG: "mpg"}
_INPUT_TYPES = (MC_NONE, *BUS_INPUTS, *CARD_INPUTS)
_SECTION_NUMBER_MAX = 0x7FFF
_VALUE_CHARS_MAX = 40
_INTEGER_MAX = Decimal(2**64)


# --- values -------------------------------------------------------------------------------------
_INT_RE = re.compile(r"[+-]?(?:0[xX][0-9a-fA-F]+|\d+)")
_REAL_RE = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?")


def _number(v: str) -> int | Decimal:
    """An integer, or a real as written (a :class:`~decimal.Decimal`, exact: ``1e-999`` is
    not 0, and no exponent builds a huge integer)."""
    if len(v) > _VALUE_CHARS_MAX:
        raise ValueError(f"{len(v)} characters is not a number")
    if _INT_RE.fullmatch(v):
        sign = -1 if v[0] == "-" else 1
        body = v.lstrip("+-")
        return sign * (int(body, 16) if body[:2].lower() == "0x" else int(body, 10))
    if _REAL_RE.fullmatch(v):
        return Decimal(v)
    raise ValueError("not a number (decimal, 0x hex or a float)")


def integer(v: str) -> int:
    """Decimal, ``0x`` hex, or a real whose value *as written* is an integer (``1.000000``,
    ``1e3``).  One rule for every integer and flag key: ``1e-999`` and ``0.5`` are both
    refused (neither is an integer), though a float would read the first as 0."""
    x = _number(v)
    if isinstance(x, Decimal):
        if x != x.to_integral_value():
            raise ValueError("not an integer")
        if abs(x) > _INTEGER_MAX:
            raise ValueError("out of range (beyond 64 bits)")
        x = int(x)
    return x


def _ranged(lo: int, hi: int, what: str = "") -> Callable[[str], int]:
    def parse(v: str) -> int:
        x = integer(v)
        if not lo <= x <= hi:
            raise ValueError(f"{x} out of range {lo}..{hi}{what}")
        return x

    return parse


def flag(v: str) -> bool:
    x = integer(v)
    if x not in (0, 1):
        raise ValueError(f"{x} is not 0 or 1")
    return bool(x)


def real(v: str) -> float:
    x = float(_number(v))
    if not math.isfinite(x):
        raise ValueError("beyond the range of a double")
    return x


def stop_dec(v: str) -> float:
    x = real(v)
    if not 0 < x <= STOP_DEC_MAX:
        raise ValueError(f"{x:g} not in (0, 32767] pulse/ms²")
    return x


def input_type(v: str) -> int:
    x = integer(v)
    if x not in _INPUT_TYPES:
        raise ValueError(
            f"type {x} is not a digital input: MC_NONE -1, MC_LIMIT_POSITIVE 0, "
            "MC_LIMIT_NEGATIVE 1, MC_ALARM 2, MC_HOME 3, MC_GPI 4, MC_ARRIVE 5, MC_MPG 6"
        )
    return x


def input_index(v: str) -> int:
    x = integer(v)
    if x != -1 and not 1 <= x <= _SECTION_NUMBER_MAX:
        raise ValueError(f"index {x}: -1 (none) or a resource number 1..32767")
    return x


_mask = _ranged(0, 0xFFFFFFFF)
_short = _ranged(-0x8000, 0x7FFF)
_scale_part = _ranged(-0x7FFF, 0x7FFF)  # checked with its partner by Scale
_error_limit = _ranged(1, POS_ERR_MAX, " pulse (GT_SetPosErr)")
_capture_source = _ranged(0, 1, " (0 external encoder, 1 pulse counter)")
_filter_time = _ranged(0, 0x7FFF)

Parser = Callable[[str], Any]
_INPUT_KEYS: dict[str, Parser] = {"active": flag, "reverse": flag, "filterTime": _filter_time}
_OUTPUT_KEYS: dict[str, Parser] = {
    "active": flag,
    "axis": _short,
    "axisItem": _short,
    "reverse": flag,
}

#: every section kind and its keys, as the vendor spells them, with the value parser
SCHEMA: dict[str, dict[str, Parser]] = {
    "profile": {"active": flag, "decSmoothStop": stop_dec, "decAbruptStop": stop_dec},
    "axis": {
        "active": flag,
        **{
            f"{role}{part}": parse
            for role in ("alarm", "limitPositive", "limitNegative", "smoothStop", "abruptStop")
            for part, parse in (("Type", input_type), ("Index", input_index))
        },
        "prfMap": _mask,
        "encMap": _mask,
        **{
            f"{m}Map{ab}{k}": _scale_part
            for m in ("prf", "enc")
            for k in (1, 2)
            for ab in ("Alpha", "Beta")
        },
    },
    "encoder": {
        "active": flag,
        "reverse": flag,
        "filterType": _short,
        "captureSource": _capture_source,
        "captureHomeSense": flag,
        "captureIndexSense": flag,
    },
    "control": {
        "active": flag,
        "axis": _short,
        "encoder1": _short,
        "encoder2": _short,
        "errorLimit": _error_limit,
        **{f"filterType{k}": _short for k in (1, 2, 3, 4)},
        "encoderSmooth": _short,
        "controlSmooth": _short,
    },
    "dac": {"active": flag, "control": _short, "reverse": flag, "bias": _short, "limit": _short},
    "step": {"active": flag, "axis": _short, "mode": _short, "parameter": _short, "reverse": flag},
    "gpo": _OUTPUT_KEYS,
    "enable": _OUTPUT_KEYS,
    "clear": _OUTPUT_KEYS,
    "gpi": _INPUT_KEYS,
    "limitPositive": _INPUT_KEYS,
    "limitNegative": _INPUT_KEYS,
    "home": _INPUT_KEYS,
    "alarm": _INPUT_KEYS,
    "arrive": _INPUT_KEYS,
    "mpg": _INPUT_KEYS,
}
#: pulse-card terminals without an EtherCAT counterpart (read, checked, stored, logged)
CARD_ONLY = ("dac", "step", "gpo", "gpi", "enable", "clear", "arrive", "mpg")
#: resources numbered like the bus axes (a number past the last axis: noted in the log)
PER_AXIS = (
    "profile",
    "axis",
    "encoder",
    "control",
    "limitPositive",
    "limitNegative",
    "home",
    "alarm",
)

_KINDS = {k.lower(): k for k in SCHEMA}
_KEYS = {kind: {k.lower(): k for k in keys} for kind, keys in SCHEMA.items()}


# --- the vendor format: model and reader ---------------------------------------------------------
@dataclass(frozen=True, slots=True)
class Setting:
    """One ``key=value`` line: the value parsed, the key as written, its line."""

    value: Any
    key: str
    line: int


@dataclass(slots=True)
class VendorSection:
    kind: str  # as SCHEMA spells it
    number: int
    line: int
    header: str  # as written, e.g. "axis1"
    settings: dict[str, Setting] = field(default_factory=dict)

    def values(self) -> dict[str, Any]:
        return {k: s.value for k, s in self.settings.items()}


@dataclass(slots=True)
class VendorConfig:
    """A parsed vendor ``*.cfg``: ``sections[(kind, number)]``."""

    path: Path
    sections: dict[tuple[str, int], VendorSection] = field(default_factory=dict)

    def get(self, kind: str, number: int) -> dict[str, Any]:
        s = self.sections.get((kind, number))
        return s.values() if s is not None else {}

    def numbers(self, kind: str) -> list[int]:
        return sorted(n for k, n in self.sections if k == kind)


_HEADER_RE = re.compile(r"\[\s*([A-Za-z]+)(\d+)\s*\]")


_COMMENT = re.compile(r"[;#]")


def _shown(value: str) -> str:
    return repr(value) if len(value) <= 48 else f"{value[:24]!r}... ({len(value)} characters)"


def _lines(text: str) -> Iterable[tuple[int, str]]:
    """(line number, text without comment), comment-only and blank lines dropped."""
    split = _COMMENT.split
    for lineno, raw in enumerate(text.splitlines(), start=1):
        line = split(raw, 1)[0].strip()
        if line:
            yield lineno, line


def _error(path: Path, lineno: int, msg: str) -> ConfigFileError:
    return ConfigFileError(f"{path}:{lineno}: {msg}")


def parse_vendor(text: str, path: Path | str = "<text>") -> VendorConfig:
    """Parse the vendor format; ConfigFileError naming ``path:line`` and the key as written."""
    path = Path(path)
    cfg = VendorConfig(path)
    current: VendorSection | None = None
    for lineno, line in _lines(text):
        if line[0] == "[":
            m = _HEADER_RE.fullmatch(line)
            kind = _KINDS.get(m.group(1).lower()) if m else None
            if m is None or kind is None:
                raise _error(
                    path,
                    lineno,
                    f"unknown section {line}; a section is a resource and its number, one of "
                    + ", ".join(f"[{k}N]" for k in SCHEMA),
                )
            number = _section_number(m.group(2))
            if not 1 <= number <= _SECTION_NUMBER_MAX:
                raise _error(
                    path,
                    lineno,
                    f"section {_shown(line)}: the number must be 1..{_SECTION_NUMBER_MAX}",
                )
            first = cfg.sections.get((kind, number))
            if first is not None:
                raise _error(
                    path, lineno, f"section {line} appears twice (first at line {first.line})"
                )
            current = VendorSection(kind, number, lineno, line[1:-1].strip())
            cfg.sections[(kind, number)] = current
            continue
        if "=" not in line:
            raise _error(path, lineno, f"{line!r} is neither [section] nor key=value")
        if current is None:
            raise _error(path, lineno, f"{line!r} before any [section]")
        written, _, value = line.partition("=")
        written, value = written.strip(), value.strip()
        key = _KEYS[current.kind].get(written.lower())
        if key is None:
            raise _error(
                path,
                lineno,
                f"unknown key {written!r} in [{current.header}] "
                f"(known: {', '.join(SCHEMA[current.kind])})",
            )
        first_setting = current.settings.get(key)
        if first_setting is not None:
            raise _error(
                path,
                lineno,
                f"{written!r} given twice in [{current.header}] (first at line "
                f"{first_setting.line})",
            )
        try:
            parsed = SCHEMA[current.kind][key](value)
        except ValueError as e:
            raise _error(
                path, lineno, f"{written}={_shown(value)} in [{current.header}]: {e}"
            ) from None
        current.settings[key] = Setting(parsed, written, lineno)
    for section in cfg.sections.values():
        _check_section(section, path)
    return cfg


def _check_section(s: VendorSection, path: Path) -> None:
    """What one key cannot check alone: the axis's maps and alpha/beta pairs."""
    if s.kind != "axis":
        return
    n = s.number
    own = 1 << (n - 1)
    for m, what in (("prf", "profile"), ("enc", "encoder")):
        st = s.settings.get(f"{m}Map")
        if st is not None and st.value != own:
            raise ConfigFileError(
                f"{path}:{st.line}: {st.key}={st.value:#x} in [{s.header}]: on a bus, axis {n} "
                f"takes {what} {n} alone ({st.key}={own:#x}); mapping other {what}s is not "
                "supported"
            )
        alpha, beta = s.settings.get(f"{m}MapAlpha1"), s.settings.get(f"{m}MapBeta1")
        if alpha is None and beta is None:
            continue
        if alpha is None or beta is None:
            given = alpha or beta
            assert given is not None
            missing = f"{m}MapBeta1" if beta is None else f"{m}MapAlpha1"
            raise ConfigFileError(
                f"{path}:{given.line}: {given.key} in [{s.header}] needs {missing} too"
            )
        try:
            Scale(alpha.value, beta.value)
        except ParameterError as e:
            raise ConfigFileError(
                f"{path}:{beta.line}: {alpha.key}={alpha.value}, {beta.key}={beta.value} in "
                f"[{s.header}]: {e}"
            ) from None


# --- gtecat's earlier format (deprecated; read for one release) --------------------------------
_LEGACY_SECTION = re.compile(r"^\[\s*(axis|encoder|profile)\s*(\d+)\s*\]$", re.IGNORECASE)
_ON = {"on": True, "1": True, "true": True, "yes": True}
_OFF = {"off": False, "0": False, "false": False, "no": False}


@dataclass
class Section:
    kind: str
    number: int
    line: int
    values: dict[str, Any] = field(default_factory=dict)


@dataclass
class Config:
    """A parsed file of gtecat's earlier format: ``sections[(kind, number)]``."""

    path: Path
    sections: dict[tuple[str, int], Section] = field(default_factory=dict)

    def get(self, kind: str, number: int) -> dict[str, Any]:
        s = self.sections.get((kind, number))
        return s.values if s is not None else {}


def _switch(v: str) -> bool:
    low = v.lower()
    if low in _ON:
        return _ON[low]
    if low in _OFF:
        return _OFF[low]
    raise ValueError(f"{v!r} is not on/off")


def _int(v: str) -> int:
    if len(v) > _VALUE_CHARS_MAX:
        raise ValueError(f"{len(v)} characters is not a number")
    return int(v, 0)


def _section_number(digits: str) -> int:
    """A section's number; one of thousands of digits is out of range, not converted."""
    return int(digits) if len(digits) <= 9 else _SECTION_NUMBER_MAX + 1


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
    x = float(v) if len(v) <= _VALUE_CHARS_MAX else math.nan
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


LEGACY_KEYS: dict[str, dict[str, Any]] = {
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
_LEGACY_ONLY = {k for keys in LEGACY_KEYS.values() for k in keys} - {"active", "reverse"}
_SPACED_HEADER = re.compile(r"\[\s*[A-Za-z_]+\s+\d+\s*\]")
_KEY_RE = re.compile(r"([^=\[\s]+)\s*=")


def is_legacy(text: str) -> bool:
    """gtecat's earlier format: ``[axis 1]`` (a space before the number) or one of its keys."""
    for _, line in _lines(text):
        if line.startswith("["):
            if _SPACED_HEADER.fullmatch(line):
                return True
            continue
        m = _KEY_RE.match(line)
        if m and m.group(1).lower() in _LEGACY_ONLY:
            return True
    return False


def parse_legacy(text: str, path: Path | str = "<text>") -> Config:
    """Parse gtecat's earlier format (errors name ``path`` and the line)."""
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
            m = _LEGACY_SECTION.match(line)
            if not m:
                raise fail(f"{line!r} is not a section [axis N], [encoder N] or [profile N]")
            kind, number = m.group(1).lower(), _section_number(m.group(2))
            if not 1 <= number <= _SECTION_NUMBER_MAX:
                raise fail(f"{_shown(line)}: the number must be 1..{_SECTION_NUMBER_MAX}")
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
        parser = LEGACY_KEYS[current.kind].get(key)
        if parser is None:
            raise fail(
                f"unknown key {key!r} in [{current.kind} {current.number}] "
                f"(known: {', '.join(LEGACY_KEYS[current.kind])})"
            )
        if key in current.values:
            raise fail(f"{key!r} given twice in [{current.kind} {current.number}]")
        try:
            current.values[key] = parser(value)
        except (ValueError, ParameterError) as e:
            raise fail(f"{key} = {_shown(value)}: {e}") from None
    return cfg


# --- reading ------------------------------------------------------------------------------------
def parse_config(text: str, path: Path | str = "<text>") -> VendorConfig | Config:
    """Parse either format (told apart by :func:`is_legacy`)."""
    text = text.lstrip("\ufeff").rstrip("\x1a")  # a BOM; a DOS end-of-file mark
    if is_legacy(text):
        return parse_legacy(text, path)
    return parse_vendor(text, path)


def decode(data: bytes) -> str:
    """The file's text: UTF-8 (with or without BOM) or UTF-16 with BOM, else GBK (the
    vendor tool's Chinese Windows), else Latin-1; values are ASCII, so only comments
    can suffer."""
    if data.startswith(b"\xef\xbb\xbf"):
        return data[3:].decode("utf-8", "replace")
    if data.startswith((b"\xff\xfe", b"\xfe\xff")):  # Notepad's "Unicode"
        return data.decode("utf-16", "replace")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError:
        pass
    try:
        return data.decode("gbk")
    except UnicodeDecodeError:
        return data.decode("latin-1")


_WINDOWS_DRIVE = re.compile(r"^[A-Za-z]:")


def find_config(name: str, log: Callable[[str], None] | None = None) -> Path:
    """The file GT_LoadConfig(name) reads.

    Applications are written for the controller's PC or its Windows CE core and pass the
    path the file had there: ``"\\gugao-board\\gugao1\\test.cfg"``, ``"D:\\cfg\\GTS800.cfg"``,
    example 5-5's ``"\\hard disk\\CPAC\\GTS800.cfg"``.  Decision: a path that exists is read
    as given; one that does not (a Windows path, or any other) is looked for by its file
    name - the part after the last ``\\`` or ``/`` - in the working folder (where the
    application runs: a private controller started by libgts inherits the program's
    folder), first as written, then ignoring case as Windows does; what was used goes to
    the master log.  ConfigFileError (7) names both places when neither has it."""
    if not name.isprintable() or "\ufffd" in name:
        # not a file name: bytes of memory (a C# wrapper declaring `ref string pFile`
        # passes a char ** where the function reads a char *)
        raise ConfigFileError(
            f"the configuration file name is not text ({name[:16]!r}...): the program passed "
            "something other than a C string (char *); a C# wrapper must declare the name "
            "`string pFile`, not `ref string pFile`"
        )
    given = Path(name)
    if given.is_file():
        return given
    base = re.split(r"[\\/]", name)[-1]
    here = Path.cwd()
    candidates = [here / base] if base and base not in (".", "..") else []
    if candidates and not candidates[0].is_file():
        try:
            candidates = [p for p in here.iterdir() if p.name.lower() == base.lower()]
        except OSError:
            candidates = []
    found = next((p for p in candidates if p.is_file()), None)
    if found is None:
        where = f"{name} not found, nor {base!r} in the working folder {here}"
        raise ConfigFileError(f"configuration file {where}")
    if log is not None:
        kind = "a Windows path" if "\\" in name or _WINDOWS_DRIVE.match(name) else "a path"
        log(
            f"GT_LoadConfig: {name} ({kind}) does not exist here; reading {found.name} from "
            f"the working folder {here}"
        )
    return found


def read_config(path: str | Path) -> VendorConfig | Config:
    """Read and parse a configuration file; ConfigFileError (7) when missing or bad."""
    p = Path(path)
    try:
        data = p.read_bytes()
    except FileNotFoundError:
        raise ConfigFileError(f"configuration file {p} not found (cwd {Path.cwd()})") from None
    except (OSError, ValueError) as e:
        raise ConfigFileError(f"configuration file {p} cannot be read: {e}") from None
    return parse_config(decode(data), p)


# --- what a vendor file leaves on the controller --------------------------------------------------
@dataclass
class _State:
    """Vendor settings loaded since GT_Reset, merged (a later file overrides key by key)."""

    axes: tuple[int, ...]
    values: dict[tuple[str, int], dict[str, Any]] = field(default_factory=dict)


_STATES: PerObject[_State] = PerObject("config_file")


def _axes_id(ctl: Controller) -> tuple[int, ...]:
    return tuple(id(ax) for ax in ctl.axes.values())


def _state(ctl: Controller) -> _State:
    st = _STATES.get(ctl)
    if st is None or st.axes != _axes_id(ctl):  # none yet, or the bus was brought up anew
        st = _STATES[ctl] = _State(_axes_id(ctl))
        sense_changed()
    if _forget not in ctl.on_reset:
        ctl.on_reset.append(_forget)
    return st


def _forget(ctl: Controller) -> None:
    """GT_Reset: every resource back to table 4-4, the loaded settings forgotten."""
    _STATES.pop(ctl, None)
    sense_changed()


def vendor_settings(ctl: Controller) -> dict[tuple[str, int], dict[str, Any]]:
    """Every vendor-format value loaded since GT_Reset, by ``(kind, number)`` - also those
    that act on nothing here (filter times, card terminals): ``[("limitPositive", 1)]
    ["filterTime"]``.  A copy."""
    st = _STATES.get(ctl)
    if st is None or st.axes != _axes_id(ctl):
        return {}
    return {k: dict(v) for k, v in st.values.items()}


#: the inputs that are switches of the machine (a wiring the machine description may state)
#: the inputs whose wiring follows the configuration unless the machine description states
#: it: the limit and home switches, and the drive's alarm output (a ``reverse=1`` alarm is
#: one that opens in fault, as the machine the file was written for has it)
SWITCH_KINDS = ("limitPositive", "limitNegative", "home", "alarm")


def machine_wiring(ctl: Controller, axis: int) -> bool | None:
    """Whether axis ``axis``'s switches are normally closed (True) or open (False) as the
    machine description's ``switch_wiring`` says; None where it does not say.  On real
    hardware (the pysoem backend) the wiring is the machine's own: False, so a
    configuration's ``reverse`` applies as written."""
    options = getattr(ctl, "options", None)
    if getattr(options, "backend", "emulated") == "pysoem":
        return False
    machine = getattr(ctl, "machine", None)
    wiring = machine.axis(axis).switch_wiring if machine is not None else None
    return None if wiring is None else wiring == "normally_closed"


def switch_sense(
    ctl: Controller, kind: str, number: int, reverse: bool | None = None
) -> tuple[bool, bool]:
    """``(normally_closed, invert)`` of input ``[kind number]``: how the emulated switch is
    wired (its electrical level is ``active != normally_closed``: GT_GetDiRaw) and whether
    the controller, applying the configuration's ``reverse``, reads it inverted
    (``reverse != normally_closed``: a limit stuck triggered, a home seen off the switch).

    Decision: where the machine description does not say how a switch is wired
    (:func:`machine_wiring` None), the emulated switch is wired the way the loaded
    configuration expects - ``reverse=1`` on a limit or home is a normally-closed switch
    on the machine the file was written for (``smarthome_test.cfg`` of the vendor's demo
    writes it on axis 1's limits and home) - so the application's own ``.cfg`` runs as it
    does there and never makes every limit read as triggered.  The drive's alarm is wired
    the same way (an application's own file with ``[alarm2] reverse=1`` must not leave its
    axis 2 in alarm for good).  A description that states ``switch_wiring`` wins: a
    ``reverse`` that disagrees with it inverts the input, as a wrongly written file would
    on the machine.  Other inputs (GPI) are no switches of the machine: ``reverse``
    inverts them as written."""
    if reverse is None:
        reverse = bool(vendor_settings(ctl).get((kind, number), {}).get("reverse", False))
    if kind not in SWITCH_KINDS:
        return False, reverse
    nc = machine_wiring(ctl, number)
    if nc is None:
        nc = reverse
    return nc, reverse != nc


# --- applying a vendor file -----------------------------------------------------------------------
class SensedInput:
    """A bus input seen through the configuration: ``get()`` gives ``mask_out`` while the
    source bit (``mask_in`` of the PDO entry) is active, inverted when ``reverse``; it stands
    where :class:`AxisResources` reads a raw 6041h / 60FDh entry."""

    __slots__ = ("entry", "mask_in", "mask_out", "reverse")

    def __init__(self, entry: Any, mask_in: int, mask_out: int, reverse: bool) -> None:
        self.entry = entry
        self.mask_in = mask_in
        self.mask_out = mask_out
        self.reverse = reverse

    def get(self) -> int:
        return self.mask_out if bool(self.entry.get() & self.mask_in) != self.reverse else 0


@dataclass(frozen=True, slots=True)
class _Role:
    """One input of an axis: its keys, its Safety fields, where AxisResources reads it."""

    name: str  # for the log
    key: str  # [axisN] key prefix
    natural: int | None  # the type Safety's axis-number input stands for (None: stop input)
    input_attr: str  # Safety field: axis number (or StopInput)
    on_attr: str | None  # Safety field switched by GT_AlarmOn/Off, GT_LmtsOn/Off
    entry_attr: str  # AxisResources attribute holding the entry
    mask_out: int | None  # what AxisResources tests (None: the stop input's mask)


_ROLES = (
    _Role("alarm", "alarm", MC_ALARM, "alarm_input", "alarm_on", "_alarm_sw", _SW_FAULT),
    _Role(
        "positive limit",
        "limitPositive",
        MC_LIMIT_POSITIVE,
        "positive_input",
        "positive_on",
        "_pos_din",
        LIMIT_POSITIVE_BIT,
    ),
    _Role(
        "negative limit",
        "limitNegative",
        MC_LIMIT_NEGATIVE,
        "negative_input",
        "negative_on",
        "_neg_din",
        LIMIT_NEGATIVE_BIT,
    ),
    _Role("smooth stop", "smoothStop", None, "smooth_stop_input", None, "_smooth_in", None),
    _Role("abrupt stop", "abruptStop", None, "abrupt_stop_input", None, "_abrupt_in", None),
)
_BIT_TYPE = {bit: t for t, (_, obj, bit) in BUS_INPUTS.items() if obj == 0x60FD}
_Source = tuple[int, int]  # (MC_* type, index); index -1 = none


def _current_source(res: AxisResources, role: _Role) -> _Source | None:
    """The source the axis has now when no vendor file named one (None: leave it alone)."""
    value = getattr(res.safety, role.input_attr)
    if value is None:
        return (MC_NONE, -1)
    if role.natural is not None:
        return (role.natural, value)
    if value.bit in _BIT_TYPE:
        return (_BIT_TYPE[value.bit], value.axis)
    return None  # an earlier-format AXIS:BIT stop input of another bit: kept as it is


def apply_vendor(ctl: Controller, cfg: VendorConfig) -> None:
    """Apply a vendor ``*.cfg`` to the bus axes (the caller checked that none moves)."""
    st = _state(ctl)
    try:
        for (kind, n), section in cfg.sections.items():
            st.values.setdefault((kind, n), {}).update(section.values())
    finally:
        sense_changed()  # (the inputs' reverse, GT_GetDi's fast path)
    notes: list[str] = []
    for n, ax in sorted(ctl.axes.items()):
        res: AxisResources = ax.motion
        p = cfg.get("profile", n)
        if "active" in p:
            res.profile.active = p["active"]
        if "decSmoothStop" in p or "decAbruptStop" in p:
            d = res.profile.stop_dec
            res.profile.stop_dec = StopDecel(
                p.get("decSmoothStop", d.smooth), p.get("decAbruptStop", d.abrupt)
            )
        a = cfg.get("axis", n)
        if "active" in a:
            res.safety.active = a["active"]
        if "prfMapAlpha1" in a:
            res.set_profile_scale(Scale(a["prfMapAlpha1"], a["prfMapBeta1"]))
        if "encMapAlpha1" in a:
            res.set_enc_scale(Scale(a["encMapAlpha1"], a["encMapBeta1"]))
        e = cfg.get("encoder", n)
        if "active" in e:
            res.encoder.active = e["active"]
        if "captureSource" in e:
            res.set_encoder_source(e["captureSource"] == 0)
        if "reverse" in e:
            # 1: the reset state (module doc); the pulse counter counts what is sent
            res.encoder.sense = 1 if e["reverse"] or not res.encoder.external else -1
        c = cfg.get("control", n)
        if "errorLimit" in c and c.get("active", True):
            res.safety.set_pos_err(c["errorLimit"])
    _wire_inputs(ctl, cfg, st, notes)
    _log_vendor(ctl, cfg, notes)


def _wire_inputs(ctl: Controller, cfg: VendorConfig, st: _State, notes: list[str]) -> None:
    """Alarm, limit and stop inputs of every axis from the merged settings; senses last."""
    sensed: list[tuple[AxisResources, _Role, Any, int, bool]] = []
    wired: set[tuple[str, int]] = set()
    for n, ax in sorted(ctl.axes.items()):
        res: AxisResources = ax.motion
        merged = st.values.get(("axis", n), {})
        here = cfg.get("axis", n)
        for role in _ROLES:
            tkey, ikey = f"{role.key}Type", f"{role.key}Index"
            current = _current_source(res, role)
            if current is None and tkey not in merged and ikey not in merged:
                continue
            base = current or (MC_NONE, -1)
            kind_t = merged.get(tkey, base[0])
            index = merged.get(ikey, base[1])
            changed = tkey in here or ikey in here
            s = res.safety
            if index == -1 or kind_t == MC_NONE:
                setattr(s, role.input_attr, None)
                continue
            if kind_t in CARD_INPUTS:
                setattr(s, role.input_attr, None)
                notes.append(
                    f"axis {n} {role.name} = {CARD_INPUTS[kind_t]}{index}, a card terminal: none"
                )
                continue
            kind, obj, bit = BUS_INPUTS[kind_t]
            settings = st.values.get((kind, index), {})
            active = settings.get("active", True)
            reverse = settings.get("reverse", False)
            if role.on_attr is None:  # a stop input: an inactive source is no input
                if not active:
                    setattr(s, role.input_attr, None)
                    continue
                setattr(s, role.input_attr, StopInput(index, bit))
            else:
                setattr(s, role.input_attr, index)
                if changed or "active" in cfg.get(kind, index):
                    setattr(s, role.on_attr, active)
            if index not in ctl.axes:
                notes.append(f"axis {n} {role.name} = {kind}{index}: no axis {index} on this bus")
            elif ctl.axes[index].io.get(obj) is None:
                notes.append(
                    f"axis {n} {role.name} = {kind}{index}: axis {index} maps no 0x{obj:04X}"
                )
            else:
                invert = switch_sense(ctl, kind, index, reverse)[1]
                unsaid = kind in SWITCH_KINDS and machine_wiring(ctl, index) is None
                if reverse and unsaid and (kind, index) not in wired:
                    wired.add((kind, index))
                    what = (
                        "an alarm that opens in fault"
                        if kind == "alarm"
                        else ("a normally-closed switch")
                    )
                    notes.append(
                        f"{kind}{index} reverse=1 ({what}): the machine description does not "
                        f"say how axis {index}'s inputs are wired (switch_wiring), so it is "
                        "wired as this configuration expects"
                    )
                mismatch = kind_t != role.natural if role.natural is not None else obj != 0x60FD
                if invert or mismatch:
                    sensed.append((res, role, ctl.axes[index].io.get(obj), bit, invert))
                if invert and kind_t == MC_ALARM:
                    notes.append(
                        f"axis {n} {role.name} = alarm{index} reverse=1: active while drive "
                        f"{index} is not in fault"
                    )
    for ax in ctl.axes.values():
        ax.motion.bind_inputs()
    for res, role, entry, bit, reverse in sensed:
        if not hasattr(res, role.entry_attr):  # AxisResources renamed it: fail loudly in tests
            raise AttributeError(f"AxisResources has no {role.entry_attr}")
        out = role.mask_out if role.mask_out is not None else 1 << bit
        setattr(res, role.entry_attr, SensedInput(entry, 1 << bit, out, reverse))


def _ranges(numbers: Iterable[int]) -> str:
    """1,2,3,5 -> '1-3,5'."""
    out: list[str] = []
    run: list[int] = []
    for n in sorted(numbers):
        if run and n == run[-1] + 1:
            run.append(n)
            continue
        if run:
            out.append(f"{run[0]}-{run[-1]}" if len(run) > 1 else str(run[0]))
        run = [n]
    if run:
        out.append(f"{run[0]}-{run[-1]}" if len(run) > 1 else str(run[0]))
    return ",".join(out)


def _log_vendor(ctl: Controller, cfg: VendorConfig, notes: list[str]) -> None:
    name = cfg.path.name
    axes = sorted(ctl.axes)
    ctl.log(
        f"GT_LoadConfig {name}: {len(cfg.sections)} sections read, applied to axes {_ranges(axes)}"
    )
    ignored = [f"[{k}{_ranges(cfg.numbers(k))}]" for k in CARD_ONLY if cfg.numbers(k)]
    if cfg.numbers("control"):
        ignored.append(f"[control{_ranges(cfg.numbers('control'))}] but errorLimit")
    if ignored:
        ctl.log(
            f"GT_LoadConfig {name}: pulse-card resources without an EtherCAT counterpart, "
            f"accepted and ignored: {' '.join(ignored)}"
        )
    missing = [
        f"[{k}{_ranges(beyond)}]"
        for k in PER_AXIS
        if (beyond := [n for n in cfg.numbers(k) if n not in ctl.axes])
    ]
    if missing:
        ctl.log(
            f"GT_LoadConfig {name}: this bus has axes {_ranges(axes)}; accepted and not "
            f"applied: {' '.join(missing)}"
        )
    if notes:
        ctl.log(f"GT_LoadConfig {name}: inputs: {'; '.join(notes)}")


# --- applying -------------------------------------------------------------------------------------
def apply_config(ctl: Controller, cfg: VendorConfig | Config) -> None:
    """Apply a parsed file of either format (the caller checked that no axis moves)."""
    if isinstance(cfg, VendorConfig):
        apply_vendor(ctl, cfg)
    else:
        apply_legacy(ctl, cfg)


def apply_legacy(ctl: Controller, cfg: Config) -> None:
    """Apply a file of gtecat's earlier format; a deprecation line in the master log."""
    ctl.log(
        f"GT_LoadConfig {cfg.path.name}: gtecat's own configuration format is deprecated and "
        "will not be read after the next release; write the vendor's *.cfg format "
        "(docs/config_file.md)"
    )
    _STATES.pop(ctl, None)  # its inputs replace any a vendor file set
    sense_changed()
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
