"""The Googol-style ``GT_*`` API: ``from gtecat import gt``.

Every function of the manual with its ``GTN_*`` twin (``short core`` first),
the vendor-header EtherCAT extras, constants and ctypes structures, plus the
emulator-only ``GTE_*`` helpers.  Functions never raise: they return the
manual's codes and ``GTE_GetLastError()`` says why.
"""

from __future__ import annotations

import importlib

from ._core import REGISTRY

_MODULES = (
    "bus_calls",
    "constants",
    "structs",
    "axis_calls",
    "homing_calls",
    "motion_calls",
    "status_calls",
    "mode_calls",
    "motion_ext_calls",
)

for _name in _MODULES:
    try:
        _mod = importlib.import_module(f"{__name__}.{_name}")
    except ModuleNotFoundError as _e:
        if _e.name != f"{__name__}.{_name}":
            raise
        continue
    for _k, _v in vars(_mod).items():
        if _k.startswith("_"):
            continue
        if _k.startswith(("GT_", "GTN_", "GTE_", "T")) or _k.isupper():
            globals()[_k] = _v

globals().update(REGISTRY)
