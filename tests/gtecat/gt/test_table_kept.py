"""The function table read once is kept in the cache folder; the next process loads it."""

from __future__ import annotations

from gtecat.gt import table, typedefs
from gtecat.gt.groups import groups


def test_the_kept_table_is_the_table_read(tmp_path, monkeypatch):
    monkeypatch.setenv("GTECAT_CACHE_DIR", str(tmp_path))
    found, read = table._load()  # read from the groups, then kept
    file = table._cache_file(found)
    assert file is not None and file.is_file()
    _, kept = table._load()  # loaded
    assert kept == read == table.collect(groups())
    assert list(kept) == list(read)
    assert all(kept[n].by_name == read[n].by_name for n in read)
    parsed = {k: list(v) for k, v in typedefs._PARSED.items()}
    typedefs._PARSED.clear()
    assert table._read_kept(file, found) is not None  # gives the typedefs back as well
    assert all(typedefs.parse(g.structs, g.name) == parsed[g.structs, g.name] for g in found)


def test_a_damaged_or_foreign_file_is_read_again(tmp_path, monkeypatch):
    monkeypatch.setenv("GTECAT_CACHE_DIR", str(tmp_path))
    found = groups()
    file = table._cache_file(found)
    file.parent.mkdir(parents=True)
    file.write_bytes(b"\x80\x05N.")  # a pickled None
    assert table._read_kept(file, found) is None
    file.write_bytes(b"not a pickle")
    assert table._read_kept(file, found) is None
    _, read = table._load()
    assert read == table.FUNCTIONS
    assert table._read_kept(file, found) is not None  # written anew


def test_the_key_is_the_groups_text(tmp_path, monkeypatch):
    monkeypatch.setenv("GTECAT_CACHE_DIR", str(tmp_path))
    found = groups()
    first = found[0]
    changed = (type(first)(**{**_fields(first), "prototypes": first.prototypes + "\n"}),)
    assert table._cache_file(found) != table._cache_file(changed + found[1:])


def _fields(g):
    return {k: getattr(g, k) for k in g.__slots__}
