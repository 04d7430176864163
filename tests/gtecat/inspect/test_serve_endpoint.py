"""A ``gtecat serve``'s inspection endpoint without root: the serve's loop on a socket pair.

The same objects ``gtecat serve`` builds (the figure 5-2 chain behind ESCs, a
:class:`~gtecat.wire.serve.WireServer`, the :class:`~gtecat.inspect.serve.ServeHost`) with a
Unix socket pair in place of the network: ``gtecat ps`` lists the serve, the fault verbs act
on its chain while its loop runs (a broadcast read counts the slaves that answer), the
operations that need a controller are refused in one line.  The wire tests
(tests/gtecat/wire/test_serve_attach.py) do the same with a real master.
"""

from __future__ import annotations

import json
import socket
import sys
import threading
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from gtecat.cli.main import main
from gtecat.inspect.client import Attached

from .conftest import FIG5_2


class Served:
    def __init__(self, server, endpoint, ours: socket.socket) -> None:
        self.server, self.endpoint, self.ours = server, endpoint, ours
        self.id = endpoint.id

    def error_code(self, slave: int, capsys: pytest.CaptureFixture[str]) -> int:
        """The drive's 603Fh once it is not 0 (it is set at the drive's next step), else 0."""
        deadline = time.monotonic() + 2
        while True:
            argv = ["sdo", "upload", str(slave), "0x603F", "0", "--json", "--attach", self.id]
            assert main(argv) == 0
            value = json.loads(capsys.readouterr().out)["value"]
            if value or time.monotonic() > deadline:
                return value
            time.sleep(0.02)

    def slaves_answering(self) -> int:
        """The working counter of a broadcast read: how many slaves the frame passed."""
        import select

        from gtecat.drives.esc import Command, Datagram, decode_frame, encode_frame

        self.ours.send(encode_frame([Datagram(Command.BRD, 0, 0, bytes(2))]))
        assert select.select([self.ours], [], [], 5)[0], "no answer"
        return decode_frame(self.ours.recv(2048)).datagrams[0].wkc


@pytest.fixture
def served(runtime_dir: Path) -> Iterator[Served]:
    from gtecat.cli.serve_cmd import build_chain
    from gtecat.inspect.serve import ServeHost, publish
    from gtecat.wire.serve import WireServer

    chain, config = build_chain(FIG5_2)
    ours, theirs = socket.socketpair(socket.AF_UNIX, socket.SOCK_DGRAM)
    # the slaves step on their own every 10 ms (no master sends process data here)
    server = WireServer(
        chain, "socketpair", sock=theirs, poll_s=0.005, wait="sleep", step_mode="cycle",
        cycle_ns=10_000_000,
    )  # fmt: skip
    host = ServeHost(server, config, eni=FIG5_2, iface="socketpair")
    published = []
    ready = threading.Event()

    def on_ready() -> None:
        published.append(publish(host))
        ready.set()

    switch = sys.getswitchinterval()
    thread = threading.Thread(target=server.serve, kwargs={"ready": on_ready}, daemon=True)
    thread.start()
    try:
        assert ready.wait(10) and published[0] is not None
        yield Served(server, published[0], ours)
    finally:
        server.stop.set()
        thread.join(5)
        if published and published[0] is not None:
            published[0].close()
        server.close()
        ours.close()
        sys.setswitchinterval(switch)
    assert not thread.is_alive()


@pytest.mark.long
def test_ps_lists_the_serve_and_the_fault_verbs_break_its_chain(served: Served, capsys) -> None:
    assert main(["ps", "--json"]) == 0
    (entry,) = json.loads(capsys.readouterr().out)
    assert (entry["kind"], entry["backend"]) == ("serve", "wire socketpair")
    assert served.slaves_answering() == 4
    assert main(["fault", "inject", "link_down", "after_slave=1", "--attach", served.id]) == 0
    assert "link down after slave 1" in capsys.readouterr().out
    assert served.slaves_answering() == 2  # the frame turns back behind slave 1
    assert main(["slaves", "--json", "--attach", served.id]) == 0
    rows = json.loads(capsys.readouterr().out)
    assert [r["link"] for r in rows] == ["up", "up", "down", "down"]
    assert [r["axes"] for r in rows] == [[1], [2], [], []]
    assert main(["fault", "clear", "--attach", served.id]) == 0
    assert capsys.readouterr().out.strip() == "1 fault cleared"
    assert served.slaves_answering() == 4
    with Attached(served.endpoint.path) as c:
        lines = c.call("log")["lines"]
        snap = c.call("snapshot")
    assert [ln.split("EtherCAT: ")[1] for ln in lines] == [
        "Fault 1 armed: link down after slave 1 (slaves 2.. vanish), at once.",
        "Fault 1 started: link down after slave 1 (slaves 2.. vanish).",
        "Fault 1 ended (cleared): link down after slave 1 (slaves 2.. vanish).",
    ]
    assert snap["states"] == [1, 1, 1, 1] and snap["received"] == 3  # INIT: no master
    # the ESCs' own registers: AL status 0x0130 = INIT, read without side effects
    assert main(["reg", "read", "0x130", "--json", "--attach", served.id]) == 0
    assert [r["value"] for r in json.loads(capsys.readouterr().out)] == [1, 1, 1, 1]
    assert main(["sii", "read", "-p", "2", "--json", "--attach", served.id]) == 0
    assert '"name": "IO 2"' in capsys.readouterr().out
    # an object read from the drive's own dictionary (by name, as the verb allows)
    assert main(["sdo", "upload", "0", "Error code", "--json", "--attach", served.id]) == 0
    got = json.loads(capsys.readouterr().out)
    assert (got["index"], got["value"]) == (0x603F, 0), got
    # a drive fault injected at runtime: the drive's 603Fh says so; clearing the cause
    # leaves the drive in FAULT until its master resets it (CiA 402): the code stays
    assert (
        main(["fault", "inject", "drive_fault", "axis=2", "code=0x2310", "--attach", served.id])
        == 0
    )
    assert "(active)" in capsys.readouterr().out
    assert served.error_code(1, capsys) == 0x2310
    assert main(["fault", "clear", "--attach", served.id]) == 0
    capsys.readouterr()
    time.sleep(0.05)
    assert served.error_code(1, capsys) == 0x2310


def test_what_needs_a_controller_is_refused_in_one_line(served: Served, capsys) -> None:
    for argv in (
        ["data"],
        ["sdo", "download", "0", "0x6060", "0", "6"],
        ["reg", "write", "-p", "0", "0x120", "2"],  # the master's to write
    ):
        assert main([*argv, "--attach", served.id]) == 1
        err = capsys.readouterr().err
        assert "needs a controller" in err and "Traceback" not in err, err
    with Attached(served.endpoint.path) as c:
        with pytest.raises(Exception, match="no operation 'nothing'"):
            c.call("nothing")
        assert c.call("info")["slaves"] == 4
        # a fault the chain cannot have: refused, nothing armed
        with pytest.raises(Exception, match="nothing follows it"):
            c.call("fault_inject", {"kind": "link_down", "after_slave": 3})
        assert c.call("fault_list") == []
