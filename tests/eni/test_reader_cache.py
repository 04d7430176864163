"""read_eni parses one file content once (gtecat.eni.reader._PARSED, keyed by its digest)."""

from __future__ import annotations

from pathlib import Path

import pytest

from gtecat.eni.errors import EniError
from gtecat.eni.reader import read_eni

ROOT = Path(__file__).resolve().parents[2]
FIG52 = ROOT / "examples" / "manual_fig5_2.eni"


def test_the_same_content_is_parsed_once_and_a_change_is_read_again(tmp_path) -> None:
    f = tmp_path / "bus.eni"
    text = FIG52.read_text(encoding="utf-8")
    f.write_text(text, encoding="utf-8")
    first = read_eni(f)
    assert read_eni(f) is first  # immutable model: shared
    f.write_text(text.replace("Slave_1", "Slave_1", 1) + "\n", encoding="utf-8")
    again = read_eni(f)
    assert again is not first and again == first  # new content, new parse, same model


def test_a_file_that_fails_fails_every_time(tmp_path) -> None:
    f = tmp_path / "bad.eni"
    f.write_text("<EtherCATConfig><Config>", encoding="utf-8")
    for _ in range(2):
        with pytest.raises(EniError):
            read_eni(f)


def test_the_same_bytes_under_another_name_keep_their_own_source(tmp_path) -> None:
    a, b = tmp_path / "a.eni", tmp_path / "b.eni"
    for f in (a, b):
        f.write_bytes(FIG52.read_bytes())
    assert read_eni(a).source != read_eni(b).source
