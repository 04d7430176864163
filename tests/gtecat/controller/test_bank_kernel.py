"""The bank's compiled cycle (gtecat/controller/bank_kernel.py): how it is chosen, and that a
machine without a compiler runs the same bank on numpy alone, with the reason readable."""

from __future__ import annotations

import ctypes
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from gtecat.controller import bank_kernel
from tests.conftest import is_setting

ROOT = Path(__file__).resolve().parents[3]

PROGRAM = r"""
import json, sys
from ctypes import byref, c_short
from gtecat import gt
gt.GT_Open(eni=sys.argv[1], clock="lockstep", log="", bank="on")
gt.GT_InitEcatComm()
s = c_short()
for _ in range(300):
    gt.GT_IsEcatReady(byref(s))
    if s.value:
        break
    gt.GTE_Wait(1)
assert gt.GT_StartEcatComm() == 0
from gtecat.controller import bank_kernel
due = gt.GTE_Controller().bank.kernel_due  # the bring-up did not wait for a build
bank_kernel.library()  # (waits for it; the bank takes it at its next cycle)
for a in range(1, 13):
    assert gt.GT_AxisOn(a) == 0 and gt.GT_PrfTrap(a) == 0
assert gt.GT_SetPos(3, 20000) == 0 and gt.GT_SetVel(3, 20.0) == 0 and gt.GT_Update(1 << 2) == 0
gt.GTE_Wait(100)
bank = gt.GTE_Controller().bank
print(json.dumps({"kernel": bank.kernel is not None, "reason": bank.kernel_reason, "due": due,
                  "rows": bank.rows_run, "kernel_cycles": bank.kernel_cycles}))
gt.GT_Close()
"""


