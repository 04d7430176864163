"""The in-process controller: libgts's private controller inside the program itself.

Where ``GTECAT_INPROCESS`` allows it, libgts does not start ``gtecat controller`` as a
process of its own: it loads the Python runtime gtecat was installed for into the
program (:func:`ask` tells it where that runtime and its packages are), and hands every
GT call's request frame to :meth:`Host.call`, which answers it with the controller
server's own dispatcher (:meth:`gtecat.native.server.Server.answer`) and returns the
reply frame.  A call is then a function call under the interpreter's lock instead of two
wake-ups of two processes: nothing waits for a CPU a busy program holds.

The server still listens on the private socket (other tools, a forked child of the
program, a second program attach as they would to the forked controller), and its thread
keeps the wall floor while the program sleeps, as the idle controller does.  Calls of the
program's threads are serialised by the interpreter's lock and the server's call lock,
as the forked controller serialises its clients.
"""

from __future__ import annotations

import atexit
import importlib.util
import json
import os
import sys
import sysconfig


class Host:
    """The program's in-process controller: one server listening at ``address`` (a Unix
    socket in a folder made for it) and the program's own connection to it."""

    def __init__(self, address: str) -> None:
        from .floor import wall_floor_setting
        from .server import Server

        self.server = Server(address, wall_floor=wall_floor_setting(), remove_dir=True)
        self.server.start()
        self.client = self.server.local_client()

    def connect(self) -> None:
        """A new connection of the program (GT_Open after the last card was closed): the
        cards it had opened are forgotten, as when its socket closes."""
        self.server.forget(self.client)
        self.client = self.server.local_client()

    def call(self, frame: bytes) -> bytes:
        """One request frame (hello or call, length prefix included) -> its reply frame.
        A request the protocol does not allow gives b"" (logged; the call returns -1)."""
        return self.server.answer(self.client, frame)

    def stop(self) -> None:
        self.server.forget(self.client)
        self.server.stop()

    def end(self) -> None:
        """The program ends (libgts's exit handler): the server stops and what this Python
        would do at its exit is done (files of the inspection endpoint removed, recordings
        written), as when the controller process ends."""
        self.stop()
        atexit._run_exitfuncs()


def start(address: str) -> Host:
    """Called by libgts once the runtime is up (its log says why, where it fails)."""
    return Host(address)


def ask(path: list[str] | None = None) -> dict[str, object]:
    """What libgts needs to host this interpreter's gtecat in a program: the shared
    runtime library to load, its home, and the module path of this environment (``path``,
    else ``sys.path``; the folder gtecat is imported from first)."""
    cfg = sysconfig.get_config_var
    libdir = str(cfg("LIBDIR") or "")
    names = [str(n) for n in (cfg("INSTSONAME"), cfg("LDLIBRARY")) if n]
    libs = [os.path.join(libdir, n) for n in names if ".so" in n or n.endswith(".dylib")]
    spec = importlib.util.find_spec("gtecat")
    root = ""
    if spec is not None and spec.origin:
        root = os.path.dirname(os.path.dirname(os.path.abspath(spec.origin)))
    path = [root] + [p for p in (sys.path if path is None else path) if p and p != root]
    return {
        "shared": bool(cfg("Py_ENABLE_SHARED")),
        "libs": [p for p in libs if os.path.exists(p)],
        "home": sys.base_prefix,
        "version": f"{sys.version_info[0]}.{sys.version_info[1]}",
        "root": root,
        "path": path,
        "prefix": sys.prefix,
        "executable": sys.executable,
    }


def main() -> int:
    """``python -m gtecat.native.inprocess``: :func:`ask`'s answer for libgts, one item a
    line: the runtime library ("" where this interpreter has none to share), its home, its
    version, the folder gtecat is in, then all of it as JSON (for :func:`settle`)."""
    a = ask(sys.path[1:])  # (not the folder `-m` was run from: the program's, not ours)
    libs = a["libs"]  # (an interpreter linked statically may have its library beside it)
    print(libs[0] if libs else "")  # type: ignore[index]
    for key in ("home", "version", "root"):
        print(a[key])
    print(json.dumps(a))
    return 0


def settle(env: bytes) -> None:
    """In the program, right after the runtime started: this environment's module path,
    prefix and interpreter (:func:`ask` of the interpreter gtecat was installed for)."""
    a = json.loads(env)
    sys.path[:] = a["path"]
    sys.prefix = sys.exec_prefix = a["prefix"]
    sys.executable = a["executable"]
    try:  # the program's command line (gtecat ps names the program by it)
        with open("/proc/self/cmdline", "rb") as f:
            sys.argv = [os.fsdecode(w) for w in f.read().split(b"\0")[:-1]]
    except OSError:
        pass


if __name__ == "__main__":
    sys.exit(main())
