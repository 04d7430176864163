"""The per-user cache's file writer (gtecat._cache.put_file)."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest

from gtecat._cache import put_file


def test_a_file_is_put_whole_over_the_old_one(tmp_path: Path) -> None:
    path = tmp_path / "a" / "b" / "store.bin"
    put_file(path, (b"old",))
    put_file(path, (b"new ", b"and ", b"whole"))
    assert path.read_bytes() == b"new and whole"
    assert sorted(p.name for p in path.parent.iterdir()) == ["store.bin"]


def test_a_write_that_fails_leaves_the_old_file_and_no_temporary(tmp_path: Path) -> None:
    path = tmp_path / "store.bin"
    put_file(path, (b"old",))

    def chunks() -> Iterator[bytes]:
        yield b"part of it"
        raise OSError(28, "No space left on device")

    with pytest.raises(OSError):
        put_file(path, chunks())
    assert path.read_bytes() == b"old"
    assert [p.name for p in tmp_path.iterdir()] == ["store.bin"]
