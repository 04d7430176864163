"""The C# face of the function table: ``gts.cs`` and the Mono dllmap that sends ``gts.dll``
to libgts.

``gts.cs`` is written the way the vendor's own C# wrapper is (``namespace gts``, ``public
class mc``, ``[DllImport("gts.dll")]`` with no calling convention, ``short`` returns), so
code written against the vendor's wrapper reads the same against this one:

* C ``long`` is ``int`` and ``unsigned long`` is ``uint`` (Windows' ``long`` has 32 bits);
* an output is ``out T``, a structure the function reads is ``ref T``, a text is ``string``
  (a text the function writes: ``StringBuilder`` with room for it);
* a pointer that takes ``count`` elements has two overloads: ``out T`` (one element, as the
  vendor writes it) and ``T[]`` (``count`` of them: ``GT_GetPrfVel(1, vel, 8, out clock)``);
  a fixed or unknown number of elements, and bytes (``byte[]``), are arrays;
* structures are ``[StructLayout(LayoutKind.Sequential)]`` with the C layout; an array
  field is unrolled into numbered fields as the vendor does (``profile1`` .. ``profile8``,
  ``pad1_1`` .. ``pad1_3``),
  which keeps the structure blittable; a ``char`` array is a ``ByValTStr`` string; a pointer
  field is ``IntPtr``;
* trailing scalar parameters keep the header's defaults (``GT_Open(short channel = 0, ...)``).

The program is compiled against ``gts.cs`` and runs on Mono with the dllmap of
:func:`mono_config` (``gtecat lib --mono-config``), which points ``gts.dll`` (and the
vendor's other library names ``gen.dll``, ``gxn.dll``) at ``libgts-llp64.so``
(:mod:`gtecat.native.llp64`): the build whose ``long`` has the 32 bits the C# side passes.
"""

from __future__ import annotations

import ctypes
import math
from pathlib import Path
from xml.sax.saxutils import quoteattr

from .. import __version__
from ..gt.table import ENUMS, FUNCTIONS, NO_CORE_TWINS, Param, Proto
from . import cdecl
from .protocol import table_digest

#: the DllImport names the vendor's wrappers load (Mono matches them case-insensitively
#: with the ``i:`` prefix); each maps to libgts
DLL_NAMES = ("gts.dll", "gts", "gen.dll", "gen", "gxn.dll", "gxn")

#: C scalar -> C# type (``long`` is Windows' 32-bit long)
SCALAR_CS = {
    "char": "sbyte",
    "unsigned char": "byte",
    "short": "short",
    "unsigned short": "ushort",
    "signed char": "sbyte",
    "int": "int",
    "unsigned int": "uint",
    "long": "int",
    "unsigned long": "uint",
    "long long": "long",
    "unsigned long long": "ulong",
    "double": "double",
    "float": "float",
}

#: ctypes type codes of structure fields -> C# type
_CODE_CS = {
    "b": "sbyte",
    "B": "byte",
    "?": "byte",
    "h": "short",
    "H": "ushort",
    "i": "int",
    "I": "uint",
    "l": "int",
    "L": "uint",
    "q": "long",
    "Q": "ulong",
    "f": "float",
    "d": "double",
    "z": "IntPtr",
    "P": "IntPtr",
}

#: C# keywords a C parameter name may collide with
_KEYWORDS = {
    *("abstract", "as", "base", "bool", "break", "byte", "case", "catch", "char", "checked"),
    *("class", "const", "continue", "decimal", "default", "delegate", "do", "double", "else"),
    *("enum", "event", "explicit", "extern", "false", "finally", "fixed", "float", "for"),
    *("foreach", "goto", "if", "implicit", "in", "int", "interface", "internal", "is", "lock"),
    *("long", "namespace", "new", "null", "object", "operator", "out", "override", "params"),
    *("private", "protected", "public", "readonly", "ref", "return", "sbyte", "sealed"),
    *("short", "sizeof", "stackalloc", "static", "string", "struct", "switch", "this", "throw"),
    *("true", "try", "typeof", "uint", "ulong", "unchecked", "unsafe", "ushort", "using"),
    *("virtual", "void", "volatile", "while"),
}


