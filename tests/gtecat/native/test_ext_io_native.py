"""Extension IO modules through libgts: the same calls give the same codes and values as in
Python (the generated C side carries the ExtMdl prototypes: text, unsigned short and double
pointers, the multi-card form)."""

from __future__ import annotations

import subprocess
import sys

import pytest

from .conftest import C_DIR, compile_client, native_env, needs_cc, run_client

pytestmark = pytest.mark.xdist_group("ext_io_native")

MACHINE = """
[ext.0]
di = 16
do = 16
[ext.1]
di = 0
do = 0
ai = 2
"""

#: the client's sequence in Python, printing the same lines
PYTHON_TWIN = r"""
from ctypes import byref, c_double, c_long, c_ushort
from gtecat import gt
v, volts, di = c_ushort(), c_double(), c_long()
def say(k, x): print(k, int(x))
say("open", gt.GT_Open(0, 1))
say("before", gt.GT_SetExtIoBit(0, 3, 0))
say("openext", gt.GT_OpenExtMdl("gts.dll"))
say("load", gt.GT_LoadExtConfig("D:\\cfg\\ExtModule.cfg"))
say("reset", gt.GT_ResetExtMdl())
say("setbit", gt.GT_SetExtIoBit(0, 3, 0))
say("dorc", gt.GT_GetExtDoValue(0, byref(v))); say("do", v.value)
say("field", gt.GTE_SetExtDi(0, 5, 1))
say("dirc", gt.GT_GetExtIoValue(0, byref(v))); say("di", v.value)
say("badmdl", gt.GT_SetExtIoBit(16, 0, 0))
say("absent", gt.GT_SetExtIoBit(5, 0, 0))
say("ad", gt.GTE_SetExtAdVoltage(1, 0, 2.5))
say("adrc", gt.GT_GetExtAdVoltage(1, 0, byref(volts))); say("mv", volts.value * 1000)
say("gts", gt.GT_SetExtIoBitGts(0, 0, 4, 0))
say("gtscard", gt.GT_SetExtIoBitGts(1, 0, 4, 0))
say("gtninit", gt.GTN_ExtModuleInit(1, 1))
say("gtndirc", gt.GTN_GetExtDi(1, 1, byref(di))); say("gtndi", di.value)
say("close", gt.GT_CloseExtMdl())
say("done", 1)
"""


@needs_cc
@pytest.mark.long
def test_ext_io_from_c_matches_python(libgts, tmp_path):
    (tmp_path / "machine.toml").write_text(MACHINE, encoding="utf-8")
    (tmp_path / "ExtModule.cfg").write_text("[mdl0]\n", encoding="utf-8")
    env = native_env(GTECAT_CARD="gts:2", GTECAT_MACHINE="machine.toml", GTECAT_CLOCK="lockstep")
    exe = compile_client(C_DIR / "ext_io_client.c", tmp_path / "ext_io", "gcc")
    r, c_out = run_client(exe, env=env, cwd=tmp_path)
    assert r.returncode == 0 and c_out.get("done") == "1", r.stdout + r.stderr
    py = subprocess.run(
        [sys.executable, "-c", PYTHON_TWIN], capture_output=True, text=True, env=env, cwd=tmp_path
    )
    assert py.returncode == 0, py.stderr
    py_out = dict(line.split(" ", 1) for line in py.stdout.splitlines())
    assert c_out == py_out
    assert (c_out["before"], c_out["load"], c_out["do"], c_out["di"]) == (
        "1",
        "0",
        "65527",
        "65503",
    )
    assert (c_out["badmdl"], c_out["absent"], c_out["mv"], c_out["gtscard"]) == (
        "7",
        "1",
        "2500",
        "-1",  # card 1 is not open
    )
    assert c_out["gtndi"] == str(1 << 5)
