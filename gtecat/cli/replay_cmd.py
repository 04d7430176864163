"""``gtecat replay FILE``: re-run a recorded session and report the first divergence.

The recorded calls are made again in order on a fresh controller (the recorded ENI and
machine description, or ``--eni`` / ``--machine``), with the faults at their places; every
return code, every value written back and every bus checkpoint is compared.  Exit 0 when
all match; 1 with the first divergence: the call, the argument, the recorded and the new
value.  Replaying against another ENI or machine description shows what a change does to
a session that worked.  A recorded ENI or machine description replaced at its name since
the recording is named before anything runs (exit 1); give it with ``--eni`` /
``--machine`` to replay against it on purpose.
"""

from __future__ import annotations

import argparse
import gc
import sys
import time
from pathlib import Path
from typing import Any

import gtecat

from . import output

EPILOG = """\
examples:
  gtecat replay session.gtrec
  gtecat replay session.gtrec --eni manual_fig5_2.eni   the same session on another ENI"""


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "replay",
        help="re-run a recording of gtecat record; exit 1 at the first divergence",
        description=output.describe(__doc__),
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("file", type=Path, help="the recording")
    p.add_argument("--eni", help="replay on this ENI instead of the recorded one")
    p.add_argument("--machine", help="replay with this machine description")
    # (the process ends at once after the replay: its session is not taken apart)
    p.set_defaults(func=run, leave_at_once=True)


def _imported_paused() -> Any:
    """The replay's modules imported (numpy on one BLAS thread, the GT layer, the faults), with
    the cyclic collector paused: the import makes ~200,000 objects that live as long as the
    process, and the collector ran ~80 times while they were made (~25 ms of a replay's
    start) to find a few hundred.  Once imported they are put in its oldest generation as a
    pass would leave them (``gc.freeze`` then ``gc.unfreeze``: moved, not walked), so the
    replay's own pause and freeze (:func:`gtecat.faults.record.replay`) start from none
    young.  Returns the replay function."""
    paused = gc.isenabled()
    if paused:
        gc.disable()
    try:
        gtecat.numpy_with_one_blas_thread()
        # a replay runs no program of its own: the GT layer's vendor surface (its ~600
        # structures, declared-only functions, constants) is made only if the recording names
        # one of them
        gtecat._SURFACE_LATER = True
        from ..faults.record import replay
    finally:
        if paused:
            from ..controller.core import process_froze, unfreeze

            if not process_froze():  # (a process that froze its own: left so)
                gc.freeze()
                unfreeze()
            gc.enable()
    return replay


def run(args: argparse.Namespace) -> int:
    replay = _imported_paused()

    t0 = time.perf_counter()
    n, div = replay(args.file, eni=args.eni, machine=args.machine)
    wall = time.perf_counter() - t0
    if div is not None:
        print(f"replay: diverged at {div}", file=sys.stderr)
        return 1
    print(f"replay: {n} calls match ({wall:.2f} s)")
    return 0
