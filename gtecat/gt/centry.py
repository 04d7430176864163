"""A GT fast reader's entry in C: the common call shape without a Python frame of its own.

``GT_GetSts(1, byref(s))`` through the compiled Python fast function (:mod:`gtecat.gt.fast`)
spends about half its time checking the shape of its arguments and writing the value through
ctypes.  The entry here (``csrc/centry.c``) does those two parts in C: it checks the shape
(an exact ``int`` axis, ``count`` absent or 1, ``pClock`` absent, None or 0, the value's
pointer ``byref(x)`` of an accepted ``x`` with no offset, or ``x`` itself; a ctypes array, or
``byref`` of one with an offset too - C's ``&arr[k]`` - takes the values from there where they
fit before its end), asks one Python
function of the reader for the value (``value(n)``: the number, or a sentinel when the entry
must not answer - not the in-process lockstep controller, no such axis, any doubt), and
writes the number into ``x``'s memory with ``x``'s width (a number the type does not hold:
not written).  Every other case is the reader's Python fast function called with the very
same arguments, keywords included, so the answers stay that function's.

As :mod:`gtecat.gt.byref_target` (whose probe of the interpreter's layout this shares), the C
file uses no Python header: a float's value is found by probing floats, the C API's
functions are taken from the running interpreter, and the entry is tested against known
answers (every kind of shape it must hand on, the widths, reference counts) before use.  Any
disagreement, or no compiler: :data:`REASON` says why and :func:`reader` gives None (the
Python fast function is then the public one, as before).

``GTE_Wait`` has an entry of its own (:func:`wait`): a wait run in C on the quick cycle armed
for the readers' entries, its cycles in one call of the kernel and counted in C where the run
went whole (csrc/centry.c ``wait_call``).

Another thread.  On the lockstep and auto clocks a cycle runs in whichever thread lets
controller time pass (GTE_Wait, a call's host latency, a controller server's wall floor),
holding the controller's clock lock, as every call of the table path does.  The entries answer
without taking it, and the GIL alone does not make what they read whole: the interpreter hands
it over between any two bytecodes of the other thread's cycle (so a read could find half the
axes, half the slaves' inputs, of the next cycle), and the axis bank's compiled cycle runs with
the GIL let go.  So an entry answers from what it read only where no other thread held the
lock when it began and, where its value function (Python) ran, none held it afterwards and
the epoch did not grow meanwhile; else it takes the lock itself (waiting with the GIL let go)
and answers holding it, as the table path would (csrc/centry.c "Another thread and the
clock", :data:`CLOCK_LOCK`).  The copy or write that follows the last look runs no Python.
The common case costs one load of the lock's holder word.  Not covered: the Python fast
functions (the shapes an entry hands on, and every shape where no entry is built) read
without the lock as before, and the cycles a card runs for another card of one time
(``ClockGroup.share``) do not take that card's lock.
"""

from __future__ import annotations

import ctypes
import functools
import logging
import struct
import sys
import threading
import types
from array import array
from collections.abc import Callable, Iterable
from typing import Any

from ..controller.epoch import EPOCH, Epoch, changed
from ..master.clock import ARMS
from . import byref_target

log = logging.getLogger(__name__)

#: the epoch's own changed(): a raw writer given it makes the epoch grow in C (raw_entry.grow)
_grow_epoch = changed

_METH_FASTCALL_KEYWORDS = 0x0080 | 0x0002
_MAX_TYPES = 16
_VP = ctypes.c_void_p
_WORD = ctypes.sizeof(_VP)

#: :func:`raw`'s ``write`` for GT_EcatIOBitWriteOutput(slave, offset, bit, value): ``value``
#: gives the output byte's run, the entry sets or clears the bit in it (csrc/centry.c)
BIT_WRITE = 2


class _Api(ctypes.Structure):
    """``struct api`` of csrc/centry.c."""

    _fields_ = [
        ("carg_value", ctypes.c_ssize_t),
        ("carg_obj", ctypes.c_ssize_t),
        ("ob_type", ctypes.c_ssize_t),
        ("b_ptr", ctypes.c_ssize_t),
        ("fval", ctypes.c_ssize_t),
        ("bsize", ctypes.c_ssize_t),
        ("bdata", ctypes.c_ssize_t),
        ("bastart", ctypes.c_ssize_t),
        ("vc_entry", ctypes.c_ssize_t),
        ("b_objects", ctypes.c_ssize_t),
        ("carg_type", _VP),
        ("int_type", _VP),
        ("float_type", _VP),
        ("bytes_type", _VP),
        ("array_meta", _VP),
        ("bytearray_type", _VP),
        ("none", _VP),
        ("zero", _VP),
        ("one", _VP),
        ("dict_type", _VP),
        ("key_one", _VP),
        ("incref", _VP),
        ("decref", _VP),
        ("vectorcall", _VP),
        ("as_ll", _VP),
        ("err_occurred", _VP),
        ("err_clear", _VP),
        ("dict_get", _VP),
        ("gate", _VP),
        ("epoch_obj", _VP),
        ("epoch_off", ctypes.c_ssize_t),
        ("clock_quick", _VP),
        ("ndarray_type", _VP),
        ("nd_data", ctypes.c_ssize_t),
        ("nd_nd", ctypes.c_ssize_t),
        ("nd_dims", ctypes.c_ssize_t),
        ("nd_descr", ctypes.c_ssize_t),
        ("nd_flags", ctypes.c_ssize_t),
        ("nd_want", ctypes.c_int),
        ("clock_lock", _VP),
        ("owner_off", ctypes.c_ssize_t),
        ("thread_ident", _VP),
        ("lock_acquire", _VP),
        ("lock_release", _VP),
        ("err_fetch", _VP),
        ("err_restore", _VP),
        ("clock_calls", _VP),
        ("arms", _VP),
        ("marks_dict", _VP),
        ("key_al", _VP),
        ("key_out", _VP),
        ("get_buffer", _VP),
        ("release_buffer", _VP),
        ("memoryview_type", _VP),
        ("np_u8", _VP),
        ("clock_books", _VP),
        ("long_from", _VP),
        ("dict_new", _VP),
        ("dict_set", _VP),
        ("tuple_pack", _VP),
        ("key_lists", _VP),
        ("key_seen", _VP),
        ("b_size", ctypes.c_ssize_t),
        ("bytes_new", _VP),
        ("float_new", _VP),
        ("simple_meta", _VP),
        ("struct_meta", _VP),
        ("union_meta", _VP),
        ("pointer_meta", _VP),
        ("voidp_type", _VP),
        ("charp_type", _VP),
        ("wcharp_type", _VP),
        ("tuple_items", ctypes.c_ssize_t),
    ]


class _Recipe(ctypes.Structure):
    """``struct recipe`` of csrc/centry.c: where a value's doubles come from."""

    _fields_ = [
        ("src", _VP),
        ("idx", _VP),
        ("rows", _VP),
        ("ratios", _VP),
        ("op", ctypes.c_longlong),
        ("t", ctypes.c_double),
    ]


class _Slot(ctypes.Structure):
    """``struct slot`` of csrc/centry.c: a value kept for the epoch it was asked in."""

    _fields_ = [
        ("epoch", ctypes.c_longlong),
        ("value", _VP),
        ("booked", ctypes.c_longlong),
        ("holds", ctypes.c_longlong),
        ("keeps", ctypes.c_longlong),
        ("rc", _Recipe),
    ]


class _ASlot(ctypes.Structure):
    """``struct aslot`` of csrc/centry.c: a span's bytes kept for their key and epoch."""

    _fields_ = [
        ("epoch", ctypes.c_longlong),
        ("n", ctypes.c_longlong),
        ("count", ctypes.c_longlong),
        ("clock", ctypes.c_longlong),
        ("tp", _VP),
        ("value", _VP),
        ("holds", ctypes.c_longlong),
        ("keeps", ctypes.c_longlong),
        ("rc", _Recipe),
        ("booked", ctypes.c_longlong),
    ]


class _Entry(ctypes.Structure):
    """``struct entry`` of csrc/centry.c: one reader's entry (the C function's self)."""

    _fields_ = [
        ("fallback", _VP),
        ("value", _VP),
        ("sentinel", _VP),
        ("core", ctypes.c_ssize_t),
        ("kind", ctypes.c_ssize_t),
        ("most", ctypes.c_ssize_t),
        ("types", _VP * _MAX_TYPES),
        ("sizes", ctypes.c_ssize_t * _MAX_TYPES),
        ("signs", ctypes.c_ssize_t * _MAX_TYPES),
        ("derefs", ctypes.c_ssize_t * _MAX_TYPES),
        ("noaxis", ctypes.c_ssize_t),
        ("avalue", _VP),
        ("gate", ctypes.c_ssize_t),
        ("after", _VP),
        ("cache", ctypes.POINTER(_Slot)),
        ("ncache", ctypes.c_ssize_t),
        ("ctypes_", _VP * _MAX_TYPES),
        ("csizes", ctypes.c_ssize_t * _MAX_TYPES),
        ("csigns", ctypes.c_ssize_t * _MAX_TYPES),
        ("acache", ctypes.POINTER(_ASlot)),
        ("nptypes", _VP * 8),
        ("npsizes", ctypes.c_ssize_t * 8),
        ("npsigns", ctypes.c_ssize_t * 8),
        ("stride", ctypes.c_ssize_t),
        ("tuple_type", _VP),
        ("titems", ctypes.c_ssize_t),
        ("cderefs", ctypes.c_ssize_t * _MAX_TYPES),
        ("steady", ctypes.c_ssize_t),
        ("nacache", ctypes.c_ssize_t),
        ("viewer", _VP),
        ("session", _VP),
        ("key_last", _VP),
    ]


class _RawEntry(ctypes.Structure):
    """``struct raw_entry`` of csrc/centry.c: a raw image function's entry."""

    _fields_ = [
        ("fallback", _VP),
        ("value", _VP),
        ("sentinel", _VP),
        ("io", ctypes.c_ssize_t),
        ("write", ctypes.c_ssize_t),
        ("gate", ctypes.c_ssize_t),
        ("after", _VP),
        ("cache", ctypes.POINTER(_ASlot)),
        ("changed", _VP),
        ("ncache", ctypes.c_ssize_t),
        ("grow", ctypes.c_ssize_t),
    ]


_MAX_OUT, _MAX_OTYPES = 3, 8


class _MultiEntry(ctypes.Structure):
    """``struct multi_entry`` of csrc/centry.c: a reader of several values."""

    _fields_ = [
        ("fallback", _VP),
        ("value", _VP),
        ("sentinel", _VP),
        ("nout", ctypes.c_ssize_t),
        ("nextra", ctypes.c_ssize_t),
        ("extra", ctypes.c_ssize_t * 3),
        ("types", (_VP * _MAX_OTYPES) * _MAX_OUT),
        ("sizes", (ctypes.c_ssize_t * _MAX_OTYPES) * _MAX_OUT),
        ("signs", (ctypes.c_ssize_t * _MAX_OTYPES) * _MAX_OUT),
        ("kinds", ctypes.c_ssize_t * _MAX_OUT),
        ("gate", ctypes.c_ssize_t),
        ("after", _VP),
        ("cache", ctypes.POINTER(_Slot)),
        ("ncache", ctypes.c_ssize_t),
        ("titems", ctypes.c_ssize_t),
        ("tuple_type", _VP),
    ]


class _WaitEntry(ctypes.Structure):
    """``struct wait_entry`` of csrc/centry.c: GTE_Wait's entry."""

    _fields_ = [
        ("fallback", _VP),
        ("after", _VP),
        ("rest", _VP),
        ("session", _VP),
        ("key_last", _VP),
        ("key_note", _VP),
        ("most", ctypes.c_longlong),
        ("batch", ctypes.c_longlong),
        ("maxc", ctypes.c_longlong),
        ("at", _VP),
    ]


_R_MAX = 6


class _RPut(ctypes.Structure):
    """``struct rput`` of csrc/centry.c: a value a replayed call sets or leaves."""

    _fields_ = [("mem", _VP), ("kind", ctypes.c_longlong), ("k", ctypes.c_longlong)]


class _Runner(ctypes.Structure):
    """``struct runner`` of csrc/centry.c: one recorded call's form, made by the replay's loop."""

    _fields_ = [
        ("fn", _VP),
        ("args", _VP),
        ("rc", _VP),
        ("python", ctypes.c_longlong),
        ("nsets", ctypes.c_longlong),
        ("nouts", ctypes.c_longlong),
        ("sets", _RPut * _R_MAX),
        ("outs", _RPut * _R_MAX),
    ]


class _RTable(ctypes.Structure):
    """``struct rtable`` of csrc/centry.c: the replay loop's calls (the C function's self)."""

    _fields_ = [
        ("mask", ctypes.c_longlong),
        ("keys", ctypes.POINTER(_VP)),
        ("runners", ctypes.POINTER(_VP)),
        ("titems", ctypes.c_ssize_t),
        ("tuple_type", _VP),
    ]


