"""The C client stubs of ``libgts.so``, generated from the function table.

Two files: ``gts_wire.h`` (the protocol's numbers, from :mod:`gtecat.native.protocol`)
and ``gts_stubs.c``: per table line a parameter descriptor and the exported
``GT_x`` / ``GTN_x`` (or ``GTE_x``) functions, each of which only fills an argument
array and calls ``gte_invoke`` (``csrc/gts_runtime.c``, hand-written, does the rest).
"""

from __future__ import annotations

import re
import socket

from .. import __version__
from ..gt._core import CMD_DECLARED
from ..gt.table import ENUMS, GROUPS, NO_CORE_TWINS, SAME_PARAM_TWINS, SCALARS, Proto
from .protocol import (
    CALL_GTN,
    CARD_SHIFT,
    CHUNK,
    MAX_FRAME,
    MAX_POINTER_BYTES,
    MSG_CALL,
    MSG_HELLO,
    PROTOCOL_VERSION,
    PTR_NULL,
    PTR_TOO_BIG,
    PTR_UNKNOWN,
    SOCKET_TYPE,
    FunctionPlan,
    Kind,
    plans,
    table_digest,
)

_SOCKET_NAMES = {socket.SOCK_SEQPACKET: "SOCK_SEQPACKET", socket.SOCK_STREAM: "SOCK_STREAM"}


def render_wire_h() -> str:
    lines = [
        f"/* gts_wire.h - protocol numbers of gtecat {__version__}; generated from",
        " * gtecat/native/protocol.py by gtecat.native.stubs: do not edit. */",
        "#ifndef GTECAT_GTS_WIRE_H",
        "#define GTECAT_GTS_WIRE_H",
        f"#define GTE_PROTOCOL_VERSION {PROTOCOL_VERSION}",
        f'#define GTE_TABLE_DIGEST "{table_digest()}"',
        f"#define GTE_MSG_HELLO {MSG_HELLO}",
        f"#define GTE_MSG_CALL {MSG_CALL}",
        f"#define GTE_CALL_GTN {CALL_GTN}",
        f"#define GTE_CARD_SHIFT {CARD_SHIFT}",
        f"#define GTE_PTR_NULL ({PTR_NULL})",
        f"#define GTE_PTR_UNKNOWN ({PTR_UNKNOWN})",
        f"#define GTE_PTR_TOO_BIG ({PTR_TOO_BIG})",
        f"#define GTE_MAX_POINTER_BYTES {MAX_POINTER_BYTES}LL",
        f"#define GTE_MAX_FRAME {MAX_FRAME}u",
        f"#define GTE_CHUNK {CHUNK}u",
        f"#define GTE_SOCKET_TYPE {_SOCKET_NAMES[SOCKET_TYPE]}",
    ]
    lines += [f"#define GTE_K_{k.name} {int(k)}" for k in Kind]
    lines.append(f"#define GTE_CMD_DECLARED {CMD_DECLARED}")
    lines += ["#endif", ""]
    return "\n".join(lines)


def _elem(plan_arg) -> str:
    p = plan_arg.param
    return f"sizeof({p.ctype})" if p.pointer else "0"


def _descriptor(plan: FunctionPlan) -> list[str]:
    name = plan.name
    flags = {
        "GT_Open": "GTE_F_OPEN",
        "GTN_OpenCard": "GTE_F_OPEN",  # the GSN-E form of GT_Open
        "GT_Close": "GTE_F_CLOSE",
        "GT_SetCardNo": "GTE_F_CARDNO",  # the process's current card (gts_runtime.c)
        "GT_GetCardNo": "GTE_F_GETCARDNO",
        "GT_SetCore": "GTE_F_SETCORE",
        "GT_GetCore": "GTE_F_GETCORE",
    }.get(name, "0")
    out = []
    if plan.args:
        out.append(f"static const gte_param P_{name}[] = {{")
        for a in plan.args:
            out.append(
                f"    {{GTE_K_{a.kind.name}, {a.count_arg}, {_elem(a)}, {a.count}}},"
                f"  /* {a.param.name} */"
            )
        out.append("};")
    params = f"P_{name}" if plan.args else "NULL"
    out.append(
        f"static const gte_function F_{name} = "
        f'{{"{name}", {plan.fid}, {len(plan.args)}, {flags}, {params}}};'
    )
    return out


