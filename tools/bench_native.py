"""Round trip of one ``GT_GetSts`` from C through libgts and the controller; prints JSON.

    python tools/bench_native.py [--calls 20000] [--clock auto|lockstep|realtime]
                                 [--eni examples/manual_fig5_2.eni] [--no-wall-floor]
                                 [--transport private|unix|tcp] [--rt-priority auto|off|N]

A C program (compiled here with ``$(python3 -m gtecat lib --cflags --libs)``) opens a
private controller, brings the bus up, enables axis 1 and then times each of
``--calls`` calls of ``GT_GetSts(1, &sts, 1, NULL)`` with ``clock_gettime``.  In
``auto`` every call charges 50 us of virtual latency, so one call in twenty also runs a
bus cycle: that is the tail (p99); ``lockstep`` shows the bare round trip.
Quality bar: p50 <= 30 us, p99 <= 200 us on the Unix socket.

``--transport unix|tcp`` starts ``gtecat controller --listen`` on a Unix socket or on TCP
127.0.0.1 (with a token) and the program attaches to it through ``GTECAT_CONTROLLER``
instead of starting a private one; bar for TCP on loopback: p50 <= 60 us, p99 <= 300 us.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

PROGRAM = r"""
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include <unistd.h>
#include "gts.h"

static long long ns(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (long long)t.tv_sec * 1000000000LL + t.tv_nsec;
}

int main(int argc, char **argv)
{
    int n = argc > 1 ? atoi(argv[1]) : 20000;
    short st = 0;
    if (GT_Open(0, 1) || GT_InitEcatComm())
        return 2;
    for (int i = 0; i < 2000 && !st; i++) {
        GT_IsEcatReady(&st);
        if (!st) {
            GTE_Wait(1);
        }
    }
    GT_StartEcatComm();
    GT_AxisOn(1);
    GTE_Wait(20);
    long sts = 0;
    for (int i = 0; i < 200; i++)
        GT_GetSts(1, &sts, 1, NULL); /* warm up */
    long long *d = malloc(sizeof *d * (size_t)n);
    long long start = ns();
    for (int i = 0; i < n; i++) {
        long long t0 = ns();
        if (GT_GetSts(1, &sts, 1, NULL) != 0)
            return 3;
        d[i] = ns() - t0;
    }
    long long total = ns() - start;
    unsigned long clock_ms = 0;
    GT_GetClock(&clock_ms, NULL);
    printf("%lld %lu\n", total, clock_ms);
    for (int i = 0; i < n; i++)
        printf("%lld\n", d[i]);
    GT_Close();
    return 0;
}
"""


def percentiles(samples_ns: list[int]) -> dict[str, float]:
    data = sorted(samples_ns)
    n = len(data)

    def pct(p: float) -> float:
        return round(data[min(n - 1, int(p * n))] / 1000.0, 1)

    return {
        "mean": round(sum(data) / n / 1000.0, 1),
        "p50": pct(0.5),
        "p90": pct(0.9),
        "p99": pct(0.99),
        "max": round(data[-1] / 1000.0, 1),
    }


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--calls", type=int, default=20000)
    ap.add_argument("--clock", default="auto", choices=("auto", "lockstep", "realtime"))
    ap.add_argument("--eni", default=str(ROOT / "examples" / "manual_fig5_2.eni"))
    ap.add_argument("--no-wall-floor", action="store_true")
    ap.add_argument(
        "--spin-us", type=int, default=None, help="GTECAT_SPIN_US: the client spins for its reply"
    )
    ap.add_argument(
        "--server-spin-us",
        type=int,
        default=None,
        help="GTECAT_SERVER_SPIN_US: the controller spins for the next request",
    )
    ap.add_argument(
        "--rt-priority",
        default=None,
        help="GTECAT_RT_PRIORITY: the controller's real-time priority while the CPUs are "
        "busy (auto, the default; off; 1-99)",
    )
    ap.add_argument(
        "--transport",
        default="private",
        choices=("private", "unix", "tcp"),
        help="private: the controller the program starts (Unix socket); unix / tcp: a "
        "`gtecat controller --listen` started here",
    )
    args = ap.parse_args(argv)

    from gtecat.native.build import ensure_built

    build = ensure_built()
    with tempfile.TemporaryDirectory() as tmp:
        src = Path(tmp) / "bench.c"
        exe = Path(tmp) / "bench"
        src.write_text(PROGRAM)
        subprocess.run(
            ["cc", "-O2", str(src), *build.cflags(), *build.libs(), "-o", str(exe)], check=True
        )
        env = {k: v for k, v in os.environ.items() if not k.startswith("GTECAT_")}
        env.update(GTECAT_ENI=args.eni, GTECAT_CLOCK=args.clock, GTECAT_LOG="")
        if args.no_wall_floor:
            env["GTECAT_WALL_FLOOR"] = "0"
        if args.spin_us is not None:
            env["GTECAT_SPIN_US"] = str(args.spin_us)
        if args.server_spin_us is not None:
            env["GTECAT_SERVER_SPIN_US"] = str(args.server_spin_us)
        if args.rt_priority is not None:
            env["GTECAT_RT_PRIORITY"] = args.rt_priority
        controller = None
        if args.transport != "private":
            address = f"unix:{tmp}/ctl.sock" if args.transport == "unix" else _free_tcp()
            env["GTECAT_TOKEN"] = "bench-token"
            controller = subprocess.Popen(
                [sys.executable, "-m", "gtecat", "controller", "--listen", address],
                env=env,
                cwd=tmp,
                stderr=subprocess.DEVNULL,
            )
            from gtecat.native.server import wait_for

            wait_for(address, 60)
            env["GTECAT_CONTROLLER"] = address
        try:
            r = subprocess.run(
                [str(exe), str(args.calls)], capture_output=True, text=True, env=env, cwd=tmp
            )
        finally:
            if controller is not None:
                controller.terminate()
                controller.wait(10)
    if r.returncode != 0:
        print(r.stderr, file=sys.stderr)
        return 1
    lines = r.stdout.split()
    total_ns, clock_ms = int(lines[0]), int(lines[1])
    samples = [int(x) for x in lines[2:]]
    stats = percentiles(samples)
    tcp = args.transport == "tcp"
    target = {"p50_us": 60, "p99_us": 300} if tcp else {"p50_us": 30, "p99_us": 200}
    result = {
        "call": "GT_GetSts(1, &sts, 1, NULL) from C",
        "transport": args.transport,
        "clock": args.clock,
        "wall_floor": not args.no_wall_floor and args.clock == "auto",
        "spin_us": {
            "client": env.get("GTECAT_SPIN_US", "default"),
            "server": env.get("GTECAT_SERVER_SPIN_US", "default"),
        },
        "rt_priority": env.get("GTECAT_RT_PRIORITY", "auto"),
        "calls": len(samples),
        "round_trip_us": stats,
        "calls_per_s": round(len(samples) / (total_ns / 1e9)),
        "controller_ms_at_end": clock_ms,
        "target": target,
        "meets_target": stats["p50"] <= target["p50_us"] and stats["p99"] <= target["p99_us"],
        "machine": {
            "cpus": os.cpu_count(),
            "load": os.getloadavg()[0],
            "python": sys.version.split()[0],
            "platform": platform.platform(),
        },
    }
    print(json.dumps(result, indent=2))
    return 0


def _free_tcp() -> str:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    time.sleep(0.01)
    return f"tcp:127.0.0.1:{port}"


if __name__ == "__main__":
    sys.exit(main())
