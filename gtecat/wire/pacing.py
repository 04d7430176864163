"""When the master's next cyclic frame is due: the serve loop's predictive wait.

A master sends its process-data frame once per cycle, with a jitter of microseconds.
Sleeping in ``poll`` until it comes costs a wake-up (35 us at the median on the 2-vCPU VM,
most of the frame's latency); spinning the whole time costs a CPU.  :class:`Pacing`
learns the period from the arrivals of process-data frames, and the loop sleeps until
shortly before the next one is due, then spins on the socket until it comes - so the
frame finds the server awake, for a fraction of a core (the window over the period,
~20 % at 1 kHz).  Frames outside the rhythm (mailbox, a master that pauses) are still
answered: the sleep ends on any frame, and a window that passes without one sends the
loop back to plain ``poll`` until that frame comes (the rhythm is kept: a late frame does
not cost the next ones their window).

How early the window opens is learned, not fixed: a sleep ends late by the host's wake-up
latency (50 us at the median on the 2-vCPU VM, 150-400 us at the 99th percentile, worse
when the host is busy), and the master's frames wander around their due time by its own
jitter.  The margin is the 99th percentile of both, over the last few hundred cycles, plus
a guard - so on a quiet machine the loop spins little, and on a noisy one it starts early
enough to be awake for 99 frames in 100 (at most half a period: then it spins the whole
time, as ``--wait spin`` does).
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field

#: periods the loop predicts; outside them it just sleeps in poll (no cycle worth spinning
#: for, or one too short to sleep in between)
MIN_PERIOD_NS = 100_000
MAX_PERIOD_NS = 20_000_000
#: the margin before anything is learned: the window opens this long before the frame is due
BASE_MARGIN_NS = 150_000
#: the learned margin never goes below this (a wake-up is never on the nanosecond)
MIN_MARGIN_NS = 40_000
#: added to the learned percentile
GUARD_NS = 30_000
#: the percentile of late wake-ups and frame deviations the margin covers
QUANTILE = 0.99
#: samples of each kind kept; the margin is learned anew after every RELEARN new ones
SAMPLES = 256
RELEARN = 32
#: the window stays open at least this long after the due time: a frame the master sends
#: late (its own scheduling) is still found awake, at the cost of a spin only when it is late
LATE_SPAN_NS = 300_000
#: arrivals in a row within a quarter period of the estimate before the window is used
STEADY_AFTER = 8
#: intervals in a row off the learned period, agreeing with each other, before it is learned
#: anew (the master changed its cycle): one or two off the
#: rhythm (a frame the master sent late, the ones it then owed sent back to back, an extra
#: frame) do not throw a learned period away - on a busy host that happened every few
#: hundred cycles, and the loop then spent the next STEADY_AFTER frames without a window
#: (a 1 ms master was once reported at 344 us)
RELEARN_AFTER = 3


@dataclass(slots=True)
class Pacing:
    last_ns: int | None = None
    period_ns: float = 0.0
    jitter_ns: float = 0.0
    steady: int = 0
    #: windows that passed without the frame (the loop then slept in poll)
    misses: int = 0
    #: the margin the window opens before the due time (learned; BASE_MARGIN_NS at first)
    margin_ns: int = BASE_MARGIN_NS
    #: how late the sleeps before a window ended (ns), and how far frames came from their
    #: due time: the last SAMPLES of each
    late_wakes: deque[int] = field(default_factory=lambda: deque(maxlen=SAMPLES))
    deviations: deque[int] = field(default_factory=lambda: deque(maxlen=SAMPLES))
    #: a window passed without the frame: no window until the next one arrives
    waiting: bool = False
    #: intervals in a row off the learned period that agree with each other, and the last
    off: int = 0
    candidate_ns: float = 0.0
    _new: int = 0

    def woke(self, late_ns: int) -> None:
        """The sleep before a window ended ``late_ns`` after the window opened."""
        self.late_wakes.append(max(0, late_ns))
        self._new += 1

    def _learn(self) -> None:
        """The margin: the QUANTILE of the late wake-ups and of the deviations, plus GUARD_NS."""
        worst = 0
        for ring in (self.late_wakes, self.deviations):
            if ring:
                worst = max(worst, sorted(ring)[min(len(ring) - 1, int(QUANTILE * len(ring)))])
        self.margin_ns = max(MIN_MARGIN_NS, worst + GUARD_NS)

    def arrived(self, t_ns: int) -> None:
        """A process-data frame arrived at ``t_ns`` (kernel time where there is one)."""
        if self.last_ns is not None:
            dt = t_ns - self.last_ns
            period = self.period_ns
            if period and abs(dt - period) < period / 4:
                self.deviations.append(abs(round(dt - period)))
                self._new += 1
                self.jitter_ns += (abs(dt - period) - self.jitter_ns) / 16
                self.period_ns += (dt - period) / 16
                self.steady += 1
                self.off = 0
            elif dt > 0:
                # off the learned period: a new one only when RELEARN_AFTER intervals in a
                # row agree on it (a change of the master's cycle); stray ones (a late frame,
                # the owed ones after it) leave the period, and the window waits two frames
                cand = self.candidate_ns
                self.off = self.off + 1 if cand and abs(dt - cand) < cand / 4 else 1
                self.candidate_ns = float(dt)
                if not period or self.off >= RELEARN_AFTER:
                    self.period_ns, self.jitter_ns, self.steady = float(dt), 0.0, 0
                    self.off = 0
                else:
                    self.steady = min(self.steady, STEADY_AFTER - 2)
            if self._new >= RELEARN:  # after the answer: the sort is not in a frame's time
                self._new = 0
                self._learn()
        self.last_ns = t_ns
        self.waiting = False

    def missed(self) -> None:
        """The window passed without the frame: sleep in poll until it comes.  The rhythm is
        kept: a master that is late once (its own scheduling) is on time again next cycle,
        and a window lost for the next STEADY_AFTER frames would cost each its wake-up."""
        self.waiting = True
        self.misses += 1

    def window(self) -> tuple[int, int] | None:
        """(open, close) of the spin around the next frame's due time, or None.  It opens
        the learned margin before the due time and closes LATE_SPAN_NS after it (the margin
        when that is longer), never more than a period in all."""
        period = self.period_ns
        last = self.last_ns
        if (
            last is None
            or self.waiting
            or self.steady < STEADY_AFTER
            # the learned estimate of a master at either bound sits a few ns beside it
            or not MIN_PERIOD_NS * 0.99 <= period <= MAX_PERIOD_NS * 1.01
        ):
            return None
        margin = int(min(period / 2, self.margin_ns))
        late = int(min(period - margin, max(margin, LATE_SPAN_NS)))
        due = last + round(period)
        return due - margin, due + late


__all__ = ["Pacing"]
