"""``gtecat serve`` against masters nobody here wrote the slaves for.

* a raw-socket master written in the test (:mod:`.rawmaster`) reproduces what
  real masters do that once went wrong: SOEM resending a mailbox write whose
  answer was late, SDO Information with fragments, emergencies, the SII read
  back whole;
* pysoem (SOEM) lists the object dictionary and sees an emergency;
* KickCAT and ebpfcat from PyPI, where they install (skipped with the reason
  otherwise).

Each test module gets its own veth pair and server; every wait is bounded.
"""

from __future__ import annotations

import contextlib
import struct
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from tests.gtecat.wire.rawmaster import (
    RawMaster,
    SdoAbortSeen,
    ServeProcess,
    veth_pair,
    why_not_root,
)

# one `gtecat serve` on one veth pair serves the module: under pytest-xdist (--dist
# loadgroup) it stays on one worker
pytestmark = [pytest.mark.wire, pytest.mark.xdist_group("wire_masters")]

ROOT = Path(__file__).resolve().parents[3]
FIG52 = ROOT / "examples" / "manual_fig5_2.eni"
TWELVE = ROOT / "examples" / "twelve_axes.eni"
FOE_FILE = b"gtecat virtual drive log\n" * 20  # 480 bytes: several FoE packets
TWINCAT = ROOT.parent / "shared" / "fixtures" / "eni" / "twincat_ek1100_el2008_el4002_el1809.xml"

_REASON = why_not_root()
if _REASON:
    pytest.skip(_REASON, allow_module_level=True)


@contextlib.contextmanager
def served(eni: Path, tmp: Path, *extra: str) -> Iterator[tuple[str, ServeProcess]]:
    try:
        pair = veth_pair()
        master_if, slave_if = pair.__enter__()
    except OSError as exc:
        pytest.skip(str(exc))
    try:
        server = ServeProcess(eni, slave_if, tmp / "stats.json", *extra, cwd=ROOT)
        try:
            yield master_if, server
        finally:
            assert server.stop() == 0, server.output
    finally:
        pair.__exit__(None, None, None)


@pytest.fixture(scope="module")
def fig52(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[str, ServeProcess]]:
    tmp = tmp_path_factory.mktemp("fig52")
    (tmp / "log.txt").write_bytes(FOE_FILE)
    extra = ("--rt-priority", "10", "--foe-file", f"log.txt={tmp / 'log.txt'}")
    with served(FIG52, tmp, *extra) as it:
        yield it


@pytest.fixture
def raw(fig52: tuple[str, ServeProcess]) -> Iterator[RawMaster]:
    with RawMaster(fig52[0]) as master:
        yield master


def preop_drive(master: RawMaster) -> tuple[int, tuple[int, int, int, int]]:
    stations = master.scan()
    assert len(stations) == 4
    sm = master.setup_mailbox(stations[0])
    assert master.request_state(stations[0], 2) == (2, 0)
    return stations[0], sm


def u32(data: bytes) -> int:
    return struct.unpack("<I", data[:4])[0]


# --- item 1: a resent mailbox write -------------------------------------------------------------
def test_a_resent_mailbox_write_is_executed_once(raw: RawMaster) -> None:
    """SOEM resends an FPWR of SM0 (same frame, same index, same mailbox counter) when its
    answer is late; the slave must not answer twice (issue 16, item 1)."""
    station, sm = preop_drive(raw)
    request = raw.mailbox_message(station, 3, struct.pack("<HBHB4x", 2 << 12, 0x40, 0x1018, 1))
    frame = raw.frame(5, 0x42, station, sm[0], request.ljust(sm[1], b"\0"))  # FPWR
    raw.send_raw(frame)
    first = raw.receive(0x42, time.monotonic() + 1)
    assert first is not None and first.wkc == 1
    deadline = time.monotonic() + 1  # the firmware takes the message: SM0 empties
    while raw.fprd(station, 0x0805, 1).data[0] & 0x08:
        assert time.monotonic() < deadline
    raw.send_raw(frame)  # the resend of the "late" frame
    second = raw.receive(0x42, time.monotonic() + 1)
    assert second is not None and second.wkc == 1  # the ESC takes the write ...
    answer = raw.mbx_read(station, sm)
    assert answer is not None and answer[8] == 0x43, answer  # expedited upload of 4 bytes
    vendor = u32(answer[12:])
    assert raw.mbx_read(station, sm, timeout=0.1) is None  # ... and the firmware answers once
    product = raw.sdo_upload(station, sm, 0x1018, 2)
    # the answers are not one behind: 1018:01 is the vendor id the SII states
    assert vendor == raw.sii_word(station, 0x08) | raw.sii_word(station, 0x09) << 16
    assert u32(product) == raw.sii_word(station, 0x0A) | raw.sii_word(station, 0x0B) << 16


