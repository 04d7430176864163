"""Real-time scheduling and time slices of gtecat's own server processes (``gtecat serve``, ``gtecat
controller`` and the controller libgts starts).

A server that answers requests must not wait behind other work on a busy host: a normal
(``SCHED_OTHER``) task woken while other programs keep every CPU busy may wait for one of
their time slices, milliseconds, where a ``SCHED_FIFO`` task runs at once.  So a server
asks for ``SCHED_FIFO`` by default (``auto``) where the system permits it (root,
``CAP_SYS_NICE`` or an ``RLIMIT_RTPRIO``), says what it got, and runs normally where it is
refused.  ``off`` never asks; a number asks for that priority (and a refusal is an error).

Decisions:

* **Priority 50** for ``auto``: above the kernel's threaded interrupt handlers of ordinary
  devices (50 is theirs too; a NIC's own stays above).
* **SCHED_RESET_ON_FORK**: threads and processes the server starts (a compiler building the
  cycle kernel, a background thread) run normally; only the serving thread is real-time.
* **No fixed CPU pinning**: a real-time task takes whichever CPU it wakes on from normal
  work, and the kernel moves it to another when a real-time task already runs there, which
  it cannot do for a pinned one.  The one exception is :class:`Beside`: while the CPUs are
  busy, the controller's serving thread, real-time or not, takes its client's CPU as its
  only one (a client waiting for its reply and the server answering it are one chain of
  work), and its CPUs back as soon as they are not.
* **Bounded spins**: a real-time task that never sleeps is stopped by the kernel for 50 ms
  of every second (``sched_rt_runtime_us``) and takes its CPU from everything else meanwhile;
  a real-time server sleeps between requests and spins only for a bounded time
  (:data:`RT_SPIN_CAP_US`).
* **A short time slice, where asked for** (:func:`short_slice`, ``GTECAT_SLICE_US``, Linux
  6.12 and later, no privilege needed): the serving thread asks for it, and libgts for each
  thread of a program that calls it.  A woken thread with a shorter slice than the running
  one gets the CPU at once where it has not used more than its share; its share itself does
  not change.  Off by default (:data:`DEFAULT_SLICE_US`: it did not help where measured).
* The decision (:func:`take`) gets the call that sets the policy injected, so the whole
  permitted / refused / off logic is tested without privileges.
"""

from __future__ import annotations

import os
import struct
import sys
from collections.abc import Callable
from dataclasses import dataclass

from gtecat.eni.errors import GtecatError

#: the SCHED_FIFO priority ``auto`` asks for
AUTO_RT_PRIORITY = 50
#: the environment variable the native controller and libgts read (auto, off or 1-99)
RT_ENV = "GTECAT_RT_PRIORITY"
#: the longest spin of a real-time server waiting for a client's next request (us)
RT_SPIN_CAP_US = 50.0
#: the system has real-time scheduling calls (Linux and other POSIX systems; not Windows)
AVAILABLE = hasattr(os, "sched_setscheduler")


class RealtimeRefused(GtecatError):
    """The system refused SCHED_FIFO (the message says why)."""


def parse_priority(text: str) -> int | str:
    """``auto``, ``off`` (``0`` too) or a priority 1-99 -> ``"auto"``, ``"off"`` or the int;
    ValueError with a sentence otherwise."""
    t = text.strip().lower()
    if t in ("auto", "off"):
        return t
    try:
        n = int(t)
    except ValueError:
        raise ValueError(f"{text!r}: a priority 1-99, auto or off") from None
    if n == 0:
        return "off"
    if not 1 <= n <= 99:
        raise ValueError(f"{n}: SCHED_FIFO priorities are 1-99")
    return n


def realtime_priority(priority: int) -> None:
    """Run the calling thread under SCHED_FIFO ``priority`` (1-99), its children and new
    threads normally; :class:`RealtimeRefused` where the system does not permit it."""
    try:
        policy = os.SCHED_FIFO | getattr(os, "SCHED_RESET_ON_FORK", 0)
        os.sched_setscheduler(0, policy, os.sched_param(priority))
    except (OSError, AttributeError, ValueError) as exc:
        raise RealtimeRefused(f"cannot set SCHED_FIFO priority {priority}: {exc}") from exc


@dataclass(frozen=True, slots=True)
class Scheduling:
    """What :func:`take` got: the priority (None: normal) and words for a status line."""

    priority: int | None
    words: str
    #: why real-time was asked for and refused ("" otherwise)
    refused: str = ""


NORMAL = Scheduling(None, "normal priority")


