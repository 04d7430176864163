"""Argument handling of every GT function, compiled from the function table.

One binder per function (:func:`binder`) turns what the caller passed into
checked values before the implementation runs, the same way for every
function:

* integer parameters take ints (numpy ints, ctypes integers, bools as C
  would); a float is accepted only where the C parameter is a ``double``;
  nan, inf, None and text are refused; a value outside the C type (``long``
  is the vendor's 32 bits) or the table's range is refused - never truncated;
* a pointer becomes a :class:`Ref`: the memory it points into is resolved to
  the ctypes object that owns it (``byref``, ``pointer``, ``cast``, arrays,
  ``create_string_buffer``, structures), so a write never goes past what that
  object owns; too small is refused with both sizes; a raw integer address is
  refused (its size cannot be known); Python containers (list, bytearray,
  memoryview, numpy arrays, bytes for inputs) work too;
* the element type of the memory must be the pointer's (the ctypes rule), decided by the
  element type and its size, never by the value: a ``double *`` takes 8-byte floats only
  (``c_double``, a float64 numpy array or ``'d'`` memoryview); an integer pointer takes
  integers of its C type's width, of either sign (C's view of the same memory: the value's
  bit pattern is stored, 40000 reads back as -25536 from a ``c_short`` for an ``unsigned
  short *``), or wider ones that hold every value of the C type (for the vendor's 32-bit
  ``long *``: ``c_int``, ``c_uint``, ``c_long`` - 64 bits on Linux -, int32, uint32 or
  int64 arrays; a 64-bit unsigned one cannot hold a negative ``long``); floats for an
  integer, integers for a double, narrower integers (a uint8 buffer for an ``unsigned long
  *``, ``c_short`` for a ``long *``), bools, chars and bytes/bytearrays are refused - the
  same for ctypes objects, numpy arrays, memoryviews and buffers, for inputs and outputs
  alike (Python lists are values, not memory: each value is checked);
* ``byref(s, offset)`` of a structure (C's ``&s.field``) points to the field at that
  offset: the call writes that field (its type must be the pointer's) and nothing else;
* a byte pointer (``unsigned char *``, ``char *``, ``void *``: raw data) takes plain
  memory only: memory holding pointers or Python objects (``py_object``, ``c_char_p``,
  ``c_void_p``, ``POINTER`` values, ``byref(pointer(x))``, arrays or structures holding
  such fields) is refused, as it is for numeric pointers; numpy arrays of Python
  objects, released and non-contiguous memoryviews are refused (they are not C memory);
* optional pointers accept ``None``, ``0`` and NULL ctypes pointers (they
  reach the implementation as ``None``); a required one given NULL is refused;
* parameter names as the manual writes them work as keywords;
* text parameters (``char *pFile``) take ``str``, ``bytes``, ``c_char_p`` or a
  char buffer and reach the implementation as ``str``.

Every refusal is a :class:`~gtecat.errors.ParameterError` (return code 7) that
names the parameter, what was given and what is legal.
"""

from __future__ import annotations

import ctypes
import inspect
import math
import numbers
import sys
from collections.abc import Callable
from types import FunctionType
from typing import Any

import numpy as np

from .._code_store import compiled as _compiled_code
from ..errors import ParameterError
from . import structs
from .table import ENUMS, SCALARS, Param, Proto

_CArgObject = type(ctypes.byref(ctypes.c_int()))
_SIMPLE = ctypes._SimpleCData
_POINTER = ctypes._Pointer
_CDATA = ctypes._SimpleCData.__mro__[1]  # ctypes._CData, the base of every ctypes instance
_NOT_NUMERIC = "?zZPOcu"  # ctypes codes of bool, char*, wchar*, void*, py_object, char, wchar
_FLOAT_CODES = "fdg"


def _struct_types() -> dict[str, type[ctypes.Structure]]:
    from ..native.cdecl import structures  # every structure gt exports (the groups' own too)
    from .bus_calls import TSlaveInfo  # defined beside its function

    out = {n: getattr(structs, n) for n in structs.__all__}
    out["TSlaveInfo"] = TSlaveInfo
    out.update({cls.__name__: cls for cls in structures()})
    return out


def shown(value: Any, limit: int = 60) -> str:
    """``repr(value)`` for a message, whatever the value: an integer of thousands of digits
    (``repr`` refuses past 4,300), an object whose ``repr`` raises, a huge container."""
    if isinstance(value, int) and value.bit_length() > 200:
        digits = int(value.bit_length() * 0.30103) + 1
        return f"{'-' if value < 0 else ''}<an integer of about {digits} digits>"
    if isinstance(value, list | tuple) and len(value) > 8:
        value = value[:8]
    try:
        r = repr(value)
    except Exception:
        r = f"<a {type(value).__name__}>"
    return r if len(r) <= limit else r[: limit - 3] + "..."


