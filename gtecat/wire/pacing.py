"""When the master's next cyclic frame is due: the serve loop's predictive wait.

A master sends its process-data frame once per cycle, with a jitter of microseconds.
Sleeping in ``poll`` until it comes costs a wake-up (35 us at the median on the 2-vCPU VM,
most of the frame's latency); spinning the whole time costs a CPU.  :class:`Pacing`
learns the period from the arrivals of process-data frames, and the loop sleeps until
shortly before the next one is due, then spins on the socket until it comes - so the
frame finds the server awake, for a fraction of a core (the window over the period,
~20 % at 1 kHz).  Frames outside the rhythm (mailbox, a master that pauses) are still
answered: the sleep ends on any frame, and a window that passes without one sends the
loop back to plain ``poll`` until the rhythm is steady again.
"""

from __future__ import annotations

from dataclasses import dataclass

#: periods the loop predicts; outside them it just sleeps in poll (no cycle worth spinning
#: for, or one too short to sleep in between)
MIN_PERIOD_NS = 100_000
MAX_PERIOD_NS = 20_000_000
#: the window opens this long before the frame is due, plus four times the jitter
BASE_MARGIN_NS = 150_000
#: arrivals in a row within a quarter period of the estimate before the window is used
STEADY_AFTER = 8


@dataclass(slots=True)
class Pacing:
    last_ns: int | None = None
    period_ns: float = 0.0
    jitter_ns: float = 0.0
    steady: int = 0
    #: windows that passed without the frame (the loop then slept in poll)
    misses: int = 0

    def arrived(self, t_ns: int) -> None:
        """A process-data frame arrived at ``t_ns`` (kernel time where there is one)."""
        if self.last_ns is not None:
            dt = t_ns - self.last_ns
            period = self.period_ns
            if period and abs(dt - period) < period / 4:
                self.jitter_ns += (abs(dt - period) - self.jitter_ns) / 16
                self.period_ns += (dt - period) / 16
                self.steady += 1
            elif dt > 0:
                self.period_ns, self.jitter_ns, self.steady = float(dt), 0.0, 0
        self.last_ns = t_ns

    def missed(self) -> None:
        """The window passed without the frame: sleep in poll until the rhythm returns."""
        self.steady = 0
        self.misses += 1

    def window(self) -> tuple[int, int] | None:
        """(open, close) of the spin around the next frame's due time, or None."""
        period = self.period_ns
        last = self.last_ns
        if (
            last is None
            or self.steady < STEADY_AFTER
            or not MIN_PERIOD_NS <= period <= MAX_PERIOD_NS
        ):
            return None
        margin = int(min(period / 2, BASE_MARGIN_NS + 4 * self.jitter_ns))
        due = last + round(period)
        return due - margin, due + margin


__all__ = ["Pacing"]
