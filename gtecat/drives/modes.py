"""Modes of operation (6060h/6061h, 6502h) and what each does in one cycle.

Every mode works on the channel's *demand*: ``dpos`` (machine counts, where
the axis should be at the end of this cycle) and ``dvel`` (counts/s), or, in
the torque modes, ``dtorque`` (per mille).  The mechanics then track that
demand.  Targets arrive in encoder counts (6064h scale); ``enc_offset``
converts: machine = encoder + enc_offset.

Mode-specific statusword bits 10/12/13 (cia402-facts.md 2.2) are left in
``ch.oms`` by each step function:

- CSP/CSV/CST: SW12 = 1 while the drive follows the command value (0 during a
  halt or a limit-switch stop), SW13 (CSP) = following error; SW10 = 0
  (reserved; no status toggle).
- PP: SW10 target reached (|607A - 6064| <= 6067h for 6068h ms after the
  profile ended), SW12 set-point acknowledge, SW13 following error.  The
  handshake is CiA 402's: a rising CW4 is taken when the one-deep set-point
  buffer is free, SW12 rises, and falls once CW4 is 0 and the buffer is free
  again.  CW5 = 1 replaces the running target at once; CW5 = 0 queues it
  behind the running one.  CW6 = 1 makes 607Ah relative to the previous target
  (CiA 402 default of 60F2h).  CW9 (change on set-point) is not implemented.
- PV: SW10 velocity reached (within 1 % or 10 counts/s of 60FFh), SW12 = speed
  is zero.  PT: SW10 torque reached.
- HM: the homing component's (SW10, SW12, SW13), cia402-facts.md 3.1.

The channel passes its controlword; the edge of CW4 is against ``ch.prev_cw``.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable
from enum import IntEnum
from typing import Any

SW10 = 1 << 10
SW12 = 1 << 12
SW13 = 1 << 13


class OpMode(IntEnum):
    """Values of 6060h/6061h (cia402-facts.md 2.1)."""

    NO_MODE = 0
    PROFILE_POSITION = 1
    VELOCITY = 2
    PROFILE_VELOCITY = 3
    PROFILE_TORQUE = 4
    HOMING = 6
    INTERPOLATED_POSITION = 7
    CYCLIC_SYNC_POSITION = 8
    CYCLIC_SYNC_VELOCITY = 9
    CYCLIC_SYNC_TORQUE = 10


#: what this drive implements by default (6502h = 0x03AD)
DEFAULT_MODES: tuple[OpMode, ...] = (
    OpMode.PROFILE_POSITION,
    OpMode.PROFILE_VELOCITY,
    OpMode.PROFILE_TORQUE,
    OpMode.HOMING,
    OpMode.CYCLIC_SYNC_POSITION,
    OpMode.CYCLIC_SYNC_VELOCITY,
    OpMode.CYCLIC_SYNC_TORQUE,
)

#: modes in which the position demand is monitored against 6065h/6066h
POSITION_MODES = frozenset({OpMode.PROFILE_POSITION, OpMode.HOMING, OpMode.CYCLIC_SYNC_POSITION})
TORQUE_MODES = frozenset({OpMode.PROFILE_TORQUE, OpMode.CYCLIC_SYNC_TORQUE})


def supported_bits(modes: Iterable[int]) -> int:
    """6502h: bit (mode - 1) for each standard mode 1..10 (python-canopen's layout)."""
    bits = 0
    for m in modes:
        if 1 <= m <= 10:
            bits |= 1 << (m - 1)
    return bits


# --- trajectory helpers --------------------------------------------------------------
def profile_step(
    s: float, v: float, target: float, vmax: float, acc: float, dec: float, dt: float
) -> tuple[float, float, bool]:
    """One cycle of an online trapezoidal profile towards ``target``.

    Accelerates with ``acc`` up to ``vmax`` and brakes with ``dec`` so as to
    stop on the target; reverses (braking first) if the target moved behind.
    Returns (position, velocity, arrived).
    """
    dist = target - s
    if dist == 0.0 and v == 0.0:
        return target, 0.0, True
    vstop = math.sqrt(2.0 * dec * abs(dist))
    vdes = min(vmax, vstop)
    if dist < 0.0:
        vdes = -vdes
    if v < vdes:
        v = min(vdes, v + (acc if v >= 0.0 else dec) * dt)
    elif v > vdes:
        v = max(vdes, v - (dec if v > 0.0 else acc) * dt)
    s_new = s + v * dt
    rest = target - s_new
    if (rest <= 0.0 < dist) or (rest >= 0.0 > dist) or (abs(rest) < 1e-6 and abs(v) <= dec * dt):
        return target, 0.0, True
    return s_new, v, False


def ramp(v: float, target: float, acc: float, dec: float, dt: float) -> float:
    """A velocity (or torque) ramp: ``acc`` when the magnitude grows, ``dec`` when it falls."""
    if v < target:
        return min(target, v + (acc if v >= 0.0 else dec) * dt)
    if v > target:
        return max(target, v - (dec if v > 0.0 else acc) * dt)
    return v


def stop_ramp(ch: Any, decel: float, dt: float) -> None:
    """Bring the demand velocity to 0 with ``decel`` (halt, quick stop, fault reaction).

    The ramp starts from the *actual* position and velocity: a stale or jumping
    set-point (a CSP step that just tripped the following error) is not followed.
    """
    if not ch.stopping:
        ch.stopping = True
        ch.torque_ctl = False
        ch.dpos = ch.mech.pos
        ch.dvel = ch.mech.vel
    v = ch.dvel
    step = decel * dt
    if v > step:
        v -= step
    elif v < -step:
        v += step
    else:
        v = 0.0
    ch.dvel = v
    ch.dpos += v * dt


def _clamp_limits(ch: Any, x: int) -> int:
    lo, hi = ch.sw_limit_min, ch.sw_limit_max
    if lo < hi:
        if x < lo:
            ch.sw_limited = True
            return lo
        if x > hi:
            ch.sw_limited = True
            return hi
    return x


# --- entering a mode ---------------------------------------------------------------------
def enter(ch: Any, mode: int) -> None:
    """Set-points cleared, demand taken from the actual state (mode switch or transition 4)."""
    ch.torque_ctl = mode in TORQUE_MODES
    ch.dpos = ch.mech.pos
    ch.dvel = ch.mech.vel
    ch.dtorque = ch.mech.torque if ch.torque_ctl else 0.0
    ch.fe_time = 0.0
    ch.fe_flag = False
    ch.stopping = False
    ch.pp_target = round(ch.mech.pos - ch.enc_offset)
    ch.pp_pending = None
    ch.pp_moving = False
    ch.sp_ack = False
    ch.win_time = 0.0
    ch.leave_homing()


# --- one cycle per mode ---------------------------------------------------------------------
def step_csp(ch: Any, cw: int, dt: float) -> None:
    ch.stopping = False
    ch.sw_limited = False
    d = _clamp_limits(ch, ch.target_position + ch.pos_offset) + ch.enc_offset
    ch.dvel = (d - ch.dpos) / dt
    ch.dpos = d
    ch.oms = SW12 | (SW13 if ch.fe_flag else 0)


def step_csv(ch: Any, cw: int, dt: float) -> None:
    ch.stopping = False
    v = float(ch.target_velocity + ch.vel_offset)
    ch.dvel = v
    ch.dpos += v * dt
    ch.oms = SW12


def step_cst(ch: Any, cw: int, dt: float) -> None:
    ch.stopping = False
    t = ch.target_torque + ch.torque_offset
    mt = ch.max_torque
    ch.dtorque = float(mt if t > mt else (-mt if t < -mt else t))
    ch.torque_ctl = True
    ch.oms = SW12


def step_pp(ch: Any, cw: int, dt: float) -> None:
    ch.stopping = False
    cw4 = cw & 0x10
    if cw4 and not ch.prev_cw & 0x10:
        if ch.pp_pending is None:
            base = ch.pp_target if cw & 0x40 else 0
            ch.sw_limited = False
            tgt = _clamp_limits(ch, base + ch.target_position)
            if cw & 0x20 or not ch.pp_moving:
                ch.pp_target = tgt
                ch.pp_moving = True
            else:
                ch.pp_pending = tgt
            ch.sp_ack = True
            ch.win_time = 0.0
    elif not cw4 and ch.sp_ack and ch.pp_pending is None:
        ch.sp_ack = False
    if ch.pp_moving:
        s, v, done = profile_step(
            ch.dpos,
            ch.dvel,
            ch.pp_target + ch.enc_offset,
            float(ch.profile_velocity),
            float(ch.profile_acceleration or 1),
            float(ch.profile_deceleration or 1),
            dt,
        )
        ch.dpos, ch.dvel = s, v
        if done:
            if ch.pp_pending is not None:
                ch.pp_target, ch.pp_pending = ch.pp_pending, None
                if not cw4:
                    ch.sp_ack = False
            else:
                ch.pp_moving = False
    else:
        ch.dvel = 0.0
    reached = False
    if not ch.pp_moving:
        if abs(ch.pp_target + ch.enc_offset - ch.mech.pos) <= ch.position_window:
            ch.win_time += dt
            reached = ch.win_time * 1000.0 >= ch.position_window_time
        else:
            ch.win_time = 0.0
    ch.oms = (SW10 if reached else 0) | (SW12 if ch.sp_ack else 0) | (SW13 if ch.fe_flag else 0)


def step_pv(ch: Any, cw: int, dt: float) -> None:
    ch.stopping = False
    vt = float(ch.target_velocity)
    v = ramp(
        ch.dvel,
        vt,
        float(ch.profile_acceleration or 1),
        float(ch.profile_deceleration or 1),
        dt,
    )
    ch.dvel = v
    ch.dpos += v * dt
    vel = ch.mech.vel
    reached = abs(vt - vel) <= max(10.0, 0.01 * abs(vt))
    zero = abs(vel) <= ch.standstill
    ch.oms = (SW10 if reached else 0) | (SW12 if zero else 0)


def step_pt(ch: Any, cw: int, dt: float) -> None:
    ch.stopping = False
    t = ch.target_torque
    mt = ch.max_torque
    t = mt if t > mt else (-mt if t < -mt else t)
    slope = float(ch.torque_slope or 1)
    ch.torque_ctl = True
    ch.dtorque = ramp(ch.dtorque, float(t), slope, slope, dt)
    ch.oms = SW10 if ch.dtorque == t else 0


def step_hm(ch: Any, cw: int, dt: float) -> None:
    cw4 = cw & 0x10
    if cw4 and not ch.prev_cw & 0x10:
        ch.start_homing()
    h = ch.homing
    if h is None:
        stop_ramp(ch, float(ch.quick_stop_deceleration or 1), dt)
    else:
        if not h.done:
            # CW8 halts; CW4 1 -> 0 interrupts (a new rising edge starts afresh)
            halt = bool(cw & 0x100) or not cw4
            if halt != ch.hm_halt:
                ch.hm_halt = halt
                h.halt(halt)
        ch.stopping = False
        d = h.step(dt, ch.mech.pos)
        ch.dvel = (d - ch.dpos) / dt
        ch.dpos = d
        if h.done and not ch.hm_applied:
            ch.finish_homing()
        ch.hm_bits = hm_bits_of(h.status_bits())
    ch.oms = ch.hm_bits | (SW13 if ch.fe_flag else 0)


def hm_bits_of(bits: tuple[bool, bool, bool]) -> int:
    reached, attained, error = bits
    return (SW10 if reached else 0) | (SW12 if attained else 0) | (SW13 if error else 0)


def step_hold(ch: Any, cw: int, dt: float) -> None:
    """No mode (0) or a mode this drive cannot run: stop and hold position."""
    stop_ramp(ch, float(ch.quick_stop_deceleration or 1), dt)
    ch.oms = SW10 if ch.dvel == 0.0 else 0


HM_NOT_STARTED = SW10  # "homing interrupted or not started" (cia402-facts.md 3.1)

#: one cycle of each mode in OPERATION ENABLED (halt handled by the channel except in HM)
MODE_STEP: dict[int, Callable[[Any, int, float], None]] = {
    OpMode.PROFILE_POSITION: step_pp,
    OpMode.PROFILE_VELOCITY: step_pv,
    OpMode.PROFILE_TORQUE: step_pt,
    OpMode.HOMING: step_hm,
    OpMode.CYCLIC_SYNC_POSITION: step_csp,
    OpMode.CYCLIC_SYNC_VELOCITY: step_csv,
    OpMode.CYCLIC_SYNC_TORQUE: step_cst,
}
