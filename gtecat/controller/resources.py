"""The resources of one GT axis (manual chapter 4) and what they do every cycle.

:class:`AxisResources` joins the profile (planner and motion mode), the axis
(equivalent scaling, limits, alarm, following error, in-position band, status
word) and the encoder of one EtherCAT axis, and runs them in the controller's
cycle (``Axis.pre_hooks`` / ``Axis.post_hooks``):

* **pre** (before the exchange): while the servo is on and the drive is in CSP
  (6060h = 8), the planner gives this cycle's sample; the axis planned position
  (``Axis.prf_pos``, written to 607Ah) is its scaled value.
* **post** (after the exchange, the drive's answer in hand): drive state and
  alarm, encoder, limits, following error, stop inputs, in-position band.

Positions, from the planner to the drive and back (all doubles)::

    profile P --ProfileScale--> axis planned A --2**PosScale, offset--> 607Ah counts
    6064h counts --2**-PosScale, EncSns--> encoder E --EncScale--> axis encoder AE

``GT_GetAxisError`` = A - AE; the following-error check, the in-position band
and the soft limits use the axis values.  Decisions where the manual is silent:

* **Servo off, or the drive in another mode** (homing, CSV...): the planned
  position follows the drive (A := 6064h, P follows A), so enabling or coming
  back to CSP never jumps; a motion in progress is dropped.  Entering another
  mode also drops the offsets GT_ZeroPos / GT_SetEncPos / GT_SynchAxisPos made:
  after a homing run the controller's positions are the drive's (6064h), as at
  power-on and after GT_Reset.
* **Alarm** (9.3), with the alarm enabled: bit 1 latches, the servo is switched
  off (6040h disable) and the motion planning stops at once (the planner holds
  where the drive is).  A drive that leaves *operation enabled* on its own
  (fault with the alarm off, communication loss) also switches the servo off,
  without a flag.
* **Limits** (9.2): a hardware switch (60FDh) or the planned position past a
  soft limit latches bit 5/6; a motion toward that side is stopped with the
  abrupt-stop deceleration (decAbruptStop, GT_SetStopDec, 1000 pulse/ms² by
  table 4-4) and refused until GT_ClrSts; motion away is allowed.  A switch is
  seen in the inputs after the exchange, so its stop starts from that cycle's
  sample.
* **Soft limit, same cycle** (9.2.2: "限位触发以后使用急停加速度紧急停止"; example
  9-1: the motion passes the limit, the limit triggers, the motion stops): the
  planned position is checked as the planner gives it, before it goes out.  The
  cycle whose sample passes a soft limit while moving toward it (positive: above
  ``positive`` and above the previous sample; negative alike) starts the emergency
  stop *where the plan crosses the limit*, inside that cycle: at the crossing
  (fraction ``f`` of the cycle after the previous sample, speed ``v``; between the
  two samples the plan is the cubic Hermite curve through both, see
  :func:`~gtecat.controller.safety.limit_crossing`) a constant-deceleration ramp at
  decAbruptStop (GT_SetStopDec; 1000 pulse/ms² by table 4-4) takes over, and this
  cycle already sends that ramp's point ``(1 - f)`` of a cycle after the crossing
  (:func:`~gtecat.controller.motion.stop.ramp_through`).  So the plan comes to rest
  at exactly ``limit + v·|v| / (2·decAbruptStop)`` - past the limit by the stopping
  distance from the crossing speed, never by one more cycle of travel - and
  however the samples fall.  A limit lying exactly on a sample is crossed at the
  start of the next cycle (``f = 0``, ``v`` that sample's speed); a limit set
  behind a moving axis, from the previous sample.  Bit 5/6 (table 6-2) is set in
  that same cycle.  A planner already braking at decAbruptStop
  (GT_Stop, an earlier trigger) keeps its ramp; one passing the limit while
  moving away from it, or standing, is not stopped.
* **Following error** (bit 4): ``|A - AE| > GT_SetPosErr`` while the servo is on
  in CSP latches bit 4 and stops the motion abruptly; the servo stays on.  Like
  an alarm or a stop input, it refuses every new motion until GT_ClrSts.
* **Stop inputs** (bits 7/8, configuration file extension): while the input is
  active the flag latches and the profile stops smoothly / abruptly.
* **GT_ClrSts** clears a latched flag only when its cause is gone (chapter 6):
  no drive alarm (alarm off, or the drive not in fault), the following error
  back within the limit, off the limit switch and inside the soft limit, the
  stop input inactive.  On a bus axis it first tries to reset a faulted drive:
  it waits until the fault reaction is over, sends a rising edge of 6040h bit 7
  and waits (at most :data:`FAULT_RESET_TIMEOUT_MS`) for the drive to leave
  FAULT - which it does only when the fault's cause is gone.  The drive is then
  *switch on disabled*: GT_AxisOn enables it again.  GT_ClrSts returns 0 either
  way; a flag whose cause persists simply stays set.
* **GT_Reset**: the servo is switched off, motion dropped, every setting back
  to table 4-4, the flags cleared (and set again at once when their cause is
  there), positions taken from the drive.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from typing import Any, Protocol

from ..errors import BusError, CommandError, ParameterError
from ..master.clock import Clock
from ..master.image import EntryAccess
from .axis import CW_QUICK_STOP, Axis, PdsState, decode_state
from .axis_status import BLOCKING, LATCHED, AxisStatus, InPosition
from .encoder import Encoder
from .motion import JogParams, Planner, TrapParams
from .motion.stop import StopKind, ramp_through
from .profile import PrfMode, Profile
from .safety import LIMIT_NEGATIVE_BIT, LIMIT_POSITIVE_BIT, Safety, limit_crossing
from .scale import AffineLink, Scale


class Controller(Protocol):
    """What the resources need of the controller core (which imports this module)."""

    axes: dict[int, Axis]
    on_reset: list[Callable[[Controller], None]]
    clock: Clock

    def axis(self, n: int) -> Axis: ...


CSP = 8
_SW_FAULT = 0x0008  # 6041h bit 3: fault (set in FAULT and FAULT REACTION ACTIVE)
_SW_STATE_MASK, _SW_ENABLED = 0x6F, 0x27
_CW_FAULT_RESET = 0x0080
#: the drive states a GT_ClrSts resets (CiA 402 FAULT and FAULT REACTION ACTIVE)
_FAULTED = (PdsState.FAULT, PdsState.FAULT_REACTION_ACTIVE)
#: controller time GT_ClrSts waits for a fault reaction to end, then for the reset to act
FAULT_REACTION_TIMEOUT_MS = 500.0
FAULT_RESET_TIMEOUT_MS = 20.0
#: GT_SetPos range (chapter 13 entry 115)
POS_LIMIT = 1073741823

_ALARM = int(AxisStatus.ALARM)
_SERVO_ON, _MOVING, _ARRIVED = (
    int(AxisStatus.SERVO_ON),
    int(AxisStatus.MOVING),
    int(AxisStatus.ARRIVED),
)
_POS_ERROR = int(AxisStatus.POS_ERROR)
_POS_LIMIT = int(AxisStatus.POSITIVE_LIMIT)
_NEG_LIMIT = int(AxisStatus.NEGATIVE_LIMIT)
_SMOOTH = int(AxisStatus.SMOOTH_STOP)
_ABRUPT = int(AxisStatus.ABRUPT_STOP)
_BLOCKING = int(BLOCKING)
_FLAG_TEXT = {
    _ALARM: "drive alarm (bit 1)",
    _POS_ERROR: "following error over the limit (bit 4)",
    _SMOOTH: "smooth-stop input (bit 7)",
    _ABRUPT: "abrupt-stop input (bit 8)",
}


class AxisResources:
    """Profile, encoder, scaling, safety and status of one GT axis (the Pythonic layer)."""

    def __init__(self, ctl: Controller, ax: Axis) -> None:
        self.ctl = ctl
        self.ax = ax
        #: what other modules keep per axis (gtecat._attrs.PerObject: capture, smart homing)
        self.extensions: dict[str, Any] = {}
        self.number = ax.number
        self.cycle_ms = ctl.clock.cycle_ns / 1e6
        self.profile = Profile(ax.number, self.cycle_ms)
        self.encoder = Encoder(self.cycle_ms)
        self.prf_link = AffineLink()
        self.enc_link = AffineLink()
        self.safety = Safety.defaults(ax.number)
        self.band = InPosition()
        self.latched = 0
        io = ax.io
        self._sw = io.get(0x6041)
        self._act = io.get(0x6064)
        self._cmd = io.get(0x607A)
        self._alarm_sw = self._sw
        self._pos_din = self._neg_din = io.get(0x60FD)
        self._smooth_in: EntryAccess | None = None
        self._smooth_mask = 0
        self._abrupt_in: EntryAccess | None = None
        self._abrupt_mask = 0
        self._csp = ax.mode_cmd == CSP
        self._a_last = ax.prf_pos
        #: the axis bank running this axis (gtecat.controller.bank), and its row there; while
        #: set, the readers below answer from the bank
        self.bank: Any = None
        self.bank_row = 0
        #: something stepping this axis from outside every cycle for now (a smart homing
        #: about to start its next leg): the bank does not take the axis, which it would
        #: only have to give back at once
        self.bank_hold = False
        #: GT_Stop calls on this axis so far, standing or not (a smart homing between two
        #: legs ends on one: nothing of the profile shows a stop of an axis at rest)
        self.stops = 0
        ax.pre_hooks.append(self._pre)
        ax.post_hooks.append(self._post)
        ax.motion = self

    # --- wiring --------------------------------------------------------------------------
    def bind_inputs(self) -> None:
        """Resolve the alarm / limit / stop inputs (axis numbers) to PDO entries."""
        s = self.safety
        axes = self.ctl.axes

        def entry(axis: int | None, index: int):
            if axis is None or axis not in axes:
                return None
            return axes[axis].io.get(index)

        self._alarm_sw = entry(s.alarm_input, 0x6041)
        self._pos_din = entry(s.positive_input, 0x60FD)
        self._neg_din = entry(s.negative_input, 0x60FD)
        self._smooth_in = self._abrupt_in = None
        if s.smooth_stop_input is not None:
            self._smooth_in = entry(s.smooth_stop_input.axis, 0x60FD)
            self._smooth_mask = 1 << s.smooth_stop_input.bit
        if s.abrupt_stop_input is not None:
            self._abrupt_in = entry(s.abrupt_stop_input.axis, 0x60FD)
            self._abrupt_mask = 1 << s.abrupt_stop_input.bit

    # --- positions -----------------------------------------------------------------------
    @property
    def unit(self) -> float:
        """Pulses per drive count (GT_SetPosScale)."""
        return 1.0 / (1 << self.ax.pos_scale)

    @property
    def prf_pos(self) -> float:
        b = self.bank
        return b.value("prf_p", self.bank_row) if b is not None else self.profile.planner.pos

    @property
    def prf_vel(self) -> float:
        b = self.bank
        return b.value("prf_v", self.bank_row) if b is not None else self.profile.planner.vel

    @property
    def prf_acc(self) -> float:
        b = self.bank
        return b.value("prf_a", self.bank_row) if b is not None else self.profile.planner.acc

    @property
    def axis_prf_pos(self) -> float:
        b = self.bank
        return b.value("a_last", self.bank_row) if b is not None else self.ax.prf_pos

    @property
    def axis_prf_vel(self) -> float:
        return self.prf_link.ratio * self.prf_vel

    @property
    def axis_prf_acc(self) -> float:
        return self.prf_link.ratio * self.prf_acc

    @property
    def enc_pos(self) -> float:
        b = self.bank
        return b.value("enc_pos", self.bank_row) if b is not None else self.encoder.pos

    @property
    def enc_vel(self) -> float:
        b = self.bank
        return b.value("enc_vel", self.bank_row) if b is not None else self.encoder.vel

    @property
    def enc_acc(self) -> float:
        b = self.bank
        return b.value("enc_acc", self.bank_row) if b is not None else self.encoder.acc

    @property
    def axis_enc_pos(self) -> float:
        return self.enc_link.axis(self.enc_pos)

    @property
    def axis_enc_vel(self) -> float:
        return self.enc_link.ratio * self.enc_vel

    @property
    def axis_enc_acc(self) -> float:
        return self.enc_link.ratio * self.enc_acc

    @property
    def axis_error(self) -> float:
        """GT_GetAxisError: axis planned - axis encoder position, pulse."""
        return self.axis_prf_pos - self.enc_link.axis(self.enc_pos)

    @property
    def moving(self) -> bool:
        b = self.bank
        if b is not None:
            return b.row_value("moving", self.bank_row)
        return not self.profile.planner.done

    @property
    def driving(self) -> bool:
        """The controller sends the plan: servo on and the drive in CSP."""
        return self.ax.servo_on and self.ax.mode_cmd == CSP

    def status(self) -> int:
        """GT_GetSts's 32-bit word (table 6-2)."""
        b = self.bank
        if b is not None:
            return b.value("sts", self.bank_row)
        s = self.latched
        if type(s) is not int:
            s = int(s)
        if self.ax.servo_on:
            s |= _SERVO_ON
        if not self.profile.planner.done:
            s |= _MOVING  # and never in position (11.7: "规划运动...立即清 0")
        elif self.band.arrived:
            s |= _ARRIVED
        return s

    def _raw_source(self) -> int | None:
        acc = self._act if self.encoder.external else self._cmd
        if acc is None:
            acc = self._cmd if self.encoder.external else self._act
        return acc.get() if acc is not None else None

    # --- the cycle -----------------------------------------------------------------------
    def _pre(self, ax: Axis, t_ns: int, dt_ns: int) -> None:
        if ax.prf_pos != self._a_last:
            # someone else set the planned position (GT_AxisOn, homing, a raw test):
            # the profile follows, incrementally (11.6)
            self._a_last = ax.prf_pos
            self.profile.hold(self.prf_link.source(ax.prf_pos))
        if ax.servo_on and ax.mode_cmd == CSP:
            planner = self.profile.planner
            if not planner.done and self.profile.active:
                p0, v0 = planner.pos, planner.vel
                a = self.prf_link.axis(planner.step()[0])
                s = self.safety
                if (a > s.soft_positive or a < s.soft_negative) and s.active:
                    a = self._soft_limit_stop(planner, p0, v0, a)
                ax.prf_pos = a
                self._a_last = a

    def _soft_limit_stop(self, planner: Planner, p0: float, v0: float, a: float) -> float:
        """This cycle's sample ``a`` passed a soft limit: the emergency stop starts in it.

        The module docstring ("Soft limit, same cycle") gives the rule; ``(p0, v0)``
        is the previous sample (profile units).  Returns this cycle's axis planned
        position.
        """
        link = self.prf_link
        a0 = link.axis(p0)
        s = self.safety
        if a > s.soft_positive and a > a0:
            self.latched |= _POS_LIMIT
            level = s.soft_positive
        elif a < s.soft_negative and a < a0:
            self.latched |= _NEG_LIMIT
            level = s.soft_negative
        else:
            return a  # past it, not moving toward it: the flag latches after the exchange
        if planner.stopping == StopKind.ABRUPT:
            return a  # already braking at decAbruptStop
        level_p = link.source(level)
        f, p, v = limit_crossing(p0, v0, planner.pos, planner.vel, level_p, self.cycle_ms)
        dec = self.profile.stop_dec.abrupt
        planner.stop(dec, True, origin=ramp_through(p, v, dec, f * self.cycle_ms))
        if not planner.done:
            planner.step()
        return link.axis(planner.pos)

    def _post(self, ax: Axis, t_ns: int, dt_ns: int) -> None:
        safety = self.safety
        sw = self._sw.get() if self._sw is not None else 0
        # --- the drive: alarm, enable lost
        if safety.active and safety.alarm_on and self._alarm_sw is not None:
            if self._alarm_sw.get() & _SW_FAULT:
                self.latched |= _ALARM
                if ax.servo_on:
                    ax.request_disable()
        if ax.servo_on:
            if sw & _SW_STATE_MASK != _SW_ENABLED:
                ax.drive_left_operation()  # by itself: a quick stop is let finish
        elif ax.cw == CW_QUICK_STOP:
            ax.quick_stop_over()
        if ax.plan_error and ax.servo_on:
            # the planned position left the numbers (checks off, a jog into infinity): 607Ah
            # held its last value; servo off and the alarm bit, as for a drive alarm, so the
            # plan follows the drive again and GT_ClrSts + GT_AxisOn recover
            self.ctl.log(f"Axis {ax.number}: {ax.plan_error}; servo off, alarm (GT_GetSts bit 1).")
            self.latched |= _ALARM
            ax.request_disable()
        csp = ax.mode_cmd == CSP
        if csp != self._csp:
            self._csp = csp
            if not csp:
                self._rebase()
        # --- not driving: the plan follows the drive
        if not (ax.servo_on and csp) and self._act is not None:
            self.follow_drive(ax)
        # --- encoder
        raw = self._raw_source()
        if raw is not None:
            self.encoder.sample(raw, 1.0 / (1 << ax.pos_scale))
        if not safety.active:
            return
        a = ax.prf_pos
        err = a - self.enc_link.axis(self.encoder.pos)
        latched = self.latched
        # --- limits: hardware switches, soft limits
        if (
            safety.positive_on
            and self._pos_din is not None
            and self._pos_din.get() & LIMIT_POSITIVE_BIT
        ) or a > safety.soft_positive:
            latched |= _POS_LIMIT
        if (
            safety.negative_on
            and self._neg_din is not None
            and self._neg_din.get() & LIMIT_NEGATIVE_BIT
        ) or a < safety.soft_negative:
            latched |= _NEG_LIMIT
        # --- following error
        if ax.servo_on and csp and not -safety.pos_err <= err <= safety.pos_err:
            latched |= _POS_ERROR
        # --- stop inputs
        if self._smooth_in is not None and self._smooth_in.get() & self._smooth_mask:
            latched |= _SMOOTH
        if self._abrupt_in is not None and self._abrupt_in.get() & self._abrupt_mask:
            latched |= _ABRUPT
        self.latched = latched
        # --- reactions
        planner = self.profile.planner
        if latched and not planner.done:
            v = self.prf_link.ratio * planner.vel
            if (
                latched & (_POS_ERROR | _ABRUPT)
                or (latched & _POS_LIMIT and v > 0.0)
                or (latched & _NEG_LIMIT and v < 0.0)
            ):
                self.profile.stop(abrupt=True)
            elif latched & _SMOOTH and planner.stopping == StopKind.NONE:
                self.profile.stop(abrupt=False)
        band = self.band
        if band.band > 0:
            band.update(t_ns, planner.done, err)

    def follow_drive(self, ax: Axis) -> None:
        """Not driving (servo off, or a drive mode other than CSP): the planned position and
        the plan follow 6064h."""
        a = (self._act.get() - ax.drive_offset) / (1 << ax.pos_scale)
        ax.prf_pos = a
        self._a_last = a
        planner = self.profile.planner
        p = self.prf_link.source(a)
        if p != planner.pos or not planner.done:
            planner.hold(p)

    def _rebase(self) -> None:
        """Positions from the drive again (another drive mode, GT_Reset): offsets dropped."""
        ax = self.ax
        ax.drive_offset = 0
        self.prf_link.synch()
        self.enc_link.synch()
        raw = self._raw_source()
        if raw is not None:
            self.encoder.rebase(raw, self.unit)
        if self._act is not None:
            a = self._act.get() / (1 << ax.pos_scale)
            ax.prf_pos = a
            self._a_last = a
        self.profile.hold(self.prf_link.source(ax.prf_pos))

    # --- causes of the latched flags -------------------------------------------------------
    def causes(self) -> int:
        """The flags whose cause is present now (what GT_ClrSts cannot clear)."""
        s = self.safety
        out = 0
        if s.alarm_on and self._alarm_sw is not None and self._alarm_sw.get() & _SW_FAULT:
            out |= _ALARM
        a = self.ax.prf_pos
        if (
            s.positive_on and self._pos_din is not None and self._pos_din.get() & LIMIT_POSITIVE_BIT
        ) or a > s.soft_positive:
            out |= _POS_LIMIT
        if (
            s.negative_on and self._neg_din is not None and self._neg_din.get() & LIMIT_NEGATIVE_BIT
        ) or a < s.soft_negative:
            out |= _NEG_LIMIT
        if self.driving and abs(self.axis_error) > s.pos_err:
            out |= _POS_ERROR
        if self._smooth_in is not None and self._smooth_in.get() & self._smooth_mask:
            out |= _SMOOTH
        if self._abrupt_in is not None and self._abrupt_in.get() & self._abrupt_mask:
            out |= _ABRUPT
        return out

    def limit_input(self, positive: bool) -> bool | None:
        """The level of the positive (negative) limit input as wired - a configuration
        file's ``reverse`` applied - whether GT_LmtsOn/Off has it on or off; None when the
        input is none (configuration file index -1).  Smart homing reads it."""
        acc = self._pos_din if positive else self._neg_din
        if acc is None:
            return None
        return bool(acc.get() & (LIMIT_POSITIVE_BIT if positive else LIMIT_NEGATIVE_BIT))

    def drive_faulted(self) -> bool:
        return self.ax.state in _FAULTED

    def drive_state(self) -> PdsState:
        """The drive's state as 6041h in the image shows it (:attr:`Axis.state`), read
        without touching the axis: an axis the bank runs stays there (its row writes 6041h
        into the image every cycle it changes, like the scalar path's exchange)."""
        sw = self._sw
        return self.ax.state if sw is None else decode_state(sw.get())

    # --- commands: modes and parameters ----------------------------------------------------
    def prf_trap(self) -> None:
        """GT_PrfTrap."""
        self._require_profile("GT_PrfTrap")
        self.profile.enter(PrfMode.TRAP)

    def prf_jog(self) -> None:
        """GT_PrfJog."""
        self._require_profile("GT_PrfJog")
        self.profile.enter(PrfMode.JOG)

    def set_trap_prm(self, prm: TrapParams) -> None:
        p = self.profile
        p.require_mode("GT_SetTrapPrm", PrfMode.TRAP)
        p.require_idle("GT_SetTrapPrm")
        p.trap_prm = prm

    def set_jog_prm(self, prm: JogParams) -> None:
        p = self.profile
        p.require_mode("GT_SetJogPrm", PrfMode.JOG)
        p.require_idle("GT_SetJogPrm")
        p.jog_prm = prm

    def set_target(self, pos: int) -> None:
        """GT_SetPos (Trap): the target of the next GT_Update."""
        self.profile.require_mode("GT_SetPos", PrfMode.TRAP)
        if not -POS_LIMIT <= pos <= POS_LIMIT:
            raise ParameterError(f"pos={pos} out of range [-1073741823, 1073741823] (entry 115)")
        self.profile.trap_target = pos

    def set_vel(self, vel: float) -> None:
        """GT_SetVel: Trap speed (> 0) or signed Jog speed, pulse/ms, for the next GT_Update."""
        p = self.profile
        p.require_mode("GT_SetVel", PrfMode.TRAP, PrfMode.JOG)
        if p.mode == PrfMode.TRAP:
            if not vel > 0.0:
                raise ParameterError(f"vel={vel!r}: a Trap speed must be > 0 pulse/ms")
            p.trap_vel = vel
        else:
            p.jog_vel = vel

    def get_vel(self) -> float:
        p = self.profile
        p.require_mode("GT_GetVel", PrfMode.TRAP, PrfMode.JOG)
        return p.trap_vel if p.mode == PrfMode.TRAP else p.jog_vel

    def _require_profile(self, what: str) -> None:
        if not self.profile.active:
            raise CommandError(
                f"{what}: profile {self.number} is not active (configuration file 'active = 0')"
            )
        self.profile.require_idle(what)

    # --- commands: motion ----------------------------------------------------------------------
    def check_motion(self, what: str, direction: float = 0.0) -> None:
        """What every start of a motion needs (GT_Update, and GT_PtStart / GT_GearStart /
        GT_FollowStart later): profile active, no blocking flag, servo on, drive in CSP, not
        toward a triggered limit.  ``direction``: sign of the motion in profile units (0 =
        unknown or both ways).  CommandError naming the first condition that fails."""
        n = self.number
        if not self.profile.active:
            raise CommandError(f"{what}: profile {n} is not active (configuration file)")
        blocked = self.latched & _BLOCKING
        if blocked:
            flags = ", ".join(t for f, t in _FLAG_TEXT.items() if blocked & f)
            raise CommandError(f"{what}: axis {n} has {flags} set; remove the cause and GT_ClrSts")
        ax = self.ax
        if not ax.servo_on:
            raise CommandError(
                f"{what}: axis {n} is not servo-enabled (GT_GetSts bit 9 = 0); call GT_AxisOn first"
            )
        if ax.mode_cmd != CSP:
            raise CommandError(
                f"{what}: axis {n}'s drive is in mode {ax.mode_cmd}, not cyclic synchronous "
                "position (8); switch back with GT_SetHomingMode(axis, 8) or "
                "GT_SetEcatAxisMode(axis, 8)"
            )
        direction *= self.prf_link.ratio
        if direction > 0.0 and self.latched & _POS_LIMIT:
            raise CommandError(
                f"{what}: axis {n}'s positive limit is triggered (GT_GetSts bit 5): motion in "
                "the positive direction is refused; move away and call GT_ClrSts"
            )
        if direction < 0.0 and self.latched & _NEG_LIMIT:
            raise CommandError(
                f"{what}: axis {n}'s negative limit is triggered (GT_GetSts bit 6): motion in "
                "the negative direction is refused; move away and call GT_ClrSts"
            )

    def check_update(self) -> None:
        """Every condition GT_Update needs for this axis; CommandError naming the first failing."""
        p = self.profile
        if p.mode not in (PrfMode.TRAP, PrfMode.JOG):
            raise CommandError(
                f"GT_Update: axis {self.number} is in {p.mode.name.capitalize()} mode; GT_Update "
                "starts Trap and Jog motions only (GT_PrfTrap / GT_PrfJog)"
            )
        if p.mode == PrfMode.TRAP:
            direction = p.trap_target - p.planner.pos
        else:
            direction = p.jog_vel
        self.check_motion("GT_Update", direction)
        if p.mode == PrfMode.TRAP and not p.trap_vel > 0.0:
            raise CommandError(
                f"GT_Update: axis {self.number} has no Trap speed; call GT_SetVel first"
            )

    def start(self) -> None:
        """GT_Update for this axis (after :meth:`check_update`): start, or change on the fly."""
        p = self.profile
        if p.mode == PrfMode.TRAP:
            trap = p.trap
            if not trap.done and trap.stopping == StopKind.NONE:
                trap.update(p.trap_target, p.trap_vel)
            else:
                trap.start(trap.pos, p.trap_target, p.trap_vel, p.trap_prm, trap.vel)
        else:
            jog = p.jog
            if not jog.done and jog.stopping == StopKind.NONE:
                jog.update(p.jog_vel)
            else:
                jog.start(jog.pos, p.jog_vel, p.jog_prm, jog.vel)

    def stop(self, abrupt: bool) -> None:
        """GT_Stop for this axis."""
        self.stops += 1
        self.profile.stop(abrupt)

    # --- commands: positions -------------------------------------------------------------------
    def set_prf_pos(self, pos: float) -> None:
        """GT_SetPrfPos: the profile position becomes ``pos``; the axis keeps its value (11.6)."""
        self.profile.require_idle("GT_SetPrfPos (entry 118: not while moving)")
        self.profile.redefine(pos)
        self.prf_link.anchor(pos, self.ax.prf_pos)

    def set_enc_pos(self, pos: float) -> None:
        """GT_SetEncPos: the encoder reading becomes ``pos``; the axis encoder keeps its value."""
        here = self.axis_enc_pos
        self.encoder.set_pos(pos)
        self.enc_link.anchor(pos, here)

    def _shift_axis(self, new: float) -> None:
        """Redefine the axis planned position without moving the drive (607Ah stays)."""
        ax = self.ax
        counts = ax.pulses_to_counts(ax.prf_pos)
        ax.prf_pos = new
        ax.drive_offset = counts - round(new * (1 << ax.pos_scale))
        self._a_last = new

    def zero_pos(self) -> None:
        """GT_ZeroPos: planned and actual positions 0 (profile, axis, encoder, axis encoder)."""
        self.profile.require_idle("GT_ZeroPos")
        self._shift_axis(0.0)
        self.prf_link.synch()
        self.profile.redefine(0.0)
        self.encoder.set_pos(0.0)
        self.enc_link.synch()

    def synch_axis_pos(self) -> None:
        """GT_SynchAxisPos: axis planned := scaled profile, axis encoder := scaled encoder."""
        self._shift_axis(self.prf_link.ratio * self.profile.planner.pos)
        self.prf_link.synch()
        self.enc_link.synch()

    def set_profile_scale(self, scale: Scale) -> None:
        self.profile.require_idle("GT_ProfileScale")
        self.prf_link.set_scale(scale, self.profile.planner.pos)

    def set_enc_scale(self, scale: Scale) -> None:
        self.profile.require_idle("GT_EncScale")
        self.enc_link.set_scale(scale, self.encoder.pos)

    def set_pos_scale(self, scale: int) -> None:
        """GT_SetPosScale: a new count exponent - the pulse becomes 2**scale drive counts.

        Every position of the axis is re-expressed in the new pulse (planned, profile,
        encoder, their offsets: all multiplied by 2**(old - new), exactly); the drive
        keeps its set-point, nothing moves.
        """
        self.profile.require_idle("GT_SetPosScale (entry 117)")
        ax = self.ax
        f = 2.0 ** (ax.pos_scale - scale)
        ax.pos_scale = scale
        if f == 1.0:
            return
        ax.prf_pos *= f  # the same drive counts: round(A * 2**scale) + drive_offset
        self._a_last = ax.prf_pos
        self.prf_link.offset *= f
        self.enc_link.offset *= f
        self.encoder.set_pos(self.encoder.pos * f)
        self.profile.redefine(self.profile.planner.pos * f)

    def set_encoder_source(self, external: bool) -> None:
        """GT_EncOn (external: 6064h) / GT_EncOff (pulse counter: 607Ah)."""
        enc = self.encoder
        if enc.external == external:
            return
        enc.external = external
        raw = self._raw_source()
        if raw is not None:
            enc.resync(raw)

    # --- status ----------------------------------------------------------------------------------
    def clear_flags(self) -> None:
        """The flag part of GT_ClrSts (after any drive fault reset)."""
        self.latched &= self.causes()

    def reset(self) -> None:
        """GT_Reset: table 4-4 for every resource of this axis."""
        ax = self.ax
        if ax.servo_on:
            ax.request_disable()
        self.safety = Safety.defaults(self.number)
        self.bind_inputs()
        self.band.reset()
        self.prf_link.reset()
        self.enc_link.reset()
        self.encoder.reset()
        self.latched = 0
        self._rebase()
        self.profile.reset(self.profile.planner.pos)


