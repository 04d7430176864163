"""What ``gtecat serve`` says about late answers and about the host: where its loop was when it
took each frame, the frames answered later than 1 ms, the hypervisor's steal, and the kernel's
preemption model in the ready line (no veth, no root: a socket pair and fake files)."""

from __future__ import annotations

import gzip
import socket
from pathlib import Path

import pytest

from tests.gtecat.wire.test_serve_veth import FakeClock, exchange, running


def test_every_frame_is_counted_where_it_was_found_and_a_late_one_is_described() -> None:
    from gtecat.drives.esc import Command, Datagram, encode_frame
    from gtecat.wire.serve import FOUND, LATE_KEPT, WireServer
    from tests.drives.esc.mini import mini_chain

    ours, theirs = socket.socketpair(socket.AF_UNIX, socket.SOCK_DGRAM)
    # every reading of the clock is 0.6 ms later: receive -> send returned takes 1.2 ms
    server = WireServer(
        mini_chain(2), "socketpair", sock=theirs, poll_s=0.005, clock=FakeClock(600_000)
    )
    frame = encode_frame([Datagram(Command.BRD, 0, 0, bytes(2))])
    with running(server):
        for _ in range(3):
            assert exchange(ours, frame) is not None
    report = server.report()
    assert set(report["found"]) == set(FOUND)
    assert sum(report["found"].values()) == 3
    assert report["latency"]["over_1ms"] == 3
    late = report["late"]
    assert 1 <= len(late) <= LATE_KEPT and len(late) == 3
    for record in late:
        assert record["latency_us"] == pytest.approx(1200.0)
        assert record["wait_us"] == 0.0  # no kernel time stamp on a socket pair
        assert record["found"] in FOUND
        assert record["at_s"] > 0
        # how much of a wait it spent running (None: it slept, nothing to tell)
        assert record["not_running_us"] is None or record["not_running_us"] >= 0
    assert report["host_steal_percent"] is None or report["host_steal_percent"] >= 0
    server._snapshot()  # the records start afresh (SIGUSR1)
    again = server.report()
    assert again["late"] == [] and sum(again["found"].values()) == 0
    ours.close()
    server.close()


def test_host_steal_reads_the_steal_column() -> None:
    from gtecat.wire.serve import host_steal

    total, steal = host_steal()
    assert total >= steal >= 0


@pytest.mark.parametrize(
    ("debugfs", "cmdline", "config", "model"),
    [
        ("none voluntary (full) lazy\n", "", "", "full"),  # the PREEMPT_DYNAMIC switch first
        (None, "ro quiet preempt=voluntary", "CONFIG_PREEMPT_NONE=y", "voluntary"),
        (None, "ro quiet", "# CONFIG_PREEMPT is not set\nCONFIG_PREEMPT_NONE=y\n", "none"),
        (None, "ro", "CONFIG_PREEMPT_RT=y\nCONFIG_PREEMPT_NONE=y\n", "rt"),
        (None, "ro", "CONFIG_PREEMPT=y\n", "full"),
        (None, "ro", None, None),  # nothing to tell from
        ("(bogus)", "preempt=sometimes", "CONFIG_HZ=250\n", None),
    ],
)
def test_kernel_preemption_model(tmp_path: Path, debugfs, cmdline, config, model) -> None:
    from gtecat.wire.serve import kernel_preemption

    paths = {}
    for name, text in (("preempt", debugfs), ("cmdline", cmdline), ("config", config)):
        paths[name] = str(tmp_path / name)
        if text is not None:
            Path(paths[name]).write_text(text)
    assert kernel_preemption(paths["preempt"], paths["cmdline"], (paths["config"],)) == model


def test_kernel_preemption_reads_a_compressed_config(tmp_path: Path) -> None:
    from gtecat.wire.serve import kernel_preemption

    packed = tmp_path / "config.gz"
    with gzip.open(packed, "wt") as fh:
        fh.write("CONFIG_PREEMPT_VOLUNTARY=y\n")
    missing = str(tmp_path / "missing")
    assert kernel_preemption(missing, missing, (str(packed),)) == "voluntary"


@pytest.mark.parametrize(
    ("model", "realtime", "words", "warns"),
    [
        ("none", True, ", kernel preemption none", True),
        ("voluntary", True, ", kernel preemption voluntary", True),
        ("none", False, ", kernel preemption none", False),  # normal priority waits anyway
        ("full", True, ", kernel preemption full", False),
        (None, True, "", False),
    ],
)
def test_the_ready_line_names_the_preemption_model_and_warns(
    monkeypatch, model, realtime, words, warns
) -> None:
    import gtecat.wire.serve as serve
    from gtecat.cli.serve_cmd import preemption_words

    monkeypatch.setattr(serve, "kernel_preemption", lambda: model)
    said, warning = preemption_words(realtime)
    assert said == words
    assert (warning is not None) == warns
    if warning:
        assert "preempt=full" in warning and "issue" not in warning