#: what an argument after a multi-value reader's outputs must be: the int 1 (a count), the
#: int 0 (a FIFO, a mode), None or the int 0 (a NULL pointer)
ONE, ZERO, NULL = 1, 0, 2


#: the session's gates, read by every gated entry before it asks its value (written by
#: :mod:`gtecat.gt._core` wherever their answer can change: :func:`set_gates`):
#: [0] nonzero while the GT_ functions address an in-process controller of core 1 on the
#: lockstep (:data:`LOCKSTEP`) or the auto clock (:data:`AUTO`: an entry's ``after`` runs
#: the call's host latency once the value is written), [1] while the GTN_ functions' core 1
#: is such a controller, [2] nonzero while its cores 2.. are views of its bus (no core of
#: their own: gtecat.controller.core_view), which the readers then answer for core 1 by the
#: bus axis's number
GATES = (ctypes.c_ssize_t * 3)()
#: an entry's gate: none, the GT_ functions', the GTN_ functions'
NO_GATE, GT_GATE, GTN_GATE = 0, 1, 2
#: an open gate's value: its controller's clock
CLOSED, LOCKSTEP, AUTO = 0, 1, 2


def set_gates(gt: int, gtn: int, views: bool = False) -> None:
    """Open (:data:`LOCKSTEP`, :data:`AUTO`) or close (:data:`CLOSED`) the two gates
    (:data:`GATES`), and say whether the GTN_ functions' cores 2.. are views of core 1's bus
    (only where the GTN_ gate is open); what the entries kept was another session's."""
    GATES[0], GATES[1] = int(gt), int(gtn)
    GATES[2] = int(bool(gtn) and views)
    EPOCH.n += 1


#: per gate, where its controller's clock keeps the numbers of a call's host latency
#: (``Clock.quick``) where the gate says :data:`AUTO` (0: none): an entry adds the call's
#: latency there itself where that runs no cycle (gtecat.gt._core.advance's first branch),
#: else calls its ``after``
CLOCK_QUICK = (ctypes.c_ssize_t * 2)()
_CLOCKS: list[Any] = [None, None]  # (their arrays, kept alive while named)


#: per gate, its controller's ``book(after, rc)`` for the armed quick cycle (0: none): what
#: follows the kernel's cycle an entry ran (gtecat.controller.core.Controller.arm_quick;
#: gtecat.gt.fast._quick_calls)
CLOCK_CALLS = (ctypes.c_ssize_t * 2)()
_CALLS: list[Any] = [None, None]  # (kept alive while named)
#: per gate, its controller's book of the armed quick cycle in C (0: none): the int64 array
#: gtecat.controller.core.Controller._book_in_c fills (where it says so, the entry that ran
#: the cycle counts it itself instead of calling the book of CLOCK_CALLS)
CLOCK_BOOKS = (ctypes.c_ssize_t * 2)()
_BOOKS: list[Any] = [None, None]  # (kept alive while named)
#: how many numbers a clock's quick array holds (gtecat.master.clock.Clock.quick)
QUICK_LEN = 12
#: how many numbers a controller's book in C holds (Controller.quick_cbook)
BOOK_LEN = 16
#: the names the book in C sets in the bank's and the controller's own dicts (kept alive)
_KEY_LISTS, _KEY_SEEN = sys.intern("_lists"), sys.intern("_steady_seen")
#: the names of the slaves' marks, as the C entries look them up
_KEY_AL, _KEY_OUT = "al_changes", "outside_changes"


def set_clocks(
    gt: Any,
    gtn: Any,
    calls: tuple[Any, Any] = (None, None),
    books: tuple[Any, Any] = (None, None),
) -> None:
    """The clocks behind the two gates (:data:`CLOCK_QUICK`; None: none), and per gate the
    book of its armed quick cycle (:data:`CLOCK_CALLS`; None: none) and that book in C
    (:data:`CLOCK_BOOKS`: an int64 array of :data:`BOOK_LEN`; None: none), set while the
    gates are closed."""
    for k, clock in enumerate((gt, gtn)):
        q = getattr(clock, "quick", None)
        if not (isinstance(q, array) and q.typecode == "q" and len(q) == QUICK_LEN):
            q = None
        _CLOCKS[k] = q
        CLOCK_QUICK[k] = 0 if q is None else q.buffer_info()[0]
        book = calls[k] if q is not None else None
        _CALLS[k] = book
        CLOCK_CALLS[k] = 0 if book is None else id(book)
        cb = books[k] if book is not None else None
        if not (isinstance(cb, array) and cb.typecode == "q" and len(cb) == BOOK_LEN):
            cb = None
        _BOOKS[k] = cb
        CLOCK_BOOKS[k] = 0 if cb is None else cb.buffer_info()[0]


#: the GT_ gate's controller for GTE_Wait's entry (csrc/centry.c wait_call): [0] its
#: clock's quick numbers, [1] its armed quick cycle's book in C (Controller.quick_cbook), on
#: the lockstep and the auto clock alike; 0: the entry waits nowhere (:func:`set_wait`)
WAIT_AT = (ctypes.c_ssize_t * 2)()
_WAIT_KEPT: list[Any] = [None]  # (their arrays, kept alive while named)


def set_wait(ctl: Any) -> None:
    """The controller behind the GT_ gate for GTE_Wait's entry (:data:`WAIT_AT`; None:
    none: an EtherCAT master's only), set while the gates are closed."""
    q = getattr(getattr(ctl, "clock", None), "quick", None)
    b = getattr(ctl, "quick_cbook", None)
    ok = (
        ctl is not None
        and getattr(ctl, "card", None) is None
        and all(
            isinstance(a, array) and a.typecode == "q" and len(a) == n
            for a, n in ((q, QUICK_LEN), (b, BOOK_LEN))
        )
    )
    WAIT_AT[0] = WAIT_AT[1] = 0
    _WAIT_KEPT[0] = (q, b) if ok else None
    if ok:
        WAIT_AT[0], WAIT_AT[1] = q.buffer_info()[0], b.buffer_info()[0]  # type: ignore[union-attr]


def _marks_dict() -> dict:
    """VirtualSlave's own dict, where its class counts the slaves' AL and outside changes
    (ValueError where the marks are not found there)."""
    import gc

    from gtecat.drives.slave import VirtualSlave

    found = [d for d in gc.get_referents(VirtualSlave.__dict__) if type(d) is dict]
    if len(found) != 1 or any(
        found[0].get(key) is not getattr(VirtualSlave, key) for key in (_KEY_AL, _KEY_OUT)
    ):
        raise ValueError("the slaves' marks are not where they are looked for")
    return found[0]


#: per gate, where its controller's clock value (GT_GetClock's: the milliseconds since
#: GT_Reset) is made from: the address of the controller's time in ns (``Clock.now_ns``)
#: and of the time GT_Reset counted from (``Controller.reset_ns``), both int64 (0: none):
#: a reader's entry writes its ``pClock`` from them (csrc/centry.c clock_ms)
CLOCK_MS = (ctypes.c_ssize_t * 4)()
_ORIGINS: list[Any] = [None, None]  # (their arrays, kept alive while named)

#: the quick cycles' timer (csrc/centry.c cycle_timer): [0] nonzero while on, [1] the
#: nanoseconds the quick cycles the entries ran took (the kernel's cycle and its book), [2]
#: how many; for a benchmark that tells a call's own cost from the controller's cycles its
#: host latency runs inside it (tools/bench.py); off, it costs a cycle one load
CYCLE_TIMER = (ctypes.c_longlong * 3)()
#: whether the entries time their quick cycles when :data:`CYCLE_TIMER` is on (a monotonic
#: clock known to the C file)
CYCLE_TIMED = False


def set_clock_ms(gt: Any, gtn: Any) -> None:
    """The controllers behind the two gates, for their clock values (:data:`CLOCK_MS`;
    None: none), set while the gates are closed."""
    for k, ctl in enumerate((gt, gtn)):
        q = getattr(getattr(ctl, "clock", None), "quick", None)
        origin = getattr(ctl, "origin", None)
        ok = all(
            isinstance(a, array) and a.typecode == "q" and len(a) == n
            for a, n in ((q, QUICK_LEN), (origin, 1))
        )
        _ORIGINS[k] = (q, origin) if ok else None
        # (now_ns: [9]; the cycles run, GT_GetClock's pLoop, the word after it: [10])
        CLOCK_MS[2 * k] = q.buffer_info()[0] + 9 * q.itemsize if ok else 0
        CLOCK_MS[2 * k + 1] = origin.buffer_info()[0] if ok else 0


#: per gate, its controller's clock lock (``Clock.lock``, a ``threading.RLock``) and that
#: lock's bound ``acquire`` and ``release`` (0: none): an entry that finds the lock held by
#: another thread answers holding it itself (csrc/centry.c "Another thread and the clock")
CLOCK_LOCK = (ctypes.c_ssize_t * 2)()
LOCK_ACQUIRE = (ctypes.c_ssize_t * 2)()
LOCK_RELEASE = (ctypes.c_ssize_t * 2)()
_LOCKS: list[Any] = [None, None]  # (the locks and their methods, kept alive while named)


def set_locks(gt: Any, gtn: Any) -> None:
    """The clocks behind the two gates, for their locks (None: none), set while the gates are
    closed.  An entry that holds a lock keeps its own reference to its release (centry.c's
    hold): the gates may change meanwhile."""
    for k, clock in enumerate((gt, gtn)):
        lock = getattr(clock, "lock", None)
        if type(lock) is not _RLOCK:
            lock = None
        kept = None if lock is None else (lock, lock.acquire, lock.release)
        _LOCKS[k] = kept
        CLOCK_LOCK[k] = 0 if kept is None else id(kept[0])
        LOCK_ACQUIRE[k] = 0 if kept is None else id(kept[1])
        LOCK_RELEASE[k] = 0 if kept is None else id(kept[2])


_RLOCK = type(threading.RLock())


def _owner_at() -> int:
    """Where a ``threading.RLock`` keeps the ident of the thread that holds it, 0 while
    nobody does (ValueError when the probe disagrees): held once and twice here, then by
    another thread, and let go."""
    lock = threading.RLock()
    if type(lock) is not _RLOCK or _RLOCK.__module__ != "_thread":
        raise ValueError("threading.RLock is not the interpreter's lock")
    words = range(_HEAD, _RLOCK.__basicsize__ - ctypes.sizeof(ctypes.c_ulong) + 1, _WORD)

    def seen() -> list[int]:
        return [ctypes.c_ulong.from_address(id(lock) + k).value for k in words]

    me = threading.get_ident()
    looks: list[tuple[int, list[int]]] = [(0, seen())]
    with lock:
        looks.append((me, seen()))
        with lock:
            looks.append((me, seen()))
    looks.append((0, seen()))

    def other() -> None:
        with lock:
            looks.append((threading.get_ident(), seen()))

    t = threading.Thread(target=other, name="gtecat-probe")
    t.start()
    t.join()
    looks.append((0, seen()))
    if len({who for who, _ in looks}) != 3:
        raise ValueError("no other thread to probe a lock's holder with")
    for i, k in enumerate(words):
        if all(got[i] == who for who, got in looks):
            return k
    raise ValueError("a lock's holder is not where it is looked for")


def _epoch_at() -> int:
    """Where an :class:`Epoch` keeps ``n`` (ValueError when the probe disagrees)."""
    probe = Epoch()
    marks = [1 << 90, 1 << 91]
    for k in range(_HEAD, sys.getsizeof(probe) - _WORD + 1, _WORD):
        for m in marks:
            probe.n = m
            if _VP.from_address(id(probe) + k).value != id(m):
                break
        else:
            return k
    raise ValueError("an epoch's number is not where it is looked for")


#: the axes (or other first arguments) below this have a value kept per entry
CACHED = 257
#: the spans of an array reader kept at once, each with where its bytes come from (a
#: program that reads two spans in turn finds both after the cycles booked in C)
SPAN_LANES = 4


#: what an entry writes: integers (of each type's width and sign), doubles, or the bytes of
#: a structure (``value(n)`` gives them, as many as the entry's size)
INT, DOUBLE, BYTES = 0, 1, 2


def _float_at() -> int:
    """Where a float keeps its value (ValueError when the probe disagrees)."""
    at = object.__basicsize__
    for x in (1.5, -2.25e300, 0.0, float("inf"), 3.0):
        if ctypes.c_double.from_address(id(x) + at).value != x:
            raise ValueError("a float's value is not where it is looked for")
    return at


