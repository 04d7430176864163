"""A drive's switch to homing mode done on its bank row (GT_SetHomingMode(axis, 6)).

A claimed CSP row at rest (its planned position on the actual one, nothing moving, the
servo on) whose axis is switched to homing mode takes two cycles on the scalar path
(:func:`gtecat.gt.homing_calls.set_homing_mode`): the drive takes 6060h = 6 in the first
exchange (``Channel.step``: the request seen, the switch due ``mode_latency_cycles``
later), switches in the exchange where it is due (``enter``, then ``step_hm`` with no
procedure: ``stop_ramp`` holds the demand where the motor stands) and shows 6061h = 6 and
its homing bits in 6041h after it; the axis layer follows the drive from the first cycle on
(``AxisResources._post``: out of CSP, its positions taken from the drive again).  Until the
switch the drive's cycle is a CSP cycle at rest; at the switch nothing of its motion
changes either (the demand is where the motor stands, its speed 0).

So the bank runs those cycles as the row's CSP cycles (the compiled kernel, with the other
rows, in one run where the controller runs cycles its quick way) with 6060h written in the
image and the row's objects unguarded but untouched, then puts the row's state into its
objects as a release does (but the drive's process values, which its step in the switch
makes again), brings them to what the switch leaves - the drive's mode bookkeeping,
``enter`` and ``step_hm``'s hold, its process values (its own ``_outputs``; its codec writes
6041h and 6061h into its buffers and the image), the axis's command and the axis layer's
rebase onto the drive - and takes the row again from them in place (``AxisBank._load``:
frozen in homing mode, :func:`gtecat.drives.homing_bank.idle_claimable`) with its guards
back, or gives it back as they stand when the bank would not take it.  The objects are then
exactly as the scalar path leaves them (``tests/gtecat/controller/test_bank_home_rows.py``
compares every object and value with the bank off), and no step of the axis or the drive
ran in Python: the switch costs the call, the other rows' compiled cycles and one store and
load of the row.

Anything else - another mode, a row moving or not plain, hooks, a touch probe, the drive's
outputs written since the bank looked (a raw write: its drive takes them), a drive
whose 6060h/6061h are not mapped or that shows another mode while switching, the realtime
clock (whose cycle thread, and other threads' calls, run while the call waits) - takes the
opened row's path (:meth:`AxisBank.call_opened`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from gtecat.drives.cia402 import State
from gtecat.drives.modes import OpMode, enter, step_hm

from ..master.clock import ClockMode
from .epoch import EPOCH
from .motion.trap import _MOVE, TrapPlanner

if TYPE_CHECKING:
    from .bank import AxisBank, _Group

_get, _set = object.__getattribute__, object.__setattr__
_BANK: list[Any] = []  # the bank module, once asked (it imports this one)


def _bank() -> Any:
    if not _BANK:
        import gtecat.controller.bank as bank

        _BANK.append(bank)
    return _BANK[0]


_HOMING = 6
_CSP = 8
_CW_ENABLED = 0x000F


def _switchable(bank: AxisBank, r: int, g: _Group) -> int:
    """The cycles the drive of claimed row ``r`` takes to show homing mode after 6060h = 6
    is written (the first exchange takes it, ``mode_latency_cycles`` more switch it), when
    its switch may run on the row (module docstring); 0 when it may not."""
    if bank.ctl.clock.mode is ClockMode.REALTIME:
        return 0  # (the cycle thread runs while the call waits: other threads' calls too)
    if (
        bank.moving[r]
        or bank.jog[r]
        or bank.hm[r]
        or bank.frz[r]
        or bank.sampled[r]
        or bank.lvel[r]
        or bank.dwatch[r]
        or bank.dpost[r]
        or r in bank._aware
        or r in bank._post_next
        or r in bank._tp_apply
        or r in bank._open
        or len(g.rows) != 1
    ):
        return 0
    ax, res = bank.axes[r], bank.res[r]
    if not (_get(ax, "servo_on") and _get(ax, "mode_cmd") == _CSP):
        return 0
    cw = _get(ax, "cw")
    if cw != _CW_ENABLED or _get(ax, "_cw_sent") != cw or _get(ax, "plan_error"):
        return 0
    if _get(ax, "link_lost") or _get(ax, "drive_offset") or _get(ax, "compensation"):
        return 0
    acc = _get(ax, "_mode_acc"), _get(ax, "_disp_acc"), _get(ax, "_tp_acc"), _get(ax, "_pos_acc")
    if None in acc or _get(ax, "_sw_acc") is None:
        return 0  # (6060h/6061h by SDO: the opened row's path)
    if acc[2].get() != acc[3].get():
        return 0  # 607Ah must hold 6064h (the axis writes 6064h there once out of CSP)
    st = bank._homing_hook(ax, res)  # (the resources' hooks and the GT homing follower)
    if st is False or (st is not None and st.active):
        return 0
    if res.latched or not res._csp:
        return 0
    ch = bank.csp.channels[r]
    s = ch._settings
    if s.mode_display_while_switching is not None or s.refuse_mode_change_while_halt:
        return 0
    if s.mode_change_states is not None and State.OPERATION_ENABLED not in s.mode_change_states:
        return 0
    if OpMode.HOMING not in ch.supported or _get(ch, "field") is not None:
        return 0
    if not bank._outputs_kept(bank.group_of[r]):
        return 0  # the drive's outputs written meanwhile (a raw write): its drive takes them
    if ch.tp_function or ch._tp_applied or _get(ch, "probe").function:
        return 0
    csp = bank.csp
    # at rest on its demand: the CSP cycle and the switch's hold leave the motion as it is
    pos = float(csp.pos[r])
    if (
        csp.vel[r] != 0.0
        or csp.acc[r] != 0.0
        or csp.torque[r] != 0.0
        or csp.dvel[r] != 0.0
        or float(csp.dpos[r]) != pos
        or csp.fe_time[r]
        or csp.limited[r]
        or csp.sw_limited[r]
        or csp.lstop[r]
        or csp.tpw[r]
        or csp.din[r] & 3
        or int(csp.target[r]) + int(csp.pos_offset[r]) + int(csp.off[r]) != pos
    ):
        return 0
    latency = int(s.mode_latency_cycles)
    return 1 + max(latency, 0)


def switch_to_homing(bank: AxisBank, ctl: Any, r: int, g: _Group) -> int | None:
    """GT_SetHomingMode(axis, 6) of claimed row ``r`` (group ``g``) run on the row (module
    docstring): 0 as the call returns it; None when the row does not qualify (the caller
    takes the opened row's path, nothing changed)."""
    # (its objects' guards off while the call looks at them and while it runs: nothing else
    # runs in its cycles, no hook among them; on again as the row is taken again)
    objs = tuple(bank._guarded_objects(g))
    b = _bank()
    b._unguard(objs)
    n = 0
    try:
        n = _switchable(bank, r, g)
    finally:
        if not n:
            b._reguard(objs)
    if not n:
        return None
    ax = bank.axes[r]
    gi = bank.group_of[r]
    clock = ctl.clock
    # the call: 6060h = 6 into the image (the raw-write checks' references follow: the bank
    # wrote it), the axis's command homing (its controlword has no CW4 or CW8 to clear)
    _get(ax, "_mode_acc").set(_HOMING)
    bank._took_group(gi)
    _set(ax, "mode_cmd", _HOMING)
    c0, b0, claim = clock.cycles, bank.bank_cycles, int(bank.claim_ids[r])
    bank.home_switch, bank.home_switch_from = r, b0
    try:
        # (the n cycles in one run where the controller can run them its quick way: only
        # their count is waited for, and the wait's budget is those n cycles)
        clock.run_until(lambda: clock.cycles >= c0 + n, n * clock.cycle_ns / 1e6, _always)
    finally:
        bank.home_switch = -1
    if (
        not (g.claimed and bank.alive[r])
        or bank.bank_cycles != b0 + n
        or bank.claim_ids[r] != claim
    ):
        # (given back meanwhile: switch_released brought its objects to the cycles run,
        # and the scalar path ran the rest)
        return 0
    bank.home_switches += 1
    if not _switch_row(bank, r, g):
        bank.frz[r] = True  # (its drive's objects hold its state: CspBank.rested)
        bank._stepping = r  # (and its axis's: nothing put back)
        try:
            bank._release_groups([g])
        finally:
            bank._stepping = -1
        bank.frz[r] = bank.frz_off[r] = False  # (a row given back has them clear)
        return 0
    b._reguard(objs)  # (the same objects: the switch replaced none, its planner held)
    bank.n_frz += 1
    bank._after_load(r, False)
    bank._counted()
    return 0


def _always() -> bool:
    return True


def _switch_row(bank: AxisBank, r: int, g: _Group) -> bool:
    """After the switch's cycles on claimed row ``r`` (group ``g``): its state into its
    objects, the switch applied to them and the row taken again from them (frozen, in homing
    mode before a homing: :meth:`AxisBank._load`); True when the bank takes it as it stands
    then, False when it must be given back with its objects as they are."""
    res = bank.res[r]
    # its state into its objects, as a release after the n CSP cycles leaves them (the
    # drive's process values aside: its step in the switch makes them again, _outputs)
    pl = res.profile.planner
    if isinstance(pl, TrapPlanner) and pl._mode == _MOVE:
        bank._last = {r: bank._planned_row(r)}  # (a move that ended in the bank: advance)
    bank._rates = {r: bank._enc_rates_row(r)}
    bank.csp.store_state(r)
    bank._put_back(r)
    _took_mode(bank, r, g, 1, sent=False)  # (its exchange's end: _switched)
    _switched(bank, r, g)
    bank._load(r)  # (taken again in place)
    EPOCH.n += 1
    return bool(bank.frz[r]) and bank._eligible_frozen(r, powered=True)


def switch_released(bank: AxisBank, r: int) -> None:
    """Row ``r`` is given back while its drive switches (:func:`switch_to_homing` runs the
    cycles; its objects hold the state of the CSP cycles the bank ran): they are brought to
    what the same cycles leave on the scalar path, whose own steps take it from there."""
    k = bank.bank_cycles - bank.home_switch_from
    if k <= 0:
        return  # (nothing exchanged yet: its drive takes 6060h at its own next step)
    _took_mode(bank, r, bank.groups[bank.group_of[r]], k)
    _rebased(bank, r)


def _took_mode(bank: AxisBank, r: int, g: _Group, k: int, sent: bool = True) -> None:
    """Row ``r``'s drive, ``k`` exchanges after 6060h = 6 was written, as its own steps
    leave it: the request decoded in the first and the switch due ``mode_latency_cycles``
    after it (Channel.step); its buffers as its last exchange leaves them (``sent``: what
    it sent too)."""
    ch = bank.csp.channels[r]
    exchange_buffers(bank, g, took=True, sent=sent)
    ch.mode_seen = _HOMING
    ch.mode_due = ch.cycle - (k - 1) + ch._settings.mode_latency_cycles


def _switched(bank: AxisBank, r: int, g: _Group) -> None:
    """Row ``r``'s objects, as the CSP cycles at rest and :func:`_took_mode` left them, brought
    to what the exchange in which the drive switches leaves on the scalar path."""
    ch = bank.csp.channels[r]
    # the switch (Channel.step): the mode entered, step_hm's hold with no procedure
    ch.mode = ch.mode_seen
    ch.mode_due = None
    enter(ch, ch.mode)
    step_hm(ch, ch.controlword, bank.ctl.clock.cycle_ns * 1e-9)
    ch._outputs()
    exchange_buffers(bank, g, took=False, sent=True)
    _rebased(bank, r)


def _rebased(bank: AxisBank, r: int) -> None:
    """The axis layer out of CSP from the first cycle's post step: the plan and the encoder
    rebased onto the drive's position, the plan following it (AxisResources._post)."""
    res = bank.res[r]
    res._csp = False
    res._rebase()
    res.follow_drive(bank.axes[r])


def exchange_buffers(bank: AxisBank, g: _Group, took: bool, sent: bool) -> None:
    """Group ``g``'s drive's buffers and the image as its exchange leaves them
    (EmulatedBackend.exchange_one): ``took``, its outputs from the image into its objects,
    as its step begins; ``sent``, its objects encoded and its inputs into the image, as it
    ends."""
    backend = bank.ctl.backend
    plan = backend._one_plan
    if plan is None or plan[0] is not backend._plan:
        plan = backend._one_plan = (backend._plan, {e[0].position: e for e in backend._plan})
    slave, out, inp = plan[1][g.position]
    image = backend.image
    codec = slave.codec
    if took:
        if out is not None:
            image.to_slave(out, slave.rx)
        if len(slave.rx) >= codec.rx_bytes:
            codec.decode(slave.rx)
    if sent:
        if len(slave.tx) >= codec.tx_bytes:
            codec.encode(slave.tx)
        if inp is not None:
            image.from_slave(inp, slave.tx)