def _body(plan: FunctionPlan, gtn: bool) -> list[str]:
    proto: Proto = plan.proto
    out = ["{"]
    slots = []  # char **pVersion: the text lands in a buffer of the library, *pVersion points to it
    if plan.args:
        out.append(f"    gte_arg a[{len(plan.args)}];")
        for i, a in enumerate(plan.args):
            p = a.param
            if p.pointer and p.stars == 2:
                slot = f"slot_{p.name}"
                out.insert(1, f"    static char {slot}[{max(int(a.count), 1)}];")
                out.append(f"    a[{i}].p = {p.name} ? {slot} : NULL;")
                slots.append((p.name, slot))
            elif p.pointer:
                out.append(f"    a[{i}].p = {p.name};")
            elif a.kind is Kind.DOUBLE:
                out.append(f"    a[{i}].d = {p.name};")
            else:
                out.append(f"    a[{i}].i = (long long){p.name};")
        args = "a"
    else:
        args = "NULL"
    core = "core" if gtn else "1"
    if not slots:
        out.append(f"    return gte_invoke(&F_{proto.name}, {int(gtn)}, {core}, {args});")
    else:
        out.append(f"    short rc = gte_invoke(&F_{proto.name}, {int(gtn)}, {core}, {args});")
        for name, slot in slots:
            out.append(f"    if (rc == 0 && {name})")
            out.append(f"        *{name} = {slot};")
        out.append("    return rc;")
    out.append("}")
    return out


def render_stubs(python: str) -> str:
    """``gts_stubs.c``; ``python`` is the interpreter a private controller runs on."""
    esc = python.replace("\\", "\\\\").replace('"', '\\"')
    lines = [
        f"/* gts_stubs.c - the GT functions of gtecat {__version__} (table {table_digest()});",
        " * generated from gtecat/gt/table.py by gtecat.native.stubs: do not edit. */",
        "#include <stddef.h>",
        '#include "gts.h"',
        '#include "gts_runtime.h"',
        "",
        f'const char gte_default_python[] = "{esc}";',
        # (here, not in the transport: the LLP64 build's stubs spell it sizeof(int), and
        # libgts's compiled transport serves that build unchanged, gtecat.native.llp64)
        "const unsigned short gte_client_long_size = sizeof(long);",
        "",
    ]
    for plan in plans():
        proto = plan.proto
        if plan.declared:
            continue  # gts_declared.c
        lines += _descriptor(plan)
        lines += [proto.c_signature(defaults=False).replace("()", "(void)"), *_body(plan, False)]
        if proto.name in NO_CORE_TWINS:  # the vendor's GTN_Open(channel, param), GTN_Close()
            own = ", ".join(n for n, _ in NO_CORE_TWINS[proto.name])
            lines += [
                proto.c_signature(defaults=False, core=True),
                "{",
                f"    return {proto.name}({own});",
                "}",
            ]
        elif proto.gtn and proto.name in SAME_PARAM_TWINS:  # GTN_Compile(pFileName, ...)
            own = ", ".join(p.name for p in proto.params)
            lines += [
                proto.c_signature(defaults=False, core=True),
                "{",
                f"    return {proto.name}({own});",
                "}",
            ]
        elif proto.gtn:
            lines += [proto.c_signature(defaults=False, core=True), *_body(plan, True)]
        lines.append("")
    return "\n".join(lines)


def _c_text(text: str) -> str:
    return text.replace("\\", "\\\\").replace('"', '\\"')


#: defined while compiling ``gts_declared.c`` beside ``gts_declared_x86_64.S``: the C unit
#: then holds the table only, the assembly the functions
DECLARED_ASM_MACRO = "GTE_DECLARED_ASM"


def _declared_bodies() -> list[tuple[Proto, bool, int, str]]:
    """(prototype, GTN twin, index, core argument) of every declared-only function."""
    out = []
    for i, plan in enumerate(p for p in plans() if p.declared):
        proto = plan.proto
        out.append((proto, False, i, "1"))
        if proto.gtn:
            core = "1" if proto.name in SAME_PARAM_TWINS or proto.name in NO_CORE_TWINS else "core"
            out.append((proto, True, i, core))
    return out


