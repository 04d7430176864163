"""Controller time: the three clock modes of DESIGN.md ("Time").

* ``lockstep`` - nothing moves until :meth:`Clock.advance` (unit tests).
* ``auto`` - virtual time; every GT call costs ``call_latency_ns`` of it, so
  unmodified polling loops terminate, deterministically and fast.
* ``realtime`` - a background thread runs cycles against the wall clock; GT
  calls hold :attr:`Clock.lock` so they are atomic with respect to a cycle.

Time is integer nanoseconds.  The clock does not know what a cycle does: the
owner passes ``run_cycle`` (one bus + controller cycle).

Several controllers in one process (the cards of one PC, the cores of one card) share
one time: their clocks join a :class:`ClockGroup`, and whatever time one of them lets
pass (a call's latency, a wait, a polling loop's cycles) passes for all of them, so a
card keeps moving while the application polls another.  Each clock still counts its own
cycles and its own time since its power-on.  Realtime clocks need no group: the wall
clock is shared already.
"""

from __future__ import annotations

import contextlib
import threading
import time
from array import array
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from enum import StrEnum
from operator import attrgetter
from typing import Any

from .._attrs import in_array


class ClockMode(StrEnum):
    LOCKSTEP = "lockstep"
    AUTO = "auto"
    REALTIME = "realtime"


#: looked up once: every advance asks (an enum member's lookup costs more than the ``is``)
_REALTIME = ClockMode.REALTIME

#: The generation of what a quick cycle armed for the GT readers' C entries relies on besides
#: the readers' epoch and the slaves' marks (``Controller.arm_quick``): a cycle hook added,
#: taken away or replaced, a clock's cycle wrapped.  It only grows; the C entries compare it
#: with the one their clock was armed in (memory they read: gtecat.gt.centry).
ARMS = array("q", (1,))


def disarm() -> None:
    """Whatever a C entry's quick cycle was armed with may be stale: it asks Python again."""
    ARMS[0] += 1


def _disarming(name: str) -> Callable[..., Any]:
    """``list.<name>`` that disarms the quick cycles first (:class:`Hooks`)."""
    base = getattr(list, name)

    def changed(self: list, *args: Any, **kwargs: Any) -> Any:
        disarm()
        return base(self, *args, **kwargs)

    changed.__name__ = name
    return changed


class Hooks(list):
    """A list of cycle hooks whose every change disarms the quick cycles (:func:`disarm`):
    a hook added in place between two calls runs in the next cycle, as with no quick way.
    Reading and iterating are a plain list's."""

    __slots__ = ()
    append = _disarming("append")
    extend = _disarming("extend")
    insert = _disarming("insert")
    remove = _disarming("remove")
    pop = _disarming("pop")
    clear = _disarming("clear")
    sort = _disarming("sort")
    reverse = _disarming("reverse")
    __setitem__ = _disarming("__setitem__")
    __delitem__ = _disarming("__delitem__")
    __iadd__ = _disarming("__iadd__")
    __imul__ = _disarming("__imul__")


def hook_list(name: str) -> property:
    """An attribute holding a :class:`Hooks` list (kept as ``_name``): a list assigned to it
    becomes one, and the assignment disarms the quick cycles too."""
    key = "_" + name

    def put(self: Any, value: Any) -> None:
        # (a plain attribute's store: asking for the object's __dict__ would make every later
        # read of its attributes take the slow way - gtecat._attrs)
        setattr(self, key, value if type(value) is Hooks else Hooks(value))
        disarm()

    # (read every cycle: a getter in C, not a Python frame)
    return property(attrgetter(key), put, doc=f"the {name} hooks (:class:`Hooks`)")


@dataclass
class CycleStats:
    """Wall-clock cycle statistics (realtime mode): period and jitter in ns."""

    cycles: int = 0
    overruns: int = 0
    periods_ns: list[int] = field(default_factory=list)
    max_samples: int = 100_000

    def add(self, period_ns: int) -> None:
        self.cycles += 1
        if len(self.periods_ns) < self.max_samples:
            self.periods_ns.append(period_ns)


