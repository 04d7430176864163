"""The vectorised axis bank: the common servo cycle of many axes as numpy rows.

Per axis and cycle the scalar objects cost 15-25 µs of Python (planner, axis layer,
drive state machine, mechanics, PDO codec, status and limit checks).  Most axes of a
machine spend most cycles in one state: servo on, drive in CSP, Trap move, Jog (at speed
or ramping toward one) or holding, no flag latched.  :class:`AxisBank` runs exactly that
state for every such axis at once - the Trap samples
(:func:`~gtecat.controller.motion.trap_table.trap_table`), the Jog's ramp, the
axis layer's 607Ah, the drive (:class:`gtecat.drives.csp_bank.CspBank`), the encoder, the soft
and hardware limits, the following error, the in-position band and the GT_GetSts word -
and reads/writes the process image as array views.

**The scalar objects stay the reference.**  An axis is *claimed* only while it is in
that state (:meth:`AxisBank._eligible` lists every condition) and *released* - its
state written back into its objects exactly as if they had run every cycle themselves -
before anything else may look at or change them:

* any GT function except the bank-aware readers (:data:`BANK_READS`) releases the
  axis it names (the axes of a mask or of a ``count`` span, a slave's axes for an SDO to
  it, every axis when it names none) before it runs, but the calls of a Trap move's start
  (:data:`IN_PLACE`), which run on their axis's row in place (:meth:`AxisBank.call_in_place`:
  the row's state put into its objects, the call, the row taken up again from them, the
  drive staying in the bank) and the calls of a drive homing's set-up and start
  (:data:`OPENED`), which run on their axis's row opened for the call
  (:meth:`AxisBank.call_opened`: the cycles they wait for step the row's objects in the
  bank's cycle, the row taken up again as the call returns); one naming a coordinate system
  releases that system's cluster alone (:meth:`AxisBank.before_call`; a segment pushed
  onto a running path the bank holds ahead may even stay: ``_push_ahead``);
* a cycle in which a claimed axis would leave the state (a limit switch reached, the
  following error, a new sample past a soft limit, a raw write to its slave's outputs, the
  drive's own following-error window, a travel reaching an edge its armed touch probe
  latches) releases it *before* that cycle, so the scalar code runs that cycle and every
  later one until the axis is back in the common state; a drive standing or braking on a
  limit switch whose flag is latched (a limit homing escaping from it, a profile stopped
  there) stays in the compiled cycle, which runs the drive's reaction;
* the field side (a fault injected, the machine moved, an SDO to the drive) releases
  the axis by touching one of its objects: while claimed they carry a guard class
  (:meth:`AxisBank._guarded_objects`) whose first attribute access gives the axis back;
* per-cycle hooks the bank does not know (a recorder, motion programs, smart homing)
  turn it off.

PT, Gear, Follow and coordinated motion run in it too (:mod:`.bank_modes`): the axes whose
planners depend on each other (a Gear/Follow slave and its master, the axes of a coordinate
system) are claimed and given back together as a cluster, their planners stepped a table
ahead and put back exactly at a release; a slave the bank cannot follow (it reads an encoder)
keeps only its own cluster (and the drives it shares) on the scalar path.

Claimed axes are re-examined whenever a GT call or a release happened, else every
:data:`RECHECK_CYCLES` cycles.  A multi-axis drive is claimed with all its channels.

Decisions: ``GTECAT_BANK`` / ``GT_Open(bank=...)`` = ``auto`` (default: used when the
bus has at least :meth:`AxisBank.auto_min_axes` CiA-402 axes, the measured crossover: one
with the compiled cycle of :mod:`.bank_kernel`, :data:`AUTO_MIN_AXES` with numpy alone), ``on``
(any bus; the differential tests use it) or ``off``.  The results are bit-identical
to the scalar path (same float operations in the same order; ``tests/gtecat/
controller/test_bank.py`` compares planned and actual positions, statuswords and GT
status cycle by cycle).
"""

from __future__ import annotations

import math
import struct
from array import array
from collections.abc import Callable
from dataclasses import dataclass
from itertools import chain, compress
from operator import attrgetter, itemgetter
from typing import TYPE_CHECKING, Any

import numpy as np

from gtecat.drives.csp_bank import (
    CW_ENABLED,
    CspBank,
    claimable,
    frozen_claimable,
    wrap32,
)
from gtecat.drives.drive import Cia402Drive
from gtecat.drives.homing_bank import ROW_FIELDS as HM_ROW_FIELDS
from gtecat.drives.homing_bank import event_bounds as homing_event_bounds
from gtecat.drives.homing_bank import homing_claimable, homing_rest_claimable, idle_claimable
from gtecat.drives.homing_bank import rest_constants as homing_rest_constants
from gtecat.drives.homing_bank import return_constants as homing_return_constants
from gtecat.drives.homing_bank import row_constants as homing_constants
from gtecat.drives.homing_bank import row_kind as homing_row_kind
from gtecat.drives.modes import SW12
from gtecat.drives.slave import AlState, VirtualSlave
from gtecat.eni.datatypes import CHANNEL_STRIDE, MAX_CHANNELS
from gtecat.eni.model import Direction

from .._attrs import in_array, own_dict
from ..master.clock import ClockMode
from .axis import CW_QUICK_STOP
from .axis_status import AxisStatus
from .bank_home_rows import switch_released, switch_to_homing
from .bank_home_start import start_at_once
from .bank_kernel import MAXSEG, NTPRM, OUT_FIN, Kernel, PtFill, PtRun, trap_fill
from .bank_kernel import library as kernel_library
from .bank_kernel import settled as kernel_settled
from .bank_kernel import wanted as kernel_wanted
from .bank_modes import (
    SAMPLED_TABLE,
    Cluster,
    kept_push,
    links,
    sampled_kind,
    trap_steppable,
)
from .bank_pt_stream import stream_kind, stream_of
from .crd.system import Delay, Motion
from .epoch import EPOCH
from .lead_screw_bank import (
    screw_arrays,
    screw_claimable,
    screw_command,
    screw_commit,
    screw_load,
    screw_put_back,
)
from .motion.jog import _IDLE as _JOG_IDLE
from .motion.jog import _MOVE as _JOG_MOVE
from .motion.jog import JogPlanner
from .motion.jog import ramp_step as jog_ramp_step
from .motion.stop import StopKind
from .motion.trap import _EPS_T, _IDLE, _MOVE, TrapPlanner
from .motion.trap_table import advance, trap_table
from .profile import PrfMode

if TYPE_CHECKING:
    from .core import Controller

#: a moving row's raw pieces (up to MAXSEG of 4 doubles) and move constants, packed into the
#: kernel's arrays (:meth:`AxisBank._load`)
_SEG_PACK = [struct.Struct(f"={4 * m}d") for m in range(MAXSEG + 1)]
_TPRM_PACK = struct.Struct(f"={NTPRM}d")

#: the crossover of the numpy bank: below this many axes the scalar path is as fast
#: (tools/bench_bank.py); with the compiled cycle the bank wins from one axis
AUTO_MIN_AXES = 4
#: cycles between two looks for axes to claim when nothing else happened
RECHECK_CYCLES = 16
#: planned drive counts from which an axis leaves the bank (its int64 arithmetic ends at 2**63)
HUGE_COUNTS = float(1 << 62)
#: samples of a Trap move computed at once (a table per axis) by numpy alone
TABLE = 2048
#: the same with the compiled cycle, which fills a used-up table itself within the cycle:
#: a short table costs no time and little memory (24 bytes per sample and axis)
KERNEL_TABLE = 32

#: TxPDO objects the bank computes (channel-0 numbers -> CspBank output names)
COMPUTED_TX = {
    0x6041: "statusword",
    0x6062: "position_demand",
    0x6064: "position_actual",
    0x606C: "velocity_actual",
    0x6074: "torque_demand",
    0x6077: "torque_actual",
    0x6078: "current_actual",
    0x60F4: "following_error_actual",
    0x60FD: "digital_inputs",
}
#: TxPDO objects that cannot change while an axis is in the bank's state
CONSTANT_TX = {0x603F, 0x6061, 0x60B9, 0x60BA, 0x60BB, 0x60BC, 0x60BD, 0x1001, 0x20F2, 0x20F9}
CONSTANT_TX |= set(range(0x60D1, 0x60D9))

#: GT functions whose implementations read a claimed axis through the bank itself, or touch
#: no axis object at all (the process image, the clock: a raw write to a claimed slave's
#: outputs is seen by the bank's next cycle, which gives the slave back first)
#: the GT functions of a Trap move's start that run on their axis's claimed row in place
#: (:meth:`AxisBank.call_in_place`): they reach that axis's axis, planner, encoder and band
#: objects and its profile (or, through their guards, anything else of its drive)
IN_PLACE = frozenset(
    {"GT_PrfTrap", "GT_SetTrapPrm", "GT_SetPos", "GT_SetVel", "GT_Update", "GT_GoHome"}
)
#: the GT functions of a drive homing's set-up and start (manual 5.2.2.2) that take their axis
#: out of the bank for the call alone (:meth:`AxisBank.call_opened`): the cycles they wait for
#: step its drive on the scalar objects, and the row is taken again when the call returns
OPENED = frozenset({"GT_SetHomingMode", "GT_SetEcatHomingPrm", "GT_StartEcatHoming"})
#: those of :data:`IN_PLACE` that write their profile's values for the next GT_Update alone
#: (the Trap target, the speed), which the bank keeps no copy of: they run with the row as
#: it stands (anything else they reached would give the drive back through its guard)
_PROFILE_ONLY = frozenset({"GT_SetPos", "GT_SetVel"})
#: function -> where it takes a ``count`` of axes, 0: it takes none (AxisBank.before_call)
_COUNTED: dict[str, int] = {}
#: the most axes a ``count`` names that go back one by one (more: every axis)
_SPAN_MOST = 64

BANK_READS = frozenset(
    {
        "GT_GetSts",
        "GT_GetPrfPos",
        "GT_GetPrfVel",
        "GT_GetPrfAcc",
        "GT_GetEncPos",
        "GT_GetEncVel",
        "GT_GetAxisPrfPos",
        "GT_GetAxisPrfVel",
        "GT_GetAxisPrfAcc",
        "GT_GetAxisEncPos",
        "GT_GetAxisEncVel",
        "GT_GetAxisEncAcc",
        "GT_GetAxisError",
        "GT_GetPrfMode",
        "GT_GetEcatRawData",
        "GT_SetEcatRawData",
        # the drives' 60FDh and 6041h bits where they lie in the process image, which the
        # bank writes every cycle as the scalar drives would (io_calls.read_di; GT_GetDi
        # polled between cycles gave every axis back and took it again: 64 axes at 0.15x)
        "GT_GetDi",
        "GT_GetDiRaw",
        "GT_EcatIOReadInput",
        "GT_EcatIOWriteOutput",
        "GT_EcatIOBitWriteOutput",
        "GT_GetClock",
        "GTE_Wait",
        "GTE_GetLastError",
        "GT_GetVersion",
        "GT_IsEcatReady",
        "GT_GetEcatHomingStatus",
        # a smart homing's parameters and status (gtecat.controller.smart_home): its own data
        "GT_GetHomeStatus",
        "GT_GetHomePrm",
        # the older cards' homing status (GT_HomeSts, gtecat.gt.legacy_home_calls): the same
        # smart homing's status and reason
        "GT_HomeSts",
        # a capture's status cleared: the unit's own data (a home capture armed again gives
        # its axis back itself, CaptureUnit.clear), the homings look again (look_again)
        "GT_ClearCaptureStatus",
        # latched flags cleared and faulted drives reset: an axis the bank runs with nothing
        # to clear is left where it is (resources.clear_status); the others give themselves
        # back through their guards as the call touches them
        "GT_ClrSts",
        # a coordinate system's state, read from the cycle the bank records of it
        # (CoordSystem.now, bank_modes.SystemTrace), or its parameters (never stepped)
        "GT_CrdStatus",
        "GT_CrdSpace",
        "GT_GetCrdPos",
        "GT_GetCrdVel",
        "GT_GetCrdPrm",
        "GT_GetCrdStopDec",
        "GT_GetRemainderSegNum",
        "GT_GetCrdMapBase",
        "GT_CrdData",
        # a PVT axis's table time and passes, from the state its row's table began with
        # (gtecat.controller.bank_pvt.now)
        "GT_PvtStatus",
        "GT_GetPvtLoop",
    }
)
#: GT functions naming coordinate systems by a mask (GT_CrdStart: bit 0 = system 1; GT_Stop:
#: bits 12, 13 = systems 1, 2, bits 0-11 = axes 1-12): (the first system's bit, axes' bits)
_CRD_MASKS = {"GT_CrdStart": (0, 0), "GT_Stop": (12, 0xFFF)}
#: GT functions naming a system that read or change other systems too: every axis goes back
_CRD_ALL = frozenset({"GT_SetCrdPrm"})


def _crd_push(name: str) -> bool:
    """A GT function that pushes one line, arc, helix or delay onto a FIFO, nothing else."""
    return name == "GT_BufDelay" or (
        name.startswith(("GT_Ln", "GT_Arc", "GT_Helix")) and not name.endswith("Ex")
    )


#: rows up to which GT_GetSts's words are made row by row (fewer calls than numpy's)
_SMALL_BANK = 32
#: the planned values :meth:`AxisBank._materialise` makes: (its Trap table, its Jog value)
_PLANNED = {"prf_p": ("t_p", "jp"), "prf_v": ("t_v", "jv"), "prf_a": ("t_a", "ja")}
#: ... their Trap tables' flat views (AxisBank._make_list: where no row jogs or homes)
_PLANNED_FLAT = {"prf_p": "_t_p1", "prf_v": "_t_v1", "prf_a": "_t_a1"}
#: AxisBank.row_value: the values made row by row, their place in their row's tuple: the
#: planned values (AxisBank._planned_one) and the encoder's rates (AxisBank._enc_rates_row)
_ROW_PLANNED = {"prf_p": 0, "prf_v": 1, "prf_a": 2}
_ROW_RATES = {"enc_vel": 0, "enc_acc": 1}
#: ... and the arrays whose list is the array's own (AxisBank._make_list's last case)
_ROW_ITEMS = frozenset({"a_last", "enc_pos"})
#: the dtype of the bank's doubles (AxisBank.span_bytes: their bytes are the values packed)
_F64 = np.dtype(np.float64)
#: ... and of its table indices (AxisBank.t_idx)
_I64 = np.dtype(np.int64)


def _flat(a: np.ndarray) -> bool:
    """One C-contiguous dimension (AxisBank.span_bytes: an array a C entry reads again)."""
    return a.ndim == 1 and a.flags.c_contiguous  # type: ignore[no-any-return]


#: the axis's mode while its drive homes (6060h = 6)
_HOMING_MODE = 6
#: the bank's arrays of homing rows (gtecat.drives.homing_bank), floats unless named in _HM_U8
_HM_ARRAYS = (
    "h_last h_el h_tr h_v h_p h_rest h_vt h_acc h_lo h_hi h_maxtr h_tmo h_fd h_from h_ilim"
).split()
_HM_U8 = ("hm", "h_set", "h_idx", "frz", "h_done")
_SERVO_ON, _MOVING, _ARRIVED = (
    int(AxisStatus.SERVO_ON),
    int(AxisStatus.MOVING),
    int(AxisStatus.ARRIVED),
)
_ALARM = int(AxisStatus.ALARM)
_POS_LIMIT = int(AxisStatus.POSITIVE_LIMIT)
_NEG_LIMIT = int(AxisStatus.NEGATIVE_LIMIT)
_SW_FAULT = 0x0008  # 6041h bit 3: fault
#: dpost: the drive's touch probe takes an edge of a cycle's travel after that cycle
#: (bank_kernel.c TP_POST; far above 60FDh's 32 bits)
TP_POST = 1 << 62
#: the touch probe's TxPDO objects: the bank writes those a drive maps into the image where
#: it changes the probe (AxisBank._put_probe), and leaves them as they are otherwise
_TP_TX = (0x60B9, 0x60BA, 0x60BB, 0x60BC, 0x60BD, *range(0x60D1, 0x60D9))


#: the modes whose planners a cluster steps ahead (gtecat.controller.bank_modes)
_SAMPLED_MODES = (PrfMode.PT, PrfMode.GEAR, PrfMode.FOLLOW, PrfMode.INTERPOLATION, PrfMode.PVT)


def _trap_key(pl: TrapPlanner) -> tuple:
    """What a Trap table is computed from (trap_table), but the sample count."""
    return (pl._T, pl._t_done, tuple(pl._segs), pl._ts, pl._t_final, pl._target, pl._dir)


# --- guards: a claimed axis's objects give themselves back when anything touches them ---------
class _Bypass:
    on = False


_OWNER: dict[int, tuple[AxisBank, int]] = {}  # id(object) -> (bank, group index)
#: id() of the objects given a dict of their own at a claim (it stays theirs: an id used
#: again by a later object only costs that object its quick attribute reads)
_OWN_DICT: set[int] = set()
_GUARDS: dict[type, type] = {}
_GUARD_SET: set[type] = set()  # (the values of _GUARDS: a guarded object's class is one)
_get, _set = object.__getattribute__, object.__setattr__


def _wake(obj: object) -> None:
    entry = _OWNER.get(id(obj))
    if entry is not None:
        bank, gi = entry
        bank._release_groups([bank.groups[gi]])


def _guard_class(cls: type) -> type:
    """``cls`` whose every attribute access first releases the object from its bank."""
    g = _GUARDS.get(cls)
    if g is None:

        def __getattribute__(self: Any, name: str) -> Any:  # noqa: N807
            if not _Bypass.on:
                _wake(self)
            return _get(self, name)

        def __setattr__(self: Any, name: str, value: Any) -> None:  # noqa: N807
            if not _Bypass.on:
                _wake(self)
            _set(self, name, value)

        g = type(
            cls.__name__,
            (cls,),
            {
                "__slots__": (),
                "__getattribute__": __getattribute__,
                "__setattr__": __setattr__,
                "__module__": cls.__module__,
                "__qualname__": cls.__qualname__,
            },
        )
        _GUARDS[cls] = g
        _GUARD_SET.add(g)
    return g


def _unguard(objs: tuple) -> None:
    """The guarded ones of ``objs`` back in their own classes (their claim stays)."""
    for obj in objs:
        cls = type(obj)
        if cls in _GUARD_SET:
            _set(obj, "__class__", cls.__base__)


def _reguard(objs: tuple) -> None:
    """``objs`` guarded again (their dicts are their own since their claim)."""
    for obj in objs:
        cls = type(obj)
        if cls not in _GUARD_SET:
            _set(obj, "__class__", _GUARDS.get(cls) or _guard_class(cls))


def _bank_safe(hook: Any) -> bool:
    """A ``pre_cycle`` or ``post_cycle`` hook that leaves the axes the bank runs alone, or
    reaches them only through their guards (which give them back first: smart homing): the
    function says so (``bank_safe`` on it), else the object of a bound method (``bank_safe``
    on it, which may change: the fault injector while a trigger watches an axis every
    cycle)."""
    safe = getattr(hook, "bank_safe", None)
    if safe is None:
        safe = getattr(getattr(hook, "__self__", None), "bank_safe", False)
    return bool(safe)


def aware_hooks(ax: Any) -> list[Any]:
    """The objects of an axis's post hooks that know the bank (``bank_post_hook``: a capture
    unit, :mod:`gtecat.controller.capture`).  Such an object says when its axis may be held
    (``bank_ready()``), which 60FDh bits matter to it now (``bank_watch``: a change gives the
    row back before that cycle; read at the claim, so an object whose bits grow gives its
    row back itself) and catches up when the row is given back (``bank_released(cycles)``:
    the cycles the bank ran without it, in which none of those bits changed)."""
    out = []
    for h in ax.post_hooks:
        obj = getattr(h, "__self__", None)
        if getattr(obj, "bank_post_hook", False):
            out.append(obj)
    return out


@dataclass
class _Group:
    """One slave (all its channels are claimed together)."""

    position: int
    drive: Cia402Drive
    rows: list[int]
    rx_bytes: np.ndarray  # buffer indices of its output bytes, 607Ah excluded
    #: the entries the bank writes into the image: (buffer byte, bytes, an output, the
    #: slave's rx (output) or tx (input) index of the first byte, its row)
    computed: list[tuple[int, int, bool, int, int]]
    claimed: bool = False


def _count(slot: int, doc: str) -> property:
    """An int attribute kept in slot ``slot`` of the bank's :attr:`AxisBank.counts`."""
    return in_array("counts", slot, doc)


#: the bank's counts kept in :attr:`AxisBank.counts`, in this order (a quick cycle's book in
#: C counts them: Controller.arm_quick's book)
_COUNTS = (
    "_countdown",
    "_refill_in",
    "rows_run",
    "bank_cycles",
    "kernel_cycles",
    "many_cycles",
    "homing_rows_run",
    "rest_rows_run",
    "frozen_rows_run",
    "_sts_epoch",
)


