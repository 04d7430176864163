"""The virtual CiA-402 servo drive: object dictionary, SDO, PDOs, state machine, modes, mechanics.

A :class:`Cia402Drive` is one EtherCAT slave with one or more axes
(:class:`Channel`); channel k's profile objects sit at index + 0x800·k (6040h,
6840h, 7040h, ...) as in ETG.5001 multi-axis devices and Googol's 4-axis
module; each channel is one GT axis.  The vendor analog inputs 20F2h/20F9h
follow the same rule (28F2h/28F9h for channel 1).

One cycle (:meth:`Cia402Drive.step`): decode ``rx`` into the objects (AL
state OP only) -> per channel: faults, state machine, mode-of-operation
request, the mode's demand, limit switches, mechanics, following error,
touch probe, statusword -> encode ``tx``.

Behaviour the standard leaves open, as implemented (each configurable in
:class:`DriveSettings`):

- **AL state below OP.** Outputs are invalid: ``rx`` is not decoded and a
  PDO-mapped controlword is ignored.  When the master leaves OP, a channel
  whose 6040h is PDO-mapped and whose power stage is on goes to SWITCH ON
  DISABLED (``comm_loss_reaction="disable"``, as kubabuda/ecat_servo does),
  or to FAULT with 603Fh = 0x8100 (``"fault"``).  When the drive itself finds
  its process data stopped (its sync-manager watchdog ran out: a cable pulled,
  a master that died), it faults with 603Fh = ``watchdog_fault_code`` (8130h,
  CiA 301 "life guard or heartbeat error", the code CiA 301 gives a drive that
  lost its cyclic communication; vendors' EtherCAT drives raise an alarm of
  their own for it rather than switching off silently), whatever its power
  stage did, so the application reads why its axis stopped once the link is
  back; 0 takes ``comm_loss_reaction`` for that case too.  A controlword that is not
  PDO-mapped (SDO-only masters) is obeyed in every AL state.  Inputs are
  encoded every cycle.
- **Limit switches** (``limit_reaction``): ``"stop"`` (default): while 60FDh
  shows a limit switch, motion into it is stopped with the quick-stop
  deceleration 6085h and blocked, motion out of it is allowed; SW11 (internal
  limit) and SW7 (warning) are set, CSx SW12 drops, the following-error check
  pauses.  ``"fault"``: moving into an active switch faults with 603Fh
  0xFF01 (positive) / 0xFF02 (negative).  ``"none"``: switches only show in
  60FDh.  In homing mode the switches belong to the homing method and never
  stop the axis.
- **60FDh**: bit 0 negative limit, bit 1 positive limit, bit 2 home switch,
  bit 16 probe input 1, bit 17 probe input 2 (logical levels, 1 = active).
- **20F2h / 20F9h**: analog inputs 1 and 2 (INT16, raw ADC counts, as GTHD
  names them for ``GT_GetEcatAxisAI``); a scenario sets them through
  :meth:`Channel.set_analog_input`.
- **Mode display** 6061h follows 6060h ``mode_latency_cycles`` cycles after the
  drive first sees the request (default 1: the next cycle); an unsupported
  mode written by SDO is refused with 0x06090030, written by PDO it is not
  taken (6061h keeps the old mode).  Optional refusals: while halt (CW8) is
  set, or outside given PDS states; a refused request waits until allowed.
- **Fault reaction** (605Eh): 0 coast, 1 slow-down ramp (6084h), 2 quick-stop
  ramp (6085h, default), 3/4 current limit; then FAULT.  **Quick stop**
  (605Ah) 0..8 as CiA 402, default 2.  **Halt** (605Dh) 1..4, default 1.
"""

from __future__ import annotations

import logging
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from functools import partial
from typing import Any

from gtecat.drives.abort import SdoAbort, SdoAbortCode
from gtecat.drives.cia402 import STATE_BITS, PowerStateMachine, State, Sw
from gtecat.drives.faults import (
    ErrorCode,
    FaultMonitor,
    FieldOverride,
    error_register,
    fault_code,
    forced_level,
)
from gtecat.drives.homing import SUPPORTED_METHODS, Homing, HomingParams
from gtecat.drives.machine import AxisMachine
from gtecat.drives.mechanics import Mechanics, MechanicsParams
from gtecat.drives.modes import (
    DEFAULT_MODES,
    HM_NOT_STARTED,
    MODE_STEP,
    POSITION_MODES,
    SW10,
    SW12,
    OpMode,
    enter,
    step_hold,
    stop_ramp,
    supported_bits,
)
from gtecat.drives.od import (
    Access,
    AttrObject,
    AttrVariable,
    DataType,
    ItemVariable,
    ObjectCode,
    ObjectDictionary,
    PdoDir,
    Variable,
    add_identity,
    attr_spec,
    item_at,
)
from gtecat.drives.pdo_mapping import PdoMapping
from gtecat.drives.sdo_server import SdoServer
from gtecat.drives.slave import AlState, AlStatusCode, VirtualSlave
from gtecat.drives.touch_probe import TouchProbe
from gtecat.eni.errors import GtecatError
from gtecat.eni.model import Direction, Identity, Pdo

log = logging.getLogger(__name__)

CHANNEL_STRIDE = 0x800
DEVICE_TYPE_SERVO = 0x00020192  # CiA 402 profile (0x192), servo drive (additional info 2)
#: homing methods this drive accepts in 6098h (the homing component's set; 0 = none chosen)
DEFAULT_HOMING_METHODS = (0, *sorted(SUPPORTED_METHODS))

