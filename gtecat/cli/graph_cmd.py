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
from pathlib import Path

from eni.layout import build_layout
from eni.reader import read_eni

from ..errors import ParameterError
from . import output
from .busview import eni_argument

EPILOG = """\
examples:
  gtecat graph manual_fig5_2.eni > bus.dot
  gtecat graph manual_fig5_2.eni --png bus.png      (needs Graphviz's dot)"""


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
    p.set_defaults(func=run)


def _q(text: str) -> str:
    return text.replace("\\", "\\\\").replace('"', '\\"')


def render(path: str) -> str:
    config = read_eni(path)
    layout = build_layout(config)
    lines = [
        "digraph bus {",
        "    rankdir=LR;",
        '    node [shape=box, fontname="Helvetica", fontsize=10];',
        f'    master [label="master\\n{_q(Path(path).name)}", shape=ellipse];',
    ]
    previous = "master"
    for s, cfg in zip(layout.slaves, config.slaves, strict=True):
        i = cfg.identity
        axes = ", ".join(str(a) for a in s.axes)
        what = (f"axis {axes}" if len(s.axes) == 1 else f"axes {axes}") if s.axes else "IO"
        label = (
            f"{s.position}: {_q(s.name)}\\n"
            f"vendor 0x{i.vendor_id:08X} product 0x{i.product_code:08X}\\n"
            f"{what}; GT raw {s.gt_offset}+{s.gt_size}"
        )
        style = ", style=rounded" if s.axes else ""
        lines.append(f'    slave{s.position} [label="{label}"{style}];')
        port = "OUT" if previous == "master" else ""
        lines.append(f'    {previous} -> slave{s.position} [label="{port}"];')
        previous = f"slave{s.position}"
    lines.append("}")
    return "\n".join(lines) + "\n"


def run(args: argparse.Namespace) -> int:
    path = eni_argument(args) or os.environ.get("GTECAT_ENI") or "Gecat.eni"
    dot = render(path)
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
