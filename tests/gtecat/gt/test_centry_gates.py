"""The session's gates (gtecat.gt.centry.GATES, gtecat.gt.fast.GATED) follow the session.

The fast readers' C entries ask their value functions only while a gate is open, and those
functions read the controller the gate names without checking the session again; so a gate
left open (or naming a controller) after the session changed would answer from the wrong
controller.  Each test walks the session through the changes that can move a gate - open,
close and reopen in lockstep and in auto, GT_SetCore, GT_SetCardNo, attaching, a card's
cores changed directly, the bank rebuilding its lists - and after each step holds the gates
to the session's own answer and the public functions (C entries) to their table paths.
"""

from __future__ import annotations

import ctypes
from ctypes import byref
from pathlib import Path
from typing import Any

import pytest

from gtecat import gt
from gtecat.gt import _core, centry, fast
from gtecat.master.clock import ClockMode

ENI = Path(__file__).resolve().parents[3] / "examples" / "manual_fig5_2.eni"


def _open(clock: str = "lockstep", move: bool = True, **options: str) -> Any:
    assert gt.GT_Open(eni=str(ENI), clock=clock, log="", **options) == 0
    assert gt.GT_InitEcatComm() == 0
    gt.GTE_Wait(60)
    assert gt.GT_StartEcatComm() == 0
    assert gt.GT_AxisOn(1) == 0
    gt.GT_PrfTrap(1)
    if move:
        prm = gt.TTrapPrm()
        prm.acc, prm.dec = 0.5, 0.5
        gt.GT_SetTrapPrm(1, byref(prm))
        gt.GT_SetPos(1, 50_000)
        gt.GT_SetVel(1, 10)
        gt.GT_Update(1)
        gt.GTE_Wait(30)  # (moving: the values differ from a fresh controller's)
    return gt.GTE_Controller()


def _session_says() -> tuple[Any, Any]:
    """The controllers the two gates must name (None: closed), from the session itself."""
    s = _core.SESSION
    c = s.controllers.get(1)
    on = c is not None and s.remote is None and c.clock.mode in (ClockMode.LOCKSTEP, ClockMode.AUTO)
    return (c if on and s.core == 1 else None), (c if on else None)


def _gates_follow() -> None:
    want = _session_says()
    got = tuple(None if c is fast._OFF else c for c in fast.GATED)
    assert got[0] is want[0] and got[1] is want[1], (got, want)
    views = want[1] is not None and len(_core.SESSION.controllers) == 1
    assert list(centry.GATES) == [_gate(want[0]), _gate(want[1]), int(views)]


def _gate(c: Any) -> int:
    """A gate's value for controller ``c`` (None: closed)."""
    if c is None:
        return centry.CLOSED
    return centry.LOCKSTEP if c.clock.mode is ClockMode.LOCKSTEP else centry.AUTO


def _shown(o: Any) -> Any:
    return bytes(o) if isinstance(o, ctypes.Structure | ctypes.Array) else o.value


#: (label, the public function, the table's, how its arguments are made: (shown, args))
def _calls() -> list[tuple[str, Any, Any, Any]]:
    ecat = sorted(fast.ECAT_READERS)[0]
    out = [
        ("sts byref", gt.GT_GetSts, lambda: (o := ctypes.c_long(), (1, byref(o)))),
        ("sts obj NULL", gt.GT_GetSts, lambda: (o := ctypes.c_long(), (1, o, 1, 0))),
        ("sts span", gt.GT_GetSts, lambda: (o := (ctypes.c_long * 2)(), (1, o, 2))),
        ("prfpos", gt.GT_GetPrfPos, lambda: (o := ctypes.c_double(), (1, byref(o)))),
        ("encpos", gt.GT_GetEncPos, lambda: (o := ctypes.c_double(), (1, o))),
        ("di", gt.GT_GetDi, lambda: (o := ctypes.c_long(), (0, byref(o)))),
        ("homing", gt.GT_GetEcatHomingStatus, lambda: (o := ctypes.c_short(), (1, byref(o)))),
        ("trap", gt.GT_GetTrapPrm, lambda: (o := gt.TTrapPrm(), (1, byref(o)))),
        ("pdo", getattr(gt, ecat), lambda: (o := ctypes.c_long(), (1, byref(o)))),
        ("raw", gt.GT_GetEcatRawData, lambda: (o := (ctypes.c_ubyte * 8)(), (0, 8, o))),
    ]
    rows = [(label, fn, fn.slow, make) for label, fn, make in out]
    rows.append(
        (
            "gtn sts",
            gt.GTN_GetSts,
            gt.GTN_GetSts.__wrapped__,
            lambda: (o := ctypes.c_long(), (1, 1, byref(o))),
        )
    )
    return rows


