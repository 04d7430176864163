"""tools/bench_wire.py's paced master: it sleeps between cycles (a real-time task that never
sleeps loses its CPU to the kernel 50 ms every second), skips a slot that has passed instead
of sending the frames it owed in a burst, and reports its own lateness beside the round trip."""

from __future__ import annotations

import time

from tools.bench_wire import percentiles, run_cycles


class FakeMaster:
    """pysoem's two calls, one of them slow once (an answer 8 ms late)."""

    expected_wkc = 3

    def __init__(self, slow_at: int) -> None:
        self.sent: list[int] = []
        self.slow_at = slow_at

    def send_processdata(self) -> None:
        self.sent.append(time.perf_counter_ns())

    def receive_processdata(self, timeout_us: int) -> int:
        if len(self.sent) == self.slow_at:
            time.sleep(0.008)
        return self.expected_wkc


def test_a_late_cycle_is_counted_and_its_slots_skipped_not_sent_in_a_burst() -> None:
    master = FakeMaster(slow_at=5)
    period = 2_000_000
    out = run_cycles(master, 12, period, spin_ns=200_000)
    assert out["cycles"] == 12 and out["wkc_errors"] == 0
    # (at least: a busy machine may delay this normal-priority test now and then)
    assert out["late"] >= 1 and out["rtt_over_1ms"] >= 1 and out["late_over_2ms"] >= 1
    assert out["skipped"] >= 2  # the 8 ms answer covered at least three 2 ms slots
    # the frames owed for those slots were not sent back to back (one short gap at most:
    # the cycle right after the late answer)
    gaps = [b - a for a, b in zip(master.sent, master.sent[1:], strict=False)]
    assert sum(gap < period // 4 for gap in gaps) <= 1
    assert set(out["master_start_late_us"]) == {"mean", "p50", "p90", "p99", "max"}
    assert "host_cpu_busy_percent" in out and "loadavg_1min" in out


def test_percentiles_of_nothing_and_of_a_list() -> None:
    assert percentiles([]) == {}
    got = percentiles([1000 * i for i in range(1, 101)])
    assert got["p50"] == 51.0 and got["max"] == 100.0
