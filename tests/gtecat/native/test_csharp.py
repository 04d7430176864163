"""C# programs on Mono, linked to libgts by the dllmap of ``gtecat lib --mono-config``.

Two console programs, compiled once per module with ``mcs`` as a user would and run with
``mono`` with nothing started before (``GT_Open`` starts a private controller):

* ``cs/CardStation.cs`` carries its own copy of the vendor wrapper, in the style of the field's
  wrappers (``[DllImport("gts.dll")]``, C ``long`` as ``int``, ``out``/``ref``, the C#
  ``THomePrm`` with three ``pad3`` ints): a GTS card (``GTECAT_CARD=gts:4``), its
  configuration loaded by a Windows path, Trap, Jog, the smart home straight after the Jog
  (the vendor's smart-home demo), card IO;
* ``cs/EcatStation.cs`` is new code on the generated ``gts.cs``: the GTN bring-up on the
  manual's figure 5-2 bus, Trap, the 8-profile read of examples 7-5/7-7/7-8, raw data, IO, SDO;
* ``cs/MultiCardStation.cs`` carries a wrapper of the older multi-card style (``short cardNum``
  first in every ``GT_`` function) and runs on the map of ``--abi gts-multicard``
  (``libgts_mc-llp64.so``).

Every return code each prints equals the one Python gives for the same call sequence.
VB.NET (``Declare Function ... Lib "gts.dll"``) binds through the same dllmap; Debian ships
no VB.NET compiler, so nothing here compiles one.
"""

from __future__ import annotations

import shutil
import subprocess
from ctypes import byref, c_double, c_long, c_short, c_uint32
from pathlib import Path

import pytest

from gtecat import gt

from .conftest import ROOT, built, native_env, parse_lines

CS_DIR = Path(__file__).resolve().parent / "cs"
EXAMPLES = ROOT / "examples"
MACHINE = EXAMPLES / "smart_home_machine.toml"

#: the assemblies the vendor's own C# wrappers name in their `using` lines (System.Data,
#: System.Drawing, System.Windows.Forms), which CardStation's copy keeps as they ship
WRAPPER_ASSEMBLIES = ("System.Data", "System.Drawing", "System.Windows.Forms")
MONO_DEBS = (
    "mono-mcs mono-runtime libmono-system-data4.0-cil libmono-system-drawing4.0-cil "
    "libmono-system-windows-forms4.0-cil"
)
needs_mono = pytest.mark.skipif(
    shutil.which("mcs") is None
    or shutil.which("mono") is None
    or not all(Path(f"/usr/lib/mono/4.5/{a}.dll").is_file() for a in WRAPPER_ASSEMBLIES),
    reason=f"needs Mono and the assemblies vendor wrappers name: apt-get install {MONO_DEBS}",
)
pytestmark = [needs_mono, pytest.mark.xdist_group("csharp")]


def _gtecat(*args: str, cwd: Path) -> None:
    """``gtecat ARGS`` as a user runs it in ``cwd`` (in this process: a child costs a second)."""
    from gtecat.cli.main import main

    with pytest.MonkeyPatch.context() as mp:
        mp.chdir(cwd)
        assert main(list(args)) == 0


@pytest.fixture(scope="module")
def programs(tmp_path_factory) -> Path:
    """Both programs compiled into one folder with ``gts.cs`` and the dllmap beside them."""
    from gtecat.native import llp64

    built("libgts-llp64", llp64.ensure_built)
    d = tmp_path_factory.mktemp("cs")
    _gtecat("lib", "--csharp", "-o", "gts.cs", cwd=d)
    _gtecat("lib", "--mono-config", "-o", "CardStation.exe.config", cwd=d)
    # the other way: the same map named by MONO_CONFIG
    _gtecat("lib", "--mono-config", "-o", "gts-mono.config", cwd=d)
    for name in ("CardStation", "EcatStation"):
        shutil.copy(CS_DIR / f"{name}.cs", d)
    for cmd in (
        ["mcs", "-nologo", *(f"-r:{a}" for a in WRAPPER_ASSEMBLIES), "CardStation.cs"],
        ["mcs", "-nologo", "EcatStation.cs", "gts.cs"],
    ):
        r = subprocess.run(cmd, cwd=d, capture_output=True, text=True)
        assert r.returncode == 0 and "warning" not in r.stdout, r.stdout + r.stderr
    return d


