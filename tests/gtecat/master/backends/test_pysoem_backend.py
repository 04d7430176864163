"""The pysoem backend's logic against a fake pysoem that keeps SOEM's semantics.

The fake (:class:`FakeSoem`) stands for the ``pysoem`` module: a ``Master``
whose slaves are in-process virtual slaves, with SOEM's behaviour where the
backend depends on it (manual state change, ``config_map`` reading the
*current* PDO sizes, SOEM's bit packing of slaves under 8 bits, LRW working
counter, ``SdoError.abort_code``, ``reconfig`` calling the PO2SO hook,
``recover`` re-addressing a slave that answers again).  The wire itself is
tested end to end in ``test_pysoem_veth.py``.
"""

from __future__ import annotations

from types import SimpleNamespace
from typing import ClassVar

import pytest

from gtecat.drives.abort import SdoAbort, SdoAbortCode
from gtecat.drives.io_slaves import IoSlave
from gtecat.drives.slave import AlState, AlStatusCode, VirtualSlave
from gtecat.eni.bits import copy_bits
from gtecat.eni.layout import build_layout
from gtecat.eni.model import InitCmd
from gtecat.eni.topology import parse_topology
from gtecat.errors import BusError, ConfigMismatch, NoSlavesError, StateError
from gtecat.master.backends.pysoem_backend import PysoemBackend, soem_bit_starts
from gtecat.master.bus import Master


# --- the fake pysoem -------------------------------------------------------------------------
class SdoError(Exception):
    def __init__(self, slave_pos, index, subindex, abort_code, desc):
        super().__init__(desc)
        self.slave_pos, self.index, self.subindex = slave_pos, index, subindex
        self.abort_code, self.desc = abort_code, desc


class WkcError(Exception):
    def __init__(self, message=None, wkc=None):
        super().__init__(message)
        self.wkc = wkc


class MailboxError(Exception):
    def __init__(self, slave_pos, error_code, desc):
        super().__init__(desc)
        self.slave_pos, self.error_code, self.desc = slave_pos, error_code, desc


class PacketError(Exception):
    def __init__(self, slave_pos, error_code):
        super().__init__(error_code)
        self.slave_pos, self.error_code = slave_pos, error_code


class ConfigMapError(Exception):
    def __init__(self, error_list):
        super().__init__(error_list)
        self.error_list = error_list


class FakeDevice:
    """One slave on the fake wire: a virtual slave plus a dict object dictionary."""

    def __init__(self, vs: VirtualSlave, od: dict[tuple[int, int], bytes] | None = None) -> None:
        self.vs = vs
        self.od = dict(od or {})
        self.refuse: dict[tuple[int, int], int] = {}  # object -> abort code
        #: object -> what SOEM reports for the next SDO to it: "lost" (no answer: WkcError
        #: after the 700 ms timeout), "error" (a mailbox error reply, SOEM reads on until its
        #: timeout), "unexpected" (an answer that is not the SDO's: packet error 1)
        self.mbx_fault: dict[tuple[int, int], str] = {}
        self.present = True
        self.writes: list[tuple[int, int, bytes]] = []
        self.coe = True  # SII mailbox protocols include CoE

    def raw_state(self) -> int:
        return int(self.vs.al_state) | (0x10 if self.vs.al_error else 0)


