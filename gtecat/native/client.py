"""``from gtecat import gt`` attached to a controller process, and the field side from Python.

``gt.GT_Open(controller="unix:/path")`` (or ``GTECAT_CONTROLLER``) makes this process's
gt session a client of a running controller (``gtecat controller``, a private one of a
libgts program, a :class:`~gtecat.native.server.Server` in another process), the way
libgts is: every ``GT_*``/``GTN_*``/``GTE_*`` call of the function table is checked
here by the same binder as in-process, marshalled per the table
(:mod:`gtecat.native.protocol`), run by the controller, and its out-pointers are written
back into the caller's memory; return codes and reasons are the controller's
(``GTE_GetLastError()``).  ``GT_Close`` detaches; the controller stays.

Decisions:

* ``GT_Open``'s keyword options (``eni=``, ``clock=``, ...) configure an in-process
  controller; attached, they are refused with 7 (the controller has its own
  configuration: ``gtecat controller --eni ...``), except ``log``, which is ignored.
* ``GT_Open`` while attached is -6, as a second in-process ``GT_Open`` is.  A
  controller that dies or stops answering (``GTECAT_TIMEOUT_MS``, default 30000) makes
  this call and every later one -1 with the reason, until ``GT_Close`` / a new ``GT_Open``.
* Pointers are sent with the bytes the table says the call moves (``count`` elements of
  the C type; fewer when the caller's memory is smaller, so the controller's room check
  refuses it as in-process).  Values travel in the table's C type; a caller's buffer of
  another element type (``c_int32`` for ``long *``, a list, a numpy array) is converted
  both ways, as the in-process stores do.
* ``GTE_Controller()``, ``GTE_Slave()`` and ``GTE_GetCycleStats()`` return Python objects
  of the controller process and cannot cross: attached, they raise and name
  :func:`field`, whose :class:`Field` runs the operations of :mod:`gtecat.native.field`
  (faults, machine inputs, IO terminals, traces, the bus) in the controller.
"""

from __future__ import annotations

import ctypes
import json
import os
import socket
import struct
import threading
from typing import Any

import numpy as np

from gtecat.eni.errors import GtecatError

from ..errors import ParameterError
from ..gt import _core
from ..gt.args import Ref, fit
from . import transport
from .protocol import (
    BLOCK,
    CALL,
    CALL_GTN,
    CARD_SHIFT,
    CHUNK,
    F64,
    FIELD_REPLY,
    FRAME,
    HELLO,
    HELLO_REPLY,
    I64,
    MAX_FRAME,
    MSG_CALL,
    MSG_FIELD,
    MSG_HELLO,
    PROTOCOL_VERSION,
    PTR,
    PTR_NULL,
    PTR_UNKNOWN,
    REPLY,
    FunctionPlan,
    Kind,
    element_type,
    plans_by_name,
    table_digest,
)

_LONG = ctypes.sizeof(ctypes.c_long)


class ControllerError(GtecatError):
    """The controller refused a field operation, or cannot be reached."""


class ControllerLost(ControllerError):
    """The connection to the controller broke (or it stopped answering)."""


def _timeout_s() -> float:
    try:
        ms = float(os.environ.get("GTECAT_TIMEOUT_MS", "30000"))
    except ValueError:
        ms = 30000.0
    return ms / 1000.0 if ms > 0 else 30.0


