"""``gtecat serve``'s choice of how to wait for frames (issue 16: the latency bar)."""

from __future__ import annotations

from pathlib import Path

import pytest

from gtecat.cli import serve_cmd
from gtecat.cli.serve_cmd import resolve_wait


@pytest.mark.parametrize(
    ("cpus", "rt", "chosen"),
    [
        ({0, 1}, None, "spin"),  # the master keeps the other CPU
        ({0, 1, 2, 3}, None, "spin"),
        ({0}, None, "predict"),  # one CPU: a spinning server would take the master's slices
        ({0, 1}, 10, "predict"),  # SCHED_FIFO: a task that never sleeps is stopped 50 ms/s
    ],
)
def test_auto_spins_where_the_master_keeps_a_cpu(monkeypatch, cpus, rt, chosen) -> None:
    monkeypatch.setattr(serve_cmd.os, "sched_getaffinity", lambda _pid: cpus)
    assert resolve_wait("auto", rt) == chosen


@pytest.mark.parametrize("wait", ["predict", "sleep", "spin"])
def test_a_chosen_mode_is_kept(monkeypatch, wait) -> None:
    monkeypatch.setattr(serve_cmd.os, "sched_getaffinity", lambda _pid: {0})
    assert resolve_wait(wait, 10) == wait


def test_the_default_is_auto() -> None:
    import argparse

    parser = argparse.ArgumentParser()
    serve_cmd.add_parser(parser.add_subparsers())
    args = parser.parse_args(["serve", "--iface", "lo", "--eni", "x.eni"])
    assert args.wait == "auto"


FIG52 = str(Path(__file__).resolve().parents[3] / "examples" / "manual_fig5_2.eni")


@pytest.mark.parametrize(
    ("args", "said"),
    [
        # the ENI's cycle range (31.25 us .. 1 s), from the one place it is written
        (["--cycle-us", "-10"], "argument --cycle-us: the cycle -10 us is out of range: legal"),
        (["--cycle-us", "0"], "argument --cycle-us: the cycle 0 us is out of range: legal"),
        (["--cycle-us", "31"], "legal is 31.25..1000000 us"),
        (["--cycle-us", "1e7"], "legal is 31.25..1000000 us"),
        (["--cycle-us", "nan"], "the cycle nan us is out of range"),
        (["--cycle-us", "x"], "the cycle 'x' is not a number of microseconds"),
        (["--duration", "-5"], "argument --duration: -5 is not greater than 0"),
        (["--duration", "nan"], "argument --duration: nan is not greater than 0"),
        (["--duration", "x"], "argument --duration: 'x' is not a number"),
    ],
)
def test_numbers_that_make_no_sense_are_refused_by_name(capsys, args, said) -> None:
    with pytest.raises(SystemExit) as done:
        serve_cmd.main(["--eni", FIG52, "--iface", "lo", *args])
    assert done.value.code == 2 and said in capsys.readouterr().err


@pytest.mark.parametrize("option", ["--stats-json", "--pcap"])
def test_a_file_that_cannot_be_written_is_refused_before_serving(capsys, option) -> None:
    """Not at the first SIGUSR1 with a traceback (outside check): one line, exit 1."""
    path = "/nonexistent-gtecat/d/out"
    code = serve_cmd.main(["--eni", FIG52, "--iface", "lo", option, path, "--duration", "0.1"])
    out = capsys.readouterr()
    assert code == 1 and "ready" not in out.out
    assert out.err == f"error: {option} {path}: No such file or directory\n"


@pytest.mark.parametrize(
    ("text", "value"), [("auto", "auto"), ("off", "off"), ("0", "off"), ("50", 50), (" 99 ", 99)]
)
def test_rt_priority_takes_a_number_auto_or_off(text, value):
    from gtecat.cli.serve_cmd import _rt_priority

    assert _rt_priority(text) == value


@pytest.mark.parametrize("text", ["100", "-1", "high", ""])
def test_rt_priority_refuses_the_rest(text):
    import argparse

    from gtecat.cli.serve_cmd import _rt_priority

    with pytest.raises(argparse.ArgumentTypeError):
        _rt_priority(text)


def test_auto_scheduling_takes_fifo_where_permitted_and_is_given_back():
    """``--rt-priority auto``: SCHED_FIFO where the system permits it, on no CPU in particular
    (a pinned real-time server cannot be moved away from another one), normal priority for an
    explicit spin; serve gives it back at the end."""
    import os

    from gtecat.cli.serve_cmd import take_scheduling
    from gtecat.scheduling import restore, snapshot

    before = snapshot()
    try:
        assert take_scheduling("auto", "spin", None) == (None, "normal priority")
        assert snapshot() == before
        assert take_scheduling("off", "predict", None) == (None, "normal priority")
        rt, words = take_scheduling("auto", "predict", None)
        if rt is None:
            assert words == "normal priority (real-time refused)"
        else:
            policy = os.sched_getscheduler(0) & ~os.SCHED_RESET_ON_FORK  # children run normally
            assert policy == os.SCHED_FIFO and words == "SCHED_FIFO 50"
            assert os.sched_getaffinity(0) == before[2]  # type: ignore[index]
    finally:
        restore(before)
    assert snapshot() == before


def test_a_cycle_in_the_enis_range_is_taken_in_nanoseconds() -> None:
    import argparse

    parser = argparse.ArgumentParser()
    serve_cmd.add_parser(parser.add_subparsers())
    for text, ns in (("31.25", 31_250), ("250", 250_000), ("1000000", 10**9)):
        args = parser.parse_args(["serve", "--iface", "lo", "--eni", "x", "--cycle-us", text])
        assert args.cycle_ns == ns
