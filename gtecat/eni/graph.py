"""The bus topology of a configuration as a Graphviz DOT graph (``gtecat graph``).

The master, then every slave in bus order, each labelled with its position, name,
identity, axes and GT raw region. A writer of the configuration, like :mod:`gtecat.eni.writer`:
a verb and a controller process render the same text.
"""

from __future__ import annotations

from pathlib import Path

from .layout import Layout
from .model import EniConfig


def _q(text: str) -> str:
    return text.replace("\\", "\\\\").replace('"', '\\"')


def render(config: EniConfig, layout: Layout) -> str:
    """DOT text of ``config`` (laid out as ``layout``); the master node names its file."""
    lines = [
        "digraph bus {",
        "    rankdir=LR;",
        '    node [shape=box, fontname="Helvetica", fontsize=10];',
        f'    master [label="master\\n{_q(Path(config.source).name)}", shape=ellipse];',
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
