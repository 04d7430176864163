"""The reference pages: they exist, their links resolve, and they cover every command,
every machine-description key and every topology kind."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
REFERENCE = ROOT / "docs" / "reference"
PAGES = ["README.md", "config-files.md", "topology.md", "machine.md", "units.md", "cli.md"]
LINK = re.compile(r"\]\(([^)#\s]+)(#[^)]*)?\)")


@pytest.mark.parametrize("name", PAGES)
def test_page_exists_and_its_links_resolve(name: str) -> None:
    page = REFERENCE / name
    text = page.read_text(encoding="utf-8")
    for target, _anchor in LINK.findall(text):
        if "://" in target:
            continue
        assert (page.parent / target).exists(), f"{name}: {target}"


def test_every_command_is_in_the_commands_page() -> None:
    from gtecat.cli.main import build_parser

    parser = build_parser()
    verbs = next(a for a in parser._actions if a.dest == "command").choices
    text = (REFERENCE / "cli.md").read_text(encoding="utf-8")
    internal = {"controller", "lib", "compile"}  # native and program tools, their own pages
    for verb in set(verbs) - internal:
        assert f"`gtecat {verb}" in text or f"`{verb}`" in text, verb


def test_every_machine_key_is_described() -> None:
    from gtecat.drives.machine import _KEYS

    text = (REFERENCE / "machine.md").read_text(encoding="utf-8")
    for key in _KEYS:
        assert f"`{key}`" in text, key


def test_every_topology_kind_is_described() -> None:
    text = (REFERENCE / "topology.md").read_text(encoding="utf-8")
    for kind in ("servo", "io", "coupler", "generic"):
        assert f"| `{kind}` |" in text, kind


def test_units_name_both_unit_systems_of_homing_and_trap() -> None:
    text = (REFERENCE / "units.md").read_text(encoding="utf-8")
    assert re.search(r"GT_SetEcatHomingPrm.*\n.*counts/s²", text)
    assert "| `GT_SetVel`, `GT_GetVel` | `vel` | pulse/ms" in text
