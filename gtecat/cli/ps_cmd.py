"""``gtecat ps``: the running gtecats whose bus the verbs and the panel can attach to.

Every Python application that called ``GT_Open``, every running controller and every
serve (the kind column says which: python, controller, serve) publishes an inspection
endpoint (unless ``GTECAT_INSPECT=0``) in a per-user runtime folder
(``$XDG_RUNTIME_DIR/gtecat``, else ``/tmp/gtecat-UID``).  Entries of processes that have
ended are removed as they are found.
"""

from __future__ import annotations

import argparse
import time

from . import output

EPILOG = """\
examples:
  gtecat ps                        the running gtecats
  gtecat ps --json
  gtecat slaves --attach 4242      the bus of the one with id 4242"""


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "ps",
        help="list the running gtecats (applications, controllers, serves) the verbs can attach to",
        description=output.describe(__doc__),
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    output.add_json(p)
    p.set_defaults(func=run)


def _age(started: float) -> str:
    s = max(0, int(time.time() - started))
    return f"{s // 3600}h{s % 3600 // 60:02d}m" if s >= 3600 else f"{s // 60}m{s % 60:02d}s"


def run(args: argparse.Namespace) -> int:
    from ..inspect import runtime

    eps = runtime.endpoints()
    if args.json:
        output.print_json([e.as_dict() for e in eps])
        return 0
    if not eps:
        print(f"no running gtecat (endpoints are published in {runtime.folder()})")
        return 0
    rows = [
        {
            "id": e.id,
            "kind": e.kind,
            "clock": e.clock,
            "backend": e.backend,
            "up": _age(e.started),
            "eni": e.eni,
            "program": e.program,
        }
        for e in eps
    ]
    output.print_table(
        rows,
        [
            ("id", "id"),
            ("kind", "kind"),
            ("clock", "clock"),
            ("backend", "backend"),
            ("up", "up"),
            ("eni", "ENI"),
            ("program", "program"),
        ],
    )
    return 0
