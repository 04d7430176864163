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


def test_a_cache_folder_keeps_the_model_for_the_next_process(tmp_path, monkeypatch) -> None:
    from gtecat.eni import reader

    cache, a, b = tmp_path / "cache", tmp_path / "a.eni", tmp_path / "b.eni"
    a.write_bytes(FIG52.read_bytes())
    first = read_eni(a, cache)
    assert len(list(cache.rglob("*.pickle"))) == 1
    monkeypatch.setattr(reader, "_PARSED", {})  # a new process
    monkeypatch.setattr(reader, "parse_eni", lambda *_: pytest.fail("parsed again"))
    assert read_eni(a, cache) == first
    b.write_bytes(FIG52.read_bytes())  # the same content elsewhere: its own source
    assert read_eni(b, cache).source == str(b)
    assert read_eni(b, cache).slaves == first.slaves


def test_a_damaged_cache_file_is_parsed_again(tmp_path) -> None:
    from gtecat.eni import reader

    cache, a = tmp_path / "cache", tmp_path / "a.eni"
    a.write_bytes(FIG52.read_bytes())
    first = read_eni(a, cache)
    (stored,) = cache.rglob("*.pickle")
    stored.write_bytes(b"\x80\x05not a pickle")
    reader._PARSED.clear()
    assert read_eni(a, cache) == first


def test_the_cache_folder_keeps_the_latest_models_only(tmp_path, monkeypatch) -> None:
    from gtecat.eni import reader

    monkeypatch.setattr(reader, "_CACHE_FILES", 2)
    cache, text = tmp_path / "cache", FIG52.read_bytes()
    for k in range(3):  # three contents (the same bus, blank lines added)
        f = tmp_path / f"bus{k}.eni"
        f.write_bytes(text + b"\n" * (k + 1))
        read_eni(f, cache)
    assert len(list(cache.rglob("*.pickle"))) == 2


def test_the_model_pickles_as_tuples_and_comes_back_equal() -> None:
    import pickle

    from gtecat.eni import model
    from gtecat.eni.reader import parse_eni

    config = parse_eni(FIG52.read_bytes(), str(FIG52))
    back = pickle.loads(pickle.dumps(config, protocol=pickle.HIGHEST_PROTOCOL))
    assert back == config and back.slaves[0].init_cmds == config.slaves[0].init_cmds
    shared = (config.slaves[0].identity,) * 2  # one object twice: still one after the trip
    again = pickle.loads(pickle.dumps(shared))
    assert again[0] is again[1] and again[0] == shared[0]
    entry = model.PdoEntry(0x6040, 0, 16, "Controlword", "UINT")
    assert entry.__getstate__() == (0x6040, 0, 16, "Controlword", "UINT", None)
