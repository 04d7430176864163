"""GTE_Wait's fast function and its quick way (Controller.wait_quick) against the general
way (the table path, Clock.advance_ns's layers): the same session on the manual's figure
5-2 bus in the auto clock - waits of 0, 1, 2 and 7 ms between polls, axis 1 jogging, Trap
moves of axis 2 ending inside a wait, a link loss and axis 2 out of the bank until it is
switched on again, at last an armed fault firing inside a wait - reads the same GT results
after every wait, with the same controller counts (the clock's, the master's, the bank's
and its drives', the readers' epoch, the quick cycles' arming).  A second session on the
twelve-axis bus waits between polls with cycle hooks there - faults armed at a time, after
a count of cycles, at a position and at homing stages, firing inside waits, smart homing
running and then idle - and reads the same too, with the same master log and fault events.
Bad arguments keep the manual's code and reason."""

from __future__ import annotations

from ctypes import byref, c_double, c_long, c_ubyte, c_ulong, c_ushort
from pathlib import Path
from typing import Any

import pytest

from gtecat import faults, gt
from gtecat.controller.core import Controller
from gtecat.controller.epoch import EPOCH
from gtecat.drives.slave import VirtualSlave
from tests.gtecat.faults.test_quiet_quick_cycles import INJECTED, MACHINE, _fired

from .conftest import bring_up, trap_move

#: the waits between polls, in turn (ms)
WAITS = (1, 0, 7, 1, 1, 2, 1, 0, 1)
PASSES = 560


def _counts(ctl: Any, marks0: tuple[int, ...]) -> tuple[Any, ...]:
    """What the wait's layers count: the clock's time, cycles and pending latency, the
    master's cycles, the bank's counts and flags, its drives' cycles, the readers' epoch and
    the steady verdict's marks (the epoch's and the slaves' changes from the session's start:
    ``marks0``), the quick cycles' arming."""
    q = ctl.clock.quick
    bank = ctl.bank
    seen = [m - m0 for m, m0 in zip(ctl._steady_seen, marks0, strict=True)]
    epoch0 = marks0[0]
    out: tuple[Any, ...] = (
        q[0], q[9], q[10], q[11], q[4] - epoch0 if q[4] else 0, ctl.master.cycles,
        EPOCH.n - epoch0, *seen, ctl._armed_left, ctl.in_batch,
        len(ctl._run_axes), ctl._links_down,
    )  # fmt: skip
    if bank is not None:
        out += (
            *bank.counts, bank.csp.cycles, bank._declined, bank._settled, bank.dirty,
            bank.n_moving, bank.n_alive, bank.csp._din_safe, bank.csp.fe_running,
        )  # fmt: skip
    return out


#: the ways a session waits: the table path with the quick way off (the general way), the
#: Python fast function, the public function (GTE_Wait's C entry in front of that one)
SLOW, PYTHON, ENTRY = "slow", "python", "entry"


def _wait_fn(way: str) -> Any:
    if way == SLOW:
        return gt.GTE_Wait.slow
    if way == PYTHON:
        return getattr(gt.GTE_Wait, "python", gt.GTE_Wait)
    return gt.GTE_Wait


def _counting(mp: pytest.MonkeyPatch, way: str, hooked: bool = False) -> list[int]:
    """[0]: the waits that took a quick way - the Python one's (:meth:`Controller.wait_quick`
    answered; ``hooked``: with a cycle hook there), or for the C entry (``ENTRY``) minus the
    waits that ended in Python (:meth:`Controller._wait_end`: the fast function's, the
    general way's, the entry's Python book) - counted as negative."""
    took = [0]
    if way == ENTRY:
        end = Controller._wait_end

        def ended(self: Controller, e0: int) -> None:
            took[0] -= 1
            end(self, e0)

        mp.setattr(Controller, "_wait_end", ended)
        return took
    own = Controller.wait_quick

    def counted(self: Controller, total: int) -> bool:
        ok = own(self, total)
        took[0] += ok and (not hooked or bool(self.pre_cycle or self.post_cycle))
        return ok

    mp.setattr(Controller, "wait_quick", counted)
    return took


#: the places of :func:`_counts` where the armed quick cycle's own numbers lie (its budget,
#: its epoch, what it was armed with) and the bank's status words' epoch: GTE_Wait's C entry
#: keeps the cycle armed after its run (its budget spent by its cycles, the words kept), the
#: Python way arms it anew; the rest is the same
ARMING = (3, 4, 11, 24)


