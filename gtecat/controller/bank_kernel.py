"""The axis bank's plain cycle compiled: one C call instead of ~80 numpy operations.

With a dozen axes the numpy cycle of :class:`~gtecat.controller.bank.AxisBank` costs its
operation count, not its arithmetic (about 80 operations of 0.5-1 µs each, whatever the
rows).  ``gtecat/controller/csrc/bank_kernel.c`` runs the same cycle row by row, with the same
IEEE operations in the same order, built with ``cc`` (with the wheel where one is, else on
first use into the per-version cache: :mod:`gtecat.cbuild`; ``-ffp-contract=off``), so it
gives the same bits as numpy and as the scalar objects.  It runs only the plain cycle (the
bank fills a Trap table that runs out before it): a raw write to a claimed slave, a row
about to leave or a new cycle time go through the numpy cycle, which stays the reference and
the fallback (no compiler: numpy alone, nothing else changes).

``GTECAT_BANK_KERNEL`` = ``auto`` (default: the compiled kernel where it builds), ``c`` (the
same; a build failure is reported in :attr:`AxisBank.kernel_reason`) or ``numpy``.

The arrays are handed over as one table of addresses, bound by name (the library lists its
field names; a list that differs from what this module binds is refused).  The numpy cycle
replaces some arrays by new ones, so every numpy cycle, claim and release unbinds and the next
kernel cycle binds again.
"""

from __future__ import annotations

import ctypes
import logging
import os
from operator import attrgetter
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ..cbuild import Background, NativeBuildError, c_source, found, shared_library
from ..cparts import BANK_CFLAGS, BANK_PLAIN_CFLAGS

if TYPE_CHECKING:
    from .bank import AxisBank

log = logging.getLogger(__name__)
#: IEEE arithmetic exactly as written, portable code (gtecat.cparts says why these flags);
#: the plain build, when the compiler refuses CFLAGS
CFLAGS, PLAIN_CFLAGS = BANK_CFLAGS, BANK_PLAIN_CFLAGS
_U8, _I64, _F64 = np.uint8, np.int64, np.float64
#: the int64 slots (``io``) and double slots (``fp``) of a cycle call, the C enums' order
(IN_N, IN_T_NS, IN_N_PLC, IN_N_RX, IN_W2, IN_W16, IN_W17, OUT_FIN) = range(8)
IN_TABLE, IN_MAXC, IN_DT_NS, OUT_DONE, OUT_FILLED, N_IO = range(8, 14)
#: the Trap pieces a row may hold for the kernel to fill its table itself, and the per-row
#: move constants (t_done, ts, t_final, target, dir, cycle ms): the C side's MAXSEG, NTPRM
MAXSEG, NTPRM = 16, 6
FP_DT, FP_T, N_FP = range(3)
_DTYPES = {"u8": _U8, "i64": _I64, "f64": _F64}
#: placement columns (the kernel's image switch)
COLUMNS = {
    "target": 0,
    "position_actual": 1,
    "digital_inputs": 2,
    "statusword": 3,
    "position_demand": 4,
    "velocity_actual": 5,
    "following_error_actual": 6,
    "torque_actual": 7,
    "current_actual": 7,
    "torque_demand": 7,
}
#: the kernel's scratch rows (one cycle's tentative values; c_* fields are CspBank's, the
#: others the bank's own attributes of the same name)
_SCRATCH = (
    "s_target s_raw s_a s_enc s_step s_pos s_vel s_acc s_dpos s_dvel s_fe s_lim s_swl "
    "s_din s_since s_arr s_lstop"
).split()

_LIB: Any = None
_LIB_REASON = ""
_FIELDS: list[tuple[str, Any]] = []
#: the build started ahead (:func:`prebuild`), in a process of its own
_AHEAD: list[Background] = []


#: GT_Open asked for a first build and it waits for the bus to reach OP (:func:`start_deferred`)
_DEFERRED: list[bool] = []


