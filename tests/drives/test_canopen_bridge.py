"""A real CANopen client nobody here wrote drives our CiA-402 drive: python-canopen's BaseNode402.

python-canopen talks SDO on python-can's virtual bus; ``tools/canopen_bridge.py`` turns each
8-byte SDO frame into a CoE mailbox message for ``Cia402Drive.mailbox`` (CoE carries the
same SDO frames, ETG.1000.6 5.6.2) and steps the drive a few cycles per request.  No PDOs:
the client falls back to SDO for the controlword, statusword and modes (cia402-facts §6.1).
python-canopen waits on the wall clock; every wait here is bounded (SDO 1 s per request,
homing 20 s), and the whole test takes well under a second.
"""

from __future__ import annotations

import logging
import uuid
from collections.abc import Iterator

import can
import canopen
import pytest
from canopen.sdo.exceptions import SdoAbortedError

from gtecat.drives.cia402 import State
from gtecat.drives.drive import Cia402Drive
from gtecat.drives.machine import AxisMachine
from gtecat.drives.slave import AlState, AlStatusCode
from gtecat.eni.model import Identity
from tools.canopen_bridge import CanSdoBridge, canopen_dictionary

NODE = 5
MACHINE = AxisMachine(
    position=2500,
    counts_per_rev=4000,
    index_offset=700,  # pulses at ..., 700, 4700, 8700, ...
    negative_limit=-20000,
    positive_limit=20000,
    home_switch=((6000, 30000),),
)


@pytest.fixture
def rig() -> Iterator[tuple[canopen.BaseNode402, Cia402Drive, CanSdoBridge]]:
    channel = f"gtecat-{uuid.uuid4().hex}"
    drive = Cia402Drive(0, "bridge drive", Identity(0x47544543, 0x00010001), machines=[MACHINE])
    assert drive.request_state(AlState.PREOP) == AlStatusCode.NO_ERROR  # mailbox from PREOP
    server_bus = can.Bus(interface="virtual", channel=channel)
    network = canopen.Network()
    network.connect(interface="virtual", channel=channel)
    network.notifier.timeout = 0.05  # its reader thread polls: disconnect need not wait 1 s
    node = canopen.BaseNode402(NODE, canopen_dictionary(drive.od))
    network.add_node(node)
    node.sdo.RESPONSE_TIMEOUT = 1.0
    bridge = CanSdoBridge(drive, server_bus, NODE).start()
    logging.getLogger("canopen.profiles.p402").setLevel(logging.ERROR)  # "fallback to SDO"
    try:
        yield node, drive, bridge
    finally:
        bridge.close()
        network.disconnect()
        server_bus.shutdown()


def test_state_changes_mode_and_homing(rig) -> None:
    node, drive, bridge = rig
    ch = drive.channel(0)
    assert node.state == "SWITCH ON DISABLED"
    node.state = "READY TO SWITCH ON"
    assert ch.state is State.READY_TO_SWITCH_ON
    node.state = "OPERATION ENABLED"  # SWITCHED ON, then OPERATION ENABLED
    assert ch.state is State.OPERATION_ENABLED
    node.op_mode = "PROFILED POSITION"
    assert node.op_mode == "PROFILED POSITION" and ch.mode_display == 1
    # method 4: positive home switch from 6000; start off it -> move +, enter it at 6000,
    # first index right of the edge: 8700.  6064h then reads 607Ch there.
    node.sdo["Homing method"].raw = 4
    node.sdo[0x6099][1].raw = 20000
    node.sdo[0x6099][2].raw = 4000
    node.sdo[0x609A].raw = 400000
    node.sdo[0x607C].raw = -77
    requests = bridge.requests
    assert node.homing(timeout=20) is True
    assert node.op_mode == "HOMING"
    assert ch.machine_position == pytest.approx(8700, abs=1.0)
    bridge.run(50)
    assert node.sdo[0x6064].raw == -77
    assert node.statusword & 0x3400 == 0x1400  # homing completed
    assert bridge.requests - requests > 10  # it really polled the drive over SDO
    node.state = "SWITCH ON DISABLED"
    assert ch.state is State.SWITCH_ON_DISABLED