class Ref:
    """A checked pointer argument: the memory behind it and how much of it there is.

    ``addr``/``nbytes`` describe ctypes memory (``elem`` its element type, None
    for plain bytes); ``py`` holds a Python container instead.  (:func:`_ref` makes one
    without ``__init__``, for the compiled binder: the two set the same slots.)
    """

    __slots__ = ("_keep", "addr", "elem", "name", "nbytes", "py")

    def __init__(
        self,
        name: str,
        addr: int = 0,
        nbytes: int = 0,
        elem: Any = None,
        keep: Any = None,
        py: Any = None,
    ) -> None:
        self.name = name
        self.addr = addr
        self.nbytes = nbytes
        self.elem = elem
        self._keep = keep
        self.py = py

    # --- sizes ----------------------------------------------------------------------------
    def capacity(self) -> int:
        """Elements of ``elem`` behind the pointer (bytes for a byte buffer)."""
        if self.py is not None:
            if isinstance(self.py, np.ndarray):
                return self.py.size
            return len(self.py)
        size = ctypes.sizeof(self.elem) if self.elem is not None else 1
        return self.nbytes // size

    def byte_capacity(self) -> int:
        if self.py is not None:
            if isinstance(self.py, np.ndarray):
                return self.py.nbytes
            if isinstance(self.py, list):
                return len(self.py)
            return memoryview(self.py).nbytes
        return self.nbytes

    def growable(self) -> bool:
        return isinstance(self.py, list)

    def readonly(self) -> bool:
        """Memory the call cannot write (``bytes``, a read-only memoryview or numpy array)."""
        t = self.py
        if isinstance(t, bytes):
            return True
        if isinstance(t, memoryview):
            return t.readonly
        if isinstance(t, np.ndarray):
            return not t.flags.writeable
        return False

    # --- values ---------------------------------------------------------------------------
    def store_values(self, values: list[Any]) -> None:
        try:
            self._store_values(values)
        except ParameterError as e:
            if str(e).startswith("the value"):
                raise ParameterError(f"{self.name}: {e}") from None
            raise

    def _store_values(self, values: list[Any]) -> None:
        keep = self._keep
        if (
            len(values) == 1
            and type(keep) is self.elem
            and self.nbytes == ctypes.sizeof(keep)
            and isinstance(keep, _SIMPLE)  # byref(a structure) is refused below
            and keep._type_ not in _NOT_NUMERIC
        ):
            keep.value = fit(self.elem, values[0])  # byref(x) / x itself: the common case
            return
        n = len(values)
        if self.py is not None:
            t = self.py
            if isinstance(t, list):
                if len(t) < n:
                    t.extend([0] * (n - len(t)))
                t[:n] = values
                return
            if isinstance(t, np.ndarray):
                flat = _numeric_array(self.name, t)
                if flat.size < n:
                    raise ParameterError(f"{self.name}: array of {flat.size} too small for {n}")
                if flat.dtype.kind in "iu":  # (the same width, the other sign: its bits)
                    b = _int_bounds(flat.dtype.kind == "i", flat.dtype.itemsize)
                    values = [
                        _same_width(v, b) if isinstance(v, numbers.Integral) else v for v in values
                    ]
                try:
                    flat[:n] = values
                except (OverflowError, TypeError, ValueError):  # narrower than the C type
                    raise ParameterError(
                        f"{self.name}: {shown(values[:4])} do not fit a {t.dtype} array"
                    ) from None
                return
            raise ParameterError(f"{self.name}: a byte buffer cannot take numbers")
        have = self.capacity()
        if have < n:
            raise ParameterError(
                f"{self.name}: {self.nbytes} bytes behind the pointer hold {have} "
                f"{_elem_name(self.elem)}, {n} needed"
            )
        elem = self.elem
        if elem is None or not issubclass(elem, _SIMPLE) or elem._type_ in _NOT_NUMERIC:
            raise ParameterError(f"{self.name}: points to {_elem_name(elem)}, not to numbers")
        size = ctypes.sizeof(elem)
        for i, v in enumerate(values):
            elem.from_address(self.addr + i * size).value = fit(elem, v)

    def load_values(self, n: int) -> list[Any]:
        if self.py is not None:
            t = self.py
            if isinstance(t, np.ndarray):
                t = _numeric_array(self.name, t)
            if len(t) < n:
                raise ParameterError(f"{self.name}: {len(t)} element(s), {n} needed")
            out = [t[i] for i in range(n)]
            for v in out:
                if not isinstance(v, numbers.Real | np.bool_):  # ["x"], [None], [1j]
                    raise ParameterError(f"{self.name}: holds {shown(v)}, not a number")
            return out
        if self.capacity() < n:
            raise ParameterError(f"{self.name}: {self.capacity()} element(s), {n} needed")
        elem = self.elem
        if elem is None or not issubclass(elem, _SIMPLE):
            return list(ctypes.string_at(self.addr, n))
        if elem._type_ in _NOT_NUMERIC:  # create_string_buffer for a short *, as store_values
            raise ParameterError(f"{self.name}: points to {_elem_name(elem)}, not to numbers")
        size = ctypes.sizeof(elem)
        return [elem.from_address(self.addr + i * size).value for i in range(n)]

    # --- bytes ------------------------------------------------------------------------------
    def store_bytes(self, data: bytes) -> None:
        n = len(data)
        have = self.byte_capacity()
        if have < n and not self.growable():
            raise ParameterError(f"{self.name}: buffer of {have} bytes too small for {n} bytes")
        if self.py is None:
            ctypes.memmove(self.addr, data, n)
            return
        t = self.py
        if isinstance(t, list):
            if len(t) < n:
                t.extend([0] * (n - len(t)))
            t[:n] = list(data)
        elif isinstance(t, np.ndarray):
            t.reshape(-1).view(np.uint8)[:n] = np.frombuffer(data, dtype=np.uint8)
        else:
            memoryview(t).cast("B")[:n] = data

    def load_bytes(self, n: int) -> bytes:
        have = self.byte_capacity()
        if have < n:
            raise ParameterError(f"{self.name}: buffer of {have} bytes shorter than size {n}")
        if self.py is None:
            return ctypes.string_at(self.addr, n)
        t = self.py
        if isinstance(t, list):
            head = t[:n]
            if not all(isinstance(v, numbers.Integral) and -128 <= v <= 255 for v in head):
                bad = next(
                    v for v in head if not (isinstance(v, numbers.Integral) and -128 <= v <= 255)
                )
                raise ParameterError(
                    f"{self.name}: the list holds {shown(bad)}; bytes are integers -128..255"
                )
            return bytes(int(v) & 0xFF for v in head)
        if isinstance(t, np.ndarray):
            return t.reshape(-1).view(np.uint8)[:n].tobytes()
        return bytes(memoryview(t).cast("B")[:n])

    def struct(self, cls: type[ctypes.Structure]) -> ctypes.Structure:
        """The memory seen as ``cls`` (the caller's own same-layout class works too, but not
        one that holds pointers or Python objects where ``cls`` has numbers: the fields
        written over them would leave wild pointers)."""
        elem = self.elem
        if (
            self.py is None
            and elem is not None
            and elem is not cls
            and holds_pointers(elem)
            and not holds_pointers(cls)
        ):
            raise ParameterError(
                f"{self.name}: points to {_elem_name(elem)}, which holds pointers or Python "
                f"objects; pass a {cls.__name__} (or a structure of its layout)"
            )
        need = ctypes.sizeof(cls)
        if self.byte_capacity() < need:
            raise ParameterError(
                f"{self.name}: {self.byte_capacity()} bytes behind the pointer, "
                f"a {cls.__name__} needs {need}"
            )
        if self.py is None:
            return cls.from_address(self.addr)
        if isinstance(self.py, bytes):
            return cls.from_buffer_copy(self.py)
        try:
            return cls.from_buffer(self.py)
        except (TypeError, ValueError) as e:
            raise ParameterError(f"{self.name}: cannot view as {cls.__name__}: {e}") from None


_NEW = object.__new__


def _ref(name: str, addr: int, nbytes: int, elem: Any, keep: Any, _new: Any = _NEW) -> Ref:
    """``Ref(name, addr, nbytes, elem, keep)`` made without ``type.__call__`` (a third less:
    the compiled binder makes one for each pointer it binds)."""
    r = _new(Ref)
    r.name = name
    r.addr = addr
    r.nbytes = nbytes
    r.elem = elem
    r._keep = keep
    r.py = None
    return r


def _elem_name(elem: Any) -> str:
    if elem is None:
        return "bytes"
    return getattr(elem, "__name__", str(elem))


_INT_BOUNDS: dict[Any, tuple[int, int]] = {}


def fit(ctype: Any, value: Any) -> Any:
    """A value for a ctypes slot: a float into an integer type (``c_long`` where the
    prototype has ``double *``) is rounded, as a C conversion of the value would be; an
    integer that the slot cannot hold (``byref(c_ubyte())`` for a status word) is refused
    rather than cut down to a silently wrong value."""
    code = ctype._type_
    if code in _FLOAT_CODES:
        return value
    if isinstance(value, float):
        if not math.isfinite(value):
            return 0
        value = round(value)
    if isinstance(value, int) and code in "bBhHiIlLqQ":
        bounds = _INT_BOUNDS.get(ctype)
        if bounds is None:
            bits = 8 * ctypes.sizeof(ctype)
            bounds = (
                (0, (1 << bits) - 1)
                if code.isupper()
                else (-(1 << (bits - 1)), (1 << (bits - 1)) - 1)
            )
            _INT_BOUNDS[ctype] = bounds
        if not bounds[0] <= value <= bounds[1]:
            value = _same_width(value, bounds)
        if not bounds[0] <= value <= bounds[1]:
            raise ParameterError(
                f"the value {shown(value)} does not fit the {ctype.__name__} behind the pointer "
                f"({bounds[0]}..{bounds[1]}); pass the prototype's type"
            )
    return value


