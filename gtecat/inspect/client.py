"""Attaching to a running gtecat's inspection endpoint (the protocol of :mod:`.endpoint`).

:class:`Attached` sends requests and returns results (a failed request raises
:class:`~gtecat.errors.BusError` with the endpoint's reason); :func:`attach_view` gives the
bus verbs an object with :class:`gtecat.controller.inspect.BusView`'s methods (the
:class:`gtecat.native.client.Field` face), so a verb prints the same attached or not.
"""

from __future__ import annotations

import itertools
import json
import socket
import threading
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from ..errors import BusError
from . import runtime


class Attached:
    """One connection to an endpoint; thread-safe (one request at a time)."""

    def __init__(self, path: str | Path, timeout: float = 10.0) -> None:
        self.path = str(path)
        self._sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        self._sock.settimeout(timeout)
        try:
            self._sock.connect(self.path)
        except OSError as e:
            self._sock.close()
            raise BusError(f"cannot attach to {self.path}: {e.strerror or e}") from None
        self._rf = self._sock.makefile("rb")
        self._ids = itertools.count(1)
        self._lock = threading.Lock()

    def call(self, op: str, *args: Any) -> Any:
        with self._lock:
            rid = next(self._ids)
            msg = json.dumps({"id": rid, "op": op, "args": list(args)}, separators=(",", ":"))
            try:
                self._sock.sendall(msg.encode() + b"\n")
                line = self._rf.readline()
            except OSError as e:
                raise BusError(f"the running gtecat went away ({e})") from None
            if not line:
                raise BusError("the running gtecat closed the connection (it has ended)")
            reply = json.loads(line)
        if not reply.get("ok"):
            raise BusError(str(reply.get("error", "refused")))
        return reply.get("result")

    def subscribe(self, op: str, period_ms: float, *args: Any) -> Iterator[Any]:
        """Results of ``op`` pushed every ``period_ms`` (the connection is then the
        subscription's: no other request on it)."""
        self.call("subscribe", op, period_ms, *args)
        self._sock.settimeout(None)
        for line in self._rf:
            msg = json.loads(line)
            if msg.get("push") == op:
                yield msg["result"]
        raise BusError("the running gtecat closed the connection (it has ended)")

    # the face gtecat.native.client.Field expects of a connection
    def field(self, op: str, *args: Any) -> Any:
        return self.call(op, *args)

    def close(self) -> None:
        try:
            self._rf.close()
        finally:
            self._sock.close()

    def __enter__(self) -> Attached:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def connect(wanted: str | None) -> tuple[runtime.EndpointInfo, Attached] | None:
    """The endpoint ``wanted`` names, else the only one running; None when none runs."""
    info = runtime.find(wanted)
    if info is None:
        return None
    return info, Attached(info.socket)


def attach_view(conn: Attached) -> Any:
    """The bus verbs' view of an attached controller (Field's methods over the endpoint)."""
    from ..native.client import Field

    return Field(conn, owned=True)  # type: ignore[arg-type]


__all__ = ["Attached", "attach_view", "connect"]
