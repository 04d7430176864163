"""A C header of the GT raw image of a layout (``gtecat cstruct``), for C/C++ and ST programs.

For every slave its region in the GT raw image (GT_GetEcatRawData / GT_SetEcatRawData,
manual 5.2.2.4) and, for every PDO entry, a macro with its byte offset in that image
(``_BIT`` for entries that are not whole bytes), a ``_REGION`` macro with the offset inside
the slave's region (the offset GT_EcatIOReadInput / GT_EcatIOWriteOutput take), and one
packed struct per slave whose members sit at those offsets. The header checks its own
offsets with static asserts, so a compiler refuses it if a struct and a macro ever
disagree. C11 or C++11. A writer of the layout, like :mod:`gtecat.eni.writer`: nothing here runs
a bus, so a verb and a controller process render the same text.
"""

from __future__ import annotations

import re
from pathlib import Path

from .layout import Layout, Placement, SlaveLayout
from .model import Direction

#: (bits, signed) -> C type of a whole-byte entry
C_TYPES = {
    (8, False): "uint8_t",
    (8, True): "int8_t",
    (16, False): "uint16_t",
    (16, True): "int16_t",
    (32, False): "uint32_t",
    (32, True): "int32_t",
    (64, False): "uint64_t",
    (64, True): "int64_t",
}


def ident(text: str) -> str:
    """``text`` as a C identifier part: letters, digits, underscores."""
    s = re.sub(r"[^0-9A-Za-z]+", "_", text).strip("_") or "entry"
    return f"e_{s}" if s[0].isdigit() else s


def _ctype(p: Placement) -> str | None:
    if p.is_padding or p.gt_bit % 8:
        return None
    if (p.data_type or "").upper() in ("REAL", "REAL32") and p.bits == 32:
        return "float"
    if (p.data_type or "").upper() in ("LREAL", "REAL64") and p.bits == 64:
        return "double"
    return C_TYPES.get((p.bits, p.signed))


def _entry_name(p: Placement) -> str:
    return f"{ident(p.name or 'entry')}_{p.index:04X}_{p.subindex:02X}"


def _slave_lines(s: SlaveLayout, prefix: str) -> tuple[list[str], list[str], list[str]]:
    """(#defines, struct, static asserts) of one slave."""
    tag = f"{prefix}SLAVE{s.position}"
    axes = ", ".join(str(a) for a in s.axes)
    what = f"axis {axes}" if len(s.axes) == 1 else (f"axes {axes}" if s.axes else "no axis")
    span = f"GT raw bytes {s.gt_offset}..{s.gt_offset + s.gt_size - 1}" if s.gt_size else "empty"
    defines = [
        f'/* slave {s.position} "{_c_comment(s.name)}": {what}, {span} '
        f"({s.out_bytes} out + {s.in_bytes} in) */",
        f"#define {tag}_GT_OFFSET {s.gt_offset}",
        f"#define {tag}_GT_SIZE {s.gt_size}",
        f"#define {tag}_OUT_BYTES {s.out_bytes}",
        f"#define {tag}_IN_BYTES {s.in_bytes}",
    ]
    members: list[str] = []
    asserts: list[str] = []
    stype = f"{prefix.lower()}slave{s.position}_gt_t"
    cursor = 0  # bytes of the region the struct has covered
    seen: set[str] = set()
    for p in s.entries:
        if p.is_padding:
            continue
        base = _entry_name(p)
        name = base
        n = 2
        while name in seen:  # the same object mapped twice
            name, n = f"{base}_{n}", n + 1
        seen.add(name)
        macro = f"{tag}_{name.upper()}"
        byte, bit = divmod(p.gt_bit, 8)
        direction = "out" if p.direction == Direction.OUT else "in"
        defines.append(
            f"#define {macro} {byte}  /* 0x{p.index:04X}:{p.subindex:02X} {direction}, "
            f"{p.data_type or '-'}, {p.bits} bit */"
        )
        defines.append(f"#define {macro}_REGION {byte - s.gt_offset}")
        if bit or p.bits % 8:
            defines.append(f"#define {macro}_BIT {bit}")
        rel = byte - s.gt_offset
        ctype = _ctype(p)
        if rel < cursor:
            continue  # inside bytes already covered (bits sharing a byte)
        if rel > cursor:
            members.append(f"    uint8_t pad_{cursor}[{rel - cursor}];")
        if ctype is not None:
            members.append(f"    {ctype} {name.lower()};  /* {macro} */")
            asserts.append(f"GTECAT_ASSERT(offsetof({stype}, {name.lower()}) == {macro}_REGION);")
            cursor = rel + p.bits // 8
        else:
            end = (p.gt_bit + p.bits + 7) // 8 - s.gt_offset
            members.append(f"    uint8_t bits_{rel}[{end - rel}];  /* {macro}, bit {bit} on */")
            cursor = end
    if cursor < s.gt_size:
        members.append(f"    uint8_t pad_{cursor}[{s.gt_size - cursor}];")
    struct = []
    if members:
        struct = ["typedef struct {", *members, f"}} {stype};", ""]
        asserts.append(f"GTECAT_ASSERT(sizeof({stype}) == {tag}_GT_SIZE);")
    return defines, struct, asserts


