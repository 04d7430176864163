"""Realtime cycle figures of the pysoem backend: period, jitter p50/p99/max, overruns (JSON).

    sudo python3 tools/bench_pysoem.py                      # 10 s at 1 ms on a fresh veth pair
    sudo python3 tools/bench_pysoem.py --seconds 60         # the issue's 60 s run
    sudo python3 tools/bench_pysoem.py --iface eth1 --no-serve --eni Gecat.eni   # a real bus

Without ``--iface`` it creates a veth pair (unique names, always deleted) and
runs ``gtecat serve`` with the ENI's virtual slaves on the far end.  The
controller runs the whole GT stack in ``realtime`` clock mode (the cycle
thread of :mod:`gtecat.master.clock`), every CiA-402 axis enabled so each cycle also
writes set-points.  Statistics are reset once the bus is ready, so bring-up
is not counted; the output is one JSON object (:func:`cycle_stats` plus the
server's frame latency and the machine).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from contextlib import ExitStack
from ctypes import byref, c_short
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))


def _ip(*args: str, check: bool = True) -> None:
    subprocess.run(["ip", *args], check=check, capture_output=True)


def make_veth(stack: ExitStack) -> tuple[str, str]:
    tag = f"{os.getpid() % 100000:05d}"
    a, b = f"gbm{tag}", f"gbs{tag}"
    _ip("link", "add", a, "type", "veth", "peer", "name", b)
    stack.callback(_ip, "link", "del", a, check=False)
    for name in (a, b):
        Path(f"/proc/sys/net/ipv6/conf/{name}/disable_ipv6").write_text("1")
        _ip("link", "set", name, "up")
    return a, b


def start_serve(stack: ExitStack, eni: Path, iface: str, stats_json: Path):
    proc = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "gtecat.cli.serve_cmd",
            "--eni",
            str(eni),
            "--iface",
            iface,
            "--stats-json",
            str(stats_json),
        ],
        cwd=ROOT,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )

    def stop() -> None:
        if proc.poll() is None:
            proc.terminate()
            try:
                proc.wait(10)
            except subprocess.TimeoutExpired:
                proc.kill()

    stack.callback(stop)
    assert proc.stdout is not None
    line = proc.stdout.readline()
    if "ready" not in line:
        raise SystemExit(f"gtecat serve did not start: {line.strip()}")
    return stop


def bare_loop(seconds: float, cycle_ns: int) -> dict:
    """The platform's own floor: the same sleep-paced loop doing nothing.

    Same pacing rule as the realtime clock (sleep to the next period, count an
    overrun and re-phase when a whole period is missed), so the difference to
    the bus run is what the stack and the wire add.
    """
    from gtecat.master.backends.cycle_stats import summarize_periods

    periods: list[int] = []
    overruns = 0
    n = int(seconds * 1e9 / cycle_ns)
    next_t = time.perf_counter_ns() + cycle_ns
    last = None
    while len(periods) < n:
        now = time.perf_counter_ns()
        if now < next_t:
            time.sleep((next_t - now) / 1e9)
            continue
        if last is not None:
            periods.append(now - last)
        last = now
        next_t += cycle_ns
        if time.perf_counter_ns() > next_t:
            overruns += 1
            next_t = time.perf_counter_ns() + cycle_ns
    return {
        "seconds": seconds,
        "overruns": overruns,
        "period": summarize_periods(periods, cycle_ns).as_dict(),
    }


def run(args: argparse.Namespace) -> dict:
    from gtecat import gt
    from gtecat.master.backends.cycle_stats import cycle_stats
    from gtecat.master.clock import CycleStats

    out: dict = {
        "machine": {
            "python": platform.python_version(),
            "kernel": platform.release(),
            "cpus": os.cpu_count(),
            "loadavg_before": os.getloadavg(),
        },
        "cycle_us": args.cycle_us,
        "seconds": args.seconds,
        "eni": str(args.eni),
    }
    with ExitStack() as stack, tempfile.TemporaryDirectory() as tmp:
        serve_stats = Path(tmp) / "serve.json"
        iface = args.iface
        if iface is None:
            iface, peer = make_veth(stack)
            out["link"] = f"veth {iface} <-> {peer}"
        else:
            out["link"] = iface
        stop_serve = None
        if not args.no_serve:
            stop_serve = start_serve(
                stack, args.eni, peer if args.iface is None else args.serve_iface, serve_stats
            )
        gt.GT_Close()
        rc = gt.GT_Open(
            eni=str(args.eni),
            backend="pysoem",
            iface=iface,
            clock="realtime",
            cycle_ms=args.cycle_us / 1000,
            log="",
        )
        stack.callback(gt.GT_Close)
        t0 = time.perf_counter()
        if rc or gt.GT_InitEcatComm():
            raise SystemExit(f"bring-up failed: {gt.GTE_GetLastError()}")
        status = c_short()
        deadline = time.monotonic() + 10
        while gt.GT_IsEcatReady(byref(status)) == 0 and status.value != 1:
            if time.monotonic() > deadline:
                raise SystemExit(f"bus not ready: {gt.GTE_GetLastError()}")
            gt.GTE_Wait(1)
        out["bring_up_ms"] = round((time.perf_counter() - t0) * 1000, 1)
        gt.GT_StartEcatComm()
        ctl = gt.GTE_Controller()
        axes = len(ctl.axes)
        enabled = sum(gt.GT_AxisOn(a) == 0 for a in range(1, axes + 1))
        out["axes_enabled"] = f"{enabled}/{axes}"
        with ctl.clock.lock:  # measure the steady state only
            ctl.clock.stats = CycleStats(max_samples=int(args.seconds * 1e6 / args.cycle_us) + 1000)
            if ctl.master is not None:
                ctl.master.wkc_errors = 0
            bus = getattr(ctl.backend, "stats", None)
            if bus is not None:
                ctl.backend.stats = type(bus)()
        gt.GTE_Wait(args.seconds * 1000)
        out.update(cycle_stats(ctl))
        ready = c_short()
        gt.GT_IsEcatReady(byref(ready))
        out["ready_at_end"] = ready.value
        out["machine"]["loadavg_after"] = os.getloadavg()
        gt.GT_Close()
        if stop_serve is not None:
            stop_serve()  # writes its --stats-json
        if serve_stats.exists():
            out["serve"] = json.loads(serve_stats.read_text())
    if args.baseline:
        out["platform_baseline"] = bare_loop(min(args.seconds, args.baseline), args.cycle_us * 1000)
    return out


def _fmt_us(ns: float | int | None) -> float | None:
    return None if ns is None else round(ns / 1000, 1)


def summary(out: dict) -> dict:
    """The figures the issue asks for, in microseconds."""
    p = out.get("period") or {}
    rtt = (out.get("bus") or {}).get("rtt") or {}
    return {
        "cycle_us": out["cycle_us"],
        "seconds": out["seconds"],
        "cycles": out.get("cycles"),
        "period_mean_us": _fmt_us(p.get("mean_ns")),
        "jitter_p50_us": _fmt_us(p.get("jitter_p50_ns")),
        "jitter_p99_us": _fmt_us(p.get("jitter_p99_ns")),
        "jitter_max_us": _fmt_us(p.get("jitter_max_ns")),
        "overruns": out.get("overruns"),
        "wkc_errors": out.get("wkc_errors"),
        "rtt_p50_us": _fmt_us(rtt.get("p50_ns")),
        "rtt_p99_us": _fmt_us(rtt.get("p99_ns")),
        "rtt_max_us": _fmt_us(rtt.get("max_ns")),
        "platform_baseline": _baseline_us(out.get("platform_baseline")),
    }


def _baseline_us(b: dict | None) -> dict | None:
    if not b:
        return None
    p = b["period"]
    return {
        "seconds": b["seconds"],
        "overruns": b["overruns"],
        "jitter_p50_us": _fmt_us(p["jitter_p50_ns"]),
        "jitter_p99_us": _fmt_us(p["jitter_p99_ns"]),
        "jitter_max_us": _fmt_us(p["jitter_max_ns"]),
    }


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seconds", type=float, default=10.0, help="measured run (default 10)")
    ap.add_argument("--cycle-us", type=int, default=1000, help="cycle time (default 1000)")
    ap.add_argument("--eni", type=Path, default=ROOT / "examples" / "manual_fig5_2.eni")
    ap.add_argument("--iface", help="use this interface instead of a fresh veth pair")
    ap.add_argument("--serve-iface", help="with --iface: where gtecat serve answers")
    ap.add_argument("--no-serve", action="store_true", help="real slaves are on --iface")
    ap.add_argument("--full", action="store_true", help="print every figure, not the summary")
    ap.add_argument(
        "--baseline",
        type=float,
        default=10.0,
        help="seconds of a bare sleep loop for comparison (0: none; default 10)",
    )
    args = ap.parse_args(argv)
    if args.iface and not args.no_serve and not args.serve_iface:
        ap.error("--iface needs --no-serve (real slaves) or --serve-iface")
    if os.geteuid() != 0:
        print("error: needs root (veth pair, raw sockets); see docs/hardware.md", file=sys.stderr)
        return 1
    out = run(args)
    print(json.dumps(out if args.full else {**summary(out), "full": out}, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