def test_homing_error_is_reported_to_the_client(rig) -> None:
    """Method 6 looks for a negative home switch moving -; there is none: NL, homing error."""
    node, drive, bridge = rig
    node.state = "OPERATION ENABLED"
    node.sdo[0x6098].raw = 6
    node.sdo[0x6099][1].raw = 40000
    node.sdo[0x609A].raw = 400000
    assert node.homing(timeout=20) is False  # at "error, velocity is not zero" (0x2000)
    bridge.run(200)
    assert node.statusword & 0x3400 == 0x2400  # error, at rest
    assert drive.channel(0).machine_position <= -20000


def test_sdo_aborts_segments_and_unknown_objects(rig) -> None:
    node, drive, _ = rig
    with pytest.raises(SdoAbortedError) as err:
        node.sdo[0x6098].raw = 15  # reserved method: refused by the drive
    assert err.value.code == 0x06090030
    with pytest.raises(SdoAbortedError) as err:
        node.sdo.upload(0x5FFF, 0)
    assert err.value.code == 0x06020000
    # segmented upload (CAN segments of 7 bytes, served by the bridge)
    assert node.sdo[0x1008].raw == drive.od.upload(0x1008, 0).decode()
    # segmented download, collected by the bridge and written through CoE in one go
    node.sdo.download(0x607C, 0, (123456).to_bytes(4, "little", signed=True), force_segment=True)
    assert drive.channel(0).home_offset == 123456
    assert node.sdo[0x6502].raw == 0x03AD  # supported modes as python-canopen reads them


def test_scripted_sdo_frames_without_a_bus() -> None:
    """CAN SDO frames straight into ``handle`` (CiA 301 7.2.4.3): request -> response bytes."""
    drive = Cia402Drive(0, "bridge drive", Identity(0x47544543, 0x00010001), machines=[MACHINE])
    drive.request_state(AlState.PREOP)
    bridge = CanSdoBridge(drive, None, NODE)  # no bus: handle() only
    # expedited upload of 6041h: 0x4B = 2 bytes of data; SWITCH ON DISABLED (mask 0x4F = 0x40)
    r = bridge.handle(bytes.fromhex("4041600000000000"))
    assert r[:4] == bytes.fromhex("4b416000") and r[6:] == bytes(2)
    assert int.from_bytes(r[4:6], "little") & 0x4F == 0x40
    # expedited download of 2 bytes (0x2B) 6040h = 0x0006 (shutdown): acknowledged with 0x60
    assert bridge.handle(bytes.fromhex("2b40600006000000")) == bytes.fromhex("6040600000000000")
    r = bridge.handle(bytes.fromhex("4041600000000000"))
    assert int.from_bytes(r[4:6], "little") & 0x6F == 0x21  # READY TO SWITCH ON
    # segmented upload of 1008h: initiate answers the size, then 7-byte segments, toggling
    name = drive.od.upload(0x1008, 0)
    r = bridge.handle(bytes.fromhex("4008100000000000"))
    assert r == bytes.fromhex("41081000") + len(name).to_bytes(4, "little")
    got, toggle = b"", 0
    while True:
        r = bridge.handle(bytes([0x60 | toggle]) + bytes(7))
        assert r[0] & 0xE0 == 0x00 and r[0] & 0x10 == toggle
        got += r[1 : 8 - ((r[0] >> 1) & 7)]
        if r[0] & 1:
            break
        toggle ^= 0x10
    assert got == name
    # a segment out of turn, an unknown object, block upload: aborts (0x80 + code)
    assert bridge.handle(bytes.fromhex("7000000000000000"))[0] == 0x80
    r = bridge.handle(bytes.fromhex("40ff5f0000000000"))
    assert r == bytes.fromhex("80ff5f00") + (0x06020000).to_bytes(4, "little")
    r = bridge.handle(bytes.fromhex("a041600000000000"))
    assert r[0] == 0x80 and int.from_bytes(r[4:], "little") == 0x05040001
    assert bridge.t_ns == bridge.requests * bridge.cycles_per_request * bridge.cycle_ns
