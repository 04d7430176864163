"""C spellings of what the GT layer declares in Python: structures, constants, parameter types.

The ctypes structures (``gtecat.gt.structs``, ``TSlaveInfo``) are the reference layout;
their C twin in ``gts.h`` is written field by field from ``_fields_`` so both agree
byte for byte on this machine (a test compiles ``sizeof``/``offsetof`` and compares).

``long`` in structures: the vendor header's structure fields written ``long`` are 32
bits (the vendor builds for Windows, where ``long`` is 32 bits) and the ctypes
structures declare them ``c_int32``.  On Linux ``long`` is 64 bits, so a C structure
field spelled ``long`` would change the layout.  ``gts.h`` therefore spells a 32-bit
field ``int`` (32 bits on every platform gcc/clang/MSVC target): assignments,
arithmetic and printing work as with ``long``; only ``long *p = &prm.homeOffset``
would need a cast.  Function parameters keep the vendor's ``long`` (the library
passes the C ``long`` of the client; the controller checks values to 32 bits).
"""

from __future__ import annotations

import ctypes
import functools
import hashlib
from collections.abc import Iterator
from dataclasses import dataclass

#: ctypes simple-type codes -> C type
_SIMPLE_C = {
    "c": "char",
    "b": "signed char",
    "B": "unsigned char",
    "h": "short",
    "H": "unsigned short",
    "i": "int",
    "I": "unsigned int",
    "l": "long",
    "L": "unsigned long",
    "q": "long long",
    "Q": "unsigned long long",
    "f": "float",
    "d": "double",
    "?": "unsigned char",  # ctypes c_bool: one byte; C99 _Bool and C++ bool differ in name
    "z": "char *",
    "P": "void *",
}


class CDeclError(ValueError):
    """A Python declaration has no faithful C spelling (bit fields, unions, ...)."""


def _base_and_dims(t: type) -> tuple[type, list[int]]:
    dims: list[int] = []
    while issubclass(t, ctypes.Array):
        dims.append(t._length_)
        t = t._type_
    return t, dims


def c_type(t: type, where: str = "") -> str:
    """The C spelling of a ctypes element type (no array dimensions)."""
    if issubclass(t, ctypes.Structure | ctypes.Union):
        return t.__name__
    if issubclass(t, ctypes._Pointer):
        return c_type(t._type_, where) + " *"
    if issubclass(t, ctypes._SimpleCData):
        code = t._type_
        if code in _SIMPLE_C:
            return _SIMPLE_C[code]
    raise CDeclError(f"{where}: no C spelling for ctypes type {t!r}")


def field_decl(name: str, t: type, where: str) -> str:
    """``double acc`` / ``char name[32]`` / ``short *pLineNo``."""
    base, dims = _base_and_dims(t)
    ct = c_type(base, where)
    suffix = "".join(f"[{d}]" for d in dims)
    if ct.endswith("*"):
        return f"{ct}{name}{suffix}"
    return f"{ct} {name}{suffix}"


def has_pointers(cls: type[ctypes.Structure]) -> bool:
    """A structure whose bytes mean nothing in another process (pointer fields)."""
    for _, t, *_ in cls._fields_:
        base, _ = _base_and_dims(t)
        if issubclass(base, ctypes._Pointer) or (
            issubclass(base, ctypes._SimpleCData) and base._type_ in "zZP"
        ):
            return True
        if issubclass(base, ctypes.Structure | ctypes.Union) and has_pointers(base):
            return True
    return False


def _deps(cls: type[ctypes.Structure]) -> Iterator[type[ctypes.Structure]]:
    for _, t, *_ in cls._fields_:
        base, _ = _base_and_dims(t)
        while issubclass(base, ctypes._Pointer):
            base = base._type_
        if issubclass(base, ctypes.Structure | ctypes.Union):
            yield base


def structures() -> list[type[ctypes.Structure]]:
    """Every structure ``from gtecat import gt`` exports, nested ones first."""
    return list(_structures())


