"""A program compiled on Linux against a vendor-style header whose structures hold C long:
``gtecat lib --m32`` builds it as a 32-bit program, so ``THomePrm`` has its Windows layout
and the smart-home parameters read back as written (a 64-bit build reads them shifted)."""

from __future__ import annotations

import os
import shlex
import shutil
import subprocess
from pathlib import Path

import pytest

from .conftest import C_DIR, native_env, needs_cxx, run_client, tool_env


def _m32_works() -> bool:
    if shutil.which("g++") is None:
        return False
    r = subprocess.run(
        ["g++", "-m32", "-x", "c++", "-", "-o", os.devnull],
        input="#include <stdio.h>\nint main(){return 0;}\n",
        capture_output=True,
        text=True,
    )
    return r.returncode == 0


needs_m32 = pytest.mark.skipif(
    not _m32_works(),
    reason="no 32-bit C/C++ library (Debian's gcc-multilib, g++-multilib): --m32 is not tested",
)
MACHINE = (
    "[axis.1]\nposition = 0\nnegative_limit = -400000\npositive_limit = 400000\n"
    "home_switch = [[50000, 60000]]\nindex_offset = 700\ncounts_per_rev = 10000\n"
)


@needs_cxx
@needs_m32
@pytest.mark.long
def test_a_vendor_header_with_long_fields_runs_as_a_32_bit_program(tmp_path: Path) -> None:
    exe = tmp_path / "home32"
    cmd = (
        f"g++ -Wall {shlex.quote(str(C_DIR / 'vendor_long_client.cpp'))} "
        f"-I{shlex.quote(str(C_DIR / 'vendor_long'))} "
        f"$(python3 -m gtecat lib --m32 --cflags --libs) -o {shlex.quote(str(exe))}"
    )
    r = subprocess.run(["bash", "-c", cmd], capture_output=True, text=True, env=tool_env())
    assert r.returncode == 0, f"{cmd}\n{r.stderr}"
    (tmp_path / "machine.toml").write_text(MACHINE, encoding="utf-8")
    env = native_env(GTECAT_CARD="gts:4", GTECAT_MACHINE=str(tmp_path / "machine.toml"))
    r, v = run_client(exe, "offset", env=env, cwd=tmp_path)
    assert r.returncode == 0 and v.get("close") == "0", r.stdout + r.stderr
    assert v["sizeof_homeprm"] == "80"  # long of 4 bytes, doubles aligned to 8
    assert (v["open"], v["axison"], v["gohome"]) == ("0", "0", "0")
    assert (v["run"], v["error"]) == ("0", "0")
    assert (v["capture"], v["target"], v["prf"]) == ("50000", "49500", "49500")  # offset -500
    assert (v["back_index"], v["back_escape"], v["back_offset"]) == ("30000", "1000", "-500")
