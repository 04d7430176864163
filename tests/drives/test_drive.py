"""The whole drive: objects per channel, ENI mappings, AL states, inputs, probe, bench.

``Rig`` is the small master the other drive tests use: it packs the outputs
with its own ``struct`` layout (independent of the drive's codec), steps the
drive and unpacks the inputs.
"""

from __future__ import annotations

import struct
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import pytest

from gtecat.drives.abort import SdoAbort, SdoAbortCode
from gtecat.drives.cia402 import State
from gtecat.drives.coe import SdoClient
from gtecat.drives.drive import Cia402Drive, DriveSettings
from gtecat.drives.machine import AxisMachine
from gtecat.drives.slave import AlState, AlStatusCode
from gtecat.eni.model import Direction, Identity, Pdo, PdoEntry

FMT = {
    0x6040: "H",
    0x6041: "H",
    0x6060: "b",
    0x6061: "b",
    0x607A: "i",
    0x6064: "i",
    0x60FF: "i",
    0x606C: "i",
    0x6071: "h",
    0x6077: "h",
    0x6078: "h",
    0x603F: "H",
    0x60F4: "i",
    0x60FD: "I",
    0x60B8: "H",
    0x60B9: "H",
    0x60BA: "i",
    0x60BB: "i",
    0x6062: "i",
    0x20F2: "h",
    0x20F9: "h",
    0x60FE: "I",
    0x6072: "H",
    0x607C: "i",
    0x6081: "I",
    0x6083: "I",
    0x6084: "I",
    0x6085: "I",
    0x6087: "I",
    0x6098: "b",
    0x6099: "I",
    0x609A: "I",
    0x6065: "I",
    0x6066: "H",
    0x605A: "h",
    0x605D: "h",
    0x605E: "h",
    0x6502: "I",
    0x6067: "I",
    0x6068: "H",
    0x607D: "i",
    0x60B0: "i",
    0x60B1: "i",
    0x60B2: "h",
}
RX = (0x6040, 0x6060, 0x607A, 0x60FF, 0x6071, 0x60B8)
TX = (0x6041, 0x6061, 0x6064, 0x606C, 0x6077, 0x603F, 0x60F4, 0x60FD, 0x60B9, 0x60BA)
MS = 1_000_000


def _fmt(index: int) -> str:
    base = index if index < 0x6000 else 0x6000 | (index & 0x07FF)
    if index >= 0x2000 and index < 0x6000:
        base = 0x2000 | (index & 0x07FF)
    return FMT[base]