class FakeSlave:
    """pysoem.CdefSlave over a FakeDevice."""

    def __init__(self, bus: FakeMaster, pos: int, dev: FakeDevice) -> None:
        self._bus, self._pos, self.dev = bus, pos, dev
        vs = dev.vs
        self.name, self.man, self.id, self.rev = (
            vs.name,
            vs.identity.vendor_id,
            vs.identity.product_code,
            vs.identity.revision_no,
        )
        self.state = 0
        self.al_status = 0
        self.is_lost = False
        self.setup_func = None
        self.obits = self.ibits = 0
        self.o_at: tuple[int, int] | None = None  # (byte in IO map, start bit)
        self.i_at: tuple[int, int] | None = None

    # process data, as pysoem's properties read SOEM's IO map
    @property
    def output(self) -> bytes:
        if self.o_at is None:
            return b""
        n = max(1, self.obits // 8) if self.obits < 8 else (self.obits + 7) // 8
        return bytes(self._bus.iomap[self.o_at[0] : self.o_at[0] + n])

    @output.setter
    def output(self, value: bytes) -> None:
        assert isinstance(value, bytes)
        assert self.o_at is not None and len(value) == len(self.output)
        self._bus.iomap[self.o_at[0] : self.o_at[0] + len(value)] = value

    @property
    def input(self) -> bytes:
        if self.i_at is None:
            return b""
        n = 1 if self.ibits < 8 else (self.ibits + 7) // 8
        return bytes(self._bus.iomap[self.i_at[0] : self.i_at[0] + n])

    # AL state
    def write_state(self) -> int:
        if not self.dev.present:
            return 0
        self.dev.vs.request_state(AlState(self.state & 0x0F))
        return 1

    def state_check(self, expected: int, timeout: int = 2000) -> int:
        self._read()
        return self.state & 0x0F

    def _read(self) -> None:
        if not self.dev.present:
            self.state, self.al_status = 0, 0
            return
        self.state = self.dev.raw_state()
        self.al_status = int(self.dev.vs.al_status_code)

    def reconfig(self, timeout: int = 500) -> int:
        vs = self.dev.vs
        vs.request_state(AlState.INIT)
        vs.request_state(AlState.PREOP)
        self._read()  # ecx_statecheck(PREOP) updates the slave's state before the hook
        if self.setup_func is not None:
            self.setup_func(self)
        vs.request_state(AlState.SAFEOP)
        self._read()
        self._bus.reconfigs.append(self._pos)
        return self.state & 0x0F

    def eeprom_read(self, word_address: int, timeout: int = 20000) -> bytes:
        assert word_address == 0x1C  # SII mailbox protocols
        return (4 if self.dev.coe else 0).to_bytes(4, "little")

    def recover(self, timeout: int = 500) -> int:
        return 1 if self.dev.present else 0

    # mailbox
    def _check_mbx(self, index: int, subindex: int) -> None:
        if not self.dev.present or self.dev.vs.al_state < AlState.PREOP:
            raise WkcError(wkc=0)
        fault = self.dev.mbx_fault.pop((index, subindex), None)
        if fault in ("lost", "error"):
            self._bus.wall_s += 0.7  # SOEM's mailbox timeout passes
        if fault == "lost":
            raise WkcError(wkc=0)
        if fault == "error":
            raise MailboxError(self._pos + 1, 4, "The service is no supported")
        if fault == "unexpected":
            raise PacketError(self._pos + 1, 1)
        code = self.dev.refuse.get((index, subindex))
        if code is None and (index, subindex) not in self.dev.od:
            code = SdoAbortCode.OBJECT_DOES_NOT_EXIST
        if code is not None:
            raise SdoError(self._pos + 1, index, subindex, int(code), "abort")

    def sdo_read(self, index: int, subindex: int, size: int = 0, ca: bool = False) -> bytes:
        self._check_mbx(index, subindex)
        data = self.dev.od[(index, subindex)]
        if len(data) > (size or 256):
            raise PacketError(self._pos + 1, 3)
        return data

    def sdo_write(self, index: int, subindex: int, data: bytes, ca: bool = False) -> None:
        assert isinstance(data, bytes)
        if (index, subindex) not in self.dev.od and (index, subindex) not in self.dev.refuse:
            self.dev.od[(index, subindex)] = b""
        self._check_mbx(index, subindex)
        self.dev.od[(index, subindex)] = data
        self.dev.writes.append((index, subindex, data))


class FakeMaster:
    """pysoem.Master: SOEM with manual state change over a list of FakeDevices."""

    devices: ClassVar[list[FakeDevice]] = []

    def __init__(self) -> None:
        self.manual_state_change = 0
        self.slaves: list[FakeSlave] = []
        self.iomap = bytearray(4096)
        self.expected_wkc = 0
        self.opened: str | None = None
        self.closed = False
        self.mapped = False
        self.reconfigs: list[int] = []
        self.frames = 0
        self.t_ns = 0
        self.wall_s = 0.0  # the wall clock SOEM's waits take (the backend's ``monotonic``)

    def open(self, iface: str) -> None:
        if iface == "missing0":
            raise ConnectionError(f"could not open interface {iface}")
        self.opened = iface

    def close(self) -> None:
        self.closed = True

    def config_init(self, usetable: bool = False) -> int:
        assert self.manual_state_change == 1, "the backend must own the AL states"
        present = []
        for d in self.devices:
            if not d.present:
                break
            present.append(d)
        self.slaves = [FakeSlave(self, i, d) for i, d in enumerate(present)]
        return len(self.slaves) or -1

    def read_state(self) -> int:
        for s in self.slaves:
            s._read()
        return min((s.state & 0x0F for s in self.slaves), default=0)

    def config_map(self) -> int:
        """SOEM's legacy map: all outputs (bit slaves packed), then all inputs."""
        self.expected_wkc = 0
        addr = 0
        for d, bits_attr, at_attr, wkc in (("o", "obits", "o_at", 2), ("i", "ibits", "i_at", 1)):
            bitpos = 0
            for s in self.slaves:
                rx, tx = s.dev.vs.pdo_sizes()
                bits = rx if d == "o" else tx
                setattr(s, bits_attr, bits)
                if not bits:
                    continue
                if bits < 8:
                    setattr(s, at_attr, (addr, bitpos))
                    bitpos += bits
                    addr += bitpos // 8
                    bitpos %= 8
                else:
                    if bitpos:
                        addr, bitpos = addr + 1, 0
                    setattr(s, at_attr, (addr, 0))
                    addr += (bits + 7) // 8
                self.expected_wkc += wkc
            if bitpos:
                addr += 1
        self.mapped = True
        return addr

    def send_processdata(self, release_gil: bool = False) -> int:
        self.frames += 1
        return 1

    def receive_processdata(self, timeout: int = 2000, release_gil: bool = False) -> int:
        """One LRW: every present slave takes its outputs, steps, gives its inputs."""
        wkc = 0
        self.t_ns += 1_000_000
        for s in self.slaves:
            vs = s.dev.vs
            if not s.dev.present:
                continue
            if s.o_at is not None:
                copy_bits(self.iomap, s.o_at[0] * 8 + s.o_at[1], vs.rx, 0, s.obits)
                if vs.al_state == AlState.OP:
                    wkc += 2
            vs.step(self.t_ns, 1_000_000)
            if s.i_at is not None and vs.al_state >= AlState.SAFEOP:
                copy_bits(vs.tx, 0, self.iomap, s.i_at[0] * 8 + s.i_at[1], s.ibits)
                wkc += 1
        return wkc if wkc else -1


def fake_soem(devices: list[FakeDevice]) -> SimpleNamespace:
    master_cls = type("Master", (FakeMaster,), {"devices": devices})
    return SimpleNamespace(
        Master=master_cls,
        SdoError=SdoError,
        WkcError=WkcError,
        MailboxError=MailboxError,
        PacketError=PacketError,
        ConfigMapError=ConfigMapError,
        __version__="fake",
    )


# --- buses -------------------------------------------------------------------------------------
TOPOLOGY = """
cycle_time_us = 1000
[[slave]]
kind = "io"
name = "IO A"
do = 16
di = 16
[[slave]]
kind = "io"
name = "Bits B"
do = 4
di = 3
packing = "bits"
[[slave]]
kind = "io"
name = "Bits C"
do = 2
di = 4
packing = "bits"
[[slave]]
kind = "io"
name = "IO D"
do = 8
di = 16
"""


def make_bus(
    topology: str = TOPOLOGY,
    *,
    hw_topology: str | None = None,
    init_cmds: dict[int, tuple[InitCmd, ...]] | None = None,
):
    cfg = parse_topology(topology)
    if init_cmds:
        import dataclasses

        cfg = dataclasses.replace(
            cfg,
            slaves=tuple(
                dataclasses.replace(s, init_cmds=s.init_cmds + init_cmds.get(s.position, ()))
                for s in cfg.slaves
            ),
        )
    layout = build_layout(cfg)
    hw = build_layout(parse_topology(hw_topology)) if hw_topology else layout
    devices = [
        FakeDevice(IoSlave(s.position, s.name, s.identity, rx_pdos=s.rx_pdos, tx_pdos=s.tx_pdos))
        for s in hw.config.slaves
    ]
    lines: list[str] = []
    backend = PysoemBackend("fake0", soem=fake_soem(devices), log=lines.append)
    master = Master(layout, backend, log=lines.append, op_delay_cycles=2)
    return master, backend, devices, lines


def bring_up(master: Master, cycles: int = 5) -> None:
    master.open()
    for k in range(cycles):
        master.cycle(k * 1_000_000, 1_000_000)


# --- tests ---------------------------------------------------------------------------------
def test_bring_up_reaches_op_with_soem_owning_no_state():
    master, backend, devices, lines = make_bus()
    bring_up(master)
    assert master.ready
    assert [d.vs.al_state for d in devices] == [AlState.OP] * 4
    assert backend.master.manual_state_change == 1
    assert backend.expected_wkc() == 4 * 3
    assert any("All slaves are in OP" in x for x in lines)


def test_config_map_runs_after_every_slaves_ps_init_cmds():
    """The IO map is built once, after the PS InitCmds of the last slave ran."""
    seen: list[tuple[str, int]] = []
    cmd = InitCmd(("PS",), 0x8000, 1, b"\x01")
    master, backend, devices, _ = make_bus(init_cmds={0: (cmd,), 3: (cmd,)})
    soem_master_cls = backend._soem_module.Master
    real_map = soem_master_cls.config_map

    def spy_map(self):
        seen.append(("map", len([d for d in devices if d.writes])))
        return real_map(self)

    soem_master_cls.config_map = spy_map
    bring_up(master)
    assert seen == [("map", 2)]  # both slaves' InitCmds were written before the one map
    assert devices[3].od[(0x8000, 1)] == b"\x01"


def test_raw_offsets_match_the_emulated_backend_bit_for_bit():
    """Bit slaves packed by SOEM into shared bytes still land at the GT raw offsets."""
    from gtecat.master.backends.emulated import EmulatedBackend

    master, _, devices, _ = make_bus()
    bring_up(master)
    emu = Master(master.layout, EmulatedBackend(), op_delay_cycles=2)
    bring_up(emu)
    out_pattern = bytes([0xA5, 0x3C])
    for m in (master, emu):
        lay = m.layout.slaves
        m.image.write_raw(lay[0].gt_offset, out_pattern)  # IO A DO
        m.image.write_raw(lay[1].gt_offset, b"\x0b")  # Bits B: 4 bits
        m.image.write_raw(lay[2].gt_offset, b"\x02")  # Bits C: 2 bits
        m.image.write_raw(lay[3].gt_offset, b"\x81")  # IO D
    emu_slaves = emu.backend.slaves
    for devs in ([d.vs for d in devices], emu_slaves):
        devs[0].set_input(0x6000, 1, 0x12)
        devs[0].set_input(0x6000, 2, 0x34)
        for k, on in enumerate((1, 0, 1)):
            devs[1].set_input(0x6000, k + 1, on)
        for k, on in enumerate((0, 1, 1, 0)):
            devs[2].set_input(0x6000, k + 1, on)
        devs[3].set_input(0x6000, 1, 0x55)
    for k in range(3):
        master.cycle(10_000_000 + k, 1_000_000)
        emu.cycle(10_000_000 + k, 1_000_000)
    raw_pysoem = master.image.read_raw(0, master.image.size)
    raw_emu = emu.image.read_raw(0, emu.image.size)
    assert raw_pysoem == raw_emu
    assert devices[1].vs.rx == emu_slaves[1].rx == bytearray(b"\x0b")
    assert devices[2].vs.rx == bytearray(b"\x02")
    assert devices[0].vs.get_output(0x7000, 1) == 0xA5
    assert raw_pysoem[master.layout.slaves[1].gt_offset + 1] == 0b101
    assert raw_pysoem[master.layout.slaves[2].gt_offset + 1] == 0b0110


def test_soem_bit_starts_follow_soem_packing():
    assert soem_bit_starts([16, 4, 2, 8]) == [None, (0, False), (4, False), None]
    assert soem_bit_starts([3, 0, 3, 3]) == [(0, False), None, (3, False), (6, True)]
    assert soem_bit_starts([4, 16, 4]) == [(0, False), None, (0, False)]


def test_no_slave_is_gt_minus_10_with_the_interface_named():
    master, _, devices, _ = make_bus()
    for d in devices:
        d.present = False
    with pytest.raises(NoSlavesError, match="fake0"):
        master.open()


def test_missing_interface_names_the_choices():
    cfg = parse_topology(TOPOLOGY)
    layout = build_layout(cfg)
    backend = PysoemBackend("missing0", soem=fake_soem([]))
    with pytest.raises(BusError, match="missing0"):
        Master(layout, backend).open()
    with pytest.raises(BusError, match="GTECAT_IFACE"):
        Master(layout, PysoemBackend(None, soem=fake_soem([]))).open()


def test_identity_mismatch_names_the_first_difference():
    hw = TOPOLOGY.replace('name = "Bits C"', 'name = "Bits C"\nproduct_code = 0x99')
    master, *_ = make_bus(hw_topology=hw)
    with pytest.raises(
        ConfigMismatch, match=r"slave 2: .*product code 0x0002[0-9A-F]{4}.*0x00000099"
    ):
        master.open()


# IO D with a fixed identity, so hardware with another mapping keeps the ENI's identity
SAME_ID = TOPOLOGY.replace('name = "IO D"', 'name = "IO D"\nproduct_code = 0x00020001')


def test_mapping_read_by_soem_that_differs_from_the_eni_is_a_mismatch():
    hw = SAME_ID.replace("do = 8\ndi = 16", "do = 8\ndi = 8")
    master, _backend, devices, _ = make_bus(SAME_ID, hw_topology=hw)
    with pytest.raises(ConfigMismatch, match=r"slave 3 \(IO D\): the ENI maps 2 input bytes.* 1"):
        master.open()
    assert devices[3].vs.al_state == AlState.PREOP  # never asked for SAFEOP


def test_mismatch_of_a_same_identity_slave_without_mailbox_explains_soem_sii_reuse():
    same = SAME_ID.replace('name = "IO A"', 'name = "IO A"\nproduct_code = 0x00020001')
    hw = same.replace("do = 8\ndi = 16", "do = 8\ndi = 8")
    master, _, devices, _ = make_bus(same, hw_topology=hw)
    devices[3].coe = False
    with pytest.raises(ConfigMismatch, match=r"slave 3 .*same vendor/product/revision as slave 0"):
        master.open()


def test_a_refused_safeop_is_reported_for_the_slave_that_refused():
    master, _, devices, _lines = make_bus()
    devices[1].vs.on_state_change = (  # type: ignore[method-assign]
        lambda old, new: (
            AlStatusCode.INVALID_SYNC_MANAGER_CONFIGURATION
            if new == AlState.SAFEOP
            else AlStatusCode.NO_ERROR
        )
    )
    with pytest.raises(StateError, match=r"slave 1 \(Bits B\): PS refused.*0x0017") as ei:
        master.open()
    assert ei.value.slave == 1


def test_sdo_abort_code_comes_back_as_sdo_abort():
    master, _backend, devices, _ = make_bus()
    bring_up(master)
    devices[0].od[(0x1018, 1)] = (0x47544543).to_bytes(4, "little")
    assert master.sdo_upload(0, 0x1018, 1) == (0x47544543).to_bytes(4, "little")
    devices[0].refuse[(0x6040, 0)] = SdoAbortCode.WRITE_OF_READ_ONLY
    with pytest.raises(SdoAbort) as ei:
        master.sdo_download(0, 0x6040, 0, b"\x06\x00")
    assert ei.value.code == 0x06010002 and (ei.value.index, ei.value.subindex) == (0x6040, 0)
    with pytest.raises(SdoAbort) as ei:
        master.sdo_upload(0, 0x2FFF, 3)
    assert ei.value.code == SdoAbortCode.OBJECT_DOES_NOT_EXIST


def test_sdo_to_a_slave_without_coe_fails_at_once_with_the_reason():
    master, _backend, devices, _ = make_bus()
    devices[2].coe = False
    bring_up(master)
    with pytest.raises(BusError, match=r"slave 2 \(Bits C\) has no CoE mailbox"):
        master.sdo_upload(2, 0x1000, 0)


def test_large_object_is_read_with_a_bigger_buffer():
    master, _backend, devices, _ = make_bus()
    bring_up(master)
    devices[0].od[(0x1008, 0)] = b"x" * 300
    assert master.sdo_upload(0, 0x1008, 0) == b"x" * 300


def test_sdo_without_answer_is_a_bus_error_not_an_abort():
    master, _backend, devices, _ = make_bus()
    bring_up(master)
    devices[0].od[(0x1000, 0)] = b"\0\0\0\0"
    devices[0].present = False
    with pytest.raises(BusError, match="no answer"):
        master.sdo_upload(0, 0x1000, 0)


@pytest.mark.parametrize(
    ("fault", "code", "text"),
    [
        ("lost", SdoAbortCode.SDO_PROTOCOL_TIMED_OUT, "no answer within the mailbox timeout"),
        ("error", SdoAbortCode.GENERAL_ERROR, "mailbox error 4"),
        ("unexpected", SdoAbortCode.GENERAL_ERROR, "packet error 1"),
    ],
)
def test_soem_outcomes_are_the_emulated_bus_codes(fault, code, text):
    """What SOEM reports becomes the abort code the emulated bus gives for the same fault
    (gtecat.drives.abort.MAILBOX_FAILURE_CODES), uploads and downloads alike."""
    master, backend, devices, _ = make_bus()
    backend._monotonic = lambda: backend.master.wall_s
    bring_up(master)
    devices[1].od[(0x1000, 0)] = b"\0\0\0\0"
    for call in (
        lambda: master.sdo_upload(1, 0x1000, 0),
        lambda: master.sdo_download(1, 0x1000, 0, b"\1\0\0\0"),
    ):
        devices[1].mbx_fault[(0x1000, 0)] = fault
        with pytest.raises(SdoAbort, match=text) as e:
            call()
        assert e.value.code == code and (e.value.index, e.value.subindex) == (0x1000, 0)
    assert master.sdo_upload(1, 0x1000, 0) == b"\0\0\0\0"  # the next one is answered


def test_a_transfer_on_the_wire_goes_through_the_controllers_runner():
    """The master hands a wire backend's SDOs to ``mailbox_transfer`` (the controller keeps
    the cycles running there); ``wait=False`` (the inspection verbs) runs them in place."""
    master, backend, devices, _ = make_bus()
    bring_up(master)
    devices[1].od[(0x1000, 0)] = b"\7\0\0\0"
    ran: list[bool] = []

    def runner(transfer):
        ran.append(True)
        return transfer()

    master.mailbox_transfer = runner
    assert backend.mailbox_on_wire
    assert master.sdo_upload(1, 0x1000, 0) == b"\7\0\0\0"
    master.sdo_download(1, 0x1000, 0, b"\1\0\0\0")
    assert len(ran) == 2
    assert master.sdo_upload(1, 0x1000, 0, wait=False) == b"\1\0\0\0"
    assert len(ran) == 2


def test_init_cmd_abort_stops_the_bring_up_with_the_code():
    cmd = InitCmd(("PS",), 0x1C12, 0, b"\x00", comment="clear sm2 pdos")
    master, _backend, devices, _ = make_bus(init_cmds={3: (cmd,)})
    devices[3].refuse[(0x1C12, 0)] = SdoAbortCode.CANNOT_TRANSFER_DEVICE_STATE
    with pytest.raises(StateError, match=r"slave 3.*0x1C12:00.*0x08000022"):
        master.open()


def _run(master: Master, n: int, t0: int = 100_000_000) -> list[bool]:
    ready = []
    for k in range(n):
        master.cycle(t0 + k * 1_000_000, 1_000_000)
        ready.append(master.ready)
    return ready


def test_slave_lost_and_back_recovers_to_op_with_init_cmds_reapplied():
    cmd = InitCmd(("PS",), 0x8000, 1, b"\x07")
    master, backend, devices, lines = make_bus(init_cmds={2: (cmd,)})
    backend.check_interval_ms = 5
    bring_up(master)
    assert master.ready
    devices[2].present = False
    ready = _run(master, 20)
    assert not any(ready)
    assert master.last.wkc == backend.expected_wkc() - 3
    assert any("slave 2 (Bits C) lost" in x for x in lines)
    # the slave runner restarts: power-on state INIT, object dictionary reset
    devices[2].present = True
    devices[2].vs.request_state(AlState.INIT)
    devices[2].od.clear()
    ready = _run(master, 40, t0=200_000_000)
    assert ready[-1]
    assert devices[2].vs.al_state == AlState.OP
    assert devices[2].od[(0x8000, 1)] == b"\x07"  # PS InitCmd re-applied by the reconfig hook
    assert backend.master.reconfigs == [2]
    assert backend.stats.recoveries == 1
    assert any("Working counter back to" in x for x in lines)


def test_safeop_error_is_acknowledged_and_op_requested_again():
    master, backend, devices, lines = make_bus()
    backend.check_interval_ms = 1
    bring_up(master)
    vs = devices[0].vs
    vs.al_state, vs.al_error = AlState.SAFEOP, True
    vs.al_status_code = AlStatusCode.SYNC_MANAGER_WATCHDOG
    ready = _run(master, 6)
    assert ready[-1] and vs.al_state == AlState.OP
    assert any("SAFEOP+ERROR, AL status 0x001B" in x for x in lines)


def test_terminate_goes_to_init_and_closes():
    import sys

    before = sys.getswitchinterval()
    master, backend, devices, _ = make_bus()
    bring_up(master)
    assert sys.getswitchinterval() <= 0.0005  # the cycle thread gets the GIL in time
    soem_master = backend.master
    master.terminate()
    backend.close()
    assert [d.vs.al_state for d in devices] == [AlState.INIT] * 4
    assert soem_master.closed and backend.master is None
    assert sys.getswitchinterval() == before
    backend.close()  # idempotent
    master.terminate()  # GT_Close after GT_TerminateEcatComm: nothing escapes
    with pytest.raises(BusError, match="closed"):
        backend.request_state(0, AlState.INIT)


def test_exchange_before_mapping_sends_nothing():
    master, backend, _devices, _ = make_bus()
    backend.open(master.layout, master.image)
    assert backend.exchange(0, 1_000_000) == 0
    assert backend.master.frames == 0


def test_backend_cycle_stats_are_collected():
    master, backend, _devices, _ = make_bus()
    bring_up(master)
    _run(master, 10)
    assert backend.stats.cycles >= 10
    assert len(backend.stats.rtt_samples()) == backend.stats.cycles


def test_ready_returns_after_recovery_even_if_states_were_read_during_the_outage():
    master, backend, devices, _ = make_bus()
    backend.check_interval_ms = 5
    bring_up(master)
    devices[2].present = False
    _run(master, 20)
    master.refresh_states()  # what GT_GetEcatSlaves / GT_GetEcatSlaveInfo do
    devices[2].present = True
    devices[2].vs.request_state(AlState.INIT)
    ready = _run(master, 40, t0=200_000_000)
    assert master.last.ok
    assert ready[-1]


def test_a_lost_slave_is_offline_from_the_first_short_cycle_and_back_after():
    """Master.offline (comm loss, gtecat.master.bus): one read_state, in the first cycle of
    short working counter, tells who is gone."""
    master, _backend, devices, lines = make_bus()
    bring_up(master)
    devices[2].present = False
    _run(master, 1)
    assert master.offline == {2: "slave 2 (Bits C) does not answer"}
    _run(master, 10, t0=110_000_000)
    assert master.offline == {2: "slave 2 (Bits C) does not answer"}
    assert any("Lost: slave 2 (Bits C) does not answer" in x for x in lines)
    devices[2].present = True
    devices[2].vs.request_state(AlState.INIT)
    ready = _run(master, 200, t0=200_000_000)
    assert ready[-1] and master.offline == {}
    assert any("Back in process data: slaves 2" in x for x in lines)


def test_a_short_stall_of_the_wire_is_not_a_loss():
    master, _backend, devices, _ = make_bus()
    bring_up(master)
    devices[1].present = False
    _run(master, 5)  # 5 lost cycles, then the slave answers again
    devices[1].present = True
    _run(master, 20, t0=200_000_000)
    assert master.offline == {}


def test_backend_states_reads_every_slave_at_once():
    master, backend, devices, _ = make_bus()
    bring_up(master)
    devices[3].present = False
    got = backend.states(4)
    assert [g[0] if g else None for g in got] == [AlState.OP, AlState.OP, AlState.OP, None]


class FakeEmergency(Exception):
    """pysoem.Emergency: error code, register, byte 1, words 2 and 3."""

    def __init__(self, slave_pos: int, error_code: int, error_reg: int, b1: int, w1: int, w2: int):
        super().__init__(slave_pos, error_code)
        self.slave_pos, self.error_code, self.error_reg = slave_pos, error_code, error_reg
        self.b1, self.w1, self.w2 = b1, w1, w2


@pytest.mark.parametrize("callbacks", [True, False], ids=["callback", "raised"])
def test_an_emergency_during_an_sdo_goes_to_the_master_log_and_the_sdo_answers(
    monkeypatch, callbacks: bool
):
    """A CoE emergency (ETG.1000.6 5.6.4) that SOEM receives while it waits for an SDO answer:
    pysoem raises it from sdo_read unless a callback takes it; either way the SDO's answer is
    returned and the emergency is the master log's line, as on the emulated bus."""
    master, backend, devices, lines = make_bus()
    devices[0].od[(0x1018, 1)] = (0x47544543).to_bytes(4, "little")
    pending = [FakeEmergency(1, 0x2310, 0x02, 0x11, 0x3322, 0x5544)]
    handlers: dict[int, object] = {}
    read = FakeSlave.sdo_read

    def sdo_read(self, index, subindex, size=0, ca=False):
        if pending:
            e = pending.pop()
            if self._pos in handlers:
                handlers[self._pos](e)
            else:
                raise e
        return read(self, index, subindex, size, ca)

    monkeypatch.setattr(FakeSlave, "sdo_read", sdo_read)
    if callbacks:
        monkeypatch.setattr(
            FakeSlave,
            "add_emergency_callback",
            lambda self, fn: handlers.__setitem__(self._pos, fn),
            raising=False,
        )
    bring_up(master)
    backend.soem.Emergency = FakeEmergency
    assert master.sdo_upload(0, 0x1018, 1) == (0x47544543).to_bytes(4, "little")
    master.cycle(10_000_000, 1_000_000)
    assert "WARNING 0: CoE EMERGENCY 0x2310 0x02 11 22 33 44 55" in lines
    assert master.emergency_count == 1
