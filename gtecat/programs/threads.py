"""The controller side of motion programs: memory, 32 threads, 32 data pages, the scheduler.

A :class:`ProgramRuntime` belongs to one controller (it is created by the first
``GT_Download`` and dies with the controller at ``GT_Close``, so a download does
not survive a power cycle, 10.3.4).  It holds:

* the downloaded :class:`~gtecat.programs.model.Program`, linked into one Python
  closure per instruction;
* the global area (1024 words) and 32 data pages of 1024 words; ``GT_Download``
  zeroes them and sets the globals' initial values; locals live on the page a
  thread is bound to and keep their values between runs (so the host can set a
  function's parameters with ``GT_SetVarValue`` before ``GT_RunThread``, 10.3.8);
* 32 threads.  Binding rules (10.3.5, entry 6): a thread runs one function; one
  function may be bound to several threads; a page serves one thread only (binding
  a page another thread holds returns 1); a running or paused thread cannot be
  rebound (1).

**Time.**  Every controller cycle (a ``before_cycle`` hook: first in the cycle,
before the axes plan, so a ``GT_Update`` from a program starts in that cycle) grants
``speed`` x cycle
instructions (default 100 per millisecond, 10.2; fractions carry over while a
thread runs).  The running threads share them round robin, one instruction each
in turn, so two threads' consecutive instructions may be interleaved (the 10.2
note) and each instruction is atomic.  Every instruction costs one slot: an
assignment, an operation, a cast, a jump, a return, a GT call (which runs inside
the controller, without the host call latency).  ``GT_Delay(ms)`` costs one slot
and then the thread sleeps ``ms`` of controller time.  A thread started by
``GT_RunThread`` executes from the next cycle.  A GT function that waits for cycles
of its own (``GT_AxisOn`` waits until the drive is enabled) holds the program
processor like any instruction: the cycles it runs execute no other instruction,
and the cycle's remaining instructions are spent.  (In the ``realtime`` clock mode
such a call cannot get its cycles from inside the cycle thread and times out.)

**Status** (``TThreadSts``): ``run`` 1 running (sleeping in ``GT_Delay`` included),
2 paused, 0 otherwise (never run, returned, stopped, failed); ``error`` the return
of the instruction executing (0, or the code of the failure); ``result`` the
function's return value; ``line`` the source line executing (the last one once the
thread ended).

**Runtime errors** stop the thread with ``error`` and ``line`` set: a GT call that
returns non-zero (its code: 1, 7 ...), and the program's own faults (:class:`Fault`).
"""

from __future__ import annotations

import ctypes
import logging
from collections.abc import Callable
from dataclasses import dataclass, replace
from enum import IntEnum
from typing import Any

from . import fixed
from .gtcalls import prototype
from .model import (
    PAGE_WORDS,
    PAGES,
    THREADS,
    BinOp,
    Function,
    Instr,
    Kind,
    Op,
    Operand,
    Program,
    UnOp,
    Variable,
    VarType,
)

log = logging.getLogger("gtecat.programs")

DEFAULT_SPEED = 100.0  #: instructions per millisecond of controller time (10.2)
GLOBAL_WORDS = 1024


class Fault(IntEnum):
    """``TThreadSts.error`` of a program's own runtime errors (GT calls give their codes)."""

    DIVISION_BY_ZERO = 101  #: ``/`` or ``%`` by zero
    INDEX_OUT_OF_RANGE = 102  #: a variable index beyond the array
    VALUE_OUT_OF_RANGE = 103  #: a GT function's double result beyond the 16.16 range
    PAGE_TAKEN = 104  #: GT_SetDataPage to a page another thread holds
    BAD_ARGUMENT = 7  #: a builtin's argument out of range (as a GT function's 7)
    INTERNAL = 199  #: the emulator failed to run an instruction (a defect of ours; logged)


class ProgramError(Exception):
    """A runtime error of an instruction (stops the thread)."""

    def __init__(self, code: int, message: str) -> None:
        super().__init__(message)
        self.code = int(code)