def _mono(exe: Path, cwd: Path, **env: str) -> dict[str, str]:
    r = subprocess.run(
        ["mono", str(exe)],
        cwd=cwd,
        env=native_env(**env),
        capture_output=True,
        text=True,
        timeout=180,
    )
    v = parse_lines(r.stdout)
    assert r.returncode == 0 and v.get("done") == "1", r.stdout + r.stderr
    return v


@pytest.fixture(scope="module")
def card(programs, tmp_path_factory) -> tuple[dict[str, str], Path]:
    cwd = tmp_path_factory.mktemp("card")
    shutil.copy(EXAMPLES / "GTS800.cfg", cwd)
    env = {"GTECAT_CARD": "gts:4", "GTECAT_MACHINE": str(MACHINE)}
    return _mono(programs / "CardStation.exe", cwd, **env), cwd


@pytest.fixture(scope="module")
def ecat(programs, tmp_path_factory) -> dict[str, str]:
    cwd = tmp_path_factory.mktemp("ecat")
    shutil.copy(EXAMPLES / "test.cfg", cwd)
    # EcatStation.exe has no App.exe.config beside it: MONO_CONFIG names the map
    return _mono(programs / "EcatStation.exe", cwd, MONO_CONFIG=str(programs / "gts-mono.config"))


# --- the vendor-style program on a GTS card -----------------------------------------------------
def test_a_vendor_style_csharp_program_runs_unchanged_under_mono(card):
    v, _ = card
    # bring-up; GT_LoadConfig("D:\\cfg\\GTS800.cfg") found GTS800.cfg in the working folder
    assert (v["open"], v["reset"], v["loadconfig"], v["clrsts"]) == ("0", "0", "0", "0")
    assert v["loadconfig_missing"] == "7" and "missing.cfg" in v["missing_reason"]
    assert [v[f"axison{a}"] for a in "1234"] == ["0"] * 4
    # Trap: out TTrapPrm / ref TTrapPrm, C long as int, out double / out uint
    assert (v["prfpos"], v["encpos"], v["trap_acc"]) == ("12345", "12345", "2")
    # int[] / double[] for count = 4 (the card's axes); 5 runs past them
    assert (v["getsts4"], v["sts_servo"], v["getprfvel4"], v["getsts5"]) == ("0", "1111", "0", "7")
    # the smart home straight after the Jog, with the C# THomePrm (4 bytes longer than C's)
    assert v["jog_moving"] == "1" and v["stop"] == "0"
    assert v["gohome"] == "0", v["gohome_reason"]
    assert (v["home_stage"], v["home_error"]) == ("100", "0")
    assert abs(int(v["home_capture"]) - 20000) <= 1  # smart_home_machine.toml: switch at 20000
    assert (v["homeprm_mode"], v["homeprm_escape"]) == ("20", "1000")
    assert v["homeprm_pad3_3"] == "77"  # the C# struct's extra int is left alone
    # IO
    assert (v["setdobit"], v["getdo"], v["gpo"]) == ("0", "0", "1")
    assert (v["getdi"], v["di_home"]) == ("0", "1")  # axis 3 stands on its home switch
    assert v["bad_axis"] == "7" and "1..4" in v["bad_axis_reason"]
    assert v["close"] == "0"


CARD_CODES = (
    "open reset loadconfig loadconfig_missing clrsts axison1 axison2 axison3 axison4 prftrap "
    "gettrapprm settrapprm setpos setvel update getprfpos getencpos getsts4 getprfvel4 getsts5 "
    "prfjog getjogprm setjogprm jogvel jogupdate stop home_clrsts gethomeprm gohome "
    "gethomeprm_after setdobit getdo getdi bad_axis close"
).split()


