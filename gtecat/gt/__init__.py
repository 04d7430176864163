"""The Googol-style ``GT_*`` API: ``from gtecat import gt``.

Every function of the manual with its ``GTN_*`` twin (``short core`` first),
the vendor-header EtherCAT extras, constants and ctypes structures, plus the
emulator-only ``GTE_*`` helpers.  Functions never raise: they return the
manual's codes and ``GTE_GetLastError()`` says why.
"""

from __future__ import annotations

import ctypes
import importlib
import threading as _threading

from ._core import REGISTRY

_MODULES = (
    "bus_calls",
    "constants",
    "structs",
    "axis_calls",
    "homing_calls",
    "home_calls",
    "io_calls",
    "motion_calls",
    "status_calls",
    "mode_calls",
    "motion_ext_calls",
    "program_calls",
    "crd_calls",
    "ext_io_calls",
    "servo_loop_calls",
    "buffered_calls",
    "plcopen_calls",
    "ecat_io_calls",
    "gantry_calls",
    "compare_calls",
    "crd_ex_calls",
    "pvt_calls",
    "lead_screw_calls",
    "net_init_calls",
    "legacy_home_calls",
    "look_ahead_ex_calls",
)


def _is_public(name: str, value: object) -> bool:
    """What the stable surface exports: functions, structures, constants (DESIGN.md)."""
    if name.startswith("_"):
        return False
    if name.startswith(("GT_", "GTN_", "GTE_")):
        return True
    if name.startswith("T") and isinstance(value, type) and issubclass(value, ctypes.Structure):
        return True  # TTrapPrm, TJogPrm, TSlaveInfo ...
    return name.isupper() and len(name) > 1 and isinstance(value, int | float | str)


for _name in _MODULES:
    try:
        _mod = importlib.import_module(f"{__name__}.{_name}")
    except ModuleNotFoundError as _e:
        if _e.name != f"{__name__}.{_name}":
            raise
        continue
    for _k, _v in vars(_mod).items():
        if _is_public(_k, _v):
            globals()[_k] = _v

globals().update(REGISTRY)


def _vendor_surface() -> None:
    """The groups' structures, enums and constants that no module above defines, and a
    function for every declared-only name (it returns the declared code with a reason)."""
    from . import typedefs
    from .declared import declared_function
    from .table import FUNCTIONS, GROUPS

    g = globals()
    existing = {k: v for k, v in g.items() if _is_public(k, v) and isinstance(v, type)}
    tds = [td for grp in GROUPS for td in typedefs.parse(grp.structs, grp.name)]
    built = typedefs.build(tds, existing)
    for name, cls in built.classes.items():
        g.setdefault(name, cls)
    known = {k: v for k, v in g.items() if _is_public(k, v) and isinstance(v, int)}
    for td in built.enums.values():
        for member, value in td.members:
            g.setdefault(member, value)
    for grp in GROUPS:
        for name, value in typedefs.parse_constants(grp.constants, known).items():
            if name not in g:
                g[name] = known[name] = value
    for name, proto in FUNCTIONS.items():
        if name not in REGISTRY:
            for fn in declared_function(proto):
                g[fn.__name__] = fn
    typedefs.BUILT = built


#: the vendor surface (:func:`_vendor_surface`: ~2,900 declared-only functions, the groups'
#: structures, enums and constants) is made the first time anything asks for a name this
#: module does not hold yet, or for the whole namespace (``dir()``, ``from gtecat.gt import
#: *``, :func:`_whole`): a process that calls only emulated functions never pays for it
_made: list[bool] = []
_lock = _threading.RLock()


def _whole() -> dict[str, object]:
    """This module's namespace with the vendor surface made (what ``vars(gt)`` held before
    it was made lazily): walk this, not ``vars(gt)``."""
    if not _made:
        with _lock:
            if not _made:
                _vendor_surface()
                _made.append(True)
                # every name made: the module's own __getattr__ is of no use now, and while
                # a module has one CPython does not specialise the loads of its attributes
                # (``gt.GT_GetSts``: about 30 ns a load instead of 11)
                g = globals()
                g["__all__"] = [k for k in g if not k.startswith("_")]
                g.pop("__getattr__", None)
    return globals()


def __getattr__(name: str) -> object:
    if name == "__all__":  # ``from gtecat.gt import *``: every public name, made first
        return [k for k in _whole() if not k.startswith("_")]
    if not name.startswith("__") and not _made:
        g = _whole()
        if name in g:
            return g[name]
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(_whole())


def _arm_faults(ctl: object) -> None:
    """The machine TOML's ``[[fault]]`` tables are armed by :mod:`gtecat.faults` on every bus
    before it is brought up; that package (a tenth of this import's Python) is imported the
    first time a bus has them.  Once imported, its own hooks do the arming."""
    import sys

    if getattr(getattr(ctl, "machine", None), "faults", ()) and "gtecat.faults" not in sys.modules:
        from .. import faults

        faults._bus_opening(ctl)


def _install_fault_hook() -> None:
    import os

    from ..controller.core import Controller

    if _arm_faults not in Controller.bus_opening_hooks:
        Controller.bus_opening_hooks.append(_arm_faults)
    if os.environ.get("GTECAT_RECORD"):
        from .. import faults  # noqa: F401  (records this process's GT calls)


_install_fault_hook()
