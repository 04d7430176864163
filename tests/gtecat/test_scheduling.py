"""The real-time scheduling decisions (gtecat/scheduling.py) and where the native controller
uses them, without privileges: the call that sets SCHED_FIFO is a fake that permits or
refuses."""

from __future__ import annotations

import argparse
from collections.abc import Callable

import pytest

from gtecat import scheduling
from gtecat.scheduling import (
    Beside,
    RealtimeRefused,
    WhenBusy,
    from_environment,
    parse_priority,
    take,
)


class FakeSystem:
    """Records what was asked for; refuses SCHED_FIFO unless ``permits``."""

    def __init__(self, permits: bool) -> None:
        self.permits = permits
        self.calls: list[object] = []

    def fifo(self, prio: int) -> None:
        self.calls.append(("fifo", prio))
        if not self.permits:
            raise RealtimeRefused(f"cannot set SCHED_FIFO priority {prio}: not permitted")

    def normal(self, policy_prio: tuple[int, int]) -> None:
        self.calls.append(("normal", policy_prio))


@pytest.mark.parametrize(
    ("text", "value"),
    [("auto", "auto"), (" AUTO ", "auto"), ("off", "off"), ("0", "off"), ("1", 1), ("99", 99)],
)
def test_priority_settings(text, value):
    assert parse_priority(text) == value


@pytest.mark.parametrize("text", ["100", "-1", "high", ""])
def test_priority_settings_refused_with_a_sentence(text):
    with pytest.raises(ValueError, match="1-99"):
        parse_priority(text)


def test_the_setting_comes_from_the_option_else_the_environment_else_auto():
    assert from_environment(None, {}) == "auto"
    assert from_environment(None, {"GTECAT_RT_PRIORITY": " "}) == "auto"
    assert from_environment(None, {"GTECAT_RT_PRIORITY": "off"}) == "off"
    assert from_environment(None, {"GTECAT_RT_PRIORITY": "20"}) == 20
    assert from_environment("off", {"GTECAT_RT_PRIORITY": "20"}) == "off"
    with pytest.raises(ValueError, match="GTECAT_RT_PRIORITY="):
        from_environment(None, {"GTECAT_RT_PRIORITY": "high"})


def test_auto_takes_fifo_where_permitted():
    system = FakeSystem(permits=True)
    got = take("auto", set_fifo=system.fifo)
    assert got == scheduling.Scheduling(50, "SCHED_FIFO 50")
    assert system.calls == [("fifo", 50)]


def test_auto_runs_normally_where_refused_and_says_why():
    system = FakeSystem(permits=False)
    got = take("auto", set_fifo=system.fifo)
    assert got.priority is None and got.words == "normal priority (real-time refused)"
    assert "not permitted" in got.refused


def test_off_never_asks():
    system = FakeSystem(permits=True)
    assert take("off", set_fifo=system.fifo) == scheduling.NORMAL
    assert system.calls == []


def test_a_loop_that_never_sleeps_stays_normal_under_auto_but_a_number_is_obeyed():
    system = FakeSystem(permits=True)
    assert take("auto", spins_forever=True, set_fifo=system.fifo) == scheduling.NORMAL
    assert take(10, spins_forever=True, set_fifo=system.fifo).priority == 10
    assert system.calls == [("fifo", 10)]


def test_auto_without_real_time_scheduling_runs_normally_without_a_complaint():
    system = FakeSystem(permits=True)
    got = take("auto", set_fifo=system.fifo, available=False)
    assert got.priority is None and not got.refused and system.calls == []


def test_a_number_refused_is_an_error():
    with pytest.raises(RealtimeRefused):
        take(10, set_fifo=FakeSystem(permits=False).fifo)


def test_when_busy_switches_on_a_change_only():
    system = FakeSystem(permits=True)
    rt = WhenBusy(50, set_fifo=system.fifo, set_normal=system.normal, normal=(0, 0))
    assert rt.busy(False) is False and system.calls == []
    assert rt.busy(True) is True
    assert rt.busy(True) is True
    assert rt.busy(False) is False
    assert system.calls == [("fifo", 50), ("normal", (0, 0))]
    assert rt.switches == 2


def test_when_busy_refused_once_is_not_asked_again():
    system = FakeSystem(permits=False)
    rt = WhenBusy(50, set_fifo=system.fifo, set_normal=system.normal)
    assert rt.busy(True) is False and "not permitted" in rt.refused
    assert rt.busy(False) is False
    assert rt.busy(True) is False
    assert system.calls == [("fifo", 50)]


