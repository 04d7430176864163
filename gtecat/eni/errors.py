"""Typed exceptions shared by every layer.

The root lives here because ``eni`` is the bottom of the dependency graph
(``eni`` -> ``drives`` -> ``gtecat``); every other package may import it.
"""

from __future__ import annotations


class GtecatError(Exception):
    """Root of every error gtecat raises on purpose."""


class EniError(GtecatError):
    """A configuration file that cannot be used, with where and what.

    ``str(err)`` reads ``file:line: slave N (name): element: message`` with the
    parts that are known, so a user can go straight to the offending line.
    """

    def __init__(
        self,
        message: str,
        *,
        file: str | None = None,
        line: int | None = None,
        slave: int | None = None,
        slave_name: str | None = None,
        element: str | None = None,
    ) -> None:
        self.message = message
        self.file = file
        self.line = line
        self.slave = slave
        self.slave_name = slave_name
        self.element = element
        super().__init__(self._render())

    def _render(self) -> str:
        where = ""
        if self.file:
            where = self.file + (f":{self.line}" if self.line else "") + ": "
        elif self.line:
            where = f"line {self.line}: "
        who = ""
        if self.slave is not None:
            who = (
                f"slave {self.slave}" + (f" ({self.slave_name})" if self.slave_name else "") + ": "
            )
        elem = f"{self.element}: " if self.element else ""
        return f"{where}{who}{elem}{self.message}"