# --- the controller side -----------------------------------------------------------------
def install(ctl: Controller) -> None:
    """Create every axis's resources (bus up) and hook GT_Reset once per controller."""
    #: GT axis -> its resources (read without touching the Axis, which the bank may guard)
    ctl.resources = {n: AxisResources(ctl, ax) for n, ax in ctl.axes.items()}
    for ax in ctl.axes.values():
        ax.motion.bind_inputs()
    if _reset_all not in ctl.on_reset:
        ctl.on_reset.append(_reset_all)


def _reset_all(ctl: Controller) -> None:
    for ax in ctl.axes.values():
        res = getattr(ax, "motion", None)
        if res is not None:
            res.reset()


def axis_resources(ctl: Controller, n: int) -> AxisResources:
    """The resources of GT axis ``n``: BusError (1) before the bus is up, 7 when out of range."""
    if type(n) is int:
        res = getattr(ctl, "resources", {}).get(n)
        if res is not None and ctl.axes.get(n) is res.ax:
            return res
    if not ctl.axes:
        raise BusError(
            f"axis {n}: no EtherCAT axis yet (call GT_InitEcatComm; the ENI must hold a "
            "CiA-402 drive)"
        )
    ax = ctl.axis(n)
    res = getattr(ax, "motion", None)
    if res is None:
        raise BusError(f"axis {n} has no motion resources (bus not brought up by GT_InitEcatComm)")
    return res