def render_declared() -> str:
    """``gts_declared.c``: every declared-only function, each a one-line body that only
    says which it is (``gte_declared``, ``gts_runtime.c``).  A unit of its own, compiled
    without optimisation beside the others: it is large and there is nothing to optimise.
    With ``GTE_DECLARED_ASM`` defined it holds the table alone (the functions come from
    :func:`render_declared_x86_64`)."""
    lines = [
        f"/* gts_declared.c - the declared-only functions of gtecat {__version__} (table",
        f" * {table_digest()}); generated by gtecat.native.stubs: do not edit. */",
        "#include <stddef.h>",
        '#include "gts.h"',
        '#include "gts_runtime.h"',
        "",
        "/* they do not look at their arguments */",
        "#if defined(__GNUC__)",
        '#pragma GCC diagnostic ignored "-Wunused-parameter"',
        "#endif",
        "",
    ]
    declared = [p for p in plans() if p.declared]
    used = {p.proto.group for p in declared}
    index = {}
    for i, g in enumerate(GROUPS):
        if g.name in used:
            index[g.name] = f"G{i}"
            lines.append(f'static const char G{i}[] = "{_c_text(g.title)}";')
    lines += ["", "const gte_declared_info gte_declared_table[] = {"]
    for p in declared:
        lines.append(f'    {{"{p.name}", {index[p.proto.group]}, {p.fid}}},')
    lines += ["    {NULL, NULL, 0},", "};", "", f"#ifndef {DECLARED_ASM_MACRO}"]
    for proto, gtn, i, core in _declared_bodies():
        if proto.unknown and not gtn:  # no prototype in gts.h: the parameters are the caller's
            lines.append(f"short {proto.name}(void);")
        sig = (
            proto.c_signature(defaults=False, core=True)
            if gtn
            else proto.c_signature(defaults=False).replace("()", "(void)")
        )
        lines += [sig, f"{{ return gte_declared({i}, {int(gtn)}, {core}); }}"]
    lines += ["#endif", ""]
    return "\n".join(lines)


def render_declared_x86_64() -> str:
    """``gts_declared_x86_64.S``: the declared-only functions of :func:`render_declared` for
    x86-64 ELF (the System V calling convention), four instructions each.

    Each only calls ``gte_declared(index, gtn, core)`` as its C body does, so its
    parameters need no declaration; the assembler takes a few hundredths of a second where
    gcc takes one to two seconds for the ~3,800 C bodies.  A 32-bit Linux build uses the
    C bodies; the Windows DLLs have their own (:func:`render_declared_win64`,
    :func:`render_declared_win32`).  ``core``, where a twin passes it, is its first
    parameter (``%di``)."""
    out = [
        f"/* gts_declared_x86_64.S - the declared-only functions of gtecat {__version__}",
        f" * (table {table_digest()}); generated by gtecat.native.stubs: do not edit. */",
        "\t.text",
    ]
    for proto, gtn, i, core in _declared_bodies():
        name = proto.twin_name if gtn else proto.name
        out += [f"\t.globl {name}", f"\t.type {name}, @function", "\t.p2align 4", f"{name}:"]
        out.append("\tmovswl %di, %edx" if core == "core" else f"\tmovl ${core}, %edx")
        out += [f"\tmovl ${i}, %edi", f"\tmovl ${int(gtn)}, %esi", "\tjmp gte_declared@PLT"]
        out.append(f"\t.size {name}, .-{name}")
    out += ['\t.section .note.GNU-stack,"",@progbits', ""]
    return "\n".join(out)


def render_declared_win64() -> str:
    """``gts_declared_win64.S``: the declared-only functions of :func:`render_declared` for
    a 64-bit Windows DLL (PE/COFF, the Microsoft x64 calling convention), four instructions
    each, as :func:`render_declared_x86_64` for Linux.

    The first three integer arguments are in ``%rcx``, ``%rdx``, ``%r8``: a twin's ``core``
    (its first parameter, a ``short`` in ``%cx``) is sign-extended into ``%r8d`` before
    ``%ecx`` takes the index.  The stub tail-jumps with the stack as it found it: the shadow
    space its caller reserved is ``gte_declared``'s, and a function that never moves ``%rsp``
    is a leaf to the unwinder, so it needs no unwind data."""
    out = [
        f"/* gts_declared_win64.S - the declared-only functions of gtecat {__version__}",
        f" * (table {table_digest()}); generated by gtecat.native.stubs: do not edit. */",
        "\t.text",
    ]
    for proto, gtn, i, core in _declared_bodies():
        name = proto.twin_name if gtn else proto.name
        out += [
            f"\t.globl {name}",
            f"\t.def {name}; .scl 2; .type 32; .endef",
            "\t.p2align 4",
            f"{name}:",
            "\tmovswl %cx, %r8d" if core == "core" else f"\tmovl ${core}, %r8d",
            f"\tmovl ${i}, %ecx",
            f"\tmovl ${int(gtn)}, %edx",
            "\tjmp gte_declared",
        ]
    out.append("")
    return "\n".join(out)


#: i686 argument bytes of the scalar types of 8 bytes (every other scalar takes a 4-byte slot)
_WIDE = frozenset({"double", "long long", "unsigned long long", "__int64", "int64_t", "uint64_t"})