def prebuild(defer: bool = False) -> None:
    """Start building the kernel in a process of its own, where it is not built yet.

    A bank made meanwhile runs its numpy cycle and takes the kernel when the build is there
    (:func:`library` with ``wait=False``, :func:`settled`); the builder finishes even when
    this process ends first: the next process finds it.  GT_Open asks with ``defer``: a
    first build on a machine (about a second of the compiler) then starts once the bus is
    in OP (:func:`start_deferred`, from GT_IsEcatReady or GT_StartEcatComm), not beside the
    bring-up: on two CPUs the compiler took a CPU the bring-up wanted (a cold bring-up of
    512 axes 1.8 s alone, 3.2-3.5 s beside it), and no axis moves before OP anyway."""
    global _LIB_REASON
    if _LIB is not None or _LIB_REASON or _AHEAD or wanted() == "numpy":
        return
    try:
        source = _source()
        builds = [
            ("bank_kernel", source, CFLAGS, ("-lm",)),
            ("bank_kernel", source, PLAIN_CFLAGS, ("-lm",)),
        ]
        if defer and not any(found(*b) for b in builds):
            _DEFERRED[:] = [True]
            return
        _DEFERRED.clear()
        _AHEAD.append(Background(builds))
    except NativeBuildError as e:  # no compiler, no cache folder: the numpy cycle alone
        _LIB_REASON = f"{type(e).__name__}: {e}"
    except Exception as e:  # no builder process (no sys.executable): built here when asked
        log.info("the bank kernel's build could not start beside the bus: %s", e)


def start_deferred() -> None:
    """The bus is in OP: the first build GT_Open deferred starts now (:func:`prebuild`)."""
    if _DEFERRED:
        _DEFERRED.clear()
        prebuild()


def settled() -> bool:
    """Whether :func:`library` answers at once (the kernel loaded, refused, or its build
    ended), never waiting; cheap enough to ask every cycle.  A deferred build that has not
    started is not settled (the bank runs numpy until it has been built)."""
    if _LIB is not None or _LIB_REASON:
        return True
    if _AHEAD:
        return _AHEAD[0].done()
    return not _DEFERRED


def _built() -> Path:
    """The kernel's library file: the build started ahead, else one built now."""
    start_deferred()  # (asked before OP: started here, and waited for)
    if not _AHEAD:
        return build(CFLAGS)
    return _AHEAD[0].wait()


def library(wait: bool = True) -> tuple[Any, str]:
    """(the loaded kernel or None, why not); built and loaded once per process.
    ``wait`` False: (None, "") while the build started ahead runs."""
    global _LIB, _LIB_REASON
    if _LIB is not None or _LIB_REASON:
        return _LIB, _LIB_REASON
    if not wait and not settled():
        return None, ""
    try:
        lib = ctypes.CDLL(str(_built()))
        lib.bank_kernel_fields.restype = ctypes.c_char_p
        lib.bank_kernel_abi.restype = ctypes.c_int
        lib.bank_kernel_cycle.restype = ctypes.c_int
        lib.bank_kernel_cycle.argtypes = (ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p)
        lib.bank_kernel_run.restype = ctypes.c_int
        lib.bank_kernel_run.argtypes = (ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p)
        lib.bank_kernel_sizes.restype = ctypes.c_int
        lib.bank_trap_fill.restype = ctypes.c_int64
        lib.bank_trap_fill.argtypes = (
            ctypes.c_void_p,
            ctypes.c_int64,
            ctypes.c_double,
            ctypes.c_void_p,
            ctypes.c_int64,
            ctypes.c_int64,
            ctypes.c_void_p,
            ctypes.c_void_p,
            ctypes.c_void_p,
        )
        lib.bank_pt_run.restype = ctypes.c_int64
        lib.bank_pt_run.argtypes = (
            ctypes.c_void_p,
            ctypes.c_void_p,
            ctypes.c_int64,
            ctypes.c_int64,
            ctypes.c_void_p,
            ctypes.c_void_p,
            ctypes.c_void_p,
        )
        lib.bank_pt_state_size.restype = ctypes.c_int
        lib.bank_pt_fill.restype = ctypes.c_int64
        lib.bank_pt_fill.argtypes = (ctypes.c_void_p,)
        lib.bank_pt_fill_args.restype = ctypes.c_int
        if lib.bank_pt_fill_args() != len(PT_FILL_ARGS):
            raise RuntimeError("the kernel's PT fill arguments are not the ones this module packs")
        if lib.bank_pt_state_size() != len(PT_STATE):
            raise RuntimeError("the kernel's PT state is not the one this module packs")
        fields = [f for f in lib.bank_kernel_fields().decode().split(",") if f]
        src_types = _field_types()
        if (
            [f for f, _ in src_types] != fields
            or lib.bank_kernel_abi() != (len(fields) << 8 | N_IO << 4 | N_FP)
            or lib.bank_kernel_sizes() != (MAXSEG << 8 | NTPRM)
        ):
            raise RuntimeError("the kernel's field list is not the one this module binds")
        _FIELDS[:] = src_types
        _LIB = lib
    except Exception as e:  # no compiler, a failed build: the numpy cycle alone
        _LIB_REASON = f"{type(e).__name__}: {e}"
    return _LIB, _LIB_REASON


