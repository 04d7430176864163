"""The Googol-style ``GT_*`` API: ``from gtecat import gt``.

Every function of the manual with its ``GTN_*`` twin (``short core`` first),
the vendor-header EtherCAT extras, constants and ctypes structures, plus the
emulator-only ``GTE_*`` helpers.  Functions never raise: they return the
manual's codes and ``GTE_GetLastError()`` says why.
"""

from __future__ import annotations

import ctypes
import gc as _gc
import importlib
import threading as _threading

# The import below makes some hundred thousand long-lived objects (the modules, the function
# table, the GT functions, the vendor structures): the cyclic collector would walk them again
# and again while they are made (a tenth of the import, more when the modules are compiled
# from source).  Paused here, on again at the end of this module (as it was).
_GC_WAS_ON = _gc.isenabled()
_gc.disable()
try:
    from ._core import REGISTRY
except BaseException:
    if _GC_WAS_ON:
        _gc.enable()
    raise

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


def _load_modules() -> None:
    g = globals()
    for name in _MODULES:
        try:
            mod = importlib.import_module(f"{__name__}.{name}")
        except ModuleNotFoundError as e:
            if e.name != f"{__name__}.{name}":
                raise
            continue
        for k, v in vars(mod).items():
            if _is_public(k, v):
                g[k] = v
    g.update(REGISTRY)


#: the vendor surface (:func:`_vendor_surface`) is built at the first look at a name this
#: module does not hold yet: 0 not yet, 1 being built, 2 built
_SURFACE = [0]
_SURFACE_LOCK = _threading.RLock()


def _complete() -> None:
    """Build the vendor surface now, if it is not built yet: what looks at this module's
    namespace as a whole (``vars(gt)``) calls this first; an attribute, ``dir()`` and
    ``from gtecat.gt import *`` do it by themselves."""
    if _SURFACE[0]:
        return
    with _SURFACE_LOCK:
        if _SURFACE[0]:
            return
        _SURFACE[0] = 1
        paused = _gc.isenabled()
        _gc.disable()
        try:
            _vendor_surface()
        except BaseException:
            _SURFACE[0] = 0
            raise
        finally:
            if paused:
                _gc.enable()
        _SURFACE[0] = 2


def __getattr__(name: str) -> object:
    # (PEP 562: only for names the module does not hold) the vendor's thousands of
    # declared-only functions, structures and constants are made at the first look at one:
    # most programs never name one, and making them is a fifth of this module's import
    if not name.startswith("_"):
        _complete()
        try:
            return globals()[name]
        except KeyError:
            pass
    elif name == "__all__":  # from gtecat.gt import *: every public name, as without __all__
        _complete()
        return [k for k in globals() if not k.startswith("_")]
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    _complete()
    return sorted(globals())


def _vendor_surface() -> None:
    """The groups' structures, enums and constants that no module above defines, and a
    function for every declared-only name (it returns the declared code with a reason);
    built by :func:`_complete`."""
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


try:
    _load_modules()
    _install_fault_hook()
finally:
    if _GC_WAS_ON:
        _gc.enable()
