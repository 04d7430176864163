"""Every code block of every tutorial page runs (issue 8 deliver 4).

Each page of ``docs/tutorial/*.md`` runs as one test, its blocks in order, in a fresh
working directory holding a copy of the repository's ``examples/`` (the tutorials are
followed from the repository root):

* ```` ```python ```` blocks share one namespace per page (a page is one script, cut
  into pieces by the text);
* a block whose info string says ``file=NAME`` is written to ``NAME`` first; a Python
  file named ``test_*.py`` is then imported and each of its ``test_*`` functions that
  takes no argument is called, as pytest would;
* ```` ```console ```` blocks hold ``$ gtecat ...`` commands, run in-process; the lines
  after a command are its expected output (a line ``...`` matches any lines, ``...``
  inside a line any text);
* other blocks (``sh``, ``toml`` without ``file=``, ``text``) are shown, not run.

A failure names the page and the line of the block.
"""

from __future__ import annotations

import contextlib
import inspect
import io
import os
import re
import runpy
import shlex
import shutil
from dataclasses import dataclass
from pathlib import Path

import pytest

from gtecat import gt
from gtecat.cli.main import main

ROOT = Path(__file__).resolve().parents[2]
TUTORIAL = ROOT / "docs" / "tutorial"
PAGES = sorted(TUTORIAL.glob("[0-9][0-9]-*.md"))  # README.md is the index
FENCE = re.compile(r"^```([\w-]*)([^\n]*)\n(.*?)^```\s*$", re.S | re.M)
ENV = ("GTECAT_ENI", "GTECAT_MACHINE", "GTECAT_CLOCK", "GTECAT_BACKEND", "GTECAT_IFACE",
       "GTECAT_BUS", "GTECAT_LOG")  # fmt: skip


@dataclass(frozen=True)
class Block:
    lang: str
    info: str
    code: str
    line: int  # line of the opening fence, 1-based

    @property
    def file(self) -> str | None:
        m = re.search(r"\bfile=(\S+)", self.info)
        return m.group(1) if m else None


def blocks(page: Path) -> list[Block]:
    text = page.read_text(encoding="utf-8")
    return [
        Block(m.group(1), m.group(2).strip(), m.group(3), text.count("\n", 0, m.start()) + 1)
        for m in FENCE.finditer(text)
    ]


def _matches(expected: list[str], actual: list[str]) -> bool:
    """Line-wise equality where an expected ``...`` line matches any number of lines."""
    if not expected:
        return not actual
    if expected[0] == "...":
        return any(_matches(expected[1:], actual[i:]) for i in range(len(actual) + 1))
    return bool(actual) and _line(expected[0], actual[0]) and _matches(expected[1:], actual[1:])


def _line(expected: str, actual: str) -> bool:
    """Equal, where ``...`` inside an expected line matches any text."""
    if "..." not in expected:
        return expected == actual
    return re.fullmatch(".*".join(map(re.escape, expected.split("..."))), actual) is not None


def run_console(block: Block, where: str) -> None:
    commands: list[tuple[str, list[str]]] = []
    for line in block.code.splitlines():
        if line.startswith("$ "):
            commands.append((line[2:], []))
        elif commands:
            commands[-1][1].append(line.rstrip())
    for command, expected in commands:
        argv = shlex.split(command)
        assert argv[0] == "gtecat", f"{where}: only gtecat commands run here: {command}"
        out = io.StringIO()
        with contextlib.redirect_stdout(out):
            rc = main(argv[1:])
        actual = [x.rstrip() for x in out.getvalue().splitlines()]
        assert rc == 0, f"{where}: `{command}` exited {rc}"
        while expected and not expected[-1]:
            expected.pop()
        assert _matches(expected, actual), f"{where}: `{command}` printed:\n" + "\n".join(actual)


def run_test_file(path: Path, where: str) -> int:
    ns = runpy.run_path(str(path), run_name=path.stem)
    tests = [
        f
        for name, f in ns.items()
        if name.startswith("test_") and callable(f) and not inspect.signature(f).parameters
    ]
    assert tests, f"{where}: {path.name} defines no test function"
    for f in tests:
        gt.GT_Close()
        try:
            f()
        except Exception as e:
            e.add_note(f"{where}: {path.name}::{f.__name__}")
            raise
        finally:
            gt.GT_Close()
    return len(tests)


