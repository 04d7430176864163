"""The Googol-style ``GT_*`` API: ``from gtecat import gt``.

Every function of the manual with its ``GTN_*`` twin (``short core`` first),
the vendor-header EtherCAT extras, constants and ctypes structures, plus the
emulator-only ``GTE_*`` helpers.  Functions never raise: they return the
manual's codes and ``GTE_GetLastError()`` says why.
"""

from __future__ import annotations

import gc as _gc
import importlib
import sys as _sys
import threading as _threading

# The cyclic garbage collector is paused while this module is imported: the import makes
# ~100,000 objects that live as long as the process (classes, functions, tables, numpy's), and
# the collector ran ~170 times during it (a full pass among them) to find almost nothing: ~40
# ms of a ~300 ms import, ~20 ms with the pause (its first pass after the import walks them
# once; frozen at the end, never).  It runs as before once the import has ended (or failed).
_gc_was_on = _gc.isenabled()
_gc.disable()
try:
    from .. import numpy_with_one_blas_thread

    numpy_with_one_blas_thread()
    from ._core import REGISTRY
    from .vendor import install as _install_vendor_surface
    from .vendor import is_public as _is_public
except BaseException:
    if _gc_was_on:
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


#: the modules of :data:`_MODULES` a process that runs no program of its own
#: (``gtecat._SURFACE_LATER``: ``gtecat replay``) imports at once: the replay's own calls
#: (``GT_Open``, ``GT_Close``) and those a recorded session of axes mostly makes - its bus
#: brought up, its axes enabled, homed, moved in Trap and polled; the others (their
#: functions' making ~30 ms of such a process's start) with the vendor surface, at the first
#: name asked of the module that it does not hold (:func:`_make_surface`)
_FIRST = frozenset(
    (
        "bus_calls",
        "constants",
        "structs",
        "axis_calls",
        "homing_calls",
        "motion_calls",
        "status_calls",
    )
)


def _import_modules(names: tuple[str, ...] | frozenset[str]) -> None:
    """The modules of :data:`_MODULES` among ``names`` imported, in that order, and their
    public names (then every registered function) put in this namespace in that order: a
    name two modules define is the later one's, however many were imported before."""
    g = globals()
    for name in _MODULES:
        if name not in names:
            continue
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


try:
    _surface_later = bool(getattr(_sys.modules.get("gtecat"), "_SURFACE_LATER", False))
    _import_modules(_FIRST if _surface_later else _MODULES)
    #: the vendor surface (:mod:`gtecat.gt.vendor`: the groups' structures, enum members and
    #: constants, ~3,800 declared-only functions), every name in this namespace from here on
    #: (no module ``__getattr__``: CPython specialises ``gt.X`` only without one) - unless the
    #: process said it runs no program of its own (``gtecat._SURFACE_LATER``, set by ``gtecat
    #: replay`` before it imports this module): then the first name asked of the module that it
    #: does not hold makes it (:func:`__getattr__`), ~25 ms of such a process's start, with
    #: the GT modules not in :data:`_FIRST`
    if not _surface_later:
        _install_vendor_surface(globals(), REGISTRY)
    # what the import made lives as long as the process: moved out of the collector's walks
    # (its first pass after the import walked all of it, ~20 ms, and every full pass again)
    from ..controller.core import freeze_import

    freeze_import()
finally:
    if _gc_was_on:
        _gc.enable()


def _whole() -> dict[str, object]:
    """This module's namespace: every name of the surface (the vendor surface made first
    where it was left for later)."""
    if _surface_later:
        _make_surface()
    return globals()


_surface_lock = _threading.RLock()
#: the surface is being made by the thread holding the lock (a name asked of this module by
#: the modules it imports meanwhile is looked for as during an import: not made again)
_making = False


def _make_surface() -> None:
    """The GT modules and the vendor surface left for later, made once (the module's
    ``__getattr__`` and ``__dir__`` then go: the namespace is the one an ordinary import
    makes)."""
    global _surface_later, _making
    with _surface_lock:
        if _surface_later and not _making:
            _making = True
            try:
                # (every module again, in order: the names an ordinary import leaves)
                _import_modules(_MODULES)
                _install_vendor_surface(globals(), REGISTRY)
                for k in ("__getattr__", "__dir__"):
                    globals().pop(k, None)
                _surface_later = False
            finally:
                _making = False


if _surface_later:

    def __getattr__(name: str) -> object:
        """A name of the vendor surface left for later: the surface made, then the name."""
        if name.startswith("__"):  # (the import system's and pickle's questions)
            raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
        _make_surface()
        try:
            return globals()[name]
        except KeyError:
            raise AttributeError(f"module {__name__!r} has no attribute {name!r}") from None

    def __dir__() -> list[str]:
        _make_surface()
        return sorted(globals())


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
