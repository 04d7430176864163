"""The vendor's whole surface through libgts: a vendor-style header compiles unchanged with
``gtecat lib --cflags``, declared-only functions answer 8 with a reason from C as from
Python, and the older multi-card ABI (``--abi gts-multicard``) runs a client of its own."""

from __future__ import annotations

import shlex
import subprocess
from pathlib import Path

import pytest

from gtecat import gt
from gtecat.gt import _core
from gtecat.gt._core import CMD_DECLARED

from .conftest import (
    C_DIR,
    FIG5_2,
    built,
    native_env,
    needs_cc,
    needs_cxx,
    run_client,
    tool_env,
)

pytestmark = [needs_cc, pytest.mark.xdist_group("c_clients")]


@pytest.fixture(scope="module")
def controller(tmp_path_factory):
    """One controller in this process for the module's C clients (they attach to it through
    GTECAT_CONTROLLER instead of each starting a private one)."""
    from gtecat.native.server import Server

    gt.GT_Close()
    assert gt.GT_Open(eni=str(FIG5_2), clock="auto", log="") == 0, gt.GTE_GetLastError()
    address = f"unix:{tmp_path_factory.mktemp('ctl')}/controller.sock"
    with Server(address):
        yield address
    _core.close_all()  # the clients opened cards 1 and 2 here too


def _compile(src: Path, out: Path, compiler: str, lib_args: str, extra: str = "") -> Path:
    cmd = (
        f"{compiler} {extra} {shlex.quote(str(src))} $(python3 -m gtecat lib {lib_args}) "
        f"-o {shlex.quote(str(out))}"
    )
    r = subprocess.run(["bash", "-c", cmd], capture_output=True, text=True, env=tool_env())
    assert r.returncode == 0, f"{cmd}\n{r.stderr}"
    assert "warning" not in r.stderr, r.stderr
    return out


@needs_cxx
@pytest.mark.long
def test_a_vendor_style_header_compiles_unchanged_and_runs(libgts, controller, tmp_path):
    """__stdcall, extern "C" in GT_API, NULL defaults and UINT8 without any include: the
    forced include of --cflags supplies them; the header's own TTrapPrm matches ours."""
    exe = _compile(
        C_DIR / "vendor_style_client.cpp",
        tmp_path / "vendor_style",
        "g++ -Wall -Wextra",
        "--cflags --libs",
        extra=f"-I{C_DIR / 'vendor_style'}",  # its gts.h before gtecat's
    )
    r, v = run_client(exe, env=native_env(GTECAT_CONTROLLER=controller), cwd=tmp_path)
    assert r.returncode == 0 and v["done"] == "1", r.stdout + r.stderr
    assert (v["open"], v["start"], v["version_rc"], v["clock_rc"]) == ("0",) * 4
    assert len(v["version"].split()) == 4  # table 11-3: aaa bbbbbb ccc dddddd
    assert (v["prftrap"], v["gettrap"], v["settrap"]) == ("0", "0", "0")
    assert (v["trap_smooth"], v["trap_acc_x100"]) == ("5", "25")
    assert v["hsio"] == str(CMD_DECLARED)
    assert v["hsio_reason"] == (
        "GT_SetHSIOOpt returned 8: GT_SetHSIOOpt is declared but not emulated "
        "(group: digital and analog IO)"
    )
    assert v["rescount"] in ("0", str(CMD_DECLARED))  # emulated or declared, never a pretend 0
    # MoveVelocity on an axis that is not servo-enabled: refused with its reason
    assert v["movevelocity"] == "1", v["movevelocity_reason"]
    assert "not servo-enabled" in v["movevelocity_reason"]
    if v["rescount"] == "0":
        assert int(v["rescount_value"]) >= 2  # the figure 5-2 bus has two axes
    assert v["close"] == "0"


@needs_cxx
@pytest.mark.long
def test_a_gvn_era_header_with_its_own_linux_branch_compiles_and_runs(libgts, controller, tmp_path):
    """The newest header shape (GT_API without __stdcall under __linux__, __int64 from
    int64_t, GP_CORE): GTN_GetPrfSts reads 5 profiles, a declared-only call answers 8."""
    exe = _compile(
        C_DIR / "vendor_gvn_client.cpp",
        tmp_path / "vendor_gvn",
        "g++ -Wall -Wextra",
        "--cflags --libs",
        extra=f"-I{C_DIR / 'vendor_gvn'}",
    )
    r, v = run_client(exe, env=native_env(GTECAT_CONTROLLER=controller), cwd=tmp_path)
    assert r.returncode == 0 and v["done"] == "1", r.stdout + r.stderr
    assert (v["prfsts"], v["prfsts_any"], v["gt_prfsts"], v["gt_prfsts_value"]) == ("0",) * 4
    assert (v["prfmode"], v["mode1"]) == ("0", "1")
    assert v["multilines"] == str(CMD_DECLARED)
    assert "GTN_RN_SetEncMultiLinesEx is declared but not emulated" in v["multilines_reason"]
    assert v["limitinfo"] == str(CMD_DECLARED)