# --- item 3: SDO Information --------------------------------------------------------------------
def test_sdo_information_lists_and_describes_the_dictionary(raw: RawMaster) -> None:
    station, sm = preop_drive(raw)
    words = raw.sii_word(station, 0x1C)
    assert words & 0x04  # CoE
    frags = raw.sdo_info(station, sm, 0x01, struct.pack("<H", 1))
    assert len(frags) > 1  # the list does not fit one mailbox: fragments, counted down
    data = b"".join(frags)
    assert struct.unpack_from("<H", data)[0] == 1
    indices = list(struct.unpack(f"<{len(data) // 2 - 1}H", data[2:]))
    assert indices == sorted(indices) and {0x1000, 0x1018, 0x6040, 0x6041} <= set(indices)
    (desc,) = raw.sdo_info(station, sm, 0x03, struct.pack("<H", 0x6041))
    index, dtype, max_sub, code = struct.unpack_from("<HHBB", desc)
    assert (index, dtype, max_sub, code) == (0x6041, 0x0006, 0, 7)
    assert desc[6:].lower().startswith(b"statusword")
    (entry,) = raw.sdo_info(station, sm, 0x05, struct.pack("<HBB", 0x6041, 0, 0x07))
    index, sub, _vi, dtype, bits, access = struct.unpack_from("<HBBHHH", entry)
    assert (index, sub, dtype, bits) == (0x6041, 0, 0x0006, 16)
    assert access & 0x0007 == 0x0007 and not access & 0x0038 and access & 0x0080
    (err,) = raw.sdo_info(station, sm, 0x03, struct.pack("<H", 0x5555))
    assert u32(err) == 0x06020000
    with pytest.raises(SdoAbortSeen) as abort:
        raw.sdo_upload(station, sm, 0x5555, 0)
    assert abort.value.code == 0x06020000


def test_pysoem_reads_the_object_dictionary(fig52: tuple[str, ServeProcess]) -> None:
    pysoem = pytest.importorskip("pysoem")
    master = pysoem.Master()
    master.open(fig52[0])
    try:
        assert master.config_init() == 4
        drive = master.slaves[0]
        od = drive.od
        by_index = {obj.index: obj for obj in od}
        assert {0x1000, 0x1018, 0x6040, 0x6041, 0x607A} <= set(by_index)
        assert by_index[0x1018].name == b"Identity" and by_index[0x1018].object_code == 9
        names = [e.name for e in by_index[0x1018].entries]
        assert b"Vendor ID" in names
        assert by_index[0x6041].data_type == pysoem.ECT_UNSIGNED16
        assert struct.unpack("<I", drive.sdo_read(0x1018, 1))[0] == drive.man
    finally:
        master.close()


# --- item 5: the SII read back over the wire ----------------------------------------------------
def _crc8(data: bytes) -> int:
    crc = 0xFF
    for b in data:
        crc ^= b
        for _ in range(8):
            crc = ((crc << 1) ^ 0x07) & 0xFF if crc & 0x80 else (crc << 1) & 0xFF
    return crc


