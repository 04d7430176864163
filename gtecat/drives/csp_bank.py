"""Many CiA-402 channels in cyclic synchronous position mode, one numpy row each.

:class:`CspBank` is the array form of what :meth:`gtecat.drives.drive.Channel.step` does in
its commonest state - *operation enabled*, mode 8 (CSP), no halt, no fault, no
touch probe edge on the way, off the limit switches - for every row at once: the CSP demand of
:func:`gtecat.drives.modes.step_csp`, :meth:`gtecat.drives.mechanics.Mechanics.track`, the
following-error window (6065h/6066h), and the process values of ``_outputs`` /
``_refresh_status`` (6041h, 6062h, 6064h, 606Ch, 6074h, 6077h, 6078h, 60F4h, 60FDh).

The scalar :class:`~gtecat.drives.drive.Channel` stays the reference: :meth:`CspBank.load`
takes a channel's state, :meth:`CspBank.store` gives it back exactly (after which the
channel's own step continues as if it had run every cycle itself).  The float
operations are the scalar code's, in the same order, so both give the same bits
(``tests/gtecat/controller/test_bank.py`` compares them through the GT API);
transcendental constants (``exp(-kp·dt)``) are computed with :mod:`math` per row, never
with numpy.

A row whose next step would leave that state (a limit switch input, a following
error timing out) is reported by :meth:`CspBank.step` in its ``events`` mask with its
state untouched, so the owner hands it back to the scalar channel for that cycle.  The
compiled cycle (``gtecat/controller/csrc/bank_kernel.c``) goes one step further: a drive
standing on a limit switch, or braking on it (``Channel._limit_switches``: its demand into
the switch braked with 6085h, ``limit_stop``, 6041h's warning bit instead of bit 12), stays
a row (:func:`claimable` with ``limits``; :attr:`CspBank.lstop` carries ``limit_stop``).
"""

from __future__ import annotations

import math
from array import array
from typing import TYPE_CHECKING

import numpy as np

from .cia402 import COMMAND_OF, STATE_BITS, TRANSITIONS, State, Sw
from .drive import _wrap32 as wrap32  # the channel's own 32-bit wrap of its object values
from .modes import SW12, OpMode

if TYPE_CHECKING:
    from .drive import Channel
    from .faults import FieldOverride

_INT32_MIN, _INT32_MAX = -(1 << 31), (1 << 31) - 1
_SW_BASE = STATE_BITS[State.OPERATION_ENABLED]
_SW_REMOTE = int(Sw.REMOTE)
_SW_INTERNAL_LIMIT = int(Sw.INTERNAL_LIMIT)
#: 6041h of a CSP drive braking on a limit switch (Channel._refresh_status): the warning bit
#: instead of "following the command value" (SW12)
_SW_LIMIT_STOP = int(Sw.WARNING) - SW12
#: Channel._limit_switches' reactions as the compiled cycle numbers them
_LIMIT_REACTIONS = {"none": 0, "stop": 1, "fault": 2}
_HALT = 0x100
#: the controlword of an enabled drive the bank takes (enable operation, nothing else)
CW_ENABLED = 0x000F


def running_reason(
    ch: Channel, mode: OpMode, cw: int, not_in_mode: str, probe: bool = False, limits: bool = False
) -> str:
    """Why ``ch`` is not simply running in ``mode`` under controlword ``cw`` ("" when it
    is): what every kind of bank row (CSP here, homing searches in
    :mod:`gtecat.drives.homing_bank`) requires before its own conditions; ``probe``: a
    touch probe armed is the caller's to judge."""
    if ch.psm.state is not State.OPERATION_ENABLED:
        return "not operation enabled"
    if ch.mode != mode or ch.mode_req != ch.mode:
        return not_in_mode
    if ch.mode_due is not None or ch.mode_seen != ch.mode:
        return "mode change pending"
    if ch.controlword != cw or ch.prev_cw != cw:
        return "controlword"
    if ch.faults.pending or ch.faults.injected or ch.faults.cause_active:
        return "fault"
    if ch.field is not None:
        return "field fault"
    if ch.torque_ctl or ch.stopping or (ch.limit_stop and not limits):
        return "stopping"
    if ch.digital_inputs & 3 and not limits:
        return "on a limit switch"
    if not probe and (ch.tp_function or ch._tp_applied or ch.probe.function):
        return "touch probe"
    return ""