_INT32_MIN, _INT32_MAX = -(1 << 31), (1 << 31) - 1
_HALT = 0x100
_OP = AlState.OP  # (looked up once: the cycle compares with it)
_QUICK_STOP = 0x4  # controlword bit 2, active low
_SW_WARNING = int(Sw.WARNING)
_SW_REMOTE = int(Sw.REMOTE)
_SW_INTERNAL_LIMIT = int(Sw.INTERNAL_LIMIT)
_RX, _TX, _RXTX = PdoDir.RX, PdoDir.TX, PdoDir.RX | PdoDir.TX
_LIMIT_REACTIONS = ("stop", "fault", "none")
_COMM_REACTIONS = ("disable", "fault", "none")


def _shared_int(value: int) -> int:
    """One int object per object index for every drive's dictionary (an index above 256 is
    a new object each time it is computed)."""
    return _INTS.setdefault(value, value)


_INTS: dict[int, int] = {}


@dataclass(frozen=True, slots=True)
class DriveSettings:
    """What differs between real drives (see the module docstring for each policy)."""

    supported_modes: tuple[int, ...] = tuple(int(m) for m in DEFAULT_MODES)
    #: 6060h at power-on.  8 (CSP) like Googol's GTHD, whose default mapping (manual
    #: figure 5-2) has no 6060h yet runs under the controller's CSP set-points
    initial_mode: int = 8
    homing_methods: tuple[int, ...] = DEFAULT_HOMING_METHODS
    mode_latency_cycles: int = 1
    #: 6061h while a mode change is pending (Festo shows -1); None = the old mode
    mode_display_while_switching: int | None = None
    refuse_mode_change_while_halt: bool = False
    #: PDS states in which a mode change is taken (None = any)
    mode_change_states: frozenset[State] | None = None
    limit_reaction: str = "stop"
    comm_loss_reaction: str = "disable"
    #: 603Fh when the sync-manager watchdog runs out (process data stopped); 0: as
    #: ``comm_loss_reaction``
    watchdog_fault_code: int = 0x8130
    following_error_fault: bool = True
    #: 6065h when the machine description gives no following_error_window, counts
    following_error_window: int = 10000
    following_error_timeout_ms: int = 10
    quick_stop_option: int = 2
    halt_option: int = 1
    fault_reaction_option: int = 2
    max_torque_permille: int = 3000
    mechanics: MechanicsParams = field(default_factory=MechanicsParams)
    #: |velocity| below which the motor counts as standing, rpm
    standstill_rpm: float = 0.6
    remote: bool = True
    strict_mapping: bool = False
    #: refuse SDO downloads to RxPDO-mapped objects in SAFEOP/OP with 0x06010006
    block_sdo_to_rxpdo: bool = False
    mailbox_size: int = 128
    #: 1008h; empty: the name the configuration gives the slave (a Googol INI's slavename,
    #: the product an ETG.2100 ENI names), as a real drive names its product there
    device_name: str = ""
    hardware_version: str = "1.0"
    software_version: str = "gtecat 0.1"

    def __post_init__(self) -> None:
        if self.limit_reaction not in _LIMIT_REACTIONS:
            raise ValueError(f"limit_reaction must be one of {_LIMIT_REACTIONS}")
        if self.comm_loss_reaction not in _COMM_REACTIONS:
            raise ValueError(f"comm_loss_reaction must be one of {_COMM_REACTIONS}")
        if self.mode_latency_cycles < 0:
            raise ValueError("mode_latency_cycles must be >= 0")


def _wrap32(x: int) -> int:
    if _INT32_MIN <= x <= _INT32_MAX:
        return x
    return ((x - _INT32_MIN) & 0xFFFFFFFF) + _INT32_MIN


def _clamp16(x: float) -> int:
    x = round(x)
    return 32767 if x > 32767 else (-32768 if x < -32768 else x)


def _level(windows: tuple[tuple[float, float], ...], pos: float) -> bool:
    for lo, hi in windows:
        if lo <= pos < hi:
            return True
    return False