def _same_width(value: int, bounds: tuple[int, int]) -> int:
    """``value`` as the integer of ``bounds`` with its bit pattern, when it is an integer of
    the same width and the other sign (65535 -> -1 in 16 bits, -1 -> 65535): C's view of
    the same memory; any other value unchanged (its caller refuses it)."""
    lo, hi = bounds
    span = hi - lo + 1
    if lo < 0:
        return value - span if hi < value < span // 2 * 2 else value
    return value + span if -(span // 2) <= value < 0 else value


# --- resolving pointers --------------------------------------------------------------------------
def _null(value: Any) -> bool:
    if value is None or value is False:
        return True
    if isinstance(value, int) and not isinstance(value, bool) and value == 0:
        return True
    if isinstance(value, _POINTER):
        return not bool(value)
    if isinstance(value, ctypes.c_void_p | ctypes.c_char_p | ctypes.c_wchar_p):
        return value.value is None
    return False


_memmove = ctypes.memmove
_sizeof = ctypes.sizeof


def _address(arg: Any) -> int:
    """Where ``byref(x[, offset])`` or a ctypes pointer points (memmove of 0 bytes returns it)."""
    return _memmove(arg, arg, 0) or 0


def _owner(objects: Any, addr: int) -> Any:
    """The ctypes object among ``objects`` (a pointer's keep-alive tree) holding ``addr``."""
    stack = [objects]
    seen: set[int] = set()
    while stack and len(seen) < 1000:
        o = stack.pop()
        if id(o) in seen:
            continue
        seen.add(id(o))
        if isinstance(o, dict):
            stack.extend(o.values())
        elif isinstance(o, _CDATA):
            start = ctypes.addressof(o)
            if start <= addr < start + ctypes.sizeof(o) and not isinstance(o, _POINTER):
                return o
            b = getattr(o, "_objects", None)
            if b:
                stack.append(b)
    return None


def _element_type(obj: Any) -> Any:
    if isinstance(obj, ctypes.Array):
        t = obj._type_
        while issubclass(t, ctypes.Array):
            t = t._type_
        return t
    return type(obj)


def resolve(name: str, value: Any) -> Ref:
    """A :class:`Ref` for a non-NULL pointer-like argument (ParameterError if none fits)."""
    if isinstance(value, _CArgObject):
        obj = value._obj
        addr = _address(value)
        start = ctypes.addressof(obj)
        nbytes = start + ctypes.sizeof(obj) - addr
        if not 0 <= addr - start <= ctypes.sizeof(obj):
            raise ParameterError(f"{name}: byref offset outside its object")
        return Ref(name, addr=addr, nbytes=nbytes, elem=_element_type(obj), keep=obj)
    if isinstance(value, _POINTER):
        addr = (
            ctypes.memmove(value, value, 0) or 0
        )  # the pointer's value, without cast()'s side effects
        owner = _owner(getattr(value, "_objects", None), addr)
        if owner is None:
            raise ParameterError(
                f"{name}: the pointer leads into memory that no Python object owns, so its "
                "size cannot be checked; pass byref(x), pointer(x) or an array"
            )
        nbytes = ctypes.addressof(owner) + ctypes.sizeof(owner) - addr
        return Ref(name, addr=addr, nbytes=nbytes, elem=value._type_, keep=owner)
    if isinstance(value, ctypes.Array | ctypes.Structure | ctypes.Union):
        return Ref(
            name,
            addr=ctypes.addressof(value),
            nbytes=ctypes.sizeof(value),
            elem=_element_type(value),
            keep=value,
        )
    if isinstance(value, _SIMPLE):
        if value._type_ in "zZP":
            raise ParameterError(
                f"{name}: a {type(value).__name__} is a pointer value; pass a buffer "
                "(create_string_buffer) or byref(x)"
            )
        return Ref(
            name,
            addr=ctypes.addressof(value),
            nbytes=ctypes.sizeof(value),
            elem=type(value),
            keep=value,
        )
    if isinstance(value, memoryview):
        return Ref(name, py=_memoryview_array(name, value))
    if isinstance(value, np.ndarray):
        if value.dtype.hasobject:
            raise ParameterError(
                f"{name}: a numpy array of dtype {value.dtype} holds Python objects, not C "
                "memory; pass an array of numbers (or uint8 for bytes)"
            )
        if not value.flags.c_contiguous:
            raise ParameterError(f"{name}: numpy array must be C-contiguous")
        return Ref(name, py=value.view(np.ndarray))  # a matrix or masked array: its memory
    if isinstance(value, list | bytearray | bytes):
        return Ref(name, py=value)
    if isinstance(value, bool | int):
        raise ParameterError(
            f"{name}={shown(value)}: a raw address is not accepted (its size cannot be checked); "
            "pass byref(x), pointer(x) or an array"
        )
    tp = type(value)
    kind = tp.__name__ if tp.__module__ == "builtins" else f"{tp.__module__}.{tp.__qualname__}"
    raise ParameterError(
        f"{name}: {'an' if kind[:1].lower() in 'aeiou' else 'a'} {kind} is not a pointer "
        "argument; pass byref(x), pointer(x), a ctypes or numpy array, or 0/None for NULL"
    )


def _memoryview_array(name: str, view: memoryview) -> np.ndarray:
    """The memory of a memoryview as a numpy array over it (writable as the view is): one
    way to read and write it whatever its shape and format; a view with gaps (``[::2]``)
    or of Python objects is not C memory and is refused."""
    try:
        fmt = view.format
    except ValueError:  # released: any attribute raises
        raise ParameterError(
            f"{name}: the memoryview is released (its memory is gone); pass a live buffer"
        ) from None
    if "O" in fmt:
        raise ParameterError(f"{name}: a memoryview of Python objects is not C memory")
    if not view.c_contiguous:
        raise ParameterError(
            f"{name}: the memoryview is not contiguous (a slice with a step); pass "
            "bytes(view) for an input or a contiguous buffer"
        )
    try:
        arr = np.asarray(view)
    except (TypeError, ValueError, NotImplementedError):
        raise ParameterError(
            f"{name}: a memoryview of format {view.format!r} is not a plain buffer"
        ) from None
    if arr.dtype.hasobject:
        raise ParameterError(f"{name}: a memoryview of Python objects is not C memory")
    return arr


_NUMERIC_KINDS = "biuf"  # numpy dtype kinds a numeric pointer takes


def _numeric_array(name: str, arr: np.ndarray) -> np.ndarray:
    if arr.dtype.kind not in _NUMERIC_KINDS:
        raise ParameterError(
            f"{name}: a numpy array of dtype {arr.dtype} does not hold numbers; pass an "
            "integer or float array"
        )
    return arr.reshape(-1)


#: the vendor's integer types: their width (Windows, where ``long`` is 4 bytes) and the
#: ctypes type to pass for them (wider integers are taken: ``c_long`` is 8 bytes on Linux)
_C_WIDTH = {
    "char": 1, "unsigned char": 1, "short": 2, "unsigned short": 2, "int": 4,
    "unsigned int": 4, "long": 4, "unsigned long": 4, "long long": 8, "unsigned long long": 8,
}  # fmt: skip
_CTYPES_OF = {
    "short": "c_short", "unsigned short": "c_ushort", "int": "c_int", "unsigned int": "c_uint",
    "long": "c_long", "unsigned long": "c_ulong", "long long": "c_longlong",
    "unsigned long long": "c_ulonglong",
}  # fmt: skip


_HOLDS: dict[Any, bool] = {}


def holds_pointers(t: Any) -> bool:
    """Whether memory of ctypes type ``t`` holds pointers or Python objects (``py_object``,
    ``c_char_p``, ``c_void_p``, ``POINTER`` values, function pointers, or arrays and
    structures with such elements or fields): not raw memory, a write of bytes or numbers
    over it would leave a wild pointer."""
    r = _HOLDS.get(t)
    if r is None:
        r = _holds(t, 0)
        if len(_HOLDS) < 1024:
            _HOLDS[t] = r
    return r


def _holds(t: Any, depth: int) -> bool:
    if depth > 64:  # (a structure nested this deep: not plain memory either)
        return True
    if not isinstance(t, type):
        return False
    if issubclass(t, _POINTER | ctypes._CFuncPtr):
        return True
    if issubclass(t, _SIMPLE):
        return t._type_ in "zZPO"
    if issubclass(t, ctypes.Array):
        return _holds(t._type_, depth + 1)
    if issubclass(t, ctypes.Structure | ctypes.Union):
        return any(_holds(f[1], depth + 1) for k in t.__mro__ for f in vars(k).get("_fields_", ()))
    return False


def _int_bounds(signed: bool, size: int) -> tuple[int, int]:
    bits = 8 * size
    return (-(1 << (bits - 1)), (1 << (bits - 1)) - 1) if signed else (0, (1 << bits) - 1)


_NP_CANDIDATES = tuple(
    np.dtype(t)
    for t in (np.int8, np.int16, np.int32, np.int64, np.uint8, np.uint16, np.uint32, np.uint64)
)


def _element_fits(p: Param, kind: str, size: int) -> bool:
    """Whether an element of ``kind`` (``f`` float, ``i`` signed, ``u`` unsigned integer,
    anything else: not a number) and ``size`` bytes is the type of ``p``'s pointer: a float
    of the double's 8 bytes for a ``double *``; for an integer pointer an integer that holds
    every value of its C type (decided by the type, never by a value)."""
    if p.ctype in ("double", "float"):
        return kind == "f" and size == 8
    if kind not in "iu" or not kind:
        return False
    _, lo, hi, _ = SCALARS["int" if p.ctype in ENUMS else p.ctype]
    width = (hi - lo).bit_length() // 8
    if size != width:  # (the same width, either sign: C's view of the same memory)
        elo, ehi = _int_bounds(kind == "i", size)
        return elo <= lo and hi <= ehi
    return True


#: what to pass for a pointer of a C type, in a refusal's words (:func:`_what_to_pass`)
_ADVICE: dict[str, str] = {}


def _what_to_pass(p: Param) -> str:
    """What to pass for ``p``'s pointer, in a refusal's words: the same for every pointer
    of one C type, so made once per type (a program that polls with a wrong type pays a
    refusal at every call, and naming the dtypes cost more than the rest of it)."""
    advice = _ADVICE.get(p.ctype)
    if advice is not None:
        return advice
    if p.ctype in ("double", "float"):
        advice = "pass byref(c_double()), a c_double array or a float64 numpy array"
    else:
        right = _CTYPES_OF.get(p.ctype, "c_long")
        nps = [str(d) for d in _NP_CANDIDATES if _element_fits(p, d.kind, d.itemsize)]
        kinds = ", ".join(nps[:-1]) + " or " + nps[-1] if len(nps) > 1 else "".join(nps)
        advice = f"pass byref({right}()), an array of it or a numpy array of {kinds}"
    _ADVICE[p.ctype] = advice
    return advice


def check_kind(p: Param, ref: Ref) -> Ref:
    """Refuse memory whose element type is not the pointer's (the rule of the module's
    docstring, for ctypes objects, numpy arrays, memoryviews and byte buffers alike): a
    ``c_long`` or an int64 array where the prototype says ``double *``, a ``c_double`` or a
    float64 array for a ``long *``, a uint8 buffer for an ``unsigned long *`` - C would not
    compile the call, and the value would be silently rounded, cut or reinterpreted, or
    whether it fits would depend on the value.  Memory holding pointers or Python objects is
    refused for a byte pointer (raw data).  7 with the type to pass."""
    byte_ptr = p.ctype in ("char", "unsigned char", "void")
    if p.stars != 1:  # (char **pVersion: the call writes a pointer there)
        return ref
    if byte_ptr or p.text:
        elem = ref.elem
        if ref.py is None and elem is not None and holds_pointers(elem):
            raise ParameterError(
                f"{p.name}: points to {_elem_name(elem)}, which holds pointers or Python "
                "objects, not raw memory; pass a buffer (create_string_buffer, a c_ubyte "
                "array, a bytearray)"
            )
        return ref
    if p.is_struct or (p.ctype not in SCALARS and p.ctype not in ENUMS):
        return ref
    t = ref.py
    if t is not None:
        if isinstance(t, np.ndarray):
            d = t.dtype
            if d.kind in _NUMERIC_KINDS and not _element_fits(p, d.kind, d.itemsize):
                raise ParameterError(
                    f"{p.name}: memory of {d} elements, the prototype says {p.ctype} *; "
                    f"{_what_to_pass(p)}"
                )
        elif isinstance(t, bytes | bytearray):
            raise ParameterError(
                f"{p.name}: a {type(t).__name__} holds bytes, the prototype says {p.ctype} *; "
                f"{_what_to_pass(p)}"
            )
        return ref
    elem = ref.elem
    if isinstance(elem, type) and issubclass(elem, _SIMPLE) and elem._type_ in _NOT_NUMERIC:
        raise ParameterError(
            f"{p.name}: points to {_elem_name(elem)}, not to numbers; {_what_to_pass(p)}"
        )
    if isinstance(elem, type) and issubclass(elem, _SIMPLE):
        code = elem._type_
        kind = "f" if code in _FLOAT_CODES else "u" if code.isupper() else "i"
        size = ctypes.sizeof(elem)
        if not _element_fits(p, kind, size):
            want_float = p.ctype in ("double", "float")
            if (kind == "f") != want_float:
                why = ""
            elif want_float:
                why = f" ({size} bytes, a double is 8)"
            else:
                _, lo, hi, _ = SCALARS["int" if p.ctype in ENUMS else p.ctype]
                width = (hi - lo).bit_length() // 8
                why = (
                    f" ({size} bytes), narrower than {p.ctype} ({width} bytes)"
                    if size < width
                    else f" (unsigned, {size} bytes), which cannot hold a negative {p.ctype}"
                )
            raise ParameterError(
                f"{p.name}: points to {elem.__name__}{why}, the prototype says {p.ctype} *; "
                f"{_what_to_pass(p)}"
            )
    return ref


# --- scalars --------------------------------------------------------------------------------------
def _integer(p: Param, value: Any) -> int:
    v = value
    if isinstance(v, _SIMPLE) and v._type_ not in "zZPO":
        v = v.value
        if isinstance(v, bytes) and len(v) == 1:
            v = v[0]
    if isinstance(v, bool | np.bool_):
        return int(v)
    if isinstance(v, numbers.Integral):
        v = int(v)
    elif isinstance(v, float | np.floating):
        raise ParameterError(
            f"{p.name}={shown(value)}: an integer is needed ({p.ctype}), not a float"
        )
    else:
        raise ParameterError(f"{p.name}={shown(value)}: an integer is needed ({p.ctype})")
    _, lo, hi, _ = SCALARS["int" if p.ctype in ENUMS else p.ctype]  # a C enum is an int
    if p.mask:
        lo = min(lo, -(1 << 31))
        hi = max(hi, (1 << 32) - 1)
    if not lo <= v <= hi:
        raise ParameterError(f"{p.name}={shown(v)} out of range {lo}..{hi} ({p.ctype})")
    if p.lo is not None and not p.lo <= v <= p.hi:  # type: ignore[operator]
        raise ParameterError(f"{p.name}={shown(v)} out of range {p.lo:g}..{p.hi:g}")
    if p.mask and v < 0:
        v &= 0xFFFFFFFF
    return v


def _real(p: Param, value: Any) -> float:
    v = value
    if type(v) is not float and type(v) is not int:  # (the common arguments: no ABC check)
        if isinstance(v, _SIMPLE) and v._type_ not in "zZPOc":
            v = v.value
        if not isinstance(v, bool | np.bool_ | numbers.Real) or isinstance(v, str):
            raise ParameterError(f"{p.name}={shown(value)}: a number is needed (double)")
    try:
        x = float(v)
    except (OverflowError, ValueError, TypeError):
        raise ParameterError(f"{p.name}={shown(value)} is not a number") from None
    if not math.isfinite(x):
        raise ParameterError(f"{p.name}={shown(value)} must be finite")
    if p.lo is not None and not p.lo <= x <= p.hi:  # type: ignore[operator]
        raise ParameterError(f"{p.name}={x:g} out of range {p.lo:g}..{p.hi:g}")
    return x


_TEXT_MAX = 4096


def _text(p: Param, value: Any) -> str:
    v = value
    if isinstance(v, ctypes.c_char_p | ctypes.c_wchar_p):
        v = v.value
    elif isinstance(v, ctypes.Array) and v._type_ in (ctypes.c_char, ctypes.c_wchar):
        v = v.value
    elif isinstance(v, _CArgObject | _POINTER | ctypes.Array):
        ref = resolve(p.name, v)  # read what the buffer owns, up to its NUL
        v = ref.load_bytes(min(ref.byte_capacity(), _TEXT_MAX)).split(b"\0", 1)[0]
    if hasattr(v, "__fspath__"):
        v = str(v.__fspath__())
    if isinstance(v, bytes | bytearray):
        v = bytes(v).split(b"\0", 1)[0]
        try:
            v = v.decode("utf-8")
        except UnicodeDecodeError:
            v = v.decode("gbk", "replace")  # Chinese Windows paths
    if not isinstance(v, str):
        raise ParameterError(f"{p.name}={shown(value)}: text is needed (char *)")
    if "\0" in v:
        v = v.split("\0", 1)[0]
    if len(v) > _TEXT_MAX:
        raise ParameterError(f"{p.name}: text of {len(v)} characters, at most {_TEXT_MAX}")
    return v


# --- the binder ----------------------------------------------------------------------------------
Converter = Callable[[Any], Any]


def _int_converter(p: Param) -> Converter:
    """The integer check of ``p`` with its bounds precomputed; plain ints take the fast path."""
    _, lo, hi, _ = SCALARS["int" if p.ctype in ENUMS else p.ctype]  # a C enum is an int
    if p.mask:
        lo, hi = min(lo, -(1 << 31)), max(hi, (1 << 32) - 1)
    if p.lo is not None:
        lo, hi = max(lo, int(p.lo)), min(hi, int(p.hi))  # type: ignore[arg-type]
    mask = p.mask

    def conv(v: Any) -> int:
        if type(v) is int and lo <= v <= hi:
            return v & 0xFFFFFFFF if mask and v < 0 else v
        return _integer(p, v)

    return conv


def _pointer_converter(p: Param) -> Converter:
    name, optional, writes = p.name, p.optional, p.direction != "in"
    numbers_kind = _pointer_kind(p) == "numbers" and not p.text

    def conv(v: Any) -> Any:
        if type(v) is _CArgObject:  # byref(x): the common case
            obj = v._obj
            addr = _address(v)
            start = ctypes.addressof(obj)
            size = ctypes.sizeof(obj)
            if start <= addr <= start + size:
                if addr != start and numbers_kind and isinstance(obj, _STRUCTS):
                    # byref(s, offset): C's &s.field, the field and nothing else
                    return check_kind(p, _field_ref(name, obj, addr, addr - start))
                elem = obj._type_ if isinstance(obj, ctypes.Array) else type(obj)
                if isinstance(elem, type) and issubclass(elem, ctypes.Array):
                    elem = _element_type(obj)
                return check_kind(p, Ref(name, addr, start + size - addr, elem, obj))
        if _null(v):
            if optional:
                return None
            raise ParameterError(f"{name} is NULL; this pointer is required")
        ref = resolve(name, v)
        if writes and ref.readonly():
            raise ParameterError(
                f"{name}: a read-only {type(v).__name__} cannot take what the call writes; "
                "pass a bytearray, a writable array or a ctypes object"
            )
        return check_kind(p, ref)

    return conv


_STRUCTS = (ctypes.Structure, ctypes.Union)


def _field_at(cls: Any, off: int, depth: int = 0) -> tuple[Any, int] | None:
    """The field of structure ``cls`` that starts ``off`` bytes into it: (its element type,
    its bytes from there: an array field's rest), looking into nested structures and
    arrays; None when ``off`` is not the start of a plain field (padding, the middle of a
    field, a bit field)."""
    if depth > 32:
        return None
    for k in cls.__mro__:
        for f in vars(k).get("_fields_", ()):
            if len(f) > 2:  # a bit field: no address of its own
                continue
            fname, ftype = f[0], f[1]
            fo = getattr(cls, fname).offset
            fsize = ctypes.sizeof(ftype)
            if not fo <= off < fo + fsize:
                continue
            rel = off - fo
            if issubclass(ftype, _STRUCTS):
                found = _field_at(ftype, rel, depth + 1)
            elif issubclass(ftype, ctypes.Array):
                inner = ftype._type_
                while issubclass(inner, ctypes.Array):
                    inner = inner._type_
                step = ctypes.sizeof(inner)
                if issubclass(inner, _STRUCTS):
                    found = _field_at(inner, rel % step, depth + 1)
                else:
                    found = (inner, fsize - rel) if rel % step == 0 else None
            else:
                found = (ftype, fsize) if rel == 0 else None
            if found is not None:
                return found
    return None


def _field_ref(name: str, obj: Any, addr: int, off: int) -> Ref:
    """The :class:`Ref` of ``byref(obj, off)`` for a numeric pointer: the field there."""
    found = _field_at(type(obj), off)
    if found is None:
        raise ParameterError(
            f"{name}: byref of a {type(obj).__name__} at offset {off} is not the address of a "
            f"field; pass byref(s, {type(obj).__name__}.field.offset) of a field of the "
            "prototype's type"
        )
    elem, nbytes = found
    return Ref(name, addr, nbytes, elem, obj)


def _converter(p: Param) -> Converter:
    if p.pointer and p.text and p.direction == "in":
        return lambda v: None if p.optional and _null(v) else _text(p, v)
    if p.pointer:
        return _pointer_converter(p)
    if p.is_float:
        return lambda v: (
            v if type(v) is float and -_INF < v < _INF and p.lo is None else _real(p, v)
        )
    return _int_converter(p)


_INF = float("inf")


def impl_params(fn: Callable[..., Any]) -> tuple[list[str], list[str]]:
    """(the names of ``fn``'s parameters that are not keyword-only, with ``*args`` among them
    as ``inspect.signature`` lists it; its keyword-only ones): from the function's code where
    it is a plain function (nothing wraps it or states its signature), else from
    ``inspect.signature`` (the GT layer asks this of each of its ~400 functions at import)."""
    code = getattr(fn, "__code__", None)
    if (
        type(fn) is FunctionType
        and code is not None
        and not code.co_flags & (_CO_VARARGS | _CO_VARKEYWORDS)
        and "__wrapped__" not in fn.__dict__
        and "__signature__" not in fn.__dict__
    ):
        n, k = code.co_argcount, code.co_kwonlyargcount
        return list(code.co_varnames[:n]), list(code.co_varnames[n : n + k])
    sig = inspect.signature(fn)
    kw = inspect.Parameter.KEYWORD_ONLY
    return (
        [n for n, q in sig.parameters.items() if q.kind is not kw],
        [n for n, q in sig.parameters.items() if q.kind is kw],
    )


_CO_VARARGS = inspect.CO_VARARGS
_CO_VARKEYWORDS = inspect.CO_VARKEYWORDS


def binder(proto: Proto, impl: Callable[..., Any]) -> Callable[[tuple, dict], tuple[list, dict]]:
    """``bind(args, kwargs) -> (positional, extra keywords)`` for ``impl`` per ``proto``.

    The implementation receives the table's parameters positionally, converted;
    keyword-only parameters of ``impl`` that the table does not know (GT_Open's
    ``eni=...``) pass through as keywords.
    """
    params = proto.params
    names = [p.name for p in params]
    index = {n: i for i, n in enumerate(names)}
    convs = [_converter(p) for p in params]
    defaults: list[Any] = []
    for p in params:
        try:
            defaults.append(p.default_value())
        except KeyError:  # an optional pointer left out is NULL (Python callers omit them)
            defaults.append(None if p.optional else _MISSING)
    positional, keyword_only = impl_params(impl)
    impl_names = [n for n in positional if n != "ctl"]
    aliases = {a: names[i] for i, a in enumerate(impl_names[: len(names)]) if a != names[i]}
    extra_kw = set(keyword_only)
    # pointers whose room is checked after conversion: counted by another argument, or by a
    # fixed count; a byref() of one scalar holds one element by construction
    counted = [
        (i, index[p.count] if isinstance(p.count, str) else None, p.count)
        for i, p in enumerate(params)
        if p.pointer and not p.text and not p.is_struct and p.count != 0  # structs: when viewed
    ]
    n_params = len(params)
    core_first = proto.core_first_form

    tails = [tuple(defaults[n:]) for n in range(n_params + 1)]
    # the first parameter from n on that has no default (None: none), for every n
    first_missing: list[int | None] = [None] * (n_params + 1)
    for i in range(n_params - 1, -1, -1):
        first_missing[i] = i if defaults[i] is _MISSING else first_missing[i + 1]

    def missing(i: int) -> ParameterError:
        return ParameterError(
            f"bad arguments: {names[i]} is missing ({proto.name} takes {', '.join(names)})"
        )

    def slow(args: tuple, kwargs: dict) -> tuple[list, dict]:
        if core_first and len(args) == n_params + 1:
            # manual 5.2.2.5 prints GT_EcatIOReadInput(core, slave, ...): the core first
            core = _integer(_CORE, args[0])
            if core != 1:
                raise ParameterError(f"core={core}: the EtherCAT core is 1")
            args = args[1:]
        if len(args) > n_params:
            raise ParameterError(
                f"{len(args)} arguments given; {proto.name} takes {n_params} "
                f"({', '.join(names) or 'none'})"
            )
        values = list(args) + [_MISSING] * (n_params - len(args))
        extra = {}
        for k, v in kwargs.items():
            i = index.get(k)
            if i is None and k in aliases:
                i = index[aliases[k]]
            if i is None:
                if k in extra_kw:
                    extra[k] = v
                    continue
                raise ParameterError(
                    f"{proto.name} has no parameter {shown(k)} (it takes {', '.join(names)})"
                )
            if values[i] is not _MISSING:
                raise ParameterError(f"{proto.name}: {k} given twice")
            values[i] = v
        for i in range(n_params):
            if values[i] is _MISSING:
                values[i] = defaults[i]
                if values[i] is _MISSING:
                    raise missing(i)
        return values, extra

    def bind(args: tuple, kwargs: dict) -> tuple[list, dict]:
        n = len(args)
        extra: dict = {}
        if kwargs or n > n_params:
            values, extra = slow(args, kwargs)
        elif n == n_params:
            values = args
        else:
            if first_missing[n] is not None:
                raise missing(first_missing[n])
            values = args + tails[n]
        out = [c(v) for c, v in zip(convs, values)]  # noqa: B905 - one value per parameter
        for i, ci, count in counted:
            ref = out[i]
            if ref is not None:
                k = out[ci] if ci is not None else count
                if k == 1 and ref.elem is type(ref._keep) and ref.nbytes == _sizeof(ref.elem):
                    continue  # byref(x) of one scalar
                if type(k) is int and k > 0:
                    _check_room(params[i], ref, k)
        return out, extra

    bind.convs = convs  # type: ignore[attr-defined]  # (fast_binder compiles with them)
    return bind


# --- the compiled binder ----------------------------------------------------------------------
def _carg_address_offset() -> int | None:
    """Where a ``byref()`` object keeps the address it passes, in bytes from its start.

    ctypes offers no reader for it (``byref(obj, offset)`` looks like ``byref(obj)``), and
    its repr costs a microsecond; the field's place in CPython's ``PyCArgObject`` is found
    here by probing objects whose addresses are known, and used only when every probe,
    with and without an offset, agrees.  None: not found (the slower ways are used)."""
    try:
        size = sys.getsizeof(ctypes.byref(ctypes.c_int()))
        objs = [ctypes.c_long(), ctypes.c_int(), ctypes.c_double(), (ctypes.c_long * 3)()]
        for k in range(16, size - 7, 8):
            ok = True
            for obj in objs:
                for off in (0, 4, 8):
                    p = ctypes.byref(obj, off)
                    if ctypes.c_void_p.from_address(id(p) + k).value != ctypes.addressof(obj) + off:
                        ok = False
            if ok:
                return k
    except Exception:  # another implementation
        return None
    return None


#: see :func:`_carg_address_offset`
CARG_AT = _carg_address_offset() if sys.implementation.name == "cpython" else None
_from_address = ctypes.c_void_p.from_address


def _machine_words() -> memoryview | None:
    """The process's memory from ``CARG_AT`` on as machine words (``WORDS[id(p) >> 3]`` is
    the word ``CARG_AT`` bytes into the object ``p``: objects start on a word), to read the
    address a ``byref()`` holds in one indexing instead of making a ``c_void_p`` for it (a
    third of the cost of checking a fresh ``byref``).  Only an aligned word inside a live
    ``byref`` object is ever read.  None where it cannot be made or its reading disagrees
    with ``c_void_p.from_address`` (the slower reader is used)."""
    if CARG_AT is None or CARG_AT % 8 or ctypes.sizeof(ctypes.c_void_p) != 8:
        return None
    try:
        words = memoryview((ctypes.c_ubyte * (1 << 62)).from_address(CARG_AT)).cast("B").cast("Q")
        for obj in (ctypes.c_long(), ctypes.c_double(), (ctypes.c_int * 4)()):
            for off in (0, 8):
                p = ctypes.byref(obj, off)
                if id(p) % 8 or words[id(p) >> 3] != ctypes.addressof(obj) + off:
                    return None
        return words
    except Exception:  # a platform where it cannot be made
        return None


#: see :func:`_machine_words`
WORDS = _machine_words()


def carg_address_source(a: str) -> str:
    """Python source reading the address that the ``byref()`` named ``a`` passes, for the
    compiled fast paths; its names (``_WORDS``, ``_from_address``, ``_byref_address``) are
    in :data:`CARG_ENV`."""
    if WORDS is not None:
        return f"_WORDS[id({a}) >> 3]"
    if CARG_AT is not None:
        return f"_from_address(id({a}) + {CARG_AT}).value"
    return f"_byref_address({a})"


def byref_address(p: Any) -> int:
    """The address ``byref(obj[, offset])`` passes (where ctypes keeps it, or memmove's)."""
    if CARG_AT is not None:
        return _from_address(id(p) + CARG_AT).value or 0
    return _address(p)


#: the names :func:`carg_address_source`'s source uses
CARG_ENV = {"_WORDS": WORDS, "_from_address": _from_address, "_byref_address": byref_address}


def _numeric_types() -> list[type]:
    out = []
    for name in dir(ctypes):
        t = getattr(ctypes, name)
        if (
            name.startswith("c_")
            and isinstance(t, type)
            and issubclass(t, _SIMPLE)
            and t._type_ not in _NOT_NUMERIC
            and t not in out
        ):
            out.append(t)
    return out


_NUMERIC = _numeric_types()


def _scalar_types(p: Param) -> frozenset[type]:
    """The ctypes types whose ``byref(x)`` (or ``x`` itself) the table path takes for ``p``
    as one plain value (:func:`check_kind` passes; :meth:`Ref.store_values` writes ``x.value``).
    What decides it is the pointer's C type, stars and text-ness (the name only words the
    refusals): one answer for each of those, found once (the fast paths ask at import)."""
    key = (p.ctype, p.stars, p.text, p.ctype in ENUMS)
    ok = _SCALAR_TYPES.get(key)
    if ok is None:
        found = set()
        for t in _NUMERIC:
            try:
                check_kind(p, Ref(p.name, 0, ctypes.sizeof(t), t))
            except ParameterError:
                continue
            found.add(t)
        ok = _SCALAR_TYPES[key] = frozenset(found)
    return ok


_SCALAR_TYPES: dict[tuple[str, int, bool, bool], frozenset[type]] = {}


#: pointer shapes the compiled binder leaves to the table's converter, and why (a test walks
#: every pointer parameter of the table with every shape clients pass and fails on any other
#: shape that does not bind inline: tests/gtecat/gt/test_compiled_binder.py)
NOT_INLINE: dict[str, str] = {
    "pointer to pointer": "a char ** that the call points at text of its own (GT_GetVersion, "
    "called once): the converter resolves it",
}


def _pointer_kind(p: Param) -> str:
    """What a one-star pointer parameter points to: ``numbers``, ``struct`` or ``bytes``."""
    if p.is_struct:
        return "struct"
    return "bytes" if p.ctype in ("char", "unsigned char", "void") else "numbers"


def _learn(kind: str, ok: frozenset, cache: dict, t: Any) -> Any:
    """Whether the compiled binder takes a ctypes object of type ``t`` inline for a pointer
    of ``kind`` (``ok``: the number types it takes): the element type its :class:`Ref` has,
    as :func:`resolve` and :func:`check_kind` would make it, else False.  Kept in ``cache``."""
    e: Any = False
    if isinstance(t, type):
        if kind == "struct":
            e = t if issubclass(t, ctypes.Structure | ctypes.Union) else False
        elif issubclass(t, ctypes.Array):
            inner = t._type_
            if kind == "bytes":
                while issubclass(inner, ctypes.Array):
                    inner = inner._type_
                e = False if holds_pointers(inner) else inner  # (py_object: not raw memory)
            elif inner in ok:  # a one-dimensional array of a number the pointer takes
                e = inner
    if len(cache) < 256:
        cache[t] = e
    return e


def _pointer_source(i: int, p: Param, a: str, v: str, env: dict[str, Any]) -> list[str]:
    """The compiled binder's lines for one pointer parameter ``p`` (argument ``a``, value
    ``v``): the shapes clients pass, inline, each giving the :class:`Ref` that the table's
    converter ``C{i}`` gives for it - ``byref(x)`` (no offset) and ``x`` itself of a number
    the pointer takes, of a ctypes array of such numbers, of a structure; a ``bytearray``,
    ``bytes`` (read only), a ctypes array or a numpy array for a byte buffer; a numpy array
    of numbers; ``None`` or ``0`` for an optional NULL.  Any other shape: ``C{i}``."""
    kind = _pointer_kind(p)
    writes = p.direction != "in"
    ok = _scalar_types(p) if kind == "numbers" else frozenset()
    cache: dict[Any, Any] = {}
    env[f"OK{i}"] = ok
    env[f"AK{i}"] = cache
    env[f"L{i}"] = lambda t: _learn(kind, ok, cache, t)
    env["_NDARRAY"] = np.ndarray
    name = repr(p.name)
    at = carg_address_source(a)
    numpy = f"t is _NDARRAY and not {a}.dtype.hasobject and {a}.flags.c_contiguous" + (
        f" and {a}.flags.writeable" if writes else ""
    )
    if kind == "numbers":  # the element types the pointer takes (check_kind's rule)
        env[f"NP{i}"] = frozenset(
            d
            for d in (*_NP_CANDIDATES, np.dtype(np.float32), np.dtype(np.float64))
            if _element_fits(p, d.kind, d.itemsize)
        )
        numpy += f" and {a}.dtype in NP{i}"
    lines = [f"t = type({a})", "if t is _CArg:", f"    o = {a}._obj", "    to = type(o)"]
    if kind == "numbers":
        lines += [
            f"    if to in OK{i}: e = to",
            "    else:",
            f"        e = AK{i}.get(to)",
            f"        if e is None: e = L{i}(to)",
        ]
    else:
        lines += [f"    e = AK{i}.get(to)", f"    if e is None: e = L{i}(to)"]
    lines += [
        f"    if e and {at} == _addressof(o): {v} = _ref({name}, _addressof(o), _sizeof(o), e, o)",
        f"    else: {v} = C{i}({a})",
    ]
    if kind == "numbers":
        lines.append(f"elif t in OK{i}: {v} = _ref({name}, _addressof({a}), _sizeof({a}), t, {a})")
    if kind == "bytes":
        lines.append(f"elif t is bytearray: {v} = Ref({name}, py={a})")
        if not writes:
            lines.append(f"elif t is bytes: {v} = Ref({name}, py={a})")
    if p.optional:  # NULL as None or 0 (False and NULL ctypes pointers: the converter)
        lines.append(f"elif {a} is None or (t is int and {a} == 0): {v} = None")
    if kind != "struct":
        lines.append(f"elif {numpy}: {v} = Ref({name}, py={a})")
    lines += [
        "else:",
        f"    e = AK{i}.get(t)",
        f"    if e is None: e = L{i}(t)",
        f"    if e: {v} = _ref({name}, _addressof({a}), _sizeof({a}), e, {a})",
        f"    else: {v} = C{i}({a})",
    ]
    return lines


def fast_binder(
    proto: Proto, convs: list[Converter] | Callable[[], list[Converter]]
) -> Callable[..., Any]:
    """The table's checks of ``proto``'s arguments compiled into one function (declare once,
    generate the rest): ``bind(*args)`` -> the converted values, exactly what
    :func:`binder`'s ``bind`` gives for them, or None when any argument is not of a plain
    shape (a plain int or float in range, ``byref(x)`` or ``x`` of a ctypes number the
    pointer takes, None or 0 for an optional pointer, an omitted argument with a default,
    no more arguments than parameters) or the generic conversion (``convs``, one per
    parameter) refused it: the caller then binds through :func:`binder`, which gives the
    value or the refusal with its reason.  Never raises.

    ``convs`` may be a function giving them (the table binder's, made then): a call whose
    arguments are all plain never needs them, so a function's first call makes no table
    binder; the first argument of another shape asks for them, and they replace the stand-ins
    in the compiled function's globals."""
    params = proto.params
    env: dict[str, Any] = {
        "_CArg": _CArgObject,
        "_addressof": ctypes.addressof,
        "_sizeof": ctypes.sizeof,
        "_byref_address": byref_address,
        "_check_room": _check_room,
        "Ref": Ref,
        "_ref": _ref,
        "_MISSING": _MISSING,
        "_INF": _INF,
        "P": params,
    }
    env.update(CARG_ENV)
    if callable(convs):
        _later_converters(env, len(params), convs)

    sig, body, out = [], [], []
    for i, p in enumerate(params):
        a, v = f"a{i}", f"v{i}"
        # (default_value raises KeyError exactly where the table gives no default: an
        # optional pointer left out is NULL, Python callers omit them)
        if p.default is None:
            d = None if p.optional else _MISSING
        else:
            d = p.default_value()
        env[f"D{i}"] = d
        if not callable(convs):
            env[f"C{i}"] = convs[i]
        sig.append(f"{a}=D{i}")
        if d is _MISSING:
            body.append(f"if {a} is _MISSING: return None")
        scalar = p.ctype in SCALARS or p.ctype in ENUMS
        if not p.pointer and not p.is_float and scalar:
            _, lo, hi, _ = SCALARS["int" if p.ctype in ENUMS else p.ctype]
            if p.mask:
                lo, hi = min(lo, -(1 << 31)), max(hi, (1 << 32) - 1)
            if p.lo is not None:
                lo, hi = max(lo, int(p.lo)), min(hi, int(p.hi))  # type: ignore[arg-type]
            body.append(f"if type({a}) is int and {lo} <= {a} <= {hi}: {v} = {a}")
            body.append(f"else: {v} = C{i}({a})")
            if p.mask:
                body.append(f"if {v} < 0: {v} &= 0xFFFFFFFF")
        elif p.is_float and p.lo is None:
            body += [
                f"if type({a}) is float and -_INF < {a} < _INF: {v} = {a}",
                # an int the double holds exactly (GT_SetVel(axis, 10)): as _real converts it
                f"elif type({a}) is int and -{1 << 53} <= {a} <= {1 << 53}: {v} = float({a})",
                f"else: {v} = C{i}({a})",
            ]
        elif p.pointer and p.text and p.direction == "in":
            # text: a str as _text takes it (a file or variable name), inline
            body += [
                f"if type({a}) is str and len({a}) <= {_TEXT_MAX} and '\\0' not in {a}: {v} = {a}",
                f"else: {v} = C{i}({a})",
            ]
        elif p.pointer and p.stars == 1:  # (text the call writes: a buffer of bytes)
            body += _pointer_source(i, p, a, v, env)
        else:
            body.append(f"{v} = C{i}({a})")
        out.append(v)
    # the room of counted pointers, as binder's bind checks it
    index = {p.name: i for i, p in enumerate(params)}
    for i, p in enumerate(params):
        if p.pointer and not p.text and not p.is_struct and p.count != 0:
            v = f"v{i}"
            one = f"{v}.elem is type({v}._keep) and {v}.nbytes == _sizeof({v}.elem)"
            if isinstance(p.count, str):
                k = f"v{index[p.count]}"
                body += [
                    f"if {v} is not None and not ({k} == 1 and {one}) and type({k}) is int "
                    f"and {k} > 0:",
                    f"    _check_room(P[{i}], {v}, {k})",
                ]
            elif p.count == 1:  # (the same test with the count known)
                body += [f"if {v} is not None and not ({one}): _check_room(P[{i}], {v}, 1)"]
            elif p.count > 0:
                body += [f"if {v} is not None: _check_room(P[{i}], {v}, {p.count})"]
    lines = [f"def bind({', '.join([*sig, '*more'])}):", "    if more: return None", "    try:"]
    lines += [f"        {x}" for x in body] or ["        pass"]
    lines += [
        "    except Exception: return None",  # the table path gives the refusal
        f"    return ({', '.join(out)}{',' if len(out) == 1 else ''})",
    ]
    code = "\n".join(lines)
    exec(_compiled_code(code, f"<gt binder {proto.name}>"), env)
    fn = env["bind"]
    fn.source = code  # type: ignore[attr-defined]
    return fn


def _later_converters(env: dict[str, Any], n: int, make: Callable[[], list[Converter]]) -> None:
    """Stand-ins ``C0``.. ``C{n-1}`` in ``env`` (a compiled binder's globals) for the table's
    converters, made by ``make()`` when the first of them is called; they then take the
    stand-ins' places, so later calls reach them directly."""

    def stand_in(i: int) -> Converter:
        def conv(v: Any) -> Any:
            real = make()
            env.update((f"C{k}", c) for k, c in enumerate(real))
            return real[i](v)

        return conv

    env.update((f"C{i}", stand_in(i)) for i in range(n))


def _check_room(p: Param, ref: Ref, n: int) -> None:
    """Refuse a pointer that cannot hold the ``n`` elements the call moves (bytes for a
    ``char`` buffer); a list grows for an output."""
    if ref.growable() and p.direction == "out":
        return
    if p.ctype in ("unsigned char", "char"):
        have = ref.byte_capacity()
        if have < n:
            raise ParameterError(f"{p.name}: buffer of {have} bytes, the call moves {n}")
        return
    have = ref.capacity()
    if have < n:
        raise ParameterError(
            f"{p.name}: room for {have} value(s) behind the pointer, the call needs {n}"
        )


class _Missing:
    def __repr__(self) -> str:
        return "<missing>"


_MISSING: Any = _Missing()
_CORE = Param("core", "short")


def core_arg(value: Any) -> int:
    """The ``short core`` of a ``GTN_*`` call, checked like any argument."""
    return _integer(_CORE, value)


__all__ = [
    "CARG_ENV",
    "NOT_INLINE",
    "Ref",
    "binder",
    "byref_address",
    "carg_address_source",
    "core_arg",
    "fast_binder",
    "fit",
    "resolve",
]