def _agree(step: str) -> None:
    """Every call of :func:`_calls` answers as its table path (after the gates' check)."""
    _gates_follow()
    bad = []
    for label, public, table, make in _calls():
        got = []
        for fn in (public, table):
            o, args = make()
            rc = fn(*args)
            got.append((rc, _shown(o), gt.GTE_GetLastError() if rc else ""))
        if got[0] != got[1]:
            bad.append(f"{step}: {label}: entry {got[0]}, table {got[1]}")
    assert not bad, "\n".join(bad)


def test_the_c_entries_are_gated() -> None:
    if centry.REASON:
        pytest.skip(f"no C entry here: {centry.REASON}")
    names = ("GT_GetSts", "GT_GetDi", "GT_GetTrapPrm", fast.HOMING, "GT_GetEcatRawData")
    for name in (*names, fast.HOME_STATUS):
        assert hasattr(getattr(gt, name), "python"), name


def test_the_gates_follow_open_close_core_card_and_attach() -> None:
    _gates_follow()  # (nothing open)
    old = _open()
    _agree("open in lockstep")
    assert fast.GATED[0] is old
    assert gt.GT_SetCore(2) == 0
    _agree("GT_SetCore(2)")  # (GT_ functions: core 2; GTN_ core 1 still the bus)
    assert gt.GT_SetCore(1) == 0
    _agree("GT_SetCore(1)")
    assert gt.GT_SetCardNo(1) == 0
    _agree("another card, not open")
    assert gt.GT_SetCardNo(0) == 0
    _agree("the first card again")
    assert gt.GT_Close() == 0
    _agree("closed")
    new = _open(move=False)
    assert new is not old
    _agree("reopened, another controller (standing)")
    assert fast.GATED[0] is new
    gt.GT_Close()
    _open(clock="auto", move=False)
    _gates_follow()
    assert list(centry.GATES)[:2] == [centry.AUTO, centry.AUTO]
    _agree("opened in auto (each call's host latency run by the entry's after)")
    gt.GT_Close()
    _open()
    _agree("reopened in lockstep")
    s = _core.SESSION
    before = s.remote
    try:
        s.remote = object()  # (attached to a controller process: the GT_ calls go there)
        _gates_follow()
        assert list(centry.GATES) == [0, 0, 0]
    finally:
        s.remote = before
    _agree("detached")


def test_the_gates_follow_a_cards_cores_changed_directly() -> None:
    ctl = _open()
    cores = _core.SESSION.controllers
    for change in (
        lambda: cores.pop(1),
        lambda: cores.__setitem__(1, ctl),
        lambda: cores.clear(),
        lambda: cores.setdefault(1, ctl),
        lambda: cores.popitem(),
        lambda: cores.update({1: ctl}),
        lambda: cores.__delitem__(1),
        lambda: cores.__ior__({1: ctl}),
    ):
        change()
        _gates_follow()
    _agree("the cores as they were")
    with _core.SESSION.selected(0, 2):  # (a native client's call on core 2)
        _agree("selected core 2")
    _agree("after the selected core")


@pytest.mark.parametrize("bank", ["on", "off"])
def test_the_entries_follow_the_bank_rebuilding_its_lists(bank: str) -> None:
    """Cycles between the calls: the bank's lists made again each cycle (when it runs the
    axes); the values move, the entries give the table's."""
    _open(bank=bank)
    for k in range(4):
        _agree(f"cycle {k}")
        gt.GTE_Wait(1 + k)
        ctl = gt.GTE_Controller()
        if ctl.bank is not None:
            ctl.bank._lists.clear()  # (as at a cycle: made again at the next read)
            _agree(f"lists cleared {k}")


def _home_calls() -> list[tuple[str, Any, Any]]:
    """(label, function, how its arguments are made): GT_GetHomeStatus's shapes."""
    T = gt.THomeStatus
    return [
        ("byref", gt.GT_GetHomeStatus, lambda: (o := T(), (1, byref(o)))),
        ("obj", gt.GT_GetHomeStatus, lambda: (o := T(), (1, o))),
        ("offset", gt.GT_GetHomeStatus, lambda: (o := (T * 2)(), (1, byref(o, 16)))),
        ("other struct", gt.GT_GetHomeStatus, lambda: (o := gt.TTrapPrm(), (1, byref(o)))),
        ("axis 2", gt.GT_GetHomeStatus, lambda: (o := T(), (2, byref(o)))),
        ("axis 9", gt.GT_GetHomeStatus, lambda: (o := T(), (9, byref(o)))),
        ("gtn", gt.GTN_GetHomeStatus, lambda: (o := T(), (1, 1, byref(o)))),
    ]


def _gtn_table(core: int, *args: Any) -> int:
    """GTN_GetHomeStatus's table path: GT_GetHomeStatus's with ``core`` addressed."""
    with _core.SESSION.selected(_core.SESSION.card, core):
        return int(gt.GT_GetHomeStatus.slow(*args))