def test_the_sii_lists_the_drive_mapping_and_the_eni_sm_layout(raw: RawMaster) -> None:
    stations = raw.scan()
    sii = raw.sii(stations[0])
    assert sii[14] == _crc8(sii[:14])
    cats: dict[int, bytes] = {}
    pos = 128
    while pos + 4 <= len(sii):
        ctype, words = struct.unpack_from("<HH", sii, pos)
        if ctype == 0xFFFF:
            break
        cats[ctype] = sii[pos + 4 : pos + 4 + 2 * words]
        pos += 4 + 2 * words
    sms = [struct.unpack_from("<HHBBBB", cats[41], 8 * k) for k in range(len(cats[41]) // 8)]
    assert [(s[0], s[2], s[5]) for s in sms] == [
        (0x1000, 0x26, 1),
        (0x1080, 0x22, 2),
        (0x1100, 0x64, 3),
        (0x1400, 0x20, 4),
    ]
    tx = cats[50]
    n_entries = tx[2]
    assert [struct.unpack_from("<H", tx, 8 + 8 * k)[0] for k in range(n_entries)] == [
        0x6041,
        0x6064,
        0x60FD,
    ]
    assert cats[30][5] & 0x02  # CoE details: SDO Information


# --- CoE emergencies on the wire ----------------------------------------------------------------
@pytest.mark.long
def test_pysoem_sees_the_emergency_of_a_faulting_drive(tmp_path: Path) -> None:
    pysoem = pytest.importorskip("pysoem")
    with served(FIG52, tmp_path) as (master_if, _server):
        master = pysoem.Master()
        master.open(master_if)
        try:
            assert master.config_init() == 4
            master.config_map()
            drive = master.slaves[0]
            seen: list = []
            drive.add_emergency_callback(seen.append)
            drive.sdo_write(0x6065, 0, struct.pack("<I", 10))  # following error window, counts
            drive.sdo_write(0x6066, 0, struct.pack("<H", 0))  # ... and its timeout, ms
            assert master.state_check(pysoem.SAFEOP_STATE, 2_000_000) == pysoem.SAFEOP_STATE
            master.state = pysoem.OP_STATE
            master.write_state()
            deadline = time.monotonic() + 5
            while master.state_check(pysoem.OP_STATE, 10_000) != pysoem.OP_STATE:
                master.send_processdata()
                master.receive_processdata(50_000)
                assert time.monotonic() < deadline, "no OP"
            start = struct.unpack_from("<i", drive.input, 2)[0]
            for cw in (0x0006, 0x0007, 0x000F) + (0x000F,) * 10:
                drive.output = struct.pack("<Hi", cw, start)
                master.send_processdata()
                master.receive_processdata(50_000)
            drive.output = struct.pack("<Hi", 0x000F, start + 1_000_000)  # far beyond the window
            deadline = time.monotonic() + 5
            while not seen and time.monotonic() < deadline:
                master.send_processdata()
                master.receive_processdata(50_000)
                drive.mbx_receive()  # SOEM hands an emergency in the mailbox to the callback
            assert seen, "no emergency reached the master"
            assert (seen[0].error_code, seen[0].error_reg) == (0x8611, 0x01)
            assert struct.unpack_from("<H", drive.input)[0] & 0x0008  # fault (reaction) bit
        finally:
            master.state = pysoem.INIT_STATE
            master.write_state()
            master.close()


# --- KickCAT and ebpfcat (PyPI) -------------------------------------------------------------------
@pytest.mark.long
def test_kickcat_maps_reads_the_dictionary_and_runs_in_op(fig52: tuple[str, ServeProcess]) -> None:
    kickcat = pytest.importorskip(
        "kickcat", reason="kickcat is not installed (pip install kickcat)"
    )
    from datetime import timedelta

    link = kickcat.create_link(fig52[0], "")
    # 10 ms timed out once on a loaded box; 50 ms cost 5 s (KickCAT waits out timeouts as it scans)
    link.set_timeout(timedelta(milliseconds=20))
    bus = kickcat.Bus(link)
    bus.init(0.1)
    assert [s.address for s in bus.slaves()] == [1001, 1002, 1003, 1004]
    bus.create_mapping()
    slaves = bus.slaves()  # after the mapping: the slaves as configured
    assert [(s.input_size, s.output_size) for s in slaves] == [(10, 6), (10, 6), (2, 2), (2, 2)]
    drive = slaves[0]
    vendor = bus.read_sdo(drive, 0x1018, 1, kickcat.Access.PARTIAL, 4, 1.0)
    assert struct.unpack("<I", vendor)[0] == eni_vendor()
    name, _ = bus.read_object_description(drive, 0x1018)
    assert name == "Identity"
    entry, text = bus.read_entry_description(drive, 0x6041, 0)
    assert entry == "Statusword" and "TxPDO" in text
    bus.request_state(kickcat.State.SAFE_OP)
    bus.wait_for_state(kickcat.State.SAFE_OP, 2.0)
    bus.request_state(kickcat.State.OPERATIONAL)
    bus.wait_for_state(kickcat.State.OPERATIONAL, 2.0, bus.process_data)
    lost = []
    for _ in range(100):
        try:
            bus.process_data()  # raises on a wrong working counter
        except RuntimeError as e:  # a frame late on a loaded machine: a master goes on
            lost.append(str(e))
    assert len(lost) <= 5, lost
    assert all(bus.get_state(s) == kickcat.State.OPERATIONAL for s in slaves)
    status = struct.unpack_from("<H", drive.input_data)[0]
    assert status & 0x004F == 0x0040  # SWITCH ON DISABLED: a CiA-402 drive after power-on


def eni_vendor() -> int:
    from gtecat.eni.reader import read_eni

    return read_eni(FIG52).slaves[0].identity.vendor_id


@pytest.mark.long
def test_ebpfcat_initialises_lists_the_dictionary_and_cycles(
    fig52: tuple[str, ServeProcess],
) -> None:
    pytest.importorskip("ebpfcat", reason="ebpfcat is not installed (pip install ebpfcat)")
    import asyncio

    from ebpfcat.ethercat import ECCmd, EtherCat, MachineState, Terminal

    def signed(address: int) -> int:  # ebpfcat packs the low address word as a signed short
        address &= 0xFFFF
        return address - 0x10000 if address >= 0x8000 else address

    async def session() -> tuple[dict, list, bytes]:
        ec = EtherCat(fig52[0])
        await ec.connect()
        assert await ec.count() == 4
        terms = [Terminal(ec) for _ in range(4)]
        for i, t in enumerate(terms):
            await asyncio.wait_for(t.initialize(-i, 1001 + i), 5)
        drive = terms[0]
        await drive.to_operational(MachineState.PRE_OPERATIONAL)
        assert (await drive.sdo_read(0x1008, 0)).startswith(b"GTHD")
        od = await asyncio.wait_for(drive.read_ODlist(), 30)
        areas = []
        for t in terms:
            out = ec.get_fmmu_addr()
            inp = ec.get_fmmu_addr()
            await t.map_fmmu(out, True).__aenter__()
            await t.map_fmmu(inp, False).__aenter__()
            areas.append((out, inp))

        async def cycle(outputs: bool) -> list[bytes]:
            got = []
            for t, (out, inp) in zip(terms, areas, strict=True):
                if outputs:
                    data = bytes(t.pdo_out_sz)
                    await ec.roundtrip(ECCmd.LWR, signed(out), out >> 16, data=data)
                got.append(await ec.roundtrip(ECCmd.LRD, signed(inp), inp >> 16, data=t.pdo_in_sz))
            return got

        for t in terms:
            await t.to_operational(MachineState.SAFE_OPERATIONAL)
        await cycle(False)
        for t in terms:
            await t.to_operational(MachineState.OPERATIONAL)
        for _ in range(50):
            inputs = await cycle(True)  # raises EtherCatError on a zero working counter
        states = [await t.get_state() for t in terms]
        return od, states, inputs[0]

    od, states, drive_inputs = asyncio.run(asyncio.wait_for(session(), 90))
    assert {0x1000, 0x1018, 0x6040, 0x6041} <= set(od)
    assert od[0x1018].name == "Identity" and od[0x1018].entries[1].name == "Vendor ID"
    assert [s[0] for s in states] == [MachineState.OPERATIONAL] * 4
    assert len(drive_inputs) == 10


@pytest.mark.long
def test_pysoem_foe_reads_a_file_and_gets_not_found_for_another(
    fig52: tuple[str, ServeProcess],
) -> None:
    pysoem = pytest.importorskip("pysoem")
    master = pysoem.Master()
    master.open(fig52[0])
    try:
        assert master.config_init() == 4
        drive = master.slaves[0]
        drive.state = pysoem.PREOP_STATE
        assert drive.foe_read("log.txt", 0, 4096) == FOE_FILE
        # SOEM ends the read on the FoE error 8001h (not found) and pysoem returns nothing
        assert drive.foe_read("firmware.efw", 0, 4096) == b""
    finally:
        master.close()
