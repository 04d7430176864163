"""Python code written for the vendor DLL, loading libgts through ctypes: same calls, same
pointer habits (byref, arrays, string buffers, None for NULL), same codes.

The library lives once per process: every test ends with GT_Close (which detaches), and
the tests that need a controller of their own name it through GTECAT_CONTROLLER.
"""

from __future__ import annotations

import ctypes
import os
import signal
import subprocess
import sys
import time
from ctypes import byref, c_char_p, c_double, c_long, c_short, c_ulong, create_string_buffer
from pathlib import Path

import pytest

from gtecat import gt
from tests.conftest import is_setting

from .conftest import FIG5_2, needs_cc

pytestmark = needs_cc


@pytest.fixture(scope="module")
def lib(libgts):
    dll = ctypes.CDLL(str(libgts.library))
    yield dll
    _end_private_controllers()


def _end_private_controllers() -> None:
    """End the controllers the library started for this process.  GT_Close detaches, and a
    private controller runs its bus until the program ends, as a card does: here the
    program is the test process, whose run goes on for minutes after this module.  (A
    later GT_Open of the library finds its controller gone and starts another.)"""
    me = os.getpid()
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            ppid = int(stat.read_text().rsplit(")", 1)[1].split()[1])
            if ppid != me or b"--private" not in stat.with_name("cmdline").read_bytes():
                continue
            pid = int(stat.parent.name)
            os.kill(pid, signal.SIGTERM)
            os.waitpid(pid, 0)
        except (OSError, ValueError, IndexError, ChildProcessError):
            continue


@pytest.fixture
def env(monkeypatch):
    for k in list(os.environ):
        if is_setting(k):
            monkeypatch.delenv(k)
    monkeypatch.setenv("GTECAT_ENI", str(FIG5_2))
    monkeypatch.setenv("GTECAT_CLOCK", "auto")
    monkeypatch.setenv("GTECAT_LOG", "")
    return monkeypatch


def last_error(lib) -> str:
    buf = create_string_buffer(512)
    assert lib.GTE_GetLastError(buf, 512) == 0
    return buf.value.decode()


def bring_up(lib) -> None:
    assert lib.GTN_Open(5, 1) == 0, last_error(lib)  # the vendor's GTN_Open(channel, param)
    assert lib.GTN_InitEcatComm(1) == 0, last_error(lib)
    status = c_short()
    for _ in range(100):
        if lib.GTN_IsEcatReady(1, byref(status)) == 0 and status.value == 1:
            break
        time.sleep(0.02)
    assert status.value == 1
    assert lib.GTN_StartEcatComm(1) == 0


def test_the_vendor_sequence_through_ctypes(lib, env):
    bring_up(lib)
    try:
        raw = (ctypes.c_ubyte * 2)(0x11, 0x22)
        assert lib.GTN_SetEcatRawData(1, 36, 2, raw) == 0
        back = (ctypes.c_ubyte * 2)()
        assert lib.GTN_GetEcatRawData(1, 36, 2, back) == 0
        assert list(back) == [0x11, 0x22]
        assert lib.GTN_SetEcatRawData(1, 38, 2, raw) == 7  # slave 3's input bytes
        assert lib.GTN_ClrSts(1, 2, 1) == 0
        assert lib.GTN_AxisOn(1, 2) == 0
        sts = c_long()
        for _ in range(200):
            lib.GTN_GetSts(1, 2, byref(sts), 1, None)
            if sts.value & (1 << 9):
                break
            time.sleep(0.005)
        assert sts.value & (1 << 9)
        # Trap: gt's own ctypes structure has the C layout
        prm = gt.TTrapPrm()
        assert lib.GTN_PrfTrap(1, 2) == 0
        assert lib.GTN_GetTrapPrm(1, 2, byref(prm)) == 0
        prm.acc, prm.dec, prm.smoothTime = 1.0, 1.0, 0
        assert lib.GTN_SetTrapPrm(1, 2, byref(prm)) == 0
        assert lib.GTN_SetVel(1, 2, c_double(40.0)) == 0
        assert lib.GTN_SetPos(1, 2, c_long(-15000)) == 0
        assert lib.GTN_Update(1, c_long(1 << 1)) == 0
        for _ in range(1000):
            time.sleep(0.01)
            lib.GTN_GetSts(1, 2, byref(sts), 1, None)
            if not sts.value & (1 << 10):
                break
        prf, enc, clock = c_double(), c_double(), c_ulong()
        assert lib.GTN_GetPrfPos(1, 2, byref(prf), 1, byref(clock)) == 0
        assert lib.GTN_GetEncPos(1, 2, byref(enc), 1, None) == 0
        assert (prf.value, enc.value) == (-15000.0, -15000.0)
        assert clock.value > 0
        # SDO with the abort code of a missing object
        target = create_string_buffer(8)
        size, abort = c_ulong(), c_ulong()
        rc = lib.GTN_EcatSDOUpload(1, 1, 0x6041, 0, target, 8, byref(size), byref(abort))
        assert (rc, size.value, abort.value) == (0, 2, 0)
        rc = lib.GTN_EcatSDOUpload(1, 1, 0x1234, 0, target, 8, byref(size), byref(abort))
        assert (rc, abort.value) == (1, 0x06020000)
        assert "0x06020000" in last_error(lib)
        assert lib.GTN_EcatSDOUpload(1, 1, 0x6041, 0, target, 8, None, None) == 0
        # NULL where required, a bad core, a bad axis: the Python codes (restype int works)
        assert lib.GTN_GetSts(1, 1, None, 1, None) == 7
        assert lib.GTN_GetSts(3, 1, byref(sts), 1, None) == 7
        assert "core 3" in last_error(lib)
        assert lib.GT_GetSts(40, byref(sts), 1, None) == 7
        lib.GT_GetSts.restype = c_short
        assert lib.GT_GetSts(1, byref(sts), 1, None) == 0
        version = c_char_p()  # the vendor header's char **: the library sets the pointer
        assert lib.GT_GetVersion(byref(version)) == 0
        assert version.value == b"010 261201 010 261201"  # table 11-3
    finally:
        assert lib.GT_Close() == 0
    assert lib.GT_GetSts(1, byref(sts), 1, None) == -1
    assert lib.GT_Close() == 0  # closing twice is fine, as in Python


