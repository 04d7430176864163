"""GT_StartEcatHoming of a drive standing in homing mode, when its homing ends at once.

A claimed row frozen in homing mode before a homing (:func:`gtecat.drives.homing_bank.
idle_claimable`: its objects hold its state, the compiled cycle skips it) whose axis raises
CW4 with method 35 or 37 in 6098h (the current position is home, CiA 402 / ETG.6010 homing
methods 35 and 37) runs, on the scalar path, one cycle in which everything happens: the axis's
pre step sends the controlword, the drive takes it, sees CW4 rise, makes its homing procedure
(which is complete as it is made: ``Homing`` with ``MethodKind.CURRENT_POSITION``), steps it
(at rest: the demand where the motor stands), applies its result (6064h redefined so that it
reads 607Ch) and shows SW10 and SW12; the axis's post step follows the drive (its positions
jump with 6064h) and the GT layer's follower ends the run as homed.

That cycle splits into an instant part - what CW4's rising edge does before the drive's
motion step: the controlword sent and decoded, the state machine's look at it, ``start_homing``,
the result applied (``finish_homing``: it only needs the procedure done, which it is from the
start) and the homing bits, ``prev_cw`` - and the rest, which is the cycle of a drive resting in
homing mode after its homing: the procedure's step at rest, the motor tracking its demand, the
process values, the axis following 6064h.  The bank runs the instant part on the row's objects
as the cycle begins (they hold the row's state: it was frozen), then takes the row from them
as the ended homing it now is (:meth:`AxisBank._load`, ``h_done`` 1) and the compiled cycle
runs the rest with the other rows; the GT follower's end is what its post step makes of the
drive's homing bits (:meth:`_AxisHoming.answered_with`).  No step of the axis or the drive runs
in Python, and the row is neither opened nor given back for the call.  Where the bank would not
take the row (:meth:`AxisBank._eligible`) it goes back with its objects as they stand, and the
scalar path runs the rest of the cycle on them: a drive step with CW4 already high is exactly
that rest (no rising edge, the procedure done and applied).

Anything else - another method, a procedure that searches, a row that is not frozen, a touch
probe, the drive's outputs written meanwhile, per-cycle hooks, the realtime clock (whose cycle
thread runs while the call waits) - opens the row for the call (:meth:`AxisBank.call_opened`).
``tests/gtecat/controller/test_bank_home_start.py`` holds it to the scalar path.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from gtecat.drives.homing_methods import MethodKind, method_spec
from gtecat.drives.modes import hm_bits_of
from gtecat.drives.slave import AlState

from ..master.clock import ClockMode
from .axis import ECAT_HOMING
from .bank_home_rows import exchange_buffers
from .epoch import EPOCH

if TYPE_CHECKING:
    from .bank import AxisBank, _Group

_get, _set = object.__getattribute__, object.__setattr__

_CW_ENABLED = 0x000F
_CW_START = 0x001F  # enable operation with CW4 (homing operation start)


def _startable(bank: AxisBank, r: int, g: _Group) -> Any:
    """The GT follower of claimed frozen row ``r`` (group ``g``) whose call raised CW4 with a
    homing that ends at once, when the start's instant part may run on the row (module
    docstring); None when it may not.  (What a frozen claim took - the drive standing in
    homing mode at rest, nothing pending: ``idle_claimable``, the axis following it - holds
    still: nothing but the call touched the objects since, and the call raised CW4 and began
    the run.  A new global reason - a recorder - makes the cycle look at every row next.)"""
    if bank.ctl.clock.mode is ClockMode.REALTIME or not bank.frz[r] or bank.frz_off[r]:
        return None
    if r in bank._aware or r in bank._post_next or r in bank._tp_apply or bank.sampled[r]:
        return None
    ax = bank.axes[r]
    if _get(ax, "cw") != _CW_START or _get(ax, "_cw_sent") != _CW_ENABLED:
        return None
    if _get(ax, "_cw_acc") is None or g.drive.al_state != AlState.OP:
        return None
    st = ECAT_HOMING.get(ax)  # (the GT follower, made with the parameters' call)
    if st is None:
        return None
    if not st.active or st.answered:
        return None
    ch = bank.csp.channels[r]
    if ch.tp_function or ch._tp_applied or _get(ch, "probe").function:
        return None
    # methods 35 and 37: the procedure is complete as it is made (HomingParams.validate
    # asks nothing more of them)
    spec = method_spec(int(ch.homing_method))
    if spec is None or spec.kind is not MethodKind.CURRENT_POSITION:
        return None
    # the drive takes in the exchange what its last one took, the controlword aside
    if not (bank._outputs_kept(bank.group_of[r]) and bank._decoded(g)):
        return None
    return st


def start_at_once(bank: AxisBank, r: int) -> bool:
    """A cycle begins while GT_StartEcatHoming runs on frozen row ``r`` (its objects without
    their guards, :meth:`AxisBank.call_opened`): the start's instant part run on the row's
    objects and the row taken as the ended homing it becomes (module docstring); True when
    it was, False when the row does not qualify (nothing changed: the caller opens it)."""
    g = bank.groups[bank.group_of[r]]
    st = _startable(bank, r, g)
    if st is None:
        return False
    bank._frozen_call = -1
    bank._stale = bank._frozen_stale
    bank._home_started = r
    EPOCH.n += 1
    csp = bank.csp
    ax, ch = bank.axes[r], csp.channels[r]
    csp.rested(r)  # (its drive's count of the cycles it stood)
    # the axis's pre step: the controlword goes out (607Ah holds 6064h already: frozen)
    _get(ax, "_cw_acc").set(_CW_START)
    _set(ax, "_cw_sent", _CW_START)
    bank._took_group(bank.group_of[r])
    # its drive's exchange up to the motion step: the outputs decoded, the state machine's
    # look at the controlword (enable operation, as before), CW4's rising edge (step_hm)
    exchange_buffers(bank, g, took=True, sent=False)
    cw = ch.controlword
    number = ch.psm.command(cw, ch.quick_stop_option, ch.faults.cause_active)
    if number:
        ch._transition(number)
    ch.start_homing()
    ch.stopping = False
    ch.finish_homing()  # (the procedure is done as it is made: its result applies now)
    ch.hm_bits = hm_bits_of(ch.homing.status_bits())
    ch.oms = ch.hm_bits  # (no following error: idle_claimable)
    ch.prev_cw = cw
    # the GT follower's post step of that cycle
    st.answered_with(ch.oms)
    # the row taken from its objects as an ended homing (or given back as they stand: the
    # re-index that follows in this cycle's _begin counts the rows again)
    if not bank._eligible_homing(r):
        bank._stepping = r  # (its objects hold its state: nothing put back)
        try:
            bank._release_groups([g])
        finally:
            bank._stepping = -1
        bank.frz[r] = bank.frz_off[r] = False  # (a row given back has them clear)
        bank.home_starts_given += 1
        return True
    bank.took_homing(r)
    bank.home_starts += 1
    return True