class ThreadState(IntEnum):
    IDLE = 0
    RUNNING = 1
    PAUSED = 2


class RuntimeRefusal(Exception):
    """A host request the runtime refuses: ``code`` 1 (command) or 7 (parameter)."""

    def __init__(self, code: int, message: str) -> None:
        super().__init__(message)
        self.code = code


@dataclass
class ThreadStatus:
    run: int
    error: int
    result: float
    line: int


class Thread:
    __slots__ = (
        "error",
        "function",
        "line",
        "mem",
        "number",
        "page",
        "pc",
        "reason",
        "result",
        "state",
        "wake_ns",
    )

    def __init__(self, number: int) -> None:
        self.number = number
        self.function: Function | None = None
        self.page = -1  #: the page of the binding (current page: ``mem``)
        self.mem: list[int] = []
        self.state = ThreadState.IDLE
        self.pc = 0
        self.line = 0
        self.error = 0
        self.result = 0.0
        self.wake_ns = 0
        self.reason = ""


Caller = Callable[[str, tuple], tuple[int, str]]
_Step = Callable[[Thread], None]


class ProgramRuntime:
    """Downloaded program, memory and threads of one controller."""

    def __init__(self, call: Caller, speed: float = DEFAULT_SPEED) -> None:
        self.call = call  #: runs a GT function: (name, args) -> (code, reason)
        self.speed = float(speed)
        self.program: Program | None = None
        self.globals: list[int] = [0] * GLOBAL_WORDS
        self.pages: list[list[int]] = [[0] * PAGE_WORDS for _ in range(PAGES)]
        self.threads = [Thread(i) for i in range(THREADS)]
        self.page_owner: dict[int, int] = {}
        self.executed = 0  #: instructions run since the download
        self.now_ns = 0
        self._credit = 0.0
        self._next = 0  # round robin: the thread to serve first
        self._steps: list[_Step] = []
        self._busy = False
        self._lines: list[int] = []

    # --- download ---------------------------------------------------------------------------
    def download(self, program: Program) -> None:
        """Load ``program``: every thread stops and is unbound, memory is zeroed."""
        steps = [self._link(program, ins, pc) for pc, ins in enumerate(program.code)]
        self.program = program
        self._steps = steps
        self._lines = [ins.line for ins in program.code]
        self.globals[:] = [0] * GLOBAL_WORDS
        for addr, word in program.global_init:
            self.globals[addr] = word
        for page in self.pages:
            page[:] = [0] * PAGE_WORDS
        self.threads = [Thread(i) for i in range(THREADS)]
        self.page_owner.clear()
        self.executed = 0
        self._credit = 0.0

    def require_program(self) -> Program:
        if self.program is None:
            raise RuntimeRefusal(1, "no motion program is downloaded (call GT_Download first)")
        return self.program

    # --- threads ----------------------------------------------------------------------------
    def bind(self, thread: int, fun_id: int, page: int) -> None:
        program = self.require_program()
        if not 0 <= fun_id < len(program.functions):
            raise RuntimeRefusal(
                7,
                f"funId={fun_id}: the program has functions 0..{len(program.functions) - 1} "
                "(GT_GetFunId gives the id)",
            )
        th = self.threads[thread]
        if th.state is not ThreadState.IDLE:
            raise RuntimeRefusal(
                1,
                f"thread {thread} is {th.state.name.lower()}: it cannot be bound to another "
                "function until it has ended (GT_StopThread)",
            )
        owner = self.page_owner.get(page)
        if owner is not None and owner != thread:
            raise RuntimeRefusal(
                1,
                f"data page {page} belongs to thread {owner}: a page serves one thread only "
                "(10.3.5); bind another page",
            )
        self._release(thread)
        self.page_owner[page] = thread
        th.function = program.functions[fun_id]
        th.page = page
        th.mem = self.pages[page]

    def _release(self, thread: int) -> None:
        for p in [p for p, t in self.page_owner.items() if t == thread]:
            del self.page_owner[p]

    def _bound(self, thread: int) -> Thread:
        self.require_program()
        th = self.threads[thread]
        if th.function is None:
            raise RuntimeRefusal(1, f"thread {thread} is not bound (call GT_Bind first)")
        return th

    def run(self, thread: int) -> None:
        th = self._bound(thread)
        if th.state is ThreadState.RUNNING:
            raise RuntimeRefusal(1, f"thread {thread} is already running")
        if th.state is ThreadState.PAUSED:
            th.state = ThreadState.RUNNING
            return
        f = th.function
        assert f is not None
        for p in [p for p, t in self.page_owner.items() if t == thread and p != th.page]:
            del self.page_owner[p]  # pages taken by GT_SetDataPage in the last run
        th.mem = self.pages[th.page]
        th.pc = f.entry
        th.line = self._lines[f.entry]
        th.error = 0
        th.result = 0.0
        th.reason = ""
        th.wake_ns = 0
        th.state = ThreadState.RUNNING

    def pause(self, thread: int) -> None:
        th = self._bound(thread)
        if th.state is ThreadState.IDLE:
            raise RuntimeRefusal(1, f"thread {thread} is not running")
        th.state = ThreadState.PAUSED

    def stop(self, thread: int) -> None:
        th = self._bound(thread)
        th.state = ThreadState.IDLE

    def stop_all(self) -> None:
        for th in self.threads:
            th.state = ThreadState.IDLE

    def status(self, thread: int) -> ThreadStatus:
        th = self.threads[thread]
        return ThreadStatus(int(th.state), th.error, th.result, th.line)

    def reason(self, thread: int) -> str:
        return self.threads[thread].reason

    # --- variables --------------------------------------------------------------------------
    def function_id(self, name: str) -> int:
        f = self.require_program().function(name)
        if f is None:
            names = ", ".join(x.name for x in self.require_program().functions)
            raise RuntimeRefusal(1, f"no function {name!r} in the program (it has {names})")
        return f.id

    def variable(self, function: str | None, name: str) -> Variable:
        program = self.require_program()
        if not function:
            v = program.global_var(name)
            if v is None:
                raise RuntimeRefusal(1, f"no global variable {name!r} in the program")
            return v
        f = program.function(function)
        if f is None:
            raise RuntimeRefusal(1, f"no function {function!r} in the program")
        v = f.local(name)
        if v is None:
            raise RuntimeRefusal(1, f"no variable {name!r} in function {function}")
        return v

    def _locate(
        self, page: int, var_id: int, data_type: int, name: str, count: int
    ) -> tuple[list[int], Variable, int]:
        program = self.require_program()
        if page == -1:
            area, candidates = self.globals, list(program.globals)
            where = "the globals"
        else:
            area = self.pages[page]
            owner = self.page_owner.get(page)
            fs = program.functions
            if owner is not None and self.threads[owner].function is not None:
                fs = (self.threads[owner].function,)  # type: ignore[assignment]
            candidates = [v for f in fs for v in f.locals]
            where = f"data page {page}"
        found = [v for v in candidates if v.address <= var_id < v.address + v.size]
        if name:
            found = [v for v in found if v.name[:31] == name[:31]]
        if not found:
            what = f"{name!r} (id {var_id})" if name else f"id {var_id}"
            raise RuntimeRefusal(
                7,
                f"variable {what} is not in {where}"
                + (" (locals use pages 0..31, globals page -1)" if page != -1 else ""),
            )
        var = found[0]
        if data_type != var.type:
            raise RuntimeRefusal(
                7,
                f"pVarInfo says dataType {data_type}; {var.name} is {var.type.c_name} "
                f"({int(var.type)})",
            )
        offset = var_id - var.address
        if offset + count > var.size:
            raise RuntimeRefusal(
                7,
                f"count={count} from element {offset} runs past {var.name} ({var.size} element(s))",
            )
        return area, var, var.address + offset

    def get_values(self, page: int, var_id: int, data_type: int, name: str, count: int) -> list:
        area, var, at = self._locate(page, var_id, data_type, name, count)
        words = area[at : at + count]
        if var.type is VarType.DOUBLE:
            return [fixed.to_float(w) for w in words]
        return [float(w) for w in words]

    def set_values(
        self, page: int, var_id: int, data_type: int, name: str, values: list[float]
    ) -> None:
        area, var, at = self._locate(page, var_id, data_type, name, len(values))
        words = []
        for i, v in enumerate(values):
            try:
                if var.type is VarType.DOUBLE:
                    words.append(fixed.from_float(float(v)))
                else:
                    words.append(fixed.int_from_float(float(v)))
            except (OverflowError, TypeError, ValueError) as e:
                raise RuntimeRefusal(7, f"pValue[{i}]={v!r} for {var.name}: {e}") from None
        area[at : at + len(words)] = words

    # --- the scheduler ----------------------------------------------------------------------
    def step(self, now_ns: int, dt_ns: int, clock: Callable[[], int] | None = None) -> int:
        """One controller cycle of program execution; returns the instructions run.

        ``clock`` reads the controller time: a GT call that waited for cycles of its
        own (GT_AxisOn) ends this cycle's execution, and the cycles it ran execute no
        program instruction (``_busy``: one instruction at a time).
        """
        if self._busy:
            return 0
        self._busy = True
        try:
            return self._step(now_ns, dt_ns, clock)
        finally:
            self._busy = False

    def _step(self, now_ns: int, dt_ns: int, clock: Callable[[], int] | None) -> int:
        self.now_ns = now_ns
        threads = self.threads
        ready = [th for th in threads if th.state is ThreadState.RUNNING]
        if not ready:
            self._credit = 0.0
            return 0
        self._credit += self.speed * dt_ns / 1_000_000
        budget = int(self._credit)
        self._credit -= budget
        order = [threads[(self._next + k) % THREADS] for k in range(THREADS)]
        runnable = [th for th in order if th.state is ThreadState.RUNNING and th.wake_ns <= now_ns]
        done = 0
        last = None
        while budget > 0 and runnable:
            keep = []
            for th in runnable:
                if budget == 0:
                    keep.append(th)
                    continue
                self._execute(th)
                budget -= 1
                done += 1
                last = th
                if clock is not None and clock() != now_ns:
                    budget = 0  # the call waited: its cycles are spent
                if th.state is ThreadState.RUNNING and th.wake_ns <= now_ns:
                    keep.append(th)
            runnable = keep
        if last is not None:
            self._next = (last.number + 1) % THREADS
        if not runnable:
            self._credit = min(self._credit, 1.0)  # idle slots are not banked
        self.executed += done
        return done

    def _execute(self, th: Thread) -> None:
        pc = th.pc
        th.line = self._lines[pc]
        try:
            self._steps[pc](th)
        except ProgramError as e:
            self._fail(th, e.code, str(e))
        except ZeroDivisionError:
            self._fail(th, Fault.DIVISION_BY_ZERO, "division by zero")
        except Exception as e:  # the image was verified at download; this is a defect of ours
            log.error("motion program instruction %d failed", pc, exc_info=True)
            self._fail(th, Fault.INTERNAL, f"internal error in the emulator: {e!r}")

    def _fail(self, th: Thread, code: int, reason: str) -> None:
        th.error = int(code)
        th.state = ThreadState.IDLE
        f = th.function
        th.reason = f"line {th.line}" + (f" ({f.name})" if f else "") + f": {reason}"

    # --- linking: one closure per instruction -----------------------------------------------
    def _link(self, program: Program, ins: Instr, pc: int) -> _Step:
        nxt = pc + 1
        op = ins.op
        if op is Op.MOV:
            dst, a = ins.operands
            put, get = self._setter(dst), self._getter(a)

            def mov(th: Thread) -> None:
                put(th, get(th))
                th.pc = nxt

            return mov
        if op is Op.UNARY:
            dst, a = ins.operands
            put, get = self._setter(dst), self._getter(a)
            fn = _UNARY[UnOp(ins.sub)]

            def unary(th: Thread) -> None:
                put(th, fn(get(th)))
                th.pc = nxt

            return unary
        if op is Op.BINARY:
            dst, a, b = ins.operands
            put, ga, gb = self._setter(dst), self._getter(a), self._getter(b)
            fn = _binary(BinOp(ins.sub), a.type)

            def binary(th: Thread) -> None:
                put(th, fn(ga(th), gb(th)))
                th.pc = nxt

            return binary
        if op is Op.CAST:
            dst, a = ins.operands
            put, get = self._setter(dst), self._getter(a)
            conv = fixed.from_int if VarType(ins.sub) is VarType.DOUBLE else fixed.to_int

            def cast(th: Thread) -> None:
                put(th, conv(get(th)))
                th.pc = nxt

            return cast
        if op is Op.JUMP:
            target = ins.target

            def jump(th: Thread) -> None:
                th.pc = target

            return jump
        if op is Op.JUMP_IF:
            (c,) = ins.operands
            get, target = self._getter(c), ins.target

            def jump_if(th: Thread) -> None:
                th.pc = target if get(th) else nxt

            return jump_if
        if op is Op.RETURN:
            (v,) = ins.operands
            ret = self._returner(v)

            def return_(th: Thread) -> None:
                ret(th)

            return return_
        if op is Op.RETURN_IF:
            c, v = ins.operands
            get, ret = self._getter(c), self._returner(v)

            def return_if(th: Thread) -> None:
                if get(th):
                    ret(th)
                else:
                    th.pc = nxt

            return return_if
        if op is Op.CALL:
            return self._link_call(program.strings[ins.target], ins, nxt)
        raise ValueError(f"instruction {pc}: unknown op {op}")  # pragma: no cover

    def _returner(self, v: Operand) -> _Step:
        if v.kind is Kind.NONE:
            get: Callable[[Thread], int] = lambda th: 0  # noqa: E731
        else:
            get = self._getter(v)
        double = v.kind is not Kind.NONE and v.type is VarType.DOUBLE

        def ret(th: Thread) -> None:
            w = get(th)
            th.result = fixed.to_float(w) if double else float(w)
            th.state = ThreadState.IDLE

        return ret

    def _area(self, kind: Kind) -> Callable[[Thread], list[int]]:
        g = self.globals
        if kind is Kind.GLOBAL:
            return lambda th: g
        return lambda th: th.mem

    def _index(self, o: Operand) -> Callable[[Thread], int]:
        """The element an operand designates (bounds checked at run time)."""
        base, size = o.value, o.size
        if o.index_kind is Kind.NONE:
            return lambda th: base
        if o.index_kind is Kind.CONST:
            at = base + o.index
            return lambda th: at
        idx_area = self._area(o.index_kind)
        ia = o.index

        def index(th: Thread) -> int:
            i = idx_area(th)[ia]
            if not 0 <= i < size:
                raise ProgramError(
                    Fault.INDEX_OUT_OF_RANGE, f"index {i} out of range 0..{size - 1}"
                )
            return base + i

        return index

    def _getter(self, o: Operand) -> Callable[[Thread], int]:
        if o.kind is Kind.CONST:
            v = o.value
            return lambda th: v
        a = o.value
        if o.index_kind in (Kind.NONE, Kind.CONST):
            a += o.index if o.index_kind is Kind.CONST else 0
            if o.kind is Kind.GLOBAL:
                g = self.globals
                return lambda th: g[a]
            return lambda th: th.mem[a]
        area, index = self._area(o.kind), self._index(o)
        return lambda th: area(th)[index(th)]

    def _setter(self, o: Operand) -> Callable[[Thread, int], None]:
        area, index = self._area(o.kind), self._index(o)

        def put(th: Thread, v: int) -> None:
            area(th)[index(th)] = v

        return put

    # --- GT calls ---------------------------------------------------------------------------
    def _link_call(self, name: str, ins: Instr, nxt: int) -> _Step:
        dst, *args = ins.operands
        put = self._setter(dst) if dst.kind is not Kind.NONE else None
        if name == "GT_Delay":
            (ms,) = args
            get = self._getter(ms)

            def delay(th: Thread) -> None:
                v = get(th)
                if not 0 <= v <= 0xFFFF:
                    raise ProgramError(Fault.BAD_ARGUMENT, f"GT_Delay: ms={v} out of 0..65535")
                th.wake_ns = self.now_ns + v * 1_000_000
                if put is not None:
                    put(th, 0)
                th.pc = nxt

            return delay
        if name == "GT_SetDataPage":
            (pg,) = args
            get = self._getter(pg)

            def set_page(th: Thread) -> None:
                p = get(th)
                if not 0 <= p < PAGES:
                    raise ProgramError(
                        Fault.BAD_ARGUMENT, f"GT_SetDataPage: page={p} out of 0..{PAGES - 1}"
                    )
                owner = self.page_owner.get(p)
                if owner is not None and owner != th.number:
                    raise ProgramError(
                        Fault.PAGE_TAKEN, f"GT_SetDataPage: page {p} belongs to thread {owner}"
                    )
                self.page_owner[p] = th.number
                th.mem = self.pages[p]
                if put is not None:
                    put(th, 0)
                th.pc = nxt

            return set_page
        if name.startswith("GTN_") and name[4:] in ("Delay", "SetDataPage"):
            return self._link_call("GT_" + name[4:], replace(ins, operands=(dst, *args[1:])), nxt)
        proto = prototype(name)
        makers = [self._arg_maker(p, o, proto) for p, o in zip(proto.params, args, strict=True)]
        call = self.call

        def gt_call(th: Thread) -> None:
            values: list[Any] = []
            backs: list[Callable[[list[Any]], None]] = []
            for make in makers:
                v, back = make(th, values)
                values.append(v)
                if back is not None:
                    backs.append(back)
            rc, reason = call(name, tuple(values))
            if rc != 0:
                raise ProgramError(rc, f"{name} returned {rc}" + (f": {reason}" if reason else ""))
            for back in backs:
                back(values)
            if put is not None:
                put(th, 0)
            th.pc = nxt

        return gt_call

    def _arg_maker(self, p: Any, o: Operand, proto: Any) -> Callable:
        from .compiler import c_value

        if not p.pointer:
            get = self._getter(o)
            if p.is_float:
                return lambda th, done: (fixed.to_float(get(th)), None)
            return lambda th, done: (c_value(p, get(th)), None)
        if o.kind is Kind.NONE:
            return lambda th, done: (None, None)
        area, start = self._area(o.kind), self._index(o)
        end = o.value + o.size
        double_slots = o.type is VarType.DOUBLE
        writes = p.direction in ("out", "inout")
        reads = p.direction in ("in", "inout")
        names = [q.name for q in proto.params]

        def to_slot(v: float) -> int:
            if double_slots:
                try:
                    return fixed.from_float(float(v))
                except OverflowError as e:
                    raise ProgramError(
                        Fault.VALUE_OUT_OF_RANGE, f"{p.name} of the GT call: {e}"
                    ) from None
            return fixed.wrap32(round(v)) if isinstance(v, float) else fixed.wrap32(int(v))

        def from_slot(w: int) -> float | int:
            return fixed.to_float(w) if double_slots else w

        if p.is_struct:
            from .gtcalls import Catalog

            cls = Catalog().struct(p.ctype)
            fields = [f[0] for f in cls._fields_]

            def struct_arg(th: Thread, done: list) -> tuple[Any, Any]:
                mem, at = area(th), start(th)
                if end - at < len(fields):
                    raise ProgramError(
                        7, f"{p.name}: {p.ctype} has {len(fields)} fields, {end - at} words given"
                    )
                s = cls()
                if reads:
                    for k, fname in enumerate(fields):
                        setattr(s, fname, _fit_field(cls, fname, from_slot(mem[at + k])))

                def back(values: list) -> None:
                    for k, fname in enumerate(fields):
                        mem[at + k] = to_slot(getattr(s, fname))

                return s, (back if writes else None)

            return struct_arg

        ctype = _CTYPES[p.ctype]
        count_index = names.index(p.count) if isinstance(p.count, str) else -1

        def pointer_arg(th: Thread, done: list) -> tuple[Any, Any]:
            mem, at = area(th), start(th)
            room = end - at
            arr = (ctype * room)()
            if reads or writes:
                for k in range(room):
                    arr[k] = _fit(ctype, from_slot(mem[at + k]))
            if not writes:
                return arr, None
            before = list(arr)

            def back(values: list) -> None:
                if isinstance(p.count, int) and p.count > 0:
                    n = min(p.count, room)
                    ks: Any = range(n)
                elif count_index >= 0:
                    n = values[count_index]
                    ks = range(max(0, min(int(n), room)))
                else:  # out[?]: what the call changed
                    ks = [k for k in range(room) if arr[k] != before[k]]
                for k in ks:
                    mem[at + k] = to_slot(arr[k])

            return arr, back

        return pointer_arg