#: the slots of some of :data:`_COUNTS`, for code that adds to them in the array itself
_ROWS_RUN, _BANK_CYCLES, _KERNEL_CYCLES = (_COUNTS.index(n) for n in _COUNTS[2:5])
_HOMING_ROWS_RUN, _REST_ROWS_RUN, _FROZEN_ROWS_RUN = (_COUNTS.index(n) for n in _COUNTS[6:9])


class AxisBank:
    """The claimed axes of one controller and their cycle (module docstring)."""

    _countdown = _count(0, "cycles until the next look for rows to claim (RECHECK_CYCLES)")
    _refill_in = _count(1, "cycles until the next look for tables to fill")
    rows_run = _count(2, "rows run, summed over the cycles")
    bank_cycles = _count(3, "the bank's cycles")
    kernel_cycles = _count(4, "the cycles the compiled cycle ran")
    many_cycles = _count(5, "the cycles run many at once (runs of cycles, quick cycles)")
    homing_rows_run = _count(6, "homing rows run, summed over the cycles")
    rest_rows_run = _count(7, "rows at rest run, summed over the cycles")
    frozen_rows_run = _count(8, "switched-off rows run, summed over the cycles")
    _sts_epoch = _count(
        9,
        "the readers' epoch the status words of _sts_last hold for (0: look at the flags); "
        "a quick cycle booked in C that could change no flag carries it to its new epoch",
    )

    def __init__(self, ctl: Controller, mode: str = "auto") -> None:
        #: the counts of :data:`_COUNTS` (their attributes), in memory compiled code adds to
        #: (a quick cycle's book: gtecat.controller.core.Controller.arm_quick)
        self.counts = array("q", bytes(8 * len(_COUNTS)))
        self.ctl = ctl
        self.mode = mode
        self.built = False
        self.groups: list[_Group] = []
        #: the claimed rows' output bytes as the last re-index saw them (:meth:`_reindex`)
        self._rx_ref = b""
        self._rx_gi = np.zeros(0, np.intp)  # (the group of each of those bytes)
        self.dirty = True
        self._countdown = 0
        self._missed = False  # the last refresh found an eligible group it could not claim
        #: cycles to the next look for rows to claim while some are out (doubled up to
        #: RECHECK_CYCLES by each look that leaves some out; 1 again after a release)
        self._wait = 1
        self._settled = False  # the next cycle's first steps ran already (settle)
        self._declined = False  # the last run of many cycles stopped before a declined one
        #: GT axes kept off the bank (a fault trigger reads their drive every cycle)
        self.held: frozenset[int] = frozenset()
        self.n = 0
        self.alive = np.zeros(0, bool)
        self.n_alive = 0
        #: the rows whose hooks took a watched input's edge after the last cycle
        #: (:meth:`_post_events`; cleared at the next): their smart homings step after it
        self.evt_rows: set[int] = set()
        self.any_post = False
        #: the row a hook's step runs on in place (:meth:`step_claimed`), -1: none
        self._stepping = -1
        #: rows a posted edge left open for the step after the cycle (:meth:`_post_event`)
        self._open: set[int] = set()
        #: the row a call of :data:`OPENED` runs on, opened for the call (:meth:`call_opened`),
        #: and the cycles that stepped it since
        self._opened: dict[int, int] = {}
        #: the frozen row such a call runs on with its guards off, not opened (-1: none),
        #: and whether the bank was to re-index before it
        self._frozen_call = -1
        self._frozen_stale = False
        #: that call is GT_StartEcatHoming, and the row whose start's instant part ran on it
        #: as the cycle began (gtecat.controller.bank_home_start; -1: none)
        self._frozen_start = False
        self._home_started = -1
        #: the bank's cycles and the outside marks after the last step of an opened row
        self._opened_marks: tuple[int, tuple[int, int]] = (-1, (-1, -1))
        #: where a group's output bytes lie in the raw-write checks' references, per
        #: claimed pattern (:meth:`_took_group`)
        self._took_at: dict[int, tuple[Any, int | None]] = {}
        #: each group's output bytes in the image (607Ah aside): their count and a function
        #: giving their values from the image (made when asked)
        self._grp_pos: dict[int, tuple[int, Callable[[Any], Any]]] = {}
        #: a slave's outputs in the image (start, stop), by position (:meth:`_decoded`)
        self._out_area: dict[int, tuple[int, int]] = {}
        #: the row such a call gave back where per-cycle hooks run (:meth:`_open_released`)
        self._held_out = -1
        #: rows whose capture unit arms its drive's touch probe: the unit writes the function
        #: after the next cycle (:meth:`_post_pending`), the drive applies it at the start of
        #: the one after (:attr:`_tp_apply`, :meth:`_apply_probes`)
        self._post_next: set[int] = set()
        self._tp_apply: set[int] = set()
        self._probe_rows: dict[int, bool] = {}  # (:meth:`probe_in_bank`)
        #: touch probe functions the bank applied to drives it runs (:meth:`_apply_probes`)
        self.probes_armed = 0
        self._tp_map: dict[int, bool] = {}  # (:meth:`_tp_mapped`)
        #: (slave, channel) -> its touch-probe objects mapped as TxPDO (:meth:`_tp_mapped`)
        self._tp_objects: dict[tuple[int, int], list[int]] | None = None
        self._tp_tx: dict[int, list[tuple[Any, Callable[[], Any]]]] = {}  # (:meth:`_put_probe`)
        self._tp_rx: dict[int, list[tuple[int, int]]] = {}  # (:meth:`_took_outputs`)
        #: the GT readers' lists of the claimed rows' values (:meth:`value`), made as they are
        #: asked for; a new dict wherever they may change (a cycle, a claim, a release), never
        #: one emptied in place: a reader that made its list from the state before another
        #: thread's cycle keeps it in the dict of that state, which no reader sees after it
        self._lists: dict[str, list[Any]] = {}
        #: the flags the last list of GT_GetSts words was made from (a few rows) and that
        #: list: made again only when one changed (a move, a jog and a rest last many runs)
        self._sts_last: tuple[tuple[bytes, ...], list[int]] | None = None
        #: counts the claims and releases of rows (an axis's resources point at the bank or
        #: not): what the GT readers' plans of many axes at once check (gtecat.gt.fast)
        self.layout = 0
        #: those plans, by (value, first axis, count)
        self.read_plans: dict[tuple[str, int, int], Any] = {}
        self.disabled_reason = ""
        self._stale = False
        #: axis-cycles the bank ran (statistics; the differential tests check it worked)
        self.rows_run = 0
        #: the compiled plain cycle (gtecat.controller.bank_kernel), None: numpy alone; the
        #: library is loaded here, at GT_InitEcatComm.  Its first build on a machine runs in
        #: a process of its own (started by GT_Open): ``auto`` does not wait for it, the bank
        #: runs numpy meanwhile and takes the kernel at the first cycle after the build
        #: (:meth:`_take_kernel`); ``c`` and the realtime clock wait here
        self.kernel: Kernel | None = None
        self._kernel_lib: Any = None
        self.kernel_due = False  # the build runs: the kernel is taken when it is there
        self.table = TABLE
        self._c_fill = False  # the kernel refills every moving row's table itself
        self._fill_out: np.ndarray | None = None
        self._kmode = kmode = kernel_wanted()
        if kmode == "numpy":
            self.kernel_reason = "GTECAT_BANK_KERNEL=numpy"
        else:
            wait = kmode == "c" or ctl.clock.mode is ClockMode.REALTIME
            self._kernel_lib, self.kernel_reason = kernel_library(wait)
            if self._kernel_lib is None and not self.kernel_reason:
                self.kernel_due = True
                self.kernel_reason = "the compiled cycle is being built (numpy meanwhile)"
            self._kernel_missing()
        #: the compiled fills of static PT tables (bank_modes), None without the kernel
        self.pt_run = PtRun(self._kernel_lib) if self._kernel_lib is not None else None
        self.pt_fill: PtFill | None = None  # (made with the rows)
        #: cycles the compiled kernel ran (statistics)
        self.kernel_cycles = 0
        #: of those, the cycles it ran many at a time (:meth:`run_many`; statistics)
        self.many_cycles = 0
        #: homing axis-cycles the compiled kernel ran (statistics)
        self.homing_rows_run = 0
        #: of those, the cycles of drives resting in homing mode after their homing
        self.rest_rows_run = 0
        self.n_rest = 0
        #: smart-homing steps run on a claimed row in place (:meth:`step_claimed`), and the
        #: edges taken after a bank cycle (:meth:`_post_events`): a watched input's, a touch
        #: probe's (statistics; the differential tests check they ran)
        self.steps_in_place = 0
        self.posted_inputs = self.posted_probes = 0
        #: calls of :data:`OPENED` that opened their row (:meth:`call_opened`), that ran on a
        #: frozen row and left it claimed, that gave it back for the call where per-cycle
        #: hooks run (statistics; the differential tests check each way ran)
        self.calls_opened = self.calls_kept = self.calls_held_out = 0
        #: switches to homing mode run on the row (gtecat.controller.bank_home_rows;
        #: statistics), and the row switching now (-1: none)
        self.home_switches = 0
        self.home_switch = -1
        self.home_switch_from = 0
        #: homing starts run on the row, the row kept and given back after them
        #: (gtecat.controller.bank_home_start; statistics)
        self.home_starts = self.home_starts_given = 0
        #: GT_PrfTrap calls on claimed rows standing in Trap mode, run as they stand
        #: (:meth:`call_in_place`; statistics)
        self.trap_holds = 0
        #: resting (servo-off) axis-cycles the compiled kernel skipped (statistics)
        self.frozen_rows_run = 0
        #: samples of PT, Gear, Follow and crd axes stepped ahead into tables (statistics)
        self.sampled_samples = 0
        own_dict(self)  # (the cycle reads these; its helpers look into vars(): gtecat._attrs)

    def _kernel_missing(self) -> None:
        if self._kernel_lib is None and not self.kernel_due and self._kmode == "c":
            self.ctl.log(
                "GTECAT_BANK_KERNEL=c: the compiled cycle is not available, numpy runs "
                f"the bank ({self.kernel_reason})"
            )

    def _take_kernel(self) -> None:
        """The kernel's build ended (:attr:`kernel_due`): every axis goes back to its objects
        (exactly, as at any release) and the rows are made again for the compiled cycle
        (its short tables, its homing and resting rows) at the next refresh; without a
        library, numpy goes on and :attr:`kernel_reason` says why."""
        self.kernel_due = False
        lib, self.kernel_reason = kernel_library()
        self._kernel_missing()
        if lib is None:
            return
        if self.built:
            self.release_all()
            self.built = False
            self.groups = []
            self.n = self.n_alive = 0
            self.alive = np.zeros(0, bool)
            self.disabled_reason = ""
            self.kernel = self.pt_fill = None
            for name in ("_gi", "_cluster_of", "order"):
                self.__dict__.pop(name, None)
        self._kernel_lib = lib
        self.pt_run = PtRun(lib)
        self.dirty = True

    def auto_min_axes(self) -> int:
        """The crossover of ``auto``: the compiled cycle wins from one axis on (1 axis moving:
        5 µs a cycle against 23 µs scalar), numpy alone from :data:`AUTO_MIN_AXES`."""
        return 1 if self._kernel_lib is not None else AUTO_MIN_AXES

    # --- structure ------------------------------------------------------------------------
    def _build(self) -> None:
        """Rows for every axis whose slave the bank can run (mapping and backend)."""
        self.built = True
        self._tp_map = {}
        self._tp_objects = None
        self._tp_tx = {}
        self._tp_rx = {}
        ctl = self.ctl
        master, backend = ctl.master, ctl.backend
        if getattr(backend, "name", "") != "emulated" or backend.hardware is not None:
            self.disabled_reason = "not the emulated backend on the ENI's own hardware"
            return
        if backend.capture is not None:
            self.disabled_reason = "a pcap is written"
            return
        layout, image = ctl.layout, master.image
        least = self.auto_min_axes() if self.mode == "auto" else 1
        if len(layout.axes) < least:
            self.disabled_reason = f"fewer than {least} axes"
            return
        by_slave: dict[int, list[Any]] = {}
        for ref in layout.axes:
            by_slave.setdefault(ref.slave, []).append(ref)
        axes, chans, groups = [], [], []
        #: the image entries the bank writes: (row, first byte in the buffer, bytes, value)
        plc: list[tuple[int, int, int, str]] = []
        for pos, refs in by_slave.items():
            slave = backend.slaves[pos] if pos < len(backend.slaves) else None
            if not isinstance(slave, Cia402Drive) or len(slave.channels) != len(refs):
                continue
            sl = layout.slaves[pos]
            ok, rows = True, []
            g_plc: list[tuple[int, int, int, str]] = []
            n_607a = 0
            rx_idx: list[int] = []
            row_of = {ref.channel: len(axes) + k for k, ref in enumerate(refs)}
            for e in sl.entries:
                if e.is_padding:
                    continue
                k, base = divmod(e.index - 0x6000, CHANNEL_STRIDE)
                base += 0x6000
                if not 0x6000 <= e.index < 0x6000 + CHANNEL_STRIDE * MAX_CHANNELS:
                    k, base = 0, e.index
                if e.logical_bit & 7 or e.bits not in (8, 16, 32):
                    ok = False
                    break
                byte, size = e.logical_bit >> 3, e.bits // 8
                if e.direction == Direction.OUT:
                    if base == 0x607A and e.subindex == 0 and e.bits == 32 and k in row_of:
                        g_plc.append((row_of[k], byte, 4, "target"))
                        n_607a += 1
                    else:
                        rx_idx.extend(range(byte, byte + size))
                elif base in COMPUTED_TX and e.subindex == 0 and k in row_of:
                    g_plc.append((row_of[k], image.outputs_bytes + byte, size, COMPUTED_TX[base]))
                elif base not in CONSTANT_TX:
                    ok = False
                    break
            if not ok or n_607a != len(refs):
                continue
            for ref in refs:
                rows.append(len(axes))
                axes.append(ctl.axes[ref.axis])
                chans.append(slave.channels[ref.channel])
            plc += g_plc
            out0 = (sl.out_logical_bit or 0) >> 3
            in0 = image.outputs_bytes + ((sl.in_logical_bit or 0) >> 3)
            computed = [
                (byte, size, name == "target", byte - (out0 if name == "target" else in0), r)
                for r, byte, size, name in g_plc
            ]
            groups.append(_Group(pos, slave, rows, np.array(rx_idx, np.intp), computed))
        if not axes:
            self.disabled_reason = "no drive the bank can run (mapping)"
            return
        self.groups = groups
        self._grp_pos = {}
        self._out_area = {}
        #: every output byte of the bank's slaves (607Ah excluded), the row whose slave owns
        #: it and what it held at the last re-index: the kernel's raw-write check of the
        #: claimed ones (updated in place, so the kernel keeps its binding)
        rx_all = [g.rx_bytes for g in groups]
        self._rx_all = np.concatenate(rx_all) if rx_all else np.zeros(0, np.intp)
        #: where each group's bytes begin in _rx_all (:meth:`_took_outputs`)
        self._rx_start = np.cumsum([0] + [len(b) for b in rx_all]).tolist()
        self._rx_row = np.concatenate(
            [np.full(len(g.rx_bytes), g.rows[0], np.int64) for g in groups] or [np.zeros(0)]
        ).astype(np.int64)
        self._rx_snap = np.zeros(len(self._rx_all), np.uint8)
        #: per output byte its group, per group whether it is claimed and its slave position
        self._rx_group = np.concatenate(
            [np.full(len(g.rx_bytes), gi, np.intp) for gi, g in enumerate(groups)]
            or [np.zeros(0, np.intp)]
        ).astype(np.intp)
        self._g_claimed = np.zeros(len(groups), bool)
        self._g_pos = np.array([g.position for g in groups], np.int64)
        self._loaded = True  # the rows' constants changed (_reindex looks at them again)
        self._singles: list[tuple[list[_Group], list[int], bool]] | None = None
        #: the bank row of each of the controller's axes (-1: not in the bank)
        self._rows_of_axes: list[int] | None = None
        self.group_of = [0] * len(axes)
        for gi, g in enumerate(groups):
            for r in g.rows:
                self.group_of[r] = gi
        self.axes = axes
        self._row_of = {id(ax): r for r, ax in enumerate(axes)}
        self.res = [ax.motion for ax in axes]
        n = self.n = len(axes)
        self.csp = CspBank(chans)
        self.alive = np.zeros(n, bool)
        self._plc = plc
        z, zi = np.zeros, np.zeros
        # controller-side state and constants
        self.unit2 = z(n)  # 2**PosScale
        self.unit = z(n)  # 2**-PosScale
        self.drive_offset = zi(n, np.int64)
        self.prf_ratio, self.prf_off = z(n), z(n)
        self.enc_ratio, self.enc_off = z(n), z(n)
        self.soft_pos, self.soft_neg = z(n), z(n)
        self.pos_err = z(n)
        self.latched = zi(n, np.int64)  # the latched GT_GetSts flags (constant in the bank)
        self.external = zi(n, bool)
        self.sense = zi(n, np.int64)
        self.enc_prev = zi(n, np.int64)
        self.enc_pos, self.enc_vel, self.enc_acc = z(n), z(n), z(n)  # vel/acc: at the claim
        self.enc_step0, self.enc_step1 = z(n), z(n)  # the last two encoder steps, pulse
        self.claim_cycle = zi(n, np.int64)
        #: a number for each claim of a row, 0 while it is out (a hook that counts on a row
        #: staying claimed compares it: the same number, the same claim)
        self.claim_ids = [0] * n
        self._claims = 0
        self.bank_cycles = 0
        self.band, self.hold_ns = z(n), zi(n, np.int64)
        self.since = zi(n, np.int64)
        self.arrived = zi(n, bool)
        self.prf_p, self.prf_v, self.prf_a = z(n), z(n), z(n)
        self.a_last = z(n)
        self.moving = zi(n, bool)  # a Trap move runs (its samples come from the table)
        self.jog = zi(n, bool)  # a Jog cruises (computed every cycle)
        self.jrp, self.jrv = z(n), z(n)  # the raw ramp's position and speed
        self.jp, self.jv, self.ja = z(n), z(n), z(n)  # the filter output (the planned values)
        self.tau, self.jE = z(n), z(n)  # smoothing time constant, e^(-T/tau)
        self.jgoal, self.jacc, self.jdec = z(n), z(n), z(n)  # target speed, its ramps
        self.taken = zi(n, np.int64)  # samples taken since the claim
        self.k0 = zi(n, np.int64)  # the planner's sample count at the claim
        #: rows whose planners a cluster steps ahead (gtecat.controller.bank_modes)
        self.sampled = zi(n, bool)
        self.fill_taken = zi(n, np.int64)  # ``taken`` at the cluster's last fill
        self.ended = zi(n, bool)
        screw_arrays(self, n)  # lead-screw compensation (gtecat.controller.lead_screw_bank)
        tl = self.table = KERNEL_TABLE if self._kernel_lib is not None else TABLE
        self.t_p, self.t_v, self.t_a = z((n, tl + 1)), z((n, tl + 1)), z((n, tl + 1))
        # (flat views of the same memory: a row's slot written by one index)
        self._t_p1, self._t_v1, self._t_a1 = (t.reshape(-1) for t in (self.t_p, self.t_v, self.t_a))
        self.base = np.arange(n, dtype=np.int64) * (tl + 1)
        # a moving row's raw pieces and move constants, for the kernel's own refills
        self.nseg = zi(n, np.int64)  # 0: none (the table is refilled here)
        self.seg = z(n * MAXSEG * 4)
        self.tprm = z(n * NTPRM)
        self.t_idx = self.base.copy()  # table index of each row's last sample
        self.t_len = zi(n, np.int64)  # valid samples in the table
        self.t_cur = zi(n, np.int64)  # next sample to take
        self.t_end = zi(n, np.int64)  # index of the end sample (or -1)
        self.T = ctl.clock.cycle_ns / 1e6
        for name in _HM_ARRAYS:
            setattr(self, name, z(n))
        for name in _HM_U8:
            setattr(self, name, zi(n, bool))
        self.h_done = zi(n, np.uint8)  # a homing row's kind (homing_bank.row_kind): 0, 1, 2
        #: the frozen rows (frz) whose servo is off: GT_GetSts's word without its servo-on bit
        #: (the others stand in homing mode before a homing, the servo on)
        self.frz_off = zi(n, bool)
        self.n_hm = self.n_frz = 0
        #: 60FDh bits whose change sends a row back before the cycle (an input a bank-aware
        #: hook samples every cycle: a capture unit's home input)
        self.dwatch = zi(n, np.int64)
        #: the same bits where the hooks take the edge after the cycle (bank_post_ready): the
        #: cycle runs in the bank, then they do (:meth:`_post_events`)
        self.dpost = zi(n, np.int64)
        #: a row moving in Trap with a limit flag latched: bit 0 positive, bit 1 negative;
        #: a sample toward that side sends it back before the cycle (AxisResources._post)
        self.lvel = zi(n, np.uint8)
        #: the bank-aware axis hooks of a claimed row (:meth:`_axis_hooks`), told at its release
        self._aware: dict[int, list[Any]] = {}

        #: releases so far (a hook that counts on rows staying claimed looks at it)
        self.releases = 0
        #: GT calls run on a claimed row without giving it back (gtecat.controller.bank_stream)
        self.streamed_calls = 0
        #: row -> the constants of its last load that _reindex's flags read (_load)
        self._consts: dict[int, tuple] = {}
        #: row -> the Trap table it left with (_keep_table): taken up again when the row comes
        #: back in the same move, instead of computed again
        self._kept: dict[int, tuple] = {}
        #: per row, the kind of its planner when bank_modes.links last looked (-1: not yet)
        self._row_link: np.ndarray | None = None
        #: per claimed pattern, what follows from it alone (_reindex)
        self._claimed_sets: dict[bytes, tuple] = {}
        #: how many patterns it keeps: each holds ~200 bytes a row, so a fixed budget of rows
        #: (256 patterns of 64 rows, 16 of 1,024) - a bus of 1,024 axes switched on one by one
        #: made a pattern per axis and kept 256 of them: ~25 kB per axis at the peak
        self._patterns_kept = max(8, min(256, 16_384 // max(1, self.n)))
        self._axes_seen: list[Any] | None = None
        self._reindex()
        if self._kernel_lib is not None:
            self.kernel = Kernel(self, self._kernel_lib)
            self.pt_fill = PtFill(self._kernel_lib, n)

    def _reindex(self) -> None:
        """Image addresses and run lists of the claimed rows (after a claim or release)."""
        for r in self._opened:  # (its outputs are its objects', not a raw write)
            self._took_group(self.group_of[r])
        self._release_written()
        alive = self.alive
        self._stale = False
        self.n_alive = int(np.count_nonzero(alive))
        self._recount()
        self._patterns()

    def _recount(self) -> None:
        """What the cycle looks at of the claimed rows' flags, counted again (after a claim or
        a release; a row opened for a call or taken again after it: :meth:`call_opened`)."""
        alive = self.alive
        if self._loaded:  # the rows' constants (they change only when a row is taken)
            self._loaded = False
            ratio, off = self.prf_ratio, self.prf_off
            self.any_prf_link = bool(np.count_nonzero((ratio != 1.0) | (off != 0.0)))
            ratio, off = self.enc_ratio, self.enc_off
            self.any_enc_link = bool(np.count_nonzero((ratio != 1.0) | (off != 0.0)))
            self.any_drive_offset = bool(np.count_nonzero(self.drive_offset))
            self.all_external = bool(self.external.all())
            self.any_sense = bool(np.count_nonzero(self.sense != 1))
            self.any_band = bool(np.count_nonzero(self.band > 0))
            self.any_scale = bool(np.count_nonzero(self.unit2 != 1.0))
        self._count_standing()
        # (a row given back has these cleared: _put_back, _store)
        self.n_jog = int(np.count_nonzero(self.jog))
        self.n_hm = int(np.count_nonzero(self.hm))
        self.n_rest = int(np.count_nonzero(self.h_done == 1)) if self.n_hm else 0
        self.n_frz = int(np.count_nonzero(self.frz))
        self.any_watch = bool(np.count_nonzero(self.dwatch))
        self.any_post = bool(np.count_nonzero(self.dpost))
        self.any_lvel = bool(np.count_nonzero(self.lvel))
        self.band_dirty = True
        self._img_stale = True  # the numpy cycle's image indices follow when it runs
        moving = self.moving & alive
        self.n_moving = int(np.count_nonzero(moving))
        self._refill_in = 0  # look for tables to fill at the next cycle
        self._c_fill = self.kernel is not None and not (
            self.n_moving and np.count_nonzero(moving & (self.nseg <= 0))
        )
        self._lists = {}  # (a new one: _lists' docs)
        self._sts_epoch = 0  # (the status words made again)

    def _counted(self) -> None:
        """After a row opened for a call or taken again from its objects (the claimed set
        stays; its counts moved with it): what :meth:`_recount` does besides the counts."""
        if self._loaded:
            self._recount()
            return
        if self.any_band:
            self._count_standing()
        self.band_dirty = True
        self._img_stale = True
        self._lists = {}  # (a new one: _lists' docs)
        self._sts_epoch = 0  # (the status words made again)

    def _patterns(self) -> None:
        """:meth:`_reindex`'s part that follows from the claimed pattern alone (a row opened
        for a call counts as the bank's: it steps the row itself, :meth:`_step_opened`)."""
        alive = self.alive
        if self._opened:  # (one given back meanwhile is the controller's, as any released row)
            group_of, claimed = self.group_of, self._g_claimed
            mine = [r for r in self._opened if claimed[group_of[r]]]
            if mine:
                alive = alive.copy()
                alive[mine] = True
        g_claimed = self._g_claimed
        rows = self._rows_of_axes
        axis_list = self.ctl._axis_list
        if rows is None or len(rows) != len(axis_list):
            row_of = {id(ax): r for r, ax in enumerate(self.axes)}
            rows = self._rows_of_axes = [row_of.get(id(ax), -1) for ax in axis_list]
            self._rows_np = np.array(rows, np.intp)
            self._rows_in = self._rows_np >= 0
            self._claimed_sets.clear()
        elif axis_list is not self._axes_seen:
            self._claimed_sets.clear()  # (its axes' run list: another list of the same axes)
        self._axes_seen = axis_list
        # what follows from the claimed pattern alone, kept per pattern (the bank gives back
        # and takes the same few): the slaves the bus leaves to the bank (one set per
        # pattern, so the bus finds its plan for it by identity), the claimed output bytes
        # and their groups, the controller's axes the bank does not run, in its order
        key = g_claimed.tobytes() + alive.tobytes()
        kept = self._claimed_sets.get(key)
        if kept is None:
            if len(self._claimed_sets) >= self._patterns_kept:
                self._claimed_sets.clear()
            sel = g_claimed[self._rx_group]
            run = ~(self._rows_in & alive.take(np.maximum(self._rows_np, 0)))
            kept = self._claimed_sets[key] = (
                frozenset(self._g_pos[g_claimed].tolist()),
                self._rx_all[sel],
                self._rx_group[sel],  # (the group of each byte: _release_written)
                list(compress(axis_list, run.tolist())),
            )
        claimed, self._rx_idx, self._rx_gi, run_axes = kept
        buf = self.ctl.master.image.buffer
        self._rx_ref = buf.take(self._rx_idx).tobytes()
        if len(self._rx_all):
            buf.take(self._rx_all, out=self._rx_snap)
        self.ctl.backend.claimed = claimed
        self.ctl._run_axes = run_axes.copy()
        self._lists = {}  # (a new one: _lists' docs)
        self._sts_epoch = 0  # (the status words made again)
        # the kernel keeps its binding: a claim and a release write the rows in place (only
        # the numpy cycle replaces arrays, and it unbinds the kernel itself)

    def _image_indices(self) -> None:
        """The numpy cycle's scatter of the claimed rows' values into the image."""
        alive = self.alive
        self._img_stale = False
        plc = [p for p in self._plc if alive[p[0]]]
        names = sorted({p[3] for p in plc} - {"target", "position_actual", "digital_inputs"})
        self._extra = names
        col = {"target": 0, "position_actual": 1, "digital_inputs": 2}
        col |= {name: 3 + k for k, name in enumerate(names)}
        n = self.n
        self._img_src = np.array([col[name] * n + r for r, _, _, name in plc], np.intp)
        self._img_dst = np.array([off + j for _, off, size, _ in plc for j in range(size)], np.intp)
        self._img_bytes = np.array(
            [4 * i + j for i, (_, _, size, _) in enumerate(plc) for j in range(size)], np.intp
        )

    # --- when the bank may run ----------------------------------------------------------------
    def _global_reason(self) -> str:
        ctl = self.ctl
        m = ctl.master
        if m is None or not m.opened or not m.ready:
            return "bus not in OP"
        if ctl.before_cycle or ctl.sample:
            return "per-cycle hooks (recorder, programs)"
        if not all(_bank_safe(f) for f in ctl.pre_cycle) or not all(
            _bank_safe(f) for f in ctl.post_cycle
        ):
            return "per-cycle hooks"
        if ctl.backend.unplugged:
            return "a slave is unplugged"
        if ctl.backend.answer_hook is not None:
            return "faults on the frames (gtecat.faults)"
        return ""

    @staticmethod
    def _homing_hook(ax: Any, res: Any, screw: int = 1) -> Any:
        """The axis's hooks are the resources' own plus at most the GT layer's homing
        follower (gtecat.gt.homing_calls) and bank-aware hooks that may be held now (a
        capture unit, :func:`aware_hooks`), and its lead screw's (``screw`` 2: in a drive
        homing; gtecat.controller.lead_screw_bank): that follower, None without one, False
        when some other hook runs or an aware one must run its next cycle."""
        if len(ax.pre_hooks) != 1 and not screw_claimable(ax, res, screw == 2):
            return False
        hooks = ax.post_hooks
        if not hooks or hooks[0] != res._post:
            return False
        st = None
        for h in hooks[1:]:
            obj = getattr(h, "__self__", None)
            if st is None and getattr(obj, "bank_homing_hook", False):
                st = obj
            elif not (getattr(obj, "bank_post_hook", False) and obj.bank_ready()):
                return False
        return st

    def _eligible(self, r: int, drive: bool = True) -> bool:
        """The scalar state the bank reproduces (module docstring); ``drive`` False: the
        drive's own conditions left out (a claimed row whose drive stays in the bank)."""
        ax = self.axes[r]
        res = self.res[r]
        if res is None or ax.number in self.held or res.bank_hold:
            return False
        if not ax.servo_on:
            return self._eligible_frozen(r)
        if ax.mode_cmd == _HOMING_MODE:
            return self._eligible_homing(r)
        if not (ax.servo_on and ax.mode_cmd == 8 and ax.csp_follow) or ax.link_lost:
            return False
        if ax.cw != CW_ENABLED or ax._cw_sent != CW_ENABLED:
            return False
        st = self._homing_hook(ax, res)
        if st is False or (st is not None and st.active) or not res._csp:
            return False
        if ax.prf_pos != res._a_last:
            return False
        if res.latched and not (self._latched_standing(ax, res) or self._latched_away(ax, res)):
            return False
        prof = res.profile
        pl = prof.planner
        if not prof.active or pl.stopping != StopKind.NONE:
            return False
        if prof.mode == PrfMode.TRAP and pl is prof.trap and isinstance(pl, TrapPlanner):
            if pl._mode not in (_IDLE, _MOVE):
                return False
        elif prof.mode == PrfMode.JOG and pl is prof.jog and isinstance(pl, JogPlanner):
            if pl._mode == _JOG_MOVE:
                # cruising or ramping toward a speed (a reversal included); a jog stopping
                # (goal 0: it settles and ends) stays scalar
                if pl._goal == 0.0 or pl._T != self.T or pl._prm is None:
                    return False
            elif pl._mode != _JOG_IDLE:
                return False
        elif prof.mode in _SAMPLED_MODES and pl is prof.planners.get(prof.mode):
            _Bypass.on = True  # (a claimed cluster's planners are read in refresh too)
            try:
                if not sampled_kind(pl):
                    return False
                if stream_kind(pl) and len(self.groups[self.group_of[r]].rows) != 1:
                    return False  # (a dynamic PT FIFO runs in a cluster of its own alone)
            finally:
                _Bypass.on = False
        else:
            return False
        if not self._inputs_plain(ax, res):
            return False
        ch = self.csp.channels[r]
        # a drive on a limit switch: the compiled cycle runs it (its reaction included) while
        # the flag of each switch it stands on is latched (nothing new for the controller);
        # the numpy cycle gives such a row back (a claimed row's 60FDh: the bank's)
        on = (ch.digital_inputs if drive else int(self.csp.din[r])) & 3
        if on:
            if self.kernel is None:
                return False
            need = (_POS_LIMIT if on & 2 else 0) | (_NEG_LIMIT if on & 1 else 0)
            if res.latched & need != need:
                return False
        return not drive or not claimable(ch, limits=self.kernel is not None)

    @staticmethod
    def _latched_standing(ax: Any, res: Any) -> bool:
        """A servo-on row with latched GT_GetSts flags (a limit switch or a stop that halted
        it, waiting for GT_ClrSts): while its profile stands no stop reacts to them
        (AxisResources._post), so the bank keeps them as they are (its GT_GetSts word carries
        them) and gives the row back before a cycle that would latch one; a row whose soft
        limit or following error is still exceeded would leave at once and stays scalar."""
        prof = res.profile
        if prof.mode not in (PrfMode.TRAP, PrfMode.JOG) or not prof.planner.done:
            return False  # (a Gear or Follow slave may start with its master, no call on it)
        return _within_safety(ax, res)

    @staticmethod
    def _latched_away(ax: Any, res: Any) -> bool:
        """A row moving in Trap with limit flags latched and nothing else (a smart homing
        leaving the limit it stopped on): AxisResources._post stops such a motion only at a
        sample toward a latched side, and the bank gives the row back before that cycle
        (:attr:`lvel`); a soft limit or following error still exceeded stays scalar."""
        if res.latched & ~(_POS_LIMIT | _NEG_LIMIT):
            return False
        prof = res.profile
        pl = prof.planner
        if prof.mode != PrfMode.TRAP or pl is not prof.trap or not isinstance(pl, TrapPlanner):
            return False
        if pl._mode != _MOVE:
            return False
        return _within_safety(ax, res)

    def _eligible_frozen(self, r: int, powered: bool = False) -> bool:
        """A servo-off axis whose drive rests unpowered (gtecat.drives.csp_bank.frozen_claimable),
        or (``powered``) a servo-on axis whose drive stands in homing mode before a homing
        (gtecat.drives.homing_bank.idle_claimable; the axis layer follows the drive as for a
        servo-off one: AxisResources._post): every value of its cycle stays as it is, so the
        compiled cycle skips the row (the image keeps the values the scalar objects wrote)."""
        if self.kernel is None:
            return False
        ch = self.csp.channels[r]
        if powered and idle_claimable(ch):
            return False  # (first: an axis just switched waits for its drive's 6061h here)
        ax, res = self.axes[r], self.res[r]
        if ax.link_lost or ax.cw != ax._cw_sent or ax.plan_error or ax.cw == CW_QUICK_STOP:
            return False  # (a quick stop the drive finishes: its controlword changes after it)
        st = self._homing_hook(ax, res)
        if st is False or (st is not None and st.active):
            return False
        if ax.prf_pos != res._a_last or res._csp != (ax.mode_cmd == 8):
            return False
        if None in (res._act, ax._tp_acc, ax._pos_acc):
            return False
        pl = res.profile.planner
        if not pl.done or pl.stopping != StopKind.NONE:
            return False
        if not self._inputs_plain(ax, res):
            return False
        enc = res.encoder
        if enc.vel != 0.0 or enc.acc != 0.0:
            return False
        a = (res._act.get() - ax.drive_offset) / (1 << ax.pos_scale)
        if a != ax.prf_pos or pl.pos != res.prf_link.source(a):
            return False  # the plan does not follow 6064h yet
        if ax._tp_acc.get() != ax._pos_acc.get():
            return False  # 607Ah does not hold 6064h yet
        s = res.safety
        if s.active:
            # the flags its cycle would latch (AxisResources._post) are latched already - a
            # drive alarm the application has not cleared yet - or the row stays scalar
            would = 0
            if s.alarm_on and res._alarm_sw is not None and res._alarm_sw.get() & _SW_FAULT:
                would |= _ALARM
            if a > s.soft_positive or ch.digital_inputs & 2:
                would |= _POS_LIMIT
            if a < s.soft_negative or ch.digital_inputs & 1:
                would |= _NEG_LIMIT
            if would & ~res.latched:
                return False
        b = res.band
        if b.band > 0:
            err = a - res.enc_link.axis(enc.pos)
            inside = -b.band <= err <= b.band
            if (inside and not b.arrived) or (not inside and (b._since is not None or b.arrived)):
                return False  # bit 11 still changes with time
        return powered or not frozen_claimable(ch)

    def _eligible_homing(self, r: int) -> bool:
        """An axis whose drive runs a homing search, moves back onto the home point found, or
        brakes and rests in homing mode after its homing (gtecat.drives.homing_bank), limit
        flags latched or not: the axis layer only follows it (607Ah = 6064h, the plan = the
        actual position, the encoder), so the compiled cycle runs the row whole."""
        if self.kernel is None:
            return False  # the numpy cycle has no homing rows
        ax, res = self.axes[r], self.res[r]
        if not ax.servo_on or ax.link_lost or res._csp:
            return False
        if self.csp.channels[r].homing is None:  # standing before a homing: frozen, powered
            return self._eligible_frozen(r, powered=True)
        st = self._homing_hook(ax, res, 2)
        if st is False:
            return False
        searching = st is not None and st.active
        if searching:
            if ax.cw != 0x1F or ax._cw_sent != 0x1F or not st.answered:
                return False
        elif ax.cw not in (0x0F, 0x1F) or ax._cw_sent != ax.cw:
            return False
        if ax.prf_pos != res._a_last:
            return False
        latched = res.latched
        if latched:
            # limit flags latched (a search that met a limit switch, a home on one): in homing
            # mode nothing reacts to them (the drive ignores its limit inputs, the plan follows
            # the drive), so they only stand in GT_GetSts; any other flag, or a soft limit
            # exceeded now, stays scalar
            if latched & ~(_POS_LIMIT | _NEG_LIMIT) or not _within_soft_limits(ax, res):
                return False
        ch = self.csp.channels[r]
        on = ch.digital_inputs & 3
        if on:  # on a limit switch: the compiled cycle keeps the row while its flag is latched
            need = (_POS_LIMIT if on & 2 else 0) | (_NEG_LIMIT if on & 1 else 0)
            if latched & need != need:
                return False
        if None in (res._act, res._cmd, ax._tp_acc, ax._pos_acc):
            return False
        pl = res.profile.planner
        if not pl.done or pl.stopping != StopKind.NONE:
            return False
        if not self._inputs_plain(ax, res):
            return False
        h = ch.homing
        if searching and (h is None or not homing_row_kind(h)):
            return not homing_claimable(ch)
        return not homing_rest_claimable(ch)  # (a run still followed: SW10 gives it back)

    @staticmethod
    def _inputs_plain(ax: Any, res: Any) -> bool:
        enc = res.encoder
        if not (enc._primed and enc.active):
            return False
        s = res.safety
        n = ax.number
        if s.alarm_input not in (n, None) or s.smooth_stop_input or s.abrupt_stop_input:
            return False
        if s.positive_input not in (n, None) or s.negative_input not in (n, None):
            return False
        din = ax.io.get(0x60FD)
        e = res._pos_din
        if e is not None and e is not din:
            return False  # a configuration's reverse (SensedInput) or another source
        e = res._neg_din
        if e is not None and e is not din:
            return False
        # the alarm read through a reverse: the kernel reads 6041h as it is
        return res._alarm_sw is res._sw

    def refresh(self) -> None:
        """Claim every slave whose axes are all eligible; drop all when the bank cannot run."""
        self.dirty = False
        self._countdown = RECHECK_CYCLES
        if not self.built:
            self._build()
        if not self.n:
            return
        reason = self._global_reason()
        if reason:
            if self.n_alive:
                self.release_all()
            return
        changed = missed = loaded = False
        for gs, srows, bad in self._components():
            if gs[0].claimed and (len(gs) == 1 or all(g.claimed for g in gs)):
                continue
            if (self._held_out >= 0 or self._opened) and any(
                r == self._held_out or r in self._opened for g in gs for r in g.rows
            ):
                continue  # (out for a call: call_opened takes it when the call returns)
            held = [g for g in gs if g.claimed]
            if held:  # part of a cluster is out: the rest comes back too, then all together
                self._release_groups(held)
                changed = True
            if bad or any(g.drive.al_state != AlState.OP for g in gs):
                continue
            if not all(self._eligible(r) for g in gs for r in g.rows):
                continue
            if srows and not all(self._steppable(r) for r in srows):
                continue
            if not all(self._can_claim(g) for g in gs):
                missed = True
                continue
            for r in srows:
                self.sampled[r] = True
            for g in gs:
                self._claim(g)
            loaded = True
            if srows:
                _Bypass.on = True
                try:
                    cl = Cluster(self, srows, [self._gi[id(g)] for g in gs])
                finally:
                    _Bypass.on = False
                for gi in cl.groups:
                    self._cluster_of[gi] = cl
                for c in cl.systems:
                    c.banked = True
            changed = True
        if loaded:
            self.csp.after_loads()
        if changed:
            self._reindex()
        if self.n_alive == self.n:
            self._wait = 1
        else:
            # rows left out: look again soon (a drive settling after a call: a few cycles),
            # then less and less often (a row out for long costs a look every RECHECK_CYCLES)
            self._countdown = min(self._wait, RECHECK_CYCLES)
            self._wait = min(2 * self._wait, RECHECK_CYCLES)
        if missed and not self._missed:
            # an eligible drive had not yet taken (or sent) what the image holds: its next
            # scalar step does, so look again after it rather than RECHECK_CYCLES later
            self._countdown = 1
        self._missed = missed

    def _components(self) -> list[tuple[list[_Group], list[int], bool]]:
        """The groups to claim together, each with its rows a cluster steps ahead and whether
        a dependency keeps it scalar (gtecat.controller.bank_modes); a group alone otherwise."""
        if not hasattr(self, "_gi"):
            self._gi = {id(g): gi for gi, g in enumerate(self.groups)}
            self._cluster_of: dict[int, Cluster] = {}
            pos = {id(ax): k for k, ax in enumerate(self.ctl._axis_list)}
            self.order = [pos.get(id(ax), k) for k, ax in enumerate(self.axes)]
        _Bypass.on = True
        try:
            pairs, sampled, bad = links(self)
        finally:
            _Bypass.on = False
        if not pairs and not sampled and not bad:
            singles = self._singles
            if singles is None:
                singles = self._singles = [([g], [], False) for g in self.groups]
            # the groups out of the bank alone (refresh passes over the claimed ones)
            return [singles[gi] for gi in (~self._g_claimed).nonzero()[0].tolist()]
        group_of = self.group_of
        parent = list(range(len(self.groups)))

        def find(i: int) -> int:
            while parent[i] != i:
                parent[i] = parent[parent[i]]
                i = parent[i]
            return i

        for a, b in pairs:
            ra, rb = find(group_of[a]), find(group_of[b])
            if ra != rb:
                parent[ra] = rb
        comps: dict[int, list[int]] = {}
        for gi in range(len(self.groups)):
            comps.setdefault(find(gi), []).append(gi)
        bad_g = {group_of[r] for r in bad}
        out = []
        for gis in comps.values():
            gs = [self.groups[gi] for gi in gis]
            srows = sorted(r for g in gs for r in g.rows if r in sampled)
            out.append((gs, srows, any(gi in bad_g for gi in gis)))
        return out

    def _steppable(self, r: int) -> bool:
        """A row a cluster steps: driven in CSP, its planner PT/Gear/Follow/crd or a Trap
        (a master)."""
        ax = self.axes[r]
        if not ax.servo_on or ax.mode_cmd != 8:
            return False
        pl = self.res[r].profile.planner
        return sampled_kind(pl) or trap_steppable(pl)

    def _can_claim(self, g: _Group) -> bool:
        """:meth:`_claim` would take the group now: the slave decoded exactly what is in the
        image (no raw write since its last step) and sent what its objects hold now (the bank
        leaves the constant TxPDO entries - analog inputs, 603Fh... - as the last scalar step
        wrote them, so one changed since, e.g. a test's set_analog_input, waits for the next
        scalar step to be sent first)."""
        sl = self.ctl.layout.slaves[g.position]
        if sl.out_bytes:
            start = (sl.out_logical_bit or 0) >> 3
            now = self.ctl.master.image.buffer[start : start + sl.out_bytes].tobytes()
            if now != bytes(g.drive.rx[: sl.out_bytes]):
                return False
        drive = g.drive
        codec = drive.codec
        if len(drive.tx) >= codec.tx_bytes:
            fresh = bytearray(len(drive.tx))
            codec.encode(fresh)
            if fresh != drive.tx:
                return False
        return True

    def _claim(self, g: _Group) -> None:
        """Take the group (the caller found :meth:`_can_claim`); the drives' flags follow
        in :meth:`refresh`, once for every group it takes."""
        for r in g.rows:
            self.csp.load(r, flags=False)
            self._load(r)
        g.claimed = True
        gi = self._gi[id(g)]
        self._g_claimed[gi] = True
        for obj in self._guarded_objects(g):
            key = id(obj)
            _OWNER[key] = (self, gi)
            _set(obj, "__class__", _guard_class(type(obj)))
            if key not in _OWN_DICT:  # (a class assigned: see gtecat._attrs; once is enough)
                _OWN_DICT.add(key)
                own_dict(obj)
        return True

    def _guarded_objects(self, g: _Group) -> list[object]:
        """The objects of a group's axes that nobody may touch while the bank runs them."""
        out: list[object] = []
        for r in g.rows:
            res = self.res[r]
            ch = self.csp.channels[r]
            out += [ch, self.axes[r], res.profile.planner, res.encoder]
            out.append(res.band)
            if self.csp.tpw[r]:
                out.append(_get(ch, "probe"))  # (its source, function or values touched)
        return out

    def _load(self, r: int, again: bool = False) -> None:
        """Take row ``r`` from its objects; ``again``: a row loaded before whose scale, links,
        limits, band and encoder settings nothing changed since (a step in place).

        (Called at every claim, step in place and posted edge: the attributes are read into
        locals once and each array is indexed once.)"""
        ax, res = self.axes[r], self.res[r]
        self.alive[r] = True
        screw_load(self, r, ax)
        aware = aware_hooks(ax)
        watch = 0
        for obj in aware:
            watch |= obj.bank_watch
        if aware:
            self._aware[r] = aware
        latched = int(res.latched)
        self.lvel[r] = (1 if latched & _POS_LIMIT else 0) | (2 if latched & _NEG_LIMIT else 0)
        res.bank, res.bank_row = self, r
        self.layout += 1
        enc = res.encoder
        b = res.band
        if not again:
            s = ax.pos_scale
            # the constants _reindex's flags look at: looked at again only when a row's changed
            # (a drive given back and taken again mostly brings the same)
            key = (
                s,
                ax.drive_offset,
                res.prf_link.ratio,
                res.prf_link.offset,
                res.enc_link.ratio,
                res.enc_link.offset,
                enc.external,
                enc.sense,
                b.band,
            )
            if self._consts.get(r) != key:
                self._consts[r] = key
                self._loaded = True
            self.unit2[r] = float(1 << s)
            self.unit[r] = 1.0 / (1 << s)
            self.drive_offset[r] = ax.drive_offset
            self.prf_ratio[r], self.prf_off[r] = res.prf_link.ratio, res.prf_link.offset
            self.enc_ratio[r], self.enc_off[r] = res.enc_link.ratio, res.enc_link.offset
            sf = res.safety
            on = sf.active
            self.soft_pos[r] = sf.soft_positive if on else np.inf
            self.soft_neg[r] = sf.soft_negative if on else -np.inf
            self.pos_err[r] = sf.pos_err if on else np.inf
            self.external[r] = enc.external
            self.sense[r] = enc.sense
            self.band[r], self.hold_ns[r] = b.band, b._hold_ns
        self.enc_prev[r] = enc._prev
        self.enc_pos[r], self.enc_vel[r], self.enc_acc[r] = enc.pos, enc.vel, enc.acc
        self._new_claim(r)
        since = b._since
        self.since[r] = -1 if since is None else since
        self.arrived[r] = b.arrived
        pl = res.profile.planner
        self.a_last[r] = ax.prf_pos
        jog = isinstance(pl, JogPlanner) and pl._mode == _JOG_MOVE
        self.jog[r] = jog
        if jog:
            self.jrp[r], self.jrv[r] = pl._raw_p, pl._raw_v
            self.jp[r], self.jv[r], self.ja[r] = pl._pos, pl._vel, pl._acc
            tau = pl._tau
            self.tau[r] = tau
            self.jE[r] = math.exp(-pl._T / tau) if tau > 0.0 else 0.0
            self.jgoal[r] = pl._goal
            self.jacc[r], self.jdec[r] = pl._prm.acc, pl._prm.dec
        sampled = bool(self.sampled[r])  # stepped ahead by its cluster (bank_modes)
        if sampled:
            moving = not pl.done
        else:
            moving = isinstance(pl, TrapPlanner) and pl._mode == _MOVE
        self.moving[r] = moving
        self.taken[r] = 0
        self.k0[r] = pl._k if moving and not sampled else 0
        self.ended[r] = False
        kept = self._kept.pop(r, None)
        if sampled:
            kept = None
        # the last sample so far sits in slot TABLE (moving: the first cycle fills the
        # table) or in slot 0, the hold slot of a row at rest
        slot = self.table if moving else 0
        if moving and not sampled and len(pl._segs) <= MAXSEG and self._kernel_lib is not None:
            segs = pl._segs
            m = len(segs)
            # (packed as doubles straight into the arrays' memory: numpy's conversion of a
            # list costs several times more)
            _SEG_PACK[m].pack_into(self.seg, r * MAXSEG * 32, *chain.from_iterable(segs))
            _TPRM_PACK.pack_into(
                self.tprm,
                r * NTPRM * 8,
                pl._t_done,
                pl._ts,
                pl._t_final,
                float(pl._target),
                pl._dir,
                pl._T,
            )
            self.nseg[r] = m
        else:
            self.nseg[r] = 0
        i = int(self.base[r]) + slot
        # (the tables' flat views: one index instead of a row and a column)
        self._t_p1[i], self._t_v1[i], self._t_a1[i] = pl._pos, pl._vel, pl._acc
        self.t_idx[r] = i
        if moving:
            cur, n, end = 0, 0, -1
            if kept is not None and kept[0] is pl and kept[1] == _trap_key(pl):
                # the same move as when the row left: its table is still in place
                j = pl._k - kept[2]
                if 0 <= j < kept[3]:
                    cur, n, end = j, kept[3], kept[4]
            self.t_cur[r], self.t_len[r], self.t_end[r] = cur, n, end
        else:
            self.t_cur[r], self.t_len[r], self.t_end[r] = 0, 1, 0
        ch = self.csp.channels[r]
        # servo off, or on and standing in homing mode before a homing (_eligible_frozen)
        off = not ax.servo_on
        self.frz_off[r] = off
        self.frz[r] = frozen = off or (ax.mode_cmd == _HOMING_MODE and ch.homing is None)
        # GT_GetSts's latched flags stay as they are while the row is in the bank
        # (_eligible_frozen, _latched_standing)
        self.latched[r] = latched
        if frozen:  # nothing of its cycle changes (_eligible_frozen): CspBank.rested at release
            self.dwatch[r], self.dpost[r] = watch, 0
            self.enc_step0[r] = self.enc_step1[r] = 0.0  # the encoder stands: speed 0
            self.hm[r] = False
            return
        self.hm[r] = homing = ax.mode_cmd == _HOMING_MODE
        if homing:  # the drive's search, or its rest after one (gtecat.drives.homing_bank)
            self._load_homing(r, ch, watch)
            return
        self._post_flags(r, watch, aware, sampled or jog)
        if aware:
            for obj in aware:
                if getattr(obj, "bank_post_next", False):
                    self._post_next.add(r)  # (probe_in_bank: the unit asked)
                    break
            else:
                self._post_next.discard(r)

    def _load_homing(self, r: int, ch: Any, watch: int) -> None:
        """:meth:`_load`'s part of a row whose drive searches its home, moves back onto it or
        rests after its homing (gtecat.drives.homing_bank), after :meth:`CspBank.load`."""
        self.dwatch[r], self.dpost[r] = watch, 0
        h = ch.homing
        for name, attr in HM_ROW_FIELDS:
            getattr(self, name)[r] = getattr(h, attr)
        self.h_set[r] = h._settled
        self.h_done[r] = kind = homing_row_kind(h)  # 0 searching, 1 ended, 2 RETURN
        consts = (homing_constants, homing_rest_constants, homing_return_constants)[kind](h)
        for name, value in consts.items():
            getattr(self, name)[r] = value
        bounds = (-math.inf, math.inf) if kind else homing_event_bounds(h, ch.mech.pos)
        assert bounds is not None  # homing_claimable checked it
        self.h_lo[r], self.h_hi[r] = bounds
        # 6041h: the state bits and remote, step_hm's bits instead of CSP's (oms = hm_bits:
        # none while searching, SW10 and SW12 or SW13 at rest after it)
        self.csp.sw_const[r] += ch.hm_bits - SW12

    def took_homing(self, r: int) -> None:
        """Frozen row ``r``, standing in homing mode before a homing, taken again as the
        homing its drive's objects hold now (gtecat.controller.bank_home_start): what
        :meth:`_load` changes of such a row then - a new claim, not frozen, the homing's part
        (:meth:`_load_homing`) - and what :meth:`CspBank.took_homing` takes of its drive, the
        counts moved with it.  The rest of the row is as its frozen claim took it: its objects
        held its state since, and the homing's start moved none of it."""
        self._new_claim(r)
        self.layout += 1
        self.frz[r] = False
        self.hm[r] = True
        csp = self.csp
        csp.took_homing(r)
        self._load_homing(r, csp.channels[r], int(self.dwatch[r]))
        csp.after_loads()
        self.n_frz -= 1
        self.n_hm += 1
        self.n_rest += int(self.h_done[r] == 1)
        self._after_load(r, False)
        self._counted()

    def _new_claim(self, r: int) -> None:
        """Row ``r`` claimed anew now (the cycle and the claim's number: a call that waits for
        cycles tells a row given back and taken again meanwhile by it)."""
        self.claim_cycle[r] = self.bank_cycles
        self._claims = claims = self._claims + 1
        self.claim_ids[r] = claims

    def _post_flags(self, r: int, watch: int, aware: list[Any], ahead: bool) -> None:
        """Row ``r``'s dwatch and dpost from its hooks' watched bits and its drive's probe
        (``ahead``: a row a cluster steps ahead, or a jog: its edges give it back)."""
        tp = bool(self.csp.tpw[r])
        post = (watch or tp) and not ahead
        if post and len(self.groups[self.group_of[r]].rows) == 1:
            for obj in aware:
                if not obj.bank_post_ready():
                    post = False
                    break
        else:
            post = False
        if post:
            # its hooks (and its drive's probe) take such an edge after the cycle, the row
            # staying (:meth:`_post_events`)
            if tp:  # (a drive mapping the probe's objects: _post_event writes them)
                watch |= TP_POST
            self.dwatch[r], self.dpost[r] = 0, watch
        else:
            self.dwatch[r], self.dpost[r] = watch, 0

    def rests(self, ax: Any) -> bool:
        """``ax``'s row is in the bank frozen (servo off, its drive resting unpowered, or
        standing in homing mode before a homing: :meth:`_eligible_frozen`): the compiled
        cycles skip it, so its process values in the image - 6041h among them - stay as they
        are over every cycle the bank runs."""
        r = self._row_of.get(id(ax)) if self.n_alive else None
        return r is not None and bool(self.alive[r] and self.frz[r])

    # --- a capture unit arming its drive's touch probe -------------------------------------
    def probe_in_bank(self, ax: Any) -> bool:
        """The touch probe of ``ax``'s drive may be armed while the bank runs the axis: a
        drive of one channel (:meth:`_post_pending` runs one row's unit).  Its objects may be
        mapped as PDO: a 60B8h written into the image is what the drive decodes before the
        next cycle (:meth:`_apply_probes`), and the probe's TxPDO objects go into the image
        wherever the bank changes the probe (:meth:`_put_probe`).  Fixed with the layout."""
        r = self._row_of.get(id(ax)) if self.built else None
        if r is None:
            return False
        ok = self._probe_rows.get(r)
        if ok is None:
            ok = self._probe_rows[r] = len(self.groups[self.group_of[r]].rows) == 1
        return ok

    def write_probe(self, ax: Any, write: Callable[[], Any]) -> bool:
        """``write()`` (a capture unit's SDO of 60B8h to ``ax``'s drive) with the row kept
        when the bank runs ``ax`` in a plain state and :meth:`probe_in_bank`: the download
        reaches the drive's objects as on the scalar path (60B8h's value), and the drive
        applies a function that differs from its last one at the start of the next cycle,
        as its own step does (:meth:`_apply_probes`).  False: not such a row (the caller
        writes, and the drive's guard gives the row back)."""
        r = self._row_of.get(id(ax)) if self.n_alive else None
        if r is None or not self._plain_row(r) or not self.groups[self.group_of[r]].claimed:
            return False
        if not self.probe_in_bank(ax):
            return False
        ch = self.csp.channels[r]
        objs = self._open_drive(ch)
        try:
            pdo = write()
        finally:
            if self.groups[self.group_of[r]].claimed:
                _reguard(objs)
        if pdo:  # (60B8h in the image: the drive decodes it before the next cycle)
            acc = _get(ax, "io").get(0x60B8)
            self._took_outputs(r, acc)
            if acc.get() != _get(ch, "tp_function"):
                self._tp_apply.add(r)
        elif _get(ch, "tp_function") != _get(ch, "_tp_applied"):
            self._tp_apply.add(r)
        return True

    def _took_outputs(self, r: int, acc: Any) -> None:
        """The output bytes of the image entry ``acc`` (aligned) were written for row ``r``,
        claimed, whose drive takes them as its own decode would (:meth:`_apply_probes`):
        the raw-write checks' references follow, so the write does not give the row back."""
        at = self._tp_rx.get(r)
        if at is None:  # (fixed with the layout: where the entry's bytes lie in _rx_all)
            gi = self.group_of[r]
            mine = self.groups[gi].rx_bytes.tolist()
            start = self._rx_start[gi]
            at = self._tp_rx[r] = [
                (start + mine.index(b), b)
                for b in range(acc._off, acc._off + acc.bits // 8)
                if b in mine
            ]
        buf, snap = self.ctl.master.image.buffer, self._rx_snap
        changed = [(k, b) for k, b in at if snap[k] != buf[b]]
        if not changed:
            return
        # (a claimed group's bytes lie together in _rx_idx too, after the claimed ones before)
        before = self._claimed_before(self.group_of[r])
        ref = bytearray(self._rx_ref)
        for k, b in changed:
            snap[k] = buf[b]
            if before is not None:
                ref[before + k] = buf[b]
        self._rx_ref = bytes(ref)

    def _put_probe(self, r: int) -> None:
        """Row ``r``'s drive's touch-probe objects mapped as TxPDO (60B9h-60BDh,
        60D1h-60D8h) into the image, as the drive's encode after its step writes them: the
        bank changed its probe (a function applied, an edge taken).  The probe unguarded."""
        pairs = self._tp_tx.get(r)
        if pairs is None:
            pairs = []
            if self._tp_mapped(r):
                io = _get(self.axes[r], "io")
                od = self.groups[self.group_of[r]].drive.od
                b = io.channel * CHANNEL_STRIDE
                assert self._tp_objects is not None  # (_tp_mapped made it)
                for index in self._tp_objects[(io.slave, io.channel)]:
                    acc = io.get(index)
                    var = od.find(index + b, 0) if acc is not None else None
                    if var is not None:
                        get = var.getter or (lambda var=var: var.value)
                        pairs.append((acc, get))
            self._tp_tx[r] = pairs
        for acc, get in pairs:
            acc.set(get())

    @staticmethod
    def _open_drive(ch: Any) -> list[Any]:
        """The guarded ones of a claimed channel and its probe, unguarded (the caller guards
        them again): an SDO of the probe's objects reaches nothing else of the drive."""
        objs = [o for o in (ch, _get(ch, "probe")) if type(o) in _GUARD_SET]
        _unguard(tuple(objs))
        return objs

    def _apply_probes(self) -> None:
        """Before a cycle: a touch probe function written to a claimed drive since its last
        cycle (:meth:`write_probe`) applied as the drive's step applies it first thing
        (TouchProbe.write_function), with the row's probe bounds, guard and post flags."""
        csp = self.csp
        for r in sorted(self._tp_apply):
            g = self.groups[self.group_of[r]]
            if not (self.alive[r] and g.claimed):
                continue
            ch = csp.channels[r]
            objs = self._open_drive(ch)
            acc = _get(self.axes[r], "io").get(0x60B8)
            if acc is not None:  # (the drive's decode of its RxPDO: Drive.step)
                _set(ch, "tp_function", acc.get() & 0xFFFF)
            f = _get(ch, "tp_function")
            probe = _get(ch, "probe")
            if f != _get(ch, "_tp_applied"):
                _set(ch, "_tp_applied", f)
                probe.write_function(f)
                self.probes_armed += 1
                self._put_probe(r)
            on = bool(probe.function & 0x0101)
            csp.tpw[r] = on
            csp.row_changed(r)
            csp.tp_lo[r], csp.tp_hi[r] = (
                probe.quiet_bounds(float(csp.pos[r])) if on else (-np.inf, np.inf)
            )
            if on and probe not in objs:  # (an armed probe carries the row's guard: _claim)
                _OWNER[id(probe)] = (self, self._gi[id(g)])
                if id(probe) not in _OWN_DICT:
                    _OWN_DICT.add(id(probe))
                    own_dict(probe)
                objs.append(probe)
            elif not on and probe in objs:
                objs.remove(probe)
                _OWNER.pop(id(probe), None)
            _reguard(tuple(objs))
            aware = self._aware.get(r, [])
            watch = 0
            for obj in aware:
                watch |= obj.bank_watch
            self._post_flags(r, watch, aware, bool(self.sampled[r] or self.jog[r]))
            self.any_watch = self.any_watch or bool(self.dwatch[r])
            self.any_post = self.any_post or bool(self.dpost[r])
        self._tp_apply.clear()
        csp.any_tp = bool(np.count_nonzero(csp.tpw & self.alive))

    def _post_pending(self) -> None:
        """After a committed cycle: the capture units of :attr:`_post_next` write their touch
        probe's function and read 60B9h (CaptureUnit.bank_pending_post), as their own cycle
        would; a unit whose later reads cannot be counted unsent gives its row back."""
        for r in sorted(self._post_next):
            g = self.groups[self.group_of[r]]
            if not (self.alive[r] and g.claimed):
                continue
            aware = self._aware.get(r, ())
            unit = next((o for o in aware if getattr(o, "bank_post_next", False)), None)
            if unit is None:  # (armed by a post of its own since: nothing pending)
                continue
            ran = int(self.bank_cycles - self.claim_cycle[r])
            objs = self._open_drive(self.csp.channels[r])
            try:
                ok = unit.bank_pending_post(ran)
            finally:
                if g.claimed:
                    _reguard(tuple(objs))
            if g.claimed and not ok:
                self._release_groups([g])
        self._post_next.clear()
        if self._stale:
            self._reindex()

    def _tp_mapped(self, r: int) -> bool:
        """Row ``r``'s drive maps a touch-probe object as TxPDO (fixed with the layout)."""
        got = self._tp_map.get(r)
        if got is None:
            # (what ``io.get(i) is not None`` finds for one of them: the (slave, channel) pairs
            # mapping one, from the layout's mapped objects once instead of a placement
            # lookup per object and row)
            pairs = self._tp_objects
            if pairs is None:
                tp = set(_TP_TX)
                pairs = self._tp_objects = {}
                for slave, index in self.ctl.layout.mapped_objects():
                    k, base = divmod(index - 0x6000, CHANNEL_STRIDE)
                    if 0x6000 <= index and 0x6000 + base in tp:
                        pairs.setdefault((slave, k), []).append(0x6000 + base)
            io = _get(self.axes[r], "io")
            got = self._tp_map[r] = (io.slave, io.channel) in pairs
        return got

    def _keep_table(self, r: int, pl: TrapPlanner) -> None:
        """A moving row leaves: remember its table (its samples stay in ``t_p``/``t_v``/``t_a``
        until the row is loaded again), so that a row given back by a call about another
        axis of its drive takes it up again.  Each sample of a table depends on the move and
        its own index only (trap_table), so the samples are the ones a new table would hold."""
        n = int(self.t_len[r])
        if n <= 0 or self.ended[r] or pl._mode != _MOVE:
            return
        first = int(self.k0[r] + self.taken[r] - self.t_cur[r])  # the planner's count at t_p[r, 0]
        self._kept[r] = (pl, _trap_key(pl), first, n, int(self.t_end[r]))

    def holds(self, ax: Any) -> bool:
        """Whether the bank runs ``ax`` now (asked without giving it back)."""
        for r, a in enumerate(self.axes):
            if a is ax:
                return bool(self.alive[r])
        return False

    def trap_quiet(self, r: int) -> int:
        """The cycles from the next one on in which claimed row ``r``'s Trap move surely goes
        on (the cycle that takes its end sample is not among them); 0 when the row is not
        a claimed Trap move.  From the planner's own end test (TrapPlanner.step): sample
        ``k`` is the end sample when ``k * T >= t_done - eps``."""
        if not (self.alive[r] and self.moving[r]) or self.sampled[r] or self.jog[r]:
            return 0
        if self.hm[r] or self.frz[r]:
            return 0
        pl = self.res[r].profile.planner
        cyc, t_done = _get(pl, "_T"), _get(pl, "_t_done")
        thr = t_done - _EPS_T * (1.0 + t_done * 1e-3)
        k = int(self.k0[r] + self.taken[r])  # the samples taken so far
        if not (cyc > 0.0 and math.isfinite(thr)):
            return 0
        end = max(k + 1, math.ceil(thr / cyc))
        while end > k + 1 and (end - 1) * cyc >= thr:
            end -= 1
        while end * cyc < thr:
            end += 1
        return end - 1 - k

    def keep_last_sample(self, rows: Any) -> None:
        """Before a row's table is written anew: the last sample taken moves to the row's
        spare slot and the row reads it there (as the kernel's refill_row does), because the
        new samples overwrite the table it sat in and a release in this same cycle (a row
        hitting a soft limit) reads it.  ``rows``: one row or an array of rows."""
        last = self.t_idx[rows]
        spare = self.base[rows] + self.table
        for t in (self._t_p1, self._t_v1, self._t_a1):  # (the tables' flat views)
            t[spare] = t[last]
        self.t_idx[rows] = spare

    def _refill(self, r: int) -> None:
        pl = self.res[r].profile.planner
        tl = self.table
        self.keep_last_sample(r)
        _Bypass.on = True
        try:
            k0 = int(self.k0[r] + self.taken[r])
            if self._kernel_lib is not None:  # the same samples, compiled
                segs = np.array(pl._segs, np.float64).reshape(-1, 4)
                prm = np.array([pl._t_done, pl._ts, pl._t_final, float(pl._target), pl._dir])
                out = self._fill_out
                if out is None:
                    out = self._fill_out = np.zeros((3, tl + 1))
                end = trap_fill(self._kernel_lib, segs, pl._T, prm, k0, tl, out)
                m = end + 1 if end < tl else tl
                p, v, a = out[0, :m], out[1, :m], out[2, :m]
            else:
                p, v, a, end = trap_table(pl, tl, k0)
        finally:
            _Bypass.on = False
        m = len(p)
        self.t_p[r, :m], self.t_v[r, :m], self.t_a[r, :m] = p, v, a
        self.t_len[r] = m
        self.t_cur[r] = 0
        self.t_end[r] = end if end < tl else -1

    def _fill_tables(self) -> None:
        """New Trap samples for the moving rows whose table ran out; :attr:`_refill_in`: the
        cycles until the next one runs out."""
        moving, cur = self.moving, self.t_cur
        # (a row given back keeps its flags until it is claimed again: not one to fill)
        need = moving & self.alive & (cur >= self.t_len)
        if np.count_nonzero(need):
            self._materialise()
            filled: set[int] = set()  # the rows of the clusters filled
            alone: dict[Any, list[int]] = {}  # PT/PVT rows alone: per compiled fill
            stream_rows: list[int] = []
            group_of = self.group_of
            flags = self.sampled[need].tolist()
            for r, sampled in zip(np.nonzero(need)[0].tolist(), flags, strict=True):
                if not sampled:
                    self._refill(r)
                    continue
                if r in filled:
                    continue
                cl = self._cluster_of[group_of[r]]
                if cl.pt_stream:  # a dynamic PT FIFO (bank_pt_stream), all of them at once
                    stream_rows.append(r)
                    cl.snaps = []
                    continue
                if cl.compiled_pt is not None:  # a PT/PVT axis alone: one compiled call
                    alone.setdefault(cl.compiled_pt, []).append(r)
                    cl.snaps = []
                    continue
                filled.update(cl.rows)
                # the planners step without their guards (a guarded attribute costs ~1 µs);
                # the compiled slaves' (bank_slaves) are not touched
                guarded = [(pl, type(pl)) for pl in cl.stepped]
                guarded = [(pl, c) for pl, c in guarded if _GUARDS.get(c.__mro__[1]) is c]
                for pl, cls in guarded:
                    _set(pl, "__class__", cls.__mro__[1])
                try:
                    cl.fill(self)  # every moving row of the cluster, the same cycles
                finally:
                    for pl, cls in guarded:
                        _set(pl, "__class__", cls)
            for fill, rows in alone.items():
                self.sampled_samples += fill.fill(self, rows, SAMPLED_TABLE)
            if stream_rows:
                self.sampled_samples += stream_of(self).fill(stream_rows, SAMPLED_TABLE)
        left = (self.t_len - cur)[moving]
        self._refill_in = int(left.min()) if len(left) else self.table

    # --- release ---------------------------------------------------------------------------------
    def release_all(self) -> None:
        if self.n_alive:
            self._release_groups([g for g in self.groups if g.claimed])
            self._settled = False  # (a release after settle: the next cycle looks again)

    def row_position(self, ch: Any) -> float | None:
        """The mechanics position of drive channel ``ch`` where a row of this bank runs it:
        its committed state after the last cycle, read without giving the row back (a
        fault trigger looks at it between cycles: :mod:`gtecat.faults`); None where the
        channel's own object holds it."""
        if type(ch) not in _GUARD_SET:
            return None
        entry = _OWNER.get(id(ch))
        if entry is None or entry[0] is not self:
            return None
        csp = self.csp
        for r, c in enumerate(csp.channels):
            if c is ch:
                return float(csp.pos[r]) if self.alive[r] else None
        return None

    def hold(self, axes: frozenset[int]) -> None:
        """Keep the GT ``axes`` off the bank from now on, the others as they are (a fault
        fault may meet them in the next cycle: :mod:`gtecat.faults`); an empty set
        lets them back at the next refresh."""
        axes = frozenset(axes)
        if axes == self.held:
            return
        self.held = axes
        for n in axes if self.built else ():
            ax = self.ctl.axes.get(n)
            if ax is not None:
                self.release_axis_object(ax)
        self.dirty = True
        self._settled = False  # (a hold after settle: the next cycle looks again)

    def before_axis_call(self, ax: Any, res: Any) -> None:
        """What :meth:`before_call` does for a GT function naming one existing axis ``ax``
        (its resources ``res``) by its first parameter (``axis``, ``profile`` or ``encoder``,
        no ``count``), for the GT fast path: the bank looks again, and ``ax`` goes back.  A
        row is alive exactly while its resources name this bank (:meth:`_load`,
        :meth:`_store`), so an axis whose resources do not has nothing to give back."""
        self.dirty = True
        if self.n_alive and res.bank is self:
            self.release_axis_object(ax)

    def look_again(self) -> None:
        """A call changed what a bank-aware hook's watchers read without giving its axis
        back (a capture cleared): they look again before the next cycle, as after a release
        (:attr:`releases`)."""
        self.releases += 1
        self.dirty = True

    def hook_added(self, ax: Any, obj: Any) -> None:
        """``obj``, a bank-aware post hook (:func:`aware_hooks`), was just added to ``ax``'s:
        a row the bank runs takes it among its own (it catches up at the release as the
        others do) when it may be held and watches nothing (a capture unit made with nothing
        armed), else the row goes back."""
        r = self._row_of.get(id(ax))
        if r is None or not self.alive[r]:
            return
        if obj.bank_watch or not obj.bank_ready():
            if r != self._stepping:
                self.release_axis_object(ax)
            return
        aware = self._aware.get(r)
        if aware is None:
            self._aware[r] = [obj]
        elif obj not in aware:
            aware.append(obj)

    def watch_grew(self, ax: Any) -> None:
        """A bank-aware hook of ``ax`` watches more 60FDh bits (:attr:`dwatch`, read at a
        claim): a claimed row goes back, but the row a step runs on in place, which is
        taken up again after the step (:meth:`step_claimed`)."""
        r = self._row_of.get(id(ax))
        if r is not None and r != self._stepping:
            self.release_axis_object(ax)

    def release_axis_object(self, ax: Any) -> None:
        r = self._row_of.get(id(ax))
        if r is not None and self.alive[r]:
            self._release_groups([self.groups[self.group_of[r]]])

    def _release_axes(self, axes: list[Any]) -> None:
        """Give back the groups of ``axes`` that the bank runs, in one release."""
        gis = set()
        for ax in axes:
            r = self._row_of.get(id(ax))
            if r is not None and self.alive[r]:
                gis.add(self.group_of[r])
        if gis:
            self._release_groups([self.groups[gi] for gi in sorted(gis)])

    def _release_groups(self, groups: list[_Group]) -> None:
        """Write the rows' committed state back into their objects; they leave the bank.
        The readers' epoch grows (gtecat.controller.epoch): a release inside a fast
        reader's call (a guarded object read: GT_GetDo's outputs) would otherwise leave the
        quick cycle the readers' C entries run armed for a bank without those rows, and
        their axes would stand still while time passes (Controller.arm_quick)."""
        if groups:
            EPOCH.n += 1
        clusters: list[Cluster] = []
        if getattr(self, "_cluster_of", None):
            out = list(groups)
            for g in groups:
                cl = self._cluster_of.get(self._gi[id(g)])
                if cl is not None and cl not in clusters:
                    clusters.append(cl)
                    out += [self.groups[gi] for gi in cl.groups if self.groups[gi] not in out]
            groups = [g for g in out if g.claimed]
        rows = [r for g in groups for r in g.rows]
        if len(rows) > 4 and 4 * len(rows) >= self.n:
            self._materialise()
            vel, acc = self._enc_rates()
            p, v, a = self.prf_p, self.prf_v, self.prf_a
            self._last = {r: (float(p[r]), float(v[r]), float(a[r])) for r in rows}
            self._rates = {r: (float(vel[r]), float(acc[r])) for r in rows}
        else:  # a few rows: theirs alone, the same operations in Python floats
            self._last = {r: self._planned_row(r) for r in rows}
            self._rates = {r: self._enc_rates_row(r) for r in rows}
        for g in groups:
            for obj in self._guarded_objects(g):
                _OWNER.pop(id(obj), None)
                cls = type(obj)
                if cls in _GUARD_SET:
                    _set(obj, "__class__", cls.__base__)
            g.claimed = False
            self._g_claimed[self._gi[id(g)]] = False
        opened = self._opened
        if opened:  # (a row opened for a call: its objects hold its state, nothing to store)
            rows = [r for r in rows if r not in opened]
        frz = self.frz
        if any(frz[r] for r in rows):
            # a frozen row's channel holds what its skipped cycles would have left
            csp = self.csp
            moved = [r for r in rows if not frz[r]]
            if moved:
                csp.store(moved)
            for r in rows:
                if frz[r]:
                    csp.rested(r)
        else:
            self.csp.store(rows)
        for r in rows:
            self._store(r)
        self.releases += 1
        for r in rows:
            self._catch_up(r)
        for g in groups:
            if opened and not self.alive[g.rows[0]] and g.rows[0] in opened:
                continue  # (its drive stepped itself: its buffers are its own)
            self._drive_buffers(g)
        for cl in clusters:
            # the planners stand where the scalar path has them (bank_modes.Cluster.rewind)
            cl.rewind(self)
            for c in cl.systems:
                c.banked = False
                c.trace = None
                c.push_hook = None
            for gi in cl.groups:
                self._cluster_of.pop(gi, None)
            self.sampled[cl.rows] = False
        self.dirty = True
        self._wait = 1
        # the image addresses and run lists follow at the next cycle (_reindex), not once per
        # release: a loop of GT calls over many axes releases one slave per call
        self._stale = True
        self.n_alive = int(np.count_nonzero(self.alive))

    def _catch_up(self, r: int) -> None:
        """Row ``r``'s bank-aware hooks catch up with the cycles the bank ran since its claim
        (they ran in the bank: nothing they watch happened), as the row leaves it."""
        aware = self._aware.pop(r, None)
        if aware:
            ran = int(self.bank_cycles - self.claim_cycle[r])
            for obj in aware:
                obj.bank_released(ran)

    def _drive_buffers(self, g: _Group) -> None:
        """Group ``g``'s drive's process data buffers as its own steps would have left them:
        the entries the bank wrote into the image in them too (its other bytes are as they
        were, so a raw write or a changed constant still waits for a step of its own:
        _can_claim).  607Ah as the bank last sent it, not as the image holds it now: a raw
        write since (not looked at: the bank writes 607Ah itself) never reached the drive -
        one cut off by a pulled cable runs on what it last received, as on the scalar path."""
        buf = self.ctl.master.image.buffer
        target = self.csp.target
        rx, tx = g.drive.rx, g.drive.tx
        for byte, size, out, i, r in g.computed:
            dst = rx if out else tx
            if 0 <= i and i + size <= len(dst):
                if out:
                    sent = (int(target[r]) & 0xFFFFFFFF).to_bytes(4, "little")
                    dst[i : i + size] = sent[:size]
                else:
                    dst[i : i + size] = buf[byte : byte + size].tobytes()

    def _store(self, r: int) -> None:
        self.alive[r] = False
        self._open.discard(r)
        # (an arming under way goes on on the scalar objects: the unit writes the function at
        # its next cycle, the drive applies one written at its next step)
        self._post_next.discard(r)
        self._tp_apply.discard(r)
        self.claim_ids[r] = 0
        self.res[r].bank = None
        self.layout += 1
        if r != self._stepping:  # (a row stepped in place: its objects hold its state)
            self._put_back(r)
        if r == self.home_switch:  # (given back while its drive switches: bank_home_rows)
            switch_released(self, r)
        # (_reindex counts these over every row: a row given back has them clear; jog, hm,
        # h_done and frz are cleared by _put_back, and a row stepped in place has none)
        self.dwatch[r] = self.dpost[r] = self.lvel[r] = 0

    def _put_back(self, r: int) -> None:
        """Row ``r``'s state into its axis objects (its drive aside), as a release leaves them
        (:attr:`_rates` holds its encoder rates, :attr:`_last` its planned values where a
        release found them; a row still alive - a step in place, a posted edge - has them
        found here, where a moving planner needs them)."""
        ax, res = self.axes[r], self.res[r]
        screw_put_back(self, r, ax)
        a = float(self.a_last[r])
        ax.prf_pos = a
        res._a_last = a
        enc = res.encoder
        enc._prev = wrap32(int(self.enc_prev[r]))  # the 32-bit value the object holds
        enc.pos = float(self.enc_pos[r])
        enc.vel, enc.acc = self._rates[r]
        b = res.band
        since = int(self.since[r])
        b._since = None if since < 0 else since
        b.arrived = bool(self.arrived[r])
        pl = res.profile.planner
        if self.frz[r]:  # (its channel as it was: CspBank.rested)
            self.frz[r] = self.frz_off[r] = False
            return
        if self.hm[r]:
            self.hm[r] = self.h_done[r] = False
            ch = self.csp.channels[r]
            ch.oms = ch.hm_bits  # step_hm (no following-error flag: the row would have left)
            h = ch.homing
            for name, attr in HM_ROW_FIELDS:
                setattr(h, attr, float(getattr(self, name)[r]))
            h._settled = bool(self.h_set[r])
            # AxisResources._post: the plan holds the axis's actual position
            p = res.prf_link.source(a)
            if p != pl.pos or not pl.done:
                pl.hold(p)
            return
        if self.sampled[r]:
            return  # its cluster puts the planner back (_release_groups)
        if self.jog[r]:
            pl._raw_p, pl._raw_v = float(self.jrp[r]), float(self.jrv[r])
            pl._pos, pl._vel, pl._acc = float(self.jp[r]), float(self.jv[r]), float(self.ja[r])
            self.jog[r] = False
            return
        if isinstance(pl, TrapPlanner) and pl._mode == _MOVE:
            last = self._last.get(r)
            if last is None:  # (a step in place or a posted edge: the row is still alive)
                last = self._planned_row(r)
            advance(pl, int(self.taken[r]), last, bool(self.ended[r]))
            self._keep_table(r, pl)

    # --- the GT boundary ------------------------------------------------------------------------
    def before_call(self, ctl: Any, proto: Any, values: tuple) -> None:
        """A GT function is about to run on ``ctl`` (the core, or a view of a core beyond
        32 axes): release what it may look at or change."""
        self.dirty = True
        if not self.n_alive:
            return
        params = proto.params
        if params and values and type(values[0]) is int:
            name = proto.name
            if params[0].name == "crd" and name not in _CRD_ALL:
                # a segment pushed onto the tail of a path the bank holds ahead: kept there
                # where no cycle of the bank's window reaches the tail (_push_ahead); else a
                # call on one coordinate system gives back its own cluster (its axes and any
                # other object it reaches release themselves through their guards)
                if not (_crd_push(name) and self._push_ahead(ctl, proto, values)):
                    self._release_systems(ctl, [values[0]])
                return
            masked = _CRD_MASKS.get(name)
            if masked is not None:
                first, axis_bits = masked
                m = values[0]
                self._release_systems(ctl, [n for n in (1, 2) if m >> (first + n - 1) & 1])
                if not m & axis_bits:
                    return
                values = (m & axis_bits, *values[1:])  # the axes of the mask, below
        if params and params[0].name in ("axis", "profile", "encoder") and values:
            counted = _COUNTED.get(proto.name)
            if counted is None:  # (a function's parameters do not change: asked once)
                counted = _COUNTED[proto.name] = next(
                    (k for k, p in enumerate(params) if p.name == "count"), 0
                )
            n = values[0]
            if not counted:
                ax = ctl.axes.get(n) if type(n) is int else None
                if ax is not None:
                    self.release_axis_object(ax)
                    return
            elif counted < len(values):
                # GT_ClrSts(axis, count), GT_ZeroPos(axis, count): the axes of the span go
                # back (what else the function reaches gives itself back through its guard)
                count = values[counted]
                if type(n) is int and type(count) is int and 0 < count <= _SPAN_MOST:
                    axes = ctl.axes
                    named = [ax for ax in map(axes.get, range(n, n + count)) if ax is not None]
                    if named:
                        self._release_axes(named)
                        return
        if params and params[0].name == "slave_position" and values and type(values[0]) is int:
            # an SDO to one slave: its axes go back (the drive's objects it reaches give
            # themselves back through their guards too); no other axis is touched
            slave = values[0]
            mine = [g for g in self.groups if g.claimed and g.position == slave]
            if mine:
                self._release_groups(mine)
            return
        if params and params[0].name == "mask" and values and type(values[0]) is int:
            # GT_Update(mask), GT_Stop(mask, option): only the axes of the mask go back
            mask = values[0]
            axes = ctl.axes
            named = [axes.get(n) for n in range(1, mask.bit_length() + 1) if mask >> (n - 1) & 1]
            if named and all(ax is not None for ax in named):
                for ax in named:
                    self.release_axis_object(ax)
                return
        self.release_all()

    def call_in_place(self, ctl: Any, proto: Any, values: tuple, call: Callable[[], Any]) -> Any:
        """``call()``'s result, a GT function of :data:`IN_PLACE` with ``values`` on ``ctl``:
        run on its axis's claimed row in place (:meth:`_in_place`, as a smart homing's step:
        the row's state into its axis, planner, encoder and band objects, the call, the row
        taken up again from them when it is still what :meth:`_eligible` asks for, else given
        back) instead of giving its drive back before it and claiming it again at the next
        cycle, which is what :meth:`before_call` does (and what happens here for any other
        row).  A Trap move started again and again (GT_PrfTrap, GT_SetTrapPrm, GT_SetPos,
        GT_SetVel, GT_Update of one axis) then leaves every drive in the bank; the values are
        the same (a release and a claim put the same state into the objects and take it back)."""
        self.dirty = True
        if proto.name in _PROFILE_ONLY:  # (nothing of the row: as it stands, guards on)
            return call()
        r = self._in_place_row(ctl, proto, values)
        if r < 0:
            self.before_call(ctl, proto, values)
            return call()
        if proto.name == "GT_PrfTrap" and self._trap_held(r):
            self.trap_holds += 1
            # GT_PrfTrap of an axis already standing in Trap mode holds its planner where it
            # stands (Profile.enter): the values it writes are the ones it finds, so the row
            # is not put into the objects and taken up again around it (the planner, whose
            # hold writes a dozen attributes, without its guard's Python call on each)
            pl = (self.res[r].profile.planner,)
            _unguard(pl)
            _Bypass.on = True
            try:
                return call()
            finally:
                _Bypass.on = False
                _reguard(pl)
        done: list[Any] = []
        self._in_place(r, self.groups[self.group_of[r]], lambda: done.append(call()))
        return done[0]

    def call_opened(self, ctl: Any, proto: Any, values: tuple, call: Callable[[], Any]) -> Any:
        """``call()``'s result, a GT function of :data:`OPENED` with ``values`` on ``ctl``.

        Its axis's row (a drive of one channel the bank runs) is *opened* for the call: its
        state goes into its objects as at a release and their guards come off, the compiled
        cycle leaves the row out, and each cycle the call waits for (the drive's answer to a
        new 6060h or to CW4) steps the row's objects as the scalar path steps them - the
        axis's pre step, its drive's exchange, the axis's post step (:meth:`_step_opened`).
        When the call returns the row is taken again from its objects if it is in a state
        the bank runs (as :meth:`refresh` would take it at the next cycle), else given back.
        The bus and the controller keep the slave and the axis as the bank's meanwhile
        (nothing re-indexed), and nothing else is looked at: a drive homing's set-up cost
        per axis on a bus of 64 axes standing in the bank a release, a re-index, a look
        over every row and a claim before.  Where the controller has per-cycle hooks (which
        run between the bank's cycle and the axes' steps) the row goes back for the call
        instead and is taken again as it returns (:meth:`_open_released`).

        A frozen row (:meth:`_eligible_frozen`: servo off, or standing in homing mode
        before its homing) is not even opened unless a cycle comes: its objects hold its
        state already (nothing of its cycles changes), so the call runs on them without
        their guards, and the row stays when the call returns with no cycle run and the row
        still frozen (a drive's homing parameters written by SDO: GT_SetEcatHomingPrm).  A
        cycle due meanwhile opens it first (:meth:`_begin`), its objects as the call left
        them."""
        ax = ctl.axes.get(values[0]) if values and type(values[0]) is int else None
        r = self._row_of.get(id(ax)) if ax is not None and self.n_alive else None
        if (
            r is None
            or not self.alive[r]
            or self._stepping >= 0
            or self._opened
            or self._frozen_call >= 0
            or self.kernel is None
        ):
            self.before_call(ctl, proto, values)
            return call()
        g = self.groups[self.group_of[r]]
        if len(g.rows) != 1 or self.sampled[r] or not g.claimed or r in self._open:
            self.before_call(ctl, proto, values)
            return call()
        clock = ctl.clock
        if ctl.pre_cycle or ctl.post_cycle:
            return self._open_released(r, g, clock, call)
        if self.frz[r] and r not in self._aware:
            objs = tuple(self._guarded_objects(g))
            _unguard(objs)
            self._frozen_call = r
            self._frozen_stale = self._stale
            self._frozen_start = proto.name == "GT_StartEcatHoming"
            self._stale = True  # (no cycle runs many at once: the next one's _begin opens it)
            try:
                return call()
            finally:
                if self._frozen_call == r:  # no cycle came: the row as the call left it
                    self._frozen_call = -1
                    self._stale = self._frozen_stale
                    homing_objects = proto.name == "GT_SetEcatHomingPrm" and values[-1] == 0
                    self._close_in_place(r, g, objs, homing_objects)
                elif self._home_started == r:  # (bank_home_start: the row stays, or went back)
                    self._home_started = -1
                    if g.claimed and self.alive[r]:
                        _reguard(objs)
                    else:
                        self._close(r, g, True)
                else:
                    self._close_opened(r, g)
        mode = values[1] if len(values) == 2 else None  # (a list from a first call's binder)
        if proto.name == "GT_SetHomingMode" and type(mode) is int and mode == 6:
            done = switch_to_homing(self, ctl, r, g)
            if done is not None:
                return done
        self._open_row(r, g, True)
        try:
            return call()
        finally:
            self._close_opened(r, g)

    def _open_row(self, r: int, g: _Group, put_back: bool) -> None:
        """Open claimed row ``r`` (group ``g``, one channel) for :meth:`call_opened`:
        ``put_back``: its state goes into its objects as a release puts it (else they hold
        it: a frozen row a call ran on in place, its objects as the call left them)."""
        EPOCH.n += 1
        objs = self._guarded_objects(g)
        _unguard(tuple(objs))
        for obj in objs:
            _OWNER.pop(id(obj), None)
        csp = self.csp
        # (the counts the cycle looks at, less this row's: its flags are cleared below)
        hm = bool(self.hm[r])
        self.n_jog -= bool(self.jog[r])
        self.n_hm -= hm
        self.n_rest -= hm and self.h_done[r] == 1
        self.n_frz -= bool(self.frz[r])
        self.n_moving -= bool(self.moving[r])
        if put_back:
            if self.frz[r]:
                csp.rested(r)
            else:
                self._last = {r: self._planned_row(r)}
                self._rates = {r: self._enc_rates_row(r)}
                csp.store([r])
            self._store(r)
            self._catch_up(r)
        else:
            csp.rested(r)
            self._stepping = r  # (its objects hold its state: nothing put back)
            try:
                self._store(r)
            finally:
                self._stepping = -1
            self.frz[r] = self.frz_off[r] = False  # (what _put_back clears)
        self.releases += 1
        self.calls_opened += 1
        self._opened[r] = 0  # (the cycles that stepped it: _step_opened, _close_opened)
        self.n_alive -= 1
        self._counted()

    def _step_opened(self, t_ns: int, dt_ns: int) -> None:
        """The cycle of each row opened for a call (:meth:`call_opened`) on its objects, as
        the scalar path runs it: the axis's pre step, its drive's exchange, its post step.
        (The raw-write checks' references of its outputs follow what the axis wrote when the
        bank looks at them, or takes it again: the compiled cycle's check leaves out the rows
        it does not run, and a re-index takes an opened row's bytes first.)"""
        backend = self.ctl.backend
        for r in sorted(self._opened):
            g = self.groups[self.group_of[r]]
            if not g.claimed or self.alive[r]:
                continue  # (given back meanwhile: the scalar path runs it)
            ax = self.axes[r]
            ax.pre(t_ns, dt_ns)
            backend.exchange_one(g.position, t_ns, dt_ns)
            ax.post(t_ns, dt_ns)
            self._opened[r] += 1
        # (what the drives' buffers may have changed by since: _close_opened)
        self._opened_marks = (self.bank_cycles, _outside_marks(backend))

    def _took_group(self, gi: int) -> None:
        """The output bytes of group ``gi`` (claimed, its row opened) as the image holds
        them now are the raw-write checks' references (the row's own objects wrote them)."""
        now, start, stop = self._group_outputs(gi)
        snap = self._rx_snap
        if now == snap[start:stop].tobytes():
            return
        snap[start:stop] = np.frombuffer(now, np.uint8)
        at = self._took_entries(gi)
        if at is not None:  # (the group's bytes lie together among the claimed ones')
            ref = self._rx_ref
            self._rx_ref = ref[:at] + now + ref[at + stop - start :]

    def _group_outputs(self, gi: int) -> tuple[bytes, int, int]:
        """Group ``gi``'s output bytes (607Ah aside) as the image holds them now, and where
        they lie in the references of every group's (:attr:`_rx_snap`)."""
        at = self._grp_pos.get(gi)
        if at is None:
            pos = self.groups[gi].rx_bytes.tolist()
            # (one itemgetter call, not a list made byte by byte: three or four times a call)
            if len(pos) > 1:
                get = itemgetter(*pos)
            else:  # (itemgetter of one index gives the value, of none refuses)
                get = (lambda v, p=pos[0]: (v[p],)) if pos else (lambda v: ())
            at = self._grp_pos[gi] = (len(pos), get)
        n, get = at
        start = self._rx_start[gi]
        return bytes(get(self.ctl.master.image.view)), start, start + n

    def _decoded(self, g: _Group) -> bool:
        """Group ``g``'s drive took in its last exchange the output bytes the image holds now
        (:meth:`_can_claim`'s first look)."""
        at = self._out_area.get(g.position)
        if at is None:
            sl = self.ctl.layout.slaves[g.position]
            start = (sl.out_logical_bit or 0) >> 3
            at = self._out_area[g.position] = (start, start + sl.out_bytes)
        start, stop = at
        rx = g.drive.rx
        return self.ctl.master.image.view[start:stop] == rx[: stop - start]

    def _outputs_kept(self, gi: int) -> bool:
        """Claimed group ``gi``'s output bytes in the image are the raw-write checks'
        references (nothing wrote them since the bank looked)."""
        now, start, stop = self._group_outputs(gi)
        return now == self._rx_snap[start:stop].tobytes()

    def _took_entries(self, gi: int) -> int | None:
        """Where claimed group ``gi``'s output bytes begin in the references of the claimed
        ones (:attr:`_rx_ref`), per pattern; None when the pattern leaves the group out."""
        at = self._took_at.get(gi)
        if at is None or at[0] is not self._rx_idx:
            before = self._claimed_before(gi)
            at = self._took_at[gi] = (
                self._rx_idx,
                None if before is None else before + self._rx_start[gi],
            )
        return at[1]

    def _claimed_before(self, gi: int) -> int | None:
        """Where group ``gi``'s bytes lie in the claimed ones (:attr:`_rx_idx`, :attr:`_rx_ref`)
        less where they lie in every group's (:attr:`_rx_start`); None when the pattern those
        were made for leaves the group out.  (Read from that pattern, not from which groups
        are claimed now: :meth:`_reindex` takes an opened row's bytes before it makes the
        new pattern, a group claimed or given back since.)"""
        gis = self._rx_gi
        p = int(gis.searchsorted(gi))
        if p == len(gis) or gis[p] != gi:
            return None
        return p - self._rx_start[gi]

    def _close_opened(self, r: int, g: _Group) -> None:
        """After :meth:`call_opened`'s call on opened row ``r``: taken again from its objects
        when :meth:`refresh` would take it now, else given back (its objects as they are)."""
        if not g.claimed or self.alive[r]:  # (given back meanwhile: as any released row)
            self._opened.pop(r, None)
            self._close(r, g, True)
            return
        gi = self.group_of[r]
        stepped = self._opened[r] and self._opened_marks == (
            self.bank_cycles,
            _outside_marks(self.ctl.backend),
        )
        if not self._opened[r]:  # (no cycle stepped it: its buffers as a release leaves them)
            self._drive_buffers(g)
        # stepped in the last cycle, nothing written to its outputs since (the image's are
        # what its drive took in that exchange) and no SDO or field change since: its drive
        # decoded what the image holds and sent what its objects hold, as _can_claim looks for
        kept = stepped and self._decoded(g)
        self._took_group(gi)
        if (
            g.drive.al_state == AlState.OP
            and not self._global_reason()
            and self._eligible(r)
            and (kept or self._can_claim(g))
        ):
            self._opened.pop(r, None)
            self.csp.load(r, flags=False)
            self._load(r)
            self.csp.after_loads()
            hm = bool(self.hm[r])
            self.n_jog += bool(self.jog[r])
            self.n_hm += hm
            self.n_rest += hm and self.h_done[r] == 1
            self.n_frz += bool(self.frz[r])
            self._after_load(r, False)
            for obj in self._guarded_objects(g):
                key = id(obj)
                _OWNER[key] = (self, gi)
                _set(obj, "__class__", _guard_class(type(obj)))
                if key not in _OWN_DICT:
                    _OWN_DICT.add(key)
                    own_dict(obj)
            self.n_alive += 1
            self._counted()
            return
        try:
            self._release_groups([g])  # (opened: nothing put back, the objects hold it)
        finally:
            self._opened.pop(r, None)
        self._reindex()
        self.dirty = True

    def _open_released(self, r: int, g: _Group, clock: Any, call: Callable[[], Any]) -> Any:
        """:meth:`call_opened` where per-cycle hooks run: the row goes back for the call (as
        :meth:`before_call` gives it back), and is taken again as the call returns when
        :meth:`refresh` would take it."""
        c0 = clock.cycles
        dirty, stale = self.dirty, self._stale
        wait, countdown = self._wait, self._countdown
        self._release_groups([g])
        # (what the release asks of the next cycle, for the rows a call gives back: nothing
        # of the other rows changes while this call runs)
        self.dirty, self._wait, self._countdown = dirty, wait, countdown
        self._held_out = r
        self.calls_held_out += 1
        try:
            return call()
        finally:
            self._held_out = -1
            self._close(r, g, stale or clock.cycles != c0)

    def _close_in_place(self, r: int, g: _Group, objs: tuple, homing_objects: bool) -> None:
        """After :meth:`call_opened`'s call on frozen row ``r`` with no cycle run: guarded
        again when it is still such a row (what a claim takes of it stays as it was: the
        calls change a drive's homing objects, its mode, its controlword, none of them
        without a cycle) and its outputs in the image are as the bank left them, else
        opened as the call left its objects and taken again from them or given back.
        ``homing_objects``: the call wrote the drive's homing objects and nothing else
        (GT_SetEcatHomingPrm without a probe function: 6098h, 6099h:01/02, 609Ah, 607Ch,
        which a drive takes at CW4's rising edge only, and the GT layer's record of the
        homing, which the bank allows while no run is active), so the row is what it was."""
        gi = self.group_of[r]
        if (
            g.claimed
            and self._outputs_kept(gi)
            and (
                homing_objects
                or (self._eligible(r) and self.frz_off[r] == (not self.axes[r].servo_on))
            )
        ):
            _reguard(objs)
            EPOCH.n += 1
            self.calls_kept += 1
            return
        self._open_row(r, g, False)
        self._close_opened(r, g)

    def _open_in_place(self) -> None:
        """A cycle comes while a call runs on frozen row :attr:`_frozen_call` with its
        guards off (:meth:`call_opened`): the row is opened first, its objects as the call
        left them."""
        r = self._frozen_call
        self._frozen_call = -1
        self._stale = self._frozen_stale
        self._open_row(r, self.groups[self.group_of[r]], False)

    def _close(self, r: int, g: _Group, stale: bool) -> None:
        """After a call whose row went back (:meth:`_open_released`, or given back while
        opened): taken again when :meth:`refresh` would take it now, else the bank looks
        again at the next cycle as after any release (``stale``: cycles ran while it was
        out, or the bank was to re-index anyway)."""
        if (
            not g.claimed
            and g.drive.al_state == AlState.OP
            and not self._global_reason()
            and self._eligible(r)
            and self._can_claim(g)
        ):
            self._claim(g)
            self.csp.after_loads()
            self.n_alive += 1
            if stale:
                self._stale = True
            else:
                # the same rows claimed as before the call: the image's references stand
                # when the call wrote none of the row's outputs (else the re-index looks)
                self._stale = self.ctl.master.image.buffer.take(self._rx_idx).tobytes() != (
                    self._rx_ref
                )
            return
        self.dirty = True
        self._wait = 1

    def _trap_held(self, r: int) -> bool:
        """Claimed row ``r`` stands in Trap mode with its planner (the object and the row)
        as :meth:`TrapPlanner.hold` leaves it where it stands: a hold there changes nothing."""
        if self.moving[r] or self.jog[r] or self.hm[r] or self.frz[r] or self.sampled[r]:
            return False
        prof = self.res[r].profile
        pl = prof.planner
        cls = type(pl)  # (a claimed planner's class is its guard's: _guard_class)
        if cls is not TrapPlanner and cls is not _GUARDS.get(TrapPlanner):
            return False
        if prof.mode != PrfMode.TRAP or not prof.active:
            return False
        g = _get  # (past the planner's guard)
        return (
            g(pl, "_mode") == _IDLE
            and g(pl, "_vel") == g(pl, "_acc") == 0.0
            and not g(pl, "_segs")
            and g(pl, "_i") == g(pl, "_j") == g(pl, "_k") == 0
            and g(pl, "_ts") == g(pl, "_t_done") == g(pl, "_t_final") == 0.0
            and g(pl, "_dir") == 1.0
            and g(pl, "stopping") == StopKind.NONE
            and self._planned_row(r) == (g(pl, "_pos"), 0.0, 0.0)
        )

    def _in_place_row(self, ctl: Any, proto: Any, values: tuple) -> int:
        """The row a call of :data:`IN_PLACE` runs on in place, else -1: one axis (a mask of
        one bit for GT_Update) whose row is claimed in a plain state, not stepping already."""
        if not (self.n_alive and self.built and values) or self._stepping >= 0:
            return -1
        n = values[0]
        if type(n) is not int:
            return -1
        if proto.name == "GT_Update":
            if n <= 0 or n & (n - 1):
                return -1
            n = n.bit_length()
        ax = ctl.axes.get(n)
        r = self._row_of.get(id(ax)) if ax is not None else None
        if r is None or not self._plain_row(r):
            return -1
        return r

    def _push_ahead(self, ctl: Any, proto: Any, values: tuple) -> bool:
        """A GT_LnXY, GT_ArcXY..., GT_HelixXY... or GT_BufDelay onto the running FIFO of a system
        the bank holds a window of cycles ahead may go onto the FIFO as it stands there: the
        segment at its tail is not reached in that window, and no segment starting in it looks
        that far (its exit speed looks at the next segment only, without a look-ahead).  Then
        the entry joins the FIFO kept for the rewind too (:meth:`_pushed_ahead`); True."""
        if ctl.clock.threaded:  # the cycles may go on before the call takes the lock
            return False
        crds = vars(ctl).get("crd_bank")
        c = crds.systems.get(values[0]) if crds is not None else None
        if c is None or not c.banked:
            return False
        names = [p.name for p in proto.params]
        fifo = values[names.index("fifo")] if "fifo" in names else 0
        if type(fifo) is not int or fifo != c.fifo or not c.running or c.stopping:
            return False
        if c.look[fifo] is not None or c.now().space(fifo) <= 1:
            return False
        for e in c.fifos[fifo]:  # a delay, or a segment of some length, before the tail
            if type(e) is Delay or (type(e) is Motion and e.geom.length > 0.0):
                break
        else:
            return False
        cl = next((x for x in self._cluster_of.values() if c in x.systems), None)
        if cl is None:
            return False
        c.push_hook = lambda c, entry, fifo: self._pushed_ahead(cl, c, entry, fifo)
        return True

    def _pushed_ahead(self, cl: Cluster, c: Any, entry: Any, fifo: int) -> None:
        if cl.snaps is not None:  # (None: the system stands where the scalar path has it)
            for obj, snap in cl.snaps:
                if obj is c:
                    kept_push(c, snap, entry, fifo)
            if c.trace is not None:
                c.trace.pushed[fifo] += 1
                c.trace.memo = None
        if not (type(entry) is Delay or (type(entry) is Motion and entry.speed_plan is None)):
            self._release_groups([self.groups[cl.groups[0]]])

    def _release_systems(self, ctl: Any, numbers: list[int]) -> None:
        """Give back the clusters that run coordinate systems ``numbers`` of ``ctl``."""
        crds = vars(ctl).get("crd_bank")
        if crds is None:
            return
        for n in numbers:
            c = crds.systems.get(n)
            if c is None or not c.banked:
                continue
            for cl in {id(cl): cl for cl in self._cluster_of.values()}.values():
                if c in cl.systems:
                    self._release_groups([self.groups[cl.groups[0]]])
                    break

    # --- reading claimed axes (the fast path of the GT getters) ---------------------------------
    def value(self, name: str, r: int) -> Any:
        lists = self._lists  # (the dict of the state the list is made of: _lists)
        lst = lists.get(name)
        if lst is None:
            lst = lists[name] = self._make_list(name)
        return lst[r]

    def row_value(self, name: str, r: int) -> Any:
        """``value(name, r)`` for a reader of one axis (the C entries ask it once a cycle
        in the auto clock): in a bank of a few rows, row ``r``'s value alone in Python
        scalars (the same operations as the list's, :meth:`_planned_row` and
        :meth:`_enc_rates_row` as a release takes them), not every row's list; else, or
        where the list is made already, the list's."""
        lst = self._lists.get(name)
        if lst is not None:
            return lst[r]
        if name == "moving":  # (the row's two flags, in a bank of any size: asked per axis)
            return bool(self.moving[r] or self.jog[r])
        if self.n > _SMALL_BANK:
            return self.value(name, r)
        if name == "sts":  # (the flags only tested: numpy's bools; the latched word an int)
            m, j, a, f = self.moving[r], self.jog[r], self.arrived[r], self.frz_off[r]
            lt = self.latched.item(r)
            return (_MOVING if m or j else _ARRIVED if a else 0) | lt | (0 if f else _SERVO_ON)
        k = _ROW_PLANNED.get(name)
        if k is not None:
            return self._planned_one(r, k)
        k = _ROW_RATES.get(name)
        if k is not None:
            return self._enc_rates_row(r)[k]
        if name in _ROW_ITEMS:
            return getattr(self, name).item(r)
        return self.value(name, r)

    def span_bytes(
        self, name: str, rows: slice
    ) -> Callable[[AxisBank], tuple[Any, ...] | None] | None:
        """A getter of the native doubles of ``_make_list(name)[rows]``, a run of rows in
        order, from a bank's arrays in one step (a span of doubles after a cycle: no list of
        every row, no Python float per row), which gives None where it does not apply; None:
        no such getter.  The Trap tables' values where no row jogs or homes, the arrays whose
        list is the array's own (float64).  With the bytes, where they come from: ``(bytes,
        0, source, index, rows, None, 0.0)``, the doubles ``source[index[r]]`` (``index``
        None: ``source[r]``) for each row r of the run (``rows``: their int64 bytes), both
        arrays the bank's own, of one C-contiguous dimension (float64, int64), which the
        compiled cycle moves in place and only Python replaces: a reader's C entry makes
        them again after a cycle booked in C (gtecat/gt/csrc/centry.c gather); ``(bytes,)``
        where it cannot say."""
        whole = not rows.start and rows.stop == self.n  # (the whole bank: no slice)
        run = array("q", range(rows.start or 0, rows.stop)).tobytes()
        flat = _PLANNED_FLAT.get(name)
        if flat is not None:
            table = attrgetter(flat)

            def planned(b: AxisBank) -> tuple[Any, ...] | None:
                if b.n_jog or b.n_hm:
                    return None
                t, i = table(b), b.t_idx
                out = t[i if whole else i[rows]].tobytes()
                if t.dtype is _F64 and i.dtype is _I64 and _flat(t) and _flat(i):
                    return out, 0, t, i, run, None, 0.0
                return (out,)

            return planned
        if name in _ROW_ITEMS:
            values = attrgetter(name)

            def items(b: AxisBank) -> tuple[Any, ...] | None:
                x = values(b)
                if x.dtype is not _F64:
                    return None
                out = (x if whole else x[rows]).tobytes()
                return (out, 0, x, None, run, None, 0.0) if _flat(x) else (out,)

            return items
        return None

    def _make_list(self, name: str) -> list[Any]:
        if name == "sts":
            if self.n <= _SMALL_BANK:  # a few rows: the four flags as lists, row by row
                if self.counts[9] == EPOCH.n and self._sts_last is not None:  # (_sts_epoch)
                    return self._sts_last[1]  # (no flag changed since they were looked at)
                moving, jog, arrived, frz, latched = (
                    self.moving,
                    self.jog,
                    self.arrived,
                    self.frz_off,
                    self.latched,
                )
                flags = (
                    moving.tobytes(),
                    jog.tobytes(),
                    arrived.tobytes(),
                    frz.tobytes(),
                    latched.tobytes(),
                )
                last = self._sts_last
                if last is not None and last[0] == flags:
                    self._sts_epoch = EPOCH.n
                    return last[1]  # (the same words: every reader only reads the list)
                words = [
                    (_MOVING if m or j else _ARRIVED if a else 0) | lt | (0 if f else _SERVO_ON)
                    for m, j, a, f, lt in zip(
                        moving.tolist(),
                        jog.tolist(),
                        arrived.tolist(),
                        frz.tolist(),
                        latched.tolist(),
                        strict=True,
                    )
                ]
                self._sts_last = (flags, words)
                self._sts_epoch = EPOCH.n
                return words
            run = self.moving | self.jog
            sts = np.where(run, _MOVING, np.where(self.arrived, _ARRIVED, 0))
            return (sts | self.latched | np.where(self.frz_off, 0, _SERVO_ON)).tolist()
        if name in ("enc_vel", "enc_acc"):
            if self.n <= _SMALL_BANK:  # (a few rows: Python floats, no numpy temporaries)
                vel, acc = self._enc_rates_lists()
                self._lists["enc_acc" if name == "enc_vel" else "enc_vel"] = (
                    acc if name == "enc_vel" else vel
                )
            else:
                vel, acc = (x.tolist() for x in self._enc_rates())
            return vel if name == "enc_vel" else acc
        if name == "axis_enc":
            if self.n <= _SMALL_BANK:
                return self._link_list(self.enc_pos, self.enc_ratio, self.enc_off)
            return self._link(self.enc_pos, self.enc_ratio, self.enc_off).tolist()
        if name == "moving":
            return (self.moving | self.jog).tolist()
        if name in _PLANNED:
            if not (self.n_jog or self.n_hm):  # (the Trap tables' values alone: one gather)
                return getattr(self, _PLANNED_FLAT[name])[self.t_idx].tolist()
            return self._planned(name).tolist()
        return getattr(self, name).tolist()

    @staticmethod
    def _link(x: np.ndarray, ratio: np.ndarray, off: np.ndarray) -> np.ndarray:
        """:meth:`AffineLink.axis` for every row (the same three cases)."""
        one = ratio == 1.0
        return np.where(one, np.where(off != 0.0, x + off, x), ratio * x + off)

    @staticmethod
    def _link_list(x: np.ndarray, ratio: np.ndarray, off: np.ndarray) -> list[float]:
        """:meth:`_link` as a list of Python floats, row by row (the same IEEE operations
        in the same cases; a few rows cost less so than numpy's temporaries)."""
        return [
            (v + o if o != 0.0 else v) if k == 1.0 else k * v + o
            for v, k, o in zip(x.tolist(), ratio.tolist(), off.tolist(), strict=True)
        ]

    def _enc_rates_lists(self) -> tuple[list[float], list[float]]:
        """:meth:`_enc_rates` as lists of Python floats, row by row (the same IEEE
        divisions and subtraction as :meth:`_enc_rates_row`)."""
        t = self.T
        now = self.bank_cycles
        vel: list[float] = []
        acc: list[float] = []
        for c, s1, s0, v, a in zip(
            self.claim_cycle.tolist(),
            self.enc_step1.tolist(),
            self.enc_step0.tolist(),
            self.enc_vel.tolist(),
            self.enc_acc.tolist(),
            strict=True,
        ):
            cnt = now - c
            if cnt < 1:
                vel.append(v)
                acc.append(a)
            else:
                v1 = s1 / t
                vel.append(v1)
                acc.append((v1 - (s0 / t if cnt >= 2 else v)) / t)
        return vel, acc

    # --- the cycle -------------------------------------------------------------------------
    def settle(self) -> None:
        """What :meth:`cycle` does first after a GT call or a release (claim what may come
        back, re-index), done before a cycle is due: when every axis comes back, the
        controller runs the cycles many at once (:meth:`Controller.run_cycles`)."""
        if not self._settled:
            self._begin()
            self._settled = True

    def _begin(self) -> None:
        if self._frozen_call >= 0 and not (
            self._frozen_start and start_at_once(self, self._frozen_call)
        ):
            self._open_in_place()
        if self.kernel_due and kernel_settled():
            self._take_kernel()
        c = self.counts
        c[0] -= 1  # (_countdown, in its array: a property's get and set are Python calls)
        # with every slave claimed and nothing touched, there is nothing to look for (a hook or
        # anything else reaching a claimed object goes through a guard, which sets dirty)
        if self.dirty or (
            c[0] <= 0 and self.n_alive + len(self._opened) + (self._held_out >= 0) != self.n
        ):
            self.refresh()
        if self._stale:
            self._reindex()

    def cycle(self, t_ns: int, dt_ns: int) -> None:
        """Run the claimed axes' whole cycle; release (before it) the ones that leave; then
        the rows opened for a call on their objects (:meth:`_step_opened`)."""
        self._cycle(t_ns, dt_ns)
        if self._opened:
            self._step_opened(t_ns, dt_ns)

    def _cycle(self, t_ns: int, dt_ns: int) -> None:
        if self.evt_rows:
            self.evt_rows.clear()
        if self._settled:
            self._settled = False  # its first steps ran just before (settle)
        else:
            self._begin()
        if not self.n_alive:
            return
        if self._tp_apply:
            self._apply_probes()
        self._lists = {}  # (a new one: _lists' docs)
        counts = self.counts
        counts[9] = 0  # (_sts_epoch: the status words made again)
        k = self.kernel
        if k is not None:
            # the plain cycle compiled; a new cycle time goes through numpy, and so does a
            # cycle the kernel declines (nothing written then)
            dt = dt_ns * 1e-9
            if (self.n_hm or self.n_frz) and dt != self.csp._dt:
                self.csp._prepare(dt)  # the drives' constants of this cycle time, as numpy would
            c_fill = self._c_fill  # the kernel refills the tables itself
            if dt == self.csp._dt:
                if not c_fill and self.n_moving and counts[1] <= 1:  # (_refill_in)
                    self._fill_tables()  # as the numpy cycle would first (its step 2)
                else:
                    counts[1] -= 1
                rc = k.cycle(t_ns, dt)
                while rc == 3:  # rows leaving (an event, a limit): back to the scalar path first
                    self._release_rows(np.nonzero(k.scratch["s_hit"] & self.alive)[0])
                    if not self.n_alive:
                        return
                    c_fill = self._c_fill
                    rc = k.cycle(t_ns, dt)
                if rc == 0:
                    self._after_kernel(k)
                    if self.any_post:
                        evt = k.scratch["s_evt"]
                        if np.count_nonzero(evt):
                            rows = np.flatnonzero(evt).tolist()
                            self._post_events(rows, t_ns, dt_ns, k.scratch["s_p0"])
                    if self._post_next:
                        self._post_pending()
                    return
                # declined: the numpy cycle looks at every table (the kernel may have
                # refilled some, or left one for it: code 4)
                self._refill_in = 1 if c_fill else self._refill_in + 1
            k.bound = False  # the numpy cycle replaces some arrays
        if self.n_hm or self.n_frz:  # the numpy cycle runs CSP rows only: the others go back
            self._release_rows(np.nonzero((self.hm | self.frz) & self.alive)[0])
            if not self.n_alive:
                return
        buf = self.ctl.master.image.buffer
        # 1. raw writes to a claimed slave's outputs: back to the scalar drive first
        if self._rx_ref and buf.take(self._rx_idx).tobytes() != self._rx_ref:
            self._reindex()  # (its first step gives the written slaves back: _release_written)
            if not self.n_alive:
                return
        # 2. this cycle's planner samples (a row at rest reads its hold slot)
        moving, cur = self.moving, self.t_cur
        self._refill_in -= 1
        if self.n_moving and self._refill_in <= 0:
            self._fill_tables()
        idx = self.base + cur
        prf_p = self.t_p.take(idx)
        ended = cur == self.t_end
        if self.n_jog:
            with np.errstate(over="ignore", invalid="ignore"):  # a jog into infinity leaves
                jog = self._jog_step()
            prf_p = np.where(self.jog, jog[2], prf_p)
        a = self._link(prf_p, self.prf_ratio, self.prf_off) if self.any_prf_link else prf_p
        # 3. 607Ah (Axis.pulses_to_counts, int32 like the PDO entry) and the drives; a
        # lead screw's compensation added (gtecat.controller.lead_screw_bank)
        cmd, ls_dir = screw_command(self, a)
        scaled = cmd * self.unit2 if self.any_scale else cmd
        # counts beyond 2**62 (or not a number) leave the bank: the scalar path's exact
        # integers (and its alarm for a position that is not a number) take them
        huge = ~(np.abs(scaled) < HUGE_COUNTS)
        with np.errstate(invalid="ignore"):
            counts = np.rint(scaled).astype(np.int64)
        if self.any_drive_offset:
            counts += self.drive_offset
        target = counts.astype(np.int32)
        csp = self.csp
        state, events = csp.step(target, dt_ns * 1e-9)
        pa = csp.output("position_actual", state)
        din = csp.output("digital_inputs", state)
        # 4. encoder (Encoder.sample; a 32-bit difference, as the object wraps it)
        raw = pa if self.all_external else np.where(self.external, pa, target)
        d = (raw - self.enc_prev).astype(np.int32)
        step = (self.sense * d if self.any_sense else d) * self.unit
        enc_pos = self.enc_pos + step
        # speed and acceleration are step/T and its difference: kept as the last two steps
        # and divided out when read (_enc_rates), the same operations Encoder.sample does
        # 5. limit switches (the controller latches them, the drive reacts), soft limits
        # and the following error: each latches a flag, so the row leaves before this cycle
        enc_axis = (
            self._link(enc_pos, self.enc_ratio, self.enc_off) if self.any_enc_link else enc_pos
        )
        err = a - enc_axis
        hit = a > self.soft_pos
        if din is not csp._din_zero:
            hit |= (din & 3) != 0
        if csp.din is not csp._din_zero:  # on a limit before the cycle: its reaction is compiled
            hit |= (csp.din & 3) != 0
        if self.any_watch:  # an input a bank-aware hook samples changes (kernel: dwatch)
            hit |= ((din ^ csp.din) & self.dwatch) != 0
        evt = ((din ^ csp.din) & self.dpost) != 0 if self.any_post else None
        if self.any_lvel:  # a sample toward a latched limit (kernel: lvel)
            v = self.prf_ratio * self.t_v.take(idx)
            hit |= ((self.lvel & 1) != 0) & (v > 0.0) | ((self.lvel & 2) != 0) & (v < 0.0)
        hit |= a < self.soft_neg
        hit |= np.abs(err) > self.pos_err
        p0 = None
        if events is not None:
            tp_edge = csp.tp_edge
            post = None
            if self.any_post and tp_edge is not None:
                post = tp_edge & ((self.dpost & TP_POST) != 0)
            if post is None or not np.count_nonzero(post):
                hit |= events
            else:  # the probe takes these edges after the cycle (_post_events)
                if csp.fe_event is not None:
                    hit |= csp.fe_event
                hit |= tp_edge & ~post
                evt = post if evt is None else evt | post
                p0 = csp.pos.copy()
        if np.count_nonzero(huge):
            hit |= huge
        # 6. the in-position band (bit 11)
        fin = ended & moving
        any_fin = bool(np.count_nonzero(fin))
        # the band only changes where a profile stands (moving rows keep since -1, not arrived)
        if self.any_band and (self.band_dirty or any_fin or self.n_standing_banded):
            standing = (ended | ~moving) & ~self.jog
            # (moving rows keep since = -1, arrived = False: nothing to do while all move)
            self.band_dirty = False
            on = self.band > 0
            inb = on & standing & (-self.band <= err) & (err <= self.band)
            since = np.where(inb, np.where(self.since < 0, t_ns, self.since), -1)
            since = np.where(on, since, self.since)
            arr = inb & (self.arrived | (t_ns - since >= self.hold_ns))
            arrived = np.where(on, arr, self.arrived)
        else:
            since, arrived = self.since, self.arrived
        # 7. rows leaving: back to the scalar objects before this cycle
        if self.n_alive != self.n:
            hit &= self.alive
        if np.count_nonzero(hit):
            gs = {self.group_of[r] for r in np.nonzero(hit)[0].tolist()}
            self._release_groups([self.groups[g] for g in gs])
            self._reindex()
            if not self.n_alive:
                return
        if self.n_jog:
            k = self.jog & self.alive
            for arr, value in zip(
                (self.jrp, self.jrv, self.jp, self.jv, self.ja), jog, strict=True
            ):
                arr[k] = value[k]
        if self.n_alive == self.n:
            csp.commit(state, din, None)
            screw_commit(self, ls_dir, None)
            self.a_last, self.t_idx = a, idx
            self.enc_prev, self.enc_pos = raw, enc_pos
            self.enc_step0, self.enc_step1 = self.enc_step1, step
            self.since, self.arrived = since, arrived
            self.taken += moving
            if any_fin:
                self.ended |= fin
                cur += moving & ~ended
                moving &= ~ended
                self.n_moving = int(np.count_nonzero(moving))
                self._count_standing()
            else:
                cur += moving
        else:
            keep = self.alive
            csp.commit(state, din, keep)
            screw_commit(self, ls_dir, keep)
            for name, value in (
                ("a_last", a),
                ("t_idx", idx),
                ("enc_prev", raw),
                ("enc_pos", enc_pos),
                ("since", since),
                ("arrived", arrived),
            ):
                getattr(self, name)[keep] = value[keep]
            s0 = self.enc_step1.copy()
            self.enc_step0[keep] = s0[keep]
            self.enc_step1[keep] = step[keep]
            mk = moving & keep
            self.taken += mk
            self.ended |= fin & keep
            cur += mk & ~ended
            moving &= ~(fin & keep)
            self.n_moving = int(np.count_nonzero(moving))
            self._count_standing()
        self.rows_run += self.n_alive
        self.bank_cycles += 1
        # 8. the image: 607Ah out, the drives' TxPDO in, in one scatter
        if self._img_stale:
            self._image_indices()
        cols = [target, pa, din]
        for name in self._extra:
            cols.append(csp.output(name, state))
        vals = np.concatenate(cols).take(self._img_src)
        buf[self._img_dst] = vals.astype("<u4").view(np.uint8).take(self._img_bytes)
        if evt is not None and np.count_nonzero(evt & self.alive):
            rows = np.flatnonzero(evt & self.alive).tolist()
            self._post_events(rows, t_ns, dt_ns, p0)
        if self._post_next:
            self._post_pending()

    def run_cycles(self, t_ns: int, dt_ns: int, n: int) -> int:
        """Up to ``n`` whole cycles from ``t_ns`` in one call of the compiled kernel, for a
        controller whose cycle has nothing else to do (:meth:`Controller.run_cycles`): the
        cycles run, each exactly the one :meth:`cycle` would run; 0 when the next cycle
        needs :meth:`cycle` (something to claim or release, a row leaving, no compiled
        kernel).  It stops before the first cycle the kernel declines and after one that
        ended a Trap move; the kernel fills a Trap table that runs out itself (else the run
        stops where the shortest table ends: the next call fills it)."""
        k = self.kernel
        if k is None or self.dirty or self._stale or not self.n or self.n_alive != self.n:
            return 0
        if self._post_next or self._tp_apply:  # (a probe arming: cycle() runs its parts)
            return 0
        if self.evt_rows:
            self.evt_rows.clear()
        dt = dt_ns * 1e-9
        if dt != self.csp._dt:
            return 0
        if self.n_moving and not self._c_fill:
            if self._refill_in <= 1:  # a table runs out: fill it first, as cycle() would
                self._fill_tables()
                self._refill_in += 1  # (counted like cycle()'s: one more than the samples left)
            n = min(n, self._refill_in - 1)  # no further than the shortest table goes
            if n <= 0:
                return 0
        if self._declined:  # the last run stopped before a cycle the kernel declines
            self._declined = False
            return 0
        rc, done = k.run(t_ns, dt, dt_ns, n)
        # the next cycle is one it declines: cycle() runs it (a row leaving, a table to fill)
        self._declined = bool(rc) and done > 0
        if done:
            self._countdown -= done - self._settled  # (the first one's count: in settle)
            self._settled = False
            self._refill_in -= done
            self._lists = {}  # (a new one: _lists' docs)
            self._sts_epoch = 0  # (the status words made again)
            self._after_kernel(k, done)
            self.many_cycles += done
        return done

    def quick_cycle_done(self, k: Kernel, rc: int) -> bool:
        """The bookkeeping of :meth:`run_cycles` after one cycle the kernel committed in a
        quick cycle (gtecat.controller.core.Controller.quick_book; ``rc`` its code), with
        :meth:`_after_kernel`'s for one cycle inline.  True: the next cycle may be a quick
        one too (none declined, no table for Python to fill).  (A quick cycle runs only
        where the last one was not declined: :meth:`Controller._quick_kernel` asks, and an
        armed one was armed after a cycle that was not.)"""
        # (each cycle of a polling loop in the auto clock runs this: the counts that stay
        # as they are - a zero added, a flag already so - are not written)
        if rc:
            self._declined = True
        if self._settled:  # (its count of the first cycle: in settle)
            self._settled = False
        else:
            self._countdown -= 1
        self._refill_in -= 1
        self._lists = {}  # (a new one: _lists' docs)
        self._sts_epoch = 0  # (the status words made again)
        csp = self.csp
        csp.cycles += 1
        if csp._din_safe:
            csp._din_safe = 0
        if csp.any_fe:
            csp.fe_running = True
        if k._io[OUT_FIN]:
            self.n_moving = int(np.count_nonzero(self.moving))
            self._count_standing()
        self.rows_run += self.n_alive
        self.bank_cycles += 1
        self.kernel_cycles += 1
        if self.n_hm:
            self.homing_rows_run += self.n_hm
        if self.n_rest:
            self.rest_rows_run += self.n_rest
        if self.n_frz:
            self.frozen_rows_run += self.n_frz
        self.many_cycles += 1
        return not rc and (not self.n_moving or self._c_fill)

    def _after_kernel(self, k: Kernel, cycles: int = 1) -> None:
        """What the numpy cycle does besides its arithmetic, after compiled cycles (the
        counts added in their array itself: each property's get and set is a Python call)."""
        csp = self.csp
        csp.counts[0] += cycles  # (CspBank.cycles)
        csp._din_safe = 0  # its count of safe cycles is numpy's, not the kernel's
        if csp.any_fe:
            csp.fe_running = True  # the numpy cycle then looks at every row's timer
        if k._io[OUT_FIN]:  # (Kernel.move_ended)
            self.n_moving = int(np.count_nonzero(self.moving))
            self._count_standing()
        c = self.counts
        c[_ROWS_RUN] += self.n_alive * cycles
        c[_BANK_CYCLES] += cycles
        c[_KERNEL_CYCLES] += cycles
        if self.n_hm:
            c[_HOMING_ROWS_RUN] += self.n_hm * cycles
            if self.n_rest:
                c[_REST_ROWS_RUN] += self.n_rest * cycles
        if self.n_frz:
            c[_FROZEN_ROWS_RUN] += self.n_frz * cycles

    def _count_standing(self) -> None:
        """Claimed rows with a band whose profile stands (their bit 11 can change)."""
        if not self.any_band:
            self.n_standing_banded = 0
            return
        st = ~self.moving & ~self.jog & (self.band > 0) & self.alive
        self.n_standing_banded = int(np.count_nonzero(st))

    def _enc_rates(self) -> tuple[np.ndarray, np.ndarray]:
        """Encoder speed and acceleration of every row (Encoder.sample: v = step/T,
        a = (v - v_before)/T), from the last two steps or the values at the claim."""
        t = self.T
        cnt = self.bank_cycles - self.claim_cycle
        v1 = self.enc_step1 / t
        v0 = np.where(cnt >= 2, self.enc_step0 / t, self.enc_vel)
        vel = np.where(cnt >= 1, v1, self.enc_vel)
        acc = np.where(cnt >= 1, (v1 - v0) / t, self.enc_acc)
        return vel, acc

    def _jog_step(self) -> tuple[np.ndarray, ...]:
        """One cycle of every Jog: :func:`~gtecat.controller.motion.jog.advance` with the raw
        speed at its goal (a = 0, one piece of length T), then ``JogPlanner.step``'s snap onto
        the goal; the same operations with the same zero constants, for the same bits
        (``-0.0`` included).  A row whose raw speed ramps takes the scalar step's own
        arithmetic (:func:`~gtecat.controller.motion.jog.ramp_step`)."""
        h = self.T
        rp, v, fp, fv, fa = self.jrp, self.jrv, self.jp, self.jv, self.ja
        p1 = rp + h * (v + 0.5 * 0.0 * h)
        v1 = v + 0.0 * h
        tau, e = self.tau, self.jE
        smooth = tau > 0.0
        nfp = np.where(smooth, p1 - tau * (v1 - 0.0) + (fp - rp + tau * (v - 0.0)) * e, p1)
        nfv = np.where(smooth, v1 - 0.0 + (fv - v + 0.0) * e, v1)
        nfa = np.where(smooth, 0.0 + (fa - 0.0) * e, 0.0)
        goal = v1
        snap = (nfv != goal) & (np.abs(nfv - goal) <= 1e-9 * (1.0 + np.abs(goal)))
        nfv = np.where(snap, goal, nfv)
        nfa = np.where(snap, 0.0, nfa)
        ramping = self.jog & self.alive & (v != self.jgoal)
        if np.count_nonzero(ramping):
            # a ramp (the raw speed not yet at its goal): JogPlanner.step's own operations,
            # row by row (a rare cycle here: the compiled cycle runs them too)
            for r in np.nonzero(ramping)[0].tolist():
                out = jog_ramp_step(
                    float(rp[r]),
                    float(v[r]),
                    float(self.jgoal[r]),
                    float(self.jacc[r]),
                    float(self.jdec[r]),
                    h,
                    float(tau[r]),
                    float(fp[r]),
                    float(fv[r]),
                    float(fa[r]),
                )
                p1[r], v1[r], nfp[r], nfv[r], nfa[r] = out
        return p1, v1, nfp, nfv, nfa

    def _materialise(self) -> None:
        """The planned speed and acceleration of the last samples (kept as table indices)."""
        idx = self.t_idx
        self.prf_v = self.t_v.take(idx)
        self.prf_a = self.t_a.take(idx)
        self.prf_p = self.t_p.take(idx)
        if self.n_jog:
            j = self.jog
            self.prf_p[j], self.prf_v[j], self.prf_a[j] = self.jp[j], self.jv[j], self.ja[j]
        if self.n_hm:  # a homing axis's plan holds its actual position
            for r in np.nonzero(self.hm & self.alive)[0].tolist():
                self.prf_p[r] = self.res[r].prf_link.source(float(self.a_last[r]))
                self.prf_v[r] = self.prf_a[r] = 0.0

    def _planned_row(self, r: int) -> tuple[float, float, float]:
        """Row ``r``'s planned position, speed and acceleration, as :meth:`_materialise`
        makes them (the same tests, in the same order of precedence)."""
        if self.n_hm and self.hm[r] and self.alive[r]:
            return self.res[r].prf_link.source(float(self.a_last[r])), 0.0, 0.0
        if self.n_jog and self.jog[r]:
            return float(self.jp[r]), float(self.jv[r]), float(self.ja[r])
        i = int(self.t_idx[r])
        return float(self._t_p1[i]), float(self._t_v1[i]), float(self._t_a1[i])

    def _planned_one(self, r: int, k: int) -> float:
        """``_planned_row(r)[k]`` alone (0: the position, 1: the speed, 2: the
        acceleration): the same tests in the same order of precedence."""
        if self.n_hm and self.hm.item(r) and self.alive.item(r):
            return self.res[r].prf_link.source(self.a_last.item(r)) if k == 0 else 0.0
        if self.n_jog and self.jog.item(r):
            return (self.jp, self.jv, self.ja)[k].item(r)
        return (self._t_p1, self._t_v1, self._t_a1)[k].item(self.t_idx.item(r))

    def _enc_rates_row(self, r: int) -> tuple[float, float]:
        """Row ``r``'s encoder speed and acceleration, :meth:`_enc_rates`'s operations in
        Python floats (the same IEEE divisions and subtraction)."""
        t = self.T
        cnt = self.counts[3] - self.claim_cycle.item(r)  # (bank_cycles, without its frame)
        if cnt < 1:
            return self.enc_vel.item(r), self.enc_acc.item(r)
        v1 = self.enc_step1.item(r) / t
        v0 = self.enc_step0.item(r) / t if cnt >= 2 else self.enc_vel.item(r)
        return v1, (v1 - v0) / t

    def _planned(self, name: str) -> np.ndarray:
        """One of :meth:`_materialise`'s three, made the same way (a reader of the planned
        position after a run of cycles needs neither the speed nor the acceleration)."""
        table, jog = _PLANNED[name]
        out = getattr(self, table).take(self.t_idx)
        if self.n_jog:  # (the jogs' values where jog is set: one copy, no masked arrays)
            np.copyto(out, getattr(self, jog), where=self.jog)
        if self.n_hm:  # a homing axis's plan holds its actual position
            for r in np.nonzero(self.hm & self.alive)[0].tolist():
                out[r] = (
                    self.res[r].prf_link.source(float(self.a_last[r])) if name == "prf_p" else 0.0
                )
        setattr(self, name, out)
        return out

    def _release_rows(self, rows: np.ndarray) -> None:
        """Release the groups of ``rows`` (before this cycle) and re-index."""
        gs = {self.group_of[r] for r in rows.tolist()}
        self._release_groups([self.groups[g] for g in sorted(gs)])
        self._reindex()

    # --- a hook's step on a claimed row -----------------------------------------------------
    def step_claimed(self, r: int, step: Callable[[], None]) -> None:
        """Run ``step`` (a smart homing's step after a cycle, which reads and changes the
        axis's objects) on row ``r`` exactly as a release before it and a claim after it
        would, without giving the drive back: the row's state goes into its axis, planner,
        encoder and band objects and is taken from them again (as a release and a claim do
        it), those four objects lose their guards for the step, and after it the row takes
        them up again (a new Trap move, flags cleared) when it is still what
        :meth:`_eligible` asks for, else it goes back as at any release.  The drive's objects
        keep their guards: a step that reaches them (an SDO to the drive) gives the row back
        then.  A row of a drive with several channels, of a cluster or not in a plain Trap
        or standing state simply goes back (the step runs on the scalar objects)."""
        g = self.groups[self.group_of[r]]
        if len(g.rows) != 1 or not self._plain_row(r):
            step()
            return
        self._in_place(r, g, step)

    def _plain_row(self, r: int) -> bool:
        """Row ``r`` is claimed in a plain Trap or standing state: a step may run on it in
        place (:meth:`_in_place`)."""
        return bool(self.alive[r]) and not (
            self.sampled[r] or self.jog[r] or self.hm[r] or self.frz[r]
        )

    def _in_place(self, r: int, g: _Group, step: Callable[[], None]) -> None:
        """:meth:`step_claimed`'s step on claimed row ``r`` of group ``g`` (its drive's
        other rows, if any, stay claimed as they are: the step reaches their objects only
        through their guards, which give the whole drive back)."""
        ax, res = self.axes[r], self.res[r]
        prof = res.profile
        pl = prof.planner
        objs = (ax, pl, res.encoder, res.band)
        if r in self._open:  # (a posted edge's: its objects hold its state, unguarded)
            self._open.discard(r)
            self._stepping = r
            self.evt_rows.discard(r)
            try:
                self._step_claimed(r, g, step, pl, objs)
            finally:
                self._stepping = -1
            return
        # (their guards off first: the row's state goes into them without a guard's Python
        # call on every attribute, as it would under _Bypass anyway)
        _unguard(objs)
        _Bypass.on = True
        try:
            self._last = {}  # (the planned values: _put_back finds them where it needs them)
            self._rates = {r: self._enc_rates_row(r)}
            self._put_back(r)
            self._catch_up(r)
        except BaseException:
            _reguard(objs)  # (still claimed: guarded as before)
            raise
        finally:
            _Bypass.on = False
        # the objects hold the row's state now: a release (within the step or after it)
        # leaves them as they are
        self._stepping = r
        self.evt_rows.discard(r)  # (its step takes the edge its hooks took)
        try:
            self._step_claimed(r, g, step, pl, objs)
        finally:
            self._stepping = -1

    def _step_claimed(
        self, r: int, g: _Group, step: Callable[[], None], pl: Any, objs: tuple
    ) -> None:
        ok = False
        was_moving = bool(self.moving[r])
        try:
            step()
            if not g.claimed:
                return  # the step reached the drive: given back
            _Bypass.on = True
            try:
                ok = self.res[r].profile.planner is pl and self._eligible(r, drive=False)
                if ok:
                    self._load(r, again=True)
                    ok = not (self.jog[r] or self.hm[r] or self.frz[r])
            finally:
                _Bypass.on = False
        finally:
            if g.claimed and not ok:
                _OWNER.pop(id(pl), None)  # (another planner: the release looks at that one)
                self._release_groups([g])
        if not ok:
            return
        self.steps_in_place += 1
        _reguard(objs)
        self._after_load(r, was_moving)

    def _after_load(self, r: int, was_moving: bool) -> None:
        """What :meth:`_reindex` counts that loading claimed row ``r`` again in place may
        change (a new move, the flags and watched inputs taken again; the claimed set stays).
        A flag "some row has it" may stay set for a row that no longer has it: it only
        makes the numpy cycle look (and find nothing)."""
        moving = bool(self.moving[r])
        self.n_moving += moving - was_moving
        self._refill_in = 0
        if self.kernel is not None:
            if not self._c_fill:
                self._c_fill = not np.count_nonzero(self.moving & self.alive & (self.nseg <= 0))
            elif moving and self.nseg[r] <= 0:
                self._c_fill = False
        if self.any_band:
            self._count_standing()
        self.any_watch = self.any_watch or bool(self.dwatch[r])
        self.any_post = self.any_post or bool(self.dpost[r])
        self.any_lvel = self.any_lvel or bool(self.lvel[r])
        self.band_dirty = True
        self._lists = {}  # (a new one: _lists' docs)
        self._sts_epoch = 0  # (the status words made again)

    def _post_events(
        self, rows: list[int], t_ns: int, dt_ns: int, p0: np.ndarray | None = None
    ) -> None:
        """After a committed cycle in which a watched input of ``rows`` changed, or their
        travel reached an edge of their drive's touch probe (:attr:`dpost`; ``p0``: where
        each row's travel started): the drive's probe takes the edge (TouchProbe.step, as the
        drive's own step ends; its bounds follow), each row's state goes into its axis objects
        (as at a release), its hooks catch up with the cycles before and run this one
        (``bank_posted``: the capture unit reads the probe as its cycle does), and the row is
        taken up again from the objects (as at a claim; the drive stays).  The result is the
        scalar path's, which ran this cycle on the objects: the bank's cycle is theirs, and
        the probe's and the hooks' part of it is what the objects' one would have been."""
        csp = self.csp
        _Bypass.on = True
        try:
            for r in rows:
                # the row's objects without their guards while its state goes into them and
                # is taken again (the same as under _Bypass, without a Python call per
                # attribute); guarded again after, the row staying
                objs = tuple(self._guarded_objects(self.groups[self.group_of[r]]))
                _unguard(objs)
                try:
                    self._post_event(r, csp, p0, t_ns, dt_ns)
                finally:
                    if self.alive[r] and self.groups[self.group_of[r]].claimed:
                        if r in self._open:  # (its axis objects stay as step_claimed has them)
                            ch = self.csp.channels[r]
                            probe = _get(ch, "probe")
                            objs = tuple(o for o in objs if o is ch or o is probe)
                        _reguard(objs)
        finally:
            _Bypass.on = False

    def _post_event(
        self, r: int, csp: CspBank, p0: np.ndarray | None, t_ns: int, dt_ns: int
    ) -> None:
        """:meth:`_post_events` for row ``r`` (its axis objects unguarded, _Bypass on)."""
        if p0 is not None and self.dpost[r] & TP_POST:
            self.posted_probes += 1
            ch = csp.channels[r]
            probe = ch.probe
            a, b = float(p0[r]), float(csp.pos[r])
            if probe.function:
                off = ch.enc_offset
                probe.step(a, b, a - off, b - off, t_ns, dt_ns)
                self._put_probe(r)
            csp.tp_lo[r], csp.tp_hi[r] = probe.quiet_bounds(b)
        self._last = {}  # (as in _in_place)
        self._rates = {r: self._enc_rates_row(r)}
        self._put_back(r)
        self.posted_inputs += bool(self.dpost[r] & ~TP_POST)
        ran = int(self.bank_cycles - self.claim_cycle[r])
        for obj in self._aware.pop(r, ()):
            obj.bank_posted(ran, t_ns, dt_ns)
        self.evt_rows.add(r)
        if self._stepped_after(r):
            # a hook steps the row after this cycle (:meth:`step_claimed`), which puts its
            # state into the same objects and takes it up from them: they hold it already,
            # so the row stays open until then (its claim counted anew: a new claim)
            self._open.add(r)
            self._claims += 1
            self.claim_ids[r] = self._claims
            return
        was_moving = bool(self.moving[r])
        self._load(r, again=True)
        self._after_load(r, was_moving)

    def _stepped_after(self, r: int) -> bool:
        """A ``post_cycle`` hook of the controller steps row ``r`` in place after this cycle
        (``bank_steps_row(bank, r)`` on the hook's object says so: a smart homing waiting
        for the edge its row's capture took; it then calls :meth:`step_claimed`)."""
        for hook in self.ctl.post_cycle:
            steps = getattr(getattr(hook, "__self__", None), "bank_steps_row", None)
            if steps is not None and steps(self, r):
                return True
        return False

    def close_open(self) -> None:
        """The rows left open after a posted edge (:meth:`_post_event`) that no step took up:
        taken from their objects again, as the post would have done."""
        while self._open:
            r = self._open.pop()
            if not (self.alive[r] and self.groups[self.group_of[r]].claimed):
                continue
            res = self.res[r]
            objs = (self.axes[r], res.profile.planner, res.encoder, res.band)
            _Bypass.on = True
            try:
                was_moving = bool(self.moving[r])
                self._load(r, again=True)
                self._after_load(r, was_moving)
            finally:
                _Bypass.on = False
            _reguard(objs)

    def _release_written(self) -> None:
        """Before the claimed rows' output bytes are seen afresh (:meth:`_reindex`): a group
        claimed at the last look whose bytes a raw write changed since goes back first, as
        the cycle would give it back (its drive decodes what the image holds), rather than
        the new look taking the written bytes for the bank's own."""
        ref = self._rx_ref
        if not ref:
            return
        idx = self._rx_idx
        now = self.ctl.master.image.buffer.take(idx)
        if len(now) != len(ref) or now.tobytes() == ref:
            return
        hit = sorted(set(self._rx_gi[now != np.frombuffer(ref, np.uint8)].tolist()))
        changed = [g for g in map(self.groups.__getitem__, hit) if g.claimed]
        if changed:
            self._release_groups(changed)


def _outside_marks(backend: Any) -> tuple[int, int]:
    """What moves whenever a slave's objects may change outside its own step: an SDO served
    (the emulated backend's count of mailbox operations), a field write or an emergency
    (:attr:`VirtualSlave.outside_changes`)."""
    return backend.__dict__.get("_mailbox_ops", -1), VirtualSlave.outside_changes


def _within_soft_limits(ax: Any, res: Any) -> bool:
    """No soft limit is exceeded now (the row would leave the bank at once)."""
    s = res.safety
    return not s.active or s.soft_negative <= ax.prf_pos <= s.soft_positive


def _within_safety(ax: Any, res: Any) -> bool:
    """Neither a soft limit nor the following error is exceeded now (an axis latched with
    one of them would leave the bank at once: it stays scalar)."""
    if not _within_soft_limits(ax, res):
        return False
    s = res.safety
    if s.active:
        a = ax.prf_pos
        if not -s.pos_err <= a - res.enc_link.axis(res.encoder.pos) <= s.pos_err:
            return False
    return True
