"""Inspection endpoints: published by GT_Open, found by gtecat ps, read by the bus verbs.

The endpoint reads what the master and the controller hold: the tests compare what it
returns with the GT calls' own readings (manual 13: GT_GetPrfPos, GT_GetEncPos, GT_GetSts)
on the figure 5-2 bus (manual 5.2.2.4).
"""

from __future__ import annotations

import ctypes
import json
import os
import stat
import threading
import time
from pathlib import Path

import pytest

from gtecat.cli.main import main
from gtecat.controller.epoch import changed
from gtecat.errors import BusError
from gtecat.inspect import client, endpoint, runtime

from .conftest import FIG5_2


def _attach() -> client.Attached:
    found = client.connect(None)
    assert found is not None
    return found[1]


def test_gt_open_publishes_a_private_socket_that_ps_lists(app, runtime_dir: Path, capsys) -> None:
    assert stat.S_IMODE(runtime_dir.stat().st_mode) == 0o700
    (ep,) = runtime.endpoints()
    assert ep.pid == os.getpid() and ep.kind == "python" and ep.clock == "lockstep"
    assert stat.S_IMODE(ep.socket.stat().st_mode) == 0o600
    assert main(["ps", "--json"]) == 0
    listed = json.loads(capsys.readouterr().out)
    assert [e["id"] for e in listed] == [ep.id]
    app.GT_Close()
    assert runtime.endpoints() == [] and not ep.socket.exists()


def test_snapshot_equals_the_gt_readings(app) -> None:
    gt = app
    prm = gt.TTrapPrm()
    prm.acc, prm.dec = 0.5, 0.5
    assert gt.GT_PrfTrap(1) == 0 and gt.GT_SetTrapPrm(1, ctypes.byref(prm)) == 0
    assert gt.GT_SetPos(1, 3000) == 0 and gt.GT_SetVel(1, 10.0) == 0 and gt.GT_Update(1) == 0
    gt.GTE_Wait(100)  # mid-move
    with _attach() as c:
        snap = c.call("snapshot")  # no cycle runs: the endpoint thread answers itself
        lay = c.call("layout")
    row = dict(zip(snap["axis_fields"], snap["axes"][0], strict=True))
    prf, enc, sts = ctypes.c_double(), ctypes.c_double(), ctypes.c_long()
    gt.GT_GetPrfPos(1, ctypes.byref(prf))
    gt.GT_GetEncPos(1, ctypes.byref(enc))
    gt.GT_GetSts(1, ctypes.byref(sts))
    assert (row["prf_pos"], row["enc_pos"], row["sts"]) == (prf.value, enc.value, sts.value)
    assert 0 < prf.value < 3000 and sts.value & 0x400  # moving (table 6-2 bit 10)
    assert snap["states"] == [8, 8, 8, 8] and snap["wkc"] == snap["expected"]
    # the GT raw offsets of figure 5-2 beside each entry, and the image decodes to 6064h
    s0 = lay["slaves"][0]
    by = {(e["index"], e["dir"]): e for e in s0["entries"]}
    assert by[(0x6040, "out")]["gt_bit"] == 0 and by[(0x6041, "in")]["gt_bit"] == 6 * 8
    e = by[(0x6064, "in")]
    image = bytes.fromhex(snap["image"])
    start = lay["inputs_offset"] + e["logical_bit"] // 8
    assert int.from_bytes(image[start : start + 4], "little", signed=True) == enc.value


