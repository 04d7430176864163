"""``gtecat scan PATH...``: will this application run on gtecat?

Examples:

    gtecat example motion_demo_cpp -o demo && gtecat scan demo/   # a project folder
    gtecat scan demo/motion_demo.cpp                  # files (C, C++, C#, VB.NET)
    gtecat scan --json demo/ > use.json

Lists every GT_/GTN_ function the sources call and every vendor constant they name, and
says for each whether gtecat emulates it, declares it only (it returns 8,
CMD_ERROR_UNKNOWN) or lacks it.  The vendor's own header or wrapper in the project is read
as declarations, not uses.  Exit status 0 only when everything used is emulated (and every
constant defined), 1 otherwise.
"""

from __future__ import annotations

import argparse
import json


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "scan",
        help="which GT functions an application's sources use, and whether they are emulated",
        description=__doc__.split("\n\n", 1)[1] if __doc__ else None,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("paths", nargs="+", metavar="PATH", help="source files or folders")
    p.add_argument("--json", action="store_true", help="machine-readable output")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from ..errors import GtecatError
    from ..gt.scan import files, scan

    try:
        n = len(files(args.paths))
        uses = scan(args.paths)
    except FileNotFoundError as e:
        raise GtecatError(str(e)) from None
    bad = [u for u in uses if not u.ok()]
    if args.json:
        print(json.dumps({
            "files": n,
            "ok": not bad,
            "uses": [
                {"name": u.name, "kind": u.kind, "status": u.status, "count": u.count,
                 "where": u.where}
                for u in uses
            ],
        }, indent=2))  # fmt: skip
        return 1 if bad else 0
    width = max((len(u.name) for u in uses), default=4)
    for u in uses:
        print(f"{u.name:<{width}}  {u.kind:<8}  {u.status:<13}  {u.count:4d}  {u.where[0]}")
    fns = [u for u in uses if u.kind == "function"]
    emu = sum(u.status == "emulated" for u in fns)
    decl = sum(u.status == "declared only" for u in fns)
    miss = sum(u.status == "missing" for u in fns)
    consts = [u for u in uses if u.kind == "constant"]
    cmiss = sum(u.status == "missing" for u in consts)
    print(
        f"{n} files: {len(fns)} functions ({emu} emulated, {decl} declared only, {miss} "
        f"missing), {len(consts)} constants ({cmiss} missing)"
    )
    return 1 if bad else 0
