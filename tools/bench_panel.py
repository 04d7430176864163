"""What watching costs: the real-time factor of 12 axes moving in Trap with and without
``gtecat panel`` attached, and the page's update rate (the panel issue's bars: at most 5 %
of the cycle time; at least 20 updates per second).

    python3 tools/bench_panel.py [--seconds 3] [--repeat 3]

The real-time factor here is controller time per CPU second of the application's own
process (its endpoint thread included), so other load on the machine does not blur it.
The application is tools.bench_scaling's (lockstep clock, public GT API, 12 single-axis
CSP drives, every axis in a long Trap move) with its inspection endpoint published in a
private runtime folder.  Windows without a panel (nothing attached) and with one
alternate, each figure the best of its windows, so a busy machine penalises both alike.
The panel is the real one (``gtecat panel --attach ID``, its own process, polling the
endpoint), with two websocket clients (processes of their own) standing in for two
browsers: they count the snapshots they receive.
"""

from __future__ import annotations

import argparse
import asyncio
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from tools import bench_scaling as bs


def _browsers(url: str, seconds: float, n: int = 2) -> list[float]:
    """``n`` websocket clients on the page's socket: snapshots per second each received."""
    import aiohttp

    ws_url = url.replace("http://", "ws://").replace("/?", "/ws?")

    async def one() -> float:
        async with aiohttp.ClientSession() as s, s.ws_connect(ws_url) as ws:
            count, t0 = 0, time.perf_counter()
            while (el := time.perf_counter() - t0) < seconds:
                try:
                    msg = await asyncio.wait_for(ws.receive(), timeout=seconds)
                except TimeoutError:
                    break
                if msg.type == aiohttp.WSMsgType.TEXT and '"type":"snap"' in msg.data:
                    count += 1
            return count / max(el, 1e-9)

    async def all_() -> list[float]:
        return list(await asyncio.gather(*(one() for _ in range(n))))

    return asyncio.run(all_())


