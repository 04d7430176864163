"""The GT layer's machinery: return codes, the last-error ring, pointer arguments, GTN twins.

Every ``GT_*`` function is a thin wrapper over :class:`gtecat.controller.core.Controller`.
:func:`gt_function` turns exceptions into the manual's return codes through
one table (manual table 3-1) and keeps the reason (SOEM's error ring), so a GT
function never raises.  Pointer arguments accept what ctypes code passes:
``byref(c_short())``, ``pointer(...)``, ctypes arrays and string buffers, a
writable ``bytearray``/``memoryview``/numpy array, or a one-element list.
"""

from __future__ import annotations

import contextlib
import ctypes
import functools
import inspect
import logging
import os
import traceback
from collections import deque
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import Any

from gtecat.drives.abort import SdoAbort
from gtecat.drives.machine import MachineError
from gtecat.eni.errors import EniError, GtecatError

from .._attrs import own_dict
from ..controller.bank import BANK_READS, IN_PLACE, OPENED
from ..controller.bank_stream import STREAMED, call_streamed
from ..controller.card import refused
from ..controller.cards import CARD_CORES
from ..controller.core import Controller
from ..controller.core_view import AXES_PER_CORE, CoreView
from ..controller.epoch import EPOCH
from ..errors import (
    BusError,
    CommandError,
    ConfigMismatch,
    NoEniError,
    NoSlavesError,
    ParameterError,
)
from ..master.clock import ClockGroup, ClockMode
from . import centry as _centry
from . import fast as _fast
from .args import _NUMERIC, Ref, binder, core_arg, fast_binder, impl_params
from .fast import FAST_MAKERS, set_gates
from .fast_stream import STREAM_MAKERS
from .table import FUNCTIONS, NO_CORE_TWINS, SAME_PARAM_TWINS, Proto
from .units import with_units

log = logging.getLogger("gtecat.gt")

# manual table 3-1 and GT_InitEcatComm's codes
CMD_OK = 0
CMD_ERROR = 1
CMD_PARAM = 7
CMD_COMM = -1
CMD_OPEN = -6
CMD_NO_RESPONSE = -7
ECAT_MISMATCH = -8
ECAT_NO_ENI = -9
ECAT_NO_SLAVES = -10
#: what a function the table declares but gtecat does not emulate returns, whatever its
#: arguments, from Python, libgts (C) and C# alike: the vendor header's
#: ``CMD_ERROR_UNKNOWN`` (8, "unsupported command"), the code the vendor's own controller
#: gives a command its firmware does not know.  Not 1 (a known command that failed, table
#: 3-1) nor 7 (a bad argument): a caller can tell "not there" from "went wrong".  The
#: reason (GTE_GetLastError) names the function and its group, and the master log says it
#: once per function.
CMD_DECLARED = 8

#: exception type -> return code; first match wins (subclasses before bases)
ERROR_CODES: tuple[tuple[type[BaseException], int], ...] = (
    (ParameterError, CMD_PARAM),
    (CommandError, CMD_ERROR),
    (SdoAbort, CMD_ERROR),
    (ConfigMismatch, ECAT_MISMATCH),
    (NoEniError, ECAT_NO_ENI),
    (NoSlavesError, ECAT_NO_SLAVES),
    (EniError, ECAT_MISMATCH),
    (MachineError, CMD_PARAM),
    (BusError, CMD_ERROR),
    (GtecatError, CMD_ERROR),
)


class NotOpen(GtecatError):
    """A GT call before GT_Open (the host cannot reach a controller: -1)."""


@dataclass(frozen=True, slots=True)
class LastError:
    function: str
    code: int
    reason: str
    clock_ms: int


class _Cores(dict):
    """A card's cores (core -> its controller): every change of it opens or closes the fast
    readers' gates (:meth:`_Session.gates`)."""

    __slots__ = ()

    def __setitem__(self, key: Any, value: Any) -> None:
        super().__setitem__(key, value)
        _gates()

    def __delitem__(self, key: Any) -> None:
        super().__delitem__(key)
        _gates()

    def pop(self, *a: Any) -> Any:
        try:
            return super().pop(*a)
        finally:
            _gates()

    def popitem(self) -> Any:
        try:
            return super().popitem()
        finally:
            _gates()

    def clear(self) -> None:
        super().clear()
        _gates()

    def setdefault(self, key: Any, default: Any = None) -> Any:
        try:
            return super().setdefault(key, default)
        finally:
            _gates()

    def update(self, *a: Any, **kw: Any) -> None:
        super().update(*a, **kw)
        _gates()

    def __ior__(self, other: Any) -> Any:
        self.update(other)
        return self