def build(
    cflags: tuple[str, ...], stem: str = "bank_kernel", libs: tuple[str, ...] = ("-lm",)
) -> Path:
    """``csrc/<stem>.c`` (the kernel, or another of the bank's C units) built with ``cflags``,
    else (the compiler refused them) with the plain flags (NativeBuildError when that fails
    too)."""
    source = _source(stem)
    try:
        return shared_library(stem, source, cflags, libs)
    except NativeBuildError as e:
        if cflags == PLAIN_CFLAGS:
            raise
        log.info("%s: the build with %s failed, built plain: %s", stem, " ".join(cflags), e)
        return shared_library(stem, source, PLAIN_CFLAGS, libs)


class Unit:
    """One of the bank's other C units (``csrc/<stem>.c``): built (:func:`build`) and loaded
    on the first call, once per process; ``bind`` declares its functions and raises where
    the library is not the one its module packs for.  A call gives (the library or None,
    why not)."""

    def __init__(self, stem: str, bind: Any, libs: tuple[str, ...] = ("-lm",)) -> None:
        self.stem, self.bind, self.libs = stem, bind, libs
        self.lib: Any = None
        self.reason = ""

    def __call__(self) -> tuple[Any, str]:
        if self.lib is None and not self.reason:
            try:
                lib = ctypes.CDLL(str(build(CFLAGS, self.stem, self.libs)))
                self.bind(lib)
                self.lib = lib
            except Exception as e:  # no compiler, a failed build: the module's Python path
                self.reason = f"{type(e).__name__}: {e}"
        return self.lib, self.reason


def _field_types() -> list[tuple[str, Any]]:
    """(name, dtype) of every field, read from the C source's FIELDS list."""
    body = _source().split("#define FIELDS", 1)[1].split("enum {", 1)[0]
    out = []
    for item in body.replace("\\", " ").split("X(")[1:]:
        name, _, rest = item.partition(",")
        out.append((name.strip(), _DTYPES[rest.split(")")[0].strip()]))
    return out


def _source(stem: str = "bank_kernel") -> str:
    return c_source("gtecat.controller", stem)


def wanted() -> str:
    """``GTECAT_BANK_KERNEL``; an unknown value is ``auto``, with a warning."""
    raw = os.environ.get("GTECAT_BANK_KERNEL", "auto")
    mode = raw.strip().lower() or "auto"
    if mode not in ("auto", "c", "numpy"):
        log.warning("GTECAT_BANK_KERNEL=%r: not auto, c or numpy; auto is used", raw)
        return "auto"
    return mode