def test_requests_run_between_the_cycles_of_a_running_application(app) -> None:
    """The application's thread runs the cycles (auto/lockstep); a panel polls meanwhile."""
    gt = app
    got: list[int] = []
    failed: list[BaseException] = []
    done = threading.Event()

    def poll() -> None:
        try:
            with _attach() as c:
                while not done.is_set():
                    got.append(c.call("snapshot")["cycles"])
        except BaseException as e:  # seen by the assertion below, not lost with the thread
            failed.append(e)

    t = threading.Thread(target=poll)
    t.start()
    try:
        # cycles run until the panel has had a few answers. How many waits that takes depends
        # on how the host schedules the two threads (a lockstep wait is quick, and on a busy
        # host the poller may not even have attached after thousands of them), so the loop
        # is bounded by a generous wall-clock limit rather than a count of waits.
        limit = time.monotonic() + 60.0
        k = 0
        while k < 300 or (len(got) < 3 and not failed and time.monotonic() < limit):
            gt.GTE_Wait(1)  # it yields to the panel's thread (a loop of quick waits did not)
            k += 1
    finally:
        done.set()
        t.join(5)
    assert not failed, failed
    assert len(got) >= 3 and got == sorted(got)  # each one a whole cycle's view, in order


def test_a_state_asked_on_the_running_bus_holds(app, capsys) -> None:
    """`gtecat states -p 2 PREOP` beside a running application (ETG.1000.6 AL states): the
    master's recovery leaves the slave there until OP is asked."""
    gt = app
    ep = endpoint.published(gt.GTE_Controller())
    assert main(["states", "-p", "2", "PREOP"]) == 0
    for _ in range(2000):  # the verb's connection closed: the wait may run cycles at once
        if not ep._watchers:
            break
        threading.Event().wait(0.001)
    gt.GTE_Wait(500)  # 5 recovery periods of the master
    with _attach() as c:
        states = c.call("snapshot")["states"]
        assert states == [8, 8, 2, 8]
        assert "Lost: slave 2" in "\n".join(c.call("log")["lines"])
    assert main(["states", "-p", "2", "OP"]) == 0
    gt.GTE_Wait(20)
    capsys.readouterr()
    assert main(["slaves", "--json"]) == 0
    assert [r["state"] for r in json.loads(capsys.readouterr().out)] == ["OP"] * 4


def test_a_slave_asked_below_op_stops_the_cycles_run_at_once(app) -> None:
    """The bus runs many cycles at once only while every slave is in OP: an IO slave an
    operator asked to PREOP stays at its fixed point, but the working counter it leaves short
    is the master's to see (the loss logged, the states read) in the very next cycle."""
    from gtecat.native import field

    gt = app
    ctl = gt.GTE_Controller()
    gt.GTE_Wait(50)
    assert ctl.run_cycles(5) == 5, "every axis in the bank and the bus steady: the batch runs"
    rows = field.run(field.Context(ctl), "states", [2, "PREOP"])
    assert [r["state"] for r in rows] == ["PREOP"]
    assert not ctl.backend.steady() and ctl.run_cycles(5) == 0
    gt.GTE_Wait(1)
    assert ctl.master.states[2] == 2 and ctl.master.last.wkc < ctl.master.last.expected
    gt.GTE_Wait(300)  # 3 recovery periods: the request holds
    assert ctl.master.states == [8, 8, 2, 8]
    assert field.run(field.Context(ctl), "states", [2, "OP"])[0]["state"] == "OP"
    gt.GTE_Wait(20)
    assert ctl.master.states == [8] * 4 and ctl.run_cycles(5) == 5


