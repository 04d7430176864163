"""gtecat benchmarks: prints one JSON object with every figure the issues ask for.

    python3 tools/bench.py            # all
    python3 tools/bench.py --quick    # fewer repetitions

Figures: ENI read of a 64-slave file; emulated bus cycles per wall second on the
manual's figure 5-2 topology (bus only: drives replaced by plain PDO slaves;
and with full CiA-402 drives) and on the 12-axis example; the cost of one
``GT_GetEcatRawData`` call; plus what each part's own bench module reports.
"""

from __future__ import annotations

import argparse
import importlib
import json
import sys
import time
from ctypes import c_ubyte
from dataclasses import replace
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
EXAMPLES = ROOT / "examples"


def _bus(eni: Path, *, plain: bool):
    from drives.io_slaves import IoSlave
    from eni.layout import build_layout
    from eni.reader import read_eni
    from gtecat.master.backends.emulated import EmulatedBackend
    from gtecat.master.bus import Master

    cfg = read_eni(eni)
    if plain:  # plain PDO slaves have no mailbox: drop the CoE InitCmds
        cfg = replace(cfg, slaves=tuple(replace(s, init_cmds=()) for s in cfg.slaves))
    layout = build_layout(cfg)
    slaves = None
    if plain:
        slaves = [
            IoSlave(s.position, s.name, s.identity, rx_pdos=s.rx_pdos, tx_pdos=s.tx_pdos)
            for s in layout.config.slaves
        ]
    master = Master(layout, EmulatedBackend(slaves=slaves), op_delay_cycles=0)
    master.open()
    master.cycle(0, 1_000_000)
    return master


def bench_cycles(eni: Path, *, plain: bool, seconds: float) -> float:
    """Bus cycles (master exchange + every slave's step) per wall second."""
    master = _bus(eni, plain=plain)
    n = 0
    t0 = time.perf_counter()
    t = 0
    while True:
        for _ in range(200):
            master.cycle(t, 1_000_000)
            t += 1_000_000
        n += 200
        el = time.perf_counter() - t0
        if el >= seconds:
            return n / el


def bench_raw_call(reps: int) -> float:
    """µs per GT_GetEcatRawData(0, 8) through the GT layer (lockstep clock)."""
    from gtecat import gt

    gt.GT_Close()
    gt.GT_Open(eni=str(EXAMPLES / "manual_fig5_2.eni"), clock="lockstep", log="")
    gt.GT_InitEcatComm()
    gt.GTE_Wait(20)
    buf = (c_ubyte * 8)()
    t0 = time.perf_counter()
    for _ in range(reps):
        gt.GT_GetEcatRawData(0, 8, buf)
    el = time.perf_counter() - t0
    gt.GT_Close()
    return el / reps * 1e6


def bench_controller_12_axes(seconds: float) -> float | None:
    """Controller + drives cycles per wall second with all 12 axes moving (issue 5)."""
    try:
        mod = importlib.import_module("tools.bench_motion_bus")
    except ModuleNotFoundError:
        return None
    return mod.cycles_per_second(seconds)


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args()
    secs = 0.5 if args.quick else 2.0
    out: dict[str, object] = {}
    try:
        from tools.bench_eni import bench_read

        out["eni_read_64_slaves"] = bench_read(64)
    except ModuleNotFoundError:
        pass
    fig = EXAMPLES / "manual_fig5_2.eni"
    twelve = EXAMPLES / "twelve_axes.eni"
    out["cycles_per_s_fig5_2_bus_only"] = round(bench_cycles(fig, plain=True, seconds=secs))
    out["cycles_per_s_fig5_2_drives"] = round(bench_cycles(fig, plain=False, seconds=secs))
    if twelve.exists():
        out["cycles_per_s_12_axes_bus_only"] = round(bench_cycles(twelve, plain=True, seconds=secs))
        out["cycles_per_s_12_axes_drives"] = round(bench_cycles(twelve, plain=False, seconds=secs))
    out["gt_get_ecat_raw_data_us"] = round(bench_raw_call(2000 if args.quick else 20000), 2)
    ctl12 = bench_controller_12_axes(secs)
    if ctl12 is not None:
        out["cycles_per_s_12_axes_controller_moving"] = round(ctl12)
    for name in ("bench_drive", "bench_homing", "bench_homing_gt", "bench_motion"):
        try:
            mod = importlib.import_module(f"tools.{name}")
        except ModuleNotFoundError:
            continue
        fn = getattr(mod, "summary", None)
        if fn is not None:
            out[name.removeprefix("bench_")] = fn(quick=args.quick)
    print(json.dumps(out, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
