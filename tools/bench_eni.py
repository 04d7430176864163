"""Benchmark: read a 64-slave ENI (issue 2 target: < 0.3 s).

``bench_read(n_slaves)`` writes an ETG.2100 ENI with :mod:`gtecat.eni.writer` into a
temporary directory (servo drives with the figure 5-2 mapping, every fourth
slave a 4-axis module, every eighth a DI16/DO16 terminal) and times
:func:`gtecat.eni.reader.read_eni` plus :func:`gtecat.eni.layout.build_layout`, best of
several runs.  ``python tools/bench_eni.py`` prints the result as JSON.
"""

from __future__ import annotations

import json
import tempfile
import time
from pathlib import Path
from typing import Any

from gtecat.eni.layout import build_layout
from gtecat.eni.reader import read_eni
from gtecat.eni.topology import build_config
from gtecat.eni.writer import write_eni_file

TARGET_S = 0.3


def bench_topology(n_slaves: int) -> dict[str, Any]:
    slaves: list[dict[str, Any]] = []
    for k in range(n_slaves):
        if k % 8 == 7:
            slaves.append({"kind": "io", "name": f"IO {k}", "do": 16, "di": 16})
        elif k % 4 == 3:
            slaves.append({"kind": "servo", "name": f"Module {k}", "channels": 4})
        else:
            slaves.append({"kind": "servo", "name": f"Drive {k}"})
    return {"cycle_time_us": 1000, "slave": slaves}


def bench_read(n_slaves: int = 64, repeat: int = 5) -> dict[str, Any]:
    cfg = build_config(bench_topology(n_slaves), "<bench>")
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "bench.eni"
        write_eni_file(cfg, path)
        size = path.stat().st_size
        best = float("inf")
        layout = None
        for _ in range(max(1, repeat)):
            t0 = time.perf_counter()
            layout = build_layout(read_eni(path))
            best = min(best, time.perf_counter() - t0)
    assert layout is not None
    return {
        "name": "eni_read",
        "n_slaves": n_slaves,
        "axes": len(layout.axes),
        "entries": sum(len(s.entries) for s in layout.slaves),
        "file_bytes": size,
        "seconds": round(best, 4),
        "target_seconds": TARGET_S,
        "ok": best < TARGET_S,
    }


if __name__ == "__main__":
    print(json.dumps(bench_read(), indent=2))