def _objects_at() -> int:
    """Where a ctypes object keeps the objects it keeps alive (``_objects``: ``pointer(x)``'s
    ``{'1': x}``; ValueError when the probe disagrees)."""
    xs = [ctypes.c_long(3), ctypes.c_double(2.5), ctypes.c_short(1)]
    ps = [ctypes.pointer(x) for x in xs]
    ps.append(ctypes.cast(ps[0], ctypes.POINTER(ctypes.c_int)))  # ({id: object})
    for k in range(_HEAD, sys.getsizeof(ps[0]) - _WORD + 1, _WORD):
        if all(_VP.from_address(id(p) + k).value == id(p._objects) for p in ps):
            if all(p._objects["1"] is x for p, x in zip(ps, xs, strict=False)):
                return k
    raise ValueError("a ctypes object's kept objects are not where they are looked for")


def _size_at() -> int:
    """Where a ctypes object keeps its size in bytes (what ``ctypes.sizeof`` gives for the
    object: a resized one's too; ValueError when the probe disagrees)."""
    xs = [
        ctypes.c_long(3),
        ctypes.c_short(1),
        (ctypes.c_double * 12)(),
        (ctypes.c_ubyte * 3)(),
        (ctypes.c_short * 5).from_buffer(bytearray(16), 2),
    ]
    grown = (ctypes.c_long * 2)()
    ctypes.resize(grown, 40)
    xs.append(grown)
    for k in range(_HEAD, sys.getsizeof(xs[0]) - _WORD + 1, _WORD):
        if all(ctypes.c_ssize_t.from_address(id(x) + k).value == ctypes.sizeof(x) for x in xs):
            return k
    raise ValueError("a ctypes object's size is not where it is looked for")


def _bytes_at() -> tuple[int, int]:
    """Where a bytes object keeps its length and its first byte (ValueError when the probe
    disagrees)."""
    at = object.__basicsize__  # (a variable-size object's length follows its head)
    samples = [bytes(range(3, 12)) * 3, b"\x07" * 5, bytes(range(40))]
    for b in samples:
        if ctypes.c_ssize_t.from_address(id(b) + at).value != len(b):
            raise ValueError("a bytes object's length is not where it is looked for")
    for k in range(at + _WORD, bytes.__basicsize__ + 1):
        if all(ctypes.string_at(id(b) + k, len(b)) == b for b in samples):
            return at, k
    raise ValueError("a bytes object's bytes are not where they are looked for")


#: numpy's array flags an entry's array must have: C_CONTIGUOUS, ALIGNED, WRITEABLE (numpy's
#: public ndarraytypes.h values; the probe checks them on arrays that have and lack each)
_ND_WANT = 0x0001 | 0x0100 | 0x0400


def _numpy_at() -> tuple[int, int, int, int, int, int]:
    """numpy's ndarray type and where an array keeps its data, its number of dimensions, its
    dimensions, its dtype and its flags ((0, ...): no numpy; ValueError when the probe
    disagrees).  The public ``PyArrayObject_fields`` layout, checked on known arrays."""
    try:
        import numpy as np
    except ImportError:
        return 0, 0, 0, 0, 0, 0
    samples = [np.zeros(3, np.int32), np.arange(6.0).reshape(2, 3), np.ones(1, np.int64)[::1]]
    ro = np.zeros(2, np.int64)
    ro.flags.writeable = False
    strided = np.zeros(8, np.int32)[::2]
    at = object.__basicsize__

    def ok(k_data: int, k_nd: int, k_dims: int, k_descr: int, k_flags: int) -> bool:
        for a in [*samples, ro, strided]:
            if _VP.from_address(id(a) + k_data).value != a.ctypes.data:
                return False
            if ctypes.c_int.from_address(id(a) + k_nd).value != a.ndim:
                return False
            dims = _VP.from_address(id(a) + k_dims).value
            if not dims or list((ctypes.c_ssize_t * a.ndim).from_address(dims)) != list(a.shape):
                return False
            if _VP.from_address(id(a) + k_descr).value != id(a.dtype):
                return False
            f = ctypes.c_int.from_address(id(a) + k_flags).value
            want = (
                bool(f & 0x0001) == a.flags.c_contiguous
                and bool(f & 0x0100) == a.flags.aligned
                and bool(f & 0x0400) == a.flags.writeable
            )
            if not want:
                return False
        return True

    # (PyArrayObject_fields: data, nd, dimensions, strides, base, descr, flags)
    k = (at, at + _WORD, at + 2 * _WORD, at + 5 * _WORD, at + 6 * _WORD)
    if not ok(*k):
        raise ValueError("a numpy array's fields are not where they are looked for")
    return (id(np.ndarray), *k)


def _np_u8() -> int:
    """numpy's uint8 dtype (the one object every array of bytes holds; 0: no numpy): a raw
    entry copies into or out of such an array (csrc/centry.c raw_mem)."""
    try:
        import numpy as np
    except ImportError:
        return 0
    return id(np.dtype(np.uint8))


def _tuple_at(size_at: int) -> int:
    """Where a tuple keeps its first item (its length where a bytes object's is;
    ValueError when the probe disagrees)."""
    samples = [(object(), 2.5), (1 << 80, "x", None), tuple(range(300, 305))]
    for t in samples:
        if ctypes.c_ssize_t.from_address(id(t) + size_at).value != len(t):
            raise ValueError("a tuple's length is not where it is looked for")
    for k in range(size_at + _WORD, tuple.__basicsize__ + 1, _WORD):
        if all(
            all(_VP.from_address(id(t) + k + i * _WORD).value == id(x) for i, x in enumerate(t))
            for t in samples
        ):
            return k
    raise ValueError("a tuple's items are not where they are looked for")


def _bytearray_at(size_at: int) -> int:
    """Where a bytearray keeps the address of its first byte (its length where a bytes
    object's is; ValueError when the probe disagrees)."""
    samples = [bytearray(b"abcdefgh" * 3), bytearray(40), bytearray(b"0123456789")]
    del samples[2][:3]  # (a bytearray whose first byte is not its allocation's)
    firsts = [ctypes.addressof((ctypes.c_char * len(b)).from_buffer(b)) for b in samples]
    for b in samples:
        if ctypes.c_ssize_t.from_address(id(b) + size_at).value != len(b):
            raise ValueError("a bytearray's length is not where it is looked for")
    for k in range(size_at + _WORD, bytearray.__basicsize__, _WORD):
        if all(
            _VP.from_address(id(b) + k).value == a for b, a in zip(samples, firsts, strict=True)
        ):
            return k
    raise ValueError("a bytearray's bytes are not where they are looked for")


_HEAD = object.__basicsize__  # (PyObject_HEAD)


class _MemberDef(ctypes.Structure):
    """CPython's ``PyMemberDef`` (stable ABI)."""

    _fields_ = [
        ("name", ctypes.c_char_p),
        ("type", ctypes.c_int),
        ("offset", ctypes.c_ssize_t),
        ("flags", ctypes.c_int),
        ("doc", ctypes.c_char_p),
    ]


class _GetSetDef(ctypes.Structure):
    """CPython's ``PyGetSetDef`` (stable ABI)."""

    _fields_ = [
        ("name", ctypes.c_char_p),
        ("get", _VP),
        ("set", _VP),
        ("doc", ctypes.c_char_p),
        ("closure", _VP),
    ]


class _TypeSlot(ctypes.Structure):
    """CPython's ``PyType_Slot`` (stable ABI)."""

    _fields_ = [("slot", ctypes.c_int), ("pfunc", _VP)]


class _TypeSpec(ctypes.Structure):
    """CPython's ``PyType_Spec`` (stable ABI)."""

    _fields_ = [
        ("name", ctypes.c_char_p),
        ("basicsize", ctypes.c_int),
        ("itemsize", ctypes.c_int),
        ("flags", ctypes.c_uint),
        ("slots", ctypes.POINTER(_TypeSlot)),
    ]


def _pointer_types_of_ctypes() -> None:
    """A pointer type ctypes made first for this module's code (its probes, its entries)
    says it is ctypes': its repr would otherwise name this module in every ``pointer(x)``
    of the user's."""
    for p in list(ctypes._pointer_type_cache.values()):  # type: ignore[attr-defined]
        if getattr(p, "__module__", None) == __name__:
            p.__module__ = "ctypes"


def by_name(name: str) -> Any:
    """The public GT function ``name`` (how a pickled or copied one comes back: itself)."""
    from .. import gt

    return getattr(gt, name)


def _bound(self: Any, obj: Any, cls: Any = None) -> Any:
    """A function's ``__get__``: itself from a class, a bound method from an instance."""
    return self if obj is None else types.MethodType(self, obj)


def _callable_type() -> type:
    """A type whose instances are called the way built-in functions are (vectorcall: the
    C function whose address an instance holds right after its head, the entry's address
    after that) and take attributes (an instance dict after those two words).  Made with
    ``PyType_FromSpec`` (stable ABI; the slot and flag numbers are the ABI's own): the
    ``__vectorcalloffset__`` and ``__dictoffset__`` members, ``__dict__`` the interpreter's
    generic one, ``tp_call`` the interpreter's ``PyVectorcall_Call``; after the weak-reference
    list the tuple of the function's parameter names (:func:`keyword_names`)."""
    T_PYSSIZET, READONLY = 19, 1
    Py_tp_call, Py_tp_members, Py_tp_getset = 50, 72, 73
    HAVE_VECTORCALL, DEFAULT = 1 << 11, 1 << 18
    members = (_MemberDef * 4)(
        _MemberDef(b"__vectorcalloffset__", T_PYSSIZET, _HEAD, READONLY, None),
        _MemberDef(b"__dictoffset__", T_PYSSIZET, _HEAD + 2 * _WORD, READONLY, None),
        _MemberDef(b"__weaklistoffset__", T_PYSSIZET, _HEAD + 3 * _WORD, READONLY, None),
    )
    getset = (_GetSetDef * 2)(
        _GetSetDef(
            b"__dict__",
            _address("PyObject_GenericGetDict"),
            _address("PyObject_GenericSetDict"),
            None,
            None,
        )
    )
    slots = (_TypeSlot * 4)(
        _TypeSlot(Py_tp_call, _address("PyVectorcall_Call")),
        _TypeSlot(Py_tp_members, ctypes.addressof(members)),
        _TypeSlot(Py_tp_getset, ctypes.addressof(getset)),
    )
    spec = _TypeSpec(
        b"gtecat.gt.centry.entry", _HEAD + 5 * _WORD, 0, HAVE_VECTORCALL | DEFAULT, slots
    )
    make = ctypes.PYFUNCTYPE(ctypes.py_object, _VP)(("PyType_FromSpec", ctypes.pythonapi))
    t = make(ctypes.addressof(spec))
    _KEEP.append((members, getset, slots, spec, t))
    t.__repr__ = lambda self: f"<GT function {getattr(self, '__name__', '?')} (C entry)>"
    # what a Python function does besides being called: pickled, copied and deep-copied as
    # itself by its name (as a function is), bound as a method where a class holds it (so
    # inspect.isroutine and pydoc take it for the function it is), weakly referenced
    t.__reduce__ = lambda self: (by_name, (self.__name__,))
    t.__get__ = _bound
    probe = t()
    probe.attribute = 1  # (an instance dict)
    if vars(probe) != {"attribute": 1}:
        raise ValueError("an entry callable keeps no attributes")
    return t  # type: ignore[no-any-return]


def keyword_names(public: Any, names: Iterable[str]) -> bool:
    """Let the C entry ``public`` answer a call that names its arguments as the table does
    (``GT_GetSts(axis=1, pSts=byref(s))``): ``names`` its parameters in order, interned (a
    call site's keyword names are); a keyword call whose names are the parameters after its
    positional arguments, in their order, is then answered as that positional call
    (csrc/centry.c ``positional``).  False where ``public`` is not an entry callable (a
    ``functools.partial``: its keyword calls go the Python way, as before)."""
    if not callables_made or type(public) is not callables_made[0]:
        return False
    kept = tuple(sys.intern(n) for n in names)
    _KEEP.append(kept)
    ctypes.c_void_p.from_address(id(public) + _HEAD + 4 * _WORD).value = id(kept)
    return True


#: the entry callable type made (:func:`_callable_type`; none: the entries are partials)
callables_made: list[type] = []


def _address(name: str) -> int:
    return ctypes.cast(getattr(ctypes.pythonapi, name), _VP).value or 0


#: why the entries are ``functools.partial`` objects rather than objects of the entry type
#: ('' where they are not: :func:`_load`)
PARTIALS = ""
#: the key under which ``pointer(x)`` keeps ``x`` (the C entry looks it up; kept alive here)
_KEY_ONE = "1"
#: the entries made (kept alive: their C functions point at them)
_KEEP: list[Any] = []
#: (the reader maker, why it is not available)
Maker = Callable[..., Any]