@functools.cache
def _structures() -> tuple[type[ctypes.Structure], ...]:
    """gt's structures are made once, at its import: walked once."""
    from .. import gt

    found = {
        v.__name__: v
        for k, v in gt._whole().items()
        if k.startswith("T")
        and isinstance(v, type)
        and issubclass(v, ctypes.Structure | ctypes.Union)
    }
    out: list[type[ctypes.Structure]] = []
    seen: set[str] = set()

    def visit(cls: type[ctypes.Structure]) -> None:
        if cls.__name__ in seen:
            return
        seen.add(cls.__name__)
        for dep in _deps(cls):
            visit(dep)
        out.append(cls)

    for cls in found.values():  # definition order: the manual's, TSlaveInfo with bus calls
        visit(cls)
    return tuple(out)


def structure(name: str) -> type[ctypes.Structure]:
    """The ctypes structure the table names (``TTrapPrm``); KeyError if gt has none."""
    return _by_name()[name]


@functools.cache
def _by_name() -> dict[str, type[ctypes.Structure]]:
    return {cls.__name__: cls for cls in _structures()}


def struct_decl(cls: type[ctypes.Structure]) -> str:
    where = cls.__name__
    if getattr(cls, "_anonymous_", None):
        raise CDeclError(f"{where}: anonymous members are not supported")
    lines = []
    pack = getattr(cls, "_pack_", None)
    if pack:
        lines.append(f"#pragma pack(push, {int(pack)})")
    doc = (cls.__doc__ or "").strip().splitlines()
    if doc:
        text = doc[0].replace("``", "").replace("*/", "* /")
        lines.append(f"/* {text} */")
    kind = "union" if issubclass(cls, ctypes.Union) else "struct"
    lines.append(f"typedef {kind} {where} {{")
    for spec in cls._fields_:
        if len(spec) != 2:
            raise CDeclError(f"{where}.{spec[0]}: bit fields are not supported")
        name, t = spec
        lines.append(f"    {field_decl(name, t, f'{where}.{name}')};")
    lines.append(f"}} {where};")
    if pack:
        lines.append("#pragma pack(pop)")
    return "\n".join(lines)


@dataclass(frozen=True, slots=True)
class Constant:
    name: str
    value: int | float | str

    def define(self) -> str:
        v = self.value
        if isinstance(v, bool):
            text = str(int(v))
        elif isinstance(v, int):
            text = f"({v})" if v < 0 else str(v)
            if not -(1 << 31) <= v < (1 << 31):
                text = f"({v}LL)" if v < 0 else f"{v}ULL" if v >= (1 << 63) else f"{v}LL"
        elif isinstance(v, float):
            text = repr(v) if "e" in repr(v) or "." in repr(v) else repr(v) + ".0"
            if v < 0:
                text = f"({text})"
        else:
            esc = v.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n")
            text = f'"{esc}"'
        return f"#define {self.name} {text}"


def constants() -> list[Constant]:
    """The constants ``gt`` exports (DESIGN.md "The stable surface"), in definition order."""
    from .. import gt
    from ..gt import typedefs

    members = {n for td in typedefs.BUILT.enums.values() for n, _ in td.members}
    out = []
    for k, v in gt._whole().items():
        if k.startswith("_") or k.startswith(("GT_", "GTN_", "GTE_")) or k in members:
            continue
        if k.isupper() and len(k) > 1 and isinstance(v, int | float | str):
            out.append(Constant(k, v))
    return out


def enums() -> list[str]:
    """``typedef enum`` of every enum the groups declare (their members are not
    ``#define``d: C++ code passes them where the prototype names the enum)."""
    from .. import gt  # noqa: F401 - builds typedefs.BUILT
    from ..gt import typedefs

    return [typedefs.enum_decl(td) for td in typedefs.BUILT.enums.values()]


def layout_text() -> str:
    """Sizes and offsets of every structure (part of the protocol digest)."""
    parts = []
    for cls in structures():
        fields = ",".join(
            f"{f[0]}@{getattr(cls, f[0]).offset}:{getattr(cls, f[0]).size}" for f in cls._fields_
        )
        parts.append(f"{cls.__name__}({ctypes.sizeof(cls)};{fields})")
    return ";".join(parts)


def digest(*texts: str) -> str:
    h = hashlib.sha256()
    for t in texts:
        h.update(t.encode())
        h.update(b"\0")
    return h.hexdigest()[:16]


__all__ = [
    "CDeclError",
    "Constant",
    "c_type",
    "constants",
    "digest",
    "enums",
    "field_decl",
    "has_pointers",
    "layout_text",
    "struct_decl",
    "structure",
    "structures",
]