def take(
    setting: int | str,
    *,
    spins_forever: bool = False,
    set_fifo: Callable[[int], None] = realtime_priority,
    available: bool = AVAILABLE,
) -> Scheduling:
    """Take the scheduling ``setting`` asks for (``auto``, ``off`` or a priority).

    ``auto`` asks for :data:`AUTO_RT_PRIORITY` and falls back to normal priority where the
    system refuses (``refused`` says why); a number asks for that priority and a refusal
    raises :class:`RealtimeRefused`.  ``spins_forever``: the caller will never sleep (a
    busy-polling loop), so ``auto`` keeps normal priority (a real-time task that never
    sleeps is stopped by the kernel 50 ms of every second); a number takes FIFO anyway.
    Where the system has no real-time scheduling (``available`` False: Windows), ``auto``
    runs normally without a complaint."""
    if setting == "off" or (setting == "auto" and spins_forever):
        return NORMAL
    if setting == "auto" and not available:
        return Scheduling(None, "normal priority (no real-time scheduling on this system)")
    prio = AUTO_RT_PRIORITY if setting == "auto" else int(setting)
    try:
        set_fifo(prio)
    except RealtimeRefused as exc:
        if setting != "auto":
            raise
        return Scheduling(None, "normal priority (real-time refused)", refused=str(exc))
    return Scheduling(prio, f"SCHED_FIFO {prio}")


def from_environment(
    given: int | str | None = None, environ: dict[str, str] | None = None
) -> int | str:
    """The setting: ``given`` (a command-line option) when not None, else
    ``GTECAT_RT_PRIORITY``, else ``auto``; ValueError for an unreadable variable."""
    if given is not None:
        return given
    env = os.environ if environ is None else environ
    text = env.get(RT_ENV, "").strip()
    if not text:
        return "auto"
    try:
        return parse_priority(text)
    except ValueError as exc:
        raise ValueError(f"{RT_ENV}={exc}") from None


class WhenBusy:
    """A server thread that runs under SCHED_FIFO ``priority`` only while the CPUs are busy
    (more threads runnable than CPUs) and under its normal policy otherwise.

    Why: on an idle machine a normal server wakes on the CPU of the client that woke it (the
    kernel's affine wake-up) and both sides may spin for each other's next message, where a
    real-time one is woken on the CPU it last ran on, which in a virtual machine may have to
    be woken itself first (tens of microseconds); on a busy machine a normal server waits
    for other programs' time slices (milliseconds), a real-time one does not, and it must not
    spin (a real-time spin takes its CPU from everything else).  :meth:`busy` is called with
    each new look at the load; it switches only on a change (one system call)."""

    def __init__(
        self,
        priority: int,
        set_fifo: Callable[[int], None] = realtime_priority,
        set_normal: Callable[[tuple[int, int]], None] | None = None,
        normal: tuple[int, int] | None = None,
    ) -> None:
        self.priority = priority
        self._set_fifo = set_fifo
        self._set_normal = set_normal or _set_policy
        #: the policy and priority outside the busy times (SCHED_OTHER 0 unless given)
        self.normal = normal if normal is not None else (getattr(os, "SCHED_OTHER", 0), 0)
        self.realtime = False
        #: why SCHED_FIFO was refused, once it was (then never asked again)
        self.refused = ""
        self.switches = 0

    def busy(self, busy: bool) -> bool:
        """Run real-time if ``busy`` (where permitted); True while real-time."""
        if busy == self.realtime or (busy and self.refused):
            return self.realtime
        try:
            if busy:
                self._set_fifo(self.priority)
            else:
                self._set_normal(self.normal)
        except RealtimeRefused as exc:
            self.refused = str(exc)
            return self.realtime
        self.realtime = busy
        self.switches += 1
        return self.realtime


def _set_policy(policy_priority: tuple[int, int]) -> None:
    policy, prio = policy_priority
    try:
        os.sched_setscheduler(0, policy, os.sched_param(prio))
    except (OSError, AttributeError, ValueError) as exc:
        raise RealtimeRefused(f"cannot go back to policy {policy}: {exc}") from exc


#: the time slice (us) the controller's serving thread asks for, and libgts for each thread
#: of a program that calls it (GTECAT_SLICE_US; 100 is the shortest the kernel grants): 0,
#: none, by default.  Measured on a loaded 2-vCPU VM (docs/performance.md) a 100 us slice did
#: not help the round trip's p50 or p99, with or without the real-time priority
DEFAULT_SLICE_US = 0
SLICE_ENV = "GTECAT_SLICE_US"
#: (sched_setattr, sched_getattr) by machine: glibc before 2.41 has no wrapper
_SCHED_ATTR_CALLS = {
    "x86_64": (314, 315),
    "aarch64": (274, 275),
    "riscv64": (274, 275),
    "i686": (351, 352),
    "armv7l": (380, 381),
    "ppc64le": (355, 356),
    "s390x": (345, 346),
}
#: struct sched_attr, version 0 (48 bytes): size, policy, flags, nice, priority, runtime
#: (a SCHED_OTHER thread's slice, ns), deadline, period
_SCHED_ATTR = struct.Struct("=IIQiIQQQ")
_RESET_ON_FORK = 0x01
#: the calling thread's sched_attr fields (None where refused), and the call that sets them
#: (OSError where refused)
SliceCalls = tuple[Callable[[], tuple | None], Callable[[tuple], None]]