#: the EtherCAT controller's axis count: profile, axis and encoder numbers run 1..12 in
#: chapter 13 ("轴号，取值范围：[1, 12]"), and the status and mask tables have 12 axis columns
CONTROLLER_AXES = 12


def resource_count(ctl: Controller) -> int:
    """How many axes the controller has, whatever the bus holds: a GTS card's own count
    (``gts:4``: 4), else 12 (or the bus's axes, where a bus holds more)."""
    card = getattr(ctl, "card", None)
    if card is not None:
        return int(card.spec.axes)
    return max(CONTROLLER_AXES, max(ctl.axes, default=0))


def axis_span(
    ctl: Controller, first: int, count: int, limit: int | None = None
) -> list[AxisResources | None]:
    """Axes ``first .. first+count-1`` (the ``count`` argument form of chapter 13).

    One rule for every function with a ``count`` (GT_GetSts, GT_ClrSts, GT_ZeroPos,
    GT_GetPrf*, GT_GetAxis*, GT_GetEnc*, GT_GetPrfMode): the controller's profiles, axes
    and encoders exist up to its axis count (:func:`resource_count`) whatever the bus
    holds, as on the device; the manual's examples 7-5, 7-7 and 7-8 read 8 profiles
    (``GT_GetPrfVel(1, ADR(arrPrfVel), 8, 0)``) on machines of fewer axes.  So the span
    must lie inside ``1 .. resource_count`` (else 7); an axis in it that no drive backs is
    ``None`` here: it reads as a resource at rest (status 0, positions, velocities and
    mode 0) and GT_ClrSts / GT_ZeroPos leave it as it is."""
    try:
        first, count = int(first), int(count)
    except (TypeError, ValueError):
        raise ParameterError(f"axis={first!r}, count={count!r} must be integers") from None
    if count < 1:
        raise ParameterError(f"count={count} must be >= 1")
    if limit is not None and count > limit:
        raise ParameterError(f"count={count}: at most {limit} at once")
    if not ctl.axes:
        axis_resources(ctl, first)  # BusError with the reason
    n = resource_count(ctl)
    last = first + count - 1
    if first < 1 or last > n:
        raise ParameterError(
            f"axis={first}, count={count}: axes {first}..{last} run past the controller's "
            f"axes 1..{n}"
        )
    return [axis_resources(ctl, k) if k in ctl.axes else None for k in range(first, last + 1)]


