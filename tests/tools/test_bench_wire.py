"""tools/bench_wire.py's paced master: it sleeps between cycles (a real-time task that never
sleeps loses its CPU to the kernel 50 ms every second), skips a slot that has passed instead
of sending the frames it owed in a burst, and reports its own lateness beside the round trip."""

from __future__ import annotations

from tools.bench_wire import percentiles, run_cycles


class FakeTime:
    """A clock that moves 1 us per reading (so a spin ends) and by the time slept."""

    def __init__(self) -> None:
        self.t = 1_000_000_000

    def clock(self) -> int:
        self.t += 1_000
        return self.t

    def sleep(self, seconds: float) -> None:
        self.t += int(seconds * 1e9)


class FakeMaster:
    """pysoem's two calls: a 50 us round trip, and once an answer 8 ms late."""

    expected_wkc = 3

    def __init__(self, now: FakeTime, slow_at: int) -> None:
        self.now = now
        self.sent: list[int] = []
        self.slow_at = slow_at

    def send_processdata(self) -> None:
        self.sent.append(self.now.t)

    def receive_processdata(self, timeout_us: int) -> int:
        self.now.t += 8_000_000 if len(self.sent) == self.slow_at else 50_000
        return self.expected_wkc


def test_a_late_cycle_is_counted_and_its_slots_skipped_not_sent_in_a_burst() -> None:
    now = FakeTime()
    master = FakeMaster(now, slow_at=5)
    period = 2_000_000
    out = run_cycles(master, 12, period, 200_000, clock=now.clock, sleep=now.sleep)
    assert out["cycles"] == 12 and out["wkc_errors"] == 0
    assert out["late"] == 1 and out["rtt_over_1ms"] == 1 and out["late_over_2ms"] == 1
    assert out["skipped"] == 3  # the 8 ms answer covered the next three 2 ms slots
    # the frames owed for those slots were not sent back to back: one cycle right after
    # the late answer (in the slot it ended in), then one per period again
    gaps = [b - a for a, b in zip(master.sent, master.sent[1:], strict=False)]
    assert sum(gap < period // 2 for gap in gaps) <= 1
    assert all(gap >= period - 10_000 for gap in gaps[5:])
    assert out["master_start_late_us"]["p50"] < 10  # the sleep ends early, a spin follows
    assert "loadavg_1min" in out


def test_percentiles_of_nothing_and_of_a_list() -> None:
    assert percentiles([]) == {}
    got = percentiles([1000 * i for i in range(1, 101)])
    assert got["p50"] == 51.0 and got["max"] == 100.0
