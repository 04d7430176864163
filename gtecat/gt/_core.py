"""The GT layer's machinery: return codes, the last-error ring, pointer arguments, GTN twins.

Every ``GT_*`` function is a thin wrapper over :class:`gtecat.controller.core.Controller`.
:func:`gt_function` turns exceptions into the manual's return codes through
one table (manual table 3-1) and keeps the reason (SOEM's error ring), so a GT
function never raises.  Pointer arguments accept what ctypes code passes:
``byref(c_short())``, ``pointer(...)``, ctypes arrays and string buffers, a
writable ``bytearray``/``memoryview``/numpy array, or a one-element list.
"""

from __future__ import annotations

import ctypes
import functools
import inspect
import logging
import traceback
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from drives.abort import SdoAbort
from drives.machine import MachineError
from eni.errors import EniError, GtecatError

from ..controller.core import Controller
from ..errors import (
    BusError,
    CommandError,
    ConfigMismatch,
    NoEniError,
    NoSlavesError,
    ParameterError,
)

log = logging.getLogger("gtecat.gt")

# manual table 3-1 and GT_InitEcatComm's codes
CMD_OK = 0
CMD_ERROR = 1
CMD_PARAM = 7
CMD_COMM = -1
CMD_OPEN = -6
CMD_NO_RESPONSE = -7
ECAT_MISMATCH = -8
ECAT_NO_ENI = -9
ECAT_NO_SLAVES = -10

#: exception type -> return code; first match wins (subclasses before bases)
ERROR_CODES: tuple[tuple[type[BaseException], int], ...] = (
    (ParameterError, CMD_PARAM),
    (CommandError, CMD_ERROR),
    (SdoAbort, CMD_ERROR),
    (ConfigMismatch, ECAT_MISMATCH),
    (NoEniError, ECAT_NO_ENI),
    (NoSlavesError, ECAT_NO_SLAVES),
    (EniError, ECAT_MISMATCH),
    (MachineError, CMD_PARAM),
    (BusError, CMD_ERROR),
    (GtecatError, CMD_ERROR),
)


class NotOpen(GtecatError):
    """A GT call before GT_Open (the host cannot reach a controller: -1)."""


@dataclass(frozen=True, slots=True)
class LastError:
    function: str
    code: int
    reason: str
    clock_ms: int


class _Session:
    """The open cores (core 1 is the EtherCAT core) and the error ring."""

    def __init__(self) -> None:
        self.controllers: dict[int, Controller] = {}
        self.errors: deque[LastError] = deque(maxlen=64)

    def controller(self, core: int = 1) -> Controller:
        c = self.controllers.get(core)
        if c is None:
            if core != 1 and 1 in self.controllers:
                raise ParameterError(f"core {core} does not exist; the EtherCAT core is 1")
            raise NotOpen("the controller is not open: call GT_Open first")
        return c


SESSION = _Session()
REGISTRY: dict[str, Callable[..., int]] = {}


def code_for(exc: BaseException) -> int:
    if isinstance(exc, NotOpen):
        return CMD_COMM
    for etype, code in ERROR_CODES:
        if isinstance(exc, etype):
            return code
    return CMD_NO_RESPONSE


def _record(name: str, code: int, reason: str) -> None:
    ms = 0
    c = SESSION.controllers.get(1)
    if c is not None:
        ms = c.clock_ms()
    SESSION.errors.append(LastError(name, code, reason, ms))


def fail(code: int, reason: str) -> int:
    """Return ``code`` from a GT function with a reason (for non-exception refusals)."""
    raise _Refusal(code, reason)


class _Refusal(Exception):
    def __init__(self, code: int, reason: str) -> None:
        super().__init__(reason)
        self.code = code