def test_there_are_tutorial_pages() -> None:
    names = [p.name for p in PAGES]
    assert names[:2] == ["01-raw-offsets.md", "02-homing-test.md"], names
    assert all(any(b.lang in ("python", "console") for b in blocks(p)) for p in PAGES)


def run_page(page: Path, cwd: Path) -> int:
    """Run every block of ``page`` in ``cwd`` (the caller chdirs); how many ran."""
    root = ROOT if page.is_relative_to(ROOT) else page.parent
    ns: dict[str, object] = {"__name__": "__tutorial__"}
    ran = 0
    gt.GT_Close()
    try:
        for b in blocks(page):
            where = f"{page.relative_to(root)}:{b.line}"
            if b.file:
                Path(b.file).parent.mkdir(parents=True, exist_ok=True)
                Path(b.file).write_text(b.code, encoding="utf-8")
                if b.lang == "python" and Path(b.file).name.startswith("test_"):
                    ran += run_test_file(Path(b.file), where)
                continue
            if b.lang == "python":
                try:
                    exec(compile(b.code, where, "exec"), ns)
                except Exception as e:
                    e.add_note(f"in the python block at {where}")
                    raise
                ran += 1
            elif b.lang == "console":
                run_console(b, where)
                ran += 1
    finally:
        gt.GT_Close()
    assert os.getcwd() == str(cwd), f"{page.name} changed the working directory"
    return ran


@pytest.fixture
def workdir(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A fresh working directory with the examples, no GTECAT_* settings."""
    for k in ENV:
        monkeypatch.delenv(k, raising=False)
    shutil.copytree(ROOT / "examples", tmp_path / "examples")
    monkeypatch.chdir(tmp_path)
    return tmp_path


@pytest.mark.parametrize("page", PAGES, ids=[p.stem for p in PAGES])
def test_tutorial_page_runs(page: Path, workdir: Path) -> None:
    assert run_page(page, workdir), f"{page.name}: nothing ran"


# --- the runner itself ----------------------------------------------------------------------
def test_expected_output_matching() -> None:
    assert _matches(["a", "...", "d"], ["a", "b", "c", "d"])
    assert _matches(["a", "..."], ["a"])
    assert not _matches(["a", "...", "d"], ["a", "b", "c"])
    assert not _matches(["a", "b"], ["a", "b", "c"])
    assert _matches(["trace: ... cycles -> x.csv"], ["trace: 2710 cycles -> x.csv"])
    assert not _matches(["trace: ... cycles -> x.csv"], ["trace: 2710 cycles -> y.csv"])


def test_runner_fails_on_wrong_output_and_failing_code(workdir: Path) -> None:
    page = workdir / "page.md"
    page.write_text(
        "```console\n$ gtecat map examples/manual_fig5_2.eni\nnot what it prints\n```\n"
    )
    with pytest.raises(AssertionError, match=r"page.md:1: `gtecat map"):
        run_page(page, workdir)
    page.write_text("text\n\n```python\nx = 1\n```\n\n```python\nassert x == 2\n```\n")
    with pytest.raises(AssertionError) as e:
        run_page(page, workdir)
    assert "in the python block at page.md:7" in "".join(e.value.__notes__)


def test_runner_writes_files_and_runs_their_tests(workdir: Path) -> None:
    page = workdir / "page.md"
    page.write_text(
        "```toml file=conf/a.toml\nx = 1\n```\n"
        "```python file=test_a.py\nimport tomllib\n"
        "def test_reads():\n    assert tomllib.load(open('conf/a.toml', 'rb'))['x'] == 1\n"
        "def test_fails():\n    assert False, 'ran'\n```\n"
    )
    with pytest.raises(AssertionError, match="ran") as e:
        run_page(page, workdir)
    assert "test_a.py::test_fails" in "".join(e.value.__notes__)
    assert (workdir / "conf" / "a.toml").read_text() == "x = 1\n"


def test_readme_code_runs(workdir: Path) -> None:
    """The README's first script (and any other block it gains) runs as printed."""
    assert run_page(ROOT / "README.md", workdir) >= 1
