"""``gtecat ifaces``: the network interfaces of this machine, for ``--backend pysoem --iface``.

One line per interface: name, link state, MAC address, speed, and whether this process may
open it for raw EtherCAT frames (root or CAP_NET_RAW). The interface cabled to the first
slave's IN port is the one to give as ``--iface`` / ``GTECAT_IFACE``.
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path

from . import output

NET = Path("/sys/class/net")


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "ifaces",
        help="list the network interfaces (for --backend pysoem --iface NIC)",
        description=output.describe(__doc__),
        epilog="examples:\n  gtecat ifaces\n  gtecat ifaces --json",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    output.add_json(p)
    p.set_defaults(func=run)


def _read(path: Path) -> str | None:
    try:
        return path.read_text().strip()
    except OSError:
        return None


def raw_socket_allowed() -> bool:
    """Root, or CAP_NET_RAW (bit 13) in the effective capabilities."""
    if os.geteuid() == 0:
        return True
    for line in (_read(Path("/proc/self/status")) or "").splitlines():
        if line.startswith("CapEff:"):
            return bool(int(line.split()[1], 16) >> 13 & 1)
    return False


def interfaces() -> list[dict[str, object]]:
    rows = []
    allowed = raw_socket_allowed()
    if NET.is_dir():
        for d in sorted(NET.iterdir()):
            speed = _read(d / "speed")
            rows.append(
                {
                    "name": d.name,
                    "state": _read(d / "operstate") or "unknown",
                    "mac": _read(d / "address") or "",
                    "speed_mbps": int(speed)
                    if speed and speed.lstrip("-").isdigit() and int(speed) > 0
                    else None,
                    "loopback": d.name == "lo",
                    "raw_frames": allowed,
                }
            )
        return rows
    try:  # not Linux: what pysoem itself finds
        import pysoem

        for a in pysoem.find_adapters():
            rows.append(
                {"name": a.name, "state": "unknown", "mac": "", "speed_mbps": None}
                | {"loopback": False, "raw_frames": allowed, "description": a.desc}
            )
    except Exception:
        pass
    return rows


def run(args: argparse.Namespace) -> int:
    rows = interfaces()
    if args.json:
        output.print_json(rows)
        return 0
    if not rows:
        print("no network interfaces found")
        return 0
    output.print_table(
        rows,
        [
            ("name", "iface"),
            ("state", "state"),
            ("mac", "mac"),
            ("speed_mbps", "Mbit/s"),
            ("raw_frames", "raw frames"),
        ],
    )
    if not rows[0]["raw_frames"]:
        print("\nraw frames need root or CAP_NET_RAW: sudo setcap cap_net_raw,cap_net_admin+ep "
              "$(readlink -f $(which python3))")  # fmt: skip
    return 0
