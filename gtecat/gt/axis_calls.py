"""GT axis-level EtherCAT calls: servo on/off, drive mode, PDO objects of one axis.

Manual chapter 5 (table 5-1) and chapter 13 entries 4, 5, 34-42, 50, 100-102,
113-114 and the vendor header's ``GT_GetEcatAxisPdoData`` / ``GT_GetEcatErrorCode``.
Each function works on the mapped PDO object chapter 13 names (``GT_GetEcatEncPos``
-> 6064h ...) and returns 1 with a reason naming the object when it is not
mapped.

Decisions where the manual is silent:

* ``GT_AxisOn`` walks the CiA-402 state machine through 6040h (shutdown,
  switch on, enable operation) and returns once the drive reports *operation
  enabled*, within ``enable_timeout_ms`` (200 ms of controller time); 1 with
  the state reached otherwise.  A drive in FAULT is not reset by it: 1, clear
  the alarm first (GT_ClrSts), as the manual's return-1 text says.  Before
  enabling, the planned position is set to the actual one so the drive does
  not jump (pitfall 4 of cia402-facts).
* ``GT_AxisOn`` needs ``GT_StartEcatComm`` (entry 129: "only after this call
  succeeds may the other motion instructions be called"): before it, 1 with the
  reason.  It is the one gate the other motion instructions need: every start of
  a planner (GT_Update, GT_PtStart, GT_GearStart, GT_FollowStart) requires the
  servo on, and GT_StartEcatHoming a drive in *operation enabled* (5.2.2.2), which
  only GT_AxisOn gives.  Calls that read or configure (GT_GetSts, GT_GetEcat*, the
  profile and safety settings, SDO, raw data) work from GT_InitEcatComm on, as
  bring-up code needs them before it starts motion control.
* ``GT_AxisOn`` after a comm loss (:mod:`gtecat.controller.core`): 1 naming the
  slave while it is offline, and 1 until GT_ClrSts once it is back (bit 1 is
  latched; entry 5 return 1: "check whether the drive has an alarm").
* ``GT_GetEcatEncPos`` reports 6064h as the drive counts it (no scaling);
  ``GT_SetPosScale`` affects the controller's own positions.
* ``GT_GetEcatAxisPdoData(axis, object, pData)`` copies the mapped
  entry's bytes (little endian, the entry's size rounded up to bytes).  On a
  multi-axis module ``object`` may be numbered as for channel 0 (0x6064) or as
  the axis's own channel (0x6864 on channel 1); another channel's object is
  refused (1), never read.
* While the axis's slave is offline (comm loss) every read of one of its PDO objects
  returns 1 naming the slave, by its own call (``GT_GetEcatEncPos`` ...) or by index
  (``GT_GetEcatAxisPdoData``, ``GT_GetEcatAxisMode``, the torque reads): the bytes there
  are the last received, not the drive's (:func:`reachable`).
"""

from __future__ import annotations

from typing import Any

from ..controller.axis import Axis, PdsState
from ..controller.core import Controller
from ..errors import BusError, CommandError, ParameterError
from ._core import check_range, gt_function, store, store_bytes

#: modes GT_SetEcatAxisMode accepts (manual entry 100, GTHD list, plus 7 of entry 39)
ECAT_MODES = (0, 1, 3, 4, 6, 7, 8, 9, 10)


def bus_axis(ctl: Controller, axis: int) -> Axis:
    """The axis, with the bus up (1 when it is not: "check the EtherCAT communication")."""
    ax = ctl.axis(axis)
    m = ctl.master
    if m is None or not m.opened:
        raise BusError("EtherCAT communication is not established (GT_InitEcatComm)")
    return ax