def _unarmed(rows: list[Any]) -> list[Any]:
    """The session's rows without the armed cycle's own numbers (:data:`ARMING`): each row
    ends with :func:`_counts`."""
    n = 33
    out: list[Any] = []
    for row in rows:
        if not isinstance(row, list) or len(row) < n:
            out.append(row)
            continue
        head, counts = row[:-n], row[-n:]
        out.append(head + [x for k, x in enumerate(counts) if k not in ARMING])
    return out


def _session(
    way: str, monkeypatch: pytest.MonkeyPatch, form: Any = int, clock: str = "auto"
) -> tuple[list[Any], int]:
    """The session (module docstring): what every pass read, and the waits that took the
    quick way (:func:`_counting`); ``form``: how the program passes its waits (``float``:
    ``GTE_Wait(1.0)``)."""
    monkeypatch.setattr(Controller, "QUICK_WAIT", way != SLOW)
    took = _counting(monkeypatch, way)
    wait = _wait_fn(way)
    bring_up(clock=clock)
    ctl = gt.GTE_Controller()
    marks0 = (EPOCH.n, 0, VirtualSlave.al_changes, VirtualSlave.outside_changes)
    for a in (1, 2):
        assert gt.GT_AxisOn(a) == 0
    wait(20)
    jog = gt.TJogPrm()
    jog.acc = jog.dec = 0.1
    assert gt.GT_PrfJog(1) == 0 and gt.GT_SetJogPrm(1, byref(jog)) == 0
    assert gt.GT_SetVel(1, 5.0) == 0 and gt.GT_Update(1) == 0
    sts, pos, clk = c_long(), c_double(), c_ulong()
    raw = (c_ubyte * 8)()
    seen: list[Any] = []
    target = 0
    back = False
    for k in range(PASSES):
        if k % 60 == 10 and k < 200:  # a short move: it ends inside one of the waits
            target += 200 if k % 120 == 10 else -200
            trap_move(2, target, 4.0)
        if k == 200:
            assert gt.GTE_UnplugSlave(1) == 0  # axis 2's drive and the IO behind it
        if k == 330:
            assert gt.GTE_ReplugSlave(1) == 0
        if k >= 350 and not back:  # the bus up again: its alarm cleared, on, in the bank
            back = gt.GT_ClrSts(2) == 0 and gt.GT_AxisOn(2) == 0
        if k == 480:  # armed now, fires inside a later wait
            faults.inject("drive_fault", axis=2, code=0x2310, after_ms=13, duration_ms=20)
        row: list[Any] = []
        for a in (1, 2):
            row += [gt.GT_GetSts(a, byref(sts)), sts.value]
            row += [gt.GT_GetPrfPos(a, byref(pos)), pos.value]
            row += [gt.GT_GetEncPos(a, byref(pos)), pos.value]
        row += [gt.GT_GetClock(byref(clk)), clk.value, gt.GT_GetEcatRawData(0, 8, raw)]
        row += [*raw, gt.GTE_GetLastError()]
        row += [back, wait(form(WAITS[k % len(WAITS)])), *_counts(ctl, marks0)]
        seen.append(row)
    assert back, gt.GTE_GetLastError()
    seen.append(ctl.log.text())
    gt.GT_Close()
    return seen, took[0] + (PASSES + 1 if way == ENTRY else 0)


def test_fast_wait_is_the_general_way(monkeypatch: pytest.MonkeyPatch) -> None:
    general, none = _session(SLOW, monkeypatch)
    assert none == 0
    # (a wait of whole milliseconds as a float - GTE_Wait(1.0) - is the int's, and so fast)
    for form in (int, float):
        quick, took = _session(PYTHON, monkeypatch, form)
        assert took > PASSES // 2  # (the quick way ran: the bus steady, the axes in the bank)
        assert len(quick) == len(general)
        for k, (a, b) in enumerate(zip(general, quick, strict=True)):
            assert a == b, f"{form.__name__} pass {k}"
    # the session went where the docstring says: axis 2 out of the bank, a link down
    assert any(row[-17] for row in general[:-1])  # (len(_run_axes))
    assert any(row[-16] for row in general[:-1])  # (_links_down)