def axes_in_mask(ctl: Controller, mask: int, strict: bool) -> list[AxisResources]:
    """Axes whose bit is set in ``mask`` (bit 0 = axis 1); ``strict``: a missing one is 7."""
    try:
        m = int(mask)
    except (TypeError, ValueError):
        raise ParameterError(f"mask={mask!r} is not an integer") from None
    out = []
    n = 1
    m &= 0xFFFFFFFF
    while m:
        if m & 1:
            if n in ctl.axes:
                out.append(axis_resources(ctl, n))
            elif strict:
                axis_resources(ctl, n)  # raises with the reason
        m >>= 1
        n += 1
    return out


def position_source(ctl: Controller, kind: int, index: int, item: int = 0) -> Callable[[], float]:
    """A master position for Gear / Follow (GT_SetGearMaster, GT_SetFollowMaster, 7.5.2):
    ``kind`` 1 encoder ``index``, 2 profile ``index`` (planned), 3 axis ``index`` (``item`` 0
    its planned, 1 its encoder position).  Axes are stepped in number order, so a master
    numbered below its slave is read in the same cycle."""
    res = axis_resources(ctl, index)
    if kind == 1:
        f = lambda: res.encoder.pos  # noqa: E731
    elif kind == 2:
        f = lambda: res.profile.planner.pos  # noqa: E731
    elif kind == 3:
        if item == 0:
            f = lambda: res.ax.prf_pos  # noqa: E731
        else:
            f = lambda: res.enc_link.axis(res.encoder.pos)  # noqa: E731
    else:
        raise ParameterError(f"master type {kind}: 1 encoder, 2 profile or 3 axis")
    # what the axis bank reads to keep a slave and its master together (gtecat.controller.bank)
    f.master = (res, kind)  # type: ignore[attr-defined]
    return f


