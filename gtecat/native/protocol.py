"""The controller protocol: one request and one reply per GT call, over a Unix socket.

Both ends are generated from the function table (:mod:`gtecat.gt.table`): the C stubs
of ``libgts.so`` (:mod:`gtecat.native.stubs`) encode a call the way this module reads
it, and the controller (:mod:`gtecat.native.server`) decodes it with the plan below.
The two ends run on one machine, so numbers travel little-endian in the client's own
C sizes (``long`` is the client's ``long``, announced in the hello).

Every message is a frame: ``u32 length`` then ``length`` bytes of body.  On Linux the
socket is ``SOCK_SEQPACKET``: a frame travels as records of at most :data:`CHUNK` bytes
(nearly always one, so one ``recv`` takes a whole request or reply, and record
boundaries cost no extra reads); elsewhere it is ``SOCK_STREAM`` with the same frames.
A receiver always offers at least :data:`CHUNK` bytes of room to a read.

Client -> controller, first message of a connection (``HELLO``)::

    u8 type = 1, 3 pad, u16 protocol version, u16 sizeof(long), char digest[16]

``digest`` names the table, the protocol, the structure layouts and the set of emulated
functions the library was built from (a declared-only function sends no arguments); the
controller refuses a library built from another table (reply status 1 with the reason).
Reply (``HELLO_REPLY``): ``i16 status, u16 text length, text``.

A call (``CALL``)::

    u8 type = 2, u8 flags (bit 0: 1 = GTN_x, the core is checked, 0 = GT_x / GTE_x;
    bits 4..7: the card the call addresses, 0..15), u16 function id (index in
    :data:`FUNCTION_NAMES`), i16 core,
    then every parameter in prototype order:
      integer scalar: i64            double: f64
      pointer: i32 size, then ``size`` bytes: the memory behind the pointer
        (in, inout and out alike, so bytes a call leaves alone come back unchanged);
        size -1 = NULL, -2 = size unknown (``out[?]``: the call decides),
        -3 = larger than :data:`MAX_POINTER_BYTES` (refused by the call's room check)
      text (``char *`` in): i32 size with the NUL, the bytes

Reply (``REPLY``)::

    i16 return code, u16 number of out blocks, u16 error text length,
    per non-NULL out/inout pointer in prototype order: u32 size, bytes,
    then the error text (UTF-8; only when the code is not 0 and the call said why)

The field side and the bus (``FIELD``, :mod:`gtecat.native.field`): what a test or an
inspection verb asks of the controller beyond the GT API (inject a drive fault, set a
machine input, read the slaves, record a trace)::

    u8 type = 3, then UTF-8 JSON {"op": name, "args": [...]}

Reply (``FIELD_REPLY``): ``i16 status (0 ok, 1 refused), then UTF-8 JSON``: the result,
or the reason as a JSON string.
"""

from __future__ import annotations

import ctypes
import struct
from dataclasses import dataclass
from enum import IntEnum
from functools import cache
from typing import Any

from ..gt.table import FUNCTIONS, PROTOTYPES, SCALARS, Param, Proto, emulated
from . import cdecl
from .transport import SOCKET_TYPE, socket_path

PROTOCOL_VERSION = 3

#: the largest record one send makes (well inside the default socket buffer)
CHUNK = 1 << 16

FRAME = struct.Struct("<I")
HELLO = struct.Struct("<B3xHH16s")
HELLO_REPLY = struct.Struct("<hH")
CALL = struct.Struct("<BBHh")
REPLY = struct.Struct("<hHH")
I64 = struct.Struct("<q")
F64 = struct.Struct("<d")
PTR = struct.Struct("<i")
BLOCK = struct.Struct("<I")

FIELD_REPLY = struct.Struct("<h")

MSG_HELLO = 1
MSG_CALL = 2

#: the flags byte of a call: bit 0 GTN, bits 4..7 the card
CALL_GTN = 0x01
CARD_SHIFT = 4
MSG_FIELD = 3

PTR_NULL = -1
PTR_UNKNOWN = -2
PTR_TOO_BIG = -3

#: the largest pointer block a client sends (a bigger count is refused as out of room)
MAX_POINTER_BYTES = 16 << 20
#: the largest frame either end accepts
MAX_FRAME = MAX_POINTER_BYTES * 4


class Kind(IntEnum):
    """How one parameter travels (the C stubs use the same numbers)."""

    INT = 0
    DOUBLE = 1
    IN = 2
    OUT = 3
    INOUT = 4
    TEXT = 5
    OUT_ANY = 6  #: ``out[?]``: the call decides how many bytes it writes