class Rig:
    """A minimal master for one drive (byte-aligned mappings of whole objects)."""

    def __init__(
        self,
        rx: Sequence[int | tuple[int, int]] = RX,
        tx: Sequence[int | tuple[int, int]] = TX,
        *,
        channels: int = 1,
        machines: Sequence[AxisMachine] | None = None,
        settings: DriveSettings | None = None,
        op: bool = True,
        cycle_ns: int = MS,
    ) -> None:
        self.rx_objs = [o if isinstance(o, tuple) else (o, 0) for o in rx]
        self.tx_objs = [o if isinstance(o, tuple) else (o, 0) for o in tx]
        self.rx_fmt = struct.Struct("<" + "".join(_fmt(i) for i, _ in self.rx_objs))
        self.tx_fmt = struct.Struct("<" + "".join(_fmt(i) for i, _ in self.tx_objs))
        rx_pdo = Pdo(
            0x1600,
            Direction.OUT,
            tuple(PdoEntry(i, s, struct.calcsize(_fmt(i)) * 8) for i, s in self.rx_objs),
        )
        tx_pdo = Pdo(
            0x1A00,
            Direction.IN,
            tuple(PdoEntry(i, s, struct.calcsize(_fmt(i)) * 8) for i, s in self.tx_objs),
        )
        self.drive = Cia402Drive(
            0,
            "rig",
            Identity(0x00000B95, 0x00010001, 2, 42),
            rx_pdos=[rx_pdo] if self.rx_objs else [],
            tx_pdos=[tx_pdo] if self.tx_objs else [],
            channels=channels,
            machines=machines,
            settings=settings,
        )
        self.sdo = SdoClient(self.drive.mailbox)
        self.out: dict[tuple[int, int], int] = dict.fromkeys(self.rx_objs, 0)
        self.inputs: dict[int, int] = {}
        self.t = 0
        self.cycle_ns = cycle_ns
        if op:
            for state in (AlState.PREOP, AlState.SAFEOP, AlState.OP):
                assert self.drive.request_state(state) == AlStatusCode.NO_ERROR

    @property
    def ch(self) -> Any:
        return self.drive.channel(0)

    def set(self, index: int, value: int, sub: int = 0) -> None:
        self.out[(index, sub)] = value

    def cycle(self, n: int = 1, **_: Any) -> dict[int, int]:
        for _k in range(n):
            if self.rx_objs:
                self.rx_fmt.pack_into(self.drive.rx, 0, *(self.out[o] for o in self.rx_objs))
            self.drive.step(self.t, self.cycle_ns)
            self.t += self.cycle_ns
            if self.tx_objs:
                values = self.tx_fmt.unpack_from(self.drive.tx)
                self.inputs = {i: v for (i, _), v in zip(self.tx_objs, values, strict=True)}
        return self.inputs

    def sw(self) -> int:
        return self.inputs[0x6041]

    def read(self, index: int, sub: int = 0, fmt: str | None = None) -> int:
        data = self.sdo.upload(index, sub)
        return struct.unpack("<" + (fmt or _fmt(index)), data)[0]

    def write(self, index: int, value: int, sub: int = 0, fmt: str | None = None) -> None:
        self.sdo.download(index, sub, struct.pack("<" + (fmt or _fmt(index)), value))

    def enable(self, mode: int | None = 8, cw_extra: int = 0) -> None:
        """Mode by PDO, then shutdown / switch on / enable operation (one cycle each + 1)."""
        if mode is not None:
            self.set(0x6060, mode)
        self.set(0x607A, self.ch.position_actual)
        for cw in (0x06, 0x07, 0x0F, 0x0F):
            self.set(0x6040, cw | cw_extra)
            self.cycle()
        assert self.ch.state is State.OPERATION_ENABLED, self.ch.state


def test_fig_5_2_mapping_sizes_and_identity() -> None:
    rig = Rig(rx=(0x6040, 0x607A), tx=(0x6041, 0x6064, 0x60FD))
    assert rig.drive.pdo_sizes() == (48, 80)
    assert len(rig.drive.rx) == 6 and len(rig.drive.tx) == 10
    assert rig.read(0x1000, 0, "I") == 0x00020192
    assert rig.read(0x1018, 1, "I") == 0x0B95
    assert rig.read(0x1018, 2, "I") == 0x00010001
    assert rig.read(0x1018, 4, "I") == 42
    assert rig.read(0x6502, 0, "I") == 0x03AD
    assert rig.sdo.upload(0x1008, 0) == rig.drive.name.encode()  # the configured name


def test_every_issue_object_exists_per_channel() -> None:
    rig = Rig(channels=3, op=False)
    od = rig.drive.od
    objects = [
        0x603F,
        0x6040,
        0x6041,
        0x605A,
        0x605D,
        0x6060,
        0x6061,
        0x6064,
        0x6065,
        0x6066,
        0x6067,
        0x6068,
        0x606C,
        0x6071,
        0x6072,
        0x6077,
        0x6078,
        0x607A,
        0x607C,
        0x607D,
        0x6081,
        0x6083,
        0x6084,
        0x6085,
        0x608F,
        0x6098,
        0x6099,
        0x609A,
        0x60B8,
        0x60B9,
        0x60BA,
        0x60BB,
        0x60BC,
        0x60BD,
        0x60D5,
        0x60D6,
        0x60D7,
        0x60D8,
        0x60F4,
        0x60FD,
        0x60FE,
        0x60FF,
        0x6502,
        0x20F2,
        0x20F9,
    ]
    for k in range(3):
        for index in objects:
            assert index + 0x800 * k in od, hex(index + 0x800 * k)
    assert od.find(0x607D, 1) and od.find(0x607D, 2)
    assert od.find(0x6099, 1) and od.find(0x6099, 2)
    assert od.find(0x60FE, 1) and od.find(0x60FE, 2)
    assert 0x8040 not in od  # only three channels