def panel_cost(seconds: float = 3.0, repeat: int = 3, axes: int = 12) -> dict[str, Any]:
    """{rtf_without, rtf_with, cost_percent, updates_per_s (two browsers), ok}."""
    run = Path(tempfile.mkdtemp(prefix="gtecat-bench-run-"))
    run.chmod(0o700)
    os.environ.update(XDG_RUNTIME_DIR=str(run), GTECAT_INSPECT="1")
    from gtecat.inspect import runtime

    gt = bs._gt()
    plan = dict.fromkeys(range(1, axes + 1), "moving")
    window = seconds / repeat
    with tempfile.TemporaryDirectory() as tmp:
        eni = bs.write_axes_eni(axes, Path(tmp) / f"axes{axes}.eni")
        bs.bring_up(eni, axes)
        try:
            for a in plan:
                bs.gtn("AxisOn", a)
            bs.STARTERS["moving"](list(plan))
            gt.GTE_Wait(bs.WARM_UP_MS)
            (ep,) = runtime.endpoints()
            from gtecat.inspect.endpoint import COST

            rates: list[float] = []
            without, with_, shares = [], [], []
            for _ in range(repeat):
                without.append(_measure(gt, window))  # nobody attached
                with_.append(_watched(gt, ep.id, window, rates, COST, shares))
            bs.check(plan)
        finally:
            gt.GT_Close()
    r0, r1 = max(without), max(with_)
    cost = (1 - r1 / r0) * 100
    ups = min(rates) if rates else 0.0
    per_cycle_us = 1000 / r0  # CPU µs of one cycle, nobody attached
    w = wrapper_ns()
    work = sorted(shares[0::2])[len(shares) // 4] * 100  # the median window's share
    requests = sum(shares[1::2]) / (len(shares) // 2) / window
    return {
        "axes": axes,
        "cpu_us_per_cycle": round(per_cycle_us, 2),
        "wrapper_ns_per_cycle": round(w, 1),
        "wrapper_percent": round(w / 10 / per_cycle_us, 2),
        "requests_per_s": round(requests, 1),
        "endpoint_work_percent": round(work, 2),
        "measured_cost_percent_noisy": round(cost, 2),
        "rtf_per_cpu_without_panel": round(r0, 3),
        "rtf_per_cpu_with_panel": round(r1, 3),
        "updates_per_s_min_of_2_browsers": round(ups, 1),
        "target": "wrapper + endpoint work <= 5 % of the cycle time, updates >= 20 /s",
        "ok": w / 10 / per_cycle_us + work <= 5.0 and ups >= 20,
    }


def _measure(gt: Any, window: float) -> float:
    """Controller ms per CPU ms of this process (the application, its endpoint thread
    included) over ``window`` wall seconds: what the cycles cost the application itself,
    whatever else the machine runs (the panel's own process is not counted)."""
    ms0, _ = bs._clock()
    c0, t0 = time.process_time(), time.perf_counter()
    while time.perf_counter() - t0 < window:
        gt.GTE_Wait(bs.CHUNK_MS)
    ms1, _ = bs._clock()
    return (ms1 - ms0) / 1000 / (time.process_time() - c0)


def _watched(
    gt: Any, ep_id: str, window: float, rates: list[float], cost: list[int], shares: list[float]
) -> float:
    """One window with a panel attached and two browsers receiving (the panel is started
    before the window, once the browsers are connected, and ended after it)."""
    panel = subprocess.Popen(
        [sys.executable, "-m", "gtecat", "panel", "--attach", ep_id, "--port", "0"],
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        line = panel.stdout.readline() if panel.stdout else ""
        url = line[line.index("http://") :].strip()
        # the browsers are processes of their own, as real ones are; the application
        # runs all the while (an idle one is answered at most every 20 ms)
        child = subprocess.Popen(
            [sys.executable, __file__, "--browsers", url, "--seconds", str(window + 1.5)],
            stdout=subprocess.PIPE,
            text=True,
        )
        t0 = time.perf_counter()
        while time.perf_counter() - t0 < 1.0:  # the browsers connect
            gt.GTE_Wait(bs.CHUNK_MS)
        n0, ns0, c0 = cost[0], cost[1], time.process_time()
        r = _measure(gt, window)
        # the endpoint's own work (reading, running, answering requests) in this window
        shares.append((cost[1] - ns0) / 1e9 / (time.process_time() - c0))
        shares.append(cost[0] - n0)
        while child.poll() is None:
            gt.GTE_Wait(bs.CHUNK_MS)
        out, _ = child.communicate(timeout=60)
        rates.extend(json.loads(out))
        return r
    finally:
        panel.terminate()
        panel.wait(5)
        gt.GTE_Wait(bs.CHUNK_MS)  # the endpoint sees the panel go


def wrapper_ns(n: int = 200_000) -> float:
    """What the endpoint adds to every cycle while someone is attached (ns, best of 5),
    measured on an empty cycle: an upper bound independent of the machine's load."""
    from gtecat.inspect.endpoint import Endpoint

    class _Clock:
        def _run_cycle(self) -> None:
            pass

    class _Ctl:
        clock = _Clock()

    ep = Endpoint(_Ctl())
    wrapped, bare = ep._cycle, _Ctl.clock._run_cycle
    best = float("inf")
    for _ in range(5):
        t0 = time.perf_counter_ns()
        for _ in range(n):
            wrapped()
        t1 = time.perf_counter_ns()
        for _ in range(n):
            bare()
        t2 = time.perf_counter_ns()
        best = min(best, ((t1 - t0) - (t2 - t1)) / n)
    return best


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seconds", type=float, default=4.0, help="wall seconds per figure")
    ap.add_argument("--repeat", type=int, default=8, help="windows per figure")
    ap.add_argument("--browsers", metavar="URL", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.browsers:
        print(json.dumps(_browsers(args.browsers, args.seconds)))
        return 0
    print(json.dumps(panel_cost(args.seconds, args.repeat), indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