def test_a_request_waits_for_a_run_of_cycles_that_began_before_the_panel_attached(app) -> None:
    """The bus runs many cycles at once while nobody is attached; a panel that attaches
    meanwhile (its request taken by the endpoint thread, no cycle coming for a while) is
    answered after that run, never beside it."""
    gt = app
    ctl = gt.GTE_Controller()
    gt.GTE_Wait(50)
    bank = ctl.bank
    batch = bank.run_cycles
    in_run, release = threading.Event(), threading.Event()
    order: list[str] = []

    def held_run(t_ns: int, dt_ns: int, n: int) -> int:
        if not in_run.is_set():
            in_run.set()
            release.wait(10)  # (the compiled kernel lets go of the interpreter as long)
            order.append("run ended")
        return batch(t_ns, dt_ns, n)

    bank.run_cycles = held_run
    changed()  # (the bank changed by hand: the cycle armed for the C entries goes with it)
    waiter = threading.Thread(target=gt.GTE_Wait, args=(50,))
    waiter.start()
    ep = endpoint.published(ctl)
    try:
        assert in_run.wait(10)
        with _attach() as c:
            asked = threading.Thread(target=lambda: order.append(str(c.call("info") and "reply")))
            asked.start()
            for _ in range(2000):  # queued; the idle path takes it after IDLE_S
                if ep._pending and ep._pending[0].claimed:
                    break
                threading.Event().wait(0.001)
            asked.join(5 * endpoint.IDLE_S)
            release.set()
            asked.join(10)
    finally:
        release.set()
        waiter.join(10)
        del bank.run_cycles
    assert order == ["run ended", "reply"]


def test_the_verbs_attach_and_say_so_when_none_runs(runtime_dir: Path, capsys, monkeypatch) -> None:
    monkeypatch.setenv("GTECAT_ENI", str(FIG5_2))
    assert main(["slaves", "--json"]) == 0
    cap = capsys.readouterr()
    assert cap.err.count("\n") == 1 and "no running gtecat" in cap.err
    assert len(json.loads(cap.out)) == 4
    with pytest.raises(BusError, match="no running gtecat with id"):
        runtime.find("12345678")


def test_stale_endpoints_are_removed_and_a_shared_folder_refused(runtime_dir: Path) -> None:
    runtime.checked_folder()
    dead = runtime_dir / "999999999.json"
    dead.write_text(json.dumps({"pid": 999_999_999, "started": 0}))
    (runtime_dir / "999999999.sock").touch()
    assert runtime.endpoints() == []
    assert not dead.exists() and not (runtime_dir / "999999999.sock").exists()
    runtime_dir.chmod(0o755)
    with pytest.raises(BusError, match="open to other users"):
        runtime.checked_folder()


def test_a_new_endpoint_removes_those_of_dead_processes_first(runtime_dir: Path) -> None:
    """A process killed (or ended by ``os._exit``) leaves its files; the next endpoint
    published removes them, by the pid in their names, and leaves a live process's, other
    files and its own."""
    from gtecat import gt

    runtime.checked_folder()
    dead = [f"999999999{s}" for s in (".json", ".sock", "-2.json", "-2.sock", ".tmp")]
    live = [f"{os.getpid()}-77.json", f"{os.getpid()}-77.sock"]
    other = ["notes.txt", "x.json"]
    for name in dead + live + other:
        (runtime_dir / name).write_text("{}")
    assert gt.GT_Open(eni=str(FIG5_2), clock="lockstep", log="") == 0
    try:
        left = sorted(p.name for p in runtime_dir.iterdir())
        mine = endpoint.published(gt.GTE_Controller())
        assert mine is not None
        assert left == sorted(live + other + [f"{mine.id}.json", f"{mine.id}.sock"])
    finally:
        gt.GT_Close()


def test_gtecat_inspect_0_publishes_nothing(runtime_dir: Path, monkeypatch) -> None:
    from gtecat import gt

    monkeypatch.setenv("GTECAT_INSPECT", "0")
    assert gt.GT_Open(eni=str(FIG5_2), clock="lockstep", log="") == 0
    try:
        assert runtime.endpoints() == []
        assert endpoint.published(gt.GTE_Controller()) is None
    finally:
        gt.GT_Close()


def test_a_bad_request_is_one_line_back(app) -> None:
    with _attach() as c:
        with pytest.raises(BusError, match="no operation 'nope'"):
            c.call("nope")
        with pytest.raises(BusError, match="no axis 9"):
            c.call("jog", 9, 1.0)
        assert c.call("info")["axes"] == [1, 2]  # the connection still answers


