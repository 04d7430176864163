"""The command line on consoles that are not UTF-8, in pipes, and with the file as an argument.

Slave names come from the configuration file in any script (GBK in a Googol INI,
Latin-1 in acontis XML); printing them must never turn a good file into
``internal error: UnicodeEncodeError`` (STYLE.md: ``error: ...`` and exit 1 only
for real errors).
"""

from __future__ import annotations

import io
import json
import sys
from pathlib import Path

import pytest

from gtecat.cli.main import main
from tests.conftest import EXAMPLES
from tests.eni.googol_text import GSlave, render

from .conftest import Cli

NAME = "伺服驱动器"


@pytest.fixture
def gbk_eni(tmp_path: Path) -> str:
    path = tmp_path / "Gecat.eni"
    drive = GSlave(NAME, 0x705, 0x1, [[(0x6040, 0, 16)]], [[(0x6041, 0, 16)]], True, 1)
    path.write_bytes(render([drive]).encode("gbk"))
    return str(path)


def _ascii_console(monkeypatch: pytest.MonkeyPatch) -> io.BytesIO:
    raw = io.BytesIO()
    monkeypatch.setattr(sys, "stdout", io.TextIOWrapper(raw, encoding="ascii"))
    return raw


def test_map_json_on_an_ascii_console_escapes_names(
    gbk_eni: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    raw = _ascii_console(monkeypatch)
    assert main(["map", gbk_eni, "--json"]) == 0
    sys.stdout.flush()
    doc = json.loads(raw.getvalue().decode("ascii"))
    assert doc["slaves"][0]["name"] == NAME and doc["slaves"][0]["axes"] == [1]


def test_map_table_on_an_ascii_console_does_not_fail(
    gbk_eni: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    raw = _ascii_console(monkeypatch)
    assert main(["map", gbk_eni]) == 0
    sys.stdout.flush()
    assert "\\u4f3a\\u670d" in raw.getvalue().decode("ascii")


class _ClosedPipe(io.StringIO):
    def write(self, s: str) -> int:
        raise BrokenPipeError(32, "Broken pipe")


def test_a_closed_pipe_is_not_an_error(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """``gtecat map x.eni | head``: the reader leaving is no ``error: [Errno 32]``."""
    monkeypatch.setattr(sys, "stdout", _ClosedPipe())
    assert main(["map", str(EXAMPLES / "manual_fig5_2.eni")]) == 0
    assert capsys.readouterr().err == ""


@pytest.mark.parametrize("verb", ["slaves", "pdos"])
def test_slaves_and_pdos_take_the_file_as_an_argument(cli: Cli, verb: str) -> None:
    rc, out, err = cli(verb, str(EXAMPLES / "manual_fig5_2.eni"), "--json")
    assert rc == 0 and err == ""
    assert len(json.loads(out)) == 4
