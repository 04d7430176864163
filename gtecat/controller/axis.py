"""Controller-side EtherCAT axes: the PDO objects of one CiA-402 channel and the servo cycle.

One :class:`Axis` per GT axis (1-based, counting CiA-402 channels in bus
order, DESIGN.md).  It owns the channel's controlword while the controller
drives it: it writes 6040h whenever its command changes and, when the drive is enabled in
cyclic synchronous position mode, the planned position to 607Ah - "a planned
position every cycle", as the real controller does.  With the servo off 607Ah
holds the actual position, so enabling or coming back to CSP never jumps; only
with the drive enabled in profile position mode is 607Ah the application's.

Objects are addressed as for channel 0 (``0x6064``); :class:`AxisIo` adds
``0x800 * channel``.  A GT function that needs an object that is not mapped
gets :class:`ObjectNotMapped` (return 1 naming the object, manual chapter 13),
except 6060h/6061h for homing, which fall back to SDO (5.2.2.2).

Units: the controller plans in pulses (float).  ``GT_SetPosScale`` sets an
exponent ``scale``: drive counts = pulses * 2**scale (manual entry for
GT_SetPosScale: a 23-bit encoder with scale 6 looks like 17 bits).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from gtecat.drives.cia402 import State as PdsState
from gtecat.drives.cia402 import decode_state as _decode_state
from gtecat.eni.datatypes import CHANNEL_STRIDE, MAX_CHANNELS
from gtecat.eni.layout import AxisRef, Layout

from .._attrs import PerObject
from ..errors import CommandError
from ..master.image import EntryAccess, ProcessImage

OBJECT_NAMES = {
    0x603F: "error code",
    0x6040: "controlword",
    0x6041: "statusword",
    0x6060: "modes of operation",
    0x6061: "modes of operation display",
    0x6064: "position actual value",
    0x606C: "velocity actual value",
    0x6071: "target torque",
    0x6077: "torque actual value",
    0x6078: "current actual value",
    0x607A: "target position",
    0x60B8: "touch probe function",
    0x60B9: "touch probe status",
    0x60BA: "touch probe 1 positive edge",
    0x60BB: "touch probe 1 negative edge",
    0x60BC: "touch probe 2 positive edge",
    0x60BD: "touch probe 2 negative edge",
    0x60F4: "following error actual value",
    0x60FD: "digital inputs",
    0x60FE: "digital outputs",
    0x60FF: "target velocity",
    0x20F2: "analog input 1",
    0x20F9: "analog input 2",
}


#: 6060h = 1, profile position: the one mode besides CSP in which the drive uses 607Ah
_PROFILE_POSITION = 1
#: end of the CiA-402 profile area of a multi-axis module (channel k's objects at +0x800*k)
_PROFILE_END = 0x6000 + CHANNEL_STRIDE * MAX_CHANNELS


class ObjectNotMapped(CommandError):
    """The object a GT function needs is not in the axis's PDO mapping (return 1)."""


def decode_state(sw: int) -> PdsState:
    """Statusword -> state with the standard masks (the drive's own decoder, cia402-facts
    1.2); a statusword matching no pattern reads as not ready to switch on."""
    return _decode_state(sw) or PdsState.NOT_READY_TO_SWITCH_ON


#: controlword "quick stop" (bit 1 enable voltage set, bit 2 quick stop clear): what the
#: controller sends a drive that went into quick stop active by itself (drive_left_operation)
CW_QUICK_STOP = 0x0002
#: statusword mask and pattern of quick stop active (cia402-facts 1.2)
_SW_STATE_MASK, _SW_QUICK_STOP_ACTIVE = 0x006F, 0x0007