class CSharpError(ValueError):
    """A table entry with no faithful C# spelling."""


def _name(n: str) -> str:
    return f"@{n}" if n in _KEYWORDS else n


# --- structures -------------------------------------------------------------------------------
def _field_lines(name: str, t: type, where: str) -> list[str]:
    dims: list[int] = []
    while issubclass(t, ctypes.Array):
        dims.append(t._length_)
        t = t._type_
    if issubclass(t, ctypes._Pointer):
        cs = "IntPtr"
    elif issubclass(t, ctypes.Structure | ctypes.Union):
        cs = t.__name__
    elif issubclass(t, ctypes._SimpleCData) and t._type_ == "c" and len(dims) != 1:
        cs = "byte"  # one char (a separator), or a table of them: bytes, not a text
    elif issubclass(t, ctypes._SimpleCData) and t._type_ == "c":
        return [
            f"[MarshalAs(UnmanagedType.ByValTStr, SizeConst = {dims[0]})]",
            f"public string {name};",
        ]
    elif issubclass(t, ctypes._SimpleCData) and t._type_ in _CODE_CS:
        cs = _CODE_CS[t._type_]
    else:
        raise CSharpError(f"{where}: no C# spelling for {t!r}")
    if not dims:
        return [f"public {cs} {name};"]
    if len(dims) > 1:
        # an array of arrays (corrX[65][65]) is one flat array in C order: the vendor's
        # wrappers unroll short arrays into numbered fields, which thousands of fields are not
        return [
            f"[MarshalAs(UnmanagedType.ByValArray, SizeConst = {math.prod(dims)})]",
            f"public {cs}[] {name};  // [{']['.join(map(str, dims))}], row after row",
        ]
    sep = "_" if name[-1:].isdigit() else ""  # pad3 -> pad3_1, profile -> profile1
    return [f"public {cs} {name}{sep}{i};" for i in range(1, dims[0] + 1)]


def struct_decl(cls: type[ctypes.Structure], indent: str = "        ") -> list[str]:
    """``[StructLayout] public struct T { ... }`` with array fields unrolled."""
    where = cls.__name__
    pack = getattr(cls, "_pack_", None)
    union = issubclass(cls, ctypes.Union)
    layout = "LayoutKind.Explicit" if union else "LayoutKind.Sequential"
    layout += f", Pack = {int(pack)}" if pack else ""
    doc = (cls.__doc__ or "").strip().splitlines()
    out = []
    if doc:
        out.append(f"{indent}/// <summary>{_xml_text(doc[0])}</summary>")
    out += [f"{indent}[StructLayout({layout})]", f"{indent}public struct {where}", f"{indent}{{"]
    for spec in cls._fields_:
        if len(spec) != 2:
            raise CSharpError(f"{where}.{spec[0]}: bit fields are not supported")
        fname, t = spec
        lines = _field_lines(fname, t, f"{where}.{fname}")
        if union:  # every member at offset 0; an unrolled array's elements one after another
            step = ctypes.sizeof(t._type_) if issubclass(t, ctypes.Array) else 0
            members = [i for i, line in enumerate(lines) if not line.startswith("[")]
            if len(members) > 1:
                lines = [f"[FieldOffset({k * step})] {lines[i]}" for k, i in enumerate(members)]
            else:
                lines = ["[FieldOffset(0)]", *lines]
        out += [f"{indent}    {line}" for line in lines]
    out.append(f"{indent}}}")
    return out


def _xml_text(s: str) -> str:
    return s.replace("``", "").replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")