def _gates() -> None:
    session = globals().get("SESSION")
    if session is not None:
        session.gates()


class _Session:
    """The open cards and cores (core 1 is the EtherCAT core), the current card, the
    error ring (:mod:`gtecat.controller.cards`)."""

    def __init__(self) -> None:
        #: card -> core -> its controller
        self.cards: dict[int, dict[int, Controller]] = {0: _Cores()}
        #: the card GT_* calls address (GT_SetCardNo): one per process, as the vendor's
        self.card = 0
        #: the current card's cores (``cards[card]``)
        self.controllers: dict[int, Controller] = self.cards[0]
        self._core = 1
        self._remote: Any = None
        #: in this process (no controller process attached), and the GT_* functions address
        #: core 1: what the fast paths answer (kept by the two properties below)
        self.local = self.plain = True
        #: the options the first card was opened with (resolved): the other cards' base
        self.base_options: Any = None
        #: every card and core of the process shares one time
        self.time = ClockGroup()
        self.views: dict[tuple[int, int], CoreView] = {}
        self.errors: deque[LastError] = deque(maxlen=64)  # the recent failures, oldest first
        self.last: LastError | None = None  # the most recent call's failure; None after a 0
        #: a reason the running call leaves although it succeeds (:func:`note`)
        self.note: str | None = None
        self.gates()

    def gates(self) -> None:
        """Open or close the fast readers' gates (:func:`fast.set_gates`): the controller
        of core 1 of the current card where it runs in this process on the lockstep or the
        auto clock (never a thread of its own: the realtime clock's cycles run beside the
        calls), for the GT_ functions where they address core 1 too.  Called wherever one of
        those can change (the card, the core, attaching, a card's cores; a controller's
        clock mode is its own for good)."""
        c = self.controllers.get(1)
        on = (
            c is not None
            and self._remote is None
            and c.clock.mode in (ClockMode.LOCKSTEP, ClockMode.AUTO)
        )
        # (cores 2.. are views of core 1's bus while the card has no core of its own)
        views = on and len(self.controllers) == 1
        set_gates(c if on and self._core == 1 else None, c if on else None, views)

    @property
    def core(self) -> int:
        """The core the GT_* functions address (GT_SetCore; the GTN_* ones name theirs)."""
        return self._core

    @core.setter
    def core(self, core: int) -> None:
        changed = core != self._core
        self._core = core
        self.plain = self.local and core == 1
        if changed:  # (a client's call names its core: most often the same one)
            self.gates()

    @property
    def remote(self) -> Any:
        """The controller process this session is attached to (``GT_Open(controller=...)``
        or GTECAT_CONTROLLER; :mod:`gtecat.native.client`), None: it runs in this process."""
        return self._remote

    @remote.setter
    def remote(self, remote: Any) -> None:
        self._remote = remote
        self.local = remote is None
        self.plain = self.local and self._core == 1
        self.gates()

    def select(self, card: int) -> None:
        """Make ``card`` the current card (GT_SetCardNo; checked by the caller)."""
        if card != self.card:
            self.card = card
            cores = self.cards.get(card)
            if cores is None:
                cores = self.cards[card] = _Cores()
            self.controllers = cores
            self.gates()

    @contextlib.contextmanager
    def selected(self, card: int, core: int | None = None) -> Iterator[None]:
        """Address ``card`` (and the GT_* functions core ``core``) for a while: a call of
        the multi-card ABI, of a client of the controller process, a motion program."""
        before, before_core = self.card, self.core
        self.select(card)
        if core is not None:
            self.core = core
        try:
            yield
        finally:
            self.select(before)
            self.core = before_core

    def where(self, ctl: Any) -> tuple[int, int] | None:
        """(card, core) of an open controller, None when it is not open here."""
        for card, cores in self.cards.items():
            for core, c in cores.items():
                if c is ctl:
                    return card, core
        return None

    def first(self) -> Controller | None:
        """Card 0's core 1, else the first open card's (what the process shows)."""
        c = self.cards.get(0, {}).get(1)
        if c is None:
            c = next((cores[1] for cores in self.cards.values() if 1 in cores), None)
        return c

    def all_controllers(self) -> list[Controller]:
        return [c for cores in self.cards.values() for c in cores.values()]

    def controller(self, core: int = 1) -> Controller:
        cores = self.controllers
        c = cores.get(core) if core == 1 else None
        if core > 1 and 1 in cores:
            c = self._core_view(core)  # the bus's axes of that core, where it has them
            if c is not None:
                # (a pop of nothing would move the gates too: every call of a core's twin)
                own = cores.pop(core) if core in cores else None
                if own is not None:  # a second core opened before the bus came up
                    self.time.leave(own.clock)
                    own.close()
            elif core <= CARD_CORES:
                c = cores.get(core) or self._open_core(core)
        if c is None:
            if self.remote is not None:
                raise NotOpen(
                    f"this session is attached to the controller at {self.remote.address}; "
                    "its Python objects stay in that process (the field side over the "
                    "socket: gtecat.native.client.field(), docs/native.md)"
                )
            if core != 1 and 1 in self.controllers:
                n = len(self.controllers[1].axes)
                cores = max(CARD_CORES, (n + AXES_PER_CORE - 1) // AXES_PER_CORE)
                raise ParameterError(
                    f"core {core} does not exist: cores 1..{cores} (core 1 is the EtherCAT "
                    f"core; core 2 the card's second core, or bus axes 33..64 on a bus of "
                    f"more than {AXES_PER_CORE} axes)"
                )
            raise NotOpen(self.not_open())
        return c

    def not_open(self) -> str:
        if self.card:
            return f"card {self.card} is not open: call GT_Open after GT_SetCardNo({self.card})"
        return "the controller is not open: call GT_Open first"

    def _core_view(self, core: int) -> Any:
        """Core ``core`` > 1: bus axes 32·(core-1)+1 .. 32·core (gtecat.controller.core_view)."""
        base = self.controllers[1]
        key = (self.card, core)
        view = self.views.get(key)
        if view is None or view._base is not base:
            view = self.views[key] = CoreView(base, core)
        return view if view.exists else None

    def _open_core(self, core: int) -> Controller:
        """The card's second core, opened at its first call (gtecat.controller.cards)."""
        from ..controller.cards import options_for

        card = self.controllers[1].options.card  # the card's own pulse personality
        base = self.base_options or self.controllers[1].options
        ctl = Controller(options_for(base, self.card, core, hardware=card))
        self.controllers[core] = ctl
        self.time.join(ctl.clock)
        return ctl

    def close_card(self) -> list[Controller]:
        """Close the current card, every core of it; the controllers closed."""
        closed = list(self.controllers.values())
        self.controllers.clear()
        for key in [k for k in self.views if k[0] == self.card]:
            del self.views[key]
        for c in closed:
            self.time.leave(c.clock)
        return closed


SESSION = _Session()
# (its attributes in a dict of its own, read quick - gtecat._attrs - and the one dict the
# C entries of GTE_Wait and GT_GetClock look into for its last error: made once, here,
# before any entry is made)
own_dict(SESSION)


def close_all() -> None:
    """Close every card of this process and make card 0 (core 1) the current one (a
    test's clean start; GT_Close closes the current card only)."""
    for card in sorted(SESSION.cards):
        SESSION.select(card)
        REGISTRY["GT_Close"]()
    SESSION.select(0)
    SESSION.core = 1


_AUTO = ClockMode.AUTO
_LOCKSTEP = ClockMode.LOCKSTEP
REGISTRY: dict[str, Callable[..., int]] = {}
#: the GT calls are being listened to (gtecat.faults: a recording, the application checks):
#: a controller process then runs every call through REGISTRY, none on a fast path
TAPPED = False


def code_for(exc: BaseException) -> int:
    if isinstance(exc, NotOpen):
        return CMD_COMM
    for etype, code in ERROR_CODES:
        if isinstance(exc, etype):
            return code
    return CMD_NO_RESPONSE


def _record(name: str, code: int, reason: str) -> None:
    ms = 0
    c = SESSION.controllers.get(1)
    if c is not None:
        ms = c.clock_ms()
    SESSION.last = LastError(name, code, reason, ms)
    SESSION.errors.append(SESSION.last)
    EPOCH.n += 1  # (a read the C entries keep clears it: they ask again)


def note(reason: str) -> None:
    """Leave ``reason`` for GTE_GetLastError although the running call returns 0: something
    the caller must hear of that is not an error of this call (a homing search that cannot
    end).  It reads ``NAME returned 0: reason`` and, like any reason, lasts until the next
    call."""
    SESSION.note = reason


def _note(name: str, reason: str) -> LastError:
    c = SESSION.controllers.get(1)
    return LastError(name, 0, reason, c.clock_ms() if c is not None else 0)


def fail(code: int, reason: str) -> int:
    """Return ``code`` from a GT function with a reason (for non-exception refusals)."""
    raise _Refusal(code, reason)


class _Refusal(Exception):
    def __init__(self, code: int, reason: str) -> None:
        super().__init__(reason)
        self.code = code


def advance(ctl: Any, name: str, rc: int) -> int:
    """The host-call latency after a GT call (cycles may run, programs step): whatever they
    raise is turned into a code and a reason like the call's own errors, never let out."""
    clock = ctl.clock
    mode = clock.mode
    if mode is _LOCKSTEP:  # (Clock.on_call does nothing in lockstep)
        return rc
    if mode is _AUTO:
        # Clock.on_call in the common case, inline: the latency runs no cycle and no other
        # clock shares this one's time (as the readers' C entries add it: centry.c latency)
        q = clock.quick
        pending = q[0] + q[1]
        if q[3] and pending < q[2]:
            q[0] = pending
            return rc
    try:
        if mode is _AUTO:
            # one cycle due on a clock alone: the controller's quick way where it takes it
            # (Controller.due_cycle), else the clock's general way
            if q[3] and pending < 2 * q[2]:
                with clock.lock:
                    pending = q[0] + q[1]  # (as it stands with the lock held)
                    if q[2] <= pending < 2 * q[2] and q[1] >= 0 and ctl.due_cycle(pending):
                        return rc
            with clock.lock:  # (its cycles: one thread's at a time, as a call's own)
                clock.advance_ns(q[1])  # (Clock.on_call in the auto clock)
        else:  # (realtime: the call yields, the lock free for the cycle thread)
            clock.on_call()
    except Exception as e:
        return cycle_failed(name, e, rc)
    return rc


def cycle_failed(name: str, e: Exception, rc: int) -> int:
    """What the cycles after call ``name`` raised, as its code and reason (``rc``: the call's
    own code, which stands when it is not 0); inside an ``except``."""
    code = code_for(e)
    if code == CMD_NO_RESPONSE:
        log.error("%s: internal error in the cycle\n%s", name, traceback.format_exc())
        _record(name, code, f"internal error in the emulator's cycle: {type(e).__name__}: {e}")
    else:
        _record(name, code, f"in the cycles after the call: {e}")
    return rc or code


_fast.CYCLE_FAILED[:] = [cycle_failed]


def call_failed(name: str, e: Exception, ctl: Any, core: Any) -> int:
    """The code and reason of an exception GT call ``name`` raised (the GT layer never
    raises), its host latency run after it; inside an ``except``."""
    if isinstance(e, _Refusal):
        rc = e.code
        _record(name, rc, str(e))
    else:
        rc = code_for(e)
        if rc == CMD_NO_RESPONSE:
            log.error("%s: internal error\n%s", name, traceback.format_exc())
            _record(name, rc, f"internal error in the emulator: {type(e).__name__}: {e}")
        else:
            _record(name, rc, str(e))
    if ctl is None and isinstance(core, int):
        ctl = SESSION.controllers.get(core)
    if ctl is not None:
        rc = advance(ctl, name, rc)
    return rc


def call_done(name: str) -> None:
    """A call that returned 0: GTE_GetLastError speaks of the most recent call only -
    nothing, or a note of something the call found wrong without failing (:func:`note`)."""
    if SESSION.note is None:
        SESSION.last = None
    else:
        note_text, SESSION.note = SESSION.note, None
        SESSION.last = _note(name, note_text)


#: the GT functions that change nothing but let controller time pass (their cycles count)
_TIME_ONLY = frozenset({"GTE_Wait"})


def gt_function(fn: Callable[..., int | None]) -> Callable[..., int]:
    """Make ``fn`` a GT function: never raises, returns a code, costs a host call.

    The function table (:mod:`gtecat.gt.table`) must declare ``fn``'s name: its
    arguments are checked and converted from the table (:mod:`gtecat.gt.args`)
    before ``fn`` runs.  ``fn`` receives the core's :class:`Controller` first
    when its first parameter is ``ctl``, then the table's parameters in order,
    and returns ``None``/0 on success.  Registers ``GT_x`` and its ``GTN_x``
    twin (``GTE_`` helpers get none).
    """
    name = fn.__name__
    proto = FUNCTIONS.get(name)
    if proto is None:
        raise RuntimeError(f"{name} is not in the function table (gtecat/gt/table.py)")
    positional, keyword_only = impl_params(fn)
    params = positional + keyword_only
    needs_ctl = bool(params) and params[0] == "ctl"
    # the table binder (args.binder): made by the first call that binds through it, not at
    # import - most of the ~400 functions are never called in a process (see _binder below)
    bind: Any = None
    card_refused = refused(name)
    opens = name == "GT_Open"
    bank_read = name in BANK_READS  # reads a banked axis through the bank: no release
    in_place = name in IN_PLACE  # runs on its axis's claimed row in place
    opened = name in OPENED  # takes its axis out of the bank for the call alone
    streamed = name in STREAMED  # runs on its axis's claimed row, the row kept (bank_stream)
    #: a fast path whose first parameter is an axis (its GTN_ twin of core c > 1 takes the
    #: bus axis on core 1's fast path; a coordinate system, a type, an offset: its table)
    by_axis = bool(proto.params) and proto.params[0].name in ("axis", "profile", "encoder")
    #: where such a function takes a count of axes from its first (GT_GetSts(axis, p, count,
    #: pClock)): a span, which must lie inside the core for core 1's fast path to answer it
    #: as the view would (else the core's table path: its own span rule and reason)
    count_at = (
        next((k for k, p in enumerate(proto.params) if p.name == "count"), -1) if by_axis else -1
    )
    #: what a call moves the readers' epoch by (:mod:`gtecat.controller.epoch`): 0 for a call
    #: that changes nothing but lets time pass, whose cycles move it themselves (Clock.counted)
    #: - a wait then leaves the steady verdict of the bus to the next run of cycles
    #: (Controller._steady_marks) instead of asking Master.steady again at every wait
    moves = 0 if name in _TIME_ONLY else 1

    def call(core: Any, args: tuple, kwargs: dict) -> int:
        before = SESSION.last
        gtn = core is not _GT
        try:
            address = _attach_address(kwargs) if opens else ""
            if gtn:
                core = core_arg(core)
                if not needs_ctl and core != 1:  # GTN_Open/GTN_Close: no other core exists
                    raise ParameterError(f"core={core}: the EtherCAT core is 1")
            else:
                core = SESSION._core  # GT_SetCore: 1 unless the program chose another
            values, extra = (bind or _binder())(args, kwargs)
        except Exception as e:
            return failed(e, None, core, before)
        return run(core, values, extra, address, before, gtn)

    def _binder() -> Any:
        """The table binder of ``fn``, made once (two threads may both make it: the same)."""
        nonlocal bind
        if bind is None:
            bind = binder(proto, fn)
        return bind

    def run(
        core: int, values: Any, extra: dict, address: str, before: Any, gtn: bool = False
    ) -> int:
        """The call with its arguments bound (``core``: the core it addresses; ``gtn``: the
        ``GTN_`` twin was called)."""
        ctl = None
        # (and before it: the cycles the call runs itself see what it changed before them -
        # Controller._run_cycles keeps the bus's steadiness while the epoch stays)
        EPOCH.n += moves
        try:
            if address or SESSION._remote is not None:  # attached: the controller process runs it
                from ..native.client import remote_call

                rc = remote_call(SESSION, name, gtn, core, values, extra, address)
            elif needs_ctl:
                ctl = SESSION.controllers.get(1) if core == 1 else None
                if ctl is None:
                    ctl = SESSION.controller(core)
                if card_refused and ctl.card is not None:  # an EtherCAT function on a card
                    raise CommandError(ctl.card.refusal(name))
                bank = ctl.bank
                # atomic with respect to the cycle thread (realtime) and to the calls of the
                # application's other threads (their cycles, their releases): the bank's
                # release included - given back while a cycle steps the bank, an axis's
                # objects would miss that cycle or get it twice (the vendor's library
                # serialises its callers' threads too)
                with ctl.clock.lock:
                    if bank is None or bank_read:
                        rc = fn(ctl, *values, **extra) if extra else fn(ctl, *values)
                    elif in_place and not extra:  # (a Trap move's start: its row in place)
                        rc = bank.call_in_place(ctl, proto, values, lambda: fn(ctl, *values))
                    elif opened and not extra:  # (a drive homing's set-up: out for the call)
                        rc = bank.call_opened(ctl, proto, values, lambda: fn(ctl, *values))
                    elif streamed and not extra:  # (a new target, a PT point: the row kept)
                        rc = call_streamed(bank, ctl, proto, values, lambda: fn(ctl, *values))
                    else:
                        bank.before_call(ctl, proto, values)  # the axes it names go back first
                        rc = fn(ctl, *values, **extra) if extra else fn(ctl, *values)
                    # (and once more below: another thread's cycles, once the lock is free,
                    # see what the call changed - Controller._run_cycles)
                    EPOCH.n += moves
            else:
                rc = fn(*values, **extra) if extra else fn(*values)
            if rc is None:
                rc = 0
            elif type(rc) is not int:
                rc = int(rc)
            if rc == 0:
                if SESSION.note is None:  # (call_done, inline: every call asks)
                    SESSION.last = None
                else:
                    call_done(name)
            elif SESSION.last is before:  # no reason recorded by a call made inside
                _record(name, rc, "no reason given")
        except Exception as e:
            return failed(e, ctl, core, before)  # (its _record: the epoch grows)
        EPOCH.n += moves  # (what the call changed: the values the C entries keep ask again)
        if ctl is None:
            ctl = SESSION.controllers.get(core)
        if ctl is not None and ctl.clock.mode is not _LOCKSTEP:  # (advance: nothing then)
            rc = advance(ctl, name, rc)
        return rc

    def failed(e: Exception, ctl: Any, core: Any, before: Any) -> int:
        return call_failed(name, e, ctl, core)

    compiled: list[Any] = []  # the compiled binder, made at the first call (args.fast_binder)

    def _convs() -> list[Any]:
        """The table binder's converters (the compiled binder asks for them at its first
        argument of a shape it does not bind inline: a call of plain arguments makes no
        table binder)."""
        return (bind or _binder()).convs  # type: ignore[attr-defined,no-any-return]

    @functools.wraps(fn)
    def gt(*args: Any, **kwargs: Any) -> int:
        if not kwargs:
            if compiled:
                values = compiled[0](*args)  # None: not a plain shape (the table binder's)
                if values is not None:
                    return run(SESSION._core, values, _NO_KW, "", SESSION.last)
            elif not opens:  # GT_Open: always the table path (its keyword options)
                compiled.append(fast_binder(proto, _convs))
                return table(*args)
        return call(_GT, args, kwargs)

    # (the table path itself: ``gt`` is the fast path's name once there is one, and the first
    # call of ``gt.slow`` must not go round through the fast path)
    table = gt

    gt.__doc__ = with_units(name, fn.__doc__)  # one units table (gtecat/gt/units.py)
    fast = None
    make = FAST_MAKERS.get(name) or STREAM_MAKERS.get(name)
    if make is not None:
        slow = gt  # (the common shapes up front: gt.fast)
        fast = gt = functools.wraps(slow)(make(name, slow, SESSION, advance))
        gt.slow = slow  # type: ignore[attr-defined]
        # (its C entry answers the table's keyword names too: GT_GetSts(axis=1, pSts=p))
        _centry.keyword_names(gt, [p.name for p in proto.params])
    gt.__signature__ = _signature(proto, fn, keyword_only)  # type: ignore[attr-defined]
    gt.prototype = proto  # type: ignore[attr-defined]
    REGISTRY[name] = gt
    if proto.gtn:
        own = NO_CORE_TWINS.get(name)
        if name in SAME_PARAM_TWINS:  # GTN_Compile(pFileName, pWrongInfo): no core either
            own = tuple((p.name, p.default or "") for p in proto.params)
        if own is not None:
            # the vendor's GTN_Open(channel=5, param=1) / GTN_Close(): no core; the core-first
            # form of earlier gtecat releases (one argument more, or core=) still works
            def gtn(*args: Any, **kwargs: Any) -> int:
                if len(args) > len(own) or "core" in kwargs:
                    if args:
                        return call(args[0], args[1:], kwargs)
                    return call(kwargs.pop("core"), (), kwargs)
                return call(_GT, args, kwargs)

        else:

            def gtn(*args: Any, **kwargs: Any) -> int:
                if args:
                    c = args[0]
                    if fast is not None and type(c) is int and not kwargs and SESSION.plain:
                        if c == 1:
                            return fast(*args[1:])  # core 1: the GT_ function's fast path
                        if (
                            by_axis
                            and len(args) > 1
                            and type(args[1]) is int
                            and 1 <= args[1] <= AXES_PER_CORE
                        ):
                            # core c's axis, where core c is a view of core 1's bus (made
                            # already): the bus axis core 1 takes by its own number
                            # (core_view: the same controller, only the numbering differs)
                            base = SESSION.controllers.get(1)
                            view = SESSION.views.get((SESSION.card, c))
                            bus = args[1] + AXES_PER_CORE * (c - 1)
                            # (a span: every axis of it the core's and on the bus)
                            last = bus
                            if 0 <= count_at < len(args) - 1:
                                k = args[count_at + 1]
                                last = (
                                    bus + k - 1
                                    if type(k) is int and 1 <= k <= AXES_PER_CORE - args[1] + 1
                                    else 0
                                )
                            if (
                                base is not None
                                and c not in SESSION.controllers  # (not a card's own core)
                                and view is not None
                                and view._base is base
                                and bus in base.axes
                                and last in base.axes
                            ):
                                return fast(bus, *args[2:])
                    if type(c) is int and not kwargs and -0x8000 <= c <= 0x7FFF:
                        # a plain core (core_arg's check) and the GT_ function's compiled
                        # binder of the rest, as for GT_x (made at the twin's first call,
                        # which binds through it too, as the GT_ function's first call does)
                        if not compiled and not opens:
                            compiled.append(fast_binder(proto, _convs))
                        if compiled:
                            values = compiled[0](*args[1:])
                            if values is not None and (needs_ctl or c == 1):
                                return run(c, values, _NO_KW, "", SESSION.last, True)
                    return call(c, args[1:], kwargs)
                return call(kwargs.pop("core", None), (), kwargs)

        if fast is not None and hasattr(fast, "gtn"):  # the reader's own GTN_ fast path
            fast.gtn_slow = gtn  # type: ignore[attr-defined]  # every other shape
            gtn = functools.wraps(gtn)(fast.gtn)  # type: ignore[attr-defined]
        gtn.__name__ = "GTN_" + name[3:]
        gtn.__doc__ = with_units(
            name,
            f"``{name}`` of the whole controller (the vendor's GTN header: no core)."
            if own is not None
            else f"``{name}`` with ``short core`` first (core 1 is the EtherCAT core).",
        )
        gtn.prototype = proto  # type: ignore[attr-defined]
        REGISTRY[gtn.__name__] = gtn
    return gt


_GT: Any = object()  # GT_x: the session's core (GT_SetCore), no core argument
_NO_KW: dict = {}  # (never written: the implementations take no keywords from a plain call)


def _attach_address(kwargs: dict) -> str:
    """GT_Open's ``controller=`` (taken out of ``kwargs``), else ``GTECAT_CONTROLLER``: the
    controller process to attach to; "" (or ``"local"``) runs the controller in this process."""
    address = kwargs.pop("controller", None)
    if address is None:
        address = os.environ.get("GTECAT_CONTROLLER", "")
    if not isinstance(address, str | os.PathLike):
        raise ParameterError(f"controller={address!r}: an address is needed, e.g. unix:/path")
    address = os.fspath(address).strip()
    return "" if address == "local" else address


#: (name, C++ default, is a double) -> its inspect.Parameter: the ~400 signatures made at
#: import share ~300 parameters (``short axis`` in most), each made once (immutable)
_PARAMETERS: dict[tuple[str, str | None, bool], inspect.Parameter] = {}
#: the signatures of the same parameters, each made once (immutable too): ~400 functions,
#: ~190 distinct parameter lists
_SIGNATURES: dict[tuple[tuple[str, str | None, bool], ...], inspect.Signature] = {}


def _signature(proto: Proto, fn: Callable[..., Any], keyword_only: list[str]) -> inspect.Signature:
    """The Python signature shown by help(): the table's parameters and defaults, then the
    implementation's keyword-only options (GT_Open's ``eni=...``)."""
    keys = tuple((p.name, p.default, p.is_float) for p in proto.params)
    if not keyword_only:
        sig = _SIGNATURES.get(keys)
        if sig is not None:
            return sig
    out = []
    for p, key in zip(proto.params, keys, strict=True):
        q = _PARAMETERS.get(key)
        if q is None:
            try:
                d = p.default_value()
            except KeyError:
                d = inspect.Parameter.empty
            q = _PARAMETERS[key] = inspect.Parameter(
                p.name, inspect.Parameter.POSITIONAL_OR_KEYWORD, default=d
            )
        out.append(q)
    if keyword_only:
        kw = inspect.Parameter.KEYWORD_ONLY
        out += [q for q in inspect.signature(fn).parameters.values() if q.kind is kw]
        return inspect.Signature(out)
    sig = _SIGNATURES[keys] = inspect.Signature(out)
    return sig


def last_error() -> LastError | None:
    """Why the most recent GT call returned non-zero; None when it returned 0.

    Per call, like a return code: every GT function that returns 0 clears it, so the
    reason never belongs to an older call.  ``SESSION.errors`` keeps the recent failures.
    """
    return SESSION.last


# --- pointer arguments ---------------------------------------------------------------------
# The binder (gtecat.gt.args) has turned every pointer argument into a Ref (or None for an
# optional NULL); these are the implementations' ways to use them.
def store(ptr: Ref | None, value: Any) -> None:
    """``*ptr = value`` (None = an optional NULL pointer: nothing is written)."""
    if ptr is not None:
        keep = ptr._keep
        t = type(keep)
        if t is ptr.elem and ptr.nbytes == _sizeof(t):  # byref(x) or x: Ref's common case
            bounds = _PLAIN.get(t, _NOT_PLAIN)
            if bounds is None:  # a double: as Ref.store_values writes it
                keep.value = value
                return
            if type(value) is int and bounds is not _NOT_PLAIN and bounds[0] <= value <= bounds[1]:
                keep.value = value
                return
        ptr.store_values([value])


def _plain_numbers() -> dict[type, tuple[int, int] | None]:
    """The ctypes number types :meth:`Ref.store_values` writes as ``x.value = v``: None for
    the floating ones (any value), else the integer range (the others: its checks)."""
    out: dict[type, tuple[int, int] | None] = {}
    for t in _NUMERIC:
        if t._type_ in "fdg":
            out[t] = None
        else:
            bits = 8 * ctypes.sizeof(t)
            signed = t._type_.islower()
            out[t] = (-(1 << (bits - 1)), (1 << (bits - 1)) - 1) if signed else (0, (1 << bits) - 1)
    return out


_PLAIN = _plain_numbers()
_NOT_PLAIN: Any = object()
_sizeof = ctypes.sizeof


def store_array(ptr: Ref | None, values: list[Any]) -> None:
    """``ptr[0..n-1] = values``; refused when the memory behind ``ptr`` is smaller."""
    if ptr is not None:
        ptr.store_values(values)


def load(ptr: Ref) -> Any:
    """``*ptr``."""
    return ptr.load_values(1)[0]


def store_bytes(ptr: Ref | None, data: bytes) -> None:
    """Copy raw bytes into a buffer argument (``unsigned char *pValue``)."""
    if ptr is None:
        raise ParameterError("pValue is NULL")
    ptr.store_bytes(data)


def load_bytes(ptr: Ref | None, n: int) -> bytes:
    """Read ``n`` bytes from a buffer argument (``unsigned char *pValue``)."""
    if ptr is None:
        raise ParameterError("pValue is NULL")
    return ptr.load_bytes(n)


def struct_arg(ptr: Ref | None, cls: type[ctypes.Structure], name: str) -> ctypes.Structure:
    """The structure behind ``byref(s)``, ``pointer(s)``, ``s`` itself or a big enough buffer
    (a caller's own class with the vendor layout works: the memory is viewed as ``cls``)."""
    if ptr is None:
        raise ParameterError(f"{name} is NULL")
    return ptr.struct(cls)


def check_range(name: str, value: int, lo: int, hi: int) -> int:
    try:
        v = int(value)
    except (TypeError, ValueError):
        raise ParameterError(f"{name}={value!r} is not an integer") from None
    if not lo <= v <= hi:
        raise ParameterError(f"{name}={v} out of range {lo}..{hi}")
    return v