class Connection:
    """One socket to a controller, greeted; calls from several threads take turns."""

    def __init__(self, address: str, *, timeout_s: float | None = None) -> None:
        self.address = address
        self.lost = ""  #: why the connection broke ("" while it works)
        #: the cards this connection has opened (gtecat.controller.cards)
        self.cards: set[int] = set()
        self._lock = threading.Lock()
        self._codecs: dict[int, _Codec] = {}
        try:
            addr = transport.parse(address)
            token = transport.client_token(addr.port).encode() if addr.tcp else b""
            sock = transport.connect(addr, timeout_s if timeout_s is not None else _timeout_s())
        except (OSError, ValueError) as e:
            raise ControllerError(f"cannot reach the controller at {address}: {e}") from None
        self._sock = sock
        hello = HELLO.pack(MSG_HELLO, PROTOCOL_VERSION, _LONG, table_digest().encode("ascii"))
        if token:  # a TCP controller's token (gtecat.native.transport)
            hello += struct.pack("<H", len(token)) + token
        body = self._exchange(hello)
        status, n = HELLO_REPLY.unpack_from(body, 0)
        if status != 0:
            text = body[HELLO_REPLY.size : HELLO_REPLY.size + n].decode("utf-8", "replace")
            self.close()
            raise ControllerError(f"the controller at {address} refused this gtecat: {text}")

    # --- transport ---------------------------------------------------------------------------
    def _exchange(self, body: bytes) -> bytes:
        """Send one message, return the reply's body (ControllerLost when the link broke)."""
        with self._lock:
            if self.lost:
                raise ControllerLost(self.lost)
            try:
                return self._exchange_locked(body)
            except (OSError, ConnectionError, ValueError) as e:
                if isinstance(e, TimeoutError | socket.timeout):
                    why = f"no reply from the controller at {self.address} within the timeout"
                else:
                    why = f"the connection to the controller at {self.address} broke: {e}"
                self.lost = why
                self._close_socket()
                raise ControllerLost(why) from None

    def _exchange_locked(self, body: bytes) -> bytes:
        sock = self._sock
        data = memoryview(FRAME.pack(len(body)) + body)
        while data:
            sent = sock.send(data[:CHUNK])
            data = data[sent:]
        buf = bytearray()
        need = 4
        while len(buf) < need:
            more = sock.recv(max(CHUNK, need - len(buf)))
            if not more:
                raise ConnectionError("the controller closed the connection")
            buf += more
            if need == 4 and len(buf) >= 4:
                (n,) = FRAME.unpack_from(buf, 0)
                if n > MAX_FRAME:
                    raise ValueError(f"a reply of {n} bytes")
                need = 4 + n
        return bytes(buf[4:need])

    def _close_socket(self) -> None:
        sock = getattr(self, "_sock", None)
        if sock is not None:
            sock.close()

    def close(self) -> None:
        with self._lock:
            if not self.lost:
                self.lost = "the connection was closed"
            self._close_socket()

    # --- GT calls ------------------------------------------------------------------------------
    def call(
        self, name: str, gtn: bool, core: int, values: list[Any], card: int = 0
    ) -> tuple[int, str]:
        """Run a bound GT call in the controller on card ``card``: (return code, reason);
        the out-pointers among ``values`` are written."""
        plan = plans_by_name()[name]
        codec = self._codecs.get(plan.fid)
        if codec is None:
            codec = self._codecs[plan.fid] = _Codec(plan, _LONG)
        request, outs = codec.encode(gtn, core, values, card)
        body = self._exchange(request)
        rc, nblocks, nerr = REPLY.unpack_from(body, 0)
        pos = REPLY.size
        blocks = []
        for _ in range(nblocks):
            (size,) = BLOCK.unpack_from(body, pos)
            pos += BLOCK.size
            blocks.append(body[pos : pos + size])
            pos += size
        text = body[pos : pos + nerr].decode("utf-8", "replace")
        codec.write_back(outs, blocks)
        return rc, text

    # --- the field side -------------------------------------------------------------------------
    def field(self, op: str, *args: Any, card: int = 0) -> Any:
        """Run one operation of :mod:`gtecat.native.field` on card ``card``; ControllerError
        with its reason."""
        req: dict[str, Any] = {"op": op, "args": list(args)}
        if card:
            req["card"] = int(card)
        body = bytes([MSG_FIELD]) + json.dumps(req).encode()
        reply = self._exchange(body)
        (status,) = FIELD_REPLY.unpack_from(reply, 0)
        value = json.loads(reply[FIELD_REPLY.size :].decode("utf-8"))
        if status != 0:
            raise ControllerError(str(value))
        return value


# --- marshalling per the table ----------------------------------------------------------------
_INT_CODES = {1: "b", 2: "h", 4: "i", 8: "q"}
_UINT_CODES = {1: "B", 2: "H", 4: "I", 8: "Q"}
_FLOAT_CODES = {4: "f", 8: "d"}


def _kind(t: Any) -> str:
    """'i' / 'u' / 'f' for a numeric ctypes type, '' otherwise."""
    code = getattr(t, "_type_", None)
    if not isinstance(code, str):
        return ""
    if code in "bhilqn":
        return "i"
    if code in "BHILQN?":
        return "u"
    if code in "fdg":
        return "f"
    return ""


