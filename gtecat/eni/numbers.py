"""Integers as configuration files spell them: ``#x1A00`` (ETG.2100), ``0x1a00``, ``5632``."""

from __future__ import annotations

#: significant digits beyond which a number is out of every field's range (2**64 has 20
#: decimal digits, 16 hex, 64 binary); longer texts are refused before converting, so a
#: 4,000-digit value costs nothing and never meets Python's int conversion limit
MAX_DIGITS = 64
_SHOWN = 32


class TooLong(ValueError):
    """A number with more significant digits than any configuration field can hold."""


def shown(text: str, *, quote: bool = True) -> str:
    """``text`` for an error message: quoted (unless ``quote`` is false and it is one
    plain word), and cut in the middle when it is long."""
    t = text.strip()
    if len(t) > _SHOWN:
        return f"{t[:12]!r}...{t[-8:]!r} ({len(t)} characters)"
    if not quote and t and t.isprintable() and not any(c.isspace() for c in t):
        return t
    return repr(t)


def parse_int(text: str | int) -> int:
    """Parse an ENI/INI/TOML integer; raises ValueError with the text when it is not one.

    :class:`TooLong` (a ValueError) when the text has more than :data:`MAX_DIGITS`
    significant digits: no field takes such a number (:mod:`gtecat.eni.limits`).
    """
    if type(text) is str:
        hit = _PARSED.get(text)
        if hit is not None:
            return hit
    if isinstance(text, bool):
        raise ValueError(f"not an integer: {shown(str(text))}")
    if isinstance(text, int):
        return text
    value = _parse(text)
    if type(text) is str and len(text) <= 24:
        if len(_PARSED) >= 4096:
            _PARSED.clear()
        _PARSED[text] = value
    return value


#: texts already parsed (an ENI spells the same few hundred numbers thousands of times);
#: only successes are kept, and only short texts
_PARSED: dict[str, int] = {}


def _parse(text: str) -> int:
    s = text.strip().replace("_", "")
    neg = s.startswith("-")
    if s.startswith(("-", "+")):
        s = s[1:]
    low = s.lower()
    if low.startswith(("#x", "0x", "#b", "0b")):
        base, digits = (16 if low[1] == "x" else 2), low[2:]
    else:
        base, digits = 10, low
    if not digits or not digits.isascii() or not digits.isalnum():
        raise ValueError(f"not an integer: {shown(text)}")
    significant = digits.lstrip("0") or "0"
    if len(significant) > MAX_DIGITS:
        raise TooLong(
            f"{shown(text)} has {len(significant)} digits, more than any number a "
            f"configuration file holds (at most {MAX_DIGITS})"
        )
    try:
        value = int(significant, base)
    except ValueError:
        raise ValueError(f"not an integer: {shown(text)}") from None
    return -value if neg else value


def parse_hex_bytes(text: str) -> bytes:
    """ETG.2100 ``Data`` (hex digits, little-endian payload as written) -> bytes."""
    hit = _HEX.get(text)
    if hit is not None:
        return hit
    data = _parse_hex(text)
    if len(text) <= 64:  # one object for the same short data, slave after slave
        if len(_HEX) >= 4096:
            _HEX.clear()
        _HEX[text] = data
    return data


_HEX: dict[str, bytes] = {}


def _parse_hex(text: str) -> bytes:
    s = "".join(text.split())
    if s.lower().startswith(("#x", "0x")):
        s = s[2:]
    if len(s) % 2:
        raise ValueError(f"odd number of hex digits in {shown(text)}")
    try:
        return bytes.fromhex(s)
    except ValueError:
        raise ValueError(f"not hex data: {shown(text)}") from None


def fmt_index(index: int, subindex: int) -> str:
    """An object address as everywhere in gtecat: ``0x6040:00``."""
    return f"0x{index:04X}:{subindex:02X}"
