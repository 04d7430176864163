"""A TwinCAT-style replay of every ENI in examples/ and the shared fixtures brings the slaves
of ``gtecat serve`` to OP: each file's own InitCmds word for word, validations and timeouts as
written, nothing synthesised (item 2: TwinCAT's own ENI writes an EL2008's output SM only at
SAFEOP -> OP)."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import replace
from pathlib import Path

import pytest

from tests.conftest import needs_fixture
from tests.gtecat.wire.eni_replay import Replay, parse
from tests.gtecat.wire.rawmaster import (
    ChainMaster,
    RawMaster,
    ServeProcess,
    veth_pair,
    why_not_root,
)

ROOT = Path(__file__).resolve().parents[3]
ENIS = sorted((ROOT / "examples").glob("*.eni")) + sorted(
    (ROOT.parent / "shared" / "fixtures" / "eni").glob("*.xml")
)


def is_xml(path: Path) -> bool:
    return b"EtherCATConfig" in path.read_bytes()[:4096]


EXAMPLE_ENIS = sorted((ROOT / "examples").glob("*.eni"))


@pytest.mark.parametrize("eni", EXAMPLE_ENIS, ids=lambda p: p.name)
def test_every_example_carries_its_own_register_init_cmds(eni: Path) -> None:
    """What a replaying master needs from the file alone: per slave the IP, PS and SO
    requests, and the master's slave count check."""
    assert is_xml(eni)
    config = parse(eni)
    assert any(
        c.comment == "read slave count" and c.cnt == len(config.slaves) for c in config.master
    )
    for s in config.slaves:
        requested = {(t, c.data[0] & 0x0F) for c in s.reg if c.ado == 0x0120 for t in c.transitions}
        assert {("IP", 2), ("PS", 4), ("SO", 8)} <= requested, s.name


@pytest.mark.wire
@pytest.mark.parametrize("eni", [p for p in ENIS if is_xml(p)], ids=lambda p: p.name)
@pytest.mark.sample(1)
def test_replay_reaches_op(eni: Path, tmp_path: Path) -> None:
    reason = why_not_root()
    if reason:
        pytest.skip(reason)
    config = parse(eni)
    try:
        pair = veth_pair("ge")
        master_if, slave_if = pair.__enter__()
    except OSError as exc:
        pytest.skip(str(exc))
    try:
        server = ServeProcess(eni, slave_if, tmp_path / "s.json", "--rt-priority", "10", cwd=ROOT)
        try:
            with RawMaster(master_if) as master:
                replay = Replay(master, config)
                failures = replay.run(cycles=50)
                states = replay.states()
        finally:
            assert server.stop() == 0, server.output
    finally:
        pair.__exit__(None, None, None)
    assert not failures, "\n".join(failures[:20])
    assert states == [(8, 0)] * len(config.slaves), states
    assert replay.commands >= 6 * len(config.slaves)  # at least the IP, PS, SO requests and checks
    assert replay.sdos > 0 or not any(s.coe for s in config.slaves)


def test_the_twincat_fixture_is_replayed_as_written() -> None:
    eni = ROOT.parent / "shared" / "fixtures" / "eni" / "twincat_ek1100_el2008_el4002_el1809.xml"
    if not eni.is_file():
        pytest.skip(needs_fixture(eni.name))
    config = parse(eni)
    el2008 = config.slaves[1]
    so = [c for c in el2008.reg if "SO" in c.transitions and c.ado == 0x0800]
    assert [c.data.hex() for c in so] == ["000f010044000100"]  # the output SM, only at SO


class _NoBus:
    """A master that must not be used: the replay fails before it sends anything."""

    def __init__(self) -> None:
        self.mbx_counter: dict[int, int] = {}

    def transact(self, *_: object) -> None:
        raise AssertionError("nothing to send")


def test_an_eni_without_register_init_cmds_fails_clearly(tmp_path: Path) -> None:
    """Nothing is synthesised: without its own commands no slave leaves INIT."""
    tree = ET.parse(ROOT / "examples" / "manual_fig5_2.eni")
    for parent in tree.getroot().iter():
        for child in list(parent):
            if child.tag == "InitCmds" and parent.tag in ("Master", "Slave"):
                parent.remove(child)
    stripped = tmp_path / "stripped.eni"
    tree.write(stripped)
    replay = Replay(_NoBus(), parse(stripped))  # type: ignore[arg-type]
    replay.transition("IP")
    assert replay.failures == [
        f"{name}: no IP InitCmd requests state 2" for name in ("GTHD 0", "GTHD 1", "IO 2", "IO 3")
    ]


#: drives, the cyclic frames the writer lays out for them (Cmd, DataLength, Cnt), and the bytes
#: of all their commands in one frame
_SEVERAL_FRAMES = [
    # 630 output and 990 input bytes: the inputs cut between two frames
    pytest.param(90, [[(11, 630, 90), (10, 836, 76)], [(10, 154, 14)]], 1672, id="90"),
    # 1,400 output and 2,200 input bytes: three frames, one a whole datagram of inputs
    pytest.param(
        200,
        [[(11, 1400, 200), (10, 66, 6)], [(10, 1474, 134)], [(10, 660, 60)]],
        3664,
        id="200",
        marks=pytest.mark.long("200 drives in three frames; 90 drives in two run by default"),
    ),
]


@pytest.mark.parametrize(("drives", "layout", "one_frame"), _SEVERAL_FRAMES)
def test_a_bus_of_several_frames_is_replayed_frame_by_frame(
    tmp_path: Path, drives: int, layout: list[list[tuple[int, int, int]]], one_frame: int
) -> None:
    """Generated drives reach OP under a master that runs the file word for word, in this
    process: every cyclic ``Frame`` goes out as one Ethernet frame (none longer than 1514
    bytes) and each of its commands comes back with its ``Cnt``.  The same commands in one
    frame, as the writer once wrote them, cannot be sent."""
    from gtecat.cli.serve_cmd import build_chain
    from tools.gen_axes_eni import write_axes_eni

    eni = write_axes_eni(drives, tmp_path / f"axes{drives}.eni")
    config = parse(eni)
    assert [[(c.cmd, c.length, c.cnt) for c in f] for f in config.cyclic] == layout
    now = [0]
    chain, _ = build_chain(eni, clock=lambda: now[0])
    master = ChainMaster(chain, tick=lambda: now.__setitem__(0, now[0] + 100_000))
    replay = Replay(master, config)
    failures = replay.run(cycles=3)
    assert not failures, "\n".join(failures[:20])
    assert replay.states() == [(8, 0)] * drives
    assert replay.cyclic_frames == len(layout) * (5 + 3)  # 5 cycles in SAFEOP, 3 in OP
    assert master.resends == 0

    one = Replay(master, replace(config, cyclic=[[c for f in config.cyclic for c in f]]))
    one.cyclic("OP", 1)
    assert one.failures == [f"frame 0: {one_frame} bytes, an Ethernet frame carries 1514"]