_CTYPES = {
    "char": ctypes.c_int8,
    "unsigned char": ctypes.c_uint8,
    "short": ctypes.c_int16,
    "unsigned short": ctypes.c_uint16,
    "int": ctypes.c_int32,
    "long": ctypes.c_int32,
    "unsigned long": ctypes.c_uint32,
    "double": ctypes.c_double,
    "float": ctypes.c_float,
}


def _fit(ctype: Any, v: float | int) -> float | int:
    if ctype in (ctypes.c_double, ctypes.c_float):
        return float(v)
    return int(v)


def _fit_field(cls: Any, name: str, v: float | int) -> float | int:
    for fname, ftype in cls._fields_:
        if fname == name:
            return _fit(ftype, v)
    return v


def _lt(a: int, b: int) -> int:
    return int(a < b)


def _gt(a: int, b: int) -> int:
    return int(a > b)


def _le(a: int, b: int) -> int:
    return int(a <= b)


def _ge(a: int, b: int) -> int:
    return int(a >= b)


def _eq(a: int, b: int) -> int:
    return int(a == b)


def _ne(a: int, b: int) -> int:
    return int(a != b)


_COMMON: dict[BinOp, Callable[[int, int], int]] = {
    BinOp.ADD: fixed.iadd,
    BinOp.SUB: fixed.isub,
    BinOp.LT: _lt,
    BinOp.GT: _gt,
    BinOp.LE: _le,
    BinOp.GE: _ge,
    BinOp.EQ: _eq,
    BinOp.NE: _ne,
    BinOp.MOD: fixed.imod,
    BinOp.LAND: lambda a, b: int(bool(a) and bool(b)),
    BinOp.LOR: lambda a, b: int(bool(a) or bool(b)),
    BinOp.BAND: lambda a, b: a & b,
    BinOp.BOR: lambda a, b: a | b,
    BinOp.BXOR: lambda a, b: a ^ b,
    BinOp.SHL: fixed.shl,
    BinOp.SHR: fixed.shr,
}
_INT = {**_COMMON, BinOp.MUL: fixed.imul, BinOp.DIV: fixed.idiv}
_DOUBLE = {**_COMMON, BinOp.MUL: fixed.fmul, BinOp.DIV: fixed.fdiv}
_UNARY: dict[UnOp, Callable[[int], int]] = {
    UnOp.NEG: fixed.ineg,
    UnOp.NOT: lambda a: int(a == 0),
    UnOp.INV: lambda a: fixed.wrap32(~a),
}


def _binary(op: BinOp, t: VarType) -> Callable[[int, int], int]:
    return (_DOUBLE if t is VarType.DOUBLE else _INT)[op]


__all__ = [
    "DEFAULT_SPEED",
    "Fault",
    "ProgramError",
    "ProgramRuntime",
    "RuntimeRefusal",
    "Thread",
    "ThreadState",
    "ThreadStatus",
]
