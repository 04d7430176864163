"""Run every code block of one tutorial page, in the current folder, as a reader would.

    python3 -P tutorial_runner.py PAGE.md [PAGE.md...]

Standalone on purpose: it imports nothing of the repository but the installed ``gtecat``,
so the tests run it from an empty temporary folder outside the checkout (``-P``: not even
this file's folder goes on ``sys.path``) and a page only passes if it works for someone
who has nothing but ``pip install gtecat``. Given several pages, it runs each in an empty
folder of its own below the current one (named after the page), one after the other in the
same interpreter. The blocks:

* ```` ```python ```` blocks share one namespace per page (a page is one script, cut
  into pieces by the text);
* a block whose info string says ``file=NAME`` is written to ``NAME`` (nothing runs);
* ```` ```console ```` blocks hold ``$ gtecat ...`` commands, run in-process; the lines
  after a command are its expected output (a line ``...`` matches any lines, ``...``
  inside a line any text);
* ```` ```sh run ```` blocks are run line by line by the shell (``python3`` is the running
  interpreter); each line must exit 0 - this is how a page's ``pytest`` runs;
* other blocks (``sh``, ``toml`` without ``file=``, ``text``) are shown, not run.

A failure names the page and the line of the block.
"""

from __future__ import annotations

import contextlib
import io
import os
import re
import shlex
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

FENCE = re.compile(r"^```([\w-]*)([^\n]*)\n(.*?)^```\s*$", re.S | re.M)


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

    @property
    def runs(self) -> bool:
        return self.lang == "sh" and re.search(r"(^|\s)run(\s|$)", self.info) is not None


def blocks(page: Path) -> list[Block]:
    text = page.read_text(encoding="utf-8")
    return [
        Block(m.group(1), m.group(2).strip(), m.group(3), text.count("\n", 0, m.start()) + 1)
        for m in FENCE.finditer(text)
    ]


def matches(expected: list[str], actual: list[str]) -> bool:
    """Line-wise equality where an expected ``...`` line matches any number of lines."""
    if not expected:
        return not actual
    if expected[0] == "...":
        return any(matches(expected[1:], actual[i:]) for i in range(len(actual) + 1))
    return (
        bool(actual) and line_matches(expected[0], actual[0]) and matches(expected[1:], actual[1:])
    )


def line_matches(expected: str, actual: str) -> bool:
    """Equal, where ``...`` inside an expected line matches any text."""
    if "..." not in expected:
        return expected == actual
    return re.fullmatch(".*".join(map(re.escape, expected.split("..."))), actual) is not None


def run_console(block: Block, where: str) -> None:
    from gtecat.cli.main import main

    commands: list[tuple[str, list[str]]] = []
    for line in block.code.splitlines():
        if line.startswith("$ "):
            commands.append((line[2:], []))
        elif commands:
            commands[-1][1].append(line.rstrip())
    for command, expected in commands:
        argv = shlex.split(command)
        assert argv[0] == "gtecat", f"{where}: only gtecat commands run here: {command}"
        out, err = io.StringIO(), io.StringIO()
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            rc = main(argv[1:])
        actual = [x.rstrip() for x in out.getvalue().splitlines()]
        assert rc == 0, f"{where}: `{command}` exited {rc}: {err.getvalue().strip()}"
        while expected and not expected[-1]:
            expected.pop()
        assert matches(expected, actual), f"{where}: `{command}` printed:\n" + "\n".join(actual)


def run_shell(block: Block, where: str) -> None:
    for line in block.code.splitlines():
        command = line.strip()
        if not command or command.startswith("#"):
            continue
        argv = shlex.split(command)
        if argv[0] in ("python3", "python"):
            argv[0] = sys.executable
        done = subprocess.run(argv, capture_output=True, text=True, timeout=600)
        assert done.returncode == 0, (
            f"{where}: `{command}` exited {done.returncode}:\n{done.stdout}{done.stderr}"
        )


def run_page(page: Path, cwd: Path | None = None) -> int:
    """Run every block of ``page`` in the current folder; how many ran."""
    from gtecat import gt

    cwd = cwd or Path.cwd()
    ns: dict[str, object] = {"__name__": "__tutorial__"}
    ran = 0
    gt.GT_Close()
    try:
        for b in blocks(page):
            where = f"{page.name}:{b.line}"
            if b.file:
                Path(b.file).parent.mkdir(parents=True, exist_ok=True)
                Path(b.file).write_text(b.code, encoding="utf-8")
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
            elif b.runs:
                run_shell(b, where)
                ran += 1
    finally:
        gt.GT_Close()
    assert os.getcwd() == str(cwd), f"{page.name} changed the working directory"
    return ran


def follow_page(page: Path) -> int:
    """Run ``page`` in the current folder with the folder on ``sys.path`` (the page's own
    modules: test_homing.py, ...), and forget those modules afterwards; 0 if it passed."""
    here = os.getcwd()
    sys.path.insert(0, here)
    try:
        ran = run_page(page)
    except Exception as e:
        notes = "".join(f"\n{n}" for n in getattr(e, "__notes__", []))
        print(f"FAILED {page.name}: {type(e).__name__}: {e}{notes}", file=sys.stderr, flush=True)
        return 1
    finally:
        sys.path.remove(here)
        for name, mod in list(sys.modules.items()):
            if (getattr(mod, "__file__", None) or "").startswith(here + os.sep):
                del sys.modules[name]
    print(f"{page.name}: {ran} blocks ran", flush=True)
    return 0 if ran else 1


def main(argv: list[str]) -> int:
    """One page in the current folder; several pages each in an empty folder of its own
    below the current one, named after the page (one interpreter for all of them)."""
    if not argv:
        print(__doc__.split("\n\n")[1], file=sys.stderr)
        return 2
    pages = [Path(a).resolve() for a in argv]
    if len(pages) == 1:
        return follow_page(pages[0])
    failed = 0
    top = os.getcwd()
    for page in pages:
        folder = Path(top) / page.stem
        folder.mkdir()
        os.chdir(folder)
        try:
            failed += follow_page(page)
        finally:
            os.chdir(top)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