def clear_status(ctl: Controller, axes: Iterable[AxisResources]) -> None:
    """GT_ClrSts on ``axes`` (their link up): reset the faulted drives (bounded), then clear
    the flags whose cause is gone and the link alarms.

    An axis the bank runs with no flag latched and no link alarm (looked at once the resets'
    cycles have run) is left where it is: the call would change nothing of it, and touching
    it would give it back to its scalar objects, which the bank would claim again at its
    next cycle (an error handler that calls GT_ClrSts every few ms paid that for every
    axis).  Read past the bank's guard: the latched flags stand still in the bank, 6041h is
    in the image (:meth:`AxisResources.drive_state`)."""
    axes = list(axes)
    faulted = [r for r in axes if r.drive_state() in _FAULTED]
    if faulted:
        _fault_reset(ctl, faulted)
    get = object.__getattribute__
    needing = [r for r in axes if r.bank is None or r.latched or get(r.ax, "link_alarm")]
    if needing and ctl.bank is not None:
        ctl.bank.dirty = True  # (what the call changes may let the bank take an axis again)
    for r in needing:
        r.clear_flags()
    for r in needing:
        r.ax.link_alarm = ""


def _fault_reset(ctl: Controller, faulted: list[AxisResources]) -> None:
    """Reset the drives of ``faulted`` (their drive in FAULT or FAULT REACTION ACTIVE): the
    controlword's bit 7 low, then rising, a few cycles each, bounded.

    The drives' state is watched every cycle in the 6041h the image holds
    (:meth:`AxisResources.drive_state`), which leaves an axis the bank runs where it is: a
    drive resting in FAULT while its cause persists (the reset refused) then rests in the bank
    for those cycles instead of being given back at each look."""
    clock = ctl.clock
    clock.run_until(
        lambda: all(r.drive_state() != PdsState.FAULT_REACTION_ACTIVE for r in faulted),
        FAULT_REACTION_TIMEOUT_MS,
    )
    for r in faulted:
        r.ax.servo_on = False
        r.ax.cw = 0x0000
    _run_cycles(ctl, 1)  # the drive sees bit 7 low ...
    for r in faulted:
        if r.drive_state() == PdsState.FAULT:
            r.ax.cw = _CW_FAULT_RESET  # ... then rising (transition 15)
    # a drive that refused the reset rests in FAULT until something outside the bank's runs
    # changes it (its cause going is an injector's event, which ends a run): while each
    # faulted axis rests frozen in the bank (servo off), 6041h in the image stays as it is
    bank = ctl.bank
    clock.run_until(
        lambda: not any(r.drive_state() == PdsState.FAULT for r in faulted),
        FAULT_RESET_TIMEOUT_MS,
        None if bank is None else lambda: all(bank.rests(r.ax) for r in faulted),
    )
    for r in faulted:
        r.ax.cw = 0x0000


def _run_cycles(ctl: Controller, n: int) -> None:
    c0 = ctl.clock.cycles
    ctl.clock.run_until(lambda: ctl.clock.cycles >= c0 + n, (n + 2) * ctl.clock.cycle_ns / 1e6)


__all__ = [
    "LATCHED",
    "AxisResources",
    "axes_in_mask",
    "axis_resources",
    "axis_span",
    "clear_status",
    "install",
    "position_source",
]
