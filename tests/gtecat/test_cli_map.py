"""``gtecat map`` and ``gtecat eni new``: output checked against golden files.

Golden files live in ``tests/golden/map_*``; they are rewritten only when the
environment says ``GTECAT_REGEN_GOLDEN=1`` (review the diff before committing).
The offsets in them are the manual's (5.2.2.4 figure 5-2, 5.2.2.5 figure 5-4),
checked in tests/eni.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
from pathlib import Path

import pytest

from gtecat.cli import eni_cmd, map_cmd
from gtecat.cli.main import main

GOLDEN = Path(__file__).resolve().parent.parent / "golden"
REGEN = os.environ.get("GTECAT_REGEN_GOLDEN") == "1"
EXAMPLES = ("manual_fig5_2", "manual_fig5_4", "twelve_axes")
FIXTURES = (
    "googol/Gecat_DM3E_stepper.eni",
    "googol/Gecat_IO.eni",
    "eni/acontis_training_slaves.xml",
    "eni/twincat_ek1100_el2008_el4002_el1809.xml",
)


def _check_golden(name: str, text: str) -> None:
    path = GOLDEN / name
    if REGEN:
        GOLDEN.mkdir(exist_ok=True)
        path.write_text(text, encoding="utf-8")
        return
    assert path.exists(), f"missing golden file {path} (GTECAT_REGEN_GOLDEN=1 writes it)"
    assert text == path.read_text(encoding="utf-8")


def _run_map(capsys: pytest.CaptureFixture[str], file: str, as_json: bool) -> str:
    rc = map_cmd.run(argparse.Namespace(file=file, json=as_json))
    out, err = capsys.readouterr()
    assert rc == 0 and err == ""
    return out


@pytest.mark.parametrize("name", EXAMPLES)
def test_map_examples_golden(
    name: str,
    examples_dir: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    monkeypatch.chdir(examples_dir)
    _check_golden(f"map_{name}.txt", _run_map(capsys, f"{name}.eni", False))
    _check_golden(f"map_{name}.json", _run_map(capsys, f"{name}.eni", True))


@pytest.mark.parametrize("rel", FIXTURES)
def test_map_fixtures_golden(
    rel: str,
    shared_fixtures: Path,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    src = shared_fixtures / rel
    shutil.copy(src, tmp_path / src.name)  # a stable label in the table header
    monkeypatch.chdir(tmp_path)
    stem = src.stem.lower()
    _check_golden(f"map_{stem}.txt", _run_map(capsys, src.name, False))
    _check_golden(f"map_{stem}.json", _run_map(capsys, src.name, True))


def test_map_table_shows_manual_offsets(
    examples_dir: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Manual 5.2.2.4: slave 1's 0x6041 at GT raw byte 22; slave 2's DI at 34."""
    out = _run_map(capsys, str(examples_dir / "manual_fig5_2.eni"), False)
    rows = [line.split() for line in out.splitlines()]
    s1 = out.split("slave 1 ")[1]
    assert any(
        r[:3] == ["in", "0x1A00", "0x6041:00"] and r[-1] == "22.0"
        for r in (line.split() for line in s1.splitlines()[:8])
    )
    assert ["in", "0x1A00", "0x6000:01", "DI", "byte", "0", "USINT", "8", "20.0", "34.0"] in rows


def test_map_json_is_the_design_schema(
    examples_dir: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    doc = json.loads(_run_map(capsys, str(examples_dir / "manual_fig5_2.eni"), True))
    assert (doc["gt_raw_bytes"], doc["outputs_bytes"], doc["inputs_bytes"]) == (40, 16, 24)
    s1 = doc["slaves"][1]
    assert (s1["position"], s1["axis"], s1["gt_offset"], s1["gt_size"]) == (1, 2, 16, 16)
    sw = next(e for e in s1["entries"] if e["index"] == 0x6041)
    assert sw == {
        "dir": "in",
        "index": 0x6041,
        "subindex": 0,
        "name": "Statusword",
        "bits": 16,
        "gt_bit": 22 * 8,
        "logical_bit": 80,
    }


@pytest.mark.parametrize(
    ("content", "needle"),
    [
        (None, "cannot read"),
        ("", "empty"),
        ("garbage", "not an ENI"),
        ('<?xml version="1.0"?>\n<EtherCATConfig><Config>', "malformed XML"),
    ],
)
def test_map_bad_file_one_line_error(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], content: str | None, needle: str
) -> None:
    path = tmp_path / "bad.eni"
    if content is not None:
        path.write_text(content)
    rc = map_cmd.run(argparse.Namespace(file=str(path), json=False))
    out, err = capsys.readouterr()
    assert rc == 1 and out == ""
    assert err.startswith("error: ") and needle in err
    assert err.count("\n") == 1 and "Traceback" not in err


def test_map_debug_reraises(tmp_path: Path) -> None:
    from gtecat.eni.errors import EniError

    with pytest.raises(EniError):
        map_cmd.run(argparse.Namespace(file=str(tmp_path / "x.eni"), json=False, debug=True))


def test_through_the_main_dispatcher(
    examples_dir: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["map", "--json", str(examples_dir / "manual_fig5_4.eni")]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["slaves"][0]["gt_size"] == 24
    assert main(["map", str(examples_dir / "missing.eni")]) == 1
    assert capsys.readouterr().err.startswith("error: ")


@pytest.mark.parametrize("name", EXAMPLES)
def test_eni_new_writes_the_shipped_example(
    name: str, examples_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "out.eni"
    rc = eni_cmd.run(
        argparse.Namespace(
            eni_command="new", topology=str(examples_dir / f"{name}.toml"), output=str(out)
        )
    )
    assert rc == 0 and capsys.readouterr().out.startswith(f"wrote {out}")
    assert out.read_text() == (examples_dir / f"{name}.eni").read_text()


def test_eni_new_errors(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bad = tmp_path / "t.toml"
    bad.write_text('[[slave]]\nkind = "robot"\n')
    assert main(["eni", "new", str(bad), "-o", str(tmp_path / "o.eni")]) == 1
    err = capsys.readouterr().err
    assert err.startswith("error: ") and "kind must be" in err and str(bad) in err
    assert not (tmp_path / "o.eni").exists()
    assert main(["eni"]) == 1
    assert "usage" in capsys.readouterr().err


def test_eni_new_to_stdout(examples_dir: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["eni", "new", str(examples_dir / "manual_fig5_4.toml")]) == 0
    assert capsys.readouterr().out == (examples_dir / "manual_fig5_4.eni").read_text()