def test_multi_axis_channels_are_independent() -> None:
    rx = (0x6040, 0x6060, 0x607A, 0x6840, 0x6860, 0x687A)
    tx = (0x6041, 0x6061, 0x6064, 0x6841, 0x6861, 0x6864)
    machines = [AxisMachine(position=100.0), AxisMachine(position=-5000.0)]
    rig = Rig(rx=rx, tx=tx, channels=2, machines=machines)
    rig.set(0x6060, 8)
    rig.set(0x6860, 9)
    rig.set(0x607A, 100)
    rig.set(0x687A, -5000)
    for cw in (0x06, 0x07, 0x0F, 0x0F):
        rig.set(0x6040, cw)
        rig.set(0x6840, 0x06)
        inp = rig.cycle()
    assert inp[0x6041] & 0x6F == 0x27 and inp[0x6841] & 0x6F == 0x21
    assert inp[0x6061] == 8 and inp[0x6861] == 9
    assert inp[0x6064] == 100 and inp[0x6864] == -5000
    assert rig.drive.channel(1).state is State.READY_TO_SWITCH_ON


def test_googol_dm3e_fixture_mapping(shared_fixtures: Path) -> None:
    from gtecat.eni.model import PdoEntry as E

    # the PDO lists of fixtures/googol/Gecat_DM3E_stepper.eni
    rx = Pdo(0x1600, Direction.OUT, (E(0x6040, 0, 16), E(0x607A, 0, 32), E(0x60B8, 0, 16)))
    tx = Pdo(
        0x1A00,
        Direction.IN,
        (
            E(0x603F, 0, 16),
            E(0x6041, 0, 16),
            E(0x6061, 0, 8),
            E(0x6064, 0, 32),
            E(0x60B9, 0, 16),
            E(0x60BA, 0, 32),
            E(0x60FD, 0, 32),
        ),
    )
    assert (shared_fixtures / "googol" / "Gecat_DM3E_stepper.eni").exists()
    d = Cia402Drive(0, "DM3E", Identity(0x4321, 0x8300), rx_pdos=[rx], tx_pdos=[tx])
    assert d.pdo_sizes() == (64, 152)
    d.expected_sizes = (64, 152)
    for state in (AlState.PREOP, AlState.SAFEOP, AlState.OP):
        assert d.request_state(state) == AlStatusCode.NO_ERROR
    SdoClient(d.mailbox).download(0x6060, 0, b"\x08")  # the file's start SDO
    d.step(0, MS)
    d.step(MS, MS)
    _err, sw, mode, pos, _tps, _tpv, din = struct.unpack("<HHbiHiI", bytes(d.tx))
    assert sw & 0x4F == 0x40 and mode == 8 and pos == 0 and din == 0


def test_unknown_objects_in_an_eni_become_placeholders() -> None:
    rx = Pdo(0x1600, Direction.OUT, (PdoEntry(0x6040, 0, 16), PdoEntry(0x2005, 3, 16)))
    tx = Pdo(0x1A00, Direction.IN, (PdoEntry(0x6041, 0, 16), PdoEntry(0x2106, 0, 32)))
    d = Cia402Drive(0, "v", Identity(1, 2), rx_pdos=[rx], tx_pdos=[tx])
    assert d.pdo_sizes() == (32, 48)
    for state in (AlState.PREOP, AlState.SAFEOP, AlState.OP):
        d.request_state(state)
    d.rx[:] = struct.pack("<HH", 0x06, 0xBEEF)
    d.step(0, MS)
    assert d.od.find(0x2005, 3).value == 0xBEEF
    assert struct.unpack("<HI", bytes(d.tx))[1] == 0


