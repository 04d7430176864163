"""``gtecat fault``: break a running machine on purpose (inject, list, clear), or list the kinds.

``inject KIND key=value ...`` arms a fault on a running gtecat (``--attach ID``, else the
only one ``gtecat ps`` lists: an application, a controller, or a ``gtecat serve``, whose
master on the wire then sees it; taken without ``--attach``, the one it acts on is named on
stderr, pid, program and start time, and with several running it acts on none and lists
them): the same kinds and keys as a machine description's
``[[fault]]`` tables, a trigger among them (``at_ms=``, ``after_ms=``, ``after_cycles=``,
``when_position=AXIS,POS``, ``at_homing=AXIS,STAGE``, ``on_sdo=SLAVE,INDEX,N``; none: at
once), ``duration_ms=`` for how long it lasts; each key once, with a value.  ``list``
shows what is armed or active, ``clear [ID]`` ends one fault or all, ``kinds`` lists every
kind with its values.
"""

from __future__ import annotations

import argparse
import sys
from typing import Any

from ..errors import BusError, ParameterError
from . import output

EPILOG = """\
examples:
  gtecat fault kinds                                   every kind and its values
  gtecat fault inject drive_fault axis=1 code=0x2310   on the only running gtecat
  gtecat fault inject link_down after_slave=1 at_ms=5000 duration_ms=200 --attach 4242
  gtecat fault inject mailbox_abort slave=0 index=0x6060 code=0x06090030
  gtecat fault inject drop_responses count=3 --attach 5120   on a gtecat serve: 3 answers lost
  gtecat fault list
  gtecat fault clear 3"""


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "fault",
        help="inject, list and clear faults on a running gtecat; list the fault kinds",
        description=output.describe(__doc__),
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    verbs = p.add_subparsers(dest="fault_verb", metavar="VERB", required=True)

    def verb(name: str, helptext: str, example: str) -> argparse.ArgumentParser:
        v = verbs.add_parser(
            name,
            help=helptext,
            description=helptext,
            epilog=f"examples:\n  {example}",
            formatter_class=argparse.RawDescriptionHelpFormatter,
        )
        v.set_defaults(func=run)
        return v

    v = verb(
        "inject",
        "arm a fault on a running gtecat",
        "gtecat fault inject switch_stuck axis=2 switch=positive value=1 after_cycles=100",
    )
    v.add_argument("kind", help="the fault kind (gtecat fault kinds lists them)")
    v.add_argument("values", nargs="*", metavar="KEY=VALUE", help="its values and trigger")
    _attach(v)
    output.add_json(v)
    v = verb("list", "the faults armed or active on a running gtecat", "gtecat fault list --json")
    _attach(v)
    output.add_json(v)
    v = verb("clear", "end one fault (by id) or every fault", "gtecat fault clear")
    v.add_argument("id", nargs="?", type=int, help="the fault's id (default: all)")
    _attach(v)
    v = verb("kinds", "every fault kind, its values and what it does", "gtecat fault kinds --json")
    output.add_json(v)


def _attach(p: argparse.ArgumentParser) -> None:
    p.add_argument("--attach", metavar="ID", help="the running gtecat (gtecat ps lists them)")


def _pairs(values: list[str]) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for text in values:
        key, sep, value = text.partition("=")
        if not sep or not key:
            raise ParameterError(f"{text!r}: expected KEY=VALUE (e.g. axis=1)")
        if key in out:
            raise ParameterError(
                f"{key}= is given twice ({key}={_shown(out[key])} and {text}): give it once"
            )
        if not value.strip():
            raise ParameterError(f"{text!r}: {key} has no value (e.g. {key}=1)")
        if "," in value:
            out[key] = [v.strip() for v in value.split(",")]
        else:
            out[key] = value
    return out


def _shown(value: Any) -> str:
    return ",".join(value) if isinstance(value, list) else str(value)


def _connect(args: argparse.Namespace) -> Any:
    from ..inspect import client

    found = client.connect(args.attach)
    if found is None:
        raise BusError(
            "no running gtecat to act on (gtecat ps lists them; an application publishes one "
            "when it calls GT_Open, a gtecat serve once it answers frames)"
        )
    if not args.attach:  # the only one running: say which (another user's, on a shared id?)
        print(f"attached to {found[0].who()}", file=sys.stderr)
    return found[1]


def run(args: argparse.Namespace) -> int:
    from .. import faults

    verb = args.fault_verb
    if verb == "kinds":
        rows = faults.kind_rows()
        if args.json:
            output.print_json(rows)
        else:
            output.print_table(
                rows, [("kind", "kind"), ("depth", "depth"), ("values", "values"), ("what", "what")]
            )
        return 0
    if verb == "inject":
        values = {"kind": args.kind, **_pairs(args.values)}
        spec = faults.spec_from_dict(values)  # refused here, before anything is sent
        with _connect(args) as conn:
            got = conn.call("fault_inject", values)
        if args.json:
            output.print_json(got)
        else:
            print(f"fault {got['id']}: {got.get('describe') or spec.describe()} ({got['state']})")
        return 0
    if verb == "list":
        with _connect(args) as conn:
            got = conn.call("fault_list")
        if args.json:
            output.print_json(got)
        elif not got:
            print("no fault armed or active")
        else:
            output.print_table(got, [("id", "id"), ("state", "state"), ("describe", "fault")])
        return 0
    with _connect(args) as conn:
        n = conn.call("fault_clear", args.id)
    print(f"{n} fault{'s' if n != 1 else ''} cleared")
    return 0
