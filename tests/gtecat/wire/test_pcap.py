"""``gtecat serve --pcap``: every frame in and out, in a file tshark reads without "Malformed"."""

from __future__ import annotations

import shutil
import struct
import subprocess
import time
from pathlib import Path

import pytest

from gtecat.wire.pcap import MAGIC_NS, PcapWriter, read_pcap

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
