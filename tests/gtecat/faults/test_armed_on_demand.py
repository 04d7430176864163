"""``from gtecat import gt`` leaves the fault vocabulary (gtecat.faults) unimported until a bus
comes up whose machine description has ``[[fault]]`` tables: those are armed all the same."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

from tests.conftest import is_setting

ROOT = Path(__file__).resolve().parents[3]

PROGRAM = r"""
import json, sys
from ctypes import byref, c_short
from gtecat import gt
before = "gtecat.faults" in sys.modules
assert gt.GT_Open(eni=sys.argv[1], machine=sys.argv[2], clock="lockstep", log="") == 0
assert gt.GT_InitEcatComm() == 0
plain = "gtecat.faults" in sys.modules
gt.GT_Close()
assert gt.GT_Open(eni=sys.argv[1], machine=sys.argv[3], clock="lockstep", log="") == 0
assert gt.GT_InitEcatComm() == 0
from gtecat import faults
kinds = [f["kind"] for f in faults.listing()]
print(json.dumps({"before": before, "plain": plain, "kinds": kinds}))
"""


def test_fault_tables_are_armed_with_the_package_imported_on_demand(tmp_path: Path) -> None:
    plain = tmp_path / "plain.toml"
    plain.write_text("[axis.1]\nposition = 0\n")
    tables = tmp_path / "faults.toml"
    tables.write_text('[[fault]]\nkind = "drive_fault"\naxis = 1\ncode = 0x3220\nat_ms = 50\n')
    env = {k: v for k, v in os.environ.items() if not is_setting(k)}
    env["PYTHONPATH"] = str(ROOT)
    eni = ROOT / "examples" / "manual_fig5_2.eni"
    r = subprocess.run(
        [sys.executable, "-c", PROGRAM, str(eni), str(plain), str(tables)],
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert r.returncode == 0, r.stderr
    got = json.loads(r.stdout.strip().splitlines()[-1])
    assert got == {"before": False, "plain": False, "kinds": ["drive_fault"]}