def _sched_attr_calls() -> SliceCalls | None:
    """sched_getattr and sched_setattr of the calling thread, None where the system has no
    such calls (not Linux, a machine not in :data:`_SCHED_ATTR_CALLS`)."""
    import ctypes
    import platform

    numbers = _SCHED_ATTR_CALLS.get(platform.machine())
    if not sys.platform.startswith("linux") or numbers is None:
        return None
    try:
        syscall = ctypes.CDLL(None, use_errno=True).syscall
    except (OSError, AttributeError):
        return None
    set_nr, get_nr = numbers

    def get() -> tuple | None:
        buf = ctypes.create_string_buffer(_SCHED_ATTR.size)
        if syscall(get_nr, 0, buf, _SCHED_ATTR.size, 0) != 0:
            return None
        return _SCHED_ATTR.unpack(buf.raw)

    def put(fields: tuple) -> None:
        buf = ctypes.create_string_buffer(_SCHED_ATTR.pack(*fields), _SCHED_ATTR.size)
        if syscall(set_nr, 0, buf, 0) != 0:
            err = ctypes.get_errno()
            raise OSError(err, os.strerror(err))

    return get, put


def short_slice(
    us: int, calls: SliceCalls | bool | None = None, *, reset_on_fork: bool = False
) -> str:
    """Ask the kernel for a time slice of ``us`` microseconds for the calling thread (its
    ``sched_attr.sched_runtime``; Linux 6.12 and later, no privilege needed); words for a
    status line, "" where nothing changed.

    Why: a thread that sleeps until a message wakes it (the controller between requests,
    a program waiting for its reply) and wakes while other programs keep the CPUs busy
    may wait for one of their time slices (milliseconds).  Under EEVDF a thread with a
    shorter slice gets an earlier deadline and, where it has not used more than its share
    of the CPU, preempts the longer-slice thread at once.  What it changes: how soon the
    thread gets a CPU after waking, and that a thread computing for long while others want
    its CPU is preempted more often; not its share (its nice value, its weight).

    Asked only of a SCHED_OTHER thread whose slice is longer (a shorter one chosen by the
    program is kept); its nice value and reset-on-fork flag stay (``reset_on_fork``: set it,
    so that threads and processes the thread starts get the default slice).  A kernel without custom
    slices reports none and is not asked; a refusal (EINVAL or E2BIG from an older kernel,
    EPERM from a sandbox) is not an error.  ``calls`` (sched_getattr, sched_setattr) are
    the system's unless given (tests; False: a system without them)."""
    if us <= 0:
        return ""
    found = _sched_attr_calls() if calls is None else calls
    if not found:
        return ""
    get, put = found  # type: ignore[misc]
    attr = get()
    if attr is None:
        return ""
    _size, policy, flags, nice, prio, runtime, _deadline, _period = attr
    if policy != getattr(os, "SCHED_OTHER", 0) or runtime <= us * 1000:
        return ""
    try:
        keep = flags & _RESET_ON_FORK | (_RESET_ON_FORK if reset_on_fork else 0)
        put((_SCHED_ATTR.size, policy, keep, nice, prio, us * 1000, 0, 0))
    except OSError:
        return ""
    return f"{us} us slice"


def slice_from_environment(environ: dict[str, str] | None = None) -> int:
    """GTECAT_SLICE_US in microseconds (0: none; the default where unset or unreadable)."""
    env = os.environ if environ is None else environ
    text = env.get(SLICE_ENV, "").strip()
    try:
        return max(0, int(text)) if text else DEFAULT_SLICE_US
    except ValueError:
        return DEFAULT_SLICE_US


def is_realtime() -> bool:
    """The calling thread runs under SCHED_FIFO or SCHED_RR."""
    try:
        policy = os.sched_getscheduler(0) & ~getattr(os, "SCHED_RESET_ON_FORK", 0)
        return policy in (os.SCHED_FIFO, os.SCHED_RR)
    except (AttributeError, OSError):
        return False


def snapshot() -> tuple[int, int, set[int]] | None:
    """This thread's policy, priority and CPUs (None where the system has no such calls)."""
    try:
        return (
            os.sched_getscheduler(0),
            os.sched_getparam(0).sched_priority,
            os.sched_getaffinity(0),
        )
    except (AttributeError, OSError):
        return None