def _type_table(ids: Any, sizes: Any, signs: Any, types: Iterable[type], kind: int) -> tuple:
    """An entry's NULL-ended table of ctypes types (csrc/centry.c's find_type): each type,
    its size and its sign (an unsigned integer's 0); the types, kept alive with the entry."""
    ts = tuple(types)
    if len(ts) >= len(ids):
        raise ValueError(f"at most {len(ids) - 1} types")
    for k, t in enumerate(ts):
        ids[k], sizes[k] = id(t), ctypes.sizeof(t)
        signs[k] = int(kind != INT or not t._type_.isupper())
    return ts


def _slots(e: Any) -> Any:
    """The memory an entry keeps its values in per axis (:data:`CACHED` slots), given to
    it; kept alive with the entry."""
    slots = (_Slot * CACHED)()
    e.cache = ctypes.cast(slots, ctypes.POINTER(_Slot))
    e.ncache = CACHED
    return slots


def _load() -> tuple[Maker | None, str]:
    if sys.implementation.name != "cpython":
        return None, "not CPython"
    gil = getattr(sys, "_is_gil_enabled", None)
    if gil is not None and not gil():
        # (an entry's reads and writes are whole against other threads only under the GIL:
        # the module docstring, "Another thread")
        return None, "the interpreter runs without a GIL"
    try:
        carg_value, carg_obj, ob_type, b_ptr = byref_target.layout()
        fval = _float_at()
        bsize, bdata = _bytes_at()
        bastart = _bytearray_at(bsize)
        objects_at = _objects_at()
        size_at = _size_at()
        epoch_at = _epoch_at()
        owner_at = _owner_at()
        titems = _tuple_at(bsize)
        numpy_at = _numpy_at()
        marks = _marks_dict()
    except Exception as e:  # (a probe that disagrees, or cannot read what it probes)
        return None, str(e)
    try:
        from ..cbuild import c_source, shared_library

        source = c_source("gtecat.gt", "centry")
        lib = ctypes.CDLL(str(shared_library("centry", source, byref_target.CFLAGS, ())))
        api = _Api(
            carg_value,
            carg_obj,
            ob_type,
            b_ptr,
            fval,
            bsize,
            bdata,
            bastart,
            _HEAD + _WORD,  # (an entry callable's layout: _callable_type)
            objects_at,
            id(type(ctypes.byref(ctypes.c_int()))),
            id(int),
            id(float),
            id(bytes),
            id(type(ctypes.Array)),
            id(bytearray),
            id(None),
            id(0),
            id(1),
            id(dict),
            id(_KEY_ONE),
            _address("Py_IncRef"),
            _address("Py_DecRef"),
            _address("PyObject_Vectorcall"),
            _address("PyLong_AsLongLongAndOverflow"),
            _address("PyErr_Occurred"),
            _address("PyErr_Clear"),
            _address("PyDict_GetItem"),
            ctypes.addressof(GATES),
            id(EPOCH),
            epoch_at,
            ctypes.addressof(CLOCK_QUICK),
            *numpy_at,
            _ND_WANT,
            ctypes.addressof(CLOCK_LOCK),
            owner_at,
            _address("PyThread_get_thread_ident"),
            ctypes.addressof(LOCK_ACQUIRE),
            ctypes.addressof(LOCK_RELEASE),
            _address("PyErr_Fetch"),
            _address("PyErr_Restore"),
            ctypes.addressof(CLOCK_CALLS),
            ARMS.buffer_info()[0],
            id(marks),
            id(_KEY_AL),
            id(_KEY_OUT),
            _address("PyObject_GetBuffer"),
            _address("PyBuffer_Release"),
            id(memoryview),
            _np_u8(),
            ctypes.addressof(CLOCK_BOOKS),
            _address("PyLong_FromLongLong"),
            _address("PyDict_New"),
            _address("PyDict_SetItem"),
            _address("PyTuple_Pack"),
            id(_KEY_LISTS),
            id(_KEY_SEEN),
            size_at,
            _address("PyBytes_FromStringAndSize"),
            _address("PyFloat_FromDouble"),
            id(type(ctypes.c_int)),
            id(type(ctypes.Structure)),
            id(type(ctypes.Union)),
            id(type(ctypes.POINTER(ctypes.c_int))),
            id(ctypes.c_void_p),
            id(ctypes.c_char_p),
            id(ctypes.c_wchar_p),
            titems,
        )
        lib.gtecat_centry_api.argtypes = [ctypes.POINTER(_Api)]
        lib.gtecat_centry_api.restype = ctypes.c_int
        if lib.gtecat_centry_api(ctypes.byref(api)) != 0:
            return None, "the library refused the layout"
        lib.gtecat_centry_clock_ms.argtypes = [_VP]
        lib.gtecat_centry_clock_ms(ctypes.addressof(CLOCK_MS))
        lib.gtecat_centry_wait_at.argtypes = [_VP]
        lib.gtecat_centry_wait_at(ctypes.addressof(WAIT_AT))  # (a GT_ write's armed cycle)
        lib.gtecat_centry_cycle_timer.argtypes = [_VP]
        global CYCLE_TIMED
        CYCLE_TIMED = lib.gtecat_centry_cycle_timer(ctypes.addressof(CYCLE_TIMER)) == 0
        meth = ctypes.cast(lib.gtecat_centry_reader, _VP).value
        raw_meth = ctypes.cast(lib.gtecat_centry_raw, _VP).value
        vc = ctypes.cast(lib.gtecat_centry_reader_vc, _VP).value
        raw_vc = ctypes.cast(lib.gtecat_centry_raw_vc, _VP).value
        multi_meth = ctypes.cast(lib.gtecat_centry_multi, _VP).value
        multi_vc = ctypes.cast(lib.gtecat_centry_multi_vc, _VP).value
        replay_meth = ctypes.cast(lib.gtecat_centry_replay, _VP).value
        wait_meth = ctypes.cast(lib.gtecat_centry_wait, _VP).value
        wait_vc = ctypes.cast(lib.gtecat_centry_wait_vc, _VP).value
        new = byref_target.function_maker()
    except Exception as e:  # no compiler, a failed build, no Python API in this process
        return None, f"{type(e).__name__}: {e}"
    try:
        callables: list[type] = [_callable_type()]
    except Exception as e:  # (the partial of a built-in function instead)
        log.debug("entry callables: %s", e)
        callables = []
    callables_made[:] = callables

    def public(fn: Any, address: int, e: Any, keep: Any) -> Any:
        """The public function of an entry: a callable of :func:`_callable_type` calling the
        C function at ``address`` with ``e``'s memory, where that type could be made; else a
        ``functools.partial`` of the built-in function ``fn`` (it passes its arguments
        straight on, no frame).  Either takes the attributes the GT layer gives its
        functions, unlike a built-in function."""
        if not callables:
            return functools.partial(fn)
        c = callables[0]()
        _KEEP.append((e, keep, fn))
        ctypes.c_void_p.from_address(id(c) + _HEAD).value = address
        ctypes.c_void_p.from_address(id(c) + _HEAD + _WORD).value = ctypes.addressof(e)
        return c

    def make(
        fallback: Callable[..., Any],
        value: Callable[[Any], Any],
        sentinel: Any,
        types: Iterable[type],
        kind: int,
        core: bool,
        most: int = 4,
        size: int = 0,
        pointers: bool = False,
        noaxis: bool = False,
        array: Callable[..., Any] | None = None,
        gate: int = NO_GATE,
        after: Callable[[], Any] | None = None,
        cache: bool = False,
        clocks: Iterable[type] = (),
        numpy: Iterable[Any] = (),
        steady: bool = False,
        viewer: Callable[[Any], Any] | None = None,
        clock_of: dict | None = None,
    ) -> Any:
        kinds = tuple(types)
        if pointers:  # (pointer(x) too: x's memory, of x's type)
            kinds += tuple(ctypes.POINTER(t) for t in kinds)
            _pointer_types_of_ctypes()
        if not 0 < len(kinds) < _MAX_TYPES or not (1 if noaxis else 2) <= most <= 4:
            raise ValueError(f"one to {_MAX_TYPES - 1} types, two to four arguments")
        e = _Entry(id(fallback), id(value), id(sentinel), int(core), kind, most)
        e.noaxis = int(noaxis)
        e.avalue = id(array) if array is not None else None
        e.gate = gate
        e.after = id(after) if after is not None else None
        # (a structure's array: its elements sizeof apart, its value the fields' bytes)
        e.stride = ctypes.sizeof(kinds[0]) if kind == BYTES and array is not None else 0
        e.tuple_type, e.titems = id(tuple), titems  # (array's (bytes,): status words alone)
        e.steady = int(steady)
        e.viewer = id(viewer) if viewer is not None else None
        if clock_of is not None:  # (GT_GetClock: the clock's value in C, the session's dict)
            e.session, e.key_last = id(clock_of), id(_KEY_LAST)
        for k, t in enumerate(kinds):
            pointer = issubclass(t, ctypes._Pointer)
            x = t._type_ if pointer else t
            e.derefs[k] = id(x) if pointer else 0  # (the type a pointer's x must have)
            e.types[k] = id(t)
            e.sizes[k] = size or ctypes.sizeof(x)
            e.signs[k] = int(kind != INT or not getattr(x, "_type_", "").isupper())
        cks = tuple(clocks)
        if cks:  # (pointer(x) too: x's memory, of x's type)
            cks += tuple(ctypes.POINTER(t) for t in cks)
            _pointer_types_of_ctypes()
        if len(cks) >= _MAX_TYPES:
            raise ValueError(f"at most {(_MAX_TYPES - 1) // 2} clock types")
        for k, t in enumerate(cks):
            pointer = issubclass(t, ctypes._Pointer)
            x = t._type_ if pointer else t
            e.ctypes_[k], e.csizes[k] = id(t), ctypes.sizeof(x)
            e.csigns[k] = int(not x._type_.isupper())
            e.cderefs[k] = id(x) if pointer else 0
        dts = tuple(numpy) if api.ndarray_type else ()
        if len(dts) >= 8:
            raise ValueError("at most seven numpy dtypes")
        for k, dt in enumerate(dts):  # (numpy's own dtype objects: compared by identity)
            e.nptypes[k], e.npsizes[k] = id(dt), dt.itemsize
            e.npsigns[k] = int(dt.kind != "u")
        slots = aslot = None
        if cache:  # (the memory the C function keeps values in, kept alive with it)
            slots = _slots(e)
            if array is not None:  # (a lane per span a program reads in turn)
                aslot = (_ASlot * SPAN_LANES)()
                e.acache = ctypes.cast(aslot, ctypes.POINTER(_ASlot))
                e.nacache = SPAN_LANES
        keep = (fallback, value, sentinel, kinds, cks, array, after, slots, aslot, dts, viewer)
        keep += (clock_of,)
        fn = new(b"gt_centry", meth, _METH_FASTCALL_KEYWORDS, e, keep)
        return public(fn, vc, e, keep)

    def make_raw(
        fallback: Callable[..., Any],
        value: Callable[..., Any],
        sentinel: Any,
        io: bool,
        write: bool,
        gate: int = NO_GATE,
        after: Callable[[], Any] | None = None,
        cache: bool = False,
        changed: Callable[[], Any] | None = None,
    ) -> Any:
        e = _RawEntry(id(fallback), id(value), id(sentinel), int(io), int(write), gate)
        e.after = id(after) if after is not None else None
        e.changed = id(changed) if write and changed is not None else None
        e.grow = int(e.changed is not None and changed is _grow_epoch)
        slot = None
        # (a writer whose value makes the epoch grow itself: nothing kept)
        if cache and (not write or changed is not None):  # (a lane per range read in turn)
            slot = (_ASlot * SPAN_LANES)()
            e.cache = ctypes.cast(slot, ctypes.POINTER(_ASlot))
            e.ncache = SPAN_LANES
        keep = (fallback, value, sentinel, after, slot, changed)
        fn = new(b"gt_centry_raw", raw_meth, _METH_FASTCALL_KEYWORDS, e, keep)
        return public(fn, raw_vc, e, keep)

    def make_multi(
        fallback: Callable[..., Any],
        value: Callable[[Any], Any],
        sentinel: Any,
        outs: list[tuple[Iterable[type], int]],
        extras: Iterable[int] = (),
        gate: int = NO_GATE,
        after: Callable[[], Any] | None = None,
        cache: bool = False,
    ) -> Any:
        more = tuple(extras)
        if not 2 <= len(outs) <= _MAX_OUT or len(more) > 3:
            raise ValueError(f"two to {_MAX_OUT} outputs, at most three arguments after them")
        e = _MultiEntry(id(fallback), id(value), id(sentinel), len(outs), len(more))
        for k, x in enumerate(more):
            e.extra[k] = x
        kinds = []
        for k, (out_types, kind) in enumerate(outs):
            if kind not in (INT, DOUBLE):
                raise ValueError("outputs of integers or doubles")
            e.kinds[k] = kind
            ts = _type_table(e.types[k], e.sizes[k], e.signs[k], out_types, kind)
            if not ts:
                raise ValueError("an output takes one type at least")
            kinds.append(ts)
        e.gate = gate
        e.after = id(after) if after is not None else None
        e.titems, e.tuple_type = titems, id(tuple)
        slots = _slots(e) if cache else None
        keep = (fallback, value, sentinel, kinds, after, slots)
        fn = new(b"gt_centry_multi", multi_meth, _METH_FASTCALL_KEYWORDS, e, keep)
        return public(fn, multi_vc, e, keep)

    def make_replay() -> ReplayLoop:
        t = _RTable(0, None, None, titems, id(tuple))
        loop = ReplayLoop(t)
        # (the table kept with the function, the loop not: its calls go with the replay)
        loop.run = new(b"gt_centry_replay", replay_meth, _METH_FASTCALL_KEYWORDS, t, None)
        return loop

    def make_wait(
        fallback: Callable[..., Any],
        after: Callable[[], Any],
        rest: Callable[[int, int], Any],
        session: dict,
        most: int,
        batch: int,
        maxc: int,
    ) -> Any:
        e = _WaitEntry(id(fallback), id(after), id(rest), id(session), id(_KEY_LAST))
        e.key_note, e.most, e.batch, e.maxc = id(_KEY_NOTE), most, batch, maxc
        e.at = ctypes.addressof(WAIT_AT)
        keep = (fallback, after, rest, session)
        fn = new(b"gt_centry_wait", wait_meth, _METH_FASTCALL_KEYWORDS, e, keep)
        return public(fn, wait_vc, e, keep)

    make.raw = make_raw  # type: ignore[attr-defined]
    make.multi = make_multi  # type: ignore[attr-defined]
    make.replay = make_replay  # type: ignore[attr-defined]
    make.wait = make_wait  # type: ignore[attr-defined]
    for _ in range(2):
        try:
            reason = (
                _self_test(make)
                or _self_test_raw(make_raw)
                or _self_test_multi(make_multi)
                or _self_test_wait(make_wait)
            )
        except Exception as e:  # (a self-test that cannot even run)
            reason = f"the self-test failed: {type(e).__name__}: {e}"
        if not reason or not callables:
            break
        log.debug("entry callables: %s; partials instead", reason)
        global PARTIALS  # (why: a test's message, a user's debugging)
        PARTIALS = reason
        callables.clear()  # (once more, each entry behind a functools.partial)
    return (make, "") if not reason else (None, reason)