@pytest.fixture
def controller(env, tmp_path):
    """A controller of the test's own, named through GTECAT_CONTROLLER."""
    address = f"unix:{tmp_path}/c.sock"
    proc = subprocess.Popen(
        [sys.executable, "-m", "gtecat", "controller", "--listen", address],
        env=dict(os.environ),
        stderr=subprocess.PIPE,
    )
    from gtecat.native.server import wait_for

    try:
        wait_for(address, 60)
        env.setenv("GTECAT_CONTROLLER", address)
        yield proc
    finally:
        if proc.poll() is None:
            proc.send_signal(signal.SIGCONT)
            proc.terminate()
        proc.wait(10)
        proc.stderr.close()


def test_cdll_declares_the_table_so_0_is_null(libgts, env):
    from gtecat import native

    typed = native.cdll()
    assert typed.GT_GetSts.restype is ctypes.c_short
    bring_up(typed)
    try:
        sts, target = c_long(), create_string_buffer(8)
        assert typed.GTN_GetSts(1, 1, byref(sts), 1, 0) == 0
        assert typed.GTN_EcatSDOUpload(1, 0, 0x6041, 0, target, 8, 0, 0) == 0
        assert typed.GTN_GetSts(1, 1, 0, 1, 0) == 7
        assert typed.GT_GetSts(1, byref(sts), 1, None) == 0
    finally:
        typed.GT_Close()


@pytest.mark.long
def test_a_dead_controller_makes_calls_return_minus_1(lib, controller):
    sts = c_long()
    assert lib.GT_Open(0, 1) == 0, last_error(lib)
    assert lib.GT_GetSts(1, byref(sts), 1, None) in (0, 1)
    controller.kill()
    controller.wait(10)
    t = time.monotonic()
    assert lib.GT_GetSts(1, byref(sts), 1, None) == -1
    assert time.monotonic() - t < 5
    text = last_error(lib)
    assert "controller not responding" in text, text
    assert lib.GT_GetClock(byref(c_ulong()), None) == -1  # and every later call
    assert "controller not responding" in last_error(lib)
    assert lib.GT_Close() == 0
    assert lib.GT_Open(0, 1) == -1  # nothing listens any more
    assert "cannot reach the controller" in last_error(lib)


@pytest.mark.long
def test_a_stopped_controller_times_out(lib, controller, env):
    sts = c_long()
    assert lib.GT_Open(0, 1) == 0, last_error(lib)
    env.setenv("GTECAT_TIMEOUT_MS", "300")  # read at each call: the open has its default
    controller.send_signal(signal.SIGSTOP)
    try:
        t = time.monotonic()
        assert lib.GT_GetSts(1, byref(sts), 1, None) == -1
        assert 0.25 < time.monotonic() - t < 5
        assert "within 300 ms" in last_error(lib)
    finally:
        controller.send_signal(signal.SIGCONT)
        lib.GT_Close()


@pytest.mark.long
def test_several_clients_share_one_controller(lib, controller, libgts, tmp_path):
    """The test process and a second process attach to the same controller at once."""
    assert lib.GT_Open(0, 1) == 0
    try:
        assert lib.GT_InitEcatComm() == 0
        status = c_short()
        for _ in range(100):
            if lib.GT_IsEcatReady(byref(status)) == 0 and status.value == 1:
                break
            time.sleep(0.02)
        raw = (ctypes.c_ubyte * 1)(0x5A)
        assert lib.GT_SetEcatRawData(32, 1, raw) == 0
        code = (
            "import ctypes, sys\n"
            f"lib = ctypes.CDLL({str(libgts.library)!r})\n"
            "b = (ctypes.c_ubyte * 1)()\n"
            "assert lib.GT_Open(0, 1) == 0\n"
            "assert lib.GT_GetEcatRawData(32, 1, b) == 0\n"
            "print(b[0])\n"
        )
        r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
        assert r.stdout.strip() == str(0x5A), r.stderr
    finally:
        lib.GT_Close()