class Kernel:
    """The binding of one bank to the compiled cycle."""

    def __init__(self, bank: AxisBank, lib: Any) -> None:
        self.bank = bank
        self.fn = lib.bank_kernel_cycle
        self.run_fn = lib.bank_kernel_run
        n = bank.n
        self.scratch = {name: np.zeros(n, _array_type(_dtype_of(name))) for name in _SCRATCH}
        self.scratch["s_jog"] = np.zeros(5 * n, _F64)
        self.scratch["s_hm"] = np.zeros(7 * n, _F64)  # a homing row's tentative search state
        self.scratch["s_hit"] = np.zeros(n, np.bool_)  # homing rows that must leave first
        #: rows whose watched input changed in a committed cycle, for their hooks (AxisBank.dpost)
        self.scratch["s_evt"] = np.zeros(n, np.bool_)
        self.scratch["s_p0"] = np.zeros(n, _F64)  # where their travel started (a probe's edge)
        self.ptrs = np.zeros(len(_FIELDS), np.uint64)
        self.io = np.zeros(N_IO, np.int64)
        self.fp = np.zeros(N_FP, np.float64)
        self.io[IN_N] = n
        self.io[IN_TABLE] = bank.table
        self.fp[FP_T] = bank.T
        self.run_fn = lib.bank_kernel_run
        #: where the run function is (the GT readers' C entries call it for an armed cycle:
        #: gtecat.controller.core.Controller.arm_quick)
        self.run_address: int = ctypes.cast(lib.bank_kernel_run, ctypes.c_void_p).value or 0
        self.bound = False
        self._keep: list[Any] = []
        self._fields_plan: list[tuple[int, str, str | None, str | None, Any]] | None = None
        self._extra_key: Any = None
        self._extra_last: dict[str, np.ndarray] | None = None
        self._args = (self.ptrs.ctypes.data, self.io.ctypes.data, self.fp.ctypes.data)
        # the same memory as io and fp: what a run of cycles sets and reads (a memoryview's
        # item costs less than a numpy array's; the arrays are never replaced)
        self._io = memoryview(self.io)
        self._fp = memoryview(self.fp)
        self.buffer: np.ndarray | None = None
        #: the identities at the last bind (:meth:`_current_ids`) and their getters
        self._ids: tuple[Any, ...] | None = None
        self._getters: tuple[Any, Any] | None = None

    def bind(self) -> None:
        """Take the addresses of the bank's current arrays (fixing dtype/layout in place
        where the numpy cycle left another one, values unchanged).

        A bind follows every claim and release (it is on the GT calls' path): a field whose
        array is the very object of the last bind keeps its checked address, and the arrays
        built here (windows, placements) are built again only when what they hold changed."""
        bank, csp = self.bank, self.bank.csp
        if csp.din is csp._din_zero:
            csp.din = csp.din.copy()  # the shared zero row is never written into
        buf = bank.ctl.master.image.buffer
        ids = self._ids
        if ids is not None and buf is self.buffer and ids == self._current_ids():
            # every array the kernel reads is the very object of the last bind (a claim or a
            # release writes rows in place): the addresses stand, nothing to look at
            self.bound = True
            return
        extra = self._extra()
        buf = bank.ctl.master.image.buffer
        self.buffer = buf
        extra["buf"] = buf
        keep = self._keep
        if len(keep) != len(_FIELDS):
            keep = [None] * len(_FIELDS)
        ptrs = self.ptrs
        for i, name, owner, attr, dtype in self._plan():
            if owner is None:
                arr = extra[name] if attr is None else self.scratch[name]
            else:
                arr = getattr(bank if owner == "bank" else csp, attr)
            if arr is keep[i]:
                continue  # the same object as the last bind: its address was checked then
            if owner is not None and (not _fits(arr, dtype) or not arr.flags.writeable):
                arr = np.ascontiguousarray(arr, dtype=_array_type(dtype)).copy()
                setattr(bank if owner == "bank" else csp, attr, arr)
            if not _fits(arr, dtype):
                raise TypeError(f"bank kernel: {name} is {arr.dtype}, not {np.dtype(dtype)}")
            keep[i] = arr
            ptrs[i] = arr.ctypes.data
        self._keep = keep  # the addresses stay valid while these live
        self.bound = True
        self._ids = self._current_ids()

    def _current_ids(self) -> tuple[Any, ...]:
        """The identities of what :meth:`bind` takes from the bank and its drives, and what
        the windows and placements are built from (:meth:`_extra`), in a few C calls."""
        get = self._getters
        if get is None:
            plan = self._plan()
            bank_get = attrgetter(*[a for _, _, o, a, _ in plan if o == "bank"])
            csp_get = attrgetter(*[a for _, _, o, a, _ in plan if o == "csp"])
            get = self._getters = (bank_get, csp_get)
        bank = self.bank
        csp = bank.csp
        return (
            tuple(map(id, get[0](bank))),
            tuple(map(id, get[1](csp))),
            tuple((value, id(lo), id(hi)) for value, lo, hi in csp.windows),
            id(bank._plc),
            id(bank._rx_all),
        )

    def _plan(self) -> list[tuple[int, str, str | None, str | None, Any]]:
        """(index, name, owner "bank"/"csp" or None for this binding's own arrays, the
        attribute or None for an array built by :meth:`_extra`, dtype) of every field."""
        plan = self._fields_plan
        if plan is None:
            extra = set(self._extra())
            plan = []
            for i, (name, dtype) in enumerate(_FIELDS):
                if name in extra or name == "buf":
                    plan.append((i, name, None, None, dtype))
                elif name in self.scratch:
                    plan.append((i, name, None, name, dtype))
                elif name.startswith("c_"):
                    plan.append((i, name, "csp", name[2:], dtype))
                else:
                    plan.append((i, name, "bank", name, dtype))
            self._fields_plan = plan
        return plan

    def _extra(self) -> dict[str, np.ndarray]:
        """The arrays this binding builds (windows, placements), the last ones again while
        what they are built from is unchanged."""
        csp = self.bank.csp
        windows = {value: (lo, hi) for value, lo, hi in csp.windows}
        key = (
            tuple((id(lo), id(hi), lo.shape) for lo, hi in windows.values()),
            self._placement_key(),
        )
        if key == self._extra_key and self._extra_last is not None:
            return dict(self._extra_last)
        empty = np.zeros(1, _F64)
        extra: dict[str, np.ndarray] = {}
        io = self.io
        for name, bit, slot in (
            ("w2", 1 << 2, IN_W2),
            ("w16", 1 << 16, IN_W16),
            ("w17", 1 << 17, IN_W17),
        ):
            lo, hi = windows.get(bit, (empty, empty))
            io[slot] = lo.shape[1] if lo.ndim == 2 else 0
            extra[name + "_lo"], extra[name + "_hi"] = lo, hi
        extra.update(self._placements(key[1]))
        self._extra_key, self._extra_last = key, extra
        return dict(extra)

    def _placement_key(self) -> tuple[Any, ...]:
        """What :meth:`_placements` builds its arrays from: every placement and every output
        byte of the bank's slaves, fixed when the bank is built (the kernel skips the rows it
        does not run: a frozen row's image keeps what its scalar objects wrote)."""
        bank = self.bank
        return id(bank._plc), id(bank._rx_all)

    def _placements(self, key: tuple[Any, ...]) -> dict[str, np.ndarray]:
        """The placements of every row and the output bytes a raw write may change, with
        their rows and the bytes the last re-index saw (``rx_ref``: updated in place)."""
        bank = self.bank
        plc = bank._plc
        self.io[IN_N_PLC] = len(plc)
        rx = bank._rx_all
        self.io[IN_N_RX] = len(rx)
        return {
            "pl_row": np.array([p[0] for p in plc] or [0], np.int64),
            "pl_off": np.array([p[1] for p in plc] or [0], np.int64),
            "pl_size": np.array([p[2] for p in plc] or [0], np.int64),
            "pl_col": np.array([COLUMNS[p[3]] for p in plc] or [0], np.int64),
            "rx_idx": rx.astype(np.int64) if len(rx) else np.zeros(1, np.int64),
            "rx_row": bank._rx_row if len(rx) else np.zeros(1, np.int64),
            "rx_ref": bank._rx_snap if len(rx) else np.zeros(1, np.uint8),
        }

    def cycle(self, t_ns: int, dt: float) -> int:
        """0: the cycle ran and is committed; 1, 4, 5: nothing was written (the numpy cycle
        must run it: a raw write, a table to fill, no memory); 3: nothing was written, the
        rows marked in ``scratch["s_hit"]`` leave first (an event, a limit)."""
        if not self.bound or self.bank.ctl.master.image.buffer is not self.buffer:
            self.bind()
        self.io[IN_T_NS] = t_ns
        self.fp[FP_DT] = dt
        return self.fn(*self._args)

    def run(self, t_ns: int, dt: float, dt_ns: int, most: int) -> tuple[int, int]:
        """Up to ``most`` whole cycles from ``t_ns``: (the code of the cycle that stopped the
        run, 0 when none did; the cycles committed).  The run stops after a cycle that ended
        a Trap move and before one the kernel declines (nothing of it written)."""
        if not self.bound or self.bank.ctl.master.image.buffer is not self.buffer:
            self.bind()
        io = self._io
        io[IN_T_NS] = t_ns
        io[IN_DT_NS] = dt_ns
        io[IN_MAXC] = most
        self._fp[FP_DT] = dt
        rc = self.run_fn(*self._args)
        return rc, io[OUT_DONE]

    @property
    def filled(self) -> bool:
        """The last call refilled some Trap table itself."""
        return bool(self.io[OUT_FILLED])

    @property
    def move_ended(self) -> bool:
        """The last committed cycle ended a Trap move (the bank recounts its moving rows);
        after :meth:`run`: any of its cycles did."""
        return bool(self._io[OUT_FIN])


