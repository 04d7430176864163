"""What a user reads speaks to a user: no issue numbers, seed names, the project's internal
files or folders beside the checkout, in the README, the docs, every ``--help``, the GT
functions' ``help()``, the shipped examples and every message text of the package (its string
literals, docstrings aside); and the links of the README and the docs resolve."""

from __future__ import annotations

import argparse
import io
import re
import tokenize
from pathlib import Path

import pytest

from gtecat.cli.main import build_parser
from tests.conftest import ROOT

#: what a user must not meet, with why it means nothing to them
INTERNAL = re.compile(
    r"issue[ -]?\d+|issue \"|\bseeds? ?0\d\d\b|seeds/|\.\./shared|/work/|DESIGN\.md|STYLE\.md"
    r"|\bthe lead\b|\bhelper\b(?= (?:branch|session))",
    re.IGNORECASE,
)
#: a piece of every alternative of INTERNAL, case folded: a text without any of them holds no
#: hit (finding that takes a seventh of INTERNAL's search through the package's 4 MB)
_PIECES = ("issue", "seed", "../shared", "/work/", "design.md", "style.md", "the lead", "helper")
DOCS = [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]
PACKAGES = ["gtecat", "eni", "drives"]


def _may_hit(text: str) -> bool:
    folded = text.casefold()
    return any(piece in folded for piece in _PIECES)


def test_every_alternative_of_internal_has_a_piece() -> None:
    """One example of each alternative of INTERNAL, found by INTERNAL and by _PIECES (a new
    alternative fails here until it has an example and a piece)."""
    examples = (
        "Issue 12",
        'issue "x"',
        "SEED 042",
        "seeds/",
        "../shared",
        "/work/",
        "design.md",
        "STYLE.md",
        "The Lead",
        "helper branch",
    )
    for example in examples:
        assert INTERNAL.search(example) and _may_hit(example), example
    depth, alternatives = 0, 1  # the "|" outside any group
    for c in INTERNAL.pattern:
        depth += (c == "(") - (c == ")")
        alternatives += c == "|" and not depth
    assert alternatives == len(examples)


def _hits(text: str) -> list[str]:
    out = []
    for n, line in enumerate(text.splitlines(), 1):
        for m in INTERNAL.finditer(line):
            out.append(f"{n}: ...{line[max(0, m.start() - 30) : m.end() + 30]}...")
    return out


@pytest.mark.parametrize("path", DOCS, ids=lambda p: str(p.relative_to(ROOT)))
def test_docs_speak_to_a_user(path: Path) -> None:
    assert not _hits(path.read_text(encoding="utf-8"))


def test_every_help_speaks_to_a_user() -> None:
    bad = []
    seen: set[int] = set()

    def walk(p: argparse.ArgumentParser) -> None:
        if id(p) in seen:
            return
        seen.add(id(p))
        bad.extend(f"{p.prog}: {h}" for h in _hits(p.format_help()))
        for a in p._actions:
            if isinstance(a, argparse._SubParsersAction):
                for child in a.choices.values():
                    walk(child)

    walk(build_parser())
    assert not bad


def test_gt_help_speaks_to_a_user() -> None:
    from gtecat import gt

    bad = []
    for name in dir(gt):
        obj = getattr(gt, name)
        if name.startswith(("GT", "T")) and getattr(obj, "__doc__", None):
            bad.extend(f"{name}: {h}" for h in _hits(obj.__doc__))
    bad.extend(f"gtecat.gt: {h}" for h in _hits(gt.__doc__ or ""))
    assert not bad


def _message_strings(path: Path) -> list[tuple[int, str]]:
    """The string literals of a module that are not docstrings (messages, help, output)."""
    out = []
    prev = None  # the token before, lines and comments aside
    for t in tokenize.generate_tokens(io.StringIO(path.read_text(encoding="utf-8")).readline):
        if t.type != tokenize.STRING and t.type != getattr(tokenize, "FSTRING_MIDDLE", -1):
            if t.type not in (tokenize.NL, tokenize.COMMENT):
                prev = t
            continue
        statement_start = prev is None or prev.type in (
            tokenize.NEWLINE,
            tokenize.INDENT,
            tokenize.DEDENT,
        )
        prev = t
        if statement_start and t.string.lstrip("rbuRBU").startswith(('"""', "'''")):
            continue  # a docstring (or a bare string statement): read by developers
        out.append((t.start[0], t.string))
    return out


def test_messages_speak_to_a_user() -> None:
    bad = []
    for pkg in PACKAGES:
        for path in sorted((ROOT / pkg).rglob("*.py")):
            text = path.read_text(encoding="utf-8")
            if not _may_hit(text) or not INTERNAL.search(text):
                continue  # nothing in the file at all: no string of it can hold a hit
            for line, text in _message_strings(path):
                for h in _hits(text):
                    bad.append(f"{path.relative_to(ROOT)}:{line}: {h.split(': ', 1)[1]}")
    assert not bad, "\n".join(bad)


def test_shipped_examples_speak_to_a_user() -> None:
    bad = []
    for path in sorted((ROOT / "gtecat" / "examples").rglob("*")):
        if path.is_file() and path.suffix in (".py", ".c", ".cpp", ".toml", ".cfg", ".txt", ".cs"):
            text = path.read_text(encoding="utf-8", errors="replace")
            bad.extend(f"{path.name}:{h}" for h in _hits(text))
            # written into the user's folder by `gtecat example`: no repository paths
            bad.extend(
                f"{path.name}: names {m.group(0)!r}"
                for m in re.finditer(r"(?<![\w.-])(?:examples|tests|tools)/\w", text)
            )
    assert not bad, "\n".join(bad)


_LINK = re.compile(r"\]\(([^)#\s]+)(?:#[^)]*)?\)")


@pytest.mark.parametrize("path", DOCS, ids=lambda p: str(p.relative_to(ROOT)))
def test_links_resolve_inside_the_repository(path: Path) -> None:
    broken = []
    for target in _LINK.findall(path.read_text(encoding="utf-8")):
        if re.match(r"[a-z]+:", target):  # http:, https:, mailto:
            continue
        resolved = (path.parent / target).resolve()
        if not resolved.exists() or ROOT not in (resolved, *resolved.parents):
            broken.append(target)
    assert not broken


_PATH = re.compile(r"`((?:gtecat|eni|drives|tools|tests|examples|docs)/[\w./-]+)`")


@pytest.mark.parametrize("path", DOCS, ids=lambda p: str(p.relative_to(ROOT)))
def test_the_files_the_docs_name_exist(path: Path) -> None:
    missing = [
        p for p in _PATH.findall(path.read_text(encoding="utf-8")) if not (ROOT / p).exists()
    ]
    assert not missing
