"""The table's census: ``gtecat api`` counts, the generated reference pages, ``gtecat scan``
on sample sources in C++, C# and VB.NET, and a scenario test for every emulated function."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from gtecat import gt
from gtecat.cli.main import main
from gtecat.gt import surface, table
from gtecat.gt._core import CMD_DECLARED, REGISTRY
from gtecat.gt.scan import scan
from tests.conftest import ROOT

SAMPLES = Path(__file__).resolve().parent / "scan_samples"
API_DOCS = ROOT / "docs" / "reference" / "api"


def _json(capsys, *argv: str) -> tuple[int, dict]:
    rc = main(list(argv))
    return rc, json.loads(capsys.readouterr().out)


def test_api_counts_add_up(capsys):
    rc, out = _json(capsys, "api", "--json")
    assert rc == 0
    assert out["functions"] == out["emulated"] + out["declared"] == len(table.exported_names())
    assert out["emulated"] == len(set(table.exported_names()) & set(REGISTRY))
    assert sum(g["emulated"] + g["declared"] for g in out["groups"]) == out["functions"]
    assert out["functions"] > 2700 and out["constants"] > 600 and out["structures"] > 100
    names = {g["name"] for g in out["groups"]}
    assert {"bus", "ecat_axis", "crd", "vendor_ext_io"} <= names
    rc, one = _json(capsys, "api", "--group", "ecat_axis", "--json")
    assert rc == 0 and "GT_AxisOn" in one["emulated"] and "GTN_AxisOn" in one["emulated"]
    assert not set(one["emulated"]) & set(one["declared"])
    rc, vendor = _json(capsys, "api", "--group", "vendor_io", "--json")
    assert "GT_SetHSIOOpt" in vendor["declared"]


def test_api_text_and_an_unknown_group(capsys):
    assert main(["api"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].split()[:3] == ["group", "emulated", "declared"]
    assert lines[-1].startswith("total")
    assert main(["api", "--group", "nope"]) == 1
    assert "no group 'nope'" in capsys.readouterr().err


def test_every_declared_name_is_a_function_of_gt_that_answers_8():
    for e in surface.entries():
        fn = getattr(gt, e.name)
        assert (e.name in REGISTRY) == e.emulated
        if not e.emulated:
            assert fn.declared  # the declared-only face, never an implementation
    assert gt.GTN_CrdBlendOn(1, 2, 3) == CMD_DECLARED  # exported by the DLL, no public prototype
    assert "declared but not emulated" in gt.GTE_GetLastError()


def test_the_reference_pages_are_current():
    """Regenerate with `gtecat api --write-docs docs/reference/api`."""
    want = surface.pages()
    have = {p.name: p.read_text(encoding="utf-8") for p in API_DOCS.glob("*.md")}
    stale = sorted(n for n in set(want) | set(have) if want.get(n) != have.get(n))
    assert not stale, f"stale pages {stale}: run gtecat api --write-docs docs/reference/api"
    readme = (ROOT / "docs" / "reference" / "README.md").read_text(encoding="utf-8")
    assert "api/README.md" in readme


def _by_name(path: Path) -> dict[str, surface.Entry | object]:
    return {u.name: u for u in scan([path])}


def _status(name: str) -> str:
    e = surface.by_name()[name]
    return "emulated" if e.emulated else "declared only"


def test_scan_a_cpp_program(capsys):
    uses = _by_name(SAMPLES / "c_app")
    fns = {n for n, u in uses.items() if u.kind == "function"}
    assert fns == {
        "GT_Open", "GT_Reset", "GT_LoadConfig", "GT_ClrSts", "GT_AxisOn", "GT_PrfTrap",
        "GT_GetSts", "GT_SetHSIOOpt", "GTN_GetResCount", "GT_MadeUpFunction",
    }  # fmt: skip
    assert uses["GT_Open"].status == "emulated"
    assert uses["GT_SetHSIOOpt"].status == _status("GT_SetHSIOOpt") == "declared only"
    assert uses["GTN_GetResCount"].status == _status("GTN_GetResCount")
    assert uses["GT_MadeUpFunction"].status == "missing"
    assert uses["CMD_SUCCESS"].status == uses["MC_AXIS"].status == "defined"
    assert uses["MC_NOT_A_CONSTANT"].status == "missing"
    assert uses["GT_AxisOn"].where == [f"{SAMPLES / 'c_app' / 'motion.cpp'}:19"]
    assert main(["scan", str(SAMPLES / "c_app")]) == 1
    out = capsys.readouterr().out
    assert "GT_MadeUpFunction" in out and "1 missing" in out


def test_scan_a_csharp_project_reads_its_wrapper_as_declarations(capsys):
    uses = _by_name(SAMPLES / "cs_app")
    fns = {n for n, u in uses.items() if u.kind == "function"}
    assert fns == {"GT_Open", "GT_GetPrfPos", "GTN_GetResCount"}  # not GT_SetPidNeverCalled
    assert {n for n, u in uses.items() if u.kind == "constant"} == {"MC_AXIS", "CMD_SUCCESS"}
    rc, out = _json(capsys, "scan", "--json", str(SAMPLES / "cs_app"))
    assert out["files"] == 2
    assert rc == (0 if out["ok"] else 1)
    assert out["ok"] == (_status("GTN_GetResCount") == "emulated")


def test_scan_a_vbnet_module_that_only_uses_emulated_functions(capsys):
    uses = _by_name(SAMPLES / "vb_app" / "Module1.vb")
    assert set(uses) == {"GT_Open", "GT_AxisOn", "GT_ClrSts"}  # Const and Declare: not uses
    assert all(u.status == "emulated" for u in uses.values())
    assert main(["scan", str(SAMPLES / "vb_app")]) == 0
    assert "3 functions (3 emulated, 0 declared only, 0 missing)" in capsys.readouterr().out


def test_scan_of_a_path_that_does_not_exist(capsys):
    assert main(["scan", str(SAMPLES / "nope")]) == 1
    assert "no such file or folder" in capsys.readouterr().err


# --- every emulated function has a scenario test ------------------------------------------------
#: files that name functions without running a scenario of them (generated, generic, census)
NOT_SCENARIOS = re.compile(r"fuzz|test_api_surface|test_header|test_units|scan_samples")


def test_every_emulated_function_has_a_scenario_test():
    """A test file under tests/ mentions each emulated GT_x (or its GTN_x twin) by name: the
    fuzzers and the census do not count, they call every function alike."""
    texts = [
        p.read_text(encoding="utf-8", errors="replace")
        for p in (ROOT / "tests").rglob("*")
        if p.suffix in (".py", ".c", ".cpp", ".cs", ".vb")
        and p.is_file()
        and not NOT_SCENARIOS.search(str(p.relative_to(ROOT)))
    ]
    words = set(re.findall(r"\b(?:GT[NE]?_)?[A-Z]\w+", "\n".join(texts)))
    missing = [
        n for n in sorted(table.emulated()) if n not in words and ("GTN_" + n[3:]) not in words
    ]
    assert not missing, f"emulated without a scenario test: {missing}"


@pytest.mark.parametrize("name", ["GT_SetHSIOOpt", "GTN_SetHSIOOpt", "GT_OpenExtMdlGts"])
def test_a_declared_call_writes_one_master_log_line(name, tmp_path):
    from tests.gtecat.gt.conftest import bring_up

    if name not in surface.by_name() or surface.by_name()[name].emulated:
        pytest.skip(f"{name} is not declared only in this table")
    bring_up("manual_fig5_2.eni", clock="lockstep")
    ctl = gt._core.SESSION.controllers[1]
    fn = getattr(gt, name)
    for _ in range(3):
        assert fn(1, 2) == CMD_DECLARED
    lines = [ln for ln in ctl.log.lines if f"{name} is declared but not emulated" in ln]
    assert len(lines) == 1, ctl.log.lines[-5:]


def test_the_longer_csharp_home_prm_works_too():
    """Eleven public C# wrappers declare THomePrm with three ints in pad3 where every C header
    has two: 4 bytes longer.  The call reads and writes the C layout's bytes, so both work."""
    import ctypes

    class CSharpHomePrm(ctypes.Structure):  # the C# wrapper's layout
        _fields_ = [
            *[(f, ctypes.c_short) for f in ("mode", "moveDir", "indexDir", "edge", "triggerIndex")],
            ("pad1", ctypes.c_short * 3),
            *[(f, ctypes.c_double) for f in ("velHigh", "velLow", "acc", "dec")],
            ("smoothTime", ctypes.c_short),
            ("pad2", ctypes.c_short * 3),
            *[(f, ctypes.c_int32) for f in ("homeOffset", "searchHomeDistance")],
            *[(f, ctypes.c_int32) for f in ("searchIndexDistance", "escapeStep")],
            ("pad3", ctypes.c_int32 * 3),
        ]

    assert ctypes.sizeof(CSharpHomePrm) > ctypes.sizeof(gt.THomePrm)  # 84 bytes, padded to 88
    assert gt.GT_Open(card="gts:2", clock="lockstep", log="") == 0, gt.GTE_GetLastError()
    prm = CSharpHomePrm()
    prm.pad3[2] = 12345  # the C# tail the C layout does not have: left alone
    assert gt.GT_GetHomePrm(1, ctypes.byref(prm)) == 0, gt.GTE_GetLastError()
    assert prm.pad3[2] == 12345
    prm.mode, prm.moveDir, prm.velHigh, prm.velLow, prm.acc, prm.dec = 20, 1, 10, 1, 0.5, 0.5
    assert gt.GT_PrfTrap(1) == 0 and gt.GT_AxisOn(1) == 0
    assert gt.GT_GoHome(1, ctypes.byref(prm)) == 0, gt.GTE_GetLastError()
    back = CSharpHomePrm()
    assert gt.GT_GetHomePrm(1, ctypes.byref(back)) == 0
    assert (back.mode, back.velHigh) == (20, 10.0)
