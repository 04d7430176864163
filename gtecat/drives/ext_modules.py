"""Extension IO modules in the machine description: ``[ext.N]`` and ``[glink.N]`` tables.

A GTS card drives extension IO modules on its own module bus (the vendor's ``ExtMdl``
functions, ``GT_OpenExtMdl`` ...; the GTN cores' ``GTN_ExtModuleInit`` family reads the
same chain with one flat numbering), and a gLink-II master drives gLink slaves.  Neither is
an EtherCAT slave: the machine description says what is plugged in::

    [ext.0]                 # module 0 (the vendor numbers modules from 0, up to 15)
    di = 16                 # digital inputs (0..32)
    do = 16                 # digital outputs (0..32)
    ai = 0                  # analog input channels (0..8)
    ao = 0                  # analog output channels (0..8)
    ai_range = [-10, 10]    # volts of the analog channels
    ao_range = [-10, 10]
    active_low = true       # a terminal that is on reads/writes level 0 (see below)

    [glink.0]               # gLink-II slave 0 (0..63)
    di = 16
    do = 16

``active_low`` left out means the family's own wiring: the GTS ``ExtMdl`` modules switch an
output on with a 0 bit and read an active input as 0 (applications write
``GT_SetExtIoBit(mdl, i, !on)``); the GTN cores' modules and gLink slaves use 1 = on.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from .machine import MachineError

#: the vendor's module numbers: ``mdl`` 0..15; gLink slaves 0..63
EXT_MODULES_MAX = 16
GLINK_SLAVES_MAX = 64
_BITS_MAX = 32
_CHANNELS_MAX = 8


@dataclass(frozen=True, slots=True)
class ExtModuleSpec:
    """One extension module as wired on the machine (the module docstring)."""

    di: int = 16
    do: int = 16
    ai: int = 0
    ao: int = 0
    ai_range: tuple[float, float] = (-10.0, 10.0)
    ao_range: tuple[float, float] = (-10.0, 10.0)
    #: None: the family's default (GTS ExtMdl active low, GTN / gLink active high)
    active_low: bool | None = None


_EXT_KEYS = {"di", "do", "ai", "ao", "ai_range", "ao_range", "active_low"}
_GLINK_KEYS = {"di", "do", "active_low"}


def _count(table: Mapping[str, Any], key: str, default: int, top: int, where: str) -> int:
    v = table.get(key, default)
    if isinstance(v, bool) or not isinstance(v, int) or not 0 <= v <= top:
        raise MachineError(f"{where}: {key} must be an integer 0..{top}, got {v!r}")
    return v


def _range(table: Mapping[str, Any], key: str, where: str) -> tuple[float, float]:
    v = table.get(key, [-10.0, 10.0])
    if (
        not isinstance(v, list)
        or len(v) != 2
        or not all(isinstance(x, int | float) and not isinstance(x, bool) for x in v)
        or not v[0] < v[1]
    ):
        raise MachineError(f"{where}: {key} must be [low, high] volts with low < high, got {v!r}")
    return float(v[0]), float(v[1])


def _tables(data: Mapping[str, Any], name: str, top: int, source: str) -> dict[int, Mapping]:
    raw = data.get(name, {})
    if not isinstance(raw, dict):
        raise MachineError(f"{source}: [{name}.N] tables expected")
    out: dict[int, Mapping] = {}
    for key, table in raw.items():
        where = f"{source}: [{name}.{key}]"
        try:
            n = int(key)
        except ValueError:
            raise MachineError(f"{where}: the number must be an integer") from None
        if not 0 <= n < top:
            raise MachineError(f"{where}: numbered 0..{top - 1}")
        if not isinstance(table, dict):
            raise MachineError(f"{where}: a table of keys expected")
        out[n] = table
    return out


def _active_low(table: Mapping[str, Any], where: str) -> bool | None:
    v = table.get("active_low")
    if v is not None and not isinstance(v, bool):
        raise MachineError(f"{where}: active_low must be true or false, got {v!r}")
    return v


def ext_modules_from_dict(data: Mapping[str, Any], source: str = "") -> dict[int, ExtModuleSpec]:
    """The ``[ext.N]`` tables of a machine description (MachineError names the bad key)."""
    out: dict[int, ExtModuleSpec] = {}
    for n, table in _tables(data, "ext", EXT_MODULES_MAX, source).items():
        where = f"{source}: [ext.{n}]"
        unknown = set(table) - _EXT_KEYS
        if unknown:
            raise MachineError(f"{where}: unknown key(s) {', '.join(sorted(unknown))}")
        out[n] = ExtModuleSpec(
            di=_count(table, "di", 16, _BITS_MAX, where),
            do=_count(table, "do", 16, _BITS_MAX, where),
            ai=_count(table, "ai", 0, _CHANNELS_MAX, where),
            ao=_count(table, "ao", 0, _CHANNELS_MAX, where),
            ai_range=_range(table, "ai_range", where),
            ao_range=_range(table, "ao_range", where),
            active_low=_active_low(table, where),
        )
    return dict(sorted(out.items()))


def glink_from_dict(data: Mapping[str, Any], source: str = "") -> dict[int, ExtModuleSpec]:
    """The ``[glink.N]`` tables (gLink-II slaves: digital IO only)."""
    out: dict[int, ExtModuleSpec] = {}
    for n, table in _tables(data, "glink", GLINK_SLAVES_MAX, source).items():
        where = f"{source}: [glink.{n}]"
        unknown = set(table) - _GLINK_KEYS
        if unknown:
            raise MachineError(f"{where}: unknown key(s) {', '.join(sorted(unknown))}")
        out[n] = ExtModuleSpec(
            di=_count(table, "di", 16, _BITS_MAX, where),
            do=_count(table, "do", 16, _BITS_MAX, where),
            active_low=_active_low(table, where),
        )
    return dict(sorted(out.items()))


__all__ = [
    "EXT_MODULES_MAX",
    "GLINK_SLAVES_MAX",
    "ExtModuleSpec",
    "ext_modules_from_dict",
    "glink_from_dict",
]
