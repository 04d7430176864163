"""``gtecat run SCRIPT.py``: run a user's GT script with chosen emulator settings.

The options become the ``GTECAT_*`` environment the script's ``GT_Open`` reads, so the
script itself needs no change.  ``--trace`` records signals every cycle once the bus is
up (see :mod:`gtecat.recorder` for the names) and writes ``<stem>.csv`` and ``<stem>.png``.
"""

from __future__ import annotations

import argparse
import os
import runpy
import sys
import time
from pathlib import Path

from ..controller import Controller
from ..errors import ParameterError


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("run", help="run a GT script under the emulator")
    p.add_argument("script", help="Python script using `from gtecat import gt`")
    p.add_argument("args", nargs="*", help="arguments for the script (after --)")
    p.add_argument("--eni", help="configuration file (GTECAT_ENI)")
    p.add_argument("--machine", help="machine description TOML (GTECAT_MACHINE)")
    p.add_argument("--clock", choices=("auto", "lockstep", "realtime"), help="GTECAT_CLOCK")
    p.add_argument("--backend", choices=("emulated", "pysoem"), help="GTECAT_BACKEND")
    p.add_argument("--iface", help="network interface for pysoem (GTECAT_IFACE)")
    p.add_argument("--trace", help="comma-separated signals, e.g. axis1.prf,axis1.enc,0:0x6041:0")
    p.add_argument("--trace-out", default=None, help="output stem (default: the script's name)")
    p.add_argument("--no-progress", action="store_true")
    p.set_defaults(func=run)


class _Progress:
    """One status line on stderr (a tty only): controller time against wall time."""

    def __init__(self, enabled: bool) -> None:
        self.enabled = enabled and sys.stderr.isatty()
        self.t0 = time.perf_counter()
        self.last = 0.0

    def __call__(self, ctl: Controller) -> None:
        if not self.enabled:
            return
        now = time.perf_counter()
        if now - self.last < 0.25:
            return
        self.last = now
        virt = ctl.clock.now_ns / 1e9
        bar = "#" * (int(virt) % 20 + 1)
        sys.stderr.write(
            f"\r  {bar:<20} {virt:8.2f} s controller time, {now - self.t0:6.1f} s wall"
        )
        sys.stderr.flush()

    def done(self) -> None:
        if self.enabled:
            sys.stderr.write("\n")


def run(args: argparse.Namespace) -> int:
    script = Path(args.script)
    if not script.is_file():
        raise ParameterError(f"script {script} not found")
    env = {
        "GTECAT_ENI": args.eni,
        "GTECAT_MACHINE": args.machine,
        "GTECAT_CLOCK": args.clock,
        "GTECAT_BACKEND": args.backend,
        "GTECAT_IFACE": args.iface,
    }
    for k, v in env.items():
        if v:
            os.environ[k] = str(Path(v).resolve()) if k in ("GTECAT_ENI", "GTECAT_MACHINE") else v
    recorders = []
    progress = _Progress(not args.no_progress)
    specs = [s for s in (args.trace or "").split(",") if s.strip()]

    def attach(ctl: Controller) -> None:
        if specs:
            from ..recorder import Recorder

            recorders.append(Recorder(ctl, specs).start())
        ctl.sample.append(lambda _t: progress(ctl))

    Controller.bus_up_hooks.append(attach)
    sys.argv = [str(script), *args.args]
    rc = 0
    try:
        runpy.run_path(str(script), run_name="__main__")
    except SystemExit as e:
        rc = e.code if isinstance(e.code, int) else (0 if e.code is None else 1)
    finally:
        Controller.bus_up_hooks.remove(attach)
        progress.done()
    stem = Path(args.trace_out) if args.trace_out else script.with_suffix("")
    for i, rec in enumerate(recorders):
        base = stem if i == 0 else stem.with_name(f"{stem.name}_{i}")
        if rec.n == 0:
            continue
        csv_path = rec.to_csv(base.with_suffix(".csv"))
        png_path = rec.plot(base.with_suffix(".png"), title=f"{script.name}: {', '.join(specs)}")
        print(f"trace: {rec.n} cycles -> {csv_path}, {png_path}")
    return rc