#: the names of the session's last error and note, as GTE_Wait's entry looks them up
_KEY_LAST, _KEY_NOTE = sys.intern("last"), sys.intern("note")


def _self_test_wait(make_wait: Callable[..., Any]) -> str:
    """'' when GTE_Wait's entry hands every call it does not make to its fallback with the
    very same arguments and keeps reference counts, else what went wrong.  (Its waits are
    held to the Python path's by the tests: a wait needs a controller.)"""

    def python(*a: Any, **kw: Any) -> Any:
        return ("python", a, kw)

    def after() -> int:
        return 0

    def rest(rc: int, pending: int) -> int:
        return 0

    session = {"last": None, "note": None}
    w = make_wait(python, after, rest, session, 100, 1000, 9)
    big, huge = 1.5, 1 << 70
    shapes: list[tuple[tuple[Any, ...], dict[str, Any]]] = [
        ((1,), {}), ((1.0,), {}), ((0,), {}), ((big,), {}), ((-1,), {}), ((huge,), {}),
        ((float("nan"),), {}), ((True,), {}), ((None,), {}), ((), {}), ((1, 2), {}),
        ((), {"ms": 1}), ((1,), {"x": 2}),
    ]  # fmt: skip
    watched = _own([big, python, after, rest, session])
    counts = [sys.getrefcount(x) for x in watched]
    for _ in range(3):
        for a, kw in shapes:
            if w(*a, **kw) != ("python", a, kw):
                return f"GTE_Wait's entry answered {a} {kw} itself with no controller"
    if [sys.getrefcount(x) for x in watched] != counts:
        return "GTE_Wait's entry changed reference counts"
    return ""


def wait(
    fallback: Callable[..., Any],
    after: Callable[[], Any],
    rest: Callable[[int, int], Any],
    session: dict,
    most: int,
    batch: int,
    maxc: int,
) -> Any:
    """GTE_Wait's C entry (csrc/centry.c ``wait_call``): a wait of ``ms`` (an exact int or
    float from 0 to ``most``) on the GT_ gate's controller (:data:`WAIT_AT`) run on the
    quick cycle armed for the readers' entries, its cycles (at most ``batch``) in one call of
    the kernel (``maxc``: the kernel's io slot of the cycles to run), booked in C where the
    run went whole; ``rest(rc, pending)`` where it did not (the controller's Python book and
    the rest of the wait, the call's code); ``after()``: the call's host latency on the auto
    clock, as a reader's.  ``session``: the GT session's own dict (its ``last`` and
    ``note`` must be None).  Every other call: ``fallback`` with the same arguments.  None
    where the C entry is not available (:data:`REASON`)."""
    if _MAKE is None:
        return None
    return _MAKE.wait(fallback, after, rest, session, most, batch, maxc)  # type: ignore[attr-defined]


def _own(objects: list[Any]) -> list[Any]:
    """The self-tests' objects whose reference counts only this code changes: not the
    interpreter's shared ints (and None, booleans), whose counts another thread of the
    process (an I/O thread of the test runner, an application's) changes at any moment."""
    return [x for x in objects if not (x is None or type(x) in (int, bool))]


def _self_test(make: Maker) -> str:
    """'' when entries give the known answers and keep reference counts, else what went
    wrong."""
    nope = object()
    big = [1 << 40]  # (a value a 32-bit object does not hold: held to watch its count)

    def value(n: Any) -> Any:
        return {1: 7, 2: big[0], 3: 1 << 70, 4: 1.5, 5: nope, 6: -(1 << 31)}.get(n, nope)

    def fvalue(n: Any) -> Any:
        return {1: 2.5, 2: 3, 5: nope}.get(n, nope)

    def python(*a: Any, **kw: Any) -> Any:
        return ("python", a, kw)

    ints = make(python, value, nope, [ctypes.c_int32, ctypes.c_int64], INT, False)
    doubles = make(python, fvalue, nope, [ctypes.c_double], DOUBLE, False)
    gtn = make(python, value, nope, [ctypes.c_int64], INT, True)
    ptrs = make(python, value, nope, [ctypes.c_int32, ctypes.c_int64], INT, False, 4, 0, True)
    clock = make(python, lambda: 7, nope, [ctypes.c_uint32], INT, False, 2, 0, False, True)
    A3 = ctypes.c_int64 * 3

    def avalue(n: Any, count: Any, tp: Any, clk: Any) -> Any:
        if tp is not A3 or not 1 <= count <= 3 or n != 1 or clk not in (None, 0):
            return nope
        return struct.pack(f"@{count}q", *range(5, 5 + count))

    arrays = make(python, value, nope, [ctypes.c_int64], INT, False, 4, 0, False, False, avalue)
    narrow = make(python, value, nope, [ctypes.c_int16, ctypes.c_uint16], INT, False, 2)

    class Pair(ctypes.Structure):
        _fields_ = [("a", ctypes.c_int32), ("b", ctypes.c_int16), ("pad", ctypes.c_int16)]

    def svalue(n: Any) -> Any:
        return {1: b"\x01\x00\x00\x00\xff\xff", 2: b"\x01"}.get(n, nope)

    structs = make(python, svalue, nope, [Pair], BYTES, False, 2, 6)
    L, I32, D = ctypes.c_int64, ctypes.c_int32, ctypes.c_double
    held = L()
    held_p = ctypes.byref(held)
    arr = (L * 2)()
    # (entry, arguments before the pointer, how the pointer is made, arguments after it,
    #  the value written or None: the Python function answers)
    cases: list[tuple[Any, tuple, Callable[[], Any], tuple, Any]] = [
        (ints, (1,), lambda: (o := L(), ctypes.byref(o), o), (), 7),
        (ints, (1,), lambda: (o := I32(), ctypes.byref(o), o), (), 7),
        (ints, (1,), lambda: (o := L(), o, o), (), 7),
        (ints, (1,), lambda: (held, held_p, held), (1,), 7),
        (ints, (1,), lambda: (o := L(), ctypes.byref(o), o), (1, 0), 7),
        (ints, (1,), lambda: (o := L(), ctypes.byref(o), o), (1, None), 7),
        (ints, (2,), lambda: (o := L(), ctypes.byref(o), o), (), 1 << 40),
        (ints, (6,), lambda: (o := I32(), ctypes.byref(o), o), (), -(1 << 31)),
        (ints, (2,), lambda: (o := I32(), ctypes.byref(o), o), (), None),  # too wide
        (ints, (3,), lambda: (o := L(), ctypes.byref(o), o), (), None),  # too wide
        (ints, (4,), lambda: (o := L(), ctypes.byref(o), o), (), None),  # a float
        (ints, (5,), lambda: (o := L(), ctypes.byref(o), o), (), None),  # the sentinel
        (ints, (9,), lambda: (o := L(), ctypes.byref(o), o), (), None),
        (ints, (True,), lambda: (o := L(), ctypes.byref(o), o), (), None),
        (ints, (1.0,), lambda: (o := L(), ctypes.byref(o), o), (), None),
        (ints, (1,), lambda: (o := (L * 2)(), ctypes.byref(o, 8), o), (), None),
        (ints, (1,), lambda: (o := L.from_buffer(arr, 8), ctypes.byref(o), o), (), 7),
        (ints, (1,), lambda: (o := ctypes.c_short(), ctypes.byref(o), o), (), None),
        (ints, (1,), lambda: (o := D(), ctypes.byref(o), o), (), None),
        (ints, (1,), lambda: (o := (L * 1)(), o, o), (), None),
        (ints, (1,), lambda: (o := L(), ctypes.pointer(o), o), (), None),
        (ints, (1,), lambda: (o := L(), ctypes.byref(o), o), (2,), None),
        (ints, (1,), lambda: (o := L(), ctypes.byref(o), o), (True,), None),
        (ints, (1,), lambda: (o := L(), ctypes.byref(o), o), (1, 5), None),
        (ints, (1,), lambda: (o := L(), ctypes.byref(o), o), (1, 0, 0), None),
        (ints, (), lambda: (o := L(), ctypes.byref(o), o), (), None),
        (ints, (1,), lambda: (None, None, None), (), None),
        (doubles, (1,), lambda: (o := D(), ctypes.byref(o), o), (), 2.5),
        (doubles, (1,), lambda: (o := D(), o, o), (1, 0), 2.5),
        (doubles, (2,), lambda: (o := D(), ctypes.byref(o), o), (), None),  # an int
        (doubles, (1,), lambda: (o := L(), ctypes.byref(o), o), (), None),
        (gtn, (1, 1), lambda: (o := L(), ctypes.byref(o), o), (), 7),
        (gtn, (1, 2), lambda: (o := L(), o, o), (1, 0), 1 << 40),
        (gtn, (2, 1), lambda: (o := L(), ctypes.byref(o), o), (), None),
        (gtn, (1,), lambda: (o := L(), ctypes.byref(o), o), (), None),
        (ptrs, (1,), lambda: (o := L(), ctypes.pointer(o), o), (), 7),
        (ptrs, (1,), lambda: (o := I32(), ctypes.pointer(o), o), (1, 0), 7),
        (ptrs, (2,), lambda: (o := I32(), ctypes.pointer(o), o), (), None),  # too wide
        (ptrs, (1,), lambda: (o := L(), ctypes.POINTER(L)(), o), (), None),  # NULL
        (ptrs, (1,), lambda: (o := L(), ctypes.byref(ctypes.pointer(o)), o), (), None),
        (ptrs, (1,), lambda: (o := D(), ctypes.pointer(o), o), (), None),
        (arrays, (1,), lambda: (o := A3(), o, o), (), [5, 0, 0]),
        (arrays, (1,), lambda: (o := A3(), o, o), (3,), [5, 6, 7]),
        (arrays, (1,), lambda: (o := A3(), o, o), (2, None), [5, 6, 0]),
        (arrays, (1,), lambda: (o := A3(), o, o), (4,), None),
        (arrays, (2,), lambda: (o := A3(), o, o), (2,), None),
        (arrays, (1,), lambda: (o := A3(), o, o), (2.0,), None),
        (arrays, (1,), lambda: (o := (ctypes.c_int64 * 4)(), o, o), (2,), None),
        # byref(array[, offset]): C's &array[k], where count whole elements fit behind it
        (arrays, (1,), lambda: (o := A3(), ctypes.byref(o), o), (2,), [5, 6, 0]),
        (arrays, (1,), lambda: (o := A3(), ctypes.byref(o, 8), o), (2,), [0, 5, 6]),
        (arrays, (1,), lambda: (o := A3(), ctypes.byref(o, 16), o), (1, 0), [0, 0, 5]),
        (arrays, (1,), lambda: (o := A3(), ctypes.byref(o, 16), o), (2,), None),  # past
        (arrays, (1,), lambda: (o := A3(), ctypes.byref(o, 24), o), (), None),  # at the end
        (arrays, (1,), lambda: (o := A3(), ctypes.byref(o, 4), o), (), None),  # mid-element
        (arrays, (1,), lambda: (o := A3(), ctypes.byref(o, 8), o), (3,), None),
        (arrays, (1,), lambda: (o := L(), o, o), (), 7),
        (clock, (), lambda: (o := ctypes.c_uint32(), ctypes.byref(o), o), (), 7),
        (clock, (), lambda: (o := ctypes.c_uint32(), o, o), (None,), 7),
        (clock, (), lambda: (o := ctypes.c_uint32(), o, o), (0,), 7),
        (clock, (), lambda: (o := ctypes.c_uint32(), o, o), (1,), None),
        (clock, (), lambda: (o := ctypes.c_uint32(), o, o), (0, 0), None),
        (clock, (), lambda: (o := ctypes.c_int32(), o, o), (), None),
        (narrow, (1,), lambda: (o := ctypes.c_int16(), ctypes.byref(o), o), (), 7),
        (narrow, (1,), lambda: (o := ctypes.c_uint16(), o, o), (), 7),
        (narrow, (6,), lambda: (o := ctypes.c_int16(), o, o), (), None),
        (narrow, (6,), lambda: (o := ctypes.c_uint16(), o, o), (), None),
        (narrow, (1,), lambda: (o := ctypes.c_int16(), o, o), (1,), None),  # two at most
        (structs, (1,), lambda: (o := Pair(pad=9), ctypes.byref(o), o), (), (1, -1, 9)),
        (structs, (1,), lambda: (o := Pair(pad=9), o, o), (), (1, -1, 9)),
        (structs, (2,), lambda: (o := Pair(), o, o), (), None),  # too short
        (structs, (1,), lambda: (o := Pair(), ctypes.byref(o, 2), o), (), None),
    ]
    for fn, before, made, after, want in cases:
        o, p, shown = made()
        args = (*before, p, *after)
        watched = _own([p, o, big[0], nope, *before, *after])
        counts = [sys.getrefcount(x) for x in watched]
        for _ in range(3):
            if isinstance(shown, Pair):
                shown.a, shown.b, shown.pad = 0, 0, 9
            elif shown is not None:
                ctypes.memset(ctypes.addressof(shown), 0, ctypes.sizeof(shown))
            got = fn(*args)
            if want is None:
                if got != ("python", args, {}):
                    return f"the entry answered {got!r} for {args!r} (the Python function must)"
            else:
                written = (
                    (shown.a, shown.b, shown.pad)
                    if isinstance(shown, Pair)
                    else list(shown)
                    if isinstance(shown, ctypes.Array)
                    else shown.value
                )
                if got != 0 or written != want:
                    return f"the entry answered {got!r} for {args!r}, not 0 with {want!r}"
                del written
            del got
        if fn(*args, kw=1) != ("python", args, {"kw": 1}):
            return "the entry answered a call with a keyword"
        if [sys.getrefcount(x) for x in watched] != counts:
            now = [sys.getrefcount(x) for x in watched]
            return f"the entry changed a reference count ({args!r}: {counts} -> {now})"

    reason = _self_test_numpy(make, python, value, nope)
    if reason:
        return reason

    gated = [make(python, value, nope, [ctypes.c_int64], INT, False, 4, 0, False, False, None, g)
             for g in (GT_GATE, GTN_GATE)]  # fmt: skip
    before = tuple(GATES)
    try:
        for k, fn in enumerate(gated):
            for on in (0, 1, 0):
                GATES[k], GATES[1 - k] = on, 1 - on
                o = L()
                got = fn(1, ctypes.byref(o))
                if not (
                    (got == 0 and o.value == 7)
                    if on
                    else (type(got) is tuple and got[0] == "python" and o.value == 0)
                ):
                    return f"a gated entry answered {got!r} with its gate {on}"
    finally:
        GATES[:] = before

    reason = _self_test_cache(make, python, nope)
    if reason:
        return reason

    def failing(n: Any) -> Any:
        raise LookupError(n)

    raising = make(python, failing, nope, [ctypes.c_int64], INT, False)
    try:
        raising(1, ctypes.byref(L()))
    except LookupError:
        pass
    else:
        return "the value's error did not reach the caller"
    return ""


