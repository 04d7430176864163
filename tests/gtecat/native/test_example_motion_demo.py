"""The worked example of issue 13: a user's compiled C++ program (examples/native/
motion_demo.cpp, seed 002's shape) runs against a controller this test hosts, while
the test drives the machine's field side and asserts through its own session.

The controller is this process's own gt session served by a :class:`Server` thread;
the program attaches with ``GTECAT_CONTROLLER``.  The test's own GT calls and field-side
actions hold ``server.lock`` so they are serialised with the program's calls.
"""

from __future__ import annotations

import subprocess
from ctypes import byref, c_long

import pytest

from gtecat import gt
from gtecat.native.server import Server

from .conftest import FIG5_2, native_env, needs_cxx

pytestmark = needs_cxx


@pytest.mark.long
def test_the_program_sees_a_drive_alarm_the_test_injects(motion_demo, tmp_path):
    gt.GT_Close()
    assert gt.GT_Open(eni=str(FIG5_2), clock="auto", log="") == 0
    address = f"unix:{tmp_path}/controller.sock"
    try:
        with Server(address) as server:
            proc = subprocess.Popen(
                [str(motion_demo), "37", "60000"],
                env=native_env(GTECAT_CONTROLLER=address),
                cwd=tmp_path,
                stdout=subprocess.PIPE,
                stderr=subprocess.PIPE,
                text=True,
            )
            seen = []
            assert proc.stdout is not None
            for line in proc.stdout:
                seen.append(line.strip())
                if line.startswith(("watching", "error")):
                    break
            assert seen[-1] == "watching", seen
            with server.lock:  # the program's axis is on its long move now
                sts = c_long()
                assert gt.GT_GetSts(1, byref(sts)) == 0
                assert sts.value & (1 << 10)  # moving
                gt.GTE_Slave(0).channel(0).inject_fault("alarm")
            out, err = proc.communicate(timeout=120)
            seen += out.splitlines()
            assert proc.returncode == 0, (seen, err)
            assert "home status 3" in seen
            assert "moved prf 30000 enc 30000" in seen
            watch = next(s for s in seen if s.startswith("watch "))
            assert watch.startswith("watch ret 0 alarm 1"), watch
            with server.lock:
                assert gt.GT_GetSts(1, byref(sts)) == 0
                assert sts.value & (1 << 1)  # the alarm is still there: its cause persists
                gt.GTE_Slave(0).channel(0).clear_injected_fault()
                assert gt.GT_ClrSts(1) == 0
                assert gt.GT_GetSts(1, byref(sts)) == 0
                assert not sts.value & (1 << 1)
            assert server.calls > 10
    finally:
        gt.GT_Close()
