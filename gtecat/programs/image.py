"""The program image (``.bin``) and the symbol file (``.ini``) of a compiled program (10.3.2).

``GT_Compile("x.c")`` / ``gtecat compile x.c`` write ``x.bin`` and ``x.ini`` beside the
source; ``GT_Download("x.bin")`` reads both (the ``.ini`` must be beside the ``.bin``,
entry 10).  Both formats are gtecat's own (the vendor's MCT2008 formats are not
public) and carry a format number; docs/programs.md describes them.

``.bin``, format 1, little-endian throughout::

    header  8s magic "GTEPRG\\r\\n", u16 format (1), u16 flags (0), u32 payload length,
            u32 CRC-32 of the payload, 16s build id (the payload's SHA-256, first 16 bytes)
    payload
      u16 string count, then per string: u16 length, UTF-8 bytes
          (strings[0] is the source file name, then the called GT functions, then
          the program's function names)
      u16 function count, then per function (:data:`FUNCTION`):
          u16 name string, u8 return type (0 int, 1 double, 255 void), u8 parameters,
          u16 local words, u32 entry, u32 end, u32 source line
      u16 global words, u16 initialised globals, then per one: u16 address, i32 word
      u32 instruction count, then per instruction (:data:`INSTR`):
          u8 op, u8 sub, u16 line, i32 target, u8 operand count, then per operand
          (:data:`OPERAND`): u8 kind, u8 type, u8 index kind, u8 flags (bit 0: pointer),
          i32 value, u16 size, u16 reserved, i32 index

``.ini``, format 1: ``[program]`` (format, source, image, build, counts), one
``[function NAME]`` per function (id, returns, params, local_words, line), one
``[global NAME]`` per global and one ``[local FUNCTION.NAME]`` per local (id = the
word address in its area, type, size, line).  ``GT_GetFunId`` / ``GT_GetVarId`` answer
from it; a build id that differs from the ``.bin``'s refuses the download.
"""

from __future__ import annotations

import configparser
import hashlib
import io
import struct
import zlib
from dataclasses import replace
from pathlib import Path

from .model import Function, Instr, Kind, Op, Operand, Program, Variable, VarType

FORMAT = 1
MAGIC = b"GTEPRG\r\n"
HEADER = struct.Struct("<8sHHII16s")
FUNCTION = struct.Struct("<HBBHIII")
INSTR = struct.Struct("<BBHiB")
OPERAND = struct.Struct("<BBBBiHHi")
_U16 = struct.Struct("<H")
_U32 = struct.Struct("<I")
_INIT = struct.Struct("<Hi")
_VOID = 255


class ImageError(Exception):
    """A ``.bin`` / ``.ini`` that cannot be read (``code``: 2007 missing, 2008 unusable)."""

    def __init__(self, code: int, message: str) -> None:
        super().__init__(message)
        self.code = code


# --- .bin ----------------------------------------------------------------------------------
def encode(program: Program) -> bytes:
    """The ``.bin`` bytes of ``program`` (header + payload)."""
    payload = _payload(program)
    build = hashlib.sha256(payload).digest()[:16]
    header = HEADER.pack(MAGIC, FORMAT, 0, len(payload), zlib.crc32(payload), build)
    return header + payload


def build_id(data: bytes) -> str:
    """The build id of a ``.bin`` (hex), without decoding it."""
    return HEADER.unpack_from(data)[5].hex()


def _payload(program: Program) -> bytes:
    strings: list[str] = [program.source, *program.strings]
    fname_index = {}
    for f in program.functions:
        fname_index[f.name] = len(strings)
        strings.append(f.name)
    out = io.BytesIO()
    out.write(_U16.pack(len(strings)))
    for s in strings:
        b = s.encode("utf-8")
        out.write(_U16.pack(len(b)) + b)
    out.write(_U16.pack(len(program.functions)))
    for f in program.functions:
        ret = _VOID if f.returns is None else int(f.returns)
        out.write(
            FUNCTION.pack(
                fname_index[f.name], ret, len(f.params), f.local_words, f.entry, f.end, f.line
            )
        )
    out.write(_U16.pack(program.global_words) + _U16.pack(len(program.global_init)))
    for addr, word in program.global_init:
        out.write(_INIT.pack(addr, word))
    out.write(_U32.pack(len(program.code)))
    for ins in program.code:
        out.write(INSTR.pack(ins.op, ins.sub, ins.line, ins.target, len(ins.operands)))
        for o in ins.operands:
            out.write(
                OPERAND.pack(
                    o.kind, o.type, o.index_kind, int(o.pointer), o.value, o.size, 0, o.index
                )
            )
    return out.getvalue()