def trap_fill(
    lib: Any, segs: np.ndarray, cyc: float, prm: np.ndarray, k0: int, n: int, out: np.ndarray
) -> int:
    """The compiled :func:`~gtecat.controller.motion.trap_table.trap_table`: samples
    ``k0+1 .. k0+n`` of the move of raw pieces ``segs`` ((m, 4) float64) and constants
    ``prm`` (t_done, ts, t_final, target, dir) into ``out`` ((3, >= n) float64: position,
    speed, acceleration); returns the end sample's index, or ``n`` when the move goes on."""
    return lib.bank_trap_fill(
        segs.ctypes.data,
        len(segs),
        cyc,
        prm.ctypes.data,
        k0,
        n,
        out[0].ctypes.data,
        out[1].ctypes.data,
        out[2].ctypes.data,
    )


#: the PtPlanner slots bank_pt_run reads and writes, in the C side's PT_ST_* order
PT_STATE = (
    "_k _T _i _loop _loops_done _toff _poff _t0 _p0 _t1 _p1 _vs _ve _a _origin _pos _vel _acc "
    "_state"
).split()
_PT_INTS = frozenset({"_k", "_i", "_loop", "_loops_done", "_state"})


class PtRun:
    """The compiled :meth:`~gtecat.controller.motion.pt.PtPlanner.run` of a static FIFO in
    motion (``bank_pt_run``), writing straight into a row of the bank's tables."""

    def __init__(self, lib: Any) -> None:
        self.fn = lib.bank_pt_run
        self.st = np.zeros(len(PT_STATE))
        self.st_ptr = self.st.ctypes.data
        #: the planner's state in PT_STATE order (also what a rewind puts back)
        self.state = attrgetter(*PT_STATE)
        self._tables: tuple = ()
        self._ptrs = (0, 0, 0)

    def __call__(
        self, pl: Any, pts: tuple[int, int], n: int, tables: tuple[np.ndarray, ...], offset: int
    ) -> int:
        """``n`` samples from the planner's state into ``tables`` (position, speed and
        acceleration arrays, float64) from flat index ``offset`` on, over the running FIFO's
        points ``pts`` (the address of m rows of float64 position, time, type; m); the
        planner's state moves on
        as ``n`` steps move it.  Returns the end sample's index or -1."""
        known = self._tables
        if not known or any(t is not k for t, k in zip(tables, known, strict=True)):
            self._tables = tables
            self._ptrs = tuple(t.ctypes.data for t in tables)
        st = self.st
        st[:] = self.state(pl)
        p, v, a = self._ptrs
        off = 8 * offset
        end = self.fn(self.st_ptr, pts[0], pts[1], n, p + off, v + off, a + off)
        put = object.__setattr__
        for name, value, whole in zip(PT_STATE, st.tolist(), _PT_WHOLE, strict=True):
            put(pl, name, int(value) if whole else value)
        return int(end)


