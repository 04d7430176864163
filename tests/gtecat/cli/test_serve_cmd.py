"""``gtecat serve``'s choice of how to wait for frames (issue 16: the latency bar)."""

from __future__ import annotations

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
