"""What a bring-up reads of its machine description, and what its master log says of it.

An outside differential check saw, about once in a few hundred bring-ups of one program with
the axis bank off, GT raw byte 238 (axis 8's 60FDh bit 17: its touch-probe 2 input, active
where the axis stands) read 0 instead of 2 - or 2 instead of 0 - in the first sample.  The
cause was outside the emulator: the check's fuzzer rewrote the very machine description file
the runs read (``Path.write_text``: truncate, then write) once per case, in processes running
beside them, so now and then GT_Open read the file between the truncate and the write: empty,
every axis with the defaults.  These tests force that condition: the file read empty gives
exactly that symptom and nothing else, and the master log names what each run read (the
file's digest, the axes it describes), so two runs that differ show whether their inputs did.
"""

from __future__ import annotations

from ctypes import byref, c_long, c_ubyte
from pathlib import Path

import pytest

from gtecat import gt
from tests.gtecat.gt.conftest import bring_up

ROOT = Path(__file__).resolve().parents[3]
ENI = ROOT / "examples" / "twelve_axes.eni"
#: the outside check's machine: probe-2 marks around axis 8's power-on position, and switches
#: and probe marks elsewhere that the axes, standing at 0, do not meet
MACHINE = """\
[axis.3]
probe1 = [[1000, 1500], [6000, 6040]]
index_offset = 250
[axis.5]
home_switch = [[2000, 4000], [9000, 9500]]
positive_limit = 12000
[axis.8]
probe2 = [[-3000, 3000]]
index_offset = -75
counts_per_rev = 1000
positive_limit = 15000
"""
#: axis 8's 60FDh (channel 3 of slave 4, 0x78FD) in the GT raw image, its byte of bits 16..23
DIN8_BITS_16_23 = 238


def _first_sample(machine: str) -> tuple[bytes, list[int], list[str]]:
    """The outside check's program: bring-up with the bank off, every axis on in Trap, one
    GT call, one cycle; the GT raw image, the status words and the master log."""
    gt.GT_Close()
    try:
        bring_up(str(ENI), machine=machine, clock="lockstep", bank="off")
        for a in range(1, 13):
            assert gt.GT_AxisOn(a) == 0 and gt.GT_PrfTrap(a) == 0
        gt.GT_GetPos(1, byref(c_long()))
        gt.GTE_Wait(1)
        size = gt.GTE_Controller().layout.gt_raw_bytes
        raw = (c_ubyte * size)()
        assert gt.GT_GetEcatRawData(0, size, raw) == 0
        sts = (c_long * 12)()
        assert gt.GT_GetSts(1, sts, 12) == 0
        return bytes(raw), list(sts), list(gt.GTE_Controller().log.lines)
    finally:
        gt.GT_Close()


@pytest.fixture(scope="module")
def runs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, tuple]:
    folder = tmp_path_factory.mktemp("machine_read")
    full = folder / "machine.toml"
    full.write_text(MACHINE, encoding="utf-8")
    empty = folder / "empty.toml"  # (the file as a reader finds it mid-rewrite)
    empty.write_bytes(b"")
    return {"full": _first_sample(str(full)), "empty": _first_sample(str(empty))}


def test_a_machine_file_read_empty_is_the_outside_checks_first_sample_flake(runs):
    (raw_full, sts_full, _), (raw_empty, sts_empty, _) = runs["full"], runs["empty"]
    differ = [k for k in range(len(raw_full)) if raw_full[k] != raw_empty[k]]
    assert differ == [DIN8_BITS_16_23], differ
    assert raw_full[DIN8_BITS_16_23] == 2  # 60FDh bit 17: probe-2 input active at 0
    assert raw_empty[DIN8_BITS_16_23] == 0
    assert sts_full == sts_empty


def test_the_same_description_gives_the_same_first_sample(runs, tmp_path):
    again = tmp_path / "again.toml"
    again.write_text(MACHINE, encoding="utf-8")
    raw, sts, _ = _first_sample(str(again))
    assert (raw, sts) == runs["full"][:2]


def test_the_master_log_names_the_description_each_run_read(runs):
    def note(lines: list[str]) -> str:
        (line,) = [x for x in lines if "Machine description" in x]
        return line

    full, empty = note(runs["full"][2]), note(runs["empty"][2])
    assert "axes described: 3, 5, 8." in full
    assert "is empty: every axis has the defaults" in empty
    digest = full.split("(sha256 ")[1][:16]
    assert len(digest) == 16 and digest not in empty
    # (the log keeps this line first: what the drives were built from, before the scan)
    assert runs["full"][2][0] == full and "Scanning bus" in runs["full"][2][1]


def test_no_line_without_a_file():
    gt.GT_Close()
    assert gt.GT_Open(eni=str(ENI), clock="lockstep", log="") == 0
    try:
        assert gt.GT_InitEcatComm() == 0
        assert not [x for x in gt.GTE_Controller().log.lines if "Machine description" in x]
    finally:
        gt.GT_Close()