def test_declared_only_gives_the_same_answer_in_python():
    assert gt.GT_SetHSIOOpt(1) == CMD_DECLARED
    assert gt.GTE_GetLastError() == (
        "GT_SetHSIOOpt returned 8: GT_SetHSIOOpt is declared but not emulated "
        "(group: digital and analog IO)"
    )
    assert gt.GTN_SetHSIOOpt(1, 1, laserChannel=0) == CMD_DECLARED
    assert "GTN_SetHSIOOpt is declared" in gt.GTE_GetLastError()


@pytest.mark.long
def test_the_multicard_abi(controller, tmp_path):
    """Manual-era GTS programs pass the card first: two cards, each a controller of its own
    (card 1 jogs while card 0 stands; card 0 closes, card 1 keeps running)."""
    from gtecat.native.build import ensure_built

    built("libgts_mc", lambda: ensure_built(abi="gts-multicard"))
    exe = _compile(
        C_DIR / "multicard_client.c", tmp_path / "mc", "gcc -Wall -Wextra",
        "--abi gts-multicard --cflags --libs",
    )  # fmt: skip
    r, v = run_client(exe, env=native_env(GTECAT_CONTROLLER=controller), cwd=tmp_path)
    assert r.returncode == 0 and v["done"] == "1", r.stdout + r.stderr
    assert v["open_card16"] == "-6"
    assert "no card 16: cards are numbered 0..15" in v["open_card16_reason"]
    assert v["axison_card2"] == "-1"
    assert "has not opened card 2" in v["axison_card2_reason"]
    assert (v["up0"], v["up1"], v["open1_again"]) == ("0", "0", "-6")
    assert (v["axison0"], v["axison1"], v["prfjog1"], v["setjog1"]) == ("0",) * 4
    assert (v["setvel1"], v["update1"], v["prfvel0_rc"], v["prfvel1_rc"]) == ("0",) * 4
    assert (v["vel0"], v["vel1"], v["moved1"]) == ("0", "20", "1")
    assert (v["mode0"], v["mode1"]) == ("0", "1")  # Trap on card 0, Jog on card 1
    assert v["hsio"] == str(CMD_DECLARED)
    assert v["close0"] == "0" and v["getsts0_closed"] == "-1"
    assert (v["getsts1"], v["running1"], v["stop1"], v["close1"]) == ("0", "1", "0", "0")


def test_two_cards_through_the_one_card_abi(libgts, controller, tmp_path):
    """GT_SetCardNo (before GT_Open too) chooses the card of every later call; card 1 jogs
    while card 0 is polled; closing card 1 leaves card 0.  (Compiled with the library's own
    flags, the ones `gtecat lib --cflags --libs` prints: the other tests here run the command.)"""
    exe = tmp_path / "cards"
    cmd = ["gcc", "-Wall", "-Wextra", str(C_DIR / "cards_client.c"), *libgts.cflags()]
    r = subprocess.run([*cmd, *libgts.libs(), "-o", str(exe)], capture_output=True, text=True)
    assert r.returncode == 0 and "warning" not in r.stderr, r.stderr
    r, v = run_client(exe, env=native_env(GTECAT_CONTROLLER=controller), cwd=tmp_path)
    assert r.returncode == 0 and v["done"] == "1", r.stdout + r.stderr
    assert (v["set16"], v["set1"], v["get_rc"], v["card"]) == ("7", "0", "0", "1")
    assert (v["up1"], v["set0"], v["up0"], v["jog1"]) == ("0",) * 4
    assert (v["vel0"], v["vel1"]) == ("0", "-10")
    assert (v["close1"], v["sts1_closed"], v["sts0"], v["servo0"]) == ("0", "-1", "0", "1")
    assert (v["setcore2"], v["getcore_rc"], v["core"], v["rescount_rc"]) == ("0", "0", "2", "0")
    assert (v["core2_axes"], v["setcore3"], v["setcore1"]) == ("12", "7", "0")
    assert v["close0"] == "0"


def test_libgts_exports_every_name_of_the_table(libgts):
    """`nm -D`: the vendor DLL's names (the table holds every one) are all exported."""
    import shutil

    from gtecat.gt.table import exported_names

    if shutil.which("nm") is None:
        pytest.skip("needs nm: apt-get install binutils")
    out = subprocess.run(
        ["nm", "-D", "--defined-only", str(libgts.library)], capture_output=True, text=True
    ).stdout
    symbols = {line.split()[-1] for line in out.splitlines() if " T " in line}
    names = set(exported_names())
    assert not names - symbols
    assert len(names) > 2700  # the GTN-era vendor DLL exports 2,057 GT_/GTN_ names
    for name in ("GTN_GetResCount", "GTN_MoveVelocity", "GT_SetHSIOOpt", "GTN_CrdBlendOn"):
        assert name in symbols


@needs_cxx
def test_the_ecat_demo_calls_compile_against_our_header(gts_h):
    """CMD_SUCCESS, MC_AXIS, GTN_GetResCount, TMoveVelocityPrm and GTN_MoveVelocity, and the
    vendor header's unsigned short * of GTN_GetEcatAxisMode / GTN_GetEcatHomingStatus."""
    cmd = ["g++", "-std=c++11", "-Wall", "-Wextra", "-pedantic", "-Werror", "-fsyntax-only"]
    cmd += [f"-I{gts_h.parent}", str(C_DIR / "ecat_demo_style.cpp")]
    r = subprocess.run(cmd, capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