def _card_codes_in_python(cwd: Path, monkeypatch) -> dict[str, int]:
    """CardStation's calls through ``from gtecat import gt`` (lockstep, time let pass)."""
    monkeypatch.chdir(cwd)
    c: dict[str, int] = {}
    c["open"] = gt.GT_Open(card="gts:4", machine=str(MACHINE), clock="lockstep", log="")
    c["reset"] = gt.GT_Reset()
    c["loadconfig"] = gt.GT_LoadConfig("D:\\cfg\\GTS800.cfg")
    c["loadconfig_missing"] = gt.GT_LoadConfig("D:\\cfg\\missing.cfg")
    c["clrsts"] = gt.GT_ClrSts(1, 4)
    for a in range(1, 5):
        c[f"axison{a}"] = gt.GT_AxisOn(a)
    trap = gt.TTrapPrm()
    c["prftrap"] = gt.GT_PrfTrap(1)
    c["gettrapprm"] = gt.GT_GetTrapPrm(1, byref(trap))
    trap.acc, trap.dec, trap.smoothTime = 2, 2, 0
    c["settrapprm"] = gt.GT_SetTrapPrm(1, byref(trap))
    c["setpos"], c["setvel"] = gt.GT_SetPos(1, 12345), gt.GT_SetVel(1, 100)
    c["update"] = gt.GT_Update(1)
    sts, clk = c_long(), c_uint32()
    for _ in range(2000):
        gt.GTE_Wait(5)
        if gt.GT_GetSts(1, byref(sts)) == 0 and not sts.value & 0x400:
            break
    c["getprfpos"] = gt.GT_GetPrfPos(1, byref(c_double()), 1, byref(clk))
    c["getencpos"] = gt.GT_GetEncPos(1, byref(c_double()), 1, byref(clk))
    c["getsts4"] = gt.GT_GetSts(1, (c_long * 4)(), 4, byref(clk))
    c["getprfvel4"] = gt.GT_GetPrfVel(1, (c_double * 4)(), 4, byref(clk))
    c["getsts5"] = gt.GT_GetSts(1, (c_long * 5)(), 5, byref(clk))
    jog = gt.TJogPrm()
    c["prfjog"] = gt.GT_PrfJog(3)
    c["getjogprm"] = gt.GT_GetJogPrm(3, byref(jog))
    jog.acc, jog.dec, jog.smooth = 1, 1, 0
    c["setjogprm"] = gt.GT_SetJogPrm(3, byref(jog))
    c["jogvel"], c["jogupdate"] = gt.GT_SetVel(3, 50), gt.GT_Update(1 << 2)
    gt.GTE_Wait(100)
    c["stop"] = gt.GT_Stop(255, 255)
    c["home_clrsts"] = gt.GT_ClrSts(3, 1)
    home = gt.THomePrm()
    c["gethomeprm"] = gt.GT_GetHomePrm(3, byref(home))
    home.mode, home.moveDir, home.indexDir, home.edge = gt.HOME_MODE_HOME, 1, 1, 0
    home.velHigh, home.velLow, home.acc, home.dec = 100, 10, 2, 2
    home.homeOffset, home.searchHomeDistance, home.escapeStep = 0, 0, 1000
    c["gohome"] = gt.GT_GoHome(3, byref(home))
    hs = gt.THomeStatus()
    for _ in range(3000):
        gt.GTE_Wait(10)
        if gt.GT_GetHomeStatus(3, byref(hs)) == 0 and not hs.run:
            break
    c["gethomeprm_after"] = gt.GT_GetHomePrm(3, byref(gt.THomePrm()))
    value = c_long()
    c["setdobit"] = gt.GT_SetDoBit(gt.MC_GPO, 1, 1)
    c["getdo"] = gt.GT_GetDo(gt.MC_GPO, byref(value))
    c["getdi"] = gt.GT_GetDi(gt.MC_HOME, byref(value))
    c["bad_axis"] = gt.GT_AxisOn(9)
    c["close"] = gt.GT_Close()
    return c