# --- constants --------------------------------------------------------------------------------
def constant_decl(c: cdecl.Constant) -> str:
    v = c.value
    if isinstance(v, bool):
        return f"public const short {c.name} = {int(v)};"
    if isinstance(v, int):
        for cs, lo, hi in (
            ("short", -(1 << 15), (1 << 15) - 1),
            ("int", -(1 << 31), (1 << 31) - 1),
            ("uint", 0, (1 << 32) - 1),
            ("long", -(1 << 63), (1 << 63) - 1),
        ):
            if lo <= v <= hi:
                suffix = "U" if cs == "uint" else "L" if cs == "long" else ""
                return f"public const {cs} {c.name} = {v}{suffix};"
        return f"public const ulong {c.name} = {v}UL;"
    if isinstance(v, float):
        return f"public const double {c.name} = {v!r};"
    esc = str(v).replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n")
    return f'public const string {c.name} = "{esc}";'


# --- functions --------------------------------------------------------------------------------
def _counted(p: Param) -> bool:
    """A pointer whose element count another parameter gives (``out[count]``) and that
    reads as one value too (``out double pValue``); bytes (``in[size]``) are always arrays."""
    return p.pointer and isinstance(p.count, str) and not p.text and not _bytes(p)


def _bytes(p: Param) -> bool:
    return p.pointer and not p.text and p.ctype in ("char", "unsigned char")


def _param_cs(p: Param, structs: set[str], *, arrays: bool) -> str:
    n = _name(p.name)
    if not p.pointer:
        if p.ctype in ENUMS:  # a C enum is an int
            return f"int {n}"
        if p.ctype in structs:  # a structure passed by value
            return f"{p.ctype} {n}"
        if p.ctype not in SCALAR_CS:
            raise CSharpError(f"{p.name}: scalar type {p.ctype!r} has no C# spelling")
        return f"{SCALAR_CS[p.ctype]} {n}"
    if p.text:
        return f"string {n}" if p.direction == "in" else f"StringBuilder {n}"
    if p.is_struct:
        cs = p.ctype if p.ctype in structs else None
        if cs is None:
            return f"IntPtr {n}"
    elif p.ctype in SCALAR_CS:
        cs = SCALAR_CS[p.ctype]
    elif p.ctype in ENUMS:
        cs = "int"
    elif p.ctype == "void":
        return f"IntPtr {n}"
    else:
        raise CSharpError(f"{p.name}: pointer to {p.ctype!r} has no C# spelling")
    many = p.count == 0 or (isinstance(p.count, int) and p.count > 1) or _bytes(p)
    if many or (arrays and _counted(p)):
        return f"[Out] {cs}[] {n}" if p.direction != "in" else f"{cs}[] {n}"
    if p.direction == "out":
        return f"out {cs} {n}"
    return f"ref {cs} {n}"  # in (the vendor's ref TTrapPrm) and inout


def _with_defaults(params: list[tuple[Param | None, str]]) -> list[str]:
    """The C++ defaults of the trailing scalar parameters (C# allows only trailing ones)."""
    out = [text for _, text in params]
    for i in range(len(params) - 1, -1, -1):
        p = params[i][0]
        if p is None or p.pointer or p.default is None:
            break
        out[i] = f"{out[i]} = {p.default}"
    return out


def _declarations(proto: Proto, structs: set[str]) -> list[str]:
    forms = [False, True] if any(_counted(p) for p in proto.params) else [False]
    out = []
    names = [proto.name]
    if proto.gtn:
        names.append("GTN_" + proto.name[3:])
    for name in names:
        for arrays in forms:
            if name != proto.name and proto.name in NO_CORE_TWINS:
                params: list[tuple[Param | None, str]] = [
                    (Param(n, "short", default=d), f"short {n}")
                    for n, d in NO_CORE_TWINS[proto.name]
                ]
            else:
                params = [(p, _param_cs(p, structs, arrays=arrays)) for p in proto.params]
                if name != proto.name:
                    params.insert(0, (None, "short core"))
            args = ", ".join(_with_defaults(params))
            out.append('        [DllImport("gts.dll")]')
            out.append(f"        public static extern short {name}({args});")
    return out