def test_the_panel_ends_and_says_why_when_the_watched_gtecat_ends(app) -> None:
    """An application that closes takes its endpoint along: the panel watching it ends
    with the reason (the command prints it and exits 1) instead of going quiet."""
    pytest.importorskip("aiohttp", reason="gtecat panel needs aiohttp (the test extra)")
    from gtecat.inspect import panel

    (ep,) = runtime.endpoints()
    listening = threading.Event()
    gone: list[str] = []
    t = threading.Thread(
        target=lambda: gone.append(
            panel.serve(
                str(ep.socket), control=False, port=0, title="t", ready=lambda u: listening.set()
            )
        )
    )
    t.start()
    assert listening.wait(20)
    app.GT_Close()
    t.join(20)
    assert not t.is_alive() and gone and gone[0]


def test_the_fault_verbs_name_the_gtecat_they_act_on(app, capsys, monkeypatch) -> None:
    # one account, several users: a fault injected without --attach says whose program it hit
    (ep,) = runtime.endpoints()
    assert main(["fault", "list"]) == 0
    err = capsys.readouterr().err
    assert err.startswith(f"attached to {ep.id} (pid {os.getpid()}, ") and "started 20" in err
    assert main(["fault", "list", "--attach", ep.id]) == 0
    assert capsys.readouterr().err == ""  # (named by the user)
    # two running: none is taken, both are listed with pid, program and start time
    other = runtime.EndpointInfo(**{**ep.__dict__, "id": "7", "pid": 7, "program": "cell.py"})
    monkeypatch.setattr(runtime, "endpoints", lambda: [ep, other])
    assert main(["fault", "inject", "drop_responses", "count=1"]) != 0
    err = capsys.readouterr().err
    assert "2 gtecats are running" in err and "7 (pid 7, cell.py, started 20" in err
    assert f"{ep.id} (pid {os.getpid()}," in err
    assert main(["fault", "list", "--attach", ep.id]) == 0
    assert capsys.readouterr().out.strip() == "no fault armed or active"
    # a trigger on an axis the bus does not have would never fire: refused
    words = ["drive_fault", "axis=1", "when_position=3,100"]
    assert main(["fault", "inject", *words, "--attach", ep.id]) != 0
    assert "when_position: no axis 3: the bus has axes 1..2" in capsys.readouterr().err


def test_a_lost_sdo_answer_over_the_endpoint_runs_none_of_the_applications_cycles(
    app, capsys
) -> None:
    # the application's own SDO waits the master's mailbox timeout in its cycles; a verb
    # beside it gets its 05040000h at once and leaves the application's clock alone
    from gtecat import faults

    faults.inject("mailbox_lost", slave=0, index=0x1018)
    cycles = app.GTE_Controller().clock.cycles
    assert main(["sdo", "upload", "0", "0x1018", "1"]) != 0
    assert "0x05040000" in capsys.readouterr().err
    assert app.GTE_Controller().clock.cycles == cycles


def test_a_control_operation_is_seen_by_the_applications_next_read(app) -> None:
    """A panel's Trap move of an idle lockstep application's axis (no GT call, no cycle
    since): the application's next GT_GetSts, GT_GetPrfMode and GT_GetTrapPrm see it, as
    their table paths do (the readers' kept values are asked again)."""
    from gtecat import gt

    def reads(fn: str) -> tuple:
        m, st, t = ctypes.c_long(), ctypes.c_long(), gt.TTrapPrm()
        call = (lambda f: getattr(gt, f)) if fn == "public" else (lambda f: getattr(gt, f).slow)
        call("GT_GetPrfMode")(1, ctypes.byref(m))
        call("GT_GetSts")(1, ctypes.byref(st))
        call("GT_GetTrapPrm")(1, ctypes.byref(t))
        return m.value, st.value, t.acc, t.dec

    before = reads("public")
    with _attach() as c:
        c.call("trap", 1, 5000, 10.0, 0.25, 0.25)
    after = reads("public")
    assert after != before and after[2:] == (0.25, 0.25)
    assert after == reads("table")