_PT_WHOLE = tuple(name in _PT_INTS for name in PT_STATE)
#: bank_pt_fill's argument slots (the C side's PT_FILL_* order): counts, then addresses
PT_FILL_ARGS = (
    "nr n table rows st before pts m t_p t_v t_a base t_idx t_len t_cur t_end taken fill_taken "
    "run nst"
).split()
_PT_RUN = PT_FILL_ARGS.index("run")


class PtFill:
    """The tables of a bank's PT rows (static FIFOs in motion, one per cluster) refilled by
    one call of the compiled ``bank_pt_fill``.  While such a row is claimed its planner's
    state lives here (``st``, and ``before``: the state when the row's current table began);
    :meth:`put_back` hands the planner the latter, which a release then steps on.

    ``state``, ``whole`` and ``run``: another planner's state (its attribute names, which of
    them are integers) and the address of its compiled run of ``bank_pt_run``'s form (a PVT
    row's: :mod:`~gtecat.controller.bank_pvt`), whose rows the same call fills."""

    def __init__(
        self,
        lib: Any,
        n: int,
        state: tuple[str, ...] | list[str] = PT_STATE,
        whole: frozenset[str] = _PT_INTS,
        run: int = 0,
    ) -> None:
        self.fn = lib.bank_pt_fill
        self.names = tuple(state)
        self._whole = tuple(name in whole for name in self.names)
        self.st = np.zeros((n, len(state)))
        self.before = np.zeros((n, len(state)))
        self.pts = np.zeros(n, np.int64)
        self.m = np.zeros(n, np.int64)
        self.rows = np.zeros(n, np.int64)
        self.args = np.zeros(len(PT_FILL_ARGS), np.int64)
        self._args_ptr = self.args.ctypes.data
        self._points: dict[int, np.ndarray] = {}  # row -> its FIFO's points (kept alive)
        self._state = attrgetter(*state)
        a = self.args
        a[_PT_RUN], a[_PT_RUN + 1] = run, len(state)
        a[3], a[4], a[5] = self.rows.ctypes.data, self.st.ctypes.data, self.before.ctypes.data
        a[6], a[7] = self.pts.ctypes.data, self.m.ctypes.data

    def load(self, r: int, pl: Any) -> None:
        """Row ``r`` runs PT planner ``pl`` (static FIFO, in motion) from now on."""
        get = object.__getattribute__
        self.st[r] = [float(v) for v in self._state(pl)]
        q = get(pl, "_fifos")[get(pl, "_r")]
        pts = np.array([(p.pos, p.time, float(int(p.type))) for p in q], np.float64)
        self._points[r] = pts
        self.pts[r], self.m[r] = pts.ctypes.data, len(pts)

    def fill(self, bank: Any, rows: list[int], n: int) -> int:
        """New tables of ``n`` samples for ``rows``; the samples written."""
        k = len(rows)
        self.rows[:k] = rows
        a = self.args
        a[0], a[1], a[2] = k, n, bank.table
        for slot, arr in enumerate(
            (
                bank.t_p,
                bank.t_v,
                bank.t_a,
                bank.base,
                bank.t_idx,
                bank.t_len,
                bank.t_cur,
                bank.t_end,
                bank.taken,
                bank.fill_taken,
            ),
            8,
        ):
            if arr.dtype != (np.float64 if slot < 11 else np.int64) or not arr.flags.c_contiguous:
                raise TypeError(f"PT fill: {PT_FILL_ARGS[slot]} is {arr.dtype}")
            a[slot] = arr.ctypes.data
        return int(self.fn(self._args_ptr))

    def put_back(self, r: int, pl: Any) -> None:
        """The planner of row ``r`` as it stood when the row's current table began."""
        put = object.__setattr__
        before = self.before[r].tolist()
        for name, value, whole in zip(self.names, before, self._whole, strict=True):
            put(pl, name, int(value) if whole else value)
        self.drop(r)

    def drop(self, r: int) -> None:
        self._points.pop(r, None)


def _fits(arr: np.ndarray, dtype: Any) -> bool:
    """``arr`` is what the kernel reads for ``dtype``: u8 fields take bytes or numpy bools
    (one byte, 0 or 1), the others exactly their type; C-contiguous either way."""
    if not arr.flags.c_contiguous:
        return False
    if dtype is _U8:
        return arr.dtype == np.uint8 or arr.dtype == np.bool_
    return arr.dtype == dtype


def _array_type(dtype: Any) -> Any:
    """The numpy type of an array the kernel reads as ``dtype``: its u8 fields are the bank's
    flags, numpy bools."""
    return np.bool_ if dtype is _U8 else dtype


def _dtype_of(name: str) -> Any:
    for f, dtype in _FIELDS:
        if f == name:
            return dtype
    raise KeyError(name)