def gt_function(fn: Callable[..., int | None]) -> Callable[..., int]:
    """Make ``fn`` a GT function: never raises, returns a code, costs a host call.

    ``fn`` receives the core's :class:`Controller` as its first argument (or
    nothing when it is declared with ``needs_controller = False``) and returns
    ``None``/0 on success.  Registers ``GT_x`` and its ``GTN_x`` twin.
    """
    name = fn.__name__
    signature = inspect.signature(fn)
    params = list(signature.parameters)
    needs_ctl = bool(params) and params[0] == "ctl"

    def call(core: int, args: tuple, kwargs: dict) -> int:
        ctl = None
        try:
            if needs_ctl:
                ctl = SESSION.controller(core)
                if ctl.clock.threaded:
                    with ctl.clock.lock:  # atomic with respect to the cycle thread
                        rc = fn(ctl, *args, **kwargs)
                else:
                    rc = fn(ctl, *args, **kwargs)
            else:
                rc = fn(*args, **kwargs)
            rc = 0 if rc is None else int(rc)
        except _Refusal as r:
            rc = r.code
            _record(name, rc, str(r))
        except TypeError as e:
            try:  # the caller's arguments do not fit the prototype: 7; else a bug inside
                signature.bind(*((None,) if needs_ctl else ()), *args, **kwargs)
            except TypeError:
                rc = CMD_PARAM
                _record(name, rc, f"bad arguments: {e}")
            else:
                rc = CMD_NO_RESPONSE
                log.error("%s: internal error\n%s", name, traceback.format_exc())
                _record(name, rc, f"internal error in the emulator: TypeError: {e}")
        except Exception as e:  # the GT layer never raises
            rc = code_for(e)
            if rc == CMD_NO_RESPONSE:
                log.error("%s: internal error\n%s", name, traceback.format_exc())
                _record(name, rc, f"internal error in the emulator: {type(e).__name__}: {e}")
            else:
                _record(name, rc, str(e))
        if ctl is None:
            ctl = SESSION.controllers.get(core)
        if ctl is not None:
            ctl.clock.on_call()
        return rc

    @functools.wraps(fn)
    def gt(*args: Any, **kwargs: Any) -> int:
        return call(1, args, kwargs)

    def gtn(core: int, *args: Any, **kwargs: Any) -> int:
        return call(int(core), args, kwargs)

    if needs_ctl:
        sig = inspect.signature(fn)
        gt.__signature__ = sig.replace(parameters=list(sig.parameters.values())[1:])  # type: ignore[attr-defined]
    gtn.__name__ = "GTN_" + name[3:]
    gtn.__doc__ = f"``{name}`` with ``short core`` first (core 1 is the EtherCAT core)."
    REGISTRY[name] = gt
    REGISTRY[gtn.__name__] = gtn
    return gt


def last_error() -> LastError | None:
    return SESSION.errors[-1] if SESSION.errors else None


# --- pointer arguments ---------------------------------------------------------------------
def _target(ptr: Any) -> Any:
    if type(ptr).__name__ == "CArgObject":
        return ptr._obj
    return ptr


def store(ptr: Any, value: Any) -> None:
    """``*ptr = value`` for whatever pointer-like thing the caller passed (None = NULL)."""
    if ptr is None:
        return
    t = _target(ptr)
    if isinstance(t, ctypes._SimpleCData):
        t.value = _fit(type(t), value)
    elif isinstance(t, ctypes._Pointer | ctypes.Array):
        t[0] = _fit(t._type_, value)
    elif isinstance(t, np.ndarray):
        t[0] = value
    elif isinstance(t, list):
        if t:
            t[0] = value
        else:
            t.append(value)
    elif isinstance(t, ctypes.Structure):
        raise ParameterError(f"expected a pointer to a number, got a {type(t).__name__}")
    elif hasattr(t, "value"):
        t.value = value
    else:
        raise ParameterError(f"argument of type {type(ptr).__name__} is not a writable pointer")


_FLOAT_TYPES = (ctypes.c_float, ctypes.c_double, ctypes.c_longdouble)


def _fit(ctype: Any, value: Any) -> Any:
    """A value for a ctypes slot: a float into an integer type (``c_long`` where the
    prototype has ``double *``) is rounded, as a C conversion of the value would be."""
    if (
        isinstance(value, float)
        and isinstance(ctype, type)
        and issubclass(ctype, ctypes._SimpleCData)
    ):
        if not issubclass(ctype, _FLOAT_TYPES) and ctype._type_ not in "?cuzZPO":
            return round(value)
    return value