class _Arg:
    """How one pointer parameter's value travels for this client."""

    __slots__ = ("byte_like", "count", "count_arg", "elem", "fmt", "kind", "plan", "size")

    def __init__(self, a: Any, long_size: int) -> None:
        self.plan = a
        self.kind = a.kind
        self.count, self.count_arg = a.count, a.count_arg
        p = a.param
        self.elem = element_type(p.ctype, long_size) if a.kind is not Kind.TEXT else None
        self.size = ctypes.sizeof(self.elem) if self.elem is not None else 1
        # structures and char buffers travel as their bytes, numbers as values of the C type
        self.byte_like = p.is_struct or p.ctype in ("char", "unsigned char")
        k = _kind(self.elem)
        table = {"i": _INT_CODES, "u": _UINT_CODES, "f": _FLOAT_CODES}.get(k, {})
        self.fmt = table.get(self.size, "")

    def raw(self, ref: Ref) -> bool:
        """True when the caller's memory holds the C type's bytes (no conversion)."""
        if self.byte_like:
            return True
        if ref.py is None:
            e = ref.elem
            return e is not None and ctypes.sizeof(e) == self.size and _kind(e) == _kind(self.elem)
        if isinstance(ref.py, np.ndarray):
            dt = ref.py.dtype
            return dt.itemsize == self.size and dt.kind == _kind(self.elem)
        return False


class _Codec:
    """One function's request encoder and reply decoder for a client ``long`` size."""

    def __init__(self, plan: FunctionPlan, long_size: int) -> None:
        self.plan = plan
        self.args = [
            _Arg(a, long_size) if a.kind not in (Kind.INT, Kind.DOUBLE) else None for a in plan.args
        ]

    def encode(
        self, gtn: bool, core: int, values: list[Any], card: int = 0
    ) -> tuple[bytes, list[Any]]:
        flags = (CALL_GTN if gtn else 0) | (card << CARD_SHIFT)
        parts = [CALL.pack(MSG_CALL, flags, self.plan.fid, core)]
        outs: list[Any] = []
        for a, spec, v in zip(self.plan.args, self.args, values, strict=True):
            if spec is None:
                parts.append(I64.pack(v) if a.kind is Kind.INT else F64.pack(float(v)))
                continue
            if v is None:
                parts.append(PTR.pack(PTR_NULL))
                continue
            if spec.kind is Kind.TEXT:
                data = str(v).encode("utf-8") + b"\0"
                parts += (PTR.pack(len(data)), data)
                continue
            if spec.kind is Kind.OUT_ANY:
                parts.append(PTR.pack(PTR_UNKNOWN))
                outs.append((spec, v, -1))
                continue
            n = values[spec.count_arg] if spec.count_arg >= 0 else spec.count
            n = max(int(n), 0)
            data = self._load(spec, v, n)
            parts += (PTR.pack(len(data)), data)
            if a.carries_back:
                outs.append((spec, v, n))
        return b"".join(parts), outs

    @staticmethod
    def _load(spec: _Arg, ref: Ref, n: int) -> bytes:
        """The bytes the pointer sends: ``n`` elements of the C type (fewer if it holds less)."""
        if spec.raw(ref):
            return ref.load_bytes(min(ref.byte_capacity(), n * spec.size))
        k = min(ref.capacity(), n)
        values = ref.load_values(k) if k else []
        if ref.growable():
            values += [0] * (n - k)  # a list grows to what the call writes
        if not spec.fmt:
            raise ParameterError(f"{ref.name}: cannot send these values as {spec.elem}")
        try:
            conv = [fit(spec.elem, v) for v in values]
            if spec.fmt in "fd":
                conv = [float(v) for v in conv]
            else:
                conv = [int(v) for v in conv]
            return struct.pack(f"<{len(conv)}{spec.fmt}", *conv)
        except (struct.error, TypeError, ValueError, OverflowError) as e:
            raise ParameterError(
                f"{ref.name}: {values[:4]} do not fit the C type {spec.plan.param.ctype}: {e}"
            ) from None

    @staticmethod
    def write_back(outs: list[Any], blocks: list[bytes]) -> None:
        for (spec, ref, n), block in zip(outs, blocks, strict=False):
            if n < 0 or spec.raw(ref):  # out[?] and same-typed memory: the bytes
                if block:
                    ref.store_bytes(block)
                continue
            k = len(block) // spec.size
            values = list(struct.unpack(f"<{k}{spec.fmt}", block[: k * spec.size]))
            if values:
                ref.store_values(values)