def _self_test_numpy(make: Maker, python: Callable[..., Any], value: Any, nope: Any) -> str:
    """'' when an entry writes the first element of the numpy arrays it takes and hands on
    the others, else what went wrong."""
    try:
        import numpy as np
    except ImportError:
        return ""
    i32, i64 = np.dtype(np.int32), np.dtype(np.int64)
    f = make(python, value, nope, [ctypes.c_int64], INT, False, 4, 0, False, False, None,
             NO_GATE, None, False, (), (i32, i64))  # fmt: skip
    ro = np.zeros(2, np.int64)
    ro.flags.writeable = False
    cases: list[tuple[int, Any, Any]] = [
        (1, np.zeros(1, np.int64), 7),
        (1, np.zeros(3, np.int32), 7),
        (6, np.zeros(2, np.int32), -(1 << 31)),
        (2, np.zeros(1, np.int32), None),  # (too wide)
        (1, np.zeros((1, 1), np.int64), None),
        (1, np.zeros(0, np.int64), None),
        (1, ro, None),
        (1, np.zeros(4, np.int64)[::2], None),
        (1, np.zeros(1, np.float64), None),
        (1, np.zeros(1, np.int16), None),
        (1, np.zeros(1, np.dtype(">i8")), None),
        (4, np.zeros(1, np.int64), None),  # (a float value)
    ]
    for n, a, want in cases:
        before = a.copy()
        got = f(n, a)
        if want is None:
            ok = got == ("python", (n, a), {}) and np.array_equal(a, before)
        else:
            ok = got == 0 and int(a[0]) == want and np.array_equal(a[1:], before[1:])
        if not ok:
            return f"a numpy entry answered {got!r} for {a!r} (axis {n})"
    return ""


def _self_test_cache(make: Maker, python: Callable[..., Any], nope: Any) -> str:
    """'' when an entry that keeps values asks again exactly when :data:`EPOCH` grows, per
    axis, its spans per key, and writes a pClock's value from its gate's clock (a span's
    and a value's: the kept values with the clock of the call), else what went wrong."""
    asked: list[Any] = []
    gen = [0]
    L, A3, U32, I32 = ctypes.c_int64, ctypes.c_int64 * 3, ctypes.c_uint32, ctypes.c_int32

    def value(n: Any) -> Any:
        asked.append(n)
        return nope if n == 9 else 100 * n + gen[0]

    def avalue(n: Any, count: Any, tp: Any, clock: Any) -> Any:
        asked.append((n, count, clock))
        if tp is not A3 or not 1 <= count <= 3 or clock is not None:
            return nope
        first = n + gen[0] if n == 3 else n
        out = struct.pack(f"@{count}q", *range(first, first + count))
        return (out,) if n == 3 else out  # (status words alone: written as bytes)

    f = make(python, value, nope, [L], INT, False, 4, 0, False, False, avalue,
             GT_GATE, None, True, [U32, I32])  # fmt: skip
    o, a, c, c32, c16 = L(), A3(), U32(), I32(), ctypes.c_uint16()
    p = ctypes.byref(o)
    times = array("q", (1_070_999_999, 1_000_000_000))  # (the time and GT_Reset's: 70 ms)
    # (args, asked, (o, a, c, c32) written, or None: the Python function answers)
    steps: list[tuple[tuple, list[Any], Any]] = [
        ((1, p), [1], (100, [0, 0, 0], 0, 0)),
        ((1, p), [], (100, [0, 0, 0], 0, 0)),
        ((2, p), [2], (200, [0, 0, 0], 0, 0)),
        ((1, p, 1, 0), [1], (101, [0, 0, 0], 0, 0)),  # (the epoch grown: asked again)
        ((9, p), [9], None),
        ((9, p), [9], None),
        ((1, a, 2), [(1, 2, None)], (0, [1, 2, 0], 0, 0)),
        ((1, a, 2), [], (0, [1, 2, 0], 0, 0)),
        ((1, a, 3), [(1, 3, None)], (0, [1, 2, 3], 0, 0)),
        ((1, a, 3, ctypes.byref(c)), [], (0, [1, 2, 3], 70, 0)),  # (kept; the clock's)
        ((1, a, 3, c32), [], (0, [1, 2, 3], 0, 70)),
        ((1, p, 1, ctypes.byref(c)), [], (101, [0, 0, 0], 70, 0)),
        ((1, p, 1, c32), [], (101, [0, 0, 0], 0, 70)),
        ((1, a, 3, c16), [], None),  # (a clock type it does not take)
        ((1, p, 1, c16), [], None),
        ((1, p, 1, c32), [], (101, [0, 0, 0], 0, (1 << 31) - 1)),  # (the largest it holds)
        ((1, p, 1, c32), [], None),  # (one more: a clock an int32 does not hold)
        ((1, a, 2, c32), [], None),  # (the span (1, 2) kept in its lane beside (1, 3))
        ((1, a, 2, c), [], (0, [1, 2, 0], 1 << 31, 0)),
        ((1, p, 1, c), [], (101, [0, 0, 0], (1 << 32) - 1, 0)),  # (before GT_Reset's: -1)
        ((3, a, 2), [(3, 2, None)], (0, [4, 5, 0], 0, 0)),  # (a 1-tuple's bytes)
        ((3, a, 2), [], (0, [4, 5, 0], 0, 0)),
        ((3, a, 2), [(3, 2, None)], (0, [5, 6, 0], 0, 0)),  # (the epoch grown: asked again)
    ]
    before = tuple(GATES), tuple(CLOCK_MS)
    try:
        GATES[0] = LOCKSTEP
        CLOCK_MS[0], CLOCK_MS[1] = times.buffer_info()[0], times.buffer_info()[0] + 8
        for k, (args, want_asked, want) in enumerate(steps):
            del asked[:]
            if k == 3:
                gen[0] = 1
                changed()
            if k == 15:
                times[0] = times[1] + ((1 << 31) - 1) * 1_000_000 + 999_999
            if k == 16:
                times[0] += 1
            if k == 19:
                times[0] = times[1] - 1
            if k == 22:
                gen[0] = 2
                changed()
            o.value, c.value, c32.value = 0, 0, 0
            ctypes.memset(a, 0, ctypes.sizeof(a))
            got = f(*args)
            if want is None:
                ok = got == ("python", args, {}) and (o.value, list(a), c.value) == (0, [0] * 3, 0)
            else:
                ok = got == 0 and (o.value, list(a), c.value, c32.value) == want
            if not ok or asked != want_asked:
                return f"a keeping entry answered {got!r} for {args!r} asking {asked!r}"
    finally:
        GATES[:] = before[0]
        CLOCK_MS[:] = before[1]
    return ""


def _self_test_multi(make_multi: Maker) -> str:
    """'' when a multi-value entry writes every value or none, takes only its shapes, keeps
    values per epoch and reference counts, else what went wrong."""
    nope = object()
    asked: list[Any] = []

    def value(n: Any) -> Any:
        asked.append(n)
        return {1: (1, -70000), 2: (1, 1 << 40), 3: (2, 1.5), 4: nope, 5: (1,)}.get(n, nope)

    def python(*a: Any, **kw: Any) -> Any:
        return ("python", a, kw)

    S, L, I32 = ctypes.c_short, ctypes.c_int64, ctypes.c_int32
    f = make_multi(python, value, nope, [([S], INT), ([L, I32], INT)], [ONE, NULL], cache=True)
    a, b = S(), L()
    pa, pb = ctypes.byref(a), ctypes.byref(b)
    cases: list[tuple[tuple, Any, int]] = [
        ((1, pa, pb), (1, -70000), 1),
        ((1, pa, pb), (1, -70000), 0),  # (kept)
        ((1, a, b, 1), (1, -70000), 0),
        ((1, pa, pb, 1, None), (1, -70000), 0),
        ((1, pa, pb, 1, 0), (1, -70000), 0),
        ((1, pa, pb, 2), None, 0),
        ((1, pa, pb, 1, 5), None, 0),
        ((1, pa, pb, 1, None, 0), None, 0),
        ((1, pa), None, 0),
        ((1, pb, pa), None, 0),
        ((1, pa, ctypes.byref(I32())), (1, -70000), 0),
        ((2, pa, ctypes.byref(I32())), None, 1),  # (too wide for a 32-bit one: none written)
        ((3, pa, pb), None, 1),  # (a float for an integer)
        ((4, pa, pb), None, 1),
        ((5, pa, pb), None, 1),
        ((True, pa, pb), None, 0),
        ((1, ctypes.byref(a, 0), pb), (1, -70000), 0),
        ((1, pa, ctypes.byref((L * 2)(), 8)), None, 0),
    ]
    for args, want, n_asked in cases:
        del asked[:]
        a.value, b.value = 9, 9
        watched = _own([*args, nope])
        counts = [sys.getrefcount(x) for x in watched]
        got = f(*args)
        if want is None:
            ok = got == ("python", args, {}) and (a.value, b.value) == (9, 9)
        else:
            second = args[2]._obj if type(args[2]) is type(pb) else args[2]
            ok = got == 0 and (a.value, second.value) == want
        if not ok or len(asked) != n_asked:
            return f"a multi-value entry answered {got!r} for {args!r}, asking {asked!r}"
        del got
        if [sys.getrefcount(x) for x in watched] != counts:
            return f"a multi-value entry changed a reference count ({args!r})"
    changed()
    del asked[:]
    if f(1, pa, pb) != 0 or asked != [1]:
        return "a multi-value entry kept a value past its epoch"
    return ""