def probe_steady(ch: Channel) -> bool:
    """The channel's touch probe is as its 60B8h asks (off, or armed with nothing about to
    change: the function applied): a CSP row may run with it, between two edges
    (:meth:`TouchProbe.quiet_bounds`)."""
    return ch.tp_function == ch._tp_applied == ch.probe.function


def claimable(ch: Channel, limits: bool = False) -> str:
    """Why ``ch`` cannot be a bank row now ("" when it can); an armed touch probe may run
    (the bank gives the row back before a cycle whose travel reaches one of its edges);
    ``limits``: so may a drive on a limit switch, braking on it or not (the compiled cycle runs
    its reaction, bank_kernel.c)."""
    s = ch._settings
    if not probe_steady(ch):
        return "touch probe being written"
    why = running_reason(
        ch, OpMode.CYCLIC_SYNC_POSITION, CW_ENABLED, "not in CSP", probe=True, limits=limits
    )
    if why:
        return why
    if ch.homing is not None and getattr(ch.homing, "active", False):
        return "homing"
    if s.limit_reaction not in ("stop", "fault", "none"):
        return "limit reaction"
    if ch.fe_flag or ch.fe_time:
        return "following error"
    return ""


#: the values :meth:`CspBank.store` gives back as the 32-bit objects hold them (wrapped)
_WRAPPED = frozenset(
    ("position_actual", "position_demand", "velocity_actual", "following_error_actual")
)

FROZEN_ATTRS = (
    "position_actual",
    "position_demand",
    "velocity_actual",
    "torque_actual",
    "current_actual",
    "torque_demand",
    "following_error_actual",
    "digital_inputs",
    "statusword",
    "mode_display",
    "oms",
    "target_position",
    "fe_flag",
    "stopping",
    "limit_stop",
    "sw_limited",
)
_UNPOWERED_IDLE = frozenset(
    {State.SWITCH_ON_DISABLED, State.READY_TO_SWITCH_ON, State.SWITCHED_ON, State.FAULT}
)


def _inert_at_rest(ff: FieldOverride) -> bool:
    """The field's hands change nothing of an unpowered drive at rest: safe torque off and
    a closed holding brake only take power or motion away, which such a drive has not
    (Channel.step: ``powered`` is already False, the motor stands, ``dpos`` on it); a
    forced input, a lost or noisy encoder, a quick-stop input or a silenced probe do."""
    return not (ff.din_set or ff.din_clear or ff.enc_noise or ff.quick_stop or ff.probe_off)


def frozen_claimable(ch: Channel) -> str:
    """Why ``ch`` is not resting unpowered with nothing to change from cycle to cycle ("" when
    it is): its step would coast a standing motor, take no transition and write the same
    process values, so a bank row may skip it whole (``frz`` rows of the axis bank)."""
    psm = ch.psm
    if psm.state not in _UNPOWERED_IDLE:
        return "powered or starting"
    cw = ch.controlword
    if cw != ch.prev_cw or psm.last_cw != cw:
        return "controlword"
    if psm.state is not State.FAULT and TRANSITIONS.get((psm.state, COMMAND_OF[cw & 0xFF])):
        return "a transition is due"
    if ch.faults.pending or (ch.faults.injected and psm.state is not State.FAULT):
        return "fault"  # (in FAULT a persisting cause only refuses a reset: cw stays as it is)
    if ch.field is not None and not _inert_at_rest(ch.field):
        return "field fault"  # (a switch forced, encoder noise: the values may change)
    if ch.mode_req != ch.mode_seen or ch.mode_due is not None:
        return "mode change pending"
    m = ch.mech
    if m.vel != 0.0 or math.copysign(1.0, m.vel) < 0 or m.acc != 0.0 or m.torque != 0.0:
        return "moving"
    if m.limited or (m.pos == 0.0 and math.copysign(1.0, m.pos) < 0):
        return "moving"
    return standing_reason(ch)


def standing_reason(ch: Channel) -> str:
    """What a channel whose cycle changes nothing needs besides its own state's conditions
    (:func:`frozen_claimable`, :func:`gtecat.drives.homing_bank.idle_claimable`): the
    demand on the motor at rest, no touch probe, 607Ah on 6064h ("" when so)."""
    if ch.dpos != ch.mech.pos or ch.dvel != 0.0:
        return "moving"
    if ch.tp_function or ch._tp_applied or ch.probe.function:
        return "touch probe"
    if ch.target_position != ch.position_actual:
        return "607Ah not yet on 6064h"
    return ""


