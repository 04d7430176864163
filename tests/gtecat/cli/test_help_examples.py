"""Every example that a ``--help`` shows runs as written (in-process, in a folder holding the
files the examples name), and every command has examples.

An example line is a line of a help text that starts with ``gtecat `` (after its indent);
two spaces or more end the command and start its comment.  Pipes run in turn (the next
command reads the previous one's output); ``> FILE`` keeps the output in FILE.  Examples
that need what a test machine lacks - a network card, a running controller, Graphviz, a
server that runs until stopped - are parsed (argparse accepts them) but not run; NEEDS says
which and why, so the list stays honest.
"""

from __future__ import annotations

import argparse
import io
import re
import shlex
import shutil
from contextlib import nullcontext, redirect_stdout
from pathlib import Path

import pytest

import gtecat
from gtecat.cli.main import build_parser, main
from gtecat.cli.run_cmd import CHECK_FINDINGS

SHIPPED = Path(gtecat.__file__).parent / "examples"

#: a text in the example -> why it is parsed only
NEEDS = {
    "--backend pysoem": "a real EtherCAT NIC",
    "--controller unix:": "a running gtecat controller",
    "--png": "Graphviz's dot",
    "gtecat serve ": "a network interface (runs until stopped)",
    "gtecat controller": "runs until stopped",
    "gtecat sweep": "a sweep of many cases (tests/gtecat/sweep runs them)",
    "--attach ": "a running gtecat with that id (gtecat ps)",
    "gtecat panel": "serves a page until stopped (tests/gtecat/inspect runs it)",
    "gtecat lib --cflags": "a C compiler (builds libgts once)",
    "gtecat lib --windows": "the mingw-w64 cross compiler (builds gts.dll once)",
    "gtecat demo": "the whole demo (tests/gtecat/test_demo.py runs it)",
    "gtecat fault inject": "a running gtecat to break (tests/gtecat/faults)",
    "gtecat fault list": "a running gtecat (tests/gtecat/faults)",
    "gtecat fault clear": "a running gtecat (tests/gtecat/faults)",
    "-- ./my_machine": "a C program built against libgts (tests/gtecat/faults, GTECAT_LONG)",
}


def _parsers() -> list[tuple[str, argparse.ArgumentParser]]:
    out: list[tuple[str, argparse.ArgumentParser]] = []
    seen: set[int] = set()

    def walk(p: argparse.ArgumentParser, path: str) -> None:
        if id(p) in seen:
            return
        seen.add(id(p))
        out.append((path, p))
        for a in p._actions:
            if isinstance(a, argparse._SubParsersAction):
                for name, child in a.choices.items():
                    walk(child, f"{path} {name}".strip())

    walk(build_parser(), "")
    return out


PARSERS = _parsers()


def _examples(p: argparse.ArgumentParser) -> list[str]:
    text = p.format_help()
    lines = []
    for raw in text.splitlines():
        s = raw.strip()
        if s.startswith("$ "):
            s = s[2:]
        if s.startswith("gtecat "):
            lines.append(s.split("  ")[0].strip())
    return lines


EXAMPLES = sorted({e for _, p in PARSERS for e in _examples(p)})


def test_every_command_has_examples():
    bare = [path or "gtecat" for path, p in PARSERS if not _examples(p)]
    assert not bare, f"--help without an example: {bare}"


@pytest.fixture
def folder(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A user's folder with the files the examples name."""
    for name in ("manual_fig5_2.eni", "manual_fig5_2.toml", "homing_probe_machine.toml"):
        shutil.copy(SHIPPED / name, tmp_path / name)
    shutil.copy(SHIPPED / "manual_fig5_2.eni", tmp_path / "Gecat.eni")
    shutil.copy(SHIPPED / "manual_fig5_2.toml", tmp_path / "my_bus.toml")
    shutil.copy(SHIPPED / "homing_probe_machine.toml", tmp_path / "machine.toml")
    shutil.copy(SHIPPED / "example_10_1_sum.c", tmp_path / "sum.c")
    shutil.copy(SHIPPED / "first_script.py", tmp_path / "first_script.py")
    for script in ("home.py", "my_machine.py"):
        (tmp_path / script).write_text("from gtecat import gt\nprint(gt.GT_Open())\n")
    monkeypatch.chdir(tmp_path)
    return tmp_path


def _run(argv: list[str], stdin: str | None, monkeypatch: pytest.MonkeyPatch) -> tuple[int, str]:
    if stdin is not None:
        monkeypatch.setattr("sys.stdin", io.StringIO(stdin))
    buf = io.StringIO()
    with redirect_stdout(buf):
        try:
            rc = main(argv)
        except SystemExit as e:  # --help, --version
            rc = int(e.code or 0)
    return rc, buf.getvalue()


@pytest.mark.long
def test_every_example_runs(folder: Path, monkeypatch: pytest.MonkeyPatch, capsys) -> None:
    assert len(EXAMPLES) > 20
    ran = []
    for example in EXAMPLES:
        need = next((why for key, why in NEEDS.items() if key in example), None)
        stages = [shlex.split(s) for s in re.split(r" \| | && ", example)]  # a pipe or a sequence
        if need is not None:
            for words in stages:
                args = [w for w in words[1:] if w != ">"]
                with pytest.raises(SystemExit) if "-h" in args else nullcontext():
                    build_parser().parse_args(args[: args.index(">")] if ">" in args else args)
            continue
        piped = None
        for words in stages:
            target = None
            if ">" in words:
                k = words.index(">")
                words, target = words[:k], words[k + 1]
            if "/dev/stdin" in words and piped is not None:
                (folder / "piped.eni").write_text(piped)
                words = [w if w != "/dev/stdin" else "piped.eni" for w in words]
            rc, out = _run(words[1:], piped, monkeypatch)
            err = capsys.readouterr().err
            # `run --check` exits CHECK_FINDINGS when the example's script drew findings
            ok = (0, CHECK_FINDINGS) if "--check" in words else (0,)
            assert rc in ok, f"{example!r} exited {rc}: {err.strip()[-500:]}"
            if target is not None:
                (folder / target).write_text(out)
            piped = out
        ran.append(example)
    assert len(ran) > len(EXAMPLES) // 2, ran