def test_strict_mapping_refuses_unknown_sdo_mapping() -> None:
    rig = Rig(settings=DriveSettings(strict_mapping=True), op=False)
    rig.drive.request_state(AlState.PREOP)
    rig.write(0x1601, 0, 0, "B")
    with pytest.raises(SdoAbort) as e:
        rig.write(0x1601, 0x20050310, 1, "I")
    assert e.value.code == SdoAbortCode.OBJECT_CANNOT_BE_MAPPED


def test_outputs_are_ignored_below_op_and_inputs_still_encoded() -> None:
    rig = Rig(op=False)
    d = rig.drive
    for state in (AlState.PREOP, AlState.SAFEOP):
        d.request_state(state)
    rig.set(0x6040, 0x06)
    inp = rig.cycle(3)
    assert rig.ch.state is State.SWITCH_ON_DISABLED  # controlword by PDO is not valid yet
    assert inp[0x6041] & 0x4F == 0x40
    d.request_state(AlState.OP)
    inp = rig.cycle()
    assert rig.ch.state is State.READY_TO_SWITCH_ON


def test_leaving_op_disables_a_pdo_controlled_axis() -> None:
    rig = Rig()
    rig.enable()
    rig.drive.request_state(AlState.SAFEOP)
    assert rig.ch.state is State.SWITCH_ON_DISABLED
    assert rig.ch.psm.last_transition == 9


def test_leaving_op_can_fault_instead() -> None:
    rig = Rig(settings=DriveSettings(comm_loss_reaction="fault"))
    rig.enable()
    rig.drive.request_state(AlState.SAFEOP)
    rig.cycle(30)
    assert rig.ch.state is State.FAULT
    assert rig.ch.error_code == 0x8100


def test_sdo_only_controlword_works_in_preop() -> None:
    """python-canopen-style masters with no PDOs drive the state machine by SDO."""
    rig = Rig(rx=(), tx=(), op=False)
    rig.drive.request_state(AlState.PREOP)
    rig.write(0x6060, 8)
    for cw in (0x06, 0x07, 0x0F):
        rig.write(0x6040, cw)
        rig.cycle(2)
    assert rig.read(0x6041) & 0x6F == 0x27
    assert rig.read(0x6061) == 8


def test_60fd_shows_switches_and_probe_inputs() -> None:
    m = AxisMachine(
        position=0.0,
        negative_limit=-1000.0,
        positive_limit=1000.0,
        home_switch=((-10.0, 10.0),),
        probe1=((-5.0, 5.0),),
        probe2=((0.0, 1.0),),
    )
    rig = Rig(machines=[m], settings=DriveSettings(limit_reaction="none"))
    assert rig.cycle()[0x60FD] == (1 << 2) | (1 << 16) | (1 << 17)
    rig.ch.machine_position = 1000.0
    assert rig.cycle()[0x60FD] == 2
    rig.ch.machine_position = -1500.0
    assert rig.cycle()[0x60FD] == 1
    rig.ch.machine_position = 7.0
    assert rig.cycle()[0x60FD] == 4