def render(namespace: str = "gts", cls: str = "mc") -> str:
    """The text of ``gts.cs``."""
    structures = cdecl.structures()
    structs = {s.__name__ for s in structures}
    lines = [
        f"// gts.cs - the GT API of gtecat {__version__} for C# (table {table_digest()}).",
        "//",
        "// Generated from the function table by gtecat.native.csharp: do not edit.",
        "// On Linux, run the program on Mono with the dllmap of `gtecat lib --mono-config`",
        "// (an App.exe.config beside the program) so gts.dll is libgts; on Windows, gtecat's",
        "// gts.dll.  C long is int here (Windows' long has 32 bits); every GT_x has its",
        "// GTN_x(short core, ...) twin; GTE_GetLastError says why the last call failed.",
        "using System;",
        "using System.Runtime.InteropServices;",
        "using System.Text;",
        "",
        f"namespace {namespace}",
        "{",
        f"    public class {cls}",
        "    {",
    ]
    lines += [f"        {constant_decl(c)}" for c in cdecl.constants()]
    lines.append("")
    for s in structures:
        lines += [*struct_decl(s), ""]
    for proto in FUNCTIONS.values():
        lines += _declarations(proto, structs)
    if "GTE_GetLastError" not in FUNCTIONS:  # the library's own (LAST_ERROR_PROTOTYPE)
        lines += [
            "",
            "        /// <summary>Why this process's last non-zero return happened.</summary>",
            '        [DllImport("gts.dll")]',
            "        public static extern short GTE_GetLastError(StringBuilder buf, short size);",
        ]
    lines += [
        "    }",
        "}",
        "",
    ]
    return "\n".join(lines)


# --- the Mono dllmap ----------------------------------------------------------------------------
def mono_config(library: Path | str) -> str:
    """A Mono configuration mapping the vendor's DLL names to ``library``.

    As ``App.exe.config`` beside ``App.exe`` (or ``Lib.dll.config`` beside the assembly that
    holds the ``DllImport``s) it adds to Mono's own maps; given as ``MONO_CONFIG`` it
    replaces Mono's system file, so the system file's maps are carried along when present
    (:func:`system_maps`)."""
    target = quoteattr(str(library))
    lines = [
        '<?xml version="1.0" encoding="utf-8"?>',
        f"<!-- gtecat {__version__}: the vendor's DLL names on libgts (the Windows-long build,",
        "     so C# int / uint meet C long / unsigned long).  Beside App.exe as App.exe.config,",
        "     or MONO_CONFIG=this-file mono App.exe.  Written by gtecat's lib command (mono",
        "     config); write it again after upgrading gtecat (the library's folder changes). -->",
        "<configuration>",
    ]
    for dll in DLL_NAMES:
        lines.append(f'  <dllmap dll="i:{dll}" target={target} os="!windows"/>')
    system = system_maps()
    if system:
        lines.append("  <!-- Mono's own maps (from its system configuration) -->")
        lines += [f"  {m}" for m in system]
    lines += ["</configuration>", ""]
    return "\n".join(lines)


def system_maps(path: Path = Path("/etc/mono/config")) -> list[str]:
    """The ``<dllmap>`` lines of Mono's system configuration (none when it is absent), so a
    file given as ``MONO_CONFIG`` keeps what Mono's class libraries map."""
    import xml.etree.ElementTree as ET

    try:
        root = ET.fromstring(path.read_text(encoding="utf-8"))
    except (OSError, ET.ParseError):
        return []
    out = []
    for el in root:
        if el.tag == "dllmap" and "gts" not in el.get("dll", "").lower():
            out.append(ET.tostring(el, encoding="unicode").strip())
    return out


__all__ = [
    "DLL_NAMES",
    "SCALAR_CS",
    "CSharpError",
    "constant_decl",
    "mono_config",
    "render",
    "struct_decl",
    "system_maps",
]
