"""The axis bank against the scalar path, side by side: where the bank starts to win.

    python tools/bench_bank.py [--axes 1,2,4,8,12,32] [--states idle,moving] [--seconds 1]

For every (axes, state) the same generated bus runs once with ``GTECAT_BANK=off`` (the
scalar objects) and once with ``on`` (every eligible axis in the bank), alternately, best of
``--repeat`` windows each; prints JSON with both real-time factors and their ratio.  The
crossover it shows is :data:`gtecat.controller.bank.AUTO_MIN_AXES` (``bank="auto"``).
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from tools.bench_scaling import run_bus  # noqa: E402


def compare(n: int, state: str, seconds: float, repeat: int) -> dict:
    out: dict = {"axes": n, "state": state}
    plan = dict.fromkeys(range(1, n + 1), state)
    old = os.environ.get("GTECAT_BANK")
    try:
        for mode in ("off", "on"):
            os.environ["GTECAT_BANK"] = mode
            r = run_bus(n, plan, seconds=seconds, repeat=repeat)
            out[mode] = r.get("rtf", r.get("error"))
    finally:
        if old is None:
            os.environ.pop("GTECAT_BANK", None)
        else:
            os.environ["GTECAT_BANK"] = old
    if isinstance(out["on"], float) and isinstance(out["off"], float):
        out["speedup"] = round(out["on"] / out["off"], 2)
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--axes", default="1,2,4,8,12,32")
    ap.add_argument("--states", default="idle,moving")
    ap.add_argument("--seconds", type=float, default=1.0)
    ap.add_argument("--repeat", type=int, default=2)
    a = ap.parse_args(argv)
    rows = [
        compare(int(n), s, a.seconds, a.repeat)
        for n in a.axes.split(",")
        for s in a.states.split(",")
    ]
    print(json.dumps(rows, indent=2))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