# --- the gt hook ---------------------------------------------------------------------------
def remote_call(
    session: Any,
    name: str,
    gtn: bool,
    core: int,
    values: list[Any],
    extra: dict[str, Any],
    address: str,
) -> int:
    """A bound GT call of an attached session (``gtecat.gt._core`` calls this); 0, or a
    refusal that carries the controller's code and reason."""
    conn: Connection | None = session.remote
    card = session.card
    if name == "GT_Open":
        return _open(session, conn, gtn, core, values, extra, address)
    assert conn is not None
    if name == "GT_Close":  # detach; a controller already gone leaves nothing to close
        try:
            rc, text = conn.call(name, gtn, core, values, card)
        except ControllerLost:
            rc, text = 0, ""
        if rc == 0:
            conn.cards.discard(card)
            if not conn.cards:  # the last card this session had open
                conn.close()
                session.remote = None
            return 0
        _refuse(name, rc, text)
    if conn.lost:
        _core.fail(_core.CMD_COMM, f"controller not responding: {conn.lost}")
    try:
        rc, text = conn.call(name, gtn, core, values, card)
    except ControllerLost as e:
        _core.fail(_core.CMD_COMM, f"controller not responding: {e}")
    if rc != 0:
        _refuse(name, rc, text)
    if name == "GT_SetCardNo":  # the session's own settings; the controller checked them
        session.select(int(values[0]))
    elif name == "GT_SetCore":
        session.core = int(values[0])
    return 0


def _refuse(name: str, rc: int, text: str) -> None:
    prefix = f"{name} returned {rc}: "
    reason = text[len(prefix) :] if text.startswith(prefix) else text
    _core.fail(rc, reason or "the controller gave no reason")


def _open(
    session: Any,
    conn: Connection | None,
    gtn: bool,
    core: int,
    values: list[Any],
    extra: dict[str, Any],
    address: str,
) -> int:
    if session.all_controllers():
        _core.fail(
            _core.CMD_OPEN,
            "the controller is already open in this process (GT_Close first, then attach)",
        )
    card = session.card
    if conn is not None and not conn.lost and (not address or address == conn.address):
        if card in conn.cards:
            _core.fail(
                _core.CMD_OPEN,
                f"card {card} is already open on the controller at {conn.address} (GT_Close first)",
            )
        try:  # another card of the same controller, on the same connection
            rc, text = conn.call("GT_Open", gtn, core, values, card)
        except ControllerLost as e:
            _core.fail(_core.CMD_COMM, f"controller not responding: {e}")
        if rc != 0:
            _refuse("GT_Open", rc, text)
        conn.cards.add(card)
        return 0
    if conn is not None and not conn.lost:
        _core.fail(
            _core.CMD_OPEN,
            f"already attached to the controller at {conn.address} (GT_Close first)",
        )
    options = sorted(k for k in extra if k != "log")
    if options:
        raise ParameterError(
            f"GT_Open: {', '.join(options)} configure a controller in this process; the "
            f"controller at {address or conn.address if conn else address} has its own "
            "configuration (gtecat controller --eni ..., or its GTECAT_* environment)"
        )
    target = address or (conn.address if conn is not None else "")
    if conn is not None:
        conn.close()
        session.remote = None
    try:
        new = Connection(target)
    except ControllerError as e:
        _core.fail(_core.CMD_COMM, str(e))
    try:
        rc, text = new.call("GT_Open", gtn, core, values, card)
    except ControllerLost as e:
        _core.fail(_core.CMD_COMM, f"controller not responding: {e}")
    if rc != 0:
        new.close()
        _refuse("GT_Open", rc, text)
    new.cards.add(card)
    session.remote = new
    return 0


# --- the field side from Python -------------------------------------------------------------
class Trace:
    """Signals the controller records every cycle (:func:`gtecat.native.field.trace_start`)."""

    def __init__(self, f: Field, specs: list[str]) -> None:
        self._field = f
        self.id = int(f.call("trace_start", list(specs)))
        self.names = [s.strip() for s in specs]
        self._rows: list[list[float]] = []

    def read(self) -> np.ndarray:
        """Every row so far, ``(n, 1 + signals)``; column 0 is controller time in ms."""
        got = self._field.call("trace_read", self.id, len(self._rows))
        self._rows += got["rows"]
        return np.array(self._rows, dtype=np.float64).reshape(-1, 1 + len(self.names))

    @property
    def data(self) -> np.ndarray:
        return self.read()

    def column(self, name: str) -> np.ndarray:
        return self.read()[:, 1 + self.names.index(name)]

    def stop(self) -> None:
        self._field.call("trace_stop", self.id)


