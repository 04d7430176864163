"""Integers as configuration files spell them: ``#x1A00`` (ETG.2100), ``0x1a00``, ``5632``."""

from __future__ import annotations


def parse_int(text: str | int) -> int:
    """Parse an ENI/INI/TOML integer; raises ValueError with the text when it is not one."""
    if isinstance(text, bool):
        raise ValueError(f"not an integer: {text!r}")
    if isinstance(text, int):
        return text
    s = text.strip().replace("_", "")
    neg = s.startswith("-")
    if neg:
        s = s[1:]
    low = s.lower()
    try:
        if low.startswith(("#x", "0x")):
            value = int(low[2:], 16)
        elif low.startswith("#b") or low.startswith("0b"):
            value = int(low[2:], 2)
        else:
            value = int(low, 10)
    except ValueError:
        raise ValueError(f"not an integer: {text!r}") from None
    if not s or low in ("#x", "0x"):
        raise ValueError(f"not an integer: {text!r}")
    return -value if neg else value


def parse_hex_bytes(text: str) -> bytes:
    """ETG.2100 ``Data`` (hex digits, little-endian payload as written) -> bytes."""
    s = "".join(text.split())
    if s.lower().startswith(("#x", "0x")):
        s = s[2:]
    if len(s) % 2:
        raise ValueError(f"odd number of hex digits in {text!r}")
    try:
        return bytes.fromhex(s)
    except ValueError:
        raise ValueError(f"not hex data: {text!r}") from None


def fmt_index(index: int, subindex: int) -> str:
    """An object address as everywhere in gtecat: ``0x6040:00``."""
    return f"0x{index:04X}:{subindex:02X}"
