"""``gtecat panel``: watch (and with --control, drive) a running machine in a web browser.

Attaches to a running gtecat (``--attach ID``, else the only one ``gtecat ps`` lists), or
with ``--eni FILE`` brings up a bus of its own (realtime clock, servo on) and shows that.
Prints the page's address with a random token; the page is served on 127.0.0.1 only and
refuses any request without the token.  Read-only unless ``--control``: then jog buttons,
a Trap move form, IO inputs of the emulated bus, SDO downloads and state requests work.
Needs the ``panel`` extra (``pip install gtecat[panel]``: aiohttp).
"""

from __future__ import annotations

import argparse
import os
import sys
import threading
import time

from ..errors import BusError, ParameterError
from . import output

EPILOG = """\
examples:
  gtecat panel --eni manual_fig5_2.eni --control --port 8765
  gtecat panel                               the only running gtecat (gtecat ps)
  gtecat panel --attach 4242 --port 0        a chosen one, any free port"""


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "panel",
        help="a web page showing a running machine: bus, process image, axes, IO, scope",
        description=output.describe(__doc__),
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    g = p.add_mutually_exclusive_group()
    g.add_argument("--attach", metavar="ID", help="the running gtecat to show (gtecat ps)")
    g.add_argument("--eni", help="bring up a bus of this configuration and show it")
    p.add_argument("--machine", help="machine description TOML (with --eni)")
    p.add_argument(
        "--clock",
        default="paced",
        choices=("paced", "realtime"),
        help="with --eni: paced (default: controller time follows the wall clock in 10 ms "
        "steps, the cycles of each step run at once: light on the CPU) or realtime (a cycle "
        "thread on the wall clock, every cycle on time)",
    )
    p.add_argument("--control", action="store_true", help="allow changing the machine")
    p.add_argument("--port", type=int, default=0, help="TCP port on 127.0.0.1 (0: any free)")
    p.set_defaults(func=run)


def _host(args: argparse.Namespace) -> str:
    """Bring up the --eni bus in this process (as an application would) and publish it."""
    import ctypes

    from .. import gt
    from ..inspect import endpoint

    os.environ["GTECAT_INSPECT"] = "1"  # the panel reads it through its endpoint
    log = os.environ.get("GTECAT_LOG", "")
    clock = "realtime" if args.clock == "realtime" else "auto"
    rc = gt.GT_Open(eni=args.eni, machine=args.machine, clock=clock, log=log)
    if rc:
        raise BusError(f"GT_Open returned {rc}: {gt.GTE_GetLastError()}")
    for call in (gt.GT_Reset, gt.GT_InitEcatComm):
        rc = call()
        if rc:
            raise BusError(f"{call.__name__} returned {rc}: {gt.GTE_GetLastError()}")
    ready = ctypes.c_short()
    for _ in range(500):
        gt.GT_IsEcatReady(ctypes.byref(ready))
        if ready.value:
            break
        gt.GTE_Wait(10)
    if not ready.value:
        raise BusError("the bus did not reach OP within 5 s")
    gt.GT_StartEcatComm()
    ctl = gt.GTE_Controller()
    for axis in sorted(ctl.axes):
        gt.GT_AxisOn(axis)
    ep = endpoint.published(ctl)
    if ep is None or ep.path is None:
        raise BusError("could not publish the inspection endpoint (see the warning above)")
    return str(ep.path)


def _pacer() -> threading.Event:
    """Let controller time follow the wall clock in steps of ``STEP_MS`` (the panel's own
    bus, ``--clock paced``): one thread, one wake-up per step.  Returns its stop event."""
    from .. import gt

    stop = threading.Event()

    def pace() -> None:
        t0 = time.monotonic()
        ctl = gt.GTE_Controller()
        ms0 = ctl.clock.now_ns / 1e6
        while not stop.is_set():
            behind = (time.monotonic() - t0) * 1000 - (ctl.clock.now_ns / 1e6 - ms0)
            if behind >= STEP_MS:
                gt.GTE_Wait(int(behind))
            stop.wait(STEP_MS / 1000)

    threading.Thread(target=pace, name="gtecat-panel-pace", daemon=True).start()
    return stop


#: controller milliseconds per step of the paced clock
STEP_MS = 10


def run(args: argparse.Namespace) -> int:
    try:
        import aiohttp  # noqa: F401
    except ImportError:
        raise ParameterError("gtecat panel needs aiohttp: pip install 'gtecat[panel]'") from None
    from ..inspect import panel, runtime

    pace = None
    if args.eni:
        path = _host(args)
        title = f"{os.path.basename(args.eni)} (this process)"
        if args.clock == "paced":
            pace = _pacer()
    else:
        info = runtime.find(args.attach)
        if info is None:
            raise BusError(
                "no running gtecat to show (gtecat ps); start your application, or give "
                "--eni FILE for a bus of the panel's own"
            )
        if info.kind == "serve":
            raise BusError(
                f"{info.id} is a gtecat serve: the panel shows a controller's bus, and a "
                "serve's controller is its master on the other end of the wire; see the "
                f"serve's slaves with gtecat states --attach {info.id} and its faults with "
                f"gtecat fault list --attach {info.id}"
            )
        path = str(info.socket)
        title = f"{info.kind} {info.id}: {os.path.basename(info.eni)}"

    def ready(url: str) -> None:
        mode = "control" if args.control else "read-only"
        print(f"gtecat panel ({mode}): {url}", flush=True)

    try:
        gone = panel.serve(path, control=args.control, port=args.port, title=title, ready=ready)
    except KeyboardInterrupt:
        gone = ""
    except OSError as e:
        print(f"error: {e}", file=sys.stderr)
        return 1
    finally:
        if pace is not None:
            pace.set()
    if gone:
        print(
            f"the watched gtecat ({title}) stopped answering: {gone}; the panel ends",
            file=sys.stderr,
        )
        return 1
    return 0
