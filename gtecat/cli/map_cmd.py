"""``gtecat map FILE.eni``: the IO-mapping table a user needs to compute raw-data offsets.

One row per mapped entry: slave, direction, PDO, index:sub, name, type,
bits, logical offset (byte.bit in its direction's ENI image) and GT raw
offset (byte.bit as GT_GetEcatRawData/GT_SetEcatRawData address it,
manual 5.2.2.4).  --json prints the same as JSON (docs/reference/cli.md).
"""

from __future__ import annotations

import argparse
import json
import sys
from typing import Any

from gtecat.eni.errors import GtecatError
from gtecat.eni.layout import Layout, Placement, SlaveLayout, build_layout
from gtecat.eni.model import Direction
from gtecat.eni.reader import read_eni

from . import output

_FORMATS = {"xml": "ETG.2100 ENI XML", "googol": "Googol INI Gecat.eni"}


def add_parser(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "map",
        help="print the process-image map (logical and GT raw offsets) of an ENI",
        description=__doc__.split("\n\n")[1] if __doc__ else None,
        epilog="examples:\n  gtecat map manual_fig5_2.eni\n  gtecat map --eni Gecat.eni --json",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("file", nargs="?", help="ENI file (ETG.2100 XML or Googol INI Gecat.eni)")
    p.add_argument("--eni", help="the same as FILE (default: $GTECAT_ENI or ./Gecat.eni)")
    p.add_argument("--json", action="store_true", help="print JSON instead of the table")
    p.set_defaults(func=run)


def _bb(bit: int) -> str:
    return f"{bit >> 3}.{bit & 7}"


def _axes(s: SlaveLayout) -> str:
    if not s.axes:
        return "no axis"
    if len(s.axes) == 1:
        return f"axis {s.axes[0]}"
    return f"axes {s.axes[0]}-{s.axes[-1]}"


def _row(p: Placement) -> list[str]:
    pad = p.is_padding
    return [
        "out" if p.direction == Direction.OUT else "in",
        f"0x{p.pdo:04X}",
        "-" if pad else f"0x{p.index:04X}:{p.subindex:02X}",
        "(padding)" if pad else (p.name or "-"),
        p.data_type or "-",
        str(p.bits),
        _bb(p.logical_bit),
        _bb(p.gt_bit),
    ]


_HEAD = ["dir", "pdo", "index:sub", "name", "type", "bits", "logical", "GT raw"]
_RIGHT = {5, 6, 7}


def render_table(layout: Layout, label: str) -> str:
    """The human table (``gtecat map`` without ``--json``)."""
    cfg = layout.config
    lines = []
    cycle = f"cycle {cfg.cycle_time_ns / 1000:g} us" if cfg.cycle_time_ns else "no cycle time"
    lines.append(
        f"{label}: {_FORMATS.get(cfg.format, cfg.format)}, {len(layout.slaves)} slave"
        f"{'s' if len(layout.slaves) != 1 else ''}, {len(layout.axes)} "
        f"ax{'es' if len(layout.axes) != 1 else 'is'}, {cycle}"
    )
    lines.append(
        f"GT raw image {layout.gt_raw_bytes} bytes; logical images: outputs "
        f"{layout.outputs_bytes} bytes, inputs {layout.inputs_bytes} bytes"
    )
    lines.append("offsets are byte.bit; GT raw offsets count from slave 0 (manual 5.2.2.4)")
    rows = [_row(p) for s in layout.slaves for p in s.entries]
    widths = [max([len(h)] + [len(r[i]) for r in rows]) for i, h in enumerate(_HEAD)]

    def fmt(cells: list[str]) -> str:
        return "  ".join(
            c.rjust(w) if i in _RIGHT else c.ljust(w)
            for i, (c, w) in enumerate(zip(cells, widths, strict=True))
        ).rstrip()

    for s in layout.slaves:
        lines.append("")
        if not s.entries:
            lines.append(
                f"slave {s.position}  {s.name}  {_axes(s)}  no process data "
                f"(empty GT raw region at {s.gt_offset})"
            )
            continue
        lines.append(
            f"slave {s.position}  {s.name}  {_axes(s)}  GT raw bytes {s.gt_offset}.."
            f"{s.gt_offset + s.gt_size - 1} ({s.out_bytes} out + {s.in_bytes} in)"
        )
        lines.append("  " + fmt(_HEAD))
        for p in s.entries:
            lines.append("  " + fmt(_row(p)))
    return "\n".join(lines) + "\n"


def _utf_stdout() -> bool:
    return (getattr(sys.stdout, "encoding", "") or "").lower().replace("-", "").startswith("utf")


def render_json(layout: Layout, *, ascii_only: bool = False) -> str:
    """The DESIGN.md document; ``ascii_only`` escapes names (``\\uXXXX``) for non-UTF consoles."""
    return json.dumps(layout.to_json(), indent=2, ensure_ascii=ascii_only) + "\n"


def run(args: argparse.Namespace) -> int:
    import os

    from .busview import eni_argument

    args.file = eni_argument(args) or os.environ.get("GTECAT_ENI") or "Gecat.eni"
    try:
        layout = build_layout(output.require_slaves(read_eni(args.file), args.file))
    except GtecatError as exc:
        if getattr(args, "debug", False):
            raise
        print("error: " + " ".join(str(exc).split()), file=sys.stderr)
        return 1
    if args.json:
        out = render_json(layout, ascii_only=not _utf_stdout())
    else:
        out = render_table(layout, args.file)
    sys.stdout.write(out)
    return 0
