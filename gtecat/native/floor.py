"""The wall floor: controller time served to native clients never falls behind wall time.

C and C++ programs wait with ``Sleep()``/``usleep()`` between polls (the vendor demo
polls ``GTN_IsEcatReady`` every 500 ms, up to 100 times).  Pure ``auto`` time moves
only when a call charges its virtual latency, so such a program would see almost no
time pass while it sleeps.  With the floor, over every interval between two looks
(before each call and on every idle tick of the controller) controller time advances
at least as much as wall time did; calls still charge their latency on top, so a
tight polling loop runs far ahead of the wall, as in ``auto``.  Controller time is
therefore never behind the wall over any stretch, and a program's ``usleep(500000)``
lets at least 500 ms of bus cycles run.

Work per look is bounded (``budget_s`` of wall time), so a call arriving after a long
sleep is served promptly; a debt left over is paid on the next looks.  An idle controller
looks every :data:`IDLE_LOOK_S` (10 ms), running the cycles of that stretch at once.  A bus whose
cycles cost more than their period cannot keep up: the debt then grows (the floor
cannot make a slow machine fast; ``realtime`` would overrun the same way).

The floor is for ``auto`` only: ``lockstep`` stays fully manual and ``realtime``
already runs on the wall clock.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable

from ..master.clock import Clock, ClockMode

#: how long an idle controller waits before it looks at the wall again (s).  Longer than a
#: scheduler tick (10 ms at HZ=100, 4 ms at 250, 1 ms at 1000): the timeout of every wait
#: between a polling client's calls is then never the CPU's next timer event, so arming and
#: cancelling it does not reprogram the CPU's timer (each an exit to the hypervisor in a
#: virtual machine).  Measured on a 2-vCPU VM: a 1 ms wait cost the controller 8-10 us of
#: CPU per call of a tight loop (24 -> 16 us) and the round trip 11 us at p50 (31 -> 20 us).
#: A call looks first anyway, so it still sees every millisecond of the wall.
IDLE_LOOK_S = 0.01


def wall_floor_setting() -> bool:
    """GTECAT_WALL_FLOOR: the wall floor unless it says 0/off/no/false (the controller
    process and the in-process controller alike)."""
    env = os.environ.get("GTECAT_WALL_FLOOR", "1").strip().lower()
    return env not in ("0", "off", "no", "false")


class WallFloor:
    """Keeps one clock at or ahead of wall time, interval by interval."""

    def __init__(
        self,
        clock: Clock,
        *,
        wall_ns: Callable[[], int] = time.monotonic_ns,
        budget_s: float = 0.02,
    ) -> None:
        self.clock = clock
        self._wall_ns = wall_ns
        self.budget_s = budget_s
        self._wall_last = wall_ns()
        self._virt_last = self._virtual()
        self.debt_ns = 0  #: wall time not yet matched by controller time

    @property
    def active(self) -> bool:
        return self.clock.mode is ClockMode.AUTO

    def _virtual(self) -> int:
        # time already charged but not yet run as a cycle counts as passed
        q = self.clock.quick  # (Clock.now_ns, Clock._pending_ns)
        return q[9] + q[0]

    def look(self) -> int:
        """Advance the clock to cover the wall time since the last look; returns cycles run."""
        wall = self._wall_ns()
        q = self.clock.quick  # (now_ns and the pending latency read in place: once per call)
        virt = q[9] + q[0]
        need = self.debt_ns + (wall - self._wall_last) - (virt - self._virt_last)
        self._wall_last = wall
        if need <= 0:
            # the usual case of a polling program: the calls' latency kept controller time
            # ahead of the wall, nothing to run and no debt (what the general way gives)
            self.debt_ns = 0
            self._virt_last = virt
            return 0
        cycles = 0
        if need > 0 and self.active:
            step = self.clock.cycle_ns
            deadline = time.perf_counter() + self.budget_s
            # (the clock's lock, as every call's cycles hold it: a reader of another thread
            # of this process waits for it rather than read half a cycle - gtecat.gt.centry)
            with self.clock.lock:
                while need > 0:
                    n = min(need, step)
                    cycles += self.clock.advance_ns(n)
                    need -= n
                    if time.perf_counter() > deadline:
                        break
        self.debt_ns = max(0, need) if self.active else 0
        self._virt_last = self._virtual()
        return cycles

    def idle_timeout(self) -> float:
        """Seconds an idle controller may wait before the next look (:data:`IDLE_LOOK_S`,
        or a cycle where cycles are longer; none while a debt is left)."""
        if not self.active:
            return 1.0
        return 0.0 if self.debt_ns > 0 else max(IDLE_LOOK_S, self.clock.cycle_ns / 1e9)


__all__ = ["IDLE_LOOK_S", "WallFloor"]
