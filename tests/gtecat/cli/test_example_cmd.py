"""``gtecat example``: the shipped examples are package data, listed, copied, and they run
where they are copied to, printing what their ``*.expected.txt`` says.

``GTECAT_REGEN_EXPECTED=1 python3 -m pytest tests/gtecat/cli/test_example_cmd.py`` rewrites the
expected outputs (and only then).
"""

from __future__ import annotations

import contextlib
import io
import json
import os
import runpy
import subprocess
import sys
from importlib import resources
from pathlib import Path

import pytest

from gtecat import gt
from gtecat.cli import example_cmd
from tests.conftest import EXAMPLES, ROOT, is_setting

from .conftest import Cli

NAMES = list(example_cmd.examples())
SCRIPTS = [n for n, e in example_cmd.examples().items() if e.script and e.script.endswith(".py")]
#: examples whose script ends with a non-zero exit code on purpose
EXIT_CODES: dict[str, int] = {}
REGEN = os.environ.get("GTECAT_REGEN_EXPECTED") == "1"


def test_the_examples_are_package_data_and_the_repository_folder_is_the_same() -> None:
    shipped = resources.files("gtecat") / "examples"
    assert shipped.joinpath("index.toml").is_file()
    assert Path(str(shipped)).resolve() == EXAMPLES.resolve()  # examples/ paths stay valid


def test_every_listed_file_exists_and_every_file_is_listed() -> None:
    listed = {f for e in example_cmd.examples().values() for f in e.all_files()}
    for f in listed:
        assert (EXAMPLES / f).is_file(), f
    on_disk = {
        str(p.relative_to(EXAMPLES))
        for p in EXAMPLES.rglob("*")
        if p.is_file() and "__pycache__" not in p.parts and p.name != "index.toml"
    }
    assert on_disk - listed == set(), "files no example ships"


def test_the_wheel_would_carry_the_examples() -> None:
    """pyproject's package data names every kind of file the examples have."""
    import tomllib

    data = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]
    patterns = data["package-data"]["gtecat"]
    for f in {f for e in example_cmd.examples().values() for f in e.all_files()} | {"index.toml"}:
        assert any(Path("examples", f).match(p) for p in patterns), f


def test_listing(cli: Cli) -> None:
    rc, out, err = cli("example")
    assert rc == 0 and err == ""
    for name in ("manual_fig5_2", "homing_probe", "example_5_2", "example_7_1"):
        assert any(line.split()[0] == name for line in out.splitlines()[1:] if line), name
    assert "gtecat example NAME [-o DIR]" in out
    rc, out, _ = cli("example", "--json")
    rows = json.loads(out)
    assert [r["name"] for r in rows] == NAMES
    fig = rows[0]
    assert {"file": "manual_fig5_2.eni", "role": "ENI"} in fig["files"]
    assert {"file": "manual_fig5_2.toml", "role": "topology (gtecat eni new)"} in fig["files"]
    homing = next(r for r in rows if r["name"] == "example_5_2")
    assert {"file": "homing_probe_machine.toml", "role": "machine description"} in homing["files"]
    assert homing["script"] == "example_5_2_homing.py"


