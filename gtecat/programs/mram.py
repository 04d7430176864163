"""The ferroelectric memory of manual 11.8: a 4096-word buffer, a non-volatile store, accesses.

The controller has a data buffer of 4096 words (``short``) that the host fills and
reads 24 words at a time (``GT_SetMRAMData`` / ``GT_GetMRAMData``) and a
non-volatile memory of the same size.  ``GT_StartAccessMRAM(address, count, mode)``
copies words ``address .. address+count-1`` between the two - mode 1 writes the
buffer into the memory, mode 0 reads the memory into the buffer - and takes
controller time: ``GT_GetMRAMStatus`` answers 0 from the start until the access is
done, then 1 (1 stays until the next start).  The access takes
:func:`access_time_ns` (1 ms, plus 1 ms per started 1024 words) and completes at the
end of the first cycle that reaches it.  A write copies the buffer as it is at the
start; a read fills the buffer at completion.  ``GT_StopAccessMRAM`` abandons the
access in progress: nothing is transferred, the status stays 0; a new start abandons
the access in progress the same way.

The non-volatile memory is a file (:class:`MramStore`), so it survives ``GT_Close``,
a new process and a crash: ``GT_Open(mram=PATH)``, else ``GTECAT_MRAM``, else
``Gecat.mram`` beside the log file (in the working directory when logging is off).
Every completed write replaces the file atomically (a temporary file beside it,
written, flushed and fsync'ed, then renamed over the old one, then the directory
fsync'ed), so a kill at any moment leaves either the old or the new contents, never a
torn store; a temporary file a killed process left behind is removed at the next open.
A missing file reads as zeros.

File format 1 (little-endian): ``8s magic "GTEMRAM\\n"``, ``u16 format``, ``u16 words``
(4096), ``u32 CRC-32 of the data``, then 4096 ``i16`` words.
"""

from __future__ import annotations

import os
import struct
import time
import zlib
from dataclasses import dataclass
from pathlib import Path

WORDS = 4096  #: buffer and memory size, words (entry 57 / 114: address in [0, 4096))
MAX_TRANSFER = 24  #: words per GT_SetMRAMData / GT_GetMRAMData (11.8.1)
FORMAT = 1
MAGIC = b"GTEMRAM\n"
HEADER = struct.Struct("<8sHHI")
_DATA = struct.Struct(f"<{WORDS}h")


class MramError(Exception):
    """The store cannot be read or written (the GT call returns 1 with the reason)."""


def access_time_ns(count: int) -> int:
    """How long an access of ``count`` words takes: 1 ms + 1 ms per started 1024 words."""
    return (1 + (count + 1023) // 1024) * 1_000_000


class MramStore:
    """The non-volatile memory: one file, replaced atomically on every write."""

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path)
        self.removed = remove_stale_temporaries(self.path)

    def read(self) -> list[int]:
        try:
            data = self.path.read_bytes()
        except FileNotFoundError:
            return [0] * WORDS
        except OSError as e:
            raise MramError(f"cannot read the MRAM store {self.path}: {e.strerror or e}") from None
        if len(data) != HEADER.size + _DATA.size:
            raise MramError(f"{self.path} is not an MRAM store ({len(data)} bytes)")
        magic, fmt, words, crc = HEADER.unpack_from(data)
        body = data[HEADER.size :]
        if magic != MAGIC or fmt != FORMAT or words != WORDS:
            raise MramError(f"{self.path} is not an MRAM store of format {FORMAT}")
        if zlib.crc32(body) != crc:
            raise MramError(f"the MRAM store {self.path} is damaged (checksum)")
        return list(_DATA.unpack(body))

    def write(self, words: list[int]) -> None:
        body = _DATA.pack(*words)
        data = HEADER.pack(MAGIC, FORMAT, WORDS, zlib.crc32(body)) + body
        tmp = self.path.with_name(f".{self.path.name}.{os.getpid()}.tmp")
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
            try:
                view = memoryview(data)
                while view:
                    n = os.write(fd, view)
                    view = view[n:]
                os.fsync(fd)
            finally:
                os.close(fd)
            os.replace(tmp, self.path)
            _fsync_dir(self.path.parent)
        except OSError as e:
            try:
                tmp.unlink()
            except OSError:
                pass
            raise MramError(f"cannot write the MRAM store {self.path}: {e.strerror or e}") from None