class Clock:
    """Counts controller time and decides when cycles run."""

    def __init__(
        self,
        run_cycle: Callable[[], None],
        *,
        cycle_ns: int = 1_000_000,
        mode: ClockMode | str = ClockMode.AUTO,
        call_latency_ns: int = 50_000,
    ) -> None:
        #: the numbers a call's host latency needs, in memory compiled code reads and writes
        #: (the GT readers' C entries add the latency themselves where it runs no cycle:
        #: gtecat.gt.centry): the latency accumulated since the last cycle (auto), the
        #: latency of a call, the cycle time, 1 while the clock shares its time with no other
        #: [4:8] a quick cycle armed for them (gtecat.controller.core.Controller.arm_quick):
        #: the readers' epoch it holds for (0: none), the generation of :data:`ARMS`, the
        #: slaves' AL and outside changes, and the address of the armed kernel's call;
        #: [9] the controller time (:attr:`now_ns`) and [10] the cycles run (:attr:`cycles`),
        #: which the entry that runs the armed cycle counts itself; [11] how many more cycles
        #: the entries may run armed so (the cycle hooks' quiet budget: each such cycle takes
        #: one; Controller.quick_book)
        self.quick = array("q", (0, int(call_latency_ns), 0, 1, 0, 0, 0, 0, 0, 0, 0, 0))
        self.cycle_ns = cycle_ns  # (checked: whole nanoseconds, positive)
        self.mode = ClockMode(mode)
        self._cycle_fn = run_cycle
        #: the owner's way to run up to N cycles at once (returns the cycles it ran, 0: run
        #: the next one through ``run_cycle``); virtual time only, None: one by one
        self.run_many: Callable[[int], int] | None = None
        self.now_ns = 0  # controller time since power-on
        self.cycles = 0
        self.lock = threading.RLock()
        self.stats = CycleStats()
        self._thread: threading.Thread | None = None
        self._stop = threading.Event()
        #: the clocks this one shares time with (None: it runs alone)
        self._group: ClockGroup | None = None
        #: called once cycles have run and their time is counted (the owner's: what was
        #: read of the time before may be stale now)
        self.counted: Callable[[], None] | None = None

    @property
    def _run_cycle(self) -> Callable[[], None]:
        """What one cycle runs (the owner's; an inspection endpoint wraps it for a while)."""
        return self._cycle_fn

    @_run_cycle.setter
    def _run_cycle(self, fn: Callable[[], None]) -> None:
        self._cycle_fn = fn
        disarm()  # (a wrapped cycle: no quick cycle runs past the wrapper)

    @property
    def cycle_ns(self) -> int:
        return self.quick[2]

    @cycle_ns.setter
    def cycle_ns(self, ns: int) -> None:
        ns = int(ns)
        if ns <= 0:
            raise ValueError("cycle time must be positive")
        self.quick[2] = ns

    now_ns = in_array("quick", 9, "Controller time since power-on, in ns.")
    cycles = in_array("quick", 10, "The cycles this clock has run.")

    @property
    def call_latency_ns(self) -> int:
        """The controller time one GT call costs in the auto clock (its host round trip)."""
        return self.quick[1]

    @call_latency_ns.setter
    def call_latency_ns(self, ns: int) -> None:
        self.quick[1] = int(ns)

    @property
    def _pending_ns(self) -> int:
        """Auto mode: the latency accumulated since the last cycle."""
        return self.quick[0]

    @_pending_ns.setter
    def _pending_ns(self, ns: int) -> None:
        self.quick[0] = int(ns)

    @property
    def group(self) -> ClockGroup | None:
        """The clocks this one shares time with (None: it runs alone)."""
        return self._group

    @group.setter
    def group(self, group: ClockGroup | None) -> None:
        self._group = group
        self.quick[3] = group is None

    # --- virtual time ------------------------------------------------------
    def cycle(self) -> None:
        """Run exactly one cycle and count its time."""
        self._cycle_fn()
        q = self.quick  # (cycles, now_ns and cycle_ns in their array: no property calls)
        q[10] += 1
        q[9] += q[2]
        if self.counted is not None:
            self.counted()

    def advance_ns(self, ns: int) -> int:
        """Let ``ns`` of controller time pass (lockstep/auto); returns cycles run."""
        if self.mode is _REALTIME:
            self._sleep(max(0, ns) / 1e9)
            return 0
        q = self.quick
        q[0] += int(ns)
        n = 0
        many = self.run_many
        while q[0] >= q[2]:
            cycle_ns = q[2]
            if many is not None:
                k = many(q[0] // cycle_ns)
                if k:
                    q[0] -= k * cycle_ns
                    self.cycles += k
                    self.now_ns += k * cycle_ns
                    if self.counted is not None:
                        self.counted()
                    n += k
                    continue
            q[0] -= cycle_ns
            self.cycle()
            n += 1
        if self._group is not None:
            self._group.share(self, int(ns))
        return n

    def advance(self, ms: float) -> int:
        return self.advance_ns(round(ms * 1_000_000))

    def on_call(self) -> None:
        """A GT call happened: in ``auto`` mode it costs virtual latency; in ``realtime``
        the caller yields the interpreter, so a tight polling loop cannot starve the
        cycle thread (the call itself ran with the cycle lock held)."""
        if self.mode is ClockMode.AUTO and self.quick[1]:
            self.advance_ns(self.quick[1])
        elif self.mode is ClockMode.REALTIME:
            time.sleep(0)

    def run_until(
        self,
        pred: Callable[[], bool],
        timeout_ms: float,
        still: Callable[[], bool] | None = None,
    ) -> bool:
        """Run whole cycles until ``pred()`` holds or ``timeout_ms`` passes.

        ``still``: where it holds (asked before each run of cycles), ``pred``'s answer
        cannot change over cycles the owner runs its quick way (:attr:`run_many`), so the
        rest of the budget goes to the owner as one run: the cycles are the ones run one by
        one would be, and ``pred`` is asked after the run (a clock of a group shares its
        time cycle by cycle, so there it is not used)."""
        if self.mode is ClockMode.REALTIME:
            deadline = time.monotonic() + timeout_ms / 1000
            while time.monotonic() < deadline:
                with self.lock:
                    if pred():
                        return True
                self._sleep(self.cycle_ns / 1e9)
            with self.lock:
                return pred()
        budget = round(timeout_ms * 1_000_000)
        spent = 0
        many = self.run_many
        while not pred():
            if spent >= budget:
                return False
            if many is not None:
                n = 1
                if still is not None and self.group is None and still():
                    n = -(-(budget - spent) // self.cycle_ns)  # (the cycles left, as one by one)
                k = many(n)
                if k:  # the owner ran them its quick way
                    self.cycles += k
                    self.now_ns += k * self.cycle_ns
                    if self.counted is not None:
                        self.counted()
                    spent += k * self.cycle_ns
                    if self.group is not None:
                        self.group.share(self, k * self.cycle_ns)
                    continue
            self.cycle()
            spent += self.cycle_ns
            if self.group is not None:
                self.group.share(self, self.cycle_ns)
        return True

    def _sleep(self, seconds: float) -> None:
        """Sleep with the cycle lock released, so the cycle thread keeps running."""
        owned = self.lock._is_owned()  # type: ignore[attr-defined]
        if owned:
            self.lock.release()
        try:
            time.sleep(seconds)
        finally:
            if owned:
                self.lock.acquire()

    def pace(self, done: Callable[[float], bool]) -> int:
        """Virtual time at the wall clock's pace while something outside runs on the wall
        clock (a mailbox transfer on a wire): one cycle each time a bus cycle of wall time
        has passed, until ``done(seconds)``, which waits up to that long for the end of that
        something, says it is over.  A cycle late by a whole period re-phases, as in
        realtime (no burst).  Returns the cycles run."""
        n = 0
        due = time.perf_counter_ns() + self.cycle_ns
        while not done(max(0, due - time.perf_counter_ns()) / 1e9):
            self.advance_ns(self.cycle_ns)
            n += 1
            due += self.cycle_ns
            now = time.perf_counter_ns()
            if now > due:
                due = now + self.cycle_ns
        return n

    @contextlib.contextmanager
    def unlocked(self) -> Iterator[None]:
        """The cycle lock let go for the block, however many times this thread holds it, so
        the cycle thread runs meanwhile; held again as before once the block ends."""
        lock = self.lock
        if not lock._is_owned():  # type: ignore[attr-defined]
            yield
            return
        state = lock._release_save()  # type: ignore[attr-defined]
        try:
            yield
        finally:
            lock._acquire_restore(state)  # type: ignore[attr-defined]

    @property
    def in_cycle_thread(self) -> bool:
        """The calling thread is the realtime cycle thread (a hook of its cycle)."""
        return self._thread is not None and threading.current_thread() is self._thread

    @property
    def now_ms(self) -> int:
        return self.now_ns // 1_000_000

    # --- realtime ----------------------------------------------------------
    @property
    def threaded(self) -> bool:
        """A cycle thread runs (realtime): callers must hold :attr:`lock`."""
        return self._thread is not None

    def start_realtime(self) -> None:
        if self.mode is not ClockMode.REALTIME or self._thread is not None:
            return
        self._stop.clear()
        self._thread = threading.Thread(
            target=self._realtime_loop, name="gtecat-cycle", daemon=True
        )
        self._thread.start()

    def stop_realtime(self) -> None:
        if self._thread is None:
            return
        self._stop.set()
        self._thread.join(timeout=2.0)
        self._thread = None

    def _realtime_loop(self) -> None:
        period = self.cycle_ns
        next_t = time.perf_counter_ns() + period
        last = None
        while not self._stop.is_set():
            now = time.perf_counter_ns()
            if now < next_t:
                time.sleep((next_t - now) / 1e9)
                continue
            if last is not None:
                self.stats.add(now - last)
            last = now
            with self.lock:
                self.cycle()
            next_t += period
            if time.perf_counter_ns() > next_t:
                # missed a whole period: count it and re-phase instead of bursting
                self.stats.overruns += 1
                next_t = time.perf_counter_ns() + period


class ClockGroup:
    """Clocks that share one time (module docstring): the time one member lets pass, the
    others let pass too, in the order they joined, right after it."""

    def __init__(self) -> None:
        self.clocks: list[Clock] = []
        self._sharing = False

    def join(self, clock: Clock) -> None:
        if clock.mode is ClockMode.REALTIME or clock in self.clocks:
            return
        self.clocks.append(clock)
        self._link()

    def leave(self, clock: Clock) -> None:
        if clock in self.clocks:
            self.clocks.remove(clock)
            clock.group = None
            self._link()

    def _link(self) -> None:
        """A clock alone needs no sharing (nothing to do on its hot path)."""
        alone = len(self.clocks) < 2
        for c in self.clocks:
            c.group = None if alone else self

    def share(self, source: Clock, ns: int) -> None:
        """``source`` let ``ns`` pass: the other members let it pass too (once: what they
        run meanwhile does not share again)."""
        if self._sharing or ns <= 0:
            return
        self._sharing = True
        try:
            for c in self.clocks:
                if c is not source:
                    c.advance_ns(ns)
        finally:
            self._sharing = False
