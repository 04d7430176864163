"""``gtecat serve --pcap``: every frame in and out, in a file tshark reads without "Malformed"."""

from __future__ import annotations

import shutil
import struct
import subprocess
import time
from pathlib import Path

import pytest

from gtecat.master.pcap import MAGIC_NS, PcapWriter, read_pcap

ROOT = Path(__file__).resolve().parents[3]
FIG52 = ROOT / "examples" / "manual_fig5_2.eni"


def test_writer_and_reader_agree(tmp_path: Path) -> None:
    path = tmp_path / "x.pcap"
    frames = [(1_700_000_000_123_456_789, b"\xff" * 6 + b"\x02" * 6 + b"\x88\xa4" + bytes(46))]
    frames.append((frames[0][0] + 1000, bytes(range(60))))
    with PcapWriter(path) as pcap:
        for t, f in frames:
            pcap.write(f, t)
    raw = path.read_bytes()
    assert struct.unpack_from("<IHHiIII", raw) == (MAGIC_NS, 2, 4, 0, 0, 65535, 1)
    assert read_pcap(path) == frames


def test_times_never_go_back(tmp_path: Path) -> None:
    """A request stamped with its kernel receive time after the previous answer's send time
    (it waited in the socket meanwhile) is recorded at that answer's time: a capture's times
    never decrease (an outside check found 12 % of a burst's records going back)."""
    path = tmp_path / "x.pcap"
    frame = bytes(60)
    with PcapWriter(path) as pcap:
        pcap.write(frame, 1_000_000)  # request 1, kernel time
        pcap.write(frame, 1_030_000)  # answer 1, sent
        pcap.write(frame, 1_010_000)  # request 2, arrived while answer 1 was being made
        pcap.write(frame, 1_050_000)  # answer 2
    times = [t for t, _ in read_pcap(path)]
    assert times == [1_000_000, 1_030_000, 1_030_000, 1_050_000]


def tshark_check(path: Path) -> str:
    tshark = shutil.which("tshark")
    if tshark is None:
        pytest.skip("tshark is not installed (Debian: apt-get install tshark)")
    out = subprocess.run(
        [tshark, "-r", str(path), "-V"], capture_output=True, text=True, timeout=120
    )
    assert out.returncode == 0, out.stderr
    text = out.stdout
    assert "Malformed" not in text, next(ln for ln in text.splitlines() if "Malformed" in ln)
    assert "EtherCAT" in text
    return text


@pytest.mark.wire
@pytest.mark.long
def test_serve_captures_a_pysoem_session_tshark_decodes(tmp_path: Path) -> None:
    from tests.gtecat.wire.rawmaster import ServeProcess, veth_pair, why_not_root

    reason = why_not_root()
    if reason:
        pytest.skip(reason)
    pysoem = pytest.importorskip("pysoem")
    pcap = tmp_path / "session.pcap"
    try:
        pair = veth_pair("gp")
        master_if, slave_if = pair.__enter__()
    except OSError as exc:
        pytest.skip(str(exc))
    try:
        server = ServeProcess(FIG52, slave_if, tmp_path / "s.json", "--pcap", str(pcap), cwd=ROOT)
        try:
            master = pysoem.Master()
            master.open(master_if)
            try:
                assert master.config_init() == 4
                master.config_map()
                master.slaves[0].sdo_read(0x1008, 0)
                master.state = pysoem.OP_STATE
                master.write_state()
                deadline = time.monotonic() + 5
                while master.state_check(pysoem.OP_STATE, 10_000) != pysoem.OP_STATE:
                    master.send_processdata()
                    master.receive_processdata(50_000)
                    assert time.monotonic() < deadline
                for _ in range(50):
                    master.send_processdata()
                    master.receive_processdata(50_000)
            finally:
                master.state = pysoem.INIT_STATE
                master.write_state()
                master.close()
        finally:
            assert server.stop() == 0, server.output
    finally:
        pair.__exit__(None, None, None)
    records = read_pcap(pcap)
    import json

    report = json.loads((tmp_path / "s.json").read_text())
    assert len(records) == report["received"] + report["sent"]
    stamps = [t for t, _ in records]  # requests carry their kernel receive time: records are
    # in processing order, a frame that waited may be stamped before the answer written first
    assert abs(stamps[0] / 1e9 - time.time()) < 600 and max(stamps) - min(stamps) < 60e9
    lrw = [f for _, f in records if len(f) > 16 and f[16] == 12]
    assert len(lrw) >= 100  # requests and answers of the cycles
    text = tshark_check(pcap)
    assert "LRW" in text and "Mailbox" in text


