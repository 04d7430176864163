"""Benchmark of the virtual CiA-402 drive: drive steps per wall second, one SDO round trip.

Each simulated cycle does what the emulated backend does for a drive: write
the master's outputs into ``rx`` (controlword + a moving CSP target), step the
drive, read ``tx``.  Drives carry the Figure 5-2 PDOs of the manual
(6040h/607Ah out, 6041h/6064h/60FDh in), one axis each, all enabled in CSP.

    python tools/bench_drive.py            # JSON for 2 and 12 axes
    python tools/bench_drive.py 2 12 24    # chosen axis counts

``realtime_factor_1khz`` is cycles per wall second / 1000: the issue asks for
>= 10 with 2 drives (Figure 5-2) and >= 3 with 12 axes.
"""

from __future__ import annotations

import json
import struct
import sys
import time
from typing import Any

from gtecat.drives.coe import SdoClient
from gtecat.drives.drive import Cia402Drive
from gtecat.drives.slave import AlState
from gtecat.eni.model import Direction, Identity, Pdo, PdoEntry

CYCLE_NS = 1_000_000
RX_PDO = Pdo(0x1600, Direction.OUT, (PdoEntry(0x6040, 0, 16), PdoEntry(0x607A, 0, 32)))
TX_PDO = Pdo(
    0x1A00,
    Direction.IN,
    (PdoEntry(0x6041, 0, 16), PdoEntry(0x6064, 0, 32), PdoEntry(0x60FD, 0, 32)),
)
_OUT = struct.Struct("<Hi")


def make_drives(n: int) -> list[Cia402Drive]:
    """``n`` single-axis drives in OP with the Figure 5-2 mapping, mode CSP (6060h by SDO)."""
    drives = []
    for k in range(n):
        d = Cia402Drive(
            k, f"drive{k}", Identity(0x0000_0B95, 0x1), rx_pdos=[RX_PDO], tx_pdos=[TX_PDO]
        )
        for state in (AlState.PREOP, AlState.SAFEOP, AlState.OP):
            d.request_state(state)
        SdoClient(d.mailbox).download(0x6060, 0, bytes([8]))
        drives.append(d)
    return drives


def _cycle(drives: list[Cia402Drive], t: int, cw: int, target: int) -> None:
    for d in drives:
        _OUT.pack_into(d.rx, 0, cw, target)
        d.step(t, CYCLE_NS)
        bytes(d.tx)


def bench(n_channels: int, cycles: int = 2000) -> dict[str, Any]:
    """Drive steps of ``n_channels`` axes per wall second, and one SDO upload round trip."""
    drives = make_drives(n_channels)
    t = 0
    for cw in (0x06, 0x07, 0x0F, 0x0F):  # walk to OPERATION ENABLED at target 0
        _cycle(drives, t, cw, 0)
        t += CYCLE_NS
    enabled = all(d.channel(0).statusword & 0x6F == 0x27 for d in drives)
    target = 0.0
    start = time.perf_counter()
    for i in range(cycles):
        target += 50.0 if i < cycles // 2 else -50.0  # 50 counts per ms: 0.5 rev/s
        _cycle(drives, t, 0x0F, int(target))
        t += CYCLE_NS
    wall = time.perf_counter() - start
    client = SdoClient(drives[0].mailbox)
    n_sdo = 200
    s0 = time.perf_counter()
    for _ in range(n_sdo):
        client.upload(0x6041, 0)
    sdo_us = (time.perf_counter() - s0) / n_sdo * 1e6
    cps = cycles / wall
    return {
        "axes": n_channels,
        "cycles": cycles,
        "enabled": enabled,
        "faulted": sum(1 for d in drives if d.channel(0).error_code),
        "cycles_per_wall_s": round(cps, 1),
        "realtime_factor_1khz": round(cps / 1000.0, 2),
        "us_per_axis_cycle": round(wall / cycles / n_channels * 1e6, 2),
        "sdo_upload_round_trip_us": round(sdo_us, 1),
    }


def summary(quick: bool = False) -> dict[str, Any]:
    """What tools/bench.py prints: both topologies against the issue's targets."""
    cycles = 500 if quick else 3000
    fig, twelve = bench(2, cycles), bench(12, cycles)
    return {
        "fig5_2_two_drives": {**fig, "target_factor": 10, "ok": fig["realtime_factor_1khz"] >= 10},
        "twelve_axes": {**twelve, "target_factor": 3, "ok": twelve["realtime_factor_1khz"] >= 3},
    }


def main(argv: list[str]) -> int:
    counts = [int(a) for a in argv] or [2, 12]
    print(json.dumps([bench(n) for n in counts], indent=2))
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