def test_card_station_codes_equal_pythons(card, monkeypatch):
    v, cwd = card
    python = _card_codes_in_python(cwd, monkeypatch)
    assert set(python) == set(CARD_CODES)
    assert {k: int(v[k]) for k in CARD_CODES} == python


# --- new code on the generated gts.cs, EtherCAT -------------------------------------------------
def test_new_code_on_the_generated_gts_cs_runs_the_gtn_bring_up(ecat):
    v = ecat
    assert (v["open"], v["init"], v["ready"], v["start"], v["reset"]) == ("0", "0", "1", "0", "0")
    # GT_LoadConfig("\\gugao-board\\gugao1\\test.cfg"): test.cfg of the working folder
    assert (v["loadconfig"], v["clrsts8"]) == ("0", "0")
    assert (v["axison"], v["enabled"]) == ("0", "1")
    for k in ("prftrap", "gettrapprm", "settrapprm", "setpos", "setvel", "update"):
        assert v[k] == "0", k
    assert (v["getprfpos2"], v["prfpos"]) == ("0", "20000")
    assert (v["getecatencpos"], v["ecatencpos"]) == ("0", "20000")
    # examples 7-5, 7-7, 7-8: 8 profiles read on a 2-drive bus; 13 run past the 12 axes
    assert (v["getprfvel8"], v["getprfvel13"]) == ("0", "7")
    assert (v["getsts8"], v["sts8_servo"]) == ("0", "100")  # axis 3 and 8: no drive, at rest
    assert (v["raw_write"], v["raw_read"], v["raw_back"]) == ("0", "0", str(0x3CA5))
    assert v["raw_write_inputs"] == "7"
    assert (v["io_write"], v["io_read"]) == ("0", "0")
    assert (v["sdo_up"], v["sdo_size"]) == ("0", "2")
    assert (v["sdo_bad"], v["sdo_bad_abort"]) == ("1", "06020000")
    assert v["bad_axis"] == "7" and "axis 99" in v["bad_axis_reason"]
    assert v["close"] == "0"


ECAT_CODES = (
    "open init start reset loadconfig clrsts8 axison prftrap gettrapprm settrapprm setpos setvel "
    "update getprfpos2 getecatencpos getprfvel8 getprfvel13 getsts8 raw_write raw_read "
    "raw_write_inputs io_write io_read sdo_up sdo_bad bad_axis close"
).split()