@pytest.fixture
def server(tmp_path):
    from gtecat.native.server import Server

    s = Server(f"unix:{tmp_path}/ctl.sock", spin_us=100)
    try:
        yield s
    finally:
        s._cleanup()  # (its sockets closed and the process's endpoint kind given back)


def test_the_controller_is_real_time_while_busy_and_then_never_spins(server, monkeypatch):
    """The native controller: SCHED_FIFO (and no spin) while more threads are runnable
    than there are CPUs, its normal policy and its spin otherwise."""
    from gtecat.native import server as server_module

    system = FakeSystem(permits=True)
    server.realtime = WhenBusy(50, set_fifo=system.fifo, set_normal=system.normal, normal=(0, 0))
    load = {"over": 2}  # runnable threads beyond the CPUs
    monkeypatch.setattr(server_module, "_runnable_over_cpus", lambda: load["over"])

    def look(over: int) -> float:
        load["over"] = over
        server._busy_next = 0.0  # the next look at the load is due
        return server._spin_budget()

    assert look(2) == 0.0
    assert system.calls == [("fifo", 50)]
    # busy, but not so busy that other programs alone hold every CPU: normal, no spin
    assert look(1) == 0.0
    assert look(0) == pytest.approx(100e-6)
    assert system.calls == [("fifo", 50), ("normal", (0, 0))]


def test_beside_takes_the_clients_cpu_after_two_looks_apart_while_busy():
    moves: list[set[int]] = []
    b = Beside({0, 1}, set_affinity=moves.append)
    assert b.look(True, 1, 1) is None  # together: nothing to do
    assert b.look(True, 1, 0) is None  # apart once
    assert b.look(True, 1, 1) is None  # together again: the count starts over
    assert b.look(True, 1, 0) is None
    assert b.look(True, 1, 0) == {0}  # apart twice in a row: onto the client's CPU
    assert b.look(True, 0, 1) == {0}  # the client moved: apart once
    assert b.look(True, 0, 1) == {1}  # twice: it follows
    assert b.look(True, None, 0) == {1}  # unreadable: left as it is
    assert b.look(False, 1, 0) is None  # idle: its CPUs back
    assert b.look(False, 1, 0) is None
    assert moves == [{0}, {1}, {0, 1}] and b.moves == 2


def test_beside_never_takes_a_cpu_it_may_not_use_and_survives_a_refusal():
    def refuse(cpus: set[int]) -> None:
        raise OSError("not permitted")

    b = Beside({1}, set_affinity=refuse, after=1)
    assert b.look(True, 1, 0) is None  # CPU 0 is not the server's
    b.cpus = {0, 1}
    assert b.look(True, 1, 0) is None and b.moves == 0


def _beside_client(server, monkeypatch) -> tuple[list[set[int]], Callable[[int], None]]:
    """The server on CPU 1, its client (pid 4242) served last on CPU 0, a Beside that moves
    after one look apart: the moves it makes, and a look at the load with ``over`` runnable
    threads beyond the CPUs."""
    from gtecat.native import server as server_module

    moves: list[set[int]] = []
    server.beside = Beside({0, 1}, set_affinity=moves.append, after=1)
    cpus = {"thread-self": 1, 4242: 0}
    monkeypatch.setattr(scheduling, "thread_cpu", lambda pid="thread-self": cpus[pid])
    load = {"over": 2}
    monkeypatch.setattr(server_module, "_runnable_over_cpus", lambda: load["over"])
    server._served_pid = 4242

    def look(over: int) -> None:
        load["over"] = over
        server._busy_next = 0.0
        server._spin_budget()

    return moves, look


def test_the_controller_follows_the_client_it_served_while_real_time(server, monkeypatch):
    """The look at the load reads the CPU of the client served last (its process id from
    the Unix socket) and the server's own; apart while real-time: the server moves."""
    import os
    import socket

    from gtecat.native import server as server_module

    a, b = socket.socketpair()
    with a, b:
        assert server_module._peer_pid(a) == os.getpid()
    system = FakeSystem(permits=True)
    server.realtime = WhenBusy(50, set_fifo=system.fifo, set_normal=system.normal, normal=(0, 0))
    moves, look = _beside_client(server, monkeypatch)
    look(2)
    assert moves == [{0}]
    look(0)  # idle: normal policy, its CPUs back
    assert moves == [{0}, {0, 1}]
    server._served_pid = 0  # a client of unknown process: never moved
    look(2)
    assert moves == [{0}, {0, 1}]