def axis_on(ctl: Controller, ax: Axis) -> None:
    """Walk the drive to operation enabled (bounded), then own its set-point."""
    if not ctl.started:
        raise CommandError(
            f"axis {ax.number}: motion control is not started; call GT_StartEcatComm once "
            "GT_IsEcatReady reports 1 (manual entry 129: motion instructions only after it)"
        )
    if ax.link_lost:
        raise CommandError(
            f"axis {ax.number}: {ax.link_lost}; check the slave and its cable, then "
            "GT_ClrSts and GT_AxisOn once it is back"
        )
    if ax.link_alarm:
        raise CommandError(
            f"axis {ax.number}: alarm after a communication loss ({ax.link_alarm}), "
            "GT_GetSts bit 1; the slave is back: call GT_ClrSts first"
        )
    if not ctl.ready:
        raise BusError(f"axis {ax.number}: the bus is not in OP (poll GT_IsEcatReady first)")
    if getattr(ax, "moving", False):
        raise CommandError(f"axis {ax.number} is moving: call GT_Stop first")
    st = ax.state
    if st in (PdsState.FAULT, PdsState.FAULT_REACTION_ACTIVE):
        code = _error_code(ax)
        raise CommandError(
            f"axis {ax.number}: drive in {st.name}"
            + (f" (603Fh = 0x{code:04X})" if code is not None else "")
            + "; remove the cause and clear the alarm with GT_ClrSts"
        )
    ax.servo_on = False
    ax.sync_to_actual()
    ok = ctl.clock.run_until(ax.enable_step, ax.timing.enable_timeout_ms)
    if not ok:
        ax.cw = 0x0000
        raise CommandError(
            f"axis {ax.number}: drive did not reach operation enabled within "
            f"{ax.timing.enable_timeout_ms:g} ms (state {ax.state.name}, statusword "
            f"0x{ax.statusword:04X})"
        )
    ax.sync_to_actual()
    ax.servo_on = True
    for hook in getattr(ax, "on_servo", []):
        hook(ax, True)


def axis_off(ctl: Controller, ax: Axis) -> None:
    ax.request_disable()
    ctl.clock.run_until(
        lambda: ax.state != PdsState.OPERATION_ENABLED, ax.timing.disable_timeout_ms
    )
    for hook in getattr(ax, "on_servo", []):
        hook(ax, False)


def _error_code(ax: Axis) -> int | None:
    acc = ax.io.get(0x603F)
    return acc.get() if acc is not None else None


@gt_function
def GT_AxisOn(ctl: Controller, axis: int) -> int:
    axis_on(ctl, bus_axis(ctl, axis))
    return 0


@gt_function
def GT_AxisOff(ctl: Controller, axis: int) -> int:
    axis_off(ctl, bus_axis(ctl, axis))
    return 0


@gt_function
def GT_SetEcatAxisMode(ctl: Controller, axis: int, mode: int) -> int:
    ax = bus_axis(ctl, axis)
    mode = int(mode)
    if mode not in ECAT_MODES:
        raise ParameterError(f"mode {mode} is not one of {ECAT_MODES} (manual entry 100)")
    ax.io.write(0x6060, mode)
    if mode == 8 and ax.mode_cmd != 8:
        ax.sync_to_actual()  # leaving another mode for CSP never jumps
    ax.mode_cmd = mode
    return 0


@gt_function
def GT_GetEcatAxisMode(ctl: Controller, axis: int, pMode: Any) -> int:
    ax = bus_axis(ctl, axis)
    reachable(ax, 0x6061)
    store(pMode, ax.io.read(0x6061))
    return 0


def reachable(ax: Axis, index: int) -> None:
    """1 when the axis's slave is offline (comm loss): its PDO objects hold the last bytes
    received, not the drive's; every GT read of an axis's PDO object asks this first."""
    # read past the axis bank's guard: looking must not give a banked axis back
    lost = object.__getattribute__(ax, "link_lost")
    if lost:
        raise CommandError(
            f"axis {ax.number}: {lost}: 0x{index:04X} cannot be read (check the slave, its "
            "cable and the EtherCAT communication)"
        )


def _reader(index: int, subindex: int = 0):
    def read(ctl: Controller, axis: int, ptr: Any) -> int:
        ax = bus_axis(ctl, axis)
        reachable(ax, index)
        store(ptr, ax.io.read(index, subindex))
        return 0

    return read


def _define(name: str, index: int, subindex: int = 0, doc: str = "") -> None:
    fn = _reader(index, subindex)
    fn.__name__ = fn.__qualname__ = name
    fn.__doc__ = doc or f"Read 0x{index:04X}:{subindex:02X} of the axis (manual chapter 13)."
    globals()[name] = gt_function(fn)