@pytest.mark.parametrize("clock", ["auto", "lockstep"])
def test_the_c_entry_waits_as_the_fast_function(
    clock: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    """GTE_Wait's C entry and the Python fast function (``GTECAT_CENTRY=0``'s public one):
    the same results, clock and counts after every wait, but for the armed cycle's own
    numbers (:data:`ARMING`), on either clock; most waits ran in C."""
    if not hasattr(gt.GTE_Wait, "python"):
        pytest.skip("no C entry here")
    python, _ = _session(PYTHON, monkeypatch, clock=clock)
    for form in (int, float):
        entry, in_c = _session(ENTRY, monkeypatch, form, clock)
        assert in_c > PASSES // 2, in_c
        assert len(entry) == len(python)
        for k, (a, b) in enumerate(zip(_unarmed(python), _unarmed(entry), strict=True)):
            assert a == b, f"{form.__name__} pass {k}"


def _hooked_session(way: str, mp: pytest.MonkeyPatch, tmp: Path) -> tuple[list[Any], int]:
    """Waits between polls with cycle hooks: faults armed at a time, after a count of
    cycles, at a position and at homing stages fire inside waits; smart homing runs, then
    stays idle.  What every pass read, the log and the faults' events; the waits that took
    the quick way with a hook there."""
    mp.setattr(Controller, "QUICK_WAIT", way != SLOW)
    took = _counting(mp, way, hooked=True)
    started = _fired(mp)
    wait = _wait_fn(way)
    machine = tmp / "cell.toml"
    machine.write_text(MACHINE)
    log = tmp / f"{way}.log"
    bring_up("twelve_axes.eni", machine=str(machine), clock="auto", log=str(log))
    ctl = gt.GTE_Controller()
    marks0 = (EPOCH.n, 0, VirtualSlave.al_changes, VirtualSlave.outside_changes)
    for a in range(1, 13):
        gt.GT_AxisOn(a)
    wait(10)
    for d in map(dict, INJECTED):  # (a position, homing stages, a far one)
        faults.inject(d.pop("kind"), **d)
    gt.GT_SetHomingMode(1, 6)
    gt.GT_SetEcatHomingPrm(1, 3, 40000, 20000, 400000, 0, 0)
    gt.GT_StartEcatHoming(1)
    home = gt.THomePrm()
    gt.GT_GetHomePrm(5, byref(home))
    home.mode, home.moveDir, home.velHigh, home.velLow = gt.HOME_MODE_HOME, 1, 40.0, 10.0
    home.acc = home.dec = 1.0
    gt.GT_PrfTrap(5)
    assert gt.GT_GoHome(5, byref(home)) == 0
    trap_move(2, 12_000, 10.0)
    sts, clk, hs = c_long(), c_ulong(), c_ushort()
    prf = (c_double * 12)()
    home_st = gt.THomeStatus()
    seen: list[Any] = []
    for k in range(HOOKED_PASSES):
        row: list[Any] = [gt.GT_GetClock(byref(clk)), clk.value]
        for a in range(1, 13):
            row += [gt.GT_GetSts(a, byref(sts)), sts.value]
            if sts.value & 0x62 and k % 10 == 0:  # an alarm, a limit: reset
                gt.GT_ClrSts(a, 1)
                gt.GT_AxisOn(a)
        row += [gt.GT_GetPrfPos(1, prf, 12, None), *prf]
        if k % 25 == 0:
            row += [gt.GT_GetEcatHomingStatus(1, byref(hs)), hs.value]
            row += [gt.GT_GetHomeStatus(5, byref(home_st)), home_st.run, home_st.stage]
            row.append([f["describe"] + f["state"] for f in faults.listing()])
        row += [wait(WAITS[k % len(WAITS)]), *_counts(ctl, marks0)]
        seen.append(row)
    seen.append(list(faults.injector_for(ctl).events))
    seen.append(started)
    gt.GT_Close()
    seen.append(log.read_text())
    return seen, took[0] + (HOOKED_PASSES + 1 if way == ENTRY else 0)


HOOKED_PASSES = 760


def test_fast_wait_with_faults_armed_is_the_general_way(tmp_path: Path) -> None:
    with pytest.MonkeyPatch.context() as mp:
        general, none = _hooked_session(SLOW, mp, tmp_path)
    with pytest.MonkeyPatch.context() as mp:
        quick, took = _hooked_session(PYTHON, mp, tmp_path)
    assert none == 0
    assert took > 300  # (the hooks quiet: the quick way ran)
    assert len(general[-2]) == 5, general[-2]  # (every fault but the far one fired)
    assert len(quick) == len(general)
    for k, (a, b) in enumerate(zip(general, quick, strict=True)):
        assert a == b, f"pass {k}"
    if not hasattr(gt.GTE_Wait, "python"):
        return
    # the C entry: the same, the armed cycle's own numbers aside (_unarmed); its waits ran
    # on the hooks' quiet budget
    with pytest.MonkeyPatch.context() as mp:
        entry, in_c = _hooked_session(ENTRY, mp, tmp_path)
    assert in_c > 300, in_c
    assert len(entry) == len(quick)
    for k, (a, b) in enumerate(zip(_unarmed(quick), _unarmed(entry), strict=True)):
        assert a == b, f"entry, pass {k}"


@pytest.mark.parametrize(
    "ms",
    [-1, -0.5, -0.0, 10**12, 2**63, 1.5, 0.0004, 2.0000001, 1e300, None, "1", float("nan")],
    ids=repr,
)
def test_bad_arguments_keep_the_table_answer(ms: Any) -> None:
    """Whatever the fast function does not take goes to the table path, and a float it takes
    (a fraction of a millisecond, -0.0) waits as the table path waits: the same code and
    reason as the table-checked function's, and the same controller time after it."""
    bring_up(clock="auto")
    ctl = gt.GTE_Controller()
    answers = []
    q = ctl.clock.quick
    for fn in (gt.GTE_Wait.slow, gt.GTE_Wait):
        before = q[9] + q[0]  # (the time passed, the latency not yet run included)
        rc = fn(ms)
        answers.append((rc, gt.GTE_GetLastError(), q[9] + q[0] - before))
    assert answers[0] == answers[1]
    assert answers[0][0] != 0 or ms in (1.5, "1", -0.0, 0.0004, 2.0000001)


def test_plain_waits_in_lockstep_and_realtime_forms() -> None:
    """The lockstep clock takes the quick way too (no host latency after it); a wait with a
    keyword goes to the table path."""
    bring_up(clock="lockstep")
    ctl = gt.GTE_Controller()
    assert gt.GT_AxisOn(1) == 0
    c0 = ctl.clock.cycles
    assert gt.GTE_Wait(5) == 0 and ctl.clock.cycles == c0 + 5
    assert gt.GTE_Wait(ms=3) == 0 and ctl.clock.cycles == c0 + 8
    assert gt.GTE_Wait(0) == 0 and ctl.clock.cycles == c0 + 8


def test_the_entry_rounds_a_float_as_the_python_path(monkeypatch: pytest.MonkeyPatch) -> None:
    """A float's milliseconds in ns, rounded half to even as ``round`` rounds them, by the C
    entry (the waits ran there: armed, nothing but waits between): the controller time
    passed is the Python path's."""
    if not hasattr(gt.GTE_Wait, "python"):
        pytest.skip("no C entry here")
    bring_up(clock="lockstep")
    ctl = gt.GTE_Controller()
    assert gt.GT_AxisOn(1) == 0
    for _ in range(3):
        gt.GTE_Wait(1)  # (the cycle armed, the loop's waits in C)
    q = ctl.clock.quick
    ended = _counting(monkeypatch, ENTRY)  # (less the waits that ended in Python)
    xs = [0.0, 0.5e-6, 1.5e-6, 2.5e-6, 0.0004, 0.0015, 0.1234565, 1.0000005, 2.0000001,
          0.3, 0.7, 0.9999999, 99.9999995, 100.0, 12.5e-6, 1e-300, 5e-324]  # fmt: skip
    for x in xs:
        before = q[9] + q[0]
        assert gt.GTE_Wait(x) == 0, gt.GTE_GetLastError()
        assert q[9] + q[0] - before == round(x * 1_000_000), x
    assert -ended[0] < len(xs) // 2, ended  # (most of them in C)


def test_a_failed_call_before_a_wait_is_forgotten_after_it() -> None:
    """A wait clears the last error as every call that returns 0 does (the entry leaves a
    wait after an error to the Python path, which clears it)."""
    bring_up(clock="lockstep")
    assert gt.GT_AxisOn(1) == 0
    for _ in range(3):
        gt.GTE_Wait(1)
    s = c_long()
    assert gt.GT_GetSts(99, byref(s)) != 0 and gt.GTE_GetLastError()
    assert gt.GTE_Wait(1) == 0 and gt.GTE_GetLastError() == ""
    assert gt.GTE_Wait(1) == 0 and gt.GTE_GetLastError() == ""


def test_waits_of_two_threads_add_up() -> None:
    """Two threads waiting on one lockstep controller (the entry takes the clock's lock as
    the Python path does): every millisecond of both passes, the readers' values of the
    last cycle."""
    import threading

    bring_up(clock="lockstep")
    ctl = gt.GTE_Controller()
    assert gt.GT_AxisOn(1) == 0
    trap_move(1, 1_000_000, 2.0)
    c0 = ctl.clock.cycles

    def waits() -> None:
        pos = c_double()
        for _ in range(400):
            gt.GTE_Wait(1)
            gt.GT_GetPrfPos(1, byref(pos))

    ts = [threading.Thread(target=waits) for _ in range(2)]
    for t in ts:
        t.start()
    for t in ts:
        t.join(60)
    assert ctl.clock.cycles - c0 == 800
    pos, slow = c_double(), c_double()
    assert gt.GT_GetPrfPos(1, byref(pos)) == 0
    assert gt.GT_GetPrfPos.slow(1, byref(slow)) == 0 and pos.value == slow.value > 0