def _run(tmp_path: Path, **env: str) -> dict:
    e = {k: v for k, v in os.environ.items() if not is_setting(k)}
    e["PYTHONPATH"] = str(ROOT)
    e["GTECAT_CACHE_DIR"] = str(tmp_path / "cache")  # nothing built before
    e.update(env)
    r = subprocess.run(
        [sys.executable, "-c", PROGRAM, str(ROOT / "examples" / "twelve_axes.eni")],
        env=e,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert r.returncode == 0, r.stderr
    return json.loads(r.stdout.strip().splitlines()[-1])


@pytest.mark.long
def test_without_a_compiler_the_bank_runs_on_numpy_and_says_why(tmp_path: Path) -> None:
    got = _run(tmp_path, CC="/no/such/compiler")
    assert not got["kernel"] and got["kernel_cycles"] == 0
    assert "/no/such/compiler" in got["reason"]
    assert got["rows"] > 12 * 50  # the bank itself still ran


@pytest.mark.long
def test_numpy_on_request(tmp_path: Path) -> None:
    got = _run(tmp_path, GTECAT_BANK_KERNEL="numpy")
    assert not got["kernel"] and got["reason"] == "GTECAT_BANK_KERNEL=numpy"
    assert got["rows"] > 12 * 50


@pytest.mark.skipif(
    not any(os.path.exists(os.path.join(d, c)) for d in os.get_exec_path() for c in ("cc", "gcc")),
    reason="no C compiler",
)
# a CI run builds the kernel into its empty cache at the first bank anyway (and the bank's
# differential tests fail when it does not build); this second build in a child is long
@pytest.mark.long("the kernel built again into an empty cache, in a child process")
def test_built_beside_the_first_bring_up_into_the_cache_and_used(tmp_path: Path) -> None:
    got = _run(tmp_path)
    assert got["kernel"], got["reason"]
    assert got["due"]  # built in a process of its own while the bus came up
    assert got["kernel_cycles"] > 50
    built = list((tmp_path / "cache").rglob("bank_kernel-*.so"))
    assert len(built) == 1


def test_the_binding_reads_the_field_list_the_library_was_built_with() -> None:
    names = [n for n, _ in bank_kernel._field_types()]
    assert len(names) == len(set(names)) > 80
    assert names[:2] == ["alive", "moving"] and names[-1] == "c_lreact"
    lib, reason = bank_kernel.library()
    if lib is None:
        pytest.skip(f"the kernel did not build here: {reason}")
    assert lib.bank_kernel_fields().decode().rstrip(",").split(",") == names


def test_unknown_mode_means_auto_with_a_warning(
    monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    monkeypatch.setenv("GTECAT_BANK_KERNEL", "fastest")
    assert bank_kernel.wanted() == "auto"
    assert "GTECAT_BANK_KERNEL='fastest'" in caplog.text
    monkeypatch.setenv("GTECAT_BANK_KERNEL", " NumPy ")
    assert bank_kernel.wanted() == "numpy"


def test_refused_flags_get_the_plain_build(monkeypatch: pytest.MonkeyPatch) -> None:
    asked: list[tuple[str, ...]] = []
    plain_builds = [True]

    def fake(stem: str, source: str, cflags: tuple[str, ...], libs: tuple[str, ...]) -> Path:
        asked.append(cflags)
        if cflags != bank_kernel.PLAIN_CFLAGS or not plain_builds[0]:
            raise bank_kernel.NativeBuildError("cc: error: unrecognized command-line option")
        return Path(f"/cache/{stem}-plain.so")

    monkeypatch.setattr(bank_kernel, "shared_library", fake)
    assert bank_kernel.build(bank_kernel.CFLAGS) == Path("/cache/bank_kernel-plain.so")
    assert asked == [bank_kernel.CFLAGS, bank_kernel.PLAIN_CFLAGS]
    asked.clear()
    plain_builds[0] = False  # the plain build failing too is the reason given
    with pytest.raises(bank_kernel.NativeBuildError, match="unrecognized"):
        bank_kernel.build(bank_kernel.CFLAGS)
    assert asked == [bank_kernel.CFLAGS, bank_kernel.PLAIN_CFLAGS]


@pytest.mark.long
@pytest.mark.skipif(
    not any(os.path.exists(os.path.join(d, c)) for d in os.get_exec_path() for c in ("cc", "gcc")),
    reason="no C compiler",
)
def test_a_real_refused_flag_falls_back_to_a_working_plain_build() -> None:
    import ctypes

    lib = ctypes.CDLL(str(bank_kernel.build((*bank_kernel.CFLAGS, "-fno-such-option-here"))))
    lib.bank_kernel_fields.restype = ctypes.c_char_p
    assert lib.bank_kernel_fields().decode().rstrip(",").split(",") == [
        n for n, _ in bank_kernel._field_types()
    ]


class _Build:
    """A build started (cbuild.Background's part the kernel module uses), never ending."""

    def __init__(self, builds: list) -> None:
        self.builds = builds

    def done(self) -> bool:
        return False


def test_a_first_build_starts_once_the_bus_is_in_op(monkeypatch: pytest.MonkeyPatch) -> None:
    """GT_Open defers a machine's first build of the kernel to OP (GT_IsEcatReady answering
    1, or GT_StartEcatComm): a compiler beside the bring-up took a CPU it wanted; a build
    already there is taken at once."""
    from gtecat import gt

    started: list[_Build] = []
    monkeypatch.setattr(bank_kernel, "_LIB", None)
    monkeypatch.setattr(bank_kernel, "_LIB_REASON", "")
    monkeypatch.setattr(bank_kernel, "_AHEAD", [])
    monkeypatch.setattr(
        bank_kernel, "Background", lambda b: started.append(_Build(b)) or started[-1]
    )
    monkeypatch.setattr(bank_kernel, "found", lambda *b: None)
    monkeypatch.delenv("GTECAT_BANK_KERNEL", raising=False)
    try:
        eni = ROOT / "examples" / "manual_fig5_2.eni"
        assert gt.GT_Open(eni=str(eni), clock="lockstep", log="") == 0
        assert gt.GT_InitEcatComm() == 0
        assert bank_kernel._DEFERRED and not started and not bank_kernel.settled()
        status = ctypes.c_short()
        while not (gt.GT_IsEcatReady(ctypes.byref(status)) == 0 and status.value == 1):
            assert not started  # not while the bus comes up
            gt.GTE_Wait(1)
        assert len(started) == 1 and not bank_kernel._DEFERRED  # at the first "ready"
        assert gt.GT_StartEcatComm() == 0
        assert len(started) == 1
        gt.GT_Close()
        bank_kernel._AHEAD.clear()
        monkeypatch.setattr(bank_kernel, "found", lambda *b: Path("/built/bank_kernel.so"))
        bank_kernel.prebuild(defer=True)  # built before: taken at once
        assert len(started) == 2 and not bank_kernel._DEFERRED
    finally:
        gt.GT_Close()
        bank_kernel._DEFERRED.clear()
