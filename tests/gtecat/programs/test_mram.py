"""The MRAM of 11.8: buffer, timed accesses, and a store that a crash cannot tear."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap

import pytest

from gtecat.programs import mram
from tests.conftest import ROOT

MS = 1_000_000


def test_access_takes_controller_time_then_status_1(tmp_path):
    m = mram.Mram(mram.MramStore(tmp_path / "m.mram"))
    assert m.status == 0
    m.set_data(0, list(range(64)))
    m.start(0, 64, 1, now_ns=0)
    assert m.status == 0
    m.tick(MS - 1)
    assert m.status == 0 and not (tmp_path / "m.mram").exists()
    m.tick(2 * MS)  # 1 ms + 1 ms per started 1024 words
    assert m.status == 1
    assert mram.MramStore(tmp_path / "m.mram").read()[:64] == list(range(64))
    assert mram.access_time_ns(4096) == 5 * MS


def test_a_write_takes_the_buffer_as_it_was_at_the_start(tmp_path):
    m = mram.Mram(mram.MramStore(tmp_path / "m.mram"))
    m.set_data(10, [1, 2, 3])
    m.start(10, 3, 1, now_ns=0)
    m.set_data(10, [9, 9, 9])
    m.tick(5 * MS)
    assert m.store.read()[10:13] == [1, 2, 3]


def test_read_fills_the_buffer_at_completion_and_stop_abandons(tmp_path):
    store = mram.MramStore(tmp_path / "m.mram")
    words = [0] * mram.WORDS
    words[100:103] = [-1, 32767, -32768]
    store.write(words)
    m = mram.Mram(store)
    m.start(100, 3, 0, now_ns=0)
    assert m.get_data(100, 3) == [0, 0, 0]
    m.tick(2 * MS)
    assert m.get_data(100, 3) == [-1, 32767, -32768] and m.status == 1
    m.set_data(0, [5])
    m.start(0, 1, 1, now_ns=0)
    m.stop()
    m.tick(10 * MS)
    assert m.status == 0 and store.read()[0] == 0


def test_a_damaged_store_fails_the_access(tmp_path):
    p = tmp_path / "m.mram"
    mram.MramStore(p).write([7] * mram.WORDS)
    data = bytearray(p.read_bytes())
    data[100] ^= 1
    p.write_bytes(bytes(data))
    m = mram.Mram(mram.MramStore(p))
    m.start(0, 1, 0, now_ns=0)
    m.tick(5 * MS)
    assert m.status == 0 and "damaged" in m.error


def test_a_failed_write_leaves_the_old_store(tmp_path, monkeypatch):
    p = tmp_path / "m.mram"
    store = mram.MramStore(p)
    store.write([1] * mram.WORDS)

    def boom(*a):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(os, "replace", boom)
    with pytest.raises(mram.MramError):
        store.write([2] * mram.WORDS)
    assert store.read() == [1] * mram.WORDS
    assert [x.name for x in tmp_path.iterdir()] == ["m.mram"]  # no temporary left


@pytest.mark.parametrize("where", ["after_write", "after_fsync", "after_replace"])
def test_a_process_killed_mid_write_never_leaves_a_torn_store(tmp_path, where):
    """A child writes the store and is killed (os._exit) at a point of the write."""
    p = tmp_path / "m.mram"
    mram.MramStore(p).write([1] * mram.WORDS)
    child = textwrap.dedent(
        f"""
        import os
        from gtecat.programs import mram
        real_write, real_fsync, real_replace = os.write, os.fsync, os.replace
        where = {where!r}
        def write(fd, data):
            if where == "after_write":
                real_write(fd, bytes(data)[: len(data) // 2])  # half the file, then die
                os._exit(9)
            return real_write(fd, data)
        def fsync(fd):
            real_fsync(fd)
            if where == "after_fsync":
                os._exit(9)
        def replace(a, b):
            real_replace(a, b)
            if where == "after_replace":
                os._exit(9)
        os.write, os.fsync, os.replace = write, fsync, replace
        mram.MramStore({str(p)!r}).write([2] * mram.WORDS)
        """
    )
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    r = subprocess.run([sys.executable, "-c", child], env=env, capture_output=True, timeout=60)
    assert r.returncode == 9, r.stderr.decode()
    store = mram.MramStore(p)  # the next open removes the dead child's temporary file
    words = store.read()  # never raises "damaged"
    assert words in ([1] * mram.WORDS, [2] * mram.WORDS)
    if where != "after_replace":
        assert words == [1] * mram.WORDS
    assert [x.name for x in tmp_path.iterdir()] == ["m.mram"]


def test_the_temporary_of_a_running_process_is_left_alone(tmp_path):
    p = tmp_path / "m.mram"
    mine = tmp_path / f".m.mram.{os.getpid()}.tmp"
    parent = tmp_path / f".m.mram.{os.getppid()}.tmp"  # alive: it runs this test's runner
    other = tmp_path / ".other.mram.1.tmp"
    for f in (mine, parent, other):
        f.write_bytes(b"x")
    assert mram.MramStore(p).removed == []
    assert sorted(x.name for x in tmp_path.iterdir()) == sorted(
        [mine.name, parent.name, other.name]
    )


def test_default_path_is_beside_the_log():
    assert str(mram.default_path("logs/Gecat.log")) == os.path.join("logs", "Gecat.mram")
    assert str(mram.default_path("")) == "Gecat.mram"