def decode(data: bytes, symbols: configparser.ConfigParser) -> Program:
    """A program from its ``.bin`` bytes and its parsed ``.ini`` (ImageError 2008 when unusable)."""
    if len(data) < HEADER.size:
        raise ImageError(2008, "not a gtecat program image (too short)")
    magic, fmt, _flags, length, crc, build = HEADER.unpack_from(data)
    if magic != MAGIC:
        raise ImageError(2008, "not a gtecat program image (compile the .c with GT_Compile)")
    if fmt != FORMAT:
        raise ImageError(2008, f"program image format {fmt}; this gtecat reads format {FORMAT}")
    payload = data[HEADER.size : HEADER.size + length]
    if len(payload) != length or zlib.crc32(payload) != crc:
        raise ImageError(2008, "the program image is damaged (length or checksum wrong)")
    try:
        return _decode_payload(payload, build.hex(), symbols)
    except (struct.error, ValueError, IndexError, KeyError, configparser.Error) as e:
        raise ImageError(2008, f"the program image cannot be read: {e}") from None


def _decode_payload(payload: bytes, build: str, symbols: configparser.ConfigParser) -> Program:
    pos = 0

    def take(st: struct.Struct) -> tuple:
        nonlocal pos
        v = st.unpack_from(payload, pos)
        pos += st.size
        return v

    (n,) = take(_U16)
    strings = []
    for _ in range(n):
        (k,) = take(_U16)
        strings.append(payload[pos : pos + k].decode("utf-8"))
        pos += k
    (nf,) = take(_U16)
    raw_functions = [take(FUNCTION) for _ in range(nf)]
    gwords, ninit = take(_U16) + take(_U16)
    inits = tuple(take(_INIT) for _ in range(ninit))
    (ni,) = take(_U32)
    code = []
    for _ in range(ni):
        op, sub, line, target, nops = take(INSTR)
        ops = []
        for _ in range(nops):
            kind, typ, ikind, flags, value, size, _r, index = take(OPERAND)
            ops.append(
                Operand(Kind(kind), VarType(typ), value, size, Kind(ikind), index, bool(flags & 1))
            )
        code.append(Instr(Op(op), line, sub, target, tuple(ops)))
    if pos != len(payload):
        raise ValueError("trailing bytes after the instructions")
    functions = []
    called = tuple(strings[1 : len(strings) - nf])
    for fid, (name_i, ret, nparams, words, entry, end, line) in enumerate(raw_functions):
        name = strings[name_i]
        sec = symbols[f"function {name}"]
        params = tuple(x.strip() for x in sec.get("params", "").split(",") if x.strip())
        if len(params) != nparams or int(sec["id"]) != fid:
            raise ValueError(f"function {name}: the symbol file does not match the image")
        locals_ = tuple(
            _variable(symbols[s], s.split(".", 1)[1])
            for s in symbols.sections()
            if s.startswith(f"local {name}.")
        )
        functions.append(
            Function(
                name,
                fid,
                None if ret == _VOID else VarType(ret),
                params,
                locals_,
                words,
                entry,
                end,
                line,
            )
        )
    globals_ = tuple(
        _variable(symbols[s], s.split(" ", 1)[1])
        for s in symbols.sections()
        if s.startswith("global ")
    )
    return Program(
        source=strings[0],
        functions=tuple(functions),
        globals=globals_,
        global_words=gwords,
        global_init=inits,
        code=tuple(code),
        strings=called,
        build=build,
    )


def _variable(sec: configparser.SectionProxy, name: str) -> Variable:
    t = {"int": VarType.INT, "double": VarType.DOUBLE}[sec["type"]]
    size = int(sec.get("size", "1"))
    return Variable(
        name,
        t,
        int(sec["id"]),
        size,
        sec.get("array", "no") == "yes",
        int(sec.get("line", "0")),
    )


