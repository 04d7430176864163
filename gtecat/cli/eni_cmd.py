"""``gtecat eni new TOPOLOGY.toml -o OUT.eni``: write an ETG.2100 ENI from a short topology.

The topology format is documented in :mod:`gtecat.eni.topology` (servo drives with a
chosen PDO mapping, multi-axis modules, DI/DO terminals, couplers with
DI/DO/AI/AO modules).  The file written reads back to the same model
(:mod:`gtecat.eni.writer`); ``gtecat map`` shows its offsets.
"""

from __future__ import annotations

import argparse
import sys
from typing import Any

from gtecat.eni.errors import GtecatError
from gtecat.eni.layout import build_layout
from gtecat.eni.topology import load_topology
from gtecat.eni.writer import write_eni_file, write_eni_to


def add_parser(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "eni",
        help="ENI tools (write an ENI from a topology)",
        epilog="examples:\n  gtecat eni new manual_fig5_2.toml -o manual_fig5_2.eni",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    sub = p.add_subparsers(dest="eni_command", metavar="COMMAND")
    new = sub.add_parser(
        "new",
        help="write an ETG.2100 ENI from a TOML topology",
        description="Write an ETG.2100 ENI XML file from a TOML topology "
        "(format: docs/reference/topology.md; `gtecat example manual_fig5_2` writes one).",
        epilog="examples:\n  gtecat eni new manual_fig5_2.toml -o manual_fig5_2.eni\n"
        "  gtecat eni new my_bus.toml | gtecat map /dev/stdin",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    new.add_argument("topology", help="topology TOML file")
    new.add_argument("-o", "--output", help="ENI file to write (default: standard output)")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    if getattr(args, "eni_command", None) != "new":
        print("error: usage: gtecat eni new TOPOLOGY.toml [-o OUT.eni]", file=sys.stderr)
        return 1
    from .busview import check_toml_kind

    check_toml_kind(args.topology, "topology")
    try:
        cfg = load_topology(args.topology)
        layout = build_layout(cfg)
    except GtecatError as exc:
        if getattr(args, "debug", False):
            raise
        print("error: " + " ".join(str(exc).split()), file=sys.stderr)
        return 1
    if not args.output or args.output == "-":
        write_eni_to(cfg, sys.stdout)  # (as it is made: 65 535 drives are 1.3 GB of XML)
        return 0
    try:
        write_eni_file(cfg, args.output)
    except OSError as exc:
        print(f"error: cannot write {args.output}: {exc.strerror or exc}", file=sys.stderr)
        return 1
    print(
        f"wrote {args.output}: {_count(len(cfg.slaves), 'slave')}, "
        f"{_count(len(layout.axes), 'axis', 'axes')}, "
        f"GT raw image {layout.gt_raw_bytes} bytes"
    )
    return 0


def _count(n: int, one: str, many: str | None = None) -> str:
    return f"{n} {one if n == 1 else (many or one + 's')}"