# --- the emulated backend: the frames a real master would have exchanged --------------------------
def _wkc(frame: bytes) -> int:
    length = struct.unpack_from("<H", frame, 22)[0] & 0x07FF  # the first datagram's length
    return struct.unpack_from("<H", frame, 26 + length)[0]


def test_emulated_bus_capture_decodes_without_malformed(tmp_path: Path) -> None:
    import ctypes

    from gtecat import gt

    pcap = tmp_path / "emulated.pcap"
    log = str(tmp_path / "g.log")
    assert gt.GT_Open(eni=str(FIG52), clock="lockstep", log=log, pcap=str(pcap)) == 0
    try:
        assert gt.GT_InitEcatComm() == 0
        status = ctypes.c_short()
        for _ in range(200):
            gt.GTE_Wait(10)
            if gt.GT_IsEcatReady(ctypes.byref(status)) == 0 and status.value == 1:
                break
        assert status.value == 1
        buf = (ctypes.c_ubyte * 4)()
        size = ctypes.c_uint32()
        assert gt.GT_EcatSDOUpload(0, 0x1018, 1, buf, 4, ctypes.byref(size)) == 0
        gt.GTE_Wait(20)
    finally:
        gt.GT_Close()
    records = read_pcap(pcap)
    frames = [f for _, f in records]
    assert [f[16] for f in frames[:2]] == [7, 7]  # the scan: BRD out, BRD back
    assert _wkc(frames[1]) == 4
    sent = [f for f in frames if not f[6] & 0x02]
    answered = [f for f in frames if f[6] & 0x02]
    assert len(sent) == len(answered) and len(frames) > 100
    commands = {f[16] for f in frames}
    assert {12, 5, 4} <= commands  # LRW cycles, state and mailbox writes, reads
    assert _wkc([f for f in answered if f[16] == 12][-2]) == 12  # in OP: 4 x (2 + 1)
    upload = [f for f in sent if f[16] == 5 and struct.unpack_from("<H", f, 20)[0] == 0x1000]
    assert upload and upload[-1][26 + 6 + 2] == 0x40  # an SDO upload request in SM0
    tshark_check(pcap)


def test_an_image_larger_than_a_frame_is_captured_in_several(tmp_path: Path) -> None:
    """90 drives: 630 output and 990 input bytes, 1,620 bytes of LRW: two frames, 1,484 bytes
    (the most one datagram holds) and 136.  Each answer's working counter counts the slaves
    whose bytes it carries: all 90 outputs (+2 each) and inputs of drives 0..77 (+1), then
    drives 77..89 (drive 77's 11 input bytes straddle the cut: it answers in both)."""
    import ctypes

    from gtecat import gt
    from tools.gen_axes_eni import write_axes_eni

    eni = write_axes_eni(90, tmp_path / "axes90.eni")
    pcap = tmp_path / "big.pcap"
    assert gt.GT_Open(eni=str(eni), clock="lockstep", log="", pcap=str(pcap)) == 0
    try:
        assert gt.GT_InitEcatComm() == 0, gt.GTE_GetLastError()
        status = ctypes.c_short()
        for _ in range(200):
            assert gt.GTE_Wait(10) == 0, gt.GTE_GetLastError()
            if gt.GT_IsEcatReady(ctypes.byref(status)) == 0 and status.value == 1:
                break
        assert status.value == 1
        assert gt.GTE_Wait(2) == 0
    finally:
        gt.GT_Close()
    frames = [f for _, f in read_pcap(pcap)]
    assert max(len(f) for f in frames) <= 1514
    lrw = [f for f in frames if f[16] == 12 and f[6] & 0x02]
    last = lrw[-2:]
    addresses = [struct.unpack_from("<I", f, 18)[0] for f in last]
    lengths = [struct.unpack_from("<H", f, 22)[0] & 0x07FF for f in last]
    assert (addresses, lengths) == ([0, 1484], [1484, 136])
    assert [_wkc(f) for f in last] == [90 * 2 + 78, 13]
