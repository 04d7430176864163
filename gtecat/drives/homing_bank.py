"""Drive homing (6060h = 6) as bank rows: when a channel's search can run without its Python.

Between two events a homing search (:class:`gtecat.drives.homing.Homing`, phases SEARCH,
APPROACH and INDEX) is a plain ramp to a constant speed: ``_scan`` finds nothing, the
phase and direction stay, and only the search bounds (travel, time, one revolution in
INDEX) can end it.  The axis bank's compiled cycle runs exactly that per row
(``homing_row`` in ``gtecat/controller/csrc/bank_kernel.c``, the same operations in the
same order as :meth:`Homing.step` and :func:`gtecat.drives.modes.step_hm`); a row leaves
the bank, before the cycle, whenever its travel since the last step touches one of the
positions where ``_scan`` could find something, or a bound would be reached.  The scalar
channel then runs that cycle (edges, reversals, the home point, RETURN, errors) and the
bank may take the row again once the search is plain again.

A drive on a limit switch is such a row too: in homing mode it ignores its limit inputs
(the search meets a switch as an event), so only the controller's limit flag, latched in
GT_GetSts, sees the switch; the bank keeps the row while that flag is latched.

After the procedure (completed, failed or interrupted) a drive left in homing mode brakes
to rest and stays: :meth:`Homing.step` scans nothing and counts no search time or travel,
the demand ramps to speed 0 and stands, only the rest time and the settled flag change.  Such
a channel is a row too (:func:`homing_rest_claimable`, the kernel's ``h_done``), which leaves
before a cycle that changes the settled flag (the statusword's SW10 and the homing's result
follow it): an application that homes and never switches back to CSP keeps its axes in the
bank, a failed search's braking included.  The move back onto a home point found (RETURN)
is such a row too, until it settles there.

Before its homing a drive switched to homing mode stands: with no procedure started
(``homing`` None) :func:`gtecat.drives.modes.step_hm` only holds the demand where the motor
stands, so its cycle changes nothing.  Such a channel is a row whose cycle the compiled
kernel skips, as a switched-off drive's (the bank's ``frz`` rows, here with the servo on:
:func:`idle_claimable`); a GT call on its axis (GT_StartEcatHoming raising CW4 among
them) gives it back before anything of it changes.  An application that switches many
axes to homing mode one after the other, then starts them, no longer steps every switched
axis in Python while each next one waits for its 6061h.

This module says when a channel may be such a row (:func:`homing_claimable`,
:func:`homing_rest_claimable`, :func:`idle_claimable`), where the nearest events lie
(:func:`event_bounds`), and moves the search state between the :class:`Homing` object and
a row (:data:`ROW_FIELDS`).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from .cia402 import State
from .csp_bank import CW_ENABLED, running_reason, standing_reason
from .homing import HomingPhase
from .homing_methods import Signal
from .modes import OpMode

if TYPE_CHECKING:
    from .drive import Channel
    from .homing import Homing

#: the controlword of a drive homing (enable operation + CW4 "homing operation start")
CW_HOMING = 0x001F
#: the controlwords of a drive resting in homing mode (CW4 still high, or dropped)
CW_RESTING = (0x000F, CW_HOMING)
_SEARCHING = (HomingPhase.SEARCH, HomingPhase.APPROACH, HomingPhase.INDEX)
_ENDED = (HomingPhase.COMPLETED, HomingPhase.FAILED, HomingPhase.INTERRUPTED)
#: (row array, Homing attribute): the search state that changes every cycle
ROW_FIELDS = (
    ("h_last", "_last"),
    ("h_el", "_elapsed"),
    ("h_tr", "_travel"),
    ("h_v", "_v"),
    ("h_p", "_p"),
    ("h_rest", "_rest_time"),
)


def homing_claimable(ch: Channel) -> str:
    """Why ``ch`` cannot run its homing search as a bank row now ("" when it can)."""
    why = running_reason(ch, OpMode.HOMING, CW_HOMING, "not in homing mode", limits=True)
    if why:
        return why
    if ch.fe_flag or ch.fe_time:
        return "following error"
    h = ch.homing
    if h is None or ch.hm_halt or ch.hm_bits or ch.hm_applied or ch.oms:
        return "no search running"
    if h.phase not in _SEARCHING or h._stopping or h.error or h.attained:
        return "not searching"
    if h.forced or h._edge_sampled:
        return "a switch forced by the field"  # (its edges are sampled: Homing._scan)
    if event_bounds(h, ch.mech.pos) is None:
        return "at an event"
    return ""


def ended(h: Homing) -> bool:
    """The procedure is over (completed, failed or interrupted): :meth:`Homing.step` scans
    nothing and counts no search time or travel, the demand ramps to speed 0 at 609Ah and
    stands; only the rest time and the settled flag change.  A row gives itself back before
    a cycle that would change that flag (SW10, the drive's ``finish_homing`` and the
    controller's homing status follow it), so braking after a failure and settling run in
    the bank too."""
    return h.phase in _ENDED and (h._stopping or h.phase is not HomingPhase.INTERRUPTED)


def returning(h: Homing) -> bool:
    """The home point is found and the drive moves back onto it (RETURN, not halted): no
    scan, no search bound, a positioning move (``_toward``) until it settles there, when the
    phase becomes COMPLETED (the kernel's row gives itself back before that cycle)."""
    return h.phase is HomingPhase.RETURN and not h._stopping and h.home_machine_position is not None


def row_kind(h: Homing) -> int:
    """The kernel's ``h_done`` of a row: 0 searching, 1 ended (:func:`ended`), 2 moving back
    onto the home point (:func:`returning`)."""
    return 1 if ended(h) else 2 if returning(h) else 0


def homing_rest_claimable(ch: Channel) -> str:
    """Why ``ch`` cannot run as a row past its search now ("" when it can): in homing mode,
    returning onto its home point (:func:`returning`) or its procedure over (:func:`ended`),
    its result applied as far as it is done."""
    cw = ch.controlword
    if cw not in CW_RESTING:
        return "controlword"
    why = running_reason(ch, OpMode.HOMING, cw, "not in homing mode", limits=True)
    if why:
        return why
    if ch.fe_flag or ch.fe_time:
        return "following error"
    h = ch.homing
    if h is None or not (ended(h) or returning(h)) or ch.hm_applied != h.done:
        return "not after a homing"
    if ch.oms != ch.hm_bits:
        return "statusword bits"
    return ""


def idle_claimable(ch: Channel) -> str:
    """Why ``ch`` is not standing in homing mode before a homing ("" when it is): operation
    enabled, mode 6 shown, no procedure (``homing`` None), controlword "enable operation"
    with CW4 low as in the cycles before, nothing pending, and the state its step keeps
    (:func:`gtecat.drives.modes.step_hm`: ``stop_ramp`` at speed 0, the motor tracking a
    demand it stands on, no following error), so that its cycle changes nothing and a bank
    row may skip it whole (the bank's ``frz`` rows with the servo on)."""
    psm = ch.psm
    if psm.state is not State.OPERATION_ENABLED:
        return "not operation enabled"
    if ch.mode != OpMode.HOMING or ch.mode_req != ch.mode or ch.mode_display != ch.mode:
        return "not in homing mode"
    if ch.mode_due is not None or ch.mode_seen != ch.mode:
        return "mode change pending"
    if ch.homing is not None:
        return "a homing"
    cw = ch.controlword
    if cw != CW_ENABLED or ch.prev_cw != cw or psm.last_cw != cw:
        return "controlword"
    if ch.faults.pending or ch.faults.injected or ch.faults.cause_active:
        return "fault"
    if ch.field is not None:
        return "field fault"
    # stop_ramp holds dvel at +0.0 and dpos where it is (stopping already set)
    if not ch.stopping or ch.torque_ctl or ch.limit_stop:
        return "not holding"
    if ch.fe_flag or ch.fe_time or ch.oms != ch.hm_bits:
        return "following error"
    m = ch.mech
    # Mechanics.track onto the demand it stands on gives +0.0 speed, acceleration and
    # torque and leaves the position: the values must be those already
    for x in (m.vel, m.acc, m.torque, ch.dvel, m.pos, ch.dpos):
        if x == 0.0 and math.copysign(1.0, x) < 0:
            return "moving"
    if m.vel != 0.0 or m.acc != 0.0 or m.torque != 0.0 or m.limited:
        return "moving"
    return standing_reason(ch)


def rest_constants(h: Homing) -> dict[str, float]:
    """An ended row's constants: the speed target 0 of an ended procedure (``_move``), no
    search bounds (the kernel checks none for ``h_done`` rows)."""
    return {
        "h_vt": 0.0,
        "h_acc": h._acc,
        "h_maxtr": math.inf,
        "h_tmo": math.inf,
        "h_idx": 0.0,
        "h_fd": 0.0,
        "h_from": 0.0,
        "h_ilim": math.inf,
    }


def return_constants(h: Homing) -> dict[str, float]:
    """A returning row's constants: ``_toward``'s top speed 6099h:01 in ``h_vt`` and the home
    point in ``h_from``; no search bounds."""
    home = h.home_machine_position
    assert home is not None
    return {**rest_constants(h), "h_vt": float(h.params.speed_switch), "h_from": home}


def event_bounds(h: Homing, pos: float) -> tuple[float, float] | None:
    """The nearest positions below and above the travel ``[h._last, pos]`` at which
    ``Homing._scan`` could meet an event (±inf: none), or None when one lies on it.

    Every event ``_scan`` reports lies inside the closed travel of its step, so a row whose
    travel stays strictly between the two bounds meets none."""
    spec, m = h._spec, h._m
    a, b = min(h._last, pos), max(h._last, pos)
    xs: list[float] = []
    if spec.signal is Signal.HOME_SWITCH:
        for lo, hi in h._hs:
            xs += (lo, hi)
    for lim in (m.negative_limit, m.positive_limit):
        if lim is not None:
            xs.append(float(lim))
    if spec.uses_index and m.index_offset is not None and m.counts_per_rev > 0:
        cpr = float(m.counts_per_rev)
        xs += m.index_positions(a - 2.0 * cpr, b + 2.0 * cpr)
    if any(a <= x <= b for x in xs) or not (math.isfinite(a) and math.isfinite(b)):
        return None
    lo = max((x for x in xs if x < a), default=-math.inf)
    hi = min((x for x in xs if x > b), default=math.inf)
    return lo, hi


def row_constants(h: Homing) -> dict[str, float]:
    """The row's constants while it searches (they change only at an event)."""
    phase = h.phase
    speed = h.params.speed_switch if phase is HomingPhase.SEARCH else h.params.speed_zero
    fd = h._spec.final_dir
    return {
        "h_vt": h._dir * float(speed),  # Homing._move's v_target, the same operation
        "h_acc": h._acc,
        "h_maxtr": h._max_travel,
        "h_tmo": float(h.params.timeout_s),
        "h_idx": float(phase is HomingPhase.INDEX),
        "h_fd": float(fd),
        "h_from": h._index_from,
        "h_ilim": float(h._m.counts_per_rev + 0.5),
    }