class Channel:
    """One axis of the drive: its objects, state machine, mode logic and mechanics.

    Scenario hooks: :attr:`machine_position`, :meth:`inject_fault`,
    :meth:`clear_injected_fault`, :meth:`set_analog_input`, and the read-only
    views :attr:`state`, :attr:`statusword`, :attr:`mode_display`,
    :attr:`error_code`, :attr:`position_actual`.
    """

    #: its state as slots (a bus of a thousand drives holds a thousand of these); an
    #: attribute set from outside that is not listed goes to ``__dict__`` as before
    __slots__ = (
        "__dict__",
        "_hs",
        "_max_torque",
        "_nl",
        "_p1",
        "_p2",
        "_pl",
        "_settings",
        "_tp_applied",
        "analog_in",
        "base",
        "controlword",
        "current_actual",
        "cw_mapped",
        "cycle",
        "digital_inputs",
        "digital_output_mask",
        "digital_outputs",
        "dpos",
        "drive",
        "dtorque",
        "dvel",
        "enc_offset",
        "error_code_value",
        "fault_powered",
        "fault_reaction_option",
        "faults",
        "fe_flag",
        "fe_time",
        "field",
        "following_error_actual",
        "following_error_timeout",
        "following_error_window",
        "halt_option",
        "hm_applied",
        "hm_bits",
        "hm_halt",
        "home_offset",
        "homing",
        "homing_acceleration",
        "homing_method",
        "homing_speed_switch",
        "homing_speed_zero",
        "k",
        "limit_stop",
        "machine",
        "mech",
        "mode",
        "mode_display",
        "mode_due",
        "mode_req",
        "mode_seen",
        "noise_now",
        "oms",
        "pos_offset",
        "position_actual",
        "position_demand",
        "position_window",
        "position_window_time",
        "pp_moving",
        "pp_pending",
        "pp_target",
        "prev_cw",
        "probe",
        "profile_acceleration",
        "profile_deceleration",
        "profile_velocity",
        "psm",
        "quick_stop_deceleration",
        "quick_stop_option",
        "sp_ack",
        "standstill",
        "statusword",
        "stopping",
        "supported",
        "sw_limit_max",
        "sw_limit_min",
        "sw_limited",
        "target_position",
        "target_torque",
        "target_velocity",
        "torque_actual",
        "torque_ctl",
        "torque_demand",
        "torque_offset",
        "torque_slope",
        "tp_function",
        "vel_offset",
        "velocity_actual",
        "win_time",
    )

    def __init__(self, drive: Cia402Drive, k: int, machine: AxisMachine) -> None:
        s = drive.settings
        self.drive = drive
        self.k = k
        self.base = k * CHANNEL_STRIDE
        self.machine = machine
        cpr = machine.counts_per_rev
        mp = s.mechanics
        if mp.counts_per_rev != cpr:
            mp = replace(mp, counts_per_rev=cpr)
        self.mech = Mechanics(mp, machine.position, s.max_torque_permille)
        self.psm = PowerStateMachine()
        self.faults = FaultMonitor()
        self.supported = frozenset({0, *s.supported_modes})
        self.standstill = s.standstill_rpm / 60.0 * cpr
        self._settings = s
        # --- switch geometry, flattened for the cycle
        self._nl = machine.negative_limit if machine.negative_limit is not None else -1e300
        self._pl = machine.positive_limit if machine.positive_limit is not None else 1e300
        self._hs = tuple(machine.home_switch)
        self._p1 = tuple(machine.probe1)
        self._p2 = tuple(machine.probe2)
        # --- process values (the objects' storage)
        self.controlword = 0
        self.statusword = 0
        self.error_code_value = 0
        self.mode_req = s.initial_mode  # 6060h (taken like any request, after the latency)
        self.mode = 0  # the active mode
        self.mode_display = 0  # 6061h
        self.target_position = 0
        self.target_velocity = 0
        self.target_torque = 0
        self._max_torque = s.max_torque_permille
        self.position_actual = _wrap32(round(self.mech.pos))
        self.position_demand = self.position_actual
        self.velocity_actual = 0
        self.torque_actual = 0
        self.current_actual = 0
        self.torque_demand = 0
        self.following_error_actual = 0
        self.digital_inputs = 0
        self.digital_outputs = 0
        self.digital_output_mask = 0
        self.analog_in = [0, 0]
        self.quick_stop_option = s.quick_stop_option
        self.halt_option = s.halt_option
        self.fault_reaction_option = s.fault_reaction_option
        fe = machine.following_error_window
        self.following_error_window = int(fe if fe is not None else s.following_error_window)
        self.following_error_timeout = s.following_error_timeout_ms
        self.position_window = max(1, cpr // 1000)
        self.position_window_time = 0
        self.home_offset = 0
        self.sw_limit_min = _INT32_MIN
        self.sw_limit_max = _INT32_MAX
        self.profile_velocity = 10 * cpr
        self.profile_acceleration = 100 * cpr
        self.profile_deceleration = 100 * cpr
        self.quick_stop_deceleration = 500 * cpr
        self.torque_slope = 10000
        self.homing_method = 0
        self.homing_speed_switch = cpr
        self.homing_speed_zero = cpr // 10
        self.homing_acceleration = 100 * cpr
        self.pos_offset = 0
        self.vel_offset = 0
        self.torque_offset = 0
        self.tp_function = 0
        # --- cycle state
        self.cycle = 0
        self.prev_cw = 0
        self.mode_seen = 0
        self.mode_due: int | None = None
        self.enc_offset = 0  # machine position of encoder 0 (set by homing)
        self.noise_now = 0  # the encoder's noise in this cycle's reading (encoder_noise), counts
        self.dpos = self.mech.pos
        self.dvel = 0.0
        self.dtorque = 0.0
        self.torque_ctl = False
        self.stopping = False  # a stop ramp (halt, quick stop, fault reaction) is running
        #: the field's hands on this channel (gtecat.faults): None while nothing is forced
        self.field: FieldOverride | None = None
        self.oms = 0
        self.fe_time = 0.0
        self.fe_flag = False
        self.sw_limited = False
        self.limit_stop = False
        self.pp_target = self.position_actual
        self.pp_pending: int | None = None
        self.pp_moving = False
        self.sp_ack = False
        self.win_time = 0.0
        self.homing: Any = None
        self.hm_bits = HM_NOT_STARTED
        self.hm_applied = False
        self.hm_halt = False
        self.cw_mapped = False
        self.fault_powered = False
        self.probe = TouchProbe(machine)
        self._tp_applied = 0
        self._add_objects(drive.od)
        self.digital_inputs = self._inputs(self.mech.pos)
        self._refresh_status()

    # --- objects -------------------------------------------------------------------------
    def _var(
        self,
        od: ObjectDictionary,
        index: int,
        name: str,
        dt: DataType,
        access: Access,
        attr: str,
        pdo: PdoDir = PdoDir.NONE,
        **kw: Any,
    ) -> None:
        """The VAR object ``index`` (this channel's) whose entry is the attribute ``attr``."""
        at = _shared_int(index + self.base)
        if kw:  # (a range or allowed values: the entry now)
            od.add_entry(AttrVariable(self, attr, at, 0, name, dt, access, pdo=pdo, **kw))
        else:  # (made when first looked at)
            od.add_object(AttrObject(self, at, attr_spec(attr, name, dt, access, pdo)))

    def _sub(
        self,
        index: int,
        sub: int,
        name: str,
        dt: DataType,
        access: Access,
        attr: str,
        pdo: PdoDir = PdoDir.NONE,
        **kw: Any,
    ) -> Variable:
        at = _shared_int(index + self.base)
        return AttrVariable(self, attr, at, sub, name, dt, access, pdo=pdo, **kw)

    def _add_objects(self, od: ObjectDictionary) -> None:
        s = self._settings
        b = self.base
        ro, rw = Access.RO, Access.RW
        d = DataType
        v = self._var
        od.add_var(0x67FF + b, "Device type", d.UINT32, Access.CONST, default=DEVICE_TYPE_SERVO)
        v(od, 0x603F, "Error code", d.UINT16, ro, "error_code_value", _TX)
        v(od, 0x6040, "Controlword", d.UINT16, rw, "controlword", _RX)
        v(od, 0x6041, "Statusword", d.UINT16, ro, "statusword", _TX)
        v(od, 0x605A, "Quick stop option code", d.INT16, rw, "quick_stop_option", low=0, high=8)
        v(od, 0x605D, "Halt option code", d.INT16, rw, "halt_option", low=1, high=4)
        v(
            od,
            0x605E,
            "Fault reaction option code",
            d.INT16,
            rw,
            "fault_reaction_option",
            low=0,
            high=4,
        )
        v(
            od,
            0x6060,
            "Modes of operation",
            d.INT8,
            rw,
            "mode_req",
            _RX,
            allowed=sorted(self.supported),
        )
        v(od, 0x6061, "Modes of operation display", d.INT8, ro, "mode_display", _TX)
        v(od, 0x6062, "Position demand value", d.INT32, ro, "position_demand", _TX)
        v(od, 0x6064, "Position actual value", d.INT32, ro, "position_actual", _TX)
        v(od, 0x6065, "Following error window", d.UINT32, rw, "following_error_window", _RX)
        v(od, 0x6066, "Following error time out", d.UINT16, rw, "following_error_timeout", _RX)
        v(od, 0x6067, "Position window", d.UINT32, rw, "position_window", _RX)
        v(od, 0x6068, "Position window time", d.UINT16, rw, "position_window_time", _RX)
        v(od, 0x606C, "Velocity actual value", d.INT32, ro, "velocity_actual", _TX)
        v(od, 0x6071, "Target torque", d.INT16, rw, "target_torque", _RX)
        v(od, 0x6072, "Max torque", d.UINT16, rw, "max_torque", _RX)
        v(od, 0x6074, "Torque demand", d.INT16, ro, "torque_demand", _TX)
        v(od, 0x6077, "Torque actual value", d.INT16, ro, "torque_actual", _TX)
        v(od, 0x6078, "Current actual value", d.INT16, ro, "current_actual", _TX)
        v(od, 0x607A, "Target position", d.INT32, rw, "target_position", _RX)
        v(od, 0x607C, "Home offset", d.INT32, rw, "home_offset", _RX)
        od.add_record(
            0x607D + b,
            "Software position limit",
            [
                self._sub(0x607D, 1, "Min position limit", d.INT32, rw, "sw_limit_min", _RX),
                self._sub(0x607D, 2, "Max position limit", d.INT32, rw, "sw_limit_max", _RX),
            ],
            code=ObjectCode.ARRAY,
        )
        v(od, 0x6081, "Profile velocity", d.UINT32, rw, "profile_velocity", _RX)
        v(od, 0x6083, "Profile acceleration", d.UINT32, rw, "profile_acceleration", _RX)
        v(od, 0x6084, "Profile deceleration", d.UINT32, rw, "profile_deceleration", _RX)
        v(od, 0x6085, "Quick stop deceleration", d.UINT32, rw, "quick_stop_deceleration", _RX)
        v(od, 0x6087, "Torque slope", d.UINT32, rw, "torque_slope", _RX)
        od.add_record(
            0x608F + b,
            "Position encoder resolution",
            [
                Variable(
                    0x608F + b,
                    1,
                    "Encoder increments",
                    d.UINT32,
                    ro,
                    default=self.machine.counts_per_rev,
                ),
                Variable(0x608F + b, 2, "Motor revolutions", d.UINT32, ro, default=1),
            ],
        )
        v(od, 0x6098, "Homing method", d.INT8, rw, "homing_method", _RX, allowed=s.homing_methods)
        od.add_record(
            0x6099 + b,
            "Homing speeds",
            [
                self._sub(
                    0x6099,
                    1,
                    "Speed during search for switch",
                    d.UINT32,
                    rw,
                    "homing_speed_switch",
                    _RX,
                ),
                self._sub(
                    0x6099,
                    2,
                    "Speed during search for zero",
                    d.UINT32,
                    rw,
                    "homing_speed_zero",
                    _RX,
                ),
            ],
            code=ObjectCode.ARRAY,
        )
        v(od, 0x609A, "Homing acceleration", d.UINT32, rw, "homing_acceleration", _RX)
        v(od, 0x60B0, "Position offset", d.INT32, rw, "pos_offset", _RX)
        v(od, 0x60B1, "Velocity offset", d.INT32, rw, "vel_offset", _RX)
        v(od, 0x60B2, "Torque offset", d.INT16, rw, "torque_offset", _RX)
        v(od, 0x60B8, "Touch probe function", d.UINT16, rw, "tp_function", _RX)
        probe = self.probe
        od.add_var(
            0x60B9 + b,
            "Touch probe status",
            d.UINT16,
            ro,
            pdo=_TX,
            getter=partial(getattr, probe, "status"),
        )
        names = (
            "Touch probe 1 positive value",
            "Touch probe 1 negative value",
            "Touch probe 2 positive value",
            "Touch probe 2 negative value",
        )
        for j, name in enumerate(names):
            od.add_entry(
                ItemVariable(probe, "values", j, 0x60BA + j + b, 0, name, d.INT32, pdo=_TX)
            )
        counters = (
            "Touch probe 1 positive edge counter",
            "Touch probe 1 negative edge counter",
            "Touch probe 2 positive edge counter",
            "Touch probe 2 negative edge counter",
        )
        for j, name in enumerate(counters):
            od.add_entry(
                ItemVariable(probe, "counters", j, 0x60D5 + j + b, 0, name, d.UINT16, pdo=_TX)
            )
        od.add_record(
            0x60D0 + b,
            "Touch probe source",
            [
                Variable(
                    0x60D0 + b,
                    j,
                    f"Touch probe {j} source",
                    d.INT16,
                    rw,
                    low=1,
                    high=6,
                    getter=partial(item_at, probe, "source_select", j - 1),
                    setter=partial(probe.set_source, j),
                )
                for j in (1, 2)
            ],
            code=ObjectCode.ARRAY,
        )
        stamps = (
            "Touch probe 1 positive edge time",
            "Touch probe 1 negative edge time",
            "Touch probe 2 positive edge time",
            "Touch probe 2 negative edge time",
        )
        for j, name in enumerate(stamps):
            od.add_var(
                0x60D1 + j + b, name, d.UINT32, ro, pdo=_TX, getter=partial(_stamp, probe, j)
            )
        v(od, 0x60F4, "Following error actual value", d.INT32, ro, "following_error_actual", _TX)
        v(od, 0x60FD, "Digital inputs", d.UINT32, ro, "digital_inputs", _TX)
        od.add_record(
            0x60FE + b,
            "Digital outputs",
            [
                self._sub(0x60FE, 1, "Physical outputs", d.UINT32, rw, "digital_outputs", _RX),
                self._sub(0x60FE, 2, "Bit mask", d.UINT32, rw, "digital_output_mask", _RX),
            ],
            code=ObjectCode.ARRAY,
        )
        v(od, 0x60FF, "Target velocity", d.INT32, rw, "target_velocity", _RX)
        od.add_var(
            0x6502 + b,
            "Supported drive modes",
            d.UINT32,
            ro,
            pdo=_TX,
            default=supported_bits(self.supported),
        )
        for j, index in enumerate((0x20F2, 0x20F9)):
            name = f"Analog input {j + 1}"
            od.add_entry(ItemVariable(self, "analog_in", j, index + b, 0, name, d.INT16, pdo=_TX))

    @property
    def max_torque(self) -> int:
        return self._max_torque

    @max_torque.setter
    def max_torque(self, value: int) -> None:
        self._max_torque = int(value)
        self.mech.set_max_torque(value)

    # --- scenario hooks ----------------------------------------------------------------
    @property
    def state(self) -> State:
        return self.psm.state

    @property
    def error_code(self) -> int:
        return self.error_code_value

    @property
    def machine_position(self) -> float:
        """The true mechanical position, machine counts (what a scale would read)."""
        return self.mech.pos

    @machine_position.setter
    def machine_position(self, value: float) -> None:
        """Move the mechanics (a scenario pushing the axis); the demand follows."""
        delta = float(value) - self.mech.pos
        self.mech.pos = float(value)
        self.dpos += delta
        self._outputs()

    def inject_fault(self, kind: str | int) -> int:
        """Raise a fault (``"alarm"``, ``"encoder"``, ... or a 603Fh code); returns its code.

        The cause persists (a fault reset is ignored) until :meth:`clear_injected_fault`,
        except for the transient kinds of :data:`gtecat.drives.faults.TRANSIENT` (following
        error, limit, communication), which are over once the drive has stopped.
        """
        code = fault_code(kind)
        self.faults.inject(code)
        return code

    def clear_injected_fault(self) -> None:
        """The injected cause is gone; a fault reset (rising CW7) can now clear the fault."""
        self.faults.clear_injected()

    def lose_counts(self, counts: int) -> None:
        """The encoder loses ``counts`` counts (``encoder_lost`` of :mod:`gtecat.faults`).

        Physically the encoder's count slips against the motor: the motor stays where it
        is, the position the drive measures (6064h) jumps by ``-counts`` and stays off by
        that much until a homing defines the position again (``enc_offset``, which relates
        the two, grows by ``counts``).  The drive's demand lives in what it measures, so
        it does not move with the slip (6062h unchanged): the control loop sees a
        following error of ``counts`` at once (CiA 402 6.3.2 / 6.4.2 (60F4h = position
        demand value - position actual value) and drives the motor by ``counts`` to close it,
        as fast as its torque allows - a real drive jumps.  6064h, 60F4h and the
        following-error supervision all start from that one measured position: an error
        beyond 6065h for longer than 6066h faults the drive with 8611h (following error)
        and it stops with its fault reaction, the motor short of the demand.  In CSP/CSV
        the demand comes from 607Ah / keeps running; in PP, PV, homing and a stop ramp
        the drive's own demand is shifted with the slip (it is the same place in the
        drive's frame).
        """
        n = int(counts)
        if not n:
            return
        self.enc_offset += n
        self.dpos += n
        h = self.homing
        if h is not None:
            h.shift_demand(n)
        self._outputs()

    def set_analog_input(self, channel: int, value: int) -> None:
        """Analog input 1 (20F2h) or 2 (20F9h), raw INT16 counts."""
        if channel not in (1, 2):
            raise ValueError(f"analog input channel {channel} is not 1 or 2")
        self.analog_in[channel - 1] = max(-32768, min(32767, int(value)))

    # --- homing (called from gtecat.drives.modes.step_hm) -----------------------------------------
    def start_homing(self) -> None:
        self.hm_applied = False
        self.hm_halt = False
        self.torque_ctl = False
        self.dpos = self.mech.pos
        self.dvel = 0.0
        try:
            self.homing = Homing(
                self.homing_params(), self.machine, self.mech.pos, self.forced_switches
            )
        except GtecatError as err:  # the homing component refused the parameters
            log.warning("axis channel %d: homing cannot start: %s", self.k, err)
            self.homing = None
            self.hm_bits = SW10 | (1 << 13)  # homing error, velocity 0
            return
        self.hm_bits = 0

    def homing_params(self) -> HomingParams:
        """6098h, 6099h:01/02, 609Ah and 607Ch as a homing takes them at CW4's rising edge."""
        return HomingParams(
            method=int(self.homing_method),
            speed_switch=float(self.homing_speed_switch),
            speed_zero=float(self.homing_speed_zero),
            acceleration=float(self.homing_acceleration),
            home_offset=int(self.home_offset),
        )

    def finish_homing(self) -> None:
        """Homing ended: on success the encoder is redefined (6064h reads the home value)."""
        self.hm_applied = True
        h = self.homing
        if h is None or h.error or not h.attained:
            return
        offset = h.encoder_offset()
        if offset is not None:
            self.enc_offset = round(offset)
            self.pp_target = round(self.mech.pos - self.enc_offset)

    def leave_homing(self) -> None:
        h = self.homing
        if h is not None and not h.done:
            self.hm_bits = HM_NOT_STARTED  # interrupted
        self.homing = None

    # --- the cycle ---------------------------------------------------------------------------
    def power_on(self) -> None:
        if self.psm.power_on():
            self._refresh_status()

    def comm_lost(self, watchdog: bool = False) -> None:
        """The slave left OP while this channel's controlword was PDO-mapped: the master
        asked for it, or (``watchdog``) the process data stopped coming."""
        reaction = self._settings.comm_loss_reaction
        state = self.psm.state
        wd_code = self._settings.watchdog_fault_code if watchdog else 0
        if wd_code:
            if state not in (State.FAULT, State.FAULT_REACTION_ACTIVE):
                self.faults.raise_fault(wd_code)
        elif reaction == "fault":
            if state not in (State.FAULT, State.FAULT_REACTION_ACTIVE):
                self.faults.raise_fault(ErrorCode.COMMUNICATION)
        elif reaction == "disable":
            number = {
                State.OPERATION_ENABLED: 9,
                State.SWITCHED_ON: 10,
                State.READY_TO_SWITCH_ON: 7,
                State.QUICK_STOP_ACTIVE: 12,
            }.get(state)
            if number is not None:
                self.psm.force(State.SWITCH_ON_DISABLED, number)
                self._transition(number)
        self.controlword = 0
        self._refresh_status()

    def _transition(self, number: int) -> None:
        state = self.psm.state
        if state is State.OPERATION_ENABLED:
            if number in (4, 16):
                enter(self, self.mode)
        else:
            self.leave_homing()
        if number == 15:
            self.faults.reset()
            self.error_code_value = 0

    def _take_fault(self) -> None:
        code = self.faults.take_pending()
        self.fault_powered = self.psm.state in (State.OPERATION_ENABLED, State.QUICK_STOP_ACTIVE)
        if self.psm.fault():
            self.error_code_value = code
            self._transition(13)
            # CiA 301 7.2.7 / ETG.1000.6 5.6.4: an emergency telegram with 603Fh and 1001h
            self.drive.emit_emergency(code, error_register(code), bytes([self.k, 0, 0, 0, 0]))

    def step(self, t_ns: int, dt_ns: int, dt: float, cw_valid: bool) -> None:
        self.cycle += 1
        mech = self.mech
        psm = self.psm
        faults = self.faults
        p0 = mech.pos
        if psm.state is State.NOT_READY_TO_SWITCH_ON:
            psm.power_on()
        if faults.pending:
            self._take_fault()
        ff = self.field
        if cw_valid:
            cw = self.controlword
            if ff is not None and ff.quick_stop:
                cw &= ~_QUICK_STOP  # the drive's quick-stop input acts like CW bit 2
            number = psm.command(cw, self.quick_stop_option, faults.cause_active)
            if number:
                self._transition(number)
        else:
            cw = self.prev_cw
        # --- 6060h -> active mode -> 6061h
        if self.mode_req != self.mode_seen:
            req = self.mode_seen = self.mode_req
            if req == self.mode:
                self.mode_due = None
            elif req in self.supported:
                self.mode_due = self.cycle + self._settings.mode_latency_cycles
            else:
                self.mode_due = None  # not taken: 6061h keeps showing the old mode
        if self.mode_due is not None and self.cycle >= self.mode_due and self._mode_allowed(cw):
            self.mode = self.mode_seen
            self.mode_due = None
            enter(self, self.mode)
        # --- demand of this cycle
        state = psm.state
        powered = True
        mode = self.mode
        if state is State.OPERATION_ENABLED:
            if cw & _HALT and mode != OpMode.HOMING:
                stop_ramp(self, self._decel(self.halt_option), dt)
                self.oms = SW10 if self.dvel == 0.0 and mech.stopped(self.standstill) else 0
            else:
                MODE_STEP.get(mode, step_hold)(self, cw, dt)
        elif state is State.QUICK_STOP_ACTIVE:
            option = self.quick_stop_option
            if option == 0:
                powered = False
                psm.quick_stop_done()
                self._transition(12)
            else:
                stop_ramp(self, self._decel(option), dt)
                if option <= 4 and self.dvel == 0.0 and mech.stopped(self.standstill):
                    psm.quick_stop_done()
                    self._transition(12)
        elif state is State.FAULT_REACTION_ACTIVE:
            option = self.fault_reaction_option
            if option == 0 or not self.fault_powered:
                powered = False  # coast (or the power stage was already off)
                psm.fault_reaction_done()
            else:
                stop_ramp(self, self._decel(option), dt)
                if self.dvel == 0.0 and mech.stopped(self.standstill):
                    psm.fault_reaction_done()
        else:
            powered = False
        if ff is not None and ff.sto:
            powered = False  # safe torque off: the power stage has no enable
        # --- limit switches
        self.limit_stop = False
        din = self.digital_inputs
        if powered and din & 3 and mode != OpMode.HOMING:
            self._limit_switches(din, p0, dt)
        # --- mechanics
        if ff is not None and ff.brake:
            mech.vel = mech.acc = 0.0  # the holding brake stays closed: the motor stalls
            if not powered:
                self.dpos, self.dvel = mech.pos, 0.0
        elif powered:
            if self.torque_ctl and not self.limit_stop:
                mech.drive_torque(self.dtorque, dt)
                self.dpos = mech.pos
                self.dvel = mech.vel
            else:
                mech.track(self.dpos, self.dvel, dt)
        else:
            mech.coast(dt)
            self.dpos = mech.pos
            self.dvel = mech.vel
        # --- the encoder's reading of this cycle (noise: encoder_noise) and the following
        # error on it (position modes, powered, not stopped by a limit switch)
        self.noise_now = ff.noise() if ff is not None and ff.enc_noise else 0
        if state is State.OPERATION_ENABLED and mode in POSITION_MODES and not self.limit_stop:
            window = self.following_error_window
            if 0 < window < 0xFFFFFFFF and abs(self.dpos - mech.pos - self.noise_now) > window:
                self.fe_time += dt
                if self.fe_time * 1000.0 > self.following_error_timeout:
                    if not self.fe_flag:
                        self.fe_flag = True
                        if self._settings.following_error_fault:
                            faults.raise_fault(ErrorCode.FOLLOWING_ERROR)
            else:
                self.fe_time = 0.0
                self.fe_flag = False
        # --- touch probe
        probe = self.probe
        if self.tp_function != self._tp_applied:
            self._tp_applied = self.tp_function
            probe.write_function(self.tp_function)
        if probe.function and not (ff is not None and ff.probe_off):
            off = self.enc_offset
            probe.step(p0, mech.pos, p0 - off, mech.pos - off, t_ns, dt_ns)
        if faults.pending:
            self._take_fault()
        self.prev_cw = cw
        self._outputs()

    def _limit_switches(self, din: int, p0: float, dt: float) -> None:
        mech = self.mech
        reaction = self._settings.limit_reaction
        if reaction == "none":
            return
        into_pos = din & 2 and (
            self.dpos > p0 or mech.vel > 0.0 or (self.torque_ctl and self.dtorque > 0.0)
        )
        into_neg = din & 1 and (
            self.dpos < p0 or mech.vel < 0.0 or (self.torque_ctl and self.dtorque < 0.0)
        )
        if not (into_pos or into_neg):
            return
        if reaction == "fault":
            self.faults.raise_fault(
                ErrorCode.POSITIVE_LIMIT if into_pos else ErrorCode.NEGATIVE_LIMIT
            )
            return
        self.limit_stop = True
        step = float(self.quick_stop_deceleration or 1) * dt
        v = mech.vel
        if into_pos:
            v = v - step if v > step else min(v, 0.0)
        else:
            v = v + step if v < -step else max(v, 0.0)
        self.dvel = v
        self.dpos = p0 + v * dt

    def _decel(self, option: int) -> float:
        """Deceleration of a stop option: 1/5 slow-down, 2/6 quick-stop ramp, else current limit."""
        if option in (1, 5):
            return float(self.profile_deceleration or 1)
        if option in (2, 6):
            return float(self.quick_stop_deceleration or 1)
        return self.mech.amax or 1.0

    def _mode_allowed(self, cw: int) -> bool:
        s = self._settings
        if s.refuse_mode_change_while_halt and cw & _HALT:
            return False
        return s.mode_change_states is None or self.psm.state in s.mode_change_states

    def _inputs(self, pos: float) -> int:
        din = 0
        if pos <= self._nl:
            din |= 1
        if pos >= self._pl:
            din |= 2
        if self._hs and _level(self._hs, pos):
            din |= 4
        if self._p1 and _level(self._p1, pos):
            din |= 1 << 16
        if self._p2 and _level(self._p2, pos):
            din |= 1 << 17
        ff = self.field
        if ff is not None:
            din = forced_level(din, ff.din_set, ff.din_clear)
        return din

    def forced_switches(self) -> tuple[int, int]:
        """The 60FDh bits the field forces on and off now (``switch_stuck``,
        ``switch_chatter``): what :meth:`_inputs` lays over the machine's switches, handed
        to the homing so that it reads the switches as 60FDh shows them."""
        ff = self.field
        return (0, 0) if ff is None else (ff.din_set, ff.din_clear)

    def _outputs(self) -> None:
        mech = self.mech
        pos = mech.pos
        off = self.enc_offset
        noise = self.noise_now
        if self.faults.injected != ErrorCode.ENCODER:
            self.position_actual = _wrap32(round(pos - off) + noise)
        self.position_demand = _wrap32(round(self.dpos - off))
        self.velocity_actual = _wrap32(round(mech.vel))
        t = _clamp16(mech.torque)
        self.torque_actual = t
        self.current_actual = t
        self.torque_demand = _clamp16(self.dtorque) if self.torque_ctl else t
        self.following_error_actual = _wrap32(round(self.dpos - pos) - noise)
        self.digital_inputs = self._inputs(pos)
        self._refresh_status()

    def _refresh_status(self) -> None:
        state = self.psm.state
        sw = STATE_BITS[state]
        if self._settings.remote:
            sw |= _SW_REMOTE
        if state is State.OPERATION_ENABLED:
            oms = self.oms
            if self.limit_stop:
                if self.mode >= OpMode.CYCLIC_SYNC_POSITION:
                    oms &= ~SW12  # no longer following the command value
                sw |= _SW_WARNING
            sw |= oms
        elif self.mode == OpMode.HOMING:
            sw |= self.hm_bits
        elif self.mech.stopped(self.standstill):
            sw |= SW10
        if self.limit_stop or self.sw_limited or self.mech.limited:
            sw |= _SW_INTERNAL_LIMIT
        self.statusword = sw
        due = self.mode_due
        shown = self._settings.mode_display_while_switching
        self.mode_display = self.mode if due is None or shown is None else shown


def _stamp(probe: TouchProbe, j: int) -> int:
    return probe.timestamps[j] & 0xFFFFFFFF


class Cia402Drive(VirtualSlave):
    """A virtual EtherCAT CiA-402 servo drive with ``channels`` axes."""

    has_mailbox = True

    def __init__(
        self,
        position: int,
        name: str,
        identity: Identity,
        *,
        rx_pdos: Sequence[Pdo] = (),
        tx_pdos: Sequence[Pdo] = (),
        channels: int = 1,
        machines: Sequence[AxisMachine] | None = None,
        settings: DriveSettings | None = None,
    ) -> None:
        if not 1 <= channels <= 8:
            raise ValueError(f"a drive has 1..8 channels, not {channels}")
        if machines is not None and len(machines) != channels:
            raise ValueError(f"{len(machines)} machine descriptions for {channels} channels")
        self.settings = settings or DriveSettings()
        self.od = ObjectDictionary()
        self._add_device_objects(name, identity)
        machines = list(machines) if machines is not None else [AxisMachine()] * channels
        self.channels = [Channel(self, k, machines[k]) for k in range(channels)]
        spare_rx = [0x1600 + 0x10 * k + j for k in range(channels) for j in range(4)]
        spare_tx = [0x1A00 + 0x10 * k + j for k in range(channels) for j in range(4)]
        self.mapping = PdoMapping(
            self.od,
            rx_pdos,
            tx_pdos,
            spare_rx=spare_rx,
            spare_tx=spare_tx,
            strict=self.settings.strict_mapping,
        )
        if self.settings.block_sdo_to_rxpdo:
            self.od.download_guard = self._guard_rxpdo
        self.sdo = SdoServer(self.od, mailbox_size=self.settings.mailbox_size)
        self._rx_mapped: set[tuple[int, int]] = set()
        self._compile()
        super().__init__(position, name, identity)

    def _add_device_objects(self, name: str, identity: Identity) -> None:
        od, s, d = self.od, self.settings, DataType
        od.add_var(0x1000, "Device type", d.UINT32, Access.RO, default=DEVICE_TYPE_SERVO)
        od.add_var(
            0x1001, "Error register", d.UINT8, Access.RO, pdo=_TX, getter=self._error_register
        )
        od.add_var(
            0x1008,
            "Manufacturer device name",
            d.VISIBLE_STRING,
            Access.CONST,
            default=s.device_name or name,
        )
        od.add_var(
            0x1009,
            "Manufacturer hardware version",
            d.VISIBLE_STRING,
            Access.CONST,
            default=s.hardware_version,
        )
        od.add_var(
            0x100A,
            "Manufacturer software version",
            d.VISIBLE_STRING,
            Access.CONST,
            default=s.software_version,
        )
        add_identity(od, identity)

    def _error_register(self) -> int:
        reg = 0
        for ch in self.channels:
            reg |= error_register(ch.error_code_value)
        return reg

    def _guard_rxpdo(self, var: Variable, al_state: AlState) -> None:
        if (
            al_state in (AlState.SAFEOP, AlState.OP)
            and (var.index, var.subindex) in self._rx_mapped
        ):
            raise SdoAbort(SdoAbortCode.OBJECT_MAPPED_TO_RXPDO, var.index, var.subindex)

    def _compile(self) -> None:
        self.codec = self.mapping.compile()
        self._rx_mapped = self.mapping.mapped_objects(Direction.OUT)
        for ch in self.channels:
            ch.cw_mapped = (0x6040 + ch.base, 0) in self._rx_mapped

    # --- VirtualSlave ---------------------------------------------------------------------
    def channel(self, k: int) -> Channel:
        """Axis channel ``k`` (0-based) of this drive."""
        return self.channels[k]

    def pdo_sizes(self) -> tuple[int, int]:
        return self.mapping.sizes()

    def mailbox(self, request: bytes) -> bytes | None:
        """One whole mailbox message (with its 6-byte header) in, the whole answer out."""
        return self.sdo.handle(request, self.al_state)

    #: the mailbox is the SDO server alone (the in-process backend may call the server's
    #: ``download_in_process`` instead of framing an expedited download)
    mailbox.sdo_server_only = True  # type: ignore[attr-defined]

    def on_state_change(self, old: AlState, new: AlState) -> AlStatusCode:
        if old == AlState.PREOP and new == AlState.SAFEOP:
            try:
                self._compile()
            except SdoAbort as err:
                log.warning("%s: PDO mapping cannot be compiled: %s", self.name, err)
                return AlStatusCode.INVALID_PROCESS_DATA_MAPPING
        if new >= AlState.PREOP and new != AlState.BOOT:
            for ch in self.channels:
                ch.power_on()
        if old == AlState.OP and new != AlState.OP:
            for ch in self.channels:
                if ch.cw_mapped:
                    ch.comm_lost(self._watchdog_ran_out)
        return AlStatusCode.NO_ERROR

    _watchdog_ran_out = False

    def watchdog_expired(self) -> None:
        self._watchdog_ran_out = True
        try:
            super().watchdog_expired()
        finally:
            self._watchdog_ran_out = False

    def step(self, t_ns: int, dt_ns: int) -> None:
        codec = self.codec
        op = self.al_state == _OP
        if op and len(self.rx) >= codec.rx_bytes:
            codec.decode(self.rx)
        if dt_ns > 0:
            dt = dt_ns * 1e-9
            for ch in self.channels:
                ch.step(t_ns, dt_ns, dt, op or not ch.cw_mapped)
        if len(self.tx) >= codec.tx_bytes:
            codec.encode(self.tx)