def _i686_layout(t: type) -> tuple[int, int]:
    """(size, alignment) of a ctypes type as mingw-w64's i686 gcc (and MSVC) lay it out in a
    structure: pointers 4, ``long`` 4, ``double`` and 64-bit integers 8 aligned to 8."""
    import ctypes

    if issubclass(t, ctypes.Array):
        size, align = _i686_layout(t._type_)
        return size * t._length_, align
    if issubclass(t, ctypes.Structure | ctypes.Union):
        pack = getattr(t, "_pack_", None) or 8
        size = align = 0
        for f in t._fields_:
            fsize, falign = _i686_layout(f[1])
            falign = min(falign, pack)
            align = max(align, falign)
            if issubclass(t, ctypes.Union):
                size = max(size, fsize)
            else:
                size = -(-size // falign) * falign + fsize
        align = max(align, 1)
        return -(-size // align) * align, align
    code = getattr(t, "_type_", None)
    if code in ("P", "z", "Z", "O") or not isinstance(code, str):
        return 4, 4  # c_void_p, c_char_p, POINTER(x): 32-bit pointers
    # Windows' long is 32 bits, its wchar_t 16
    size = {"l": 4, "L": 4, "u": 2}.get(code) or ctypes.sizeof(t)
    return size, size


def _twin_params(proto: Proto, gtn: bool) -> list[tuple[str, bool]]:
    """(C type, pointer) of each parameter of a declared-only function or its twin."""
    if gtn and proto.name in NO_CORE_TWINS:
        return [("short", False)] * len(NO_CORE_TWINS[proto.name])
    core = [("short", False)] if gtn and proto.name not in SAME_PARAM_TWINS else []
    return core + [(p.ctype, p.pointer) for p in proto.params]


def stdcall_bytes(proto: Proto, gtn: bool) -> int:
    """The bytes of arguments a 32-bit ``__stdcall`` function of this prototype pops (the
    ``N`` of its ``_GT_x@N`` symbol): each parameter takes its size rounded up to 4 bytes
    (pointers, ``short``, ``long``, ``float`` 4; ``double`` and 64-bit integers 8; a
    structure by value its i686 size)."""
    from .cdecl import structure

    total = 0
    for ctype, pointer in _twin_params(proto, gtn):
        if pointer:
            size = 4
        elif ctype in _WIDE:
            size = 8
        elif ctype in SCALARS or ctype in ENUMS:
            size = 4
        else:
            size = _i686_layout(structure(ctype))[0]
        total += -(-size // 4) * 4
    return total


#: the names the Windows build makes ``__stdcall`` (:func:`gtecat.native.windows.to_stdcall`)
_STDCALL = re.compile(r"G[A-Z]*_\w+")


def render_declared_win32() -> str:
    """``gts_declared_win32.S``: the declared-only functions of :func:`render_declared` for
    a 32-bit Windows DLL (PE/COFF, i686), ``__stdcall`` as ``gts.h`` declares them there
    (the few vendor names outside ``GT*_``, ``ConvertPhysical``, stay ``cdecl``).

    The callee pops its arguments: each stub pushes ``gte_declared``'s three (``cdecl``,
    ``core`` read from the twin's first stack slot), calls it, takes them back and returns
    with ``ret N``, ``N`` the argument bytes of :func:`stdcall_bytes`.  Each symbol is
    decorated as the C compiler decorates the function (``_GT_x@N``), so the build's
    ``.def`` and import library read them as they read the C build's.  Entered with the
    stack 16-byte aligned less the return address, the three pushes align it again for the
    call."""
    out = [
        f"/* gts_declared_win32.S - the declared-only functions of gtecat {__version__}",
        f" * (table {table_digest()}); generated by gtecat.native.stubs: do not edit. */",
        "\t.text",
    ]
    for proto, gtn, i, core in _declared_bodies():
        name = proto.twin_name if gtn else proto.name
        if _STDCALL.fullmatch(name):
            n = stdcall_bytes(proto, gtn)
            name = f"_{name}@{n}"
        else:  # a vendor name outside GT*_ (ConvertPhysical): cdecl, the caller pops
            n, name = 0, f"_{name}"
        out += [
            f"\t.globl {name}",
            f"\t.def {name}; .scl 2; .type 32; .endef",
            "\t.p2align 4",
            f"{name}:",
            "\tmovswl 4(%esp), %eax" if core == "core" else f"\tmovl ${core}, %eax",
            "\tpushl %eax",
            f"\tpushl ${int(gtn)}",
            f"\tpushl ${i}",
            "\tcall _gte_declared",
            "\taddl $12, %esp",
            f"\tret ${n}" if n else "\tret",
        ]
    out.append("")
    return "\n".join(out)


__all__ = [
    "DECLARED_ASM_MACRO",
    "render_declared",
    "render_declared_win32",
    "render_declared_win64",
    "render_declared_x86_64",
    "render_stubs",
    "render_wire_h",
    "stdcall_bytes",
]