def test_ecat_station_codes_equal_pythons(ecat, tmp_path, monkeypatch):
    shutil.copy(EXAMPLES / "test.cfg", tmp_path)
    monkeypatch.chdir(tmp_path)
    c: dict[str, int] = {}
    clk, sts = c_uint32(), c_long()
    c["open"] = gt.GTN_Open(eni=str(EXAMPLES / "manual_fig5_2.eni"), clock="lockstep", log="")
    c["init"] = gt.GTN_InitEcatComm(1)
    ready = c_short()
    while gt.GTN_IsEcatReady(1, byref(ready)) != 0 or ready.value != 1:
        gt.GTE_Wait(1)
    c["start"], c["reset"] = gt.GTN_StartEcatComm(1), gt.GTN_Reset(1)
    c["loadconfig"] = gt.GTN_LoadConfig(1, "\\gugao-board\\gugao1\\test.cfg")
    c["clrsts8"], c["axison"] = gt.GTN_ClrSts(1, 1, 8), gt.GTN_AxisOn(1, 1)
    while not (gt.GTN_GetSts(1, 1, byref(sts)) == 0 and sts.value & 0x200):
        gt.GTE_Wait(1)
    trap = gt.TTrapPrm()
    c["prftrap"] = gt.GTN_PrfTrap(1, 1)
    c["gettrapprm"] = gt.GTN_GetTrapPrm(1, 1, byref(trap))
    trap.acc, trap.dec = 2, 2
    c["settrapprm"] = gt.GTN_SetTrapPrm(1, 1, byref(trap))
    c["setpos"], c["setvel"] = gt.GTN_SetPos(1, 1, 20000), gt.GTN_SetVel(1, 1, 100)
    c["update"] = gt.GTN_Update(1, 1)
    gt.GTE_Wait(1000)
    c["getprfpos2"] = gt.GTN_GetPrfPos(1, 1, (c_double * 2)(), 2, byref(clk))
    c["getecatencpos"] = gt.GTN_GetEcatEncPos(1, 1, byref(c_long()))
    c["getprfvel8"] = gt.GTN_GetPrfVel(1, 1, (c_double * 8)(), 8, byref(clk))
    c["getprfvel13"] = gt.GTN_GetPrfVel(1, 1, (c_double * 13)(), 13, byref(clk))
    c["getsts8"] = gt.GTN_GetSts(1, 1, (c_long * 8)(), 8, byref(clk))
    two = bytearray(b"\xa5\x3c")
    c["raw_write"] = gt.GTN_SetEcatRawData(1, 32, 2, two)
    c["raw_read"] = gt.GTN_GetEcatRawData(1, 32, 2, bytearray(2))
    c["raw_write_inputs"] = gt.GTN_SetEcatRawData(1, 34, 2, two)
    c["io_write"] = gt.GTN_EcatIOWriteOutput(1, 3, 0, 2, bytearray(b"\x0f\xf0"))
    c["io_read"] = gt.GTN_EcatIOReadInput(1, 3, 0, 2, bytearray(2))
    size, abort = c_uint32(), c_uint32()
    c["sdo_up"] = gt.GTN_EcatSDOUpload(1, 0, 0x6041, 0, bytearray(4), 4, byref(size), byref(abort))
    c["sdo_bad"] = gt.GTN_EcatSDOUpload(1, 0, 0x2FFF, 0, bytearray(4), 4, byref(size), byref(abort))
    c["bad_axis"] = gt.GTN_AxisOn(1, 99)
    c["close"] = gt.GTN_Close()
    assert set(c) == set(ECAT_CODES)
    assert {k: int(ecat[k]) for k in ECAT_CODES} == c


# --- a wrapper of the older multi-card style (cardNum first) ------------------------------------
@pytest.fixture(scope="module")
def multicard(tmp_path_factory) -> tuple[dict[str, str], Path]:
    """MultiCardStation.cs compiled and run on the ``--abi gts-multicard`` map."""
    from gtecat.native import llp64

    built("libgts_mc-llp64", lambda: llp64.ensure_built(abi="gts-multicard"))
    d = tmp_path_factory.mktemp("multicard")
    shutil.copy(CS_DIR / "MultiCardStation.cs", d)
    shutil.copy(EXAMPLES / "GTS800.cfg", d)
    config = "MultiCardStation.exe.config"
    _gtecat("lib", "--abi", "gts-multicard", "--mono-config", "-o", config, cwd=d)
    r = subprocess.run(
        ["mcs", "-nologo", "MultiCardStation.cs"], cwd=d, capture_output=True, text=True
    )
    assert r.returncode == 0 and "warning" not in r.stdout, r.stdout + r.stderr
    return _mono(d / "MultiCardStation.exe", d, GTECAT_CARD="gts:4"), d


