"""What a PDO entry's data type means: its bit size, its signedness, its CiA-402 default.

ENI files name types the IEC 61131-3 way (``UINT``, ``DINT``, ``BOOL``; ETG.2100
``DataType``), ESI/CoE files the CiA 301 way (``UNSIGNED16``, ``INTEGER32``);
Googol's INI ``Gecat.eni`` names none.  When a file gives no type, the standard
CiA-402 object table (IEC 61800-7-201, see ``cia402-facts.md`` section 2.3)
supplies one for the drive objects, per channel: channel ``k`` of a multi-axis
module repeats object ``0x60xx`` at ``0x60xx + 0x800*k``.
"""

from __future__ import annotations

import re

# IEC 61131-3 / ETG.2100 names and the CiA 301 / ESI spellings -> (bits, signed)
_TYPES: dict[str, tuple[int, bool]] = {
    "BOOL": (1, False),
    "BIT": (1, False),
    "BYTE": (8, False),
    "WORD": (16, False),
    "DWORD": (32, False),
    "LWORD": (64, False),
    "SINT": (8, True),
    "USINT": (8, False),
    "INT": (16, True),
    "UINT": (16, False),
    "DINT": (32, True),
    "UDINT": (32, False),
    "LINT": (64, True),
    "ULINT": (64, False),
    "REAL": (32, False),
    "LREAL": (64, False),
    "FLOAT": (32, False),
    "DOUBLE": (64, False),
    "REAL32": (32, False),
    "REAL64": (64, False),
    "BOOLEAN": (1, False),
}
for _n in (8, 16, 24, 32, 40, 48, 56, 64):
    _TYPES[f"INT{_n}"] = (_n, True)
    _TYPES[f"UINT{_n}"] = (_n, False)
    _TYPES[f"INTEGER{_n}"] = (_n, True)
    _TYPES[f"UNSIGNED{_n}"] = (_n, False)

_BITN = re.compile(r"^BIT(?:ARR)?(\d{1,2})$")


def _norm(data_type: str) -> str:
    return data_type.strip().upper().replace(" ", "")


def type_bits(data_type: str) -> int | None:
    """Bit size of a named type, ``None`` when the name is unknown (``BIT3`` -> 3)."""
    key = _norm(data_type)
    if key in _TYPES:
        return _TYPES[key][0]
    m = _BITN.match(key)
    if m and 1 <= int(m.group(1)) <= 64:
        return int(m.group(1))
    return None


def type_signed(data_type: str) -> bool | None:
    """True for the signed integer types, False for the others, None when unknown."""
    key = _norm(data_type)
    if key in _TYPES:
        return _TYPES[key][1]
    if _BITN.match(key):
        return False
    return None


# CiA-402 drive objects that appear in PDOs: index -> (name, IEC type)
CIA402_OBJECTS: dict[int, tuple[str, str]] = {
    0x603F: ("Error code", "UINT"),
    0x6040: ("Controlword", "UINT"),
    0x6041: ("Statusword", "UINT"),
    0x605A: ("Quick stop option code", "INT"),
    0x6060: ("Modes of operation", "SINT"),
    0x6061: ("Modes of operation display", "SINT"),
    0x6062: ("Position demand value", "DINT"),
    0x6063: ("Position actual internal value", "DINT"),
    0x6064: ("Position actual value", "DINT"),
    0x6065: ("Following error window", "UDINT"),
    0x606B: ("Velocity demand value", "DINT"),
    0x606C: ("Velocity actual value", "DINT"),
    0x6071: ("Target torque", "INT"),
    0x6072: ("Max torque", "UINT"),
    0x6073: ("Max current", "UINT"),
    0x6074: ("Torque demand", "INT"),
    0x6077: ("Torque actual value", "INT"),
    0x6078: ("Current actual value", "INT"),
    0x607A: ("Target position", "DINT"),
    0x607C: ("Home offset", "DINT"),
    0x607F: ("Max profile velocity", "UDINT"),
    0x6080: ("Max motor speed", "UDINT"),
    0x6081: ("Profile velocity", "UDINT"),
    0x6083: ("Profile acceleration", "UDINT"),
    0x6084: ("Profile deceleration", "UDINT"),
    0x6085: ("Quick stop deceleration", "UDINT"),
    0x6098: ("Homing method", "SINT"),
    0x60B0: ("Position offset", "DINT"),
    0x60B1: ("Velocity offset", "DINT"),
    0x60B2: ("Torque offset", "INT"),
    0x60B8: ("Touch probe function", "UINT"),
    0x60B9: ("Touch probe status", "UINT"),
    0x60BA: ("Touch probe pos1 pos value", "DINT"),
    0x60BB: ("Touch probe pos1 neg value", "DINT"),
    0x60BC: ("Touch probe pos2 pos value", "DINT"),
    0x60BD: ("Touch probe pos2 neg value", "DINT"),
    0x60E0: ("Positive torque limit value", "UINT"),
    0x60E1: ("Negative torque limit value", "UINT"),
    0x60F4: ("Following error actual value", "DINT"),
    0x60FC: ("Position demand internal value", "DINT"),
    0x60FD: ("Digital inputs", "UDINT"),
    0x60FE: ("Digital outputs", "UDINT"),
    0x60FF: ("Target velocity", "DINT"),
    0x6502: ("Supported drive modes", "UDINT"),
}
# objects whose PDO entry is a sub-index other than 0 (60FE:01 physical outputs)
_SUBINDEXED = {0x60FE}

CHANNEL_STRIDE = 0x800  # CiA-402 channel k: objects at 0x6000 + 0x800*k (IEC 61800-7-201)
MAX_CHANNELS = 8


def channel_of(index: int) -> tuple[int, int] | None:
    """``(channel, channel-0 index)`` for a CiA-402 profile area object, else None."""
    if not 0x6000 <= index < 0x6000 + CHANNEL_STRIDE * MAX_CHANNELS:
        return None
    k, off = divmod(index - 0x6000, CHANNEL_STRIDE)
    return k, 0x6000 + off


def cia402_type(index: int, subindex: int, bits: int) -> str:
    """The standard type of a drive object mapped with ``bits`` bits, or ``""``.

    Only a sub-index 0 object (or 60FE's sub-indices) whose standard size
    matches the mapped size counts: ETG.5001 IO modules reuse the same index
    range (0x6060:01 is a 1-bit input of module 6, not the INT8 mode).
    """
    ch = channel_of(index)
    if ch is None:
        return ""
    base = ch[1]
    obj = CIA402_OBJECTS.get(base)
    if obj is None or (subindex != 0 and base not in _SUBINDEXED):
        return ""
    return obj[1] if type_bits(obj[1]) == bits else ""


def cia402_name(index: int, subindex: int, bits: int) -> str:
    """The standard name of a drive object (as for :func:`cia402_type`), or ``""``."""
    if not cia402_type(index, subindex, bits):
        return ""
    ch = channel_of(index)
    assert ch is not None
    return CIA402_OBJECTS[ch[1]][0]


def entry_signed(data_type: str, index: int, subindex: int, bits: int) -> bool:
    """Signedness of an entry: from its data type, else from the CiA-402 object."""
    if data_type:
        s = type_signed(data_type)
        if s is not None:
            return s
    std = cia402_type(index, subindex, bits)
    return bool(std) and bool(type_signed(std))


def default_type(bits: int) -> str:
    """A neutral unsigned type name for a mapped size (used by the writer)."""
    named = {1: "BOOL", 8: "USINT", 16: "UINT", 32: "UDINT", 64: "ULINT"}
    return named.get(bits, f"BIT{bits}" if 1 <= bits <= 64 else "")