def store_array(ptr: Any, values: list[Any]) -> None:
    """Write ``values`` into an array argument (ctypes array, numpy, list, pointer)."""
    if ptr is None:
        return
    t = _target(ptr)
    if isinstance(t, ctypes._SimpleCData):
        if len(values) > 1:
            raise ParameterError(f"count {len(values)} needs an array, got a single value")
        t.value = _fit(type(t), values[0])
        return
    if isinstance(t, ctypes.Array | np.ndarray | list | ctypes._Pointer):
        if not isinstance(t, ctypes._Pointer) and len(t) < len(values):
            if isinstance(t, list):
                t.extend([0] * (len(values) - len(t)))
            else:
                raise ParameterError(f"array of {len(t)} too small for {len(values)} values")
        elem = getattr(t, "_type_", None)
        for i, v in enumerate(values):
            t[i] = _fit(elem, v)
        return
    raise ParameterError(f"argument of type {type(ptr).__name__} is not a writable array")


def load(ptr: Any) -> Any:
    """``*ptr`` (or the value itself when a plain number is passed)."""
    t = _target(ptr)
    if isinstance(t, ctypes._SimpleCData):
        return t.value
    if isinstance(t, ctypes._Pointer | ctypes.Array | np.ndarray | list):
        return t[0]
    return t


def store_bytes(ptr: Any, data: bytes) -> None:
    """Copy raw bytes into a buffer argument (``unsigned char *pValue``)."""
    if ptr is None:
        raise ParameterError("pValue is NULL")
    t = _target(ptr)
    n = len(data)
    if isinstance(t, ctypes._SimpleCData | ctypes.Array | ctypes.Structure):
        if ctypes.sizeof(t) < n:
            raise ParameterError(f"buffer of {ctypes.sizeof(t)} bytes too small for {n} bytes")
        ctypes.memmove(ctypes.addressof(t), data, n)
        return
    if isinstance(t, ctypes._Pointer):
        ctypes.memmove(t, data, n)
        return
    if isinstance(t, bytearray | memoryview):
        if len(t) < n:
            raise ParameterError(f"buffer of {len(t)} bytes too small for {n} bytes")
        t[:n] = data
        return
    if isinstance(t, np.ndarray):
        view = t.reshape(-1).view(np.uint8)
        if view.size < n:
            raise ParameterError(f"buffer of {view.size} bytes too small for {n} bytes")
        view[:n] = np.frombuffer(data, dtype=np.uint8)
        return
    if isinstance(t, list):
        t[:n] = list(data)
        return
    raise ParameterError(f"argument of type {type(ptr).__name__} is not a writable buffer")


def load_bytes(ptr: Any, n: int) -> bytes:
    """Read ``n`` bytes from a buffer argument (``unsigned char *pValue``)."""
    if ptr is None:
        raise ParameterError("pValue is NULL")
    t = _target(ptr)
    if isinstance(t, bytes | bytearray | memoryview):
        if len(t) < n:
            raise ParameterError(f"buffer of {len(t)} bytes shorter than size {n}")
        return bytes(t[:n])
    if isinstance(t, ctypes._SimpleCData | ctypes.Array | ctypes.Structure):
        if ctypes.sizeof(t) < n:
            raise ParameterError(f"buffer of {ctypes.sizeof(t)} bytes shorter than size {n}")
        return ctypes.string_at(ctypes.addressof(t), n)
    if isinstance(t, ctypes._Pointer):
        return ctypes.string_at(t, n)
    if isinstance(t, np.ndarray):
        b = t.reshape(-1).view(np.uint8)
        if b.size < n:
            raise ParameterError(f"buffer of {b.size} bytes shorter than size {n}")
        return b[:n].tobytes()
    if isinstance(t, list):
        if len(t) < n:
            raise ParameterError(f"buffer of {len(t)} bytes shorter than size {n}")
        return bytes(int(v) & 0xFF for v in t[:n])
    if isinstance(t, int) and n <= 8:
        return (t & ((1 << (8 * n)) - 1)).to_bytes(n, "little")
    raise ParameterError(f"argument of type {type(ptr).__name__} is not a readable buffer")


def check_range(name: str, value: int, lo: int, hi: int) -> int:
    try:
        v = int(value)
    except (TypeError, ValueError):
        raise ParameterError(f"{name}={value!r} is not an integer") from None
    if not lo <= v <= hi:
        raise ParameterError(f"{name}={v} out of range {lo}..{hi}")
    return v