# controlword the controller sends to move one step towards operation enabled
_ENABLE_STEP = {
    PdsState.NOT_READY_TO_SWITCH_ON: 0x0000,
    PdsState.SWITCH_ON_DISABLED: 0x0006,  # shutdown -> ready to switch on
    PdsState.READY_TO_SWITCH_ON: 0x0007,  # switch on
    PdsState.SWITCHED_ON: 0x000F,  # enable operation
    PdsState.OPERATION_ENABLED: 0x000F,
    PdsState.QUICK_STOP_ACTIVE: 0x0000,  # disable voltage -> switch on disabled
    PdsState.FAULT_REACTION_ACTIVE: 0x0000,
    PdsState.FAULT: 0x0000,
}


#: a key not looked up yet in :attr:`AxisIo._cache` (None there: looked up, not mapped)
_UNSEEN = object()


class AxisIo:
    """Typed access to the mapped objects of one channel, SDO for the rest."""

    def __init__(
        self,
        image: ProcessImage,
        layout: Layout,
        ref: AxisRef,
        sdo_upload: Callable[[int, int, int], bytes] | None = None,
        sdo_download: Callable[[int, int, int, bytes], None] | None = None,
        sdo_download_values: Callable[[int, list[tuple[int, int, int, int]]], None] | None = None,
    ) -> None:
        self.ref = ref
        self.slave = ref.slave
        self.channel = ref.channel
        self._image = image
        self._layout = layout
        self._cache: dict[tuple[int, int], EntryAccess | None] = {}
        self._sdo_upload = sdo_upload
        self._sdo_download = sdo_download
        self._sdo_download_values = sdo_download_values

    @classmethod
    def on(cls, master: Any, layout: Layout, ref: AxisRef) -> AxisIo:
        """The channel ``ref`` of ``master``'s bus, its SDOs through the master."""
        return cls(
            master.image,
            layout,
            ref,
            master.sdo_upload,
            master.sdo_download,
            master.sdo_download_values,
        )

    def index(self, index: int) -> int:
        """Object index of this channel (channel 0 index + 0x800*k for 0x6000-0x67FF)."""
        if 0x6000 <= index < 0x6800:
            return index + 0x800 * self.channel
        return index

    def channel0_index(self, index: int) -> int | None:
        """``index`` as channel 0 numbers it, or None when it is another channel's object.

        Both numberings name this channel's profile objects (0x6841 is channel 1's
        statusword, so is 0x6041 on channel 1's axis); a profile object of another
        channel (0x7041 on channel 1) is not this axis's, whatever the module maps.
        """
        if not 0x6000 <= index < _PROFILE_END:
            return index
        k, offset = divmod(index - 0x6000, CHANNEL_STRIDE)
        if k == 0 or k == self.channel:
            return 0x6000 + offset
        return None

    def get(self, index: int, subindex: int = 0) -> EntryAccess | None:
        key = (index, subindex)
        if key not in self._cache:
            # (channel0_index inline: an axis's first look at each object it uses - five
            # objects a drive homing's set-up writes, on every axis - finds it here)
            if 0x6000 <= index < _PROFILE_END:
                k, offset = divmod(index - 0x6000, CHANNEL_STRIDE)
                base = 0x6000 + offset if k == 0 or k == self.channel else None
            else:
                base = index
            p = None if base is None else self._layout.axis_entry(self.ref.axis, base, subindex)
            self._cache[key] = self._image.access(p) if p is not None else None
        return self._cache[key]

    def require(self, index: int, subindex: int = 0) -> EntryAccess:
        acc = self.get(index, subindex)
        if acc is None and self.channel0_index(index) is None:
            k = (index - 0x6000) // CHANNEL_STRIDE
            own = self.index(0x6000 + (index - 0x6000) % CHANNEL_STRIDE)
            raise ObjectNotMapped(
                f"axis {self.ref.axis}: object 0x{index:04X}:{subindex:02X} belongs to channel "
                f"{k} of slave {self.slave}, and axis {self.ref.axis} is its channel "
                f"{self.channel}; ask for 0x{own:04X} (or the channel-0 number)"
            )
        if acc is None:
            raise ObjectNotMapped(
                f"axis {self.ref.axis}: object 0x{self.index(index):04X}:{subindex:02X} "
                f"({OBJECT_NAMES.get(index, 'object')}) is not mapped as PDO in the ENI "
                f"(slave {self.slave}); map it in your configuration tool and export the ENI "
                "again (`gtecat map FILE.eni` shows what is mapped)"
            )
        return acc

    def read(self, index: int, subindex: int = 0) -> int:
        return self.require(index, subindex).get()

    def write(self, index: int, value: int, subindex: int = 0) -> None:
        self.require(index, subindex).set(value)

    def sdo_read(self, index: int, subindex: int, size: int, signed: bool = False) -> int:
        if self._sdo_upload is None:
            raise CommandError("no mailbox on this backend")
        data = self._sdo_upload(self.slave, self.index(index), subindex)
        return int.from_bytes(data[:size], "little", signed=signed)

    def sdo_write(self, index: int, subindex: int, value: int, size: int) -> None:
        if self._sdo_download is None:
            raise CommandError("no mailbox on this backend")
        data = int(value).to_bytes(size, "little", signed=value < 0)
        self._sdo_download(self.slave, self.index(index), subindex, data)

    def write_all_or_sdo(self, items: list[tuple[int, int, int, int]]) -> None:
        """Write ``(index, subindex, value, size)`` objects in order, each by PDO if mapped,
        else by SDO (the SDOs one after the other in one call where the master takes them
        so: every one a download of its own, the first that fails raised; the values, ints
        that fit their sizes, as they are: :meth:`gtecat.master.bus.Master.sdo_download_values`)."""
        many = self._sdo_download_values
        cache = self._cache
        base = 0x800 * self.channel
        sdo: list[tuple[int, int, int, int]] = []
        for item in items:
            index, subindex, value, size = item
            acc = cache.get((index, subindex), _UNSEEN)
            if acc is _UNSEEN:
                acc = self.get(index, subindex)
            if acc is None and many is not None:
                if base and 0x6000 <= index < 0x6800:  # (self.index)
                    item = (index + base, subindex, value, size)
                sdo.append(item)
                continue
            if sdo:  # (in order: the SDOs before this object first)
                many(self.slave, sdo)
                sdo = []
            if acc is not None:
                acc.set(value)  # type: ignore[union-attr]
            else:
                self.sdo_write(index, subindex, value, size)
        if sdo:
            many(self.slave, sdo)

    def read_or_sdo(self, index: int, subindex: int, size: int, signed: bool = False) -> int:
        """PDO if mapped, else SDO (manual 5.2.2.2 for 6060h/6061h)."""
        acc = self.get(index, subindex)
        if acc is not None:
            return acc.get()
        return self.sdo_read(index, subindex, size, signed)

    def write_or_sdo(self, index: int, subindex: int, value: int, size: int) -> bool:
        """Write by PDO if mapped (True), else by SDO (False)."""
        acc = self.get(index, subindex)
        if acc is not None:
            acc.set(value)
            return True
        self.sdo_write(index, subindex, value, size)
        return False


