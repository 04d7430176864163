"""``gtecat cstruct FILE.eni``: a C header of the GT raw image, for C/C++ and ST programs.

Like IgH's ``ethercat cstruct``, but for the offsets the GT calls take: for every slave its
region in the GT raw image (GT_GetEcatRawData / GT_SetEcatRawData, manual 5.2.2.4) and, for
every PDO entry, a macro with its byte offset in that image (``_BIT`` for entries that are
not whole bytes), a ``_REGION`` macro with the offset inside the slave's region (the offset
GT_EcatIOReadInput / GT_EcatIOWriteOutput take), and one packed struct per slave whose members
sit at those offsets. The header checks its own offsets with static asserts, so a compiler
refuses it if a struct and a macro ever disagree. C11 or C++11.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

from gtecat.eni.cstruct import render
from gtecat.eni.layout import build_layout
from gtecat.eni.reader import read_eni

from ..errors import ParameterError
from . import output
from .busview import add_controller, controller_address, eni_argument

EPILOG = """\
examples:
  gtecat cstruct manual_fig5_2.eni -o gt_raw.h
  gtecat cstruct --eni Gecat.eni --prefix X_ > x_raw.h
  gtecat cstruct --controller unix:/tmp/ctl.sock      the ENI a running controller read"""


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "cstruct",
        help="write a C header of the GT raw offsets and PDO entries of an ENI",
        description=output.describe(__doc__),
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("file", nargs="?", help="ENI file (default: $GTECAT_ENI or ./Gecat.eni)")
    p.add_argument("--eni", help="the same as FILE")
    p.add_argument("-o", "--output", help="header to write (default: standard output)")
    p.add_argument("--prefix", default="", help="prefix for every macro and type name")
    p.add_argument("-p", "--position", type=int, help="one slave only")
    add_controller(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    address = controller_address(args)
    if address:
        from ..native.client import Field

        with Field.connect(address) as f:
            text = f.cstruct(args.prefix, args.position)
            slaves = len(f.positions())
        return _write(args, text, slaves)
    args.file = eni_argument(args) or os.environ.get("GTECAT_ENI") or "Gecat.eni"
    layout = build_layout(output.require_slaves(read_eni(args.file), args.file))
    if args.position is not None and not 0 <= args.position < len(layout.slaves):
        raise ParameterError(
            f"no slave {args.position}: {args.file} has slaves 0..{len(layout.slaves) - 1}"
        )
    text = render(layout, args.file, prefix=args.prefix, only=args.position)
    return _write(args, text, len(layout.slaves))


def _write(args: argparse.Namespace, text: str, slaves: int) -> int:
    if not args.output or args.output == "-":
        sys.stdout.write(text)
        return 0
    Path(args.output).write_text(text, encoding="utf-8")
    raw = next((line.split()[-1] for line in text.splitlines() if "GT_RAW_BYTES " in line), "?")
    print(f"wrote {args.output}: {slaves} slaves, GT raw image {raw} bytes")
    return 0