class Field:
    """The operations of :mod:`gtecat.native.field`, run by the controller (its call lock
    held, so each is atomic with respect to a cycle and to the other clients' calls)."""

    def __init__(self, connection: Connection, *, owned: bool = False, card: int = 0) -> None:
        self.connection = connection
        self._owned = owned
        #: the card whose machine the operations act on (gtecat.controller.cards)
        self.card = card

    @classmethod
    def connect(cls, address: str, card: int = 0) -> Field:
        """A connection of its own (an inspection verb; no GT_Open needed)."""
        return cls(Connection(address), owned=True, card=card)

    def close(self) -> None:
        if self._owned:
            self.connection.close()

    def __enter__(self) -> Field:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def call(self, op: str, *args: Any) -> Any:
        if self.card:  # (an inspection endpoint's connection knows one machine only)
            return self.connection.field(op, *args, card=self.card)
        return self.connection.field(op, *args)

    # the bus: gtecat.controller.inspect.BusView's methods, same names and results
    def positions(self, position: int | None = None) -> list[int]:
        return self.call("positions", position)

    def slaves(self, position: int | None = None) -> list[dict[str, Any]]:
        return self.call("slaves", position)

    def pdos(self, position: int | None = None) -> list[dict[str, Any]]:
        return self.call("pdos", position)

    def sdo_upload(self, slave: int, index: int, subindex: int) -> bytes:
        return bytes.fromhex(self.call("sdo_upload", slave, index, subindex)["bytes"])

    def sdo_download(self, slave: int, index: int, subindex: int, data: bytes) -> None:
        self.call("sdo_download", slave, index, subindex, bytes(data).hex())

    def sdo_entry(self, slave: int, index: int, subindex: int) -> dict[str, str]:
        return self.call("sdo_entry", slave, index, subindex)

    def sdo_find(self, slave: int, name: str, subindex: int | None = None) -> dict[str, Any]:
        return self.call("sdo_find", slave, name, subindex)

    def sdos(
        self, position: int | None = None, values: bool = True, grep: str | None = None
    ) -> list[dict[str, Any]]:
        return self.call("sdos", position, values, grep)

    def states(self, position: int | None = None, target: str | None = None) -> list[dict]:
        return self.call("states", position, target)

    def reg_read(self, position: int, address: int, size: int) -> bytes:
        return bytes.fromhex(self.call("reg_read", position, address, size))

    def reg_write(self, position: int, address: int, data: bytes) -> None:
        self.call("reg_write", position, address, bytes(data).hex())

    def sii(self, position: int) -> bytes:
        return bytes.fromhex(self.call("sii", position))

    def data(self, position: int | None = None, cycles: int = 0) -> list[dict[str, Any]]:
        return self.call("data", position, cycles)

    def cstruct(self, prefix: str = "", position: int | None = None) -> str:
        return self.call("cstruct", prefix, position)

    def graph(self) -> str:
        return self.call("graph")

    # drives
    def inject_fault(self, slave: int, kind: str | int, channel: int = 0) -> int:
        return self.call("inject_fault", slave, kind, channel)

    def clear_injected_fault(self, slave: int, channel: int = 0) -> None:
        self.call("clear_injected_fault", slave, channel)

    def set_machine_position(self, slave: int, value: float, channel: int = 0) -> None:
        self.call("set_machine_position", slave, float(value), channel)

    def set_analog_input(self, slave: int, n: int, value: int, channel: int = 0) -> None:
        self.call("set_analog_input", slave, n, value, channel)

    def drive(self, slave: int, channel: int = 0) -> dict[str, Any]:
        return self.call("drive", slave, channel)

    # IO terminals
    def set_input(self, slave: int, index: int, subindex: int, value: int) -> None:
        self.call("set_input", slave, index, subindex, value)

    def set_input_bit(self, slave: int, bit: int, on: bool) -> None:
        self.call("set_input_bit", slave, bit, bool(on))

    def get_output(self, slave: int, index: int, subindex: int) -> int:
        return self.call("get_output", slave, index, subindex)

    # traces and the cycle
    def trace(self, specs: list[str] | str) -> Trace:
        if isinstance(specs, str):
            specs = [s for s in specs.split(",") if s.strip()]
        return Trace(self, list(specs))

    def cycle_stats(self) -> dict[str, Any]:
        return self.call("cycle_stats")


def field(address: str | None = None, card: int | None = None) -> Field:
    """The field side of the controller this session is attached to (``GT_Open(controller=
    ...)``), or of the one at ``address`` on a connection of its own; of card ``card``
    (default: the session's current card, ``GT_SetCardNo``)."""
    if card is None:
        card = _core.SESSION.card
    if address is not None:
        return Field.connect(address, card)
    conn = _core.SESSION.remote
    if conn is None:
        raise ControllerError(
            "this session is not attached to a controller: GT_Open(controller='unix:/path') "
            "first, or field('unix:/path')"
        )
    return Field(conn, card=card)


__all__ = [
    "Connection",
    "ControllerError",
    "ControllerLost",
    "Field",
    "Trace",
    "field",
    "remote_call",
]