def _self_test_raw(make_raw: Maker) -> str:
    """'' when raw entries copy what they must, hand on the rest and keep reference counts."""
    nope = object()
    image = (ctypes.c_ubyte * 16)(*range(16))
    base = ctypes.addressof(image)
    U8 = ctypes.c_ubyte * 8

    try:
        import numpy as np
    except ImportError:
        np = None  # type: ignore[assignment]
    W, S = ctypes.c_ushort, TwoBytes
    taken = (U8, W, S, bytearray, bytes, memoryview, *(() if np is None else (np.ndarray,)))

    def value(*a: Any) -> Any:  # ([slave,] offset, size, type): inside the image, U8 only
        offset, size, tp = a[-3:]
        if tp not in taken or offset + size > 16 or size > 8:
            return nope
        if tp in (W, S) and size > 2:  # (runs_of's check of a ctypes type's size)
            return nope
        if len(a) == 4 and a[0] != 2:
            return nope
        if size == 5:  # (two runs: the image's bytes 0..1 and then 8..10)
            return runs([(0, base, 2), (2, base + 8, 3)])
        if size == 6:  # (a run past the buffer)
            return runs([(4, base, 3)])
        return runs([(0, base + offset, size)])

    def runs(r: list[tuple[int, int, int]]) -> bytes:
        return b"".join(struct.pack("=qqq", *x) for x in r)

    def python(*a: Any, **kw: Any) -> Any:
        return ("python", a, kw)

    get = make_raw(python, value, nope, False, False)
    put = make_raw(python, value, nope, False, True)
    io = make_raw(python, value, nope, True, False)
    bget = get
    cases: list[tuple[Any, tuple, Any]] = [
        (get, (4, 8), lambda: (o := U8(), o, bytes(range(4, 12)))),
        (get, (4, 8), lambda: (o := U8(), ctypes.byref(o), bytes(range(4, 12)))),
        (get, (0, 3), lambda: (o := U8(), o, bytes([0, 1, 2, 0, 0, 0, 0, 0]))),
        (get, (0, 5), lambda: (o := U8(), o, bytes([0, 1, 8, 9, 10, 0, 0, 0]))),
        (get, (0, 6), lambda: (o := U8(), o, None)),
        (io, (2, 1, 2), lambda: (o := U8(), o, bytes([1, 2, 0, 0, 0, 0, 0, 0]))),
        (io, (3, 1, 2), lambda: (o := U8(), o, None)),
        (get, (12, 8), lambda: (o := U8(), o, None)),  # past the image
        (get, (0, 0), lambda: (o := U8(), o, None)),
        (get, (0, -1), lambda: (o := U8(), o, None)),
        (get, (True, 2), lambda: (o := U8(), o, None)),
        (get, (0, 2.0), lambda: (o := U8(), o, None)),
        (get, (0, 1 << 70), lambda: (o := U8(), o, None)),
        (get, (0, 2), lambda: (o := (ctypes.c_ubyte * 9)(), o, None)),  # another type
        # byref(array, offset) (C's &buf[k]): the size's bytes from there, within the array
        (get, (0, 2), lambda: (o := U8(), ctypes.byref(o, 1), bytes([0, 0, 1, 0, 0, 0, 0, 0]))),
        (get, (0, 2), lambda: (o := U8(), ctypes.byref(o, 6), bytes([0] * 6 + [0, 1]))),
        (get, (0, 2), lambda: (o := U8(), ctypes.byref(o, 7), None)),  # past its end
        (get, (0, 2), lambda: (o := U8(), ctypes.byref(o, 8), None)),
        (get, (0,), lambda: (o := U8(), o, None)),
        (bget, (4, 8), lambda: (o := bytearray(9), o, bytes([*range(4, 12), 0]))),
        (bget, (4, 8), lambda: (o := bytearray(7), o, None)),  # too short
        (bget, (4, 3), lambda: (o := bytes(8), o, None)),  # (bytes: read only)
        (bget, (4, 8), lambda: (o := memoryview(bytearray(8)), o, bytes(range(4, 12)))),
        (bget, (4, 8), lambda: (o := memoryview(bytearray(7)), o, None)),  # too short
        (bget, (4, 3), lambda: (o := memoryview(bytes(8)), o, None)),  # (read only)
        (bget, (4, 3), lambda: (o := memoryview(bytearray(16))[::2], o, None)),
        # a memoryview of numbers: its bytes (as the table takes it)
        (
            bget,
            (4, 2),
            lambda: (o := memoryview(bytearray(8)).cast("H"), o, bytes([4, 5] + [0] * 6)),
        ),
        (bget, (4, 2), lambda: (o := memoryview(bytearray(8)).cast("P"), o, None)),  # pointers
        (bget, (4, 3), lambda: (o := _released(), o, None)),
        # a ctypes number or structure (a word of IO), byref of one: its memory
        (get, (4, 2), lambda: (o := W(), o, bytes([4, 5]))),
        (get, (4, 2), lambda: (o := W(), ctypes.byref(o), bytes([4, 5]))),
        (get, (4, 2), lambda: (o := S(), ctypes.byref(o), bytes([4, 5]))),
        (get, (4, 3), lambda: (o := W(), o, None)),  # (bigger than it)
        (get, (4, 2), lambda: (o := W(), ctypes.byref(o, 1), None)),  # past its end
        (get, (4, 2), lambda: (o := ctypes.c_short(), o, None)),  # (a type value refuses)
        (get, (4, 2), lambda: (o := ctypes.c_ushort(), ctypes.pointer(o), None)),
    ]
    if np is not None:
        ro = np.zeros(8, np.uint8)
        ro.flags.writeable = False
        cases += [
            (bget, (4, 8), lambda: (o := np.zeros(8, np.uint8), o, bytes(range(4, 12)))),
            (bget, (4, 8), lambda: (o := np.zeros(7, np.uint8), o, None)),  # too short
            # another dtype, another shape: its bytes, C-contiguous (as the table takes it)
            (bget, (4, 3), lambda: (o := np.zeros(8, np.int8), o, bytes([4, 5, 6, *[0] * 5]))),
            (bget, (4, 2), lambda: (o := np.zeros(1, np.uint16), o, bytes([4, 5]))),
            (bget, (4, 3), lambda: (o := np.zeros(16, np.uint8)[::2], o, None)),
            (bget, (4, 3), lambda: (o := np.zeros(1, np.uint16), o, None)),  # too short
            (bget, (4, 2), lambda: (o := np.zeros(4, np.uint16)[::2], o, None)),
            (bget, (4, 2), lambda: (o := np.zeros(2, object), o, None)),  # Python objects
            (
                bget,
                (4, 3),
                lambda: (o := np.zeros((2, 8), np.uint8), o, bytes([4, 5, 6, *[0] * 13])),
            ),
            (bget, (4, 3), lambda: (ro, ro, None)),  # (read only)
        ]
    for fn, before, made in cases:
        o, p, want = made()
        args = (*before, p)
        watched = _own([o, p, nope, *before])
        counts = [sys.getrefcount(x) for x in watched]
        for _ in range(3):
            got = fn(*args)
            if want is None:
                if got != ("python", args, {}):
                    return f"the raw entry answered {got!r} for {args!r} (Python must)"
            elif got != 0 or bytes(o) != want:
                return f"the raw entry answered {got!r}, {bytes(o)!r} for {args!r}"
            del got
        if fn(*args, kw=1) != ("python", args, {"kw": 1}):
            return "the raw entry answered a call with a keyword"
        if [sys.getrefcount(x) for x in watched] != counts:
            return f"the raw entry changed a reference count ({args!r})"
    asked: list[Any] = []

    def counted(*a: Any) -> Any:
        asked.append(a)
        return value(*a)

    kept = make_raw(python, counted, nope, False, False, NO_GATE, None, True)
    for k, (args, want) in enumerate(
        [((4, 2), 1), ((4, 2), 0), ((4, 3), 1), ((4, 3), 0), ((4, 3), 1), ((12, 8), 1),
         ((12, 8), 1), ((4, 2), 1)]
    ):  # fmt: skip
        if k == 4:
            changed()  # (the epoch grows: asked again)
        del asked[:]
        o = U8()
        got = kept(*args, o)
        ok = got == ("python", (*args, o), {}) if args[0] == 12 else got == 0
        if not ok or len(asked) != want:
            return f"a keeping raw entry answered {got!r} for {args!r}, asking {len(asked)}"
    src = U8(*range(50, 58))
    if put(2, 4, src) != 0 or bytes(image)[:8] != bytes([0, 1, 50, 51, 52, 53, 6, 7]):
        return "the raw entry did not write into the image"
    if put(1, 2, b"\x09\x08\x07") != 0 or bytes(image)[:4] != bytes([0, 9, 8, 51]):
        return "the raw entry did not write bytes into the image"
    if get(0, 2, bytes(4)) != ("python", (0, 2, bytes(4)), {}):
        return "the raw entry read into bytes"
    # a writer that keeps its runs: the image changed (and changed() called) only where a
    # byte differs; a write from a memoryview, a numpy array
    hits: list[int] = []
    del asked[:]
    cput = make_raw(python, counted, nope, False, True, NO_GATE, None, True, lambda: hits.append(1))
    for src, want_hits, want_asked in [
        (bytes([9, 8]), 0, 1),  # (the bytes the image holds)
        (bytes([9, 8]), 0, 0),  # (kept)
        (bytes([7, 6]), 1, 0),
        (memoryview(bytearray([5, 4])), 1, 1),
        (memoryview(bytes([5, 4])), 0, 0),
        *(() if np is None else [(np.array([3, 2], np.uint8), 1, 1)]),
    ]:
        del hits[:], asked[:]
        got = cput(1, 2, src)
        counts = (len(hits), len(asked))
        if got != 0 or bytes(image)[1:3] != bytes(src) or counts != (want_hits, want_asked):
            return f"a keeping raw writer answered {got!r} for {src!r}: {hits!r} {asked!r}"

    def hits_one() -> None:
        hits.append(1)

    # a bit writer (slave 2's byte at the offset): the bit set or cleared, changed() where
    # the byte changed; any other bit, value or type: Python
    def bit_value(slave: int, offset: int, bit: int, tp: Any) -> Any:  # (slave 2's byte)
        return runs([(0, base + offset, 1)]) if slave == 2 and tp is int else nope

    bits = make_raw(python, bit_value, nope, True, BIT_WRITE, NO_GATE, None, True, hits_one)
    image[5] = 0x10
    for args, want_byte, want_hits in [
        ((2, 5, 3, 1), 0x18, 1),
        ((2, 5, 3, 1), 0x18, 0),
        ((2, 5, 4, 0), 0x08, 1),
        ((2, 5, 8, 1), None, 0),
        ((2, 5, -1, 1), None, 0),
        ((2, 5, 0, 2), None, 0),
        ((2, 5, 0, True), None, 0),
        ((2, 5, 0, 1.0), None, 0),
        ((3, 5, 0, 1), None, 0),
        ((2, 5, 0), None, 0),
    ]:
        del hits[:]
        was = image[5]
        got = bits(*args)
        if want_byte is None:
            ok = got == ("python", args, {}) and image[5] == was
        else:
            ok = got == 0 and image[5] == want_byte and len(hits) == want_hits
        if not ok:
            return f"a bit writer answered {got!r} for {args!r}: {image[5]:#x} {hits!r}"
    return ""


class TwoBytes(ctypes.Structure):
    """A structure of two bytes (the raw entries' self-test)."""

    _fields_ = [("lo", ctypes.c_ubyte), ("hi", ctypes.c_ubyte)]


def _released() -> memoryview:
    m = memoryview(bytearray(8))
    m.release()
    return m


_MAKE, REASON = _load()
_pointer_types_of_ctypes()
if _MAKE is None:
    log.debug("C entry of the fast readers not used: %s", REASON)


