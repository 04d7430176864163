"""``gtecat graph FILE.eni``: the bus topology as a Graphviz DOT graph (``--png`` draws it).

Like IgH's ``ethercat graph``: the master, then every slave in bus order, each labelled with
its position, name, identity, axes and GT raw region. The graph is read from the ENI, so no
bus needs to run; ``dot`` (Graphviz) draws it: ``gtecat graph Gecat.eni | dot -Tpng > bus.png``.
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys

from gtecat.eni.graph import render as render_graph
from gtecat.eni.layout import build_layout
from gtecat.eni.reader import read_eni

from ..errors import ParameterError
from . import output
from .busview import add_controller, controller_address, eni_argument

EPILOG = """\
examples:
  gtecat graph manual_fig5_2.eni > bus.dot
  gtecat graph manual_fig5_2.eni --png bus.png      (needs Graphviz's dot)
  gtecat graph --controller unix:/tmp/ctl.sock       the bus of a running controller"""


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "graph",
        help="print the bus topology as a DOT graph (or draw it with --png)",
        description=output.describe(__doc__),
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("file", nargs="?", help="ENI file (default: $GTECAT_ENI or ./Gecat.eni)")
    p.add_argument("--eni", help="the same as FILE")
    p.add_argument("--png", metavar="FILE", help="draw the graph into FILE with Graphviz dot")
    add_controller(p)
    p.set_defaults(func=run)


def render(path: str) -> str:
    config = output.require_slaves(read_eni(path), path)
    return render_graph(config, build_layout(config))


def run(args: argparse.Namespace) -> int:
    address = controller_address(args)
    if address:
        from ..native.client import Field

        with Field.connect(address) as f:
            dot = f.graph()
    else:
        dot = render(eni_argument(args) or os.environ.get("GTECAT_ENI") or "Gecat.eni")
    if not args.png:
        sys.stdout.write(dot)
        return 0
    exe = shutil.which("dot")
    if exe is None:
        raise ParameterError(
            "--png needs Graphviz's dot (apt-get install graphviz); or print the DOT text "
            "without --png and draw it elsewhere"
        )
    done = subprocess.run([exe, "-Tpng", "-o", args.png], input=dot, text=True, capture_output=True)
    if done.returncode != 0:
        raise ParameterError(f"dot failed: {done.stderr.strip().splitlines()[-1:]}")
    print(f"wrote {args.png}")
    return 0
