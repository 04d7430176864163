"""The per-user runtime folder where running gtecats publish their inspection endpoints.

``$XDG_RUNTIME_DIR/gtecat`` (the user's own tmpfs on a systemd machine), else
``/tmp/gtecat-UID``.  The folder is created 0700; one that exists must belong to the user
and be closed to others (group and others no access), else nothing is published there
and the reason is given: another user could otherwise listen in place of a controller.

Each endpoint is two files: ``ID.sock`` (the Unix socket, 0600) and ``ID.json`` (who
published it: pid, kind, program, ENI, start time).  An entry whose pid is gone is stale
(its process was killed, or ended without its atexit handlers): :func:`endpoints` removes
it, and every new endpoint removes those of dead processes first (:func:`sweep`), so the
folder does not fill up on a machine where such processes are common (test runs).
"""

from __future__ import annotations

import contextlib
import json
import os
import stat
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..errors import BusError


def folder() -> Path:
    base = os.environ.get("XDG_RUNTIME_DIR", "")
    if base and Path(base).is_dir():
        return Path(base) / "gtecat"
    return Path("/tmp") / f"gtecat-{os.getuid()}"


def checked_folder(create: bool = True) -> Path:
    """The folder, made 0700 when missing; BusError when it is not the user's own."""
    path = folder()
    if create:
        with contextlib.suppress(FileExistsError):
            path.mkdir(mode=0o700, parents=False)
    try:
        st = path.lstat()
    except FileNotFoundError:
        return path
    if not stat.S_ISDIR(st.st_mode):
        raise BusError(f"{path} is not a folder; remove it so gtecat can publish its endpoints")
    if st.st_uid != os.getuid():
        raise BusError(f"{path} belongs to uid {st.st_uid}, not to you; endpoints not published")
    if st.st_mode & 0o077:
        raise BusError(
            f"{path} is open to other users (mode {stat.S_IMODE(st.st_mode):04o}); "
            "chmod 700 it so gtecat can publish its endpoints there"
        )
    return path


@dataclass(frozen=True)
class EndpointInfo:
    """One published endpoint, as ``gtecat ps`` shows it."""

    id: str
    pid: int
    kind: str
    program: str
    eni: str
    clock: str
    backend: str
    started: float
    socket: Path

    def who(self) -> str:
        """Which process it is, for a user who shares the machine (and the user id) with
        others: ``ID (pid N, PROGRAM, started HH:MM:SS)``."""
        started = time.strftime("%Y-%m-%d %H:%M:%S", time.localtime(self.started))
        return f"{self.id} (pid {self.pid}, {self.program or self.kind}, started {started})"

    def as_dict(self) -> dict[str, Any]:
        d = dict(self.__dict__)
        d["socket"] = str(self.socket)
        return d


def alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def remove(path: Path) -> None:
    for p in (path.with_suffix(".sock"), path.with_suffix(".json")):
        with contextlib.suppress(FileNotFoundError):
            p.unlink()


def sweep(path: Path) -> None:
    """Remove the files of endpoints whose process is gone, told by the pid in their name
    (``PID`` or ``PID-N``; nothing is read).  A live process's files are left, also half
    published ones (its socket before its ``.json``)."""
    try:
        names = os.listdir(path)
    except OSError:
        return
    gone: dict[int, bool] = {}
    for name in names:
        stem, dot, ext = name.rpartition(".")
        if not dot or ext not in ("sock", "json", "tmp"):
            continue
        head = stem.split("-", 1)[0]
        if not head.isdigit():
            continue
        pid = int(head)
        if pid not in gone:
            gone[pid] = not alive(pid)
        if gone[pid]:
            with contextlib.suppress(OSError):
                (path / name).unlink()


def endpoints() -> list[EndpointInfo]:
    """Every live endpoint, oldest first; stale ones (dead pid, no socket) are removed."""
    path = folder()
    if not path.is_dir():
        return []
    checked_folder(create=False)
    out = []
    for meta in sorted(path.glob("*.json")):
        try:
            d = json.loads(meta.read_text(encoding="utf-8"))
            pid = int(d["pid"])
        except (OSError, ValueError, KeyError, TypeError):
            remove(meta)
            continue
        sock = meta.with_suffix(".sock")
        if not alive(pid) or not sock.exists():
            remove(meta)
            continue
        out.append(
            EndpointInfo(
                id=meta.stem,
                pid=pid,
                kind=str(d.get("kind", "")),
                program=str(d.get("program", "")),
                eni=str(d.get("eni", "")),
                clock=str(d.get("clock", "")),
                backend=str(d.get("backend", "")),
                started=float(d.get("started", 0.0)),
                socket=sock,
            )
        )
    out.sort(key=lambda e: e.started)
    return out


def find(wanted: str | None) -> EndpointInfo | None:
    """The endpoint ``wanted`` names (its ID or pid), or the only one running (None: none
    runs); BusError when several run and none is named, or the named one is not there."""
    eps = endpoints()
    if wanted:
        for e in eps:
            if wanted in (e.id, str(e.pid)):
                return e
        have = ", ".join(e.id for e in eps) or "none"
        raise BusError(f"no running gtecat with id {wanted!r} (running: {have}; see gtecat ps)")
    if len(eps) > 1:
        raise BusError(
            f"{len(eps)} gtecats are running: "
            + "; ".join(e.who() for e in eps)
            + "; choose one with --attach ID (gtecat ps lists them)"
        )
    return eps[0] if eps else None