def test_write_into_a_folder(cli: Cli, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    rc, out, err = cli("example", "example_5_2")
    assert rc == 0 and err == ""
    folder = tmp_path / "example_5_2"
    assert sorted(p.name for p in folder.iterdir()) == [
        "example_5_2_homing.expected.txt",
        "example_5_2_homing.py",
        "homing_probe.eni",
        "homing_probe_machine.toml",
    ]
    assert out.splitlines()[0].startswith("wrote 4 files to example_5_2/: manual example 5-2")
    assert out.splitlines()[-1] == "next: cd example_5_2 && python3 example_5_2_homing.py"
    # again: same files, nothing to refuse
    assert cli("example", "example_5_2")[0] == 0
    rc, out, _ = cli("example", "manual_fig5_2", "-o", ".")
    assert rc == 0 and out.splitlines()[-1] == "next: python3 first_script.py"
    assert (tmp_path / "manual_fig5_2.eni").read_bytes() == (
        EXAMPLES / "manual_fig5_2.eni"
    ).read_bytes()
    rc, out, _ = cli("example", "manual_fig5_4", "-o", "buses")
    assert rc == 0 and out.splitlines()[-1] == "next: cd buses && gtecat map manual_fig5_4.eni"


def test_a_changed_file_is_not_overwritten_without_force(cli: Cli, tmp_path: Path) -> None:
    mine = tmp_path / "manual_fig5_2.eni"
    mine.write_text("my own ENI\n")
    rc, out, err = cli("example", "manual_fig5_2", "-o", str(tmp_path))
    assert rc == 1 and out == "" and err.count("\n") == 1
    assert f"{mine} exists and differs" in err and "--force" in err
    assert mine.read_text() == "my own ENI\n" and not (tmp_path / "first_script.py").exists()
    assert cli("example", "manual_fig5_2", "-o", str(tmp_path), "--force")[0] == 0
    assert mine.read_bytes() == (EXAMPLES / "manual_fig5_2.eni").read_bytes()


@pytest.mark.parametrize(
    ("name", "words"),
    [("nope", "no example called 'nope'; `gtecat example` lists them"), ("example_7", "ambiguous")],
)
def test_unknown_or_ambiguous_names_are_one_line(cli: Cli, name: str, words: str) -> None:
    rc, out, err = cli("example", name)
    assert rc == 1 and out == "" and err.startswith("error: ") and err.count("\n") == 1
    assert words in err


def test_a_unique_prefix_is_enough(cli: Cli, tmp_path: Path) -> None:
    rc, _, _ = cli("example", "example_5_3", "-o", str(tmp_path))
    assert rc == 0 and (tmp_path / "example_5_3_probe.py").is_file()


@pytest.fixture
def clean_env(monkeypatch: pytest.MonkeyPatch) -> dict[str, str]:
    for k in list(os.environ):
        if is_setting(k):
            monkeypatch.delenv(k)
    return {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}


@pytest.mark.parametrize("name", SCRIPTS)
@pytest.mark.sample(1)
def test_each_script_runs_where_it_was_copied_and_prints_what_it_promises(
    name: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, clean_env: dict[str, str]
) -> None:
    example = example_cmd.find(name)
    example_cmd.write(example, tmp_path)
    script = tmp_path / Path(example.script or "").name
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(sys, "argv", [str(script)])
    out, rc = io.StringIO(), 0
    gt.GT_Close()
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(io.StringIO()):
            runpy.run_path(str(script), run_name="__main__")
    except SystemExit as e:
        rc = e.code if isinstance(e.code, int) else (0 if e.code is None else 1)
    finally:
        gt.GT_Close()
    assert rc == EXIT_CODES.get(name, 0)
    expected = EXAMPLES / (example.expected or Path(example.script or "").stem + ".expected.txt")
    if REGEN:
        expected.write_text(out.getvalue(), encoding="utf-8")
    assert expected.is_file(), f"no {expected.name}: run with GTECAT_REGEN_EXPECTED=1"
    assert out.getvalue() == expected.read_text(encoding="utf-8")


def test_the_first_script_runs_with_only_the_installed_package(
    tmp_path: Path, clean_env: dict[str, str]
) -> None:
    """A new user's folder: no repository on sys.path, the files from `gtecat example`."""
    env = dict(clean_env, PYTHONNOUSERSITE="1")
    run = subprocess.run(
        [sys.executable, "-P", "-m", "gtecat", "example", "manual_fig5_2", "-o", "."],
        cwd=tmp_path, env=env, capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert run.returncode == 0, run.stderr
    probe = "import sys, importlib.util; print(importlib.util.find_spec('tests') is None)"
    run = subprocess.run(
        [sys.executable, "-P", "-c", probe], cwd=tmp_path, env=env, capture_output=True, text=True
    )
    assert run.stdout.strip() == "True", "the repository is on sys.path"
    run = subprocess.run(
        [sys.executable, "-P", "first_script.py"],
        cwd=tmp_path, env=env, capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert run.returncode == 0, run.stderr
    assert run.stdout == (EXAMPLES / "first_script.expected.txt").read_text()


def test_no_example_prints_the_reason_with_a_second_prefix() -> None:
    """GTE_GetLastError() already says "GT_X returned N: ..."; adding it again doubles it."""
    import re

    doubled = re.compile(r"(returned|=) \{rtn\}: \{gt\.GTE_GetLastError\(\)\}")
    for path in EXAMPLES.rglob("*.py"):
        assert not doubled.search(path.read_text(encoding="utf-8")), path.name
