"""``gtecat controller [--listen unix:/path | tcp:HOST:PORT]``: one virtual controller for
native clients.

Runs the controller (bus, clock, axes, field side) of the ``GTECAT_*`` environment (or
the options) and serves it over a Unix socket, or over TCP, to any number of clients:
programs linked with ``libgts.so`` (``GTECAT_CONTROLLER=unix:/path``), a Windows program
with gtecat's ``gts.dll`` beside it (``tcp:HOST:PORT``), Python code loading the library
through ctypes, other tools.

Over TCP every connection presents a token: the one in ``--token-file`` when given, else
``GTECAT_TOKEN``, else a random one written to a file only you can read (its path is
printed).  It listens on 127.0.0.1 unless you name another address; the clients are
served independently, and a connection without the right token is closed.

The first client's ``GT_Open`` opens the controller; calls are served one at a time.
In ``auto`` clock mode the controller keeps its time at or ahead of wall time (the wall
floor, docs/native.md), so programs that sleep between polls see their sleeps pass;
``--no-wall-floor`` (GTECAT_WALL_FLOOR=0) keeps pure, deterministic ``auto``.

While other programs keep every CPU busy, the controller serves calls under real-time
priority (SCHED_FIFO 50) where the system permits it (root or CAP_SYS_NICE), so that a
call does not wait for another program's time slice; ``--rt-priority off``
(GTECAT_RT_PRIORITY=off) never asks for it.  ``--slice-us 100`` (GTECAT_SLICE_US=100;
Linux 6.12 and later) makes the serving thread ask for a short time slice, so that at
normal priority a request that wakes it tends to run it at once (off by default).

``libgts.so`` starts a private one of these by itself on ``GT_Open`` when
``GTECAT_CONTROLLER`` is not set; it ends with the program.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import signal
import socket
import sys
from pathlib import Path
from types import FrameType
from typing import TYPE_CHECKING

from .. import scheduling

if TYPE_CHECKING:
    from ..native.server import Server


def default_address() -> str:
    from ..native.transport import DEFAULT_TCP_PORT, runtime_dir

    if not hasattr(socket, "AF_UNIX"):  # Windows: no Unix sockets for the DLL to reach
        return f"tcp:127.0.0.1:{DEFAULT_TCP_PORT}"
    return f"unix:{runtime_dir() / 'controller.sock'}"


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "controller",
        help="run a virtual controller for libgts / ctypes clients (Unix socket)",
        description=__doc__,
        epilog="examples:\n"
        "  gtecat controller --eni manual_fig5_2.eni --listen unix:/tmp/ctl.sock\n"
        "  gtecat controller --eni Gecat.eni --machine machine.toml --clock lockstep\n"
        "  gtecat controller --eni Gecat.eni --listen tcp:127.0.0.1:7701\n"
        "  gtecat controller --eni Gecat.eni --listen tcp:0.0.0.0:7701 --token-file ctl.token",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument(
        "--listen",
        metavar="ADDR",
        help="unix:/path (or unix:@name, Linux abstract), or tcp:HOST:PORT (127.0.0.1 unless "
        f"HOST says otherwise; port 0: any free port); default {default_address()}",
    )
    p.add_argument(
        "--token-file",
        metavar="FILE",
        help="tcp: the token clients must present, read from FILE (else GTECAT_TOKEN, else "
        "a random one written to a file only you can read)",
    )
    p.add_argument("--eni", help="configuration file (else GTECAT_ENI, else ./Gecat.eni)")
    p.add_argument("--machine", help="machine description TOML (else GTECAT_MACHINE)")
    p.add_argument("--clock", choices=("auto", "lockstep", "realtime"), help="else GTECAT_CLOCK")
    p.add_argument("--backend", choices=("emulated", "pysoem"), help="else GTECAT_BACKEND")
    p.add_argument("--iface", help="network interface for pysoem (else GTECAT_IFACE)")
    p.add_argument("--card", help="a GTS pulse card, gts:N, instead of a bus (else GTECAT_CARD)")
    p.add_argument(
        "--no-wall-floor",
        action="store_true",
        help="auto clock without the wall floor: controller time moves only by call latency "
        "and waits (deterministic; programs that sleep see no time pass)",
    )
    p.add_argument(
        "--rt-priority",
        type=_rt_priority,
        metavar="N|auto|off",
        help="while other programs keep every CPU busy, serve calls under SCHED_FIFO "
        "priority N (1-99); auto (the default, else "
        f"{scheduling.RT_ENV}) takes priority {scheduling.AUTO_RT_PRIORITY} where the system "
        "permits it (root or CAP_SYS_NICE), else runs normally; off never asks",
    )
    p.add_argument(
        "--slice-us",
        type=_slice_us,
        metavar="US",
        help="a time slice the serving thread asks for (Linux 6.12 and later; 100 is the "
        "shortest), so that it runs sooner when a request wakes it while other programs "
        f"keep the CPUs busy; else {scheduling.SLICE_ENV}, else "
        f"{scheduling.DEFAULT_SLICE_US}: the thread is left alone",
    )
    # set by libgts when it starts a private controller
    p.add_argument("--ready-fd", type=int, help=argparse.SUPPRESS)
    p.add_argument("--lifeline-fd", type=int, help=argparse.SUPPRESS)
    p.add_argument("--private", action="store_true", help=argparse.SUPPRESS)
    p.set_defaults(func=run)


def _rt_priority(text: str) -> int | str:
    try:
        return scheduling.parse_priority(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def _slice_us(text: str) -> int:
    try:
        us = int(text)
    except ValueError:
        us = -1
    if us < 0:
        raise argparse.ArgumentTypeError(f"{text!r}: microseconds, 0 or more")
    return us


def _token(args: argparse.Namespace) -> tuple[str, str]:
    """The token of a TCP controller and a line saying where clients find it ("" when it
    is a new one: written to the port's default token file once the port is bound)."""
    from ..native import transport

    if args.token_file:
        return transport.read_token_file(args.token_file), f"token: in {args.token_file}"
    env = os.environ.get("GTECAT_TOKEN", "").strip()
    if env:
        transport.check_token(env, "GTECAT_TOKEN")
        return env, "token: GTECAT_TOKEN"
    return transport.make_token(), ""


def _take_scheduling(server: Server, rt_setting: int | str) -> tuple[scheduling.Scheduling, bool]:
    """Give the serving thread what ``rt_setting`` asks for: real-time while the CPUs are busy
    where permitted (:class:`scheduling.WhenBusy`), and in every case its client's CPU while
    they are busy (:class:`scheduling.Beside`: a normal-priority controller beside its client
    met the bar under load more often than one left where the kernel puts it).  Returns what
    was taken and whether the controller was started real-time (``chrt``: then left as it
    is); :class:`scheduling.RealtimeRefused` for a priority number the system refuses."""
    normal = scheduling.snapshot()
    started_rt = rt_setting == "auto" and scheduling.is_realtime()
    if started_rt:
        rt_setting = "off"
    taken = scheduling.take(rt_setting)
    if taken.priority is not None:
        server.realtime = scheduling.WhenBusy(taken.priority, normal=normal[:2] if normal else None)
        server.realtime.realtime = True  # until the first look at the load
    if normal:
        server.beside = scheduling.Beside(normal[2])
    return taken, started_rt


def _wall_floor(args: argparse.Namespace) -> bool:
    from ..native.floor import wall_floor_setting

    return not args.no_wall_floor and wall_floor_setting()


def _close_inherited(keep: set[int]) -> None:
    """A private controller holds none of the program's descriptors (sockets, files)."""
    try:
        fds = [int(n) for n in os.listdir("/proc/self/fd")]
    except OSError:
        fds = list(range(3, 256))
    for fd in fds:
        if fd > 2 and fd not in keep:
            with contextlib.suppress(OSError):
                os.close(fd)


def run(args: argparse.Namespace) -> int:
    from ..native.server import Server

    if args.private:
        _close_inherited({fd for fd in (args.ready_fd, args.lifeline_fd) if fd is not None})
    from ..native import transport

    address = args.listen or default_address()
    token, token_note = None, ""
    own_file = False
    try:
        addr = transport.parse(address)
        if args.token_file and not addr.tcp:
            raise ValueError(
                "--token-file is for tcp: addresses (a Unix socket is guarded by its folder)"
            )
        if addr.tcp:
            token, token_note = _token(args)
            own_file = not token_note
    except ValueError as e:
        print(f"error: {e}", file=sys.stderr)
        return 1
    if not args.listen and not addr.tcp:
        try:
            transport.private_dir(Path(addr.path).parent)
        except (OSError, ValueError) as e:
            print(f"error: {e}", file=sys.stderr)
            return 1
    options = {
        k: v
        for k, v in (
            ("eni", args.eni),
            ("machine", args.machine),
            ("clock", args.clock),
            ("backend", args.backend),
            ("iface", args.iface),
            ("card", args.card),
        )
        if v is not None
    }
    try:
        rt_setting = scheduling.from_environment(args.rt_priority)
    except ValueError as e:
        print(f"error: {e}", file=sys.stderr)
        return 1
    server = Server(
        address,
        open_options=options,
        wall_floor=_wall_floor(args),
        lifeline_fd=args.lifeline_fd,
        remove_dir=args.private,
        token=token,
    )

    token_path = None
    if own_file and token is not None:
        # the port's own file (port 0: the one bound), gone when the controller ends
        token_path = transport.default_token_file(transport.parse(server.address).port)
        try:
            transport.private_dir(token_path.parent)
            transport.write_token_file(token_path, token)
        except (OSError, ValueError) as e:
            print(f"error: {e}", file=sys.stderr)
            server.stop()
            return 1
        token_note = f"token: written to {token_path} (readable by you only)"

    # the scheduling of the thread that serves, once the socket listens: asked for now (the
    # line says what the system permits; a refusal of a number ends the controller here),
    # then taken only while the CPUs are busy (scheduling.WhenBusy)
    slice_us = args.slice_us if args.slice_us is not None else scheduling.slice_from_environment()
    # (the compiler it may start builds with the default slice, as it runs normally)
    slice_words = scheduling.short_slice(slice_us, reset_on_fork=True)
    try:
        taken, started_rt = _take_scheduling(server, rt_setting)
    except scheduling.RealtimeRefused as e:
        print(f"error: {e}", file=sys.stderr)
        server.stop()
        return 1

    def stop(signum: int, frame: FrameType | None) -> None:
        server.stop()

    signal.signal(signal.SIGTERM, stop)
    if args.private:
        signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is for the program; it ends us
    if args.ready_fd is not None:
        with contextlib.suppress(OSError):
            os.write(args.ready_fd, b"ready\n")
            os.close(args.ready_fd)
    else:
        sched = "real-time priority as started" if started_rt else taken.words
        if taken.priority is not None:
            sched += " while the CPUs are busy"
        if slice_words:
            sched += f", {slice_words}"
        if taken.refused:
            sched += ": run as root or give python CAP_SYS_NICE for real-time priority"
        print(
            f"gtecat controller listening on {server.address} ({sched})",
            file=sys.stderr,
            flush=True,
        )
        if token_note:
            print(token_note, file=sys.stderr, flush=True)
    try:
        server.serve_forever()
    finally:
        if token_path is not None:
            with contextlib.suppress(OSError):
                token_path.unlink()
    return 0