def _home_agree(step: str) -> None:
    bad = []
    for label, public, make in _home_calls():
        table = _gtn_table if label == "gtn" else public.slow
        fns = [public, table]
        if hasattr(public, "python"):
            fns.append(public.python)
        got = []
        for fn in fns:
            o, args = make()
            rc = fn(*args)
            got.append((rc, bytes(o), gt.GTE_GetLastError() if rc else ""))
        if any(g != got[0] for g in got):
            bad.append(f"{step}: {label}: {got}")
    assert not bad, "\n".join(bad)


def test_the_home_status_answers_as_the_table_through_a_smart_homing() -> None:
    """GT_GetHomeStatus on its fast path (C entry and Python) and its table path, polled
    through a smart homing of an EtherCAT drive from start to end; a value a field would
    wrap; another session."""
    from gtecat.controller.smart_home import smart_home

    from .conftest import bring_up
    from .test_home_calls import ecat_machine, home_prm

    bring_up("homing_probe.eni", machine=ecat_machine(), clock="lockstep")
    assert gt.GT_AxisOn(1) == 0
    _home_agree("before any homing")  # (the table path makes it at its first call)
    assert gt.GT_GoHome(1, byref(home_prm(mode=gt.HOME_MODE_HOME))) == 0
    st = gt.THomeStatus()
    seen = set()
    for k in range(20_000):
        if k % 50 == 0:
            _home_agree(f"cycle {k}")
        assert gt.GT_GetHomeStatus(1, byref(st)) == 0
        seen.add((st.run, st.stage))
        if not st.run:
            break
        gt.GTE_Wait(1)
    assert not st.run and len(seen) > 2, seen
    _home_agree("homed")
    home = smart_home(gt.GTE_Controller(), 1)
    home.status.capturePos = 1 << 40  # (a c_int32 field wraps it: the table path's own)
    _home_agree("wrapping")
    assert gt.GT_SetCore(2) == 0
    _home_agree("core 2")


def _auto_session(use: str) -> list[Any]:
    """A moving axis polled 600 times in the auto clock (each call costs host latency, a
    cycle running every few calls) through the public functions (``use`` "public": their C
    entries) or their Python paths: what each call answered and the controller's time."""
    _open(clock="auto")
    out: list[Any] = []
    try:
        ctl = gt.GTE_Controller()
        for k in range(100):
            for label, public, _table, make in _calls():
                if label.startswith("gtn"):
                    continue  # (a twin has no Python path of its own to call)
                fn = public if use == "public" else public.python
                o, args = make()
                rc = fn(*args)
                out.append((k, label, rc, _shown(o), ctl.clock.now_ns))
    finally:
        gt.GT_Close()
    return out


def test_in_the_auto_clock_the_entries_run_the_calls_latency_as_the_python_path() -> None:
    """The auto clock: an entry answers, then runs the call's host latency (its cycles,
    when one is due) as the Python path does: the same answers at the same controller
    times, call by call."""
    if centry.REASON:
        pytest.skip(f"no C entry here: {centry.REASON}")
    entry, python = _auto_session("public"), _auto_session("python")
    bad = [f"{a} / {b}" for a, b in zip(entry, python, strict=True) if a != b]
    assert not bad, "\n".join(bad[:5])
    assert entry[-1][-1] > entry[0][-1]  # (time passed: cycles ran among the calls)


def test_the_auto_clock_gives_the_entries_its_numbers(monkeypatch: pytest.MonkeyPatch) -> None:
    """A clock whose quick numbers are not the length the entries read (a slot added on one
    side only) would leave the gate without a clock: every call's latency and cycle in
    Python, silently.  The auto clock's gate has its clock, and its calls' cycles run in C
    (none reaches the controller's Python way after the first, which arms the next)."""
    if centry.REASON:
        pytest.skip(f"no C entry here: {centry.REASON}")
    from gtecat.controller.core import Controller

    _open("auto")
    try:
        ctl = gt.GTE_Controller()
        assert len(ctl.clock.quick) == centry.QUICK_LEN
        assert centry.CLOCK_QUICK[0] == ctl.clock.quick.buffer_info()[0]
        gt.GTE_Wait(20)
        due = Controller.due_cycle
        seen: list[int] = []

        def counted(self: Controller, pending: int) -> bool:
            seen.append(pending)
            return due(self, pending)

        monkeypatch.setattr(Controller, "due_cycle", counted)
        s = ctypes.c_long()
        cycles = ctl.clock.cycles
        for _ in range(400):
            gt.GT_GetSts(1, byref(s))
        assert ctl.clock.cycles - cycles == 20
        assert len(seen) <= 1
    finally:
        gt.GT_Close()