class CspBank:
    """The rows' state and constants as arrays; ``step`` runs one cycle of all of them."""

    @property
    def cycles(self) -> int:
        """Cycles stepped; a row has stepped cycles - start[r] since its load."""
        return self.counts[0]

    @cycles.setter
    def cycles(self, n: int) -> None:
        self.counts[0] = n

    def __init__(self, channels: list[Channel]) -> None:
        self.channels = list(channels)
        n = len(self.channels)
        self.n = n
        f = np.zeros
        self.pos, self.vel, self.acc, self.torque = f(n), f(n), f(n), f(n)
        self.dpos, self.dvel, self.fe_time = f(n), f(n), f(n)
        self.limited = np.zeros(n, bool)
        self.sw_limited = np.zeros(n, bool)
        #: [0] the cycles stepped (:attr:`cycles`), in memory compiled code adds to (the
        #: controller's quick cycle)
        self.counts = array("q", (0,))
        self.start = np.zeros(n, np.int64)
        self.din = np.zeros(n, np.int64)  # 60FDh of the last cycle
        self.target = np.zeros(n, np.int64)  # 607Ah of the last cycle
        # constants
        self.vmax, self.amax, self.a_rated = f(n), f(n), f(n)
        self.visc, self.e, self.c = f(n), f(n), f(n)
        self.kp, self.kff = f(n), f(n)
        self.off = np.zeros(n, np.int64)  # enc_offset
        self.pos_offset = np.zeros(n, np.int64)
        self.sw_min = np.zeros(n, np.int64)
        self.sw_max = np.zeros(n, np.int64)
        self.fe_window = f(n)
        self.fe_check = np.zeros(n, bool)
        self.fe_timeout = f(n)
        self.nl, self.pl = f(n), f(n)
        self.sw_const = np.zeros(n, np.int64)  # state bits + remote
        #: an armed touch probe: the row leaves before a cycle whose travel reaches tp_lo or
        #: tp_hi, the nearest edges it would latch (TouchProbe.quiet_bounds)
        self.tpw = np.zeros(n, bool)
        self.tp_lo, self.tp_hi = np.full(n, -np.inf), np.full(n, np.inf)
        self.any_tp = False
        #: a row on a limit switch (the compiled cycle only: :func:`claimable` with
        #: ``limits``): the drive's reaction (_LIMIT_REACTIONS: 0 none, 1 the quick-stop brake,
        #: 2 a fault), its 6085h (or 1), and ``limit_stop`` of the last cycle
        self.lreact = np.zeros(n, np.int64)
        self.qsd = f(n)
        self.lstop = np.zeros(n, bool)
        wins: list[tuple[int, int, tuple[tuple[float, float], ...]]] = []
        self.windows: list[tuple[int, np.ndarray, np.ndarray]] = []
        self._dt = 0.0
        self.e, self.c = f(n), f(n)
        self.lim, self.nlim, self.half_lim = f(n), f(n), f(n)
        self.fe_running = self.fe_next = False  # some row's following-error timer runs
        self._din_safe = 0  # cycles in which no row can reach a limit switch
        #: a load changed what :meth:`_flags` looks at (the values of each row's last load)
        self._flags_due = True
        self._row_flags: dict[int, tuple] = {}
        #: the (kp, kff, amax, dt) each row's _prepare_row last computed with
        self._prepared: dict[int, tuple] = {}
        self._din_zero: np.ndarray | None = None
        self.nvmax = f(n)
        for r, ch in enumerate(self.channels):
            self.load(r)
            for bit, win in ((2, ch._hs), (16, ch._p1), (17, ch._p2)):
                if win:
                    wins.append((r, bit, win))
        #: switch windows (home switch 60FDh bit 2, probes bits 16/17) as padded arrays
        for bit in (2, 16, 17):
            mine = [(r, w) for r, b, w in wins if b == bit]
            if not mine:
                continue
            width = max(len(w) for _, w in mine)
            lo = np.full((n, width), np.inf)
            hi = np.full((n, width), -np.inf)
            for r, w in mine:
                for j, (a, b) in enumerate(w):
                    lo[r, j], hi[r, j] = a, b
            self.windows.append((1 << bit, lo, hi))
        self._flags()

    def load(self, r: int, flags: bool = True) -> None:
        """Take row ``r``'s state from its channel (which must be :func:`claimable`);
        ``flags`` False: the caller calls :meth:`_flags` once after loading several rows,
        before the next step or output."""
        ch = self.channels[r]
        m = ch.mech
        if self.din is self._din_zero:  # (the shared zeros of cycles off every switch)
            self.din = self._din_zero.copy()
        self.din[r] = ch.digital_inputs
        self.target[r] = ch.target_position
        self._din_safe = 0
        self.start[r] = self.cycles
        self.pos[r], self.vel[r], self.acc[r], self.torque[r] = m.pos, m.vel, m.acc, m.torque
        self.dpos[r], self.dvel[r] = ch.dpos, ch.dvel
        self.fe_time[r] = ch.fe_time
        self.fe_running = self.fe_running or bool(ch.fe_time)
        self.limited[r] = m.limited
        self.sw_limited[r] = ch.sw_limited
        self.vmax[r], self.amax[r], self.a_rated[r] = m.vmax, m.amax, m.a_rated
        self.nvmax[r] = -self.vmax[r]
        self.visc[r], self.kp[r], self.kff[r] = m.visc, m.kp, m.kff
        if self._dt:
            key = (m.kp, m.kff, m.amax, self._dt)
            if self._prepared.get(r) != key:  # (a drive taken again mostly brings the same)
                self._prepare_row(r, self._dt)
                self._prepared[r] = key
        self.off[r] = ch.enc_offset
        self.pos_offset[r] = ch.pos_offset
        lo, hi = ch.sw_limit_min, ch.sw_limit_max
        self.sw_min[r], self.sw_max[r] = (lo, hi) if lo < hi else (_INT32_MIN * 4, _INT32_MAX * 4)
        w = ch.following_error_window
        self.fe_check[r] = 0 < w < 0xFFFFFFFF
        self.fe_window[r] = w
        self.fe_timeout[r] = ch.following_error_timeout
        self.nl[r], self.pl[r] = ch._nl, ch._pl
        self.sw_const[r] = _SW_BASE | SW12 | (_SW_REMOTE if ch._settings.remote else 0)
        self.lreact[r] = _LIMIT_REACTIONS[ch._settings.limit_reaction]
        self.qsd[r] = float(ch.quick_stop_deceleration or 1)
        self.lstop[r] = ch.limit_stop
        probe = ch.probe
        on = bool(probe.function & 0x0101)
        self.tpw[r] = on
        self.tp_lo[r], self.tp_hi[r] = probe.quiet_bounds(m.pos) if on else (-np.inf, np.inf)
        self._flags_key(r, ch)
        if flags:
            self._flags()

    def _flags_key(self, r: int, ch: Channel) -> None:
        """What :meth:`_flags` looks at of row ``r`` (channel ``ch``): looked at again only
        when it changed (a drive given back and taken again mostly brings the same)."""
        key = (
            ch.pos_offset,
            ch.enc_offset,
            ch.sw_limit_min,
            ch.sw_limit_max,
            ch.following_error_window,
            bool(ch.probe.function & 0x0101),
        )
        if self._row_flags.get(r) != key:
            self._row_flags[r] = key
            self._flags_due = True

    def took_homing(self, r: int) -> None:
        """Row ``r``'s channel, standing in homing mode before a homing (:meth:`rested` up to
        now), started a homing that ended as it began (gtecat.controller.bank_home_start):
        what :meth:`load` takes of it that the start changed - the decoded 607Ah, the demand
        put where the motor stands, the encoder offset of the result; :meth:`after_loads`
        follows."""
        ch = self.channels[r]
        self.target[r] = ch.target_position
        self.dpos[r], self.dvel[r] = ch.dpos, ch.dvel
        self.off[r] = ch.enc_offset
        self._flags_key(r, ch)

    def row_changed(self, r: int) -> None:
        """Row ``r``'s values that :meth:`_flags` reads were changed outside :meth:`load`
        (its touch probe armed in the bank): its next load looks at them again."""
        self._row_flags.pop(r, None)

    def after_loads(self) -> None:
        """:meth:`_flags` after loads with ``flags`` False, when one changed what it looks at
        (the values it reads change only at a load)."""
        if self._flags_due:
            self._flags()

    def _prepare(self, dt: float) -> None:
        """``Mechanics._prepare`` per row, with math.exp (numpy's exp may differ by an ulp)."""
        self._dt = dt
        self._din_safe = 0
        self._prepared.clear()
        for r in range(len(self.channels)):
            self._prepare_row(r, dt)

    def _prepare_row(self, r: int, dt: float) -> None:
        kp, kff = float(self.kp[r]), float(self.kff[r])
        e = math.exp(-kp * dt)
        self.e[r] = e
        self.c[r] = (1.0 - kff) * (1.0 - e) / kp
        self.lim[r] = self.amax[r] * dt
        self.nlim[r] = -self.lim[r]
        self.half_lim[r] = 0.5 * self.lim[r]

    def _flags(self) -> None:
        """Which optional parts of the cycle any row needs (skipped when none does)."""
        self._flags_due = False
        self.any_pos_offset = bool(np.count_nonzero(self.pos_offset))
        self.any_off = bool(np.count_nonzero(self.off))
        # 607Ah is an int32: limits at (or beyond) the int32 range never clamp it
        self.any_sw = self.any_pos_offset or bool(
            np.count_nonzero(self.sw_min > _INT32_MIN) or np.count_nonzero(self.sw_max < _INT32_MAX)
        )
        self.no_windows = not self.windows
        self._din_zero = np.zeros(self.n, np.int64)
        self.any_fe = bool(np.count_nonzero(self.fe_check))
        self.any_tp = bool(np.count_nonzero(self.tpw))
        self.nvmax = -self.vmax

    # --- one cycle -------------------------------------------------------------------------
    def step(self, target: np.ndarray, dt: float) -> tuple[dict[str, np.ndarray], np.ndarray]:
        """One cycle of every row with 607Ah = ``target`` (int64, already int32-wrapped).

        Returns the tentative state (:meth:`commit` makes it the rows' state) and the mask
        of rows that must leave the bank *before* this cycle (its following error timing
        out, its travel reaching an edge its touch probe latches), or None.  The owner must
        also let rows whose 60FDh has a limit bit leave (the drive's own reaction runs on
        the next cycle).
        """
        if dt != self._dt:
            self._prepare(dt)
        self._din_safe -= 1
        # --- step_csp: clamp to 607Dh, enc_offset, demand velocity
        x = target + self.pos_offset if self.any_pos_offset else target
        if self.any_sw:
            sw_lim = (x < self.sw_min) | (x > self.sw_max)
            x = np.minimum(np.maximum(x, self.sw_min), self.sw_max)
        else:
            sw_lim = np.zeros(self.n, bool)
        if self.any_off:
            x = x + self.off
        demand = x.astype(np.float64)
        dvel = (demand - self.dpos) / dt
        # --- Mechanics.track(demand, dvel, dt), operation for operation
        p, v0, vmax = self.pos, self.vel, self.vmax
        vff = np.minimum(np.maximum(dvel, self.nvmax), vmax)
        e1 = (demand - vff * dt - p) * self.e + self.c * vff
        v = (demand - e1 - p) / dt
        lim = self.lim
        dist = demand - p
        rel = dist - vff * dt
        # the closing-speed cap: vstop >= min(|rel|/dt, lim) (m = 0: vstop = |rel|/dt;
        # m >= 1: vstop >= m*lim), so rows within half of that of vff cannot be capped
        # (the half keeps the shortcut clear of every rounding at the boundary)
        gap = v - vff
        arel = np.abs(rel)
        if np.count_nonzero(np.abs(gap) > np.minimum(arel * (0.5 / dt), self.half_lim)):
            vstop = closing_speed(arel, lim, dt)
            hi = vff + vstop
            c1 = (rel > 0.0) & (v > hi)
            np.copyto(v, hi, where=c1)
            lo = vff - vstop
            c2 = (rel < 0.0) & (v < lo)
            np.copyto(v, lo, where=c2)
            limited = c1 | c2
        else:
            limited = np.zeros(self.n, bool)
        dv = v - v0
        if np.count_nonzero(np.abs(dv) > lim):
            up, down = dv > lim, dv < self.nlim
            np.copyto(v, v0 + lim, where=up)
            np.copyto(v, v0 - lim, where=down)
            limited = limited | up | down
        limited_any = bool(np.count_nonzero(limited))
        if limited_any:
            fwd = (rel > 0.0) & (dist > 0.0) & (v * dt > dist)
            land = limited & (fwd | ((rel < 0.0) & (dist < 0.0) & (v * dt < dist)))
            np.copyto(v, dist / dt, where=land)
        if np.count_nonzero(np.abs(v) > vmax):
            over, under = v > vmax, v < self.nvmax
            np.copyto(v, vmax, where=over)
            np.copyto(v, self.nvmax, where=under)
            limited = limited | over | under
            limited_any = True
        a = (v - v0) / dt
        pos = p + v * dt
        # --- following error window (6065h/6066h); a row timing out leaves the bank first
        events = None
        fe_time = self.fe_time
        if self.any_fe:
            fe_out = np.abs(demand - pos) > self.fe_window
            if self.fe_running or np.count_nonzero(fe_out & self.fe_check):
                fe_out &= self.fe_check
                fe_time = np.where(fe_out, fe_time + dt, 0.0)
                events = fe_out & (fe_time * 1000.0 > self.fe_timeout)
                self.fe_next = bool(np.count_nonzero(fe_time))
            else:
                self.fe_next = False
        #: this cycle's rows whose travel reaches an edge the touch probe would latch (None:
        #: none looked at), and the following-error events (their owner tells them apart)
        self.tp_edge = None
        self.fe_event = events
        if self.any_tp:  # a travel reaching an edge the touch probe would latch
            moved = self.tpw & (pos != p)
            if np.count_nonzero(moved):
                lo, hi = np.minimum(p, pos), np.maximum(p, pos)
                edge = self.tp_edge = moved & ~((self.tp_lo < lo) & (hi < self.tp_hi))
                events = edge if events is None else events | edge
        state = {
            "pos": pos,
            "vel": v,
            "acc": a,
            "dpos": demand,
            "dvel": dvel,
            "fe_time": fe_time,
            "limited": limited,
            "sw_limited": sw_lim,
            "target": target,
        }
        self.limited_any = limited_any  # of this tentative state (statusword bit 11)
        return state, events

    def commit(
        self, state: dict[str, np.ndarray], din: np.ndarray, keep: np.ndarray | None
    ) -> None:
        """Make ``state`` (whose 60FDh is ``din``) the state of the rows in ``keep`` (None: all)."""
        self.fe_running = self.fe_next
        if keep is None:
            self.lstop[:] = False  # (a row braking on a limit leaves before a numpy cycle)
            for name, value in state.items():
                setattr(self, name, value)
            self.cycles += 1
            self.din = din
        else:
            self.lstop[keep] = False
            for name, value in state.items():
                getattr(self, name)[keep] = value[keep]
            self.cycles += 1
            self.start[~keep] += 1  # the rows left out did not step
            if self.din is self._din_zero:
                self.din = self._din_zero.copy()
            self.din[keep] = din[keep]

    def output(self, name: str, state: dict[str, np.ndarray] | None = None) -> np.ndarray:
        """One process value of ``Channel._outputs`` / ``_refresh_status`` for every row (int64,
        not yet wrapped to 32 bits), of the committed state or of a tentative ``state``."""
        g = state.__getitem__ if state is not None else self.__getattribute__
        if name == "position_actual":
            x = g("pos") - self.off if self.any_off else g("pos")
            return np.rint(x).astype(np.int64)
        if name == "digital_inputs":
            pos = g("pos")
            if self.no_windows and self._din_safe > 0:
                return self._din_zero  # no row can have reached a switch yet (see below)
            near = (pos >= self.pl) | (pos <= self.nl)
            if self.no_windows and not np.count_nonzero(near):
                # off every switch (shared array: never written into); no row moves more
                # than vmax*dt a cycle, so none can reach one for the next few cycles
                gap = min(float((self.pl - pos).min()), float((pos - self.nl).min()))
                step = float(self.vmax.max()) * self._dt
                cycles = gap / step - 2.0 if step > 0.0 else 1e9
                self._din_safe = int(min(cycles, 1e9)) if cycles > 0.0 else 0
                return self._din_zero
            din = 2 * (pos >= self.pl) + (pos <= self.nl)
            for value, lo, hi in self.windows:
                x = pos[:, None]
                din = din | (((lo <= x) & (x < hi)).any(axis=1) * value)
            return din
        if name == "statusword":
            if state is not None and not self.limited_any and not self.any_sw:
                return self.sw_const  # no row limited (so no 6041h bit 11)
            stop = self.lstop if state is None else None  # (numpy's own cycles: none)
            lim = g("limited") | g("sw_limited")
            if stop is not None and np.count_nonzero(stop):
                lim = lim | stop
                return self.sw_const + lim * _SW_INTERNAL_LIMIT + stop * _SW_LIMIT_STOP
            if not np.count_nonzero(lim):
                return self.sw_const
            return self.sw_const + lim * _SW_INTERNAL_LIMIT
        if name == "position_demand":
            return np.rint(g("dpos") - self.off).astype(np.int64)
        if name == "velocity_actual":
            return np.rint(g("vel")).astype(np.int64)
        if name == "following_error_actual":
            return np.rint(g("dpos") - g("pos")).astype(np.int64)
        if name in ("torque_actual", "current_actual", "torque_demand"):
            torque = g("acc") / self.a_rated * 1000.0 + g("vel") * self.visc
            return np.minimum(np.maximum(np.rint(torque), -32768), 32767).astype(np.int64)
        raise KeyError(name)

    # --- hand back ---------------------------------------------------------------------------
    def store(self, rows: list[int] | None = None) -> None:
        """Give rows back to their channels, exactly as if each channel had stepped itself."""
        names = (
            "position_actual",
            "position_demand",
            "velocity_actual",
            "torque_actual",
            "current_actual",
            "torque_demand",
            "following_error_actual",
            "digital_inputs",
            "statusword",
        )
        # a few rows (a drive given back, up to a 4-axis one): each in plain floats, a tenth
        # of the numpy calls' cost per row (None: a row numpy must give, below), its values
        # (Python ints) set straight from its own dict
        ones = [self._one_row(r) for r in rows] if rows is not None and len(rows) <= 4 else None
        per_row: dict[int, dict[str, int]] | None = None
        out: dict[str, np.ndarray] = {}
        at: list[int] = []
        if ones is not None and None not in ones:
            per_row = dict(zip(rows, ones, strict=True))  # type: ignore[arg-type]
        elif rows is None or 4 * len(rows) >= self.n:
            out = {name: self.output(name) for name in names}
            at = list(range(self.n))
        else:  # a few rows (one slave given back): their values alone, the same operations
            out = self._row_outputs(np.asarray(rows, np.intp))
            at = [0] * self.n
            for k, r in enumerate(rows):
                at[r] = k
        wrapped = _WRAPPED
        for r in range(len(self.channels)) if rows is None else rows:
            ch = self.store_state(r)
            if per_row is not None:
                for name, x in per_row[r].items():
                    setattr(ch, name, wrap32(x) if name in wrapped else x)
            else:
                k = at[r]
                for name, values in out.items():
                    x = int(values[k])
                    setattr(ch, name, wrap32(x) if name in wrapped else x)
            ch.mode_display = ch.mode

    def store_state(self, r: int) -> Channel:
        """Row ``r``'s state into its channel as :meth:`store` gives it back, but its process
        values (6064h, 60FDh, 6041h...): for a caller whose next step on the channel makes
        them again from that state (``Channel._outputs``: a drive switching its mode on its
        row, gtecat.controller.bank_home_rows).  Returns the channel."""
        ch = self.channels[r]
        m = ch.mech
        a, v = float(self.acc[r]), float(self.vel[r])
        m.pos, m.vel, m.acc = float(self.pos[r]), v, a
        m.torque = a / m.a_rated * 1000.0 + v * m.visc
        m.limited = bool(self.limited[r])
        ch.dpos, ch.dvel = float(self.dpos[r]), float(self.dvel[r])
        ch.fe_time = float(self.fe_time[r])
        ch.fe_flag = False
        ch.sw_limited = bool(self.sw_limited[r])
        ch.stopping = False
        ch.limit_stop = bool(self.lstop[r])
        ch.oms = SW12
        ch.cycle += self.cycles - int(self.start[r])
        self.start[r] = self.cycles
        ch.target_position = int(self.target[r])
        return ch

    def rested(self, r: int) -> None:
        """Give row ``r`` back after cycles the bank skipped whole (a frozen row: its channel
        rests unpowered, :func:`frozen_claimable`, or stands in homing mode before a homing,
        :func:`gtecat.drives.homing_bank.idle_claimable`): each of those steps would have
        left every value of the channel as it is, and nothing touched the channel meanwhile
        (the bank's guard gives a row back first), so its objects hold them already; only
        its count of cycles moves on."""
        self.channels[r].cycle += self.cycles - int(self.start[r])
        self.start[r] = self.cycles

    def _one_row(self, r: int) -> dict[str, int] | None:
        """:meth:`_row_outputs` of row ``r`` alone in Python floats: the same IEEE operations
        in the same order (``round`` of a float rounds half to even, as ``np.rint``; an int64
        offset becomes the same double numpy subtracts), a tenth of the numpy calls' cost;
        None where numpy's integer conversion differs from Python's (a value that is not a
        number or beyond 2**62), which :meth:`_row_outputs` then gives."""
        pos, dpos = float(self.pos[r]), float(self.dpos[r])
        vel, acc = float(self.vel[r]), float(self.acc[r])
        off = float(self.off[r]) if self.any_off else 0.0
        x = pos - off if self.any_off else pos
        torque = acc / float(self.a_rated[r]) * 1000.0 + vel * float(self.visc[r])
        dem = dpos - float(self.off[r])
        fe = dpos - pos
        big = 4611686018427387904.0  # 2**62
        if not (abs(x) < big and abs(dem) < big and abs(vel) < big and abs(fe) < big):
            return None
        if not abs(torque) < big:
            return None
        din = 2 * (pos >= float(self.pl[r])) + (pos <= float(self.nl[r]))
        for value, lo, hi in self.windows:
            if any(a <= pos < b for a, b in zip(lo[r].tolist(), hi[r].tolist(), strict=True)):
                din |= value
        t = min(max(round(torque), -32768), 32767)
        stop = bool(self.lstop[r])
        lim = bool(self.limited[r]) or bool(self.sw_limited[r]) or stop
        return {
            "position_actual": round(x),
            "position_demand": round(dem),
            "velocity_actual": round(vel),
            "torque_actual": t,
            "current_actual": t,
            "torque_demand": t,
            "following_error_actual": round(fe),
            "digital_inputs": din,
            "statusword": int(self.sw_const[r])
            + (_SW_INTERNAL_LIMIT if lim else 0)
            + (_SW_LIMIT_STOP if stop else 0),
        }

    def _row_outputs(self, idx: np.ndarray) -> dict[str, np.ndarray]:
        """:meth:`output` of the committed state for the rows ``idx`` only (in that order):
        element by element the same operations."""
        pos, dpos, vel, acc = self.pos[idx], self.dpos[idx], self.vel[idx], self.acc[idx]
        off = self.off[idx]
        x = pos - off if self.any_off else pos
        din = 2 * (pos >= self.pl[idx]) + (pos <= self.nl[idx])
        for value, lo, hi in self.windows:
            p = pos[:, None]
            din = din | (((lo[idx] <= p) & (p < hi[idx])).any(axis=1) * value)
        stop = self.lstop[idx]
        lim = self.limited[idx] | self.sw_limited[idx] | stop
        torque = acc / self.a_rated[idx] * 1000.0 + vel * self.visc[idx]
        t = np.minimum(np.maximum(np.rint(torque), -32768), 32767).astype(np.int64)
        return {
            "position_actual": np.rint(x).astype(np.int64),
            "position_demand": np.rint(dpos - off).astype(np.int64),
            "velocity_actual": np.rint(vel).astype(np.int64),
            "torque_actual": t,
            "current_actual": t,
            "torque_demand": t,
            "following_error_actual": np.rint(dpos - pos).astype(np.int64),
            "digital_inputs": din,
            "statusword": self.sw_const[idx] + lim * _SW_INTERNAL_LIMIT + stop * _SW_LIMIT_STOP,
        }


def closing_speed(dist: np.ndarray, lim: np.ndarray, dt: float) -> np.ndarray:
    """:func:`gtecat.drives.mechanics._closing_speed` for every row (same operations and order)."""
    ok = (dist > 0.0) & (lim > 0.0)
    out = np.zeros_like(dist)
    if not ok.any():
        return out
    idx = np.nonzero(ok)[0]
    dd = dist[idx] / dt
    lm = lim[idx]
    half = 0.5 * lm
    m = np.floor_divide(np.sqrt(half * half + 2.0 * lm * dd) - half, lm)
    res = np.full(len(idx), np.nan)
    open_ = np.ones(len(idx), bool)
    v = dd
    for _ in range(8):
        v = np.where(open_, (dd + lm * m * (m + 1.0) / 2.0) / (m + 1.0), v)
        dec = open_ & (v < m * lm) & (m > 0.0)
        inc = open_ & ~dec & (v >= (m + 1.0) * lm)
        hit = open_ & ~dec & ~inc
        res = np.where(hit, v, res)
        open_ = open_ & ~hit
        m = m - dec + inc
        if not open_.any():
            break
    res = np.where(open_, np.minimum(v, dd), res)
    out[idx] = res
    return out