@pytest.mark.long
def test_a_multicard_wrapper_runs_on_the_multicard_map(multicard):
    v, d = multicard
    from gtecat.native import llp64

    target = llp64.ensure_built(abi="gts-multicard")
    assert target.name == "libgts_mc-llp64.so"
    text = (d / "MultiCardStation.exe.config").read_text(encoding="utf-8")
    assert f'<dllmap dll="i:gts.dll" target="{target}" os="!windows"/>' in text
    # cards 0..15; card 2 is not open; card 1 is a controller of its own: its axis 1 stands
    # where card 0's moved, and it keeps working after card 0 is closed
    assert v["open_card16"] == "-6" and "no card 16" in v["open_card16_reason"]
    assert v["axison_card2"] == "-1" and "card 2" in v["axison_card2_reason"]
    assert (v["open_card1"], v["axison_card1"], v["getprfpos_card1"]) == ("0", "0", "0")
    assert float(v["prfpos_card1"]) == 0.0
    assert (v["getsts_card1"], v["servo_card1"], v["close_card1"]) == ("0", "1", "0")
    assert v["getsts_closed"] == "-1"
    # C long as int (GT_SetPos / GT_GetPos, GT_GetSts, GT_Update's mask), ref / out TTrapPrm
    assert (v["trap_acc"], v["target"], v["prfpos"]) == ("2", "12345", "12345")
    assert (v["sts_servo"], v["gpo"]) == ("1111", "2")


MULTICARD_CODES = (
    "open reset loadconfig clrsts axison1 axison2 axison3 axison4 prftrap gettrapprm settrapprm "
    "gettrapprm_back setpos getpos setvel update getprfpos getsts4 setdobit getdo close"
).split()


@pytest.mark.long
def test_multicard_station_codes_and_values_equal_pythons(multicard, monkeypatch):
    v, d = multicard
    monkeypatch.chdir(d)
    c: dict[str, int] = {}
    c["open"] = gt.GT_Open(card="gts:4", clock="lockstep", log="")
    c["reset"] = gt.GT_Reset()
    c["loadconfig"] = gt.GT_LoadConfig("GTS800.cfg")
    c["clrsts"] = gt.GT_ClrSts(1, 4)
    for a in range(1, 5):
        c[f"axison{a}"] = gt.GT_AxisOn(a)
    trap, back = gt.TTrapPrm(), gt.TTrapPrm()
    c["prftrap"] = gt.GT_PrfTrap(1)
    c["gettrapprm"] = gt.GT_GetTrapPrm(1, byref(trap))
    trap.acc, trap.dec, trap.smoothTime = 2, 2, 0
    c["settrapprm"] = gt.GT_SetTrapPrm(1, byref(trap))
    c["gettrapprm_back"] = gt.GT_GetTrapPrm(1, byref(back))
    target = c_long()
    c["setpos"] = gt.GT_SetPos(1, 12345)
    c["getpos"] = gt.GT_GetPos(1, byref(target))
    c["setvel"], c["update"] = gt.GT_SetVel(1, 100), gt.GT_Update(1)
    sts, clk, prf = c_long(), c_uint32(), c_double()
    for _ in range(2000):
        gt.GTE_Wait(5)
        if gt.GT_GetSts(1, byref(sts)) == 0 and not sts.value & 0x400:
            break
    c["getprfpos"] = gt.GT_GetPrfPos(1, byref(prf), 1, byref(clk))
    four = (c_long * 4)()
    c["getsts4"] = gt.GT_GetSts(1, four, 4, byref(clk))
    gpo = c_long()
    c["setdobit"] = gt.GT_SetDoBit(gt.MC_GPO, 2, 1)
    c["getdo"] = gt.GT_GetDo(gt.MC_GPO, byref(gpo))
    c["close"] = gt.GT_Close()
    assert set(c) == set(MULTICARD_CODES)
    assert {k: int(v[k]) for k in MULTICARD_CODES} == c
    servo = "".join("1" if s & 0x200 else "0" for s in four)
    values = (back.acc, target.value, prf.value, servo, gpo.value)
    assert values == (
        float(v["trap_acc"]),
        int(v["target"]),
        float(v["prfpos"]),
        v["sts_servo"],
        int(v["gpo"]),
    )


# --- the map the programs ran with ------------------------------------------------------------
def test_the_mono_config_maps_every_vendor_name(programs):
    from gtecat.native import llp64

    text = (programs / "CardStation.exe.config").read_text(encoding="utf-8")
    target = str(llp64.ensure_built())
    for dll in ("gts.dll", "gts", "gen.dll", "gxn.dll"):
        assert f'<dllmap dll="i:{dll}" target="{target}" os="!windows"/>' in text
