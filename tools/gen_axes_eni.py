"""Write an N-axis bus as ETG.2100 ENI: N single-axis CiA-402 CSP drives, nothing else.

    python tools/gen_axes_eni.py 64 -o axes64.eni [--no-modes]

Each slave maps, like the drives of ``examples/twelve_axes.eni`` without the
probe and velocity objects: outputs 6040h (u16), 607Ah (i32), 6060h (i8);
inputs 6041h (u16), 6064h (i32), 60FDh (u32), 6061h (i8).  ``--no-modes``
leaves 6060h/6061h out (the controller then reaches them by SDO).  The file is
built by :mod:`gtecat.eni.topology` and written by :mod:`gtecat.eni.writer`, the same path as
``gtecat eni new``, slave by slave as it is made: any count from 1 to 65 535 (the most an
EtherCAT bus holds) is written in memory that grows with the model only (about 6 kB a
drive; 65 535 drives: 1.3 GB of XML).  The cyclic process data goes in one ``Frame`` up to
81 drives (7 output + 11 input bytes each, 1,498 bytes of EtherCAT in an Ethernet frame),
in several beyond (:mod:`gtecat.eni.cyclic`: 300 drives take four).  The benchmarks import
:func:`write_axes_eni`.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from gtecat.eni.model import EniConfig  # noqa: E402
from gtecat.eni.topology import MAX_SLAVES, build_config  # noqa: E402
from gtecat.eni.writer import write_eni_file  # noqa: E402

MAX_AXES = MAX_SLAVES  # one drive a slave, as many as a bus holds (16-bit station addresses)
RX = ("0x6040:0:16", "0x607A:0:32", "0x6060:0:8")
TX = ("0x6041:0:16", "0x6064:0:32", "0x60FD:0:32", "0x6061:0:8")
#: GT raw bytes of one slave: outputs 2 + 4 (+ 1), inputs 2 + 4 + 4 (+ 1)
SLAVE_BYTES = {True: 7 + 11, False: 6 + 10}


def axes_topology(n: int, *, modes: bool = True) -> dict[str, Any]:
    """The topology mapping (as ``gtecat eni new`` reads it from TOML) of ``n`` drives."""
    if not 1 <= n <= MAX_AXES:
        raise ValueError(
            f"axes must be 1..{MAX_AXES} (one drive a slave, and an EtherCAT bus holds at most "
            f"{MAX_AXES} slaves), not {n}"
        )
    rx = list(RX if modes else RX[:2])
    tx = list(TX if modes else TX[:3])
    return {
        "cycle_time_us": 1000,
        "master": f"gtecat {n} axes",
        "slave": [
            {"kind": "servo", "name": f"Drive {k + 1}", "rx": rx, "tx": tx} for k in range(n)
        ],
    }


def axes_config(n: int, *, modes: bool = True) -> EniConfig:
    """The :class:`EniConfig` of ``n`` single-axis drives."""
    return build_config(axes_topology(n, modes=modes), f"<{n} axes>")


def write_axes_eni(n: int, path: str | Path, *, modes: bool = True) -> Path:
    """Write the ``n``-drive ENI to ``path`` and return the path."""
    p = Path(path)
    write_eni_file(axes_config(n, modes=modes), p)
    return p


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument(
        "axes", type=int, help=f"number of drives, 1..{MAX_AXES} (the most slaves a bus holds)"
    )
    ap.add_argument("-o", "--output", required=True, help="ENI file to write")
    ap.add_argument("--no-modes", action="store_true", help="leave 6060h/6061h unmapped")
    args = ap.parse_args(argv)
    try:
        p = write_axes_eni(args.axes, args.output, modes=not args.no_modes)
    except ValueError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 1
    except OSError as exc:
        print(f"error: cannot write {args.output}: {exc.strerror or exc}", file=sys.stderr)
        return 1
    print(f"{p}: {args.axes} axes")
    return 0


if __name__ == "__main__":
    sys.exit(main())
