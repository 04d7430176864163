"""One formatting layer for every verb: a table for people, ``--json`` for scripts.

A verb builds a list of rows (dicts of plain values), then hands them to
:func:`emit`, which prints JSON when ``--json`` was given and an aligned table
otherwise.  Numbers that are addresses or raw words print in hex in the table
(``0x6041:00``, ``0x1237``) and stay integers in JSON.
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Callable, Sequence
from typing import Any

Column = tuple[str, str] | tuple[str, str, Callable[[Any], str]]


def add_json(p: argparse.ArgumentParser) -> None:
    p.add_argument("--json", action="store_true", help="print JSON instead of a table")


def add_position(p: argparse.ArgumentParser, *, required: bool = False) -> None:
    """``-p POSITION`` as in IgH's ``ethercat`` tool: one slave, by its 0-based bus position."""
    p.add_argument(
        "-p",
        "--position",
        type=int,
        required=required,
        metavar="POSITION",
        help="slave position on the bus (0-based)" + ("" if required else "; default: all"),
    )


def _ascii_only() -> bool:
    enc = (getattr(sys.stdout, "encoding", "") or "").lower().replace("-", "")
    return not enc.startswith("utf")


def print_json(obj: Any) -> None:
    print(json.dumps(obj, indent=2, ensure_ascii=_ascii_only()))


def hex_addr(index: int, subindex: int) -> str:
    """An object address as printed everywhere: ``0x6040:00``."""
    return f"0x{index:04X}:{subindex:02X}"


def hex_word(value: int, bits: int) -> str:
    """``value`` as ``0x..`` with as many digits as ``bits`` hold."""
    digits = max(2, (bits + 3) // 4)
    return f"0x{value & ((1 << bits) - 1) if bits else value:0{digits}X}"


def text(value: Any) -> str:
    if value is None:
        return "-"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, (list, tuple)):
        return ",".join(text(v) for v in value) or "-"
    return str(value)


def table(rows: Sequence[dict[str, Any]], columns: Sequence[Column]) -> str:
    """Rows as aligned columns: ``(key, heading[, format])``; numbers align right."""
    heads = [c[1] for c in columns]
    cells = []
    for r in rows:
        line = []
        for c in columns:
            v = r.get(c[0])
            line.append(c[2](v) if len(c) > 2 and v is not None else text(v))  # type: ignore[misc]
        cells.append(line)
    widths = [max([len(h)] + [len(line[i]) for line in cells]) for i, h in enumerate(heads)]
    right = [
        bool(rows) and all(isinstance(r.get(c[0]), int) and len(c) == 2 for r in rows)
        for c in columns
    ]

    def fmt(line: list[str]) -> str:
        return "  ".join(
            s.rjust(w) if right[i] else s.ljust(w)
            for i, (s, w) in enumerate(zip(line, widths, strict=True))
        ).rstrip()

    return "\n".join([fmt(heads), *(fmt(line) for line in cells)])


def print_table(rows: Sequence[dict[str, Any]], columns: Sequence[Column]) -> None:
    print(table(rows, columns))


def emit(args: argparse.Namespace, rows: Any, columns: Sequence[Column]) -> int:
    """``--json``: the rows as JSON; otherwise the table. Returns 0 (a verb's exit code)."""
    if getattr(args, "json", False):
        print_json(rows)
    else:
        print_table(rows, columns)
    return 0


def require_slaves(config: Any, path: Any) -> Any:
    """Refuse an ENI without slaves (a bus with nothing on it has no offsets, no axes and
    nothing to show; GT_InitEcatComm answers it with -10)."""
    if not config.slaves:
        from gtecat.eni.errors import EniError

        raise EniError(
            "the configuration describes no slaves, so there is no bus to show; export it "
            "again from your configuration tool with the slaves scanned in",
            file=str(path),
        )
    return config


def describe(doc: str | None) -> str | None:
    """A module docstring as ``--help`` text: without its title line and reST markup."""
    if not doc:
        return None
    parts = doc.split("\n\n", 1)
    body = parts[1] if len(parts) > 1 else parts[0]
    return body.replace("``", "").strip()