def reader(
    fallback: Callable[..., Any],
    value: Callable[[Any], Any],
    sentinel: Any,
    types: Iterable[type],
    kind: int,
    core: bool = False,
    most: int = 4,
    size: int = 0,
    pointers: bool = False,
    noaxis: bool = False,
    array: Callable[..., Any] | None = None,
    gate: int = NO_GATE,
    after: Callable[[], Any] | None = None,
    clocks: Iterable[type] = (),
    numpy: Iterable[Any] = (),
    steady: bool = False,
    viewer: Callable[[Any], Any] | None = None,
    clock_of: dict | None = None,
) -> Any:
    """The C entry of a reader: ``f(n, p[, count[, pClock]])`` (``f(core, n, p, ...)`` where
    ``core``; at most ``most`` arguments after it) writing ``value(n)`` into ``p``'s object
    (of one of ``types``) for the common shape, else ``fallback`` with the same arguments;
    ``value`` gives ``sentinel`` where the entry must not answer.  ``kind``: :data:`INT`
    (each type's width and sign), :data:`DOUBLE`, or :data:`BYTES` (``value`` gives
    ``size`` bytes, copied to the start of the object); ``numpy``: numpy dtypes whose
    one-dimensional, C-contiguous, aligned, writable arrays of at least one element take the
    value in their first element (the Python fast function's numpy shape); ``pointers``:
    ``pointer(x)`` of
    those types too (``x``'s memory; NULL: ``fallback``); ``noaxis``: ``f(p[, q])`` with
    ``q`` omitted, None or 0 (where ``most`` is 2; 1: ``f(p)`` only), writing ``value()``
    (GT_GetClock's ``pClock``, ``pLoop``; GT_IsEcatReady's ``pStatus``), or, where
    ``clocks`` are given, ``q`` of those (as a pClock below) taking the clock's cycles run
    (GT_GetClock's ``pLoop``);
    ``array``: for ``p`` a ctypes array, ``array(n, count, type(p), clock)`` (``count`` an
    int, 1 where omitted; ``clock`` None where pClock is omitted, None or 0, and 1 where it
    is ``byref(x)`` (no offset), ``x`` or ``pointer(x)`` of one of ``clocks``) gives the bytes
    written to the array's start (it checks the array's type and length), then where
    ``clock`` is 1 the clock's value (native int64; written into ``x`` where ``x``'s type
    holds it), else anything but bytes; for ``p`` a numpy array of ``numpy``'s dtypes and a
    ``count`` of 2 or more, ``array(n, count, p.dtype, None)`` (the entry checks its
    length) likewise;
    ``gate``: :data:`GT_GATE` or :data:`GTN_GATE`, ``value`` and ``array`` asked only while
    that gate of :data:`GATES` is open (else ``fallback``; ``after()``, where given, the
    call's return once its value is written while the gate says :data:`AUTO`), so they
    need not check the session themselves; a gated entry keeps what ``value`` and
    ``array`` give for the epoch they were asked in and writes it again while
    :data:`EPOCH` stays (they must give the same while it does, :data:`EPOCH`); ``steady``:
    and across the quick cycles the entries book themselves (no Python runs in those: what
    an attribute no cycle changes gives, a profile's mode); ``viewer``: for ``p`` a
    memoryview, ``viewer(p)`` gives the ctypes array the call is then made with (the view
    shows all of it, of a type the reader takes), else None (``fallback``); ``clock_of``:
    GT_GetClock's entry (``noaxis``, gated), the GT session's own dict - its value is then
    the gate's clock's milliseconds since GT_Reset made in C (csrc/centry.c ``clock_ms``, as
    ``value`` makes them) wherever the session's ``last`` is None, ``value`` elsewhere.
    A callable that takes attributes (:func:`_callable_type`); None where the C entry is
    not available (:data:`REASON`)."""
    if _MAKE is None:
        return None
    return _MAKE(
        fallback,
        value,
        sentinel,
        types,
        kind,
        core,
        most,
        size,
        pointers,
        noaxis,
        array,
        gate,
        after,
        gate != NO_GATE,
        clocks,
        numpy,
        steady,
        viewer,
        clock_of,
    )


def raw(
    fallback: Callable[..., Any],
    value: Callable[..., Any],
    sentinel: Any,
    io: bool,
    write: bool | int,
    gate: int = NO_GATE,
    after: Callable[[], Any] | None = None,
    changed: Callable[[], Any] | None = None,
) -> Any:
    """The C entry of a raw image function: ``f([slave,] offset, size, buf)`` with ``buf`` a
    ctypes array, number or structure (or ``byref`` of one, with an offset too: C's
    ``&buf[k]``, where the ``size`` bytes from there end within the object: a ``c_ushort``
    for a word of IO), a bytearray, a C-contiguous numpy array of numbers (any dtype and
    shape: its bytes) or a C-contiguous memoryview of a plain number format of at least
    ``size`` bytes (or bytes, where ``write``; writable, where not) and plain ints copies the
    runs that ``value([slave,] offset, size, type(buffer))`` gives between the buffer and the
    image (into the image where ``write``): ``(first byte in the buffer, address, bytes)`` as
    native int64 triples in one bytes object (:func:`runs`); ``value`` gives ``sentinel``
    where the entry must not answer (it checks a ctypes type's size and that its memory holds
    no pointers); every other
    call: ``fallback``; ``gate``: as :func:`reader`'s (a gated reader keeps its runs for
    their epoch).  ``changed``: a writer's call where the write changed a byte of the image
    (its ``value`` then must not make the epoch grow itself: a gated writer keeps its runs
    for their epoch too, and a write of the bytes the image holds changes nothing); None: its
    ``value`` makes the epoch grow.  ``write`` :data:`BIT_WRITE`: ``f(slave, offset, bit,
    value)`` with plain ints, ``bit`` 0..7 and ``value`` 0 or 1, sets or clears that bit of
    the one byte ``value(slave, offset, bit, int)``'s run gives.  None where the C entry is
    not available (:data:`REASON`)."""
    if _MAKE is None:
        return None
    return _MAKE.raw(fallback, value, sentinel, io, write, gate, after, gate != NO_GATE, changed)  # type: ignore[attr-defined]


def multi(
    fallback: Callable[..., Any],
    value: Callable[[Any], Any],
    sentinel: Any,
    outs: list[tuple[Iterable[type], int]],
    extras: Iterable[int] = (),
    gate: int = NO_GATE,
    after: Callable[[], Any] | None = None,
) -> Any:
    """The C entry of a reader of several values: ``f(n, p1, p2[, p3][, extras...])`` with
    each ``p`` ``byref(x)`` (no offset) or ``x`` of one of its output's types (``outs``: the
    types and :data:`INT` or :data:`DOUBLE` per output) and each argument after them what
    ``extras`` says (:data:`ONE`, :data:`ZERO`, :data:`NULL`) writes the tuple ``value(n)``
    gives, each number checked to fit before any is written; else ``fallback`` with the same
    arguments.  ``gate`` and ``after``: as :func:`reader`'s (a gated entry keeps its values
    for their epoch).  None where the C entry is not available (:data:`REASON`)."""
    if _MAKE is None:
        return None
    return _MAKE.multi(fallback, value, sentinel, outs, extras, gate, after, gate != NO_GATE)  # type: ignore[attr-defined]


_RUN = struct.Struct("=qqq")


def runs(triples: Iterable[tuple[int, int, int]]) -> bytes:
    """Runs of a copy as :func:`raw`'s ``value`` gives them: ``(first byte in the caller's
    array, address in the image, bytes)`` each."""
    return b"".join(_RUN.pack(*t) for t in triples)


#: the kind csrc/centry.c's replay loop gives each simple ctypes type's values (struct rput)
_R_KINDS = {
    **{code: ctypes.sizeof(getattr(ctypes, name)) for code, name in (
        ("b", "c_byte"), ("h", "c_short"), ("i", "c_int"), ("l", "c_long"), ("q", "c_longlong"),
    )},
    **{code: 16 + ctypes.sizeof(getattr(ctypes, name)) for code, name in (
        ("B", "c_ubyte"), ("H", "c_ushort"), ("I", "c_uint"), ("L", "c_ulong"),
        ("Q", "c_ulonglong"),
    )},
    "d": 100,
    "f": 101,
}  # fmt: skip


class ReplayLoop:
    """A replay's loop in C (csrc/centry.c ``replay_run``): ``run(steps, start)`` makes the
    calls of ``steps`` (a tuple of ``(call, values)``) from ``start`` whose calls were
    taught it (:meth:`teach`), as the replay's compiled runs make them, and stops at the
    first it cannot: its index (nothing of that call made), or ``(index, code)`` where the
    call was made and its code or a value it left may differ from the recorded one (the
    replay compares in full).  A call it was not taught stops it, every time one it was
    told to leave to Python."""

    def __init__(self, table: Any) -> None:
        self._table = table
        self._keys: Any = None
        self._runners: Any = None
        self._held: dict[int, tuple[Any, ...]] = {}  # id(call) -> (call, its runner, keep)
        self.run: Callable[[tuple, int], Any] = lambda steps, start: start
        self._grow(1024)

    def _grow(self, slots: int) -> None:
        keys, runners = (_VP * slots)(), (_VP * slots)()
        mask = slots - 1
        for key, (_, runner, _) in self._held.items():
            h = (key >> 4) & mask
            while keys[h]:
                h = (h + 1) & mask
            keys[h], runners[h] = key, ctypes.addressof(runner)
        t = self._table
        t.mask = 0  # (no slot while they are replaced: one only, the first, looked at)
        self._keys, self._runners = keys, runners
        t.keys = ctypes.cast(keys, ctypes.POINTER(_VP))
        t.runners = ctypes.cast(runners, ctypes.POINTER(_VP))
        t.mask = mask

    def knows(self, call: Any) -> bool:
        return id(call) in self._held

    def teach(
        self,
        call: Any,
        fn: Any = None,
        args: tuple = (),
        rc: Any = None,
        sets: Iterable[tuple[Any, int]] = (),
        outs: Iterable[tuple[Any, int]] = (),
    ) -> bool:
        """``call`` made here: ``fn(*args)``, its code ``rc`` (an int), the values
        ``values[k]`` set into each object of ``sets`` before it and compared with each of
        ``outs`` after it (a simple ctypes object, or a writable memoryview of an array's
        bytes); or, with ``fn`` None, or an object of another kind, left to Python.  True
        where this loop makes it."""
        r = _Runner()
        keep: list[Any] = [call, fn, args, rc]
        puts = [_r_put(x, k, keep) for x, k in sets], [_r_put(x, k, keep) for x, k in outs]
        if (
            fn is None
            or type(rc) is not int
            or type(args) is not tuple
            or None in puts[0]
            or None in puts[1]
            or len(puts[0]) > _R_MAX
            or len(puts[1]) > _R_MAX
        ):
            r.python = 1
        else:
            r.fn, r.args, r.rc = id(fn), id(args), id(rc)
            r.nsets, r.nouts = len(puts[0]), len(puts[1])
            for into, got in zip((r.sets, r.outs), puts, strict=True):
                for j, put in enumerate(got):
                    into[j] = put
        if 2 * (len(self._held) + 1) > self._table.mask + 1:
            self._grow(2 * (self._table.mask + 1))
        key = id(call)
        self._held[key] = (call, r, keep)
        mask = self._table.mask
        h = (key >> 4) & mask
        while self._keys[h] and self._keys[h] != key:
            h = (h + 1) & mask
        self._runners[h] = ctypes.addressof(r)
        self._keys[h] = key  # (the key last: the runner is there when it is found)
        return not r.python


def _r_put(x: Any, k: int, keep: list[Any]) -> Any:
    """A value of the replay loop (``struct rput``): where ``x`` keeps it and its kind, None
    where the loop does not take it."""
    if type(x) is memoryview:
        if x.readonly or not x.contiguous or not x.nbytes:
            return None
        c = ctypes.c_ubyte.from_buffer(x)  # (its first byte; kept: the memory stays there)
        keep.append(c)
        return _RPut(ctypes.addressof(c), -x.nbytes, k)
    kind = _R_KINDS.get(getattr(type(x), "_type_", None))  # type: ignore[arg-type]
    if kind is None or not isinstance(x, ctypes._SimpleCData):  # type: ignore[attr-defined]
        return None
    if (kind % 16 or 8) != ctypes.sizeof(x) and kind < 100:
        return None
    keep.append(x)
    return _RPut(ctypes.addressof(x), kind, k)


def replay_loop() -> ReplayLoop | None:
    """A new replay loop in C (:class:`ReplayLoop`), None where the C entries are not
    available (:data:`REASON`)."""
    if _MAKE is None:
        return None
    return _MAKE.replay()  # type: ignore[attr-defined, no-any-return]