def _c_comment(text: str) -> str:
    return text.replace("*/", "* /").encode("ascii", "backslashreplace").decode()


def render(layout: Layout, source: str, *, prefix: str = "", only: int | None = None) -> str:
    guard = f"GTECAT_{ident(Path(source).stem).upper()}_H"
    slaves = [s for s in layout.slaves if only is None or s.position == only]
    out = [
        f"/* The GT raw image of {_c_comment(Path(source).name)}, written by gtecat cstruct.",
        " *",
        " * <NAME> is the byte offset in the GT raw image (GT_GetEcatRawData, GT_SetEcatRawData,",
        " * manual 5.2.2.4); <NAME>_REGION the offset inside the slave's region",
        " * (GT_EcatIOReadInput, GT_EcatIOWriteOutput); <NAME>_BIT the bit in that byte for",
        " * entries that are not whole bytes. Little endian, as on the bus. */",
        f"#ifndef {guard}",
        f"#define {guard}",
        "",
        "#include <stddef.h>",
        "#include <stdint.h>",
        "",
        "#ifdef __cplusplus",
        "#define GTECAT_ASSERT(x) static_assert(x, #x)",
        "#else",
        "#define GTECAT_ASSERT(x) _Static_assert(x, #x)",
        "#endif",
        "",
        f"#define {prefix}GT_RAW_BYTES {layout.gt_raw_bytes}",
        f"#define {prefix}SLAVE_COUNT {len(layout.slaves)}",
        f"#define {prefix}AXIS_COUNT {len(layout.axes)}",
        "",
    ]
    structs: list[str] = []
    asserts: list[str] = []
    for s in slaves:
        d, st, a = _slave_lines(s, prefix)
        out += [*d, ""]
        structs += st
        asserts += a
    if only is None:
        members = [
            f"    {prefix.lower()}slave{s.position}_gt_t slave{s.position};"
            for s in slaves
            if s.gt_size
        ]
        if members:
            structs += ["typedef struct {", *members, f"}} {prefix.lower()}gt_raw_t;", ""]
            asserts.append(
                f"GTECAT_ASSERT(sizeof({prefix.lower()}gt_raw_t) == {prefix}GT_RAW_BYTES);"
            )
            asserts += [
                f"GTECAT_ASSERT(offsetof({prefix.lower()}gt_raw_t, slave{s.position}) == "
                f"{prefix}SLAVE{s.position}_GT_OFFSET);"
                for s in slaves
                if s.gt_size
            ]
    if structs:
        out += ["#pragma pack(push, 1)", "", *structs, "#pragma pack(pop)", ""]
    out += [*asserts, "", f"#endif /* {guard} */", ""]
    return "\n".join(out)