def remove_stale_temporaries(path: Path) -> list[Path]:
    """Remove the temporary files of writes that a killed process left beside ``path``
    (``.NAME.<pid>.tmp``, see :meth:`MramStore.write`): the store itself was never torn
    (the rename is atomic), but the leftovers would pile up.  A temporary of a process that
    still runs is left alone (it may be writing now); on Windows, where no harmless
    liveness test exists, one younger than a minute is.  Returns what was removed."""
    prefix = f".{path.name}."
    removed = []
    try:
        candidates = [p for p in path.parent.iterdir() if p.name.startswith(prefix)]
    except OSError:
        return removed
    for p in candidates:
        pid = p.name[len(prefix) :].removesuffix(".tmp")
        if not p.name.endswith(".tmp") or not pid.isdigit() or int(pid) == os.getpid():
            continue
        if _running(int(pid), p):
            continue
        try:
            p.unlink()
            removed.append(p)
        except OSError:
            pass
    return removed


def _running(pid: int, tmp: Path) -> bool:
    if os.name == "nt":  # os.kill(pid, 0) would terminate the process there
        try:
            return time.time() - tmp.stat().st_mtime < 60
        except OSError:
            return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError, OSError):
        return True  # another user's process (or a pid the OS cannot take): not ours to judge
    return True


def _fsync_dir(directory: Path) -> None:
    try:
        fd = os.open(directory, os.O_RDONLY)
    except OSError:
        return  # not every platform opens directories
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


@dataclass
class _Access:
    mode: int
    address: int
    count: int
    done_ns: int
    snapshot: list[int]


class Mram:
    """One controller's buffer, access state and store."""

    def __init__(self, store: MramStore) -> None:
        self.store = store
        self.buffer = [0] * WORDS
        self.status = 0
        self.access: _Access | None = None
        self.error = ""  #: why the last access failed ("" if it did not)

    def set_data(self, address: int, words: list[int]) -> None:
        self.buffer[address : address + len(words)] = words

    def get_data(self, address: int, count: int) -> list[int]:
        return self.buffer[address : address + count]

    def start(self, address: int, count: int, mode: int, now_ns: int) -> None:
        snapshot = self.buffer[address : address + count] if mode == 1 else []
        self.status = 0
        self.error = ""
        self.access = _Access(mode, address, count, now_ns + access_time_ns(count), snapshot)

    def stop(self) -> None:
        self.access = None

    def tick(self, now_ns: int) -> None:
        """End of a cycle at ``now_ns``: complete the access when its time has come."""
        a = self.access
        if a is None or now_ns < a.done_ns:
            return
        self.access = None
        try:
            stored = self.store.read()
            if a.mode == 1:
                stored[a.address : a.address + a.count] = a.snapshot
                self.store.write(stored)
            else:
                self.buffer[a.address : a.address + a.count] = stored[
                    a.address : a.address + a.count
                ]
        except MramError as e:
            self.error = str(e)
            return  # the status stays 0: the access did not complete
        self.status = 1


def default_path(log: str | None) -> Path:
    """``Gecat.mram`` beside the log file (the working directory when logging is off)."""
    if log:
        return Path(log).with_name("Gecat.mram")
    return Path("Gecat.mram")


__all__ = [
    "MAX_TRANSFER",
    "WORDS",
    "Mram",
    "MramError",
    "MramStore",
    "access_time_ns",
    "default_path",
]