def restore(before: tuple[int, int, set[int]] | None) -> None:
    """Give back what :func:`snapshot` saw."""
    if before is None:
        return
    policy, prio, cpus = before
    try:
        os.sched_setscheduler(0, policy, os.sched_param(prio))
        os.sched_setaffinity(0, cpus)
    except (AttributeError, OSError):
        pass


#: looks at the load (one every 10 ms) that must find the server on another CPU than its
#: client, while busy, before :class:`Beside` moves it to the client's CPU
BESIDE_AFTER = 2


class Beside:
    """Keeps a server on its client's CPU while the CPUs are busy, real-time or not.

    Why: a client waiting for its reply and the server answering it are one chain of work.
    On two CPUs each kept busy by another program, each side shares its CPU with one of
    them, and the client, a normal task, woken on a CPU where another program runs may wait
    for that program's time slice after every reply: measured on 2 CPUs with two busy
    programs, the sides on different CPUs gave p50 33 us (and p99 up to 2 ms) in every run,
    where on one CPU (the kernel then moves the other programs to the other CPU, as the
    server's real-time time counts there) they gave p50 18 us, p99 < 100 us.  The kernel
    leaves the sides where they are once a real-time server has its CPU, so the server
    moves itself: after :data:`BESIDE_AFTER` looks in a row that find it on another CPU
    than its client while busy, it takes the client's CPU as its only one
    (``sched_setaffinity``; it follows the client when the client moves); when the CPUs are
    no longer busy it takes its CPUs back.

    A server at normal priority (no right to real-time) is kept beside its client too.
    Apart, each side then shares a CPU with another program at an equal share; each call
    spends some of it (sleeping earns none back), so for a program that calls in a tight
    loop every few hundred calls a side is not woken ahead of the other program and waits
    for the scheduler's next tick (4 ms at 250 Hz).  Together, the pair asks for one CPU,
    which the kernel's balancing leaves to it more often than not; measured on 2 CPUs with
    two busy programs (docs/performance.md), loaded runs meeting the bar went from about
    four in ten to six.
    :meth:`look` gets the CPU numbers (the caller reads them), so the decision is tested
    with faked ones."""

    def __init__(
        self,
        cpus: set[int],
        set_affinity: Callable[[set[int]], None] | None = None,
        after: int = BESIDE_AFTER,
    ) -> None:
        #: the CPUs the server may use outside the busy times
        self.cpus = set(cpus)
        self._set = set_affinity or _set_affinity
        self.after = after
        self.apart = 0
        #: the CPUs taken now (None: :attr:`cpus`, untouched)
        self.current: set[int] | None = None
        self.moves = 0

    def look(self, busy: bool, own_cpu: int | None, client_cpu: int | None) -> set[int] | None:
        """One look at the load: returns the CPUs the server now runs on (None: its own)."""
        if not busy:
            self.apart = 0
            if self.current is not None and self._apply(self.cpus):
                self.current = None
            return self.current
        if own_cpu is None or client_cpu is None or own_cpu == client_cpu:
            self.apart = 0
            return self.current
        self.apart += 1
        if self.apart < self.after or client_cpu not in self.cpus:
            return self.current
        self.apart = 0
        if self._apply({client_cpu}):
            self.current = {client_cpu}
            self.moves += 1
        return self.current

    def _apply(self, cpus: set[int]) -> bool:
        try:
            self._set(cpus)
        except OSError:
            return False
        return True


def _set_affinity(cpus: set[int]) -> None:
    os.sched_setaffinity(0, cpus)


def thread_cpu(pid: int | str = "thread-self") -> int | None:
    """The CPU a process (its main thread; ``thread-self``: the calling thread) last ran on
    (/proc/PID/stat, field 39); None where it cannot be read."""
    try:
        with open(f"/proc/{pid}/stat", "rb") as f:
            stat = f.read()
        return int(stat[stat.rindex(b")") + 2 :].split()[36])
    except (OSError, ValueError, IndexError):
        return None


__all__ = [
    "AUTO_RT_PRIORITY",
    "AVAILABLE",
    "BESIDE_AFTER",
    "DEFAULT_SLICE_US",
    "NORMAL",
    "RT_ENV",
    "RT_SPIN_CAP_US",
    "SLICE_ENV",
    "Beside",
    "RealtimeRefused",
    "Scheduling",
    "WhenBusy",
    "from_environment",
    "is_realtime",
    "parse_priority",
    "realtime_priority",
    "restore",
    "short_slice",
    "slice_from_environment",
    "snapshot",
    "take",
    "thread_cpu",
]