def test_a_normal_priority_controller_follows_its_client_too(server, monkeypatch):
    """Without real-time rights (no WhenBusy) the server still takes its client's CPU while
    other programs could hold every CPU, and gives its CPUs back when they cannot."""
    assert server.realtime is None
    moves, look = _beside_client(server, monkeypatch)
    look(1)  # busy, but the server and its client count two of those threads: left alone
    assert moves == []
    look(2)
    assert moves == [{0}]
    look(0)
    assert moves == [{0}, {0, 1}]


@pytest.mark.parametrize("permits", [True, False])
def test_the_controller_command_puts_its_server_beside_the_client_real_time_or_not(
    server, monkeypatch, permits
):
    from gtecat.cli import controller_cmd

    system = FakeSystem(permits=permits)
    monkeypatch.setattr(scheduling, "take", lambda setting: take(setting, set_fifo=system.fifo))
    monkeypatch.setattr(scheduling, "snapshot", lambda: (0, 0, {0, 1}))
    monkeypatch.setattr(scheduling, "is_realtime", lambda: False)
    taken, started_rt = controller_cmd._take_scheduling(server, "auto")
    assert not started_rt
    assert taken.priority == (50 if permits else None)
    assert (server.realtime is not None) == permits
    assert isinstance(server.beside, Beside) and server.beside.cpus == {0, 1}


def test_the_controller_command_moves_nothing_where_it_cannot_read_its_cpus(server, monkeypatch):
    from gtecat.cli import controller_cmd

    monkeypatch.setattr(scheduling, "snapshot", lambda: None)
    controller_cmd._take_scheduling(server, "off")
    assert server.realtime is None and server.beside is None


def test_thread_cpu_reads_a_cpu_number():
    import os

    if not os.path.exists("/proc/self/stat"):
        pytest.skip("no /proc")
    assert scheduling.thread_cpu() in os.sched_getaffinity(0) | set(range(os.cpu_count() or 1))
    assert scheduling.thread_cpu(2**31 - 1) is None


class _Requests:
    """A client socket that holds ``n`` requests, then nothing yet (recv raises as a
    non-blocking socket does)."""

    def __init__(self, n: int) -> None:
        self.left, self.reads = n, 0

    def recv(self, size: int) -> bytes:
        self.reads += 1
        if self.left:
            self.left -= 1
            return b"request"
        raise BlockingIOError


def test_without_a_spin_the_controller_goes_back_to_the_poller_after_a_reply(server, monkeypatch):
    """Busy CPUs (no spin): one request served, then no read that would find nothing yet
    (the poller reports the next request); with a spin it reads on for the next one."""
    from types import SimpleNamespace

    served: list[bytes] = []
    monkeypatch.setattr(server, "_frames", lambda c, data: served.append(data) or True)
    sock = _Requests(2)
    client = SimpleNamespace(sock=sock, out=b"", buf=b"", pid=0)
    monkeypatch.setattr(server, "_spin_budget", lambda: 0.0)
    server._readable(client)
    assert (served, sock.reads) == ([b"request"], 1)
    monkeypatch.setattr(server, "_spin_budget", lambda: 1e-6)
    server._readable(client)  # the second request, then a spin that ends empty-handed
    assert len(served) == 2 and sock.reads >= 3


def test_a_server_started_real_time_spins_briefly(server):
    """Started under chrt (no switching of its own): its spin is bounded."""
    server._bound_spin(started_realtime=False)
    assert server.spin_s == pytest.approx(100e-6)
    server._bound_spin(started_realtime=True)
    assert server.spin_s == pytest.approx(scheduling.RT_SPIN_CAP_US / 1e6)


def test_the_controller_command_refuses_an_unreadable_setting(tmp_path, monkeypatch, capsys):
    from gtecat.cli import controller_cmd

    with pytest.raises(SystemExit):
        parser = argparse.ArgumentParser()
        controller_cmd.add_parser(parser.add_subparsers())
        parser.parse_args(["controller", "--rt-priority", "high"])
    assert "a priority 1-99, auto or off" in capsys.readouterr().err
    monkeypatch.setenv("GTECAT_RT_PRIORITY", "high")
    args = argparse.Namespace(
        listen=f"unix:{tmp_path}/ctl.sock",
        token_file=None,
        eni=None,
        machine=None,
        clock=None,
        backend=None,
        iface=None,
        card=None,
        no_wall_floor=False,
        ready_fd=None,
        lifeline_fd=None,
        private=False,
        rt_priority=None,
        slice_us=None,
    )
    assert controller_cmd.run(args) == 1
    assert "error: GTECAT_RT_PRIORITY='high': a priority 1-99" in capsys.readouterr().err


