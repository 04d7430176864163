"""The master log: what the real controller writes to ``Gecat.log``.

The iDEABOX master is IgH-based, so its log reads like the IgH kernel log
("Scanning bus", "Slave states: PREOP", "All slaves are in OP mode", CoE
emergencies).  We write the same kind of line for what our master does, with
the controller time in front, to a file and to memory (``lines``).
"""

from __future__ import annotations

from pathlib import Path


class MasterLog:
    def __init__(self, path: str | Path | None = None, *, clock_ms=lambda: 0) -> None:
        self.path = Path(path) if path else None
        self.lines: list[str] = []
        self._clock_ms = clock_ms
        self._fh = None

    def __call__(self, message: str) -> None:
        line = f"[{self._clock_ms():>10} ms] EtherCAT: {message}"
        self.lines.append(line)
        if self.path is not None:
            try:
                if self._fh is None:
                    self._fh = self.path.open("a", encoding="utf-8")
                self._fh.write(line + "\n")
                self._fh.flush()
            except OSError:
                self.path = None  # an unwritable log must not stop the bus

    def text(self) -> str:
        return "\n".join(self.lines)

    def close(self) -> None:
        if self._fh is not None:
            self._fh.close()
            self._fh = None
