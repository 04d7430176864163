"""A protocol-level client for tests: encodes calls as libgts does, from the same plans."""

from __future__ import annotations

import ctypes
import socket
from typing import Any

from gtecat.native import protocol as p
from gtecat.native.protocol import socket_path

_LONG = ctypes.sizeof(ctypes.c_long)


class WireClient:
    def __init__(self, address: str, *, digest: str | None = None) -> None:
        self.sock = socket.socket(socket.AF_UNIX, p.SOCKET_TYPE)
        self.sock.settimeout(10)
        self.sock.connect(socket_path(address))
        d = (digest or p.table_digest()).encode()
        status, text = self._hello(d)
        self.hello_status, self.hello_text = status, text
        self.by_name = {pl.name: pl for pl in p.plans()}

    def _send(self, body: bytes) -> bytes:
        data = p.FRAME.pack(len(body)) + body
        for i in range(0, len(data), p.CHUNK):  # records of at most CHUNK bytes
            self.sock.sendall(data[i : i + p.CHUNK])
        out = b""
        need = 4
        while len(out) < need:
            chunk = self.sock.recv(max(p.CHUNK, need - len(out)))
            if not chunk:
                raise ConnectionError("controller closed the connection")
            out += chunk
            if need == 4 and len(out) >= 4:
                need = 4 + p.FRAME.unpack_from(out, 0)[0]
        return out[4:need]

    def _hello(self, digest: bytes) -> tuple[int, str]:
        body = self._send(p.HELLO.pack(p.MSG_HELLO, p.PROTOCOL_VERSION, _LONG, digest))
        status, n = p.HELLO_REPLY.unpack_from(body, 0)
        return status, body[p.HELLO_REPLY.size : p.HELLO_REPLY.size + n].decode()

    def call(self, name: str, *args: Any, core: int | None = None) -> tuple[int, list, str]:
        """(return code, out blocks as bytes, error text); pointer args are bytes / None /
        an int (an out pointer of that many bytes) / "?" (size unknown)."""
        # a GTN_ line of its own (the header declares it with its core) is a plan of its own;
        # else GTN_x is GT_x's twin with the core in front
        own = name in self.by_name
        base = name if own else "GT_" + name[4:]
        plan = self.by_name[base]
        gtn = name.startswith("GTN_") and not own
        parts = [p.CALL.pack(p.MSG_CALL, int(gtn), plan.fid, core if core is not None else 1)]
        for a, v in zip(plan.args, args, strict=True):
            if a.kind is p.Kind.INT:
                parts.append(p.I64.pack(int(v)))
            elif a.kind is p.Kind.DOUBLE:
                parts.append(p.F64.pack(float(v)))
            elif v is None:
                parts.append(p.PTR.pack(p.PTR_NULL))
            elif v == "?":
                parts.append(p.PTR.pack(p.PTR_UNKNOWN))
            elif isinstance(v, int):
                parts.append(p.PTR.pack(v) + bytes(v))
            else:
                data = bytes(v)
                parts.append(p.PTR.pack(len(data)) + data)
        body = self._send(b"".join(parts))
        rc, nblocks, nerr = p.REPLY.unpack_from(body, 0)
        pos = p.REPLY.size
        blocks = []
        for _ in range(nblocks):
            (size,) = p.BLOCK.unpack_from(body, pos)
            pos += 4
            blocks.append(body[pos : pos + size])
            pos += size
        return rc, blocks, body[pos : pos + nerr].decode()

    def close(self) -> None:
        self.sock.close()