class FakeSliceCalls:
    """sched_getattr / sched_setattr of a thread: reports ``attr``, records what was set,
    refuses when ``refuse`` is an errno."""

    def __init__(self, policy=0, nice=0, runtime=1_400_000, flags=0, refuse=0, readable=True):
        self.attr = (48, policy, flags, nice, 0, runtime, 0, 0)
        self.readable, self.refuse = readable, refuse
        self.set: list[tuple] = []

    def calls(self):
        def get():
            return self.attr if self.readable else None

        def put(fields):
            self.set.append(fields)
            if self.refuse:
                raise OSError(self.refuse, "refused")

        return get, put


def test_a_normal_thread_asks_for_a_short_slice_keeping_its_nice_and_flags():
    system = FakeSliceCalls(nice=5, flags=0x01 | 0x20)  # reset-on-fork kept, util clamp not
    assert scheduling.short_slice(100, system.calls()) == "100 us slice"
    assert system.set == [(48, 0, 0x01, 5, 0, 100_000, 0, 0)]


def test_the_controller_s_threads_and_children_get_the_default_slice():
    system = FakeSliceCalls(nice=0, flags=0)
    assert scheduling.short_slice(100, system.calls(), reset_on_fork=True) == "100 us slice"
    assert system.set == [(48, 0, 0x01, 0, 0, 100_000, 0, 0)]


@pytest.mark.parametrize(
    "system",
    [
        FakeSliceCalls(policy=1),  # SCHED_FIFO: no slice to shorten
        FakeSliceCalls(runtime=0),  # a kernel without custom slices reports none
        FakeSliceCalls(runtime=100_000),  # the program chose one as short
        FakeSliceCalls(readable=False),  # sched_getattr refused
    ],
    ids=["fifo", "old-kernel", "short-already", "unreadable"],
)
def test_the_slice_is_not_asked_for_where_it_would_change_nothing(system):
    assert scheduling.short_slice(100, system.calls()) == ""
    assert system.set == []


@pytest.mark.parametrize("errno", [22, 7, 1])  # EINVAL, E2BIG, EPERM
def test_a_refused_slice_is_silent(errno):
    system = FakeSliceCalls(refuse=errno)
    assert scheduling.short_slice(100, system.calls()) == ""
    assert len(system.set) == 1


def test_no_slice_without_the_system_calls_or_when_turned_off():
    system = FakeSliceCalls()
    assert scheduling.short_slice(0, system.calls()) == ""
    assert system.set == []
    # a system without sched_setattr (Windows, an unknown machine): nothing asked
    assert scheduling.short_slice(100, calls=False) == ""


def test_the_slice_setting_comes_from_the_environment():
    assert scheduling.slice_from_environment({}) == scheduling.DEFAULT_SLICE_US
    assert scheduling.slice_from_environment({"GTECAT_SLICE_US": "0"}) == 0
    assert scheduling.slice_from_environment({"GTECAT_SLICE_US": " 200 "}) == 200
    assert scheduling.slice_from_environment({"GTECAT_SLICE_US": "-5"}) == 0
    assert scheduling.slice_from_environment({"GTECAT_SLICE_US": "short"}) == 0
    assert scheduling.DEFAULT_SLICE_US == 0  # off unless asked for (docs/performance.md)


def test_the_slice_of_a_thread_on_this_system():
    """The real calls, in a thread of its own (the test's threads keep theirs): where the
    kernel has custom slices the thread runs with the one asked for, elsewhere nothing."""
    import threading

    calls = scheduling._sched_attr_calls()
    got: dict[str, object] = {}

    def thread() -> None:
        got["before"] = calls[0]() if calls else None
        got["words"] = scheduling.short_slice(100)
        got["after"] = calls[0]() if calls else None

    t = threading.Thread(target=thread)
    t.start()
    t.join()
    before, after = got["before"], got["after"]
    if before is None or before[1] != 0 or not before[5] or before[5] <= 100_000:
        assert got["words"] == ""
        return
    assert got["words"] == "100 us slice"
    assert after[5] == 100_000 and after[3] == before[3]  # the slice; the nice as it was