_define("GT_GetEcatEncPos", 0x6064, doc="Position actual value 6064h (entry 41).")
_define("GT_GetEcatEncVel", 0x606C, doc="Velocity actual value 606Ch (entry 42).")
_define("GT_GetEcatAxisPE", 0x60F4, doc="Following error actual value 60F4h (entry 40).")
_define("GT_GetEcatAxisDI", 0x60FD, doc="Digital inputs 60FDh (entry 37).")
_define("GT_GetEcatAxisDO", 0x60FE, 1, doc="Digital outputs 60FEh:01 as sent (entry 38).")
_define("GT_GetEcatAxisAtITorque", 0x6077, doc="Torque actual value 6077h (entry 36).")
_define("GT_GetEcatAxisAtICurrent", 0x6078, doc="Current actual value 6078h (entry 35).")
_define("GT_GetEcatErrorCode", 0x603F, doc="Error code 603Fh (vendor header).")


@gt_function
def GT_SetEcatAxisDO(ctl: Controller, axis: int, DoValue: int) -> int:
    bus_axis(ctl, axis).io.write(0x60FE, int(DoValue) & 0xFFFFFFFF, 1)
    return 0


@gt_function
def GT_GetEcatAxisAI(ctl: Controller, axis: int, channel: int, pValue: Any) -> int:
    """Analog input ``channel`` 1 -> 20F2h, 2 -> 20F9h (the objects entry 34 names)."""
    channel = check_range("channel", channel, 1, 2)
    ax = bus_axis(ctl, axis)
    index = 0x20F2 if channel == 1 else 0x20F9
    reachable(ax, index)
    store(pValue, ax.io.read(index))
    return 0


@gt_function
def GT_SetEcatAxisPT(ctl: Controller, axis: int, torque: int) -> int:
    """Target torque 6071h (entry 101), in the drive's unit (per mille of rated torque)."""
    check_range("torque", torque, -32768, 32767)
    bus_axis(ctl, axis).io.write(0x6071, int(torque))
    return 0


@gt_function
def GT_SetEcatAxisPV(ctl: Controller, axis: int, velocity: int) -> int:
    """Target velocity 60FFh (entry 102), drive counts per second."""
    check_range("velocity", velocity, -(1 << 31), (1 << 31) - 1)
    bus_axis(ctl, axis).io.write(0x60FF, int(velocity))
    return 0


@gt_function
def GT_SetPosScale(ctl: Controller, axis: int, scale: int) -> int:
    """Encoder scale exponent: drive counts = pulses * 2**scale (entry 117)."""
    ax = ctl.axis(axis)
    scale = check_range("scale", scale, 0, 16)
    if getattr(ax, "moving", False):
        raise CommandError(f"axis {axis} is moving: call GT_Stop first (entry 117)")
    if ax.motion is not None:
        ax.motion.set_pos_scale(scale)  # the planned position and 607Ah stay where they are
        return 0
    actual = ax.actual_counts() if ax.io.get(0x6064) is not None else None
    ax.pos_scale = scale
    if actual is not None and not ax.servo_on:
        ax.sync_to_actual()
    return 0


@gt_function
def GT_GetPosScale(ctl: Controller, axis: int, pScale: Any) -> int:
    store(pScale, ctl.axis(axis).pos_scale)
    return 0


@gt_function
def GT_GetEcatAxisPdoData(ctl: Controller, axis: int, object: int, pData: Any) -> int:
    """Any mapped object of the axis by index (0x6064, or its channel's own 0x6864), subindex 0:
    the vendor header's three parameters (vendor demos call
    ``GTN_GetEcatAxisPdoData(core, axis, 0x6041, (unsigned char *)&sw)``)."""
    ax = bus_axis(ctl, axis)
    check_range("object", object, 0, 0xFFFF)
    acc = ax.io.require(int(object), 0)
    reachable(ax, int(object))
    value = acc.get()
    n = (acc.bits + 7) // 8
    store_bytes(pData, (value & ((1 << (8 * n)) - 1)).to_bytes(n, "little"))
    return 0