def test_analog_inputs_and_digital_outputs() -> None:
    rig = Rig(rx=(0x6040, (0x60FE, 1)), tx=(0x6041, 0x20F2, 0x20F9))
    rig.ch.set_analog_input(1, 1234)
    rig.ch.set_analog_input(2, -99999)
    rig.set(0x60FE, 0x5, sub=1)
    inp = rig.cycle()
    assert inp[0x20F2] == 1234 and inp[0x20F9] == -32768
    assert rig.ch.digital_outputs == 5
    with pytest.raises(SdoAbort) as e:
        rig.write(0x20F2, 1)
    assert e.value.code == SdoAbortCode.WRITE_OF_READ_ONLY
    with pytest.raises(ValueError):
        rig.ch.set_analog_input(3, 0)


def test_touch_probe_through_pdo() -> None:
    m = AxisMachine(position=0.0, probe1=((500.25, 900.0),))
    rig = Rig(machines=[m])
    rig.enable(mode=8)
    rig.set(0x60B8, 0x0013)  # probe 1, continuous, rising edge
    rig.cycle()
    assert rig.inputs[0x60B9] & 1
    target = 0
    for _ in range(20):
        target += 100
        rig.set(0x607A, target)
        rig.cycle()
    assert rig.inputs[0x60B9] & 0b10
    assert abs(rig.inputs[0x60BA] - 500) <= 1
    assert rig.read(0x60D5, 0, "H") == 1


def test_block_sdo_to_rxpdo_mapped_objects_when_asked() -> None:
    rig = Rig(settings=DriveSettings(block_sdo_to_rxpdo=True))
    with pytest.raises(SdoAbort) as e:
        rig.write(0x607A, 5)
    assert e.value.code == SdoAbortCode.OBJECT_MAPPED_TO_RXPDO
    rig.write(0x6081, 1000, fmt="I")  # not mapped: fine
    assert Rig().sdo.download(0x607A, 0, b"\x05\x00\x00\x00") is None  # default: accepted


def test_bench_function_reports_figures() -> None:
    from tools.bench_drive import bench

    result = bench(2, cycles=200)
    assert result["enabled"] and result["faulted"] == 0
    assert result["cycles_per_wall_s"] > 0 and result["sdo_upload_round_trip_us"] > 0


def test_settings_are_validated() -> None:
    with pytest.raises(ValueError):
        DriveSettings(limit_reaction="explode")
    with pytest.raises(ValueError):
        Cia402Drive(0, "x", Identity(1, 1), channels=9)


def test_each_drive_has_its_own_objects() -> None:
    """Entries made when first looked at (a channel's plain attributes, 1C00h) and those read
    through the drive's lists (touch probe, analog inputs) are each drive's own: a write to
    one drive's dictionary never shows in another's."""
    a, b = Rig(op=False).drive, Rig(op=False).drive
    for drive in (a, b):
        drive.request_state(AlState.PREOP)
    a.od.download(0x6081, 0, struct.pack("<I", 4321))
    assert a.channel(0).profile_velocity == 4321
    assert b.channel(0).profile_velocity != 4321
    assert b.od.upload(0x6081, 0) != a.od.upload(0x6081, 0)
    assert a.od.find(0x6081, 0) is not b.od.find(0x6081, 0)
    assert a.od.find(0x6081, 0) is a.od.find(0x6081, 0)  # (made once)
    assert a.od.find(0x1C00, 3) is not b.od.find(0x1C00, 3)
    assert a.od.upload(0x1C00, 0) == b"\x04" and a.od.upload(0x1C00, 3) == b"\x03"
    a.channel(0).analog_in[1] = -5
    a.channel(0).probe.counters[0] = 7
    assert struct.unpack("<h", a.od.upload(0x20F9, 0))[0] == -5
    assert struct.unpack("<h", b.od.upload(0x20F9, 0))[0] == 0
    assert a.od.upload(0x60D5, 0) == b"\x07\x00" and b.od.upload(0x60D5, 0) == b"\x00\x00"
    with pytest.raises(SdoAbort) as e:
        a.od.download(0x60D5, 0, b"\x01\x00")  # (read-only, as before)
    assert e.value.code == SdoAbortCode.WRITE_OF_READ_ONLY
