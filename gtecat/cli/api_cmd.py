"""``gtecat api``: the GT API by group - what is emulated and what is declared only.

Examples:

    gtecat api                       # every group: emulated / declared-only counts
    gtecat api --group ecat_axis     # one group's functions and prototypes
    gtecat api --group vendor_io --json
    gtecat api --json                # the census as JSON

Every function of the vendor's public headers is declared, so an application finds every
name it calls; an emulated one runs on the emulator, a declared-only one returns 8
(CMD_ERROR_UNKNOWN) with the reason in GTE_GetLastError.  gtecat scan checks an
application's sources against this census.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from ..errors import GtecatError


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "api",
        help="the GT API by group: emulated and declared-only functions",
        description=__doc__.split("\n\n", 1)[1] if __doc__ else None,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--group", metavar="G", help="list the functions of group G")
    p.add_argument("--json", action="store_true", help="machine-readable output")
    p.add_argument(
        "--write-docs",
        metavar="DIR",
        help="write the reference pages (one per group) into DIR (docs/reference/api)",
    )
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from ..gt import surface

    if args.write_docs:
        changed = surface.write_pages(Path(args.write_docs))
        print(f"{len(changed)} page(s) written" + (f": {', '.join(changed)}" if changed else ""))
        return 0
    groups = surface.counts()
    if args.group:
        names = [g.name for g in groups]
        if args.group not in names:
            raise GtecatError(f"no group {args.group!r}; the groups: {', '.join(names)}")
        es = [e for e in surface.entries() if e.group == args.group]
        if args.json:
            g = next(g for g in groups if g.name == args.group)
            print(json.dumps({
                "name": g.name, "title": g.title,
                "emulated": [e.name for e in es if e.emulated],
                "declared": [e.name for e in es if not e.emulated],
                "functions": [
                    {"name": e.name, "emulated": e.emulated, "prototype": e.prototype()}
                    for e in es
                ],
            }, indent=2))  # fmt: skip
            return 0
        for e in es:
            mark = "emulated" if e.emulated else "declared"
            print(f"{mark:<9} {e.prototype()};")
        return 0
    s = surface.summary()
    if args.json:
        out = {
            **s,
            "groups": [
                {"name": g.name, "title": g.title, "emulated": g.emulated,
                 "declared": g.declared, "vendor": g.vendor}
                for g in groups
            ],
        }  # fmt: skip
        print(json.dumps(out, indent=2))
        return 0
    width = max(len(g.name) for g in groups)
    print(f"{'group':<{width}}  emulated  declared  what")
    for g in groups:
        print(f"{g.name:<{width}}  {g.emulated:8d}  {g.declared:8d}  {g.title}")
    print(
        f"{'total':<{width}}  {s['emulated']:8d}  {s['declared']:8d}  {s['functions']} functions, "
        f"{s['constants']} constants, {s['structures']} structures"
    )
    return 0