# --- .ini ----------------------------------------------------------------------------------
def symbols_text(program: Program, image_name: str, build: str) -> str:
    """The ``.ini`` text of ``program`` whose ``.bin`` is ``image_name`` with ``build``."""
    lines = [
        f"; gtecat motion program symbols, format {FORMAT} (docs/programs.md); generated by",
        "; GT_Compile / gtecat compile - edit the source, not this file",
        "[program]",
        f"format = {FORMAT}",
        f"source = {program.source}",
        f"image = {image_name}",
        f"build = {build}",
        f"functions = {len(program.functions)}",
        f"global_words = {program.global_words}",
        f"instructions = {len(program.code)}",
        "",
    ]
    for f in program.functions:
        ret = "void" if f.returns is None else f.returns.c_name
        lines += [
            f"[function {f.name}]",
            f"id = {f.id}",
            f"returns = {ret}",
            f"params = {', '.join(f.params)}",
            f"local_words = {f.local_words}",
            f"line = {f.line}",
            "",
        ]
    for v in program.globals:
        lines += [f"[global {v.name}]", *_var_lines(v), ""]
    for f in program.functions:
        for v in f.locals:
            lines += [f"[local {f.name}.{v.name}]", *_var_lines(v), ""]
    return "\n".join(lines)


def _var_lines(v: Variable) -> list[str]:
    return [
        f"id = {v.address}",
        f"type = {v.type.c_name}",
        f"size = {v.size}",
        f"array = {'yes' if v.array else 'no'}",
        f"line = {v.line}",
    ]


def read_symbols(text: str) -> configparser.ConfigParser:
    cp = configparser.ConfigParser(interpolation=None, delimiters=("=",))
    cp.optionxform = str  # type: ignore[assignment, method-assign]
    cp.read_string(text)
    return cp


# --- files ---------------------------------------------------------------------------------
def write(program: Program, source_path: str | Path) -> tuple[Path, Path]:
    """Write ``.bin`` and ``.ini`` beside ``source_path``; returns their paths."""
    src = Path(source_path)
    bin_path, ini_path = src.with_suffix(".bin"), src.with_suffix(".ini")
    data = encode(program)
    build = build_id(data)
    bin_path.write_bytes(data)
    ini_path.write_text(symbols_text(program, bin_path.name, build), encoding="utf-8")
    return bin_path, ini_path


def load(image_path: str | Path) -> Program:
    """Read a ``.bin`` and the ``.ini`` beside it (ImageError 2007 / 2008)."""
    p = Path(image_path)
    if len(str(p)) > 4095:
        raise ImageError(2007, "the file name is too long")
    try:
        data = p.read_bytes()
    except FileNotFoundError:
        raise ImageError(2007, f"no program image {p.resolve()} (compile the .c first)") from None
    except OSError as e:
        raise ImageError(2008, f"cannot open {p}: {e.strerror or e}") from None
    ini = p.with_suffix(".ini")
    try:
        text = ini.read_text(encoding="utf-8")
    except OSError:
        raise ImageError(
            2008, f"no symbol file {ini.name} beside {p.name}: the .ini and the .bin go together"
        ) from None
    try:
        symbols = read_symbols(text)
        build = symbols["program"]["build"]
        fmt = int(symbols["program"]["format"])
    except (configparser.Error, KeyError, ValueError) as e:
        raise ImageError(2008, f"{ini.name} is not a gtecat symbol file: {e}") from None
    if fmt != FORMAT:
        raise ImageError(2008, f"{ini.name}: symbol format {fmt}; this gtecat reads {FORMAT}")
    program = decode(data, symbols)
    if build != program.build:
        raise ImageError(
            2008, f"{ini.name} belongs to another build of the program than {p.name}: recompile"
        )
    return replace(program)


__all__ = [
    "FORMAT",
    "MAGIC",
    "ImageError",
    "build_id",
    "decode",
    "encode",
    "load",
    "read_symbols",
    "symbols_text",
    "write",
]