@dataclass(frozen=True, slots=True)
class ArgPlan:
    """One parameter of a function as the wire carries it."""

    param: Param
    kind: Kind
    count: int  #: fixed element count (pointers; 0 when ``count_arg`` says)
    count_arg: int  #: index of the parameter holding the count, -1 if fixed

    @property
    def carries_back(self) -> bool:
        return self.kind in (Kind.OUT, Kind.INOUT, Kind.OUT_ANY)


@dataclass(frozen=True, slots=True)
class FunctionPlan:
    name: str
    fid: int
    proto: Proto
    args: tuple[ArgPlan, ...]
    #: why the call cannot travel (a structure with pointers), None when it can
    unsupported: str | None = None
    #: declared but not emulated: no arguments travel, the controller answers
    #: CMD_DECLARED (:mod:`gtecat.gt.declared`)
    declared: bool = False

    def null_refusal(self, args: list[Any]) -> str | None:
        """Why the decoded ``args`` are refused before anything else (7, as the Python
        binder says it: a required pointer given NULL), None when they are not; lets a
        function that cannot travel still check its arguments first, as in Python."""
        for a, v in zip(self.args, args, strict=False):
            if a.param.pointer and not a.param.optional and v is None:
                return f"{a.param.name} is NULL; this pointer is required"
        return None


def _kind(p: Param) -> Kind:
    if not p.pointer:
        return Kind.DOUBLE if p.is_float else Kind.INT
    if p.text and p.direction == "in":
        return Kind.TEXT
    if p.count == 0:
        return Kind.OUT_ANY
    return {"in": Kind.IN, "out": Kind.OUT, "inout": Kind.INOUT}[p.direction]


def _plan(proto: Proto, fid: int, declared: bool = False) -> FunctionPlan:
    if declared:
        return FunctionPlan(proto.name, fid, proto, (), None, declared=True)
    index = {p.name: i for i, p in enumerate(proto.params)}
    args = []
    unsupported = None
    for p in proto.params:
        kind = _kind(p)
        if isinstance(p.count, str):
            count, count_arg = 0, index[p.count]
        else:
            count, count_arg = int(p.count), -1
        args.append(ArgPlan(p, kind, count, count_arg))
        if p.pointer and p.is_struct:
            try:
                cls = cdecl.structure(p.ctype)
            except KeyError:
                raise cdecl.CDeclError(
                    f"{proto.name}: the table names structure {p.ctype}, but gtecat.gt "
                    "exports no ctypes structure of that name"
                ) from None
            if cdecl.has_pointers(cls):
                unsupported = (
                    f"{proto.name}: {p.ctype} holds pointers, which mean nothing in the "
                    "controller process; not available through libgts"
                )
    return FunctionPlan(proto.name, fid, proto, tuple(args), unsupported)


def element_type(ctype: str, long_size: int) -> Any:
    """The ctypes element behind a pointer of C type ``ctype`` for a client whose
    ``long`` has ``long_size`` bytes (a structure: gt's ctypes structure)."""
    if ctype in ("long", "unsigned long"):
        signed = ctype == "long"
        return {
            4: ctypes.c_int32 if signed else ctypes.c_uint32,
            8: ctypes.c_int64 if signed else ctypes.c_uint64,
        }[long_size]
    if ctype in SCALARS:
        return getattr(ctypes, SCALARS[ctype][0])
    return cdecl.structure(ctype)


#: function ids: the table's names in sorted order
FUNCTION_NAMES: tuple[str, ...] = tuple(sorted(FUNCTIONS))


@cache
def plans() -> tuple[FunctionPlan, ...]:
    done = emulated()
    return tuple(_plan(FUNCTIONS[n], i, n not in done) for i, n in enumerate(FUNCTION_NAMES))


@cache
def plans_by_name() -> dict[str, FunctionPlan]:
    return {p.name: p for p in plans()}


@cache
def table_digest() -> str:
    """16 hex digits naming the table, this protocol and the structure layouts."""
    return cdecl.digest(
        PROTOTYPES, str(PROTOCOL_VERSION), cdecl.layout_text(), ",".join(sorted(emulated()))
    )


__all__ = [
    "BLOCK",
    "CALL",
    "CALL_GTN",
    "CARD_SHIFT",
    "CHUNK",
    "F64",
    "FIELD_REPLY",
    "FRAME",
    "FUNCTION_NAMES",
    "HELLO",
    "HELLO_REPLY",
    "I64",
    "MAX_FRAME",
    "MAX_POINTER_BYTES",
    "MSG_CALL",
    "MSG_FIELD",
    "MSG_HELLO",
    "PROTOCOL_VERSION",
    "PTR",
    "PTR_NULL",
    "PTR_TOO_BIG",
    "PTR_UNKNOWN",
    "REPLY",
    "SOCKET_TYPE",
    "ArgPlan",
    "FunctionPlan",
    "Kind",
    "element_type",
    "plans",
    "plans_by_name",
    "socket_path",
    "table_digest",
]
