"""Every tutorial page runs, as a new user follows it: in an empty folder outside the
repository, with the installed package only.

Each page (and the README) runs in its own process (``tutorial_runner.py``, started with
``python3 -P`` from a fresh temporary folder, ``PYTHONPATH`` and every ``GTECAT_*`` setting
removed). So the repository root is not on ``sys.path`` (``import tests`` fails there, and
``examples/`` is not reachable as a folder): a page finds its ENI and machine files only
through ``gtecat example ...``, as a user does. ``gtecat`` itself is the installed one - in
CI a ``pip install .``, on a developer's machine the editable install, which is the same
package read from the working tree (building a wheel into a fresh venv per run would only add
minutes; the wheel's contents are checked in ``tests/gtecat/cli/test_example_cmd.py``).
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from gtecat import gt
from tests.conftest import LONG, is_setting

from .tutorial_runner import blocks, matches, run_page

ROOT = Path(__file__).resolve().parents[2]
TUTORIAL = ROOT / "docs" / "tutorial"
PAGES = sorted(TUTORIAL.glob("[0-9][0-9]-*.md"))  # README.md is the index
RUNNER = Path(__file__).with_name("tutorial_runner.py")


def user_env() -> dict[str, str]:
    return {
        k: v
        for k, v in os.environ.items()
        if not is_setting(k) and k not in ("PYTHONPATH", "PYTHONSTARTUP")
    }


def follow(page: Path, folder: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-P", str(RUNNER), str(page)],
        cwd=folder,
        env=user_env(),
        capture_output=True,
        text=True,
        timeout=900,
    )


def test_there_are_tutorial_pages() -> None:
    names = [p.name for p in PAGES]
    assert names[:2] == ["01-raw-offsets.md", "02-homing-test.md"], names
    assert all(any(b.lang in ("python", "console") for b in blocks(p)) for p in PAGES)


#: what the default run follows: the first page and the README (no pytest run inside, a few
#: seconds); the pages that run pytest and ``gtecat run`` follow under GTECAT_LONG=1
QUICK = {"01-raw-offsets", "README"}


def _followed_here(page: Path) -> bool:
    return LONG or (page.stem if page.parent == TUTORIAL else "README") in QUICK


@pytest.fixture(scope="module")
def followed(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, str]:
    """Every page of this run followed by one runner process (an interpreter start and
    gtecat's import once, not per page), each page in an empty folder of its own:
    (folder, output)."""
    folder = tmp_path_factory.mktemp("pages")
    assert not folder.resolve().is_relative_to(ROOT)
    pages = [p for p in [*PAGES, ROOT / "README.md"] if _followed_here(p)]
    done = subprocess.run(
        [sys.executable, "-P", str(RUNNER), *map(str, pages)],
        cwd=folder,
        env=user_env(),
        capture_output=True,
        text=True,
        timeout=900,
    )
    return folder, done.stdout + done.stderr


@pytest.mark.xdist_group("tutorial_pages")  # one worker follows them all, once
@pytest.mark.parametrize(
    "page",
    [
        pytest.param(p, marks=() if _followed_here(p) else pytest.mark.long)
        for p in [*PAGES, ROOT / "README.md"]
    ],
    ids=[*(p.stem for p in PAGES), "README"],
)
def test_page_runs_in_an_empty_folder_with_the_installed_package(
    page: Path, followed: tuple[Path, str]
) -> None:
    folder, out = followed
    assert (folder / page.stem).is_dir()
    failed = [ln for ln in out.splitlines() if ln.startswith(f"FAILED {page.name}:")]
    assert not failed, out[out.index(failed[0]) :]
    assert any(ln.startswith(f"{page.name}: ") and "blocks ran" in ln for ln in out.splitlines()), (
        out
    )


def test_every_page_starts_from_a_shipped_example() -> None:
    """No page reads the repository's examples/ folder: a user has none."""
    for page in [*PAGES, ROOT / "README.md"]:
        code = "".join(b.code for b in blocks(page))
        assert "examples/" not in code, page.name
        first = next(b for b in blocks(page) if b.lang == "console")
        assert first.code.startswith("$ gtecat example "), page.name


def test_the_readme_shows_the_first_script_as_shipped() -> None:
    shown = [b.code for b in blocks(ROOT / "README.md") if b.lang == "python"]
    assert shown[0] == (ROOT / "examples" / "first_script.py").read_text(encoding="utf-8")


def test_no_internal_references_in_what_users_read() -> None:
    words = ("DESIGN.md", "../shared", "cia402-facts", "seed 0", "STYLE.md")
    pages = [*TUTORIAL.glob("*.md"), ROOT / "README.md", *(ROOT / "docs").glob("reference/*.md")]
    for page in pages:
        text = page.read_text(encoding="utf-8")
        for w in words:
            assert w not in text, f"{page.name}: {w}"


# --- the runner itself ----------------------------------------------------------------------
@pytest.fixture
def workdir(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    for k in [k for k in os.environ if is_setting(k)]:
        monkeypatch.delenv(k)
    monkeypatch.chdir(tmp_path)
    gt.GT_Close()
    return tmp_path


def test_expected_output_matching() -> None:
    assert matches(["a", "...", "d"], ["a", "b", "c", "d"])
    assert matches(["a", "..."], ["a"])
    assert not matches(["a", "...", "d"], ["a", "b", "c"])
    assert not matches(["a", "b"], ["a", "b", "c"])
    assert matches(["trace: ... cycles -> x.csv"], ["trace: 2710 cycles -> x.csv"])
    assert not matches(["trace: ... cycles -> x.csv"], ["trace: 2710 cycles -> y.csv"])


def test_runner_fails_on_wrong_output_and_failing_code(workdir: Path) -> None:
    page = workdir / "page.md"
    page.write_text("```console\n$ gtecat example\nnot what it prints\n```\n")
    with pytest.raises(AssertionError, match=r"page.md:1: `gtecat example"):
        run_page(page)
    page.write_text("text\n\n```python\nx = 1\n```\n\n```python\nassert x == 2\n```\n")
    with pytest.raises(AssertionError) as e:
        run_page(page)
    assert "in the python block at page.md:7" in "".join(e.value.__notes__)


def test_runner_writes_files_and_runs_shell_lines(workdir: Path) -> None:
    page = workdir / "page.md"
    page.write_text(
        "```toml file=conf/a.toml\nx = 1\n```\n"
        "```sh run\npython3 -c \"import tomllib; assert tomllib.load(open('conf/a.toml', 'rb'))"
        "['x'] == 1\"\n```\n"
        "```sh\nfalse  # shown, not run\n```\n"
    )
    assert run_page(page) == 1
    assert (workdir / "conf" / "a.toml").read_text() == "x = 1\n"
    page.write_text("```sh run\npython3 -c 'raise SystemExit(3)'\n```\n")
    with pytest.raises(AssertionError, match="exited 3"):
        run_page(page)


@pytest.mark.long
def test_runner_as_a_process_reports_one_failure_line(tmp_path: Path) -> None:
    page = tmp_path / "page.md"
    page.write_text("```python\nassert 1 == 2, 'the reason'\n```\n")
    done = follow(page, tmp_path)
    assert done.returncode == 1 and "FAILED page.md: AssertionError: the reason" in done.stderr