@dataclass
class ServoTiming:
    """Bounds of the controller's enable/disable walks (cycles)."""

    enable_timeout_ms: float = 200.0
    disable_timeout_ms: float = 100.0


#: an axis's drive-homing follower, which the GT layer makes (gtecat.gt.homing_calls) and the
#: bank's homing starts read (:mod:`.bank_home_start`): declared here, beside the axis it is
#: kept on, so that both name the same state
ECAT_HOMING: PerObject[Any] = PerObject("ecat_homing")


class Axis:
    """One GT axis: controlword ownership, servo on/off and the CSP set-point.

    Motion resources (profile, encoder, status, limits) build on this class;
    they set :attr:`prf_pos` (pulses) and read the feedback in :meth:`post`.
    """

    def __init__(self, number: int, io: AxisIo) -> None:
        self.number = number
        self.io = io
        #: what other modules keep per axis (gtecat._attrs.PerObject: homing, capture, ...)
        self.extensions: dict[str, Any] = {}
        self.pos_scale = 0  # GT_SetPosScale exponent
        self.prf_pos = 0.0  # planned position, pulses
        #: added to the planned position on its way to the drive (lead-screw compensation,
        #: :mod:`gtecat.controller.lead_screw`), pulses
        self.compensation = 0.0
        self.drive_offset = 0  # drive counts at planned position 0
        self.cw = 0  # controlword the controller sends
        self._cw_sent = -1
        self.servo_on = False
        #: why the controller cannot reach this axis's slave ("" while it can; comm loss,
        #: :mod:`gtecat.controller.core`), and the reason of the last loss, kept until
        #: GT_ClrSts with the slave back (GT_AxisOn is refused until then)
        self.link_lost = ""
        self.link_alarm = ""
        #: why 607Ah could not follow the planned position this cycle (not finite), "" else
        self.plan_error = ""
        self.csp_follow = True  # write 607A from prf_pos while enabled in CSP
        self.timing = ServoTiming()
        self._cw_acc = io.get(0x6040)
        self._sw_acc = io.get(0x6041)
        self._tp_acc = io.get(0x607A)
        self._pos_acc = io.get(0x6064)
        self._mode_acc = io.get(0x6060)
        self._disp_acc = io.get(0x6061)
        self.mode_cmd = 8  # what we believe 6060 is (CSP until told otherwise)
        if self._mode_acc is not None:
            # the controller runs its axes in CSP: a mapped 6060h starts at 8, not at 0
            # ("no mode"), which would leave the drive deaf to 607Ah
            self._mode_acc.set(self.mode_cmd)
        self.pre_hooks: list[Callable[[Axis, int, int], None]] = []
        self.post_hooks: list[Callable[[Axis, int, int], None]] = []
        #: the axis's motion resources (gtecat.controller.resources.AxisResources), set at bus up
        self.motion: Any = None

    @property
    def moving(self) -> bool:
        """The profile is planning a motion (GT_GetSts bit 10); False without resources."""
        m = self.motion
        return m is not None and m.moving

    # --- feedback ------------------------------------------------------------------
    @property
    def statusword(self) -> int:
        return self._sw_acc.get() if self._sw_acc is not None else 0

    @property
    def state(self) -> PdsState:
        return decode_state(self.statusword)

    def actual_counts(self) -> int:
        if self._pos_acc is None:
            self.io.require(0x6064)  # raises ObjectNotMapped with the full message
        return self._pos_acc.get()

    def counts_to_pulses(self, counts: float) -> float:
        return (counts - self.drive_offset) / (1 << self.pos_scale)

    def pulses_to_counts(self, pulses: float) -> int:
        """Drive counts of an axis position in pulses (exact; 607Ah takes its low 32 bits).
        A position that is not a number (an unchecked axis jogging into infinity) has no
        counts: CommandError, which the cycle turns into an axis alarm (Axis.pre)."""
        x = pulses * (1 << self.pos_scale)
        if not math.isfinite(x):
            raise CommandError(
                f"axis {self.number}: the planned position is {pulses!r} pulses, not a number "
                "of drive counts"
            )
        return round(x) + self.drive_offset

    def actual_pulses(self) -> float:
        return self.counts_to_pulses(self.actual_counts())

    def mode_display(self) -> int:
        return self.io.read_or_sdo(0x6061, 0, 1, signed=True)

    # --- the cycle ----------------------------------------------------------------------
    def pre(self, t_ns: int, dt_ns: int) -> None:
        """Before the exchange: hooks plan, then controlword and 607A go out."""
        for h in self.pre_hooks:
            h(self, t_ns, dt_ns)
        if self._cw_acc is not None and self.cw != self._cw_sent:
            # the controller writes 6040h when it changes its command, so a user's raw
            # write of the controlword (GT_SetEcatRawData) stands until then
            self._cw_acc.set(self.cw)
            self._cw_sent = self.cw
        if self._tp_acc is not None:
            if self.servo_on and self.mode_cmd == 8:
                if self.csp_follow:
                    try:
                        self._tp_acc.set(self.pulses_to_counts(self.prf_pos + self.compensation))
                        self.plan_error = ""
                    except CommandError as e:  # 607Ah holds; the axis alarms (resources)
                        self.plan_error = str(e)
            elif not self.servo_on or self.mode_cmd != _PROFILE_POSITION:
                # elsewhere 607A stays on the actual position, so enabling or coming back
                # to CSP never jumps; in profile position mode 607A is the application's
                # target (GT_SetEcatRawData), which the drive takes on CW4
                if self._pos_acc is not None:
                    self._tp_acc.set(self._pos_acc.get())

    def post(self, t_ns: int, dt_ns: int) -> None:
        for h in self.post_hooks:
            h(self, t_ns, dt_ns)

    # --- servo on/off --------------------------------------------------------------------
    def sync_to_actual(self) -> None:
        """Planned position := actual position (no jump on enable or mode change)."""
        if self._pos_acc is not None:
            self.prf_pos = self.actual_pulses()

    def enable_step(self) -> bool:
        """Choose the next controlword towards operation enabled; True when there."""
        st = self.state
        if st == PdsState.OPERATION_ENABLED:
            self.cw = 0x000F | (self.cw & 0x0070 if self.mode_cmd != 8 else 0)
            return True
        self.cw = _ENABLE_STEP[st]
        return False

    def lose_link(self, reason: str) -> None:
        """The slave stopped exchanging process data: servo off, controlword 0.

        Controlword 0 (disable voltage) waits in the image, so a drive that comes back
        is switched off, never enabled again by a stale "enable operation".
        """
        self.link_lost = self.link_alarm = reason
        self.servo_on = False
        self.cw = 0x0000

    def drive_left_operation(self) -> None:
        """The drive left operation enabled by itself while the servo was on: servo off.

        A drive in *quick stop active* (its quick-stop input, or a quick stop it started
        itself) is braking on its quick-stop ramp (6085h, as 605Ah says).  Cutting its voltage
        then (disable voltage, transition 12) would end the ramp and let the motor coast, so
        the controller sends "quick stop" (controlword 0002h) instead: the drive finishes its
        quick stop and 605Ah decides where it ends - 1..4 in *switch on disabled* by itself,
        5..8 standing in quick stop active.  The command never enables it again (transition 16
        needs "enable operation"), whatever 605Ah says and whenever the input is released.
        The manual says what the controller does on a drive alarm (chapter 9.3: servo off) and
        nothing of a drive's quick stop (chapter 5 neither); CiA 402 gives the ramp to the
        drive, and a servo off that cuts it short would be the controller's doing.  Once the
        drive has left quick stop active, the controller sends disable voltage (0000h), as for
        any other drive that dropped out (:meth:`quick_stop_over`).  ``GT_AxisOn`` walks back
        from either state; GT_GetSts shows bit 9 clear (no alarm: the drive did not fault)
        from the cycle the controller saw the drive leave operation enabled.  Any other
        state: :meth:`request_disable`.
        """
        if self.statusword & _SW_STATE_MASK == _SW_QUICK_STOP_ACTIVE:
            self.servo_on = False
            self.cw = CW_QUICK_STOP
        else:
            self.request_disable()

    def quick_stop_over(self) -> None:
        """After :meth:`drive_left_operation`: the drive no longer in quick stop active (its
        ramp done, 605Ah 1..4) gets disable voltage, the controlword of a servo-off axis.
        Called every cycle the controller holds "quick stop" with the servo off."""
        if self.statusword & _SW_STATE_MASK != _SW_QUICK_STOP_ACTIVE:
            self.cw = 0x0000

    def request_disable(self) -> None:
        self.servo_on = False
        self.cw = (
            0x0006
            if self.state
            in (PdsState.OPERATION_ENABLED, PdsState.SWITCHED_ON, PdsState.READY_TO_SWITCH_ON)
            else 0x0000
        )
